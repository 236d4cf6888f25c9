"""The parallel explicit kernel (per-spring forces, per-point CSR gather) equals the serial one to
round-off, with anchors, tension-only cords, damping and fixed points."""
import numpy as np

from interplay.geometry import shapes
from interplay.kernels import parallel as PAR
from interplay.systems.springmass import SpringNetwork


def network(parallel, n=24):
    x, t = shapes.grid(1.0, 1.0, n, n)
    net = SpringNetwork.from_mesh(
        "c", x, t, 0.15, 200.0, dt=1e-5, integrator="explicit", fixed=[0, n - 1],
        mass_damping=0.3, stiffness_damping=1e-6, parallel=parallel,
        anchors=([5, n + 4, n + 5], np.zeros((3, 3)) + [0.1, 0.2, 0.3], 50.0, 0.01))
    rng = np.random.default_rng(1)
    net.tension_only[::3] = True  # every third spring a cord
    net.x += 0.2 * net.l0.min() * rng.normal(size=net.x.shape)
    net.v[:] = 0.1 * rng.normal(size=net.x.shape)
    net.v[net.fixed] = 0.0
    net.fext[:] = 1e-3 * rng.normal(size=net.x.shape)
    return net


def test_adjacency_lists_every_spring_end_once():
    net = network(False, n=6)
    indptr, ids, sign, a_ptr, a_ids, _ = PAR.adjacency(len(net.x), net.si, net.sj, net.a_idx)
    for p in range(len(net.x)):
        own = ids[indptr[p]:indptr[p + 1]]
        sg = sign[indptr[p]:indptr[p + 1]]
        assert sorted(own[sg > 0]) == sorted(np.flatnonzero(net.si == p))
        assert sorted(own[sg < 0]) == sorted(np.flatnonzero(net.sj == p))
        assert sorted(a_ids[a_ptr[p]:a_ptr[p + 1]]) == sorted(np.flatnonzero(net.a_idx == p))


def test_parallel_step_equals_serial():
    serial, par = network(False), network(True)
    assert serial._adj is None and par._adj is not None
    # one step: the forces themselves, f = m dv / h (sums in another order: round-off only)
    h = 1e-5
    v0 = serial.v.copy()
    serial.step(h)
    par.step(h)
    f_serial = serial.m[:, None] * (serial.v - v0) / h
    f_par = par.m[:, None] * (par.v - v0) / h
    assert np.abs(f_par - f_serial).max() <= 1e-9 * np.abs(f_serial).max()
    # many substeps inside one kernel call: still equal to round-off growth
    serial.advance(2e-3)
    par.advance(2e-3)
    assert np.abs(par.x - serial.x).max() < 1e-10
    assert np.array_equal(par.x[par.fixed], serial.x[serial.fixed])


def test_parallel_is_opt_in():
    # measured slower than the serial kernel on 2 cores (kernels/parallel.py): never by default
    x, t = shapes.grid(1.0, 1.0, 200, 200)  # 198k springs
    net = SpringNetwork.from_mesh("c", x, t, 0.15, 200.0, dt=1e-3)
    assert len(net.si) > 150_000 and net._adj is None
