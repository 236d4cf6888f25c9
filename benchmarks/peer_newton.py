"""NVIDIA Newton (``newton`` 1.8, on warp-lang) as a peer in the cloth drape benchmark, on the CPU.

The scene is bench_cloth.py's: a 1 m cloth of n x n vertices (our criss-cross grid triangulation,
``shapes.grid``), flat at z = 0.35 m over a fixed 0.25 m sphere at the origin, 0.15 kg/m^2,
pinned at vertices 0 and n-1, gravity 9.81 m/s^2 along -z, 2 s.

Solver: ``SolverVBD`` (Vertex Block Descent, Newton's cloth solver of choice), with the
settings of Newton's own cloth examples (example_cloth_hanging, the VBD cloth examples): 60
frames/s, 10 substeps per frame (dt = 1/600 s), 10 VBD iterations per substep, the collision
pipeline run before every substep, no self-contact. Fewer substeps also stay stable but the
membrane is less converged, so the cloth stretches and sags more (32^2, 2 s, substeps x
iterations: 10 x 10 lowest z -0.28 m, max edge strain 6 %; 5 x 10: -0.31 m, 17 %; 2 x 10:
-0.38 m, 130 %; 1 x 10 sinks 8 mm into the sphere; 20 x 10: -0.24 m, 2 %; ours, implicit:
-0.22 m, 0.7 %). At 10 x 10 the finer cloths converge less (64^2: -0.31 m, 128^2: -0.36 m;
mean edge strain 0.4 %, 1.2 %, but 67 %, 560 % on the edges at the pins), so they are softer
than ours. SolverXPBD with springs k = 200 N / l0 diverged in the first frame.

Membrane: Newton's VBD cloth is a stable Neo-Hookean triangle FEM whose tri_ke, tri_ka are the
2D Lame parameters mu, lambda (N/m). Our network puts springs of k = S / l0 (S = 200 N) on the
grid edges and on both diagonals of each cell; its small-strain energy density for a cell
of side h is (S/h) [(exx^2 + eyy^2)/2 + (exx + eyy)^2 / (2 sqrt 2) + sqrt2 exy^2]. The
isotropic membrane with mu = S / (2h), lambda = S / (sqrt2 h) has the same energy for every
normal strain along the grid axes (the network is sqrt 2 stiffer in axis-aligned shear).
Both grow as 1/h, like the network. tri_kd = 1e-4 s x tri_ke (roughly our stiffness damping,
1e-4 s); bending edge_ke = 1e-5 N m / h, a cotton-like bending stiffness of 1e-5 N m
(our springs have none to first order). No mass damping: VBD has no such term.

Contact: particle radius 5 mm (the thickness), sphere shape margin 0, contact ke 2e3 N/m,
kd 0.01 N s/m, mu 0.3 on both the particle and the shape side (VBD averages the two).

Timing: ``available()`` runs one frame of a 4 x 4 cloth of the same scene, which compiles
(first run ever, ~30 s; kept in warp's kernel cache, WARP_CACHE_PATH) or loads every kernel;
``newton_cloth`` then times the whole 2 s of stepping of the n x n cloth, model build excluded.
Warp runs CPU kernels on one thread.
"""
from __future__ import annotations

import functools
import time

import numpy as np

from drape import (CONTACT_KD, CONTACT_KE, DENSITY, DURATION, FRAME, HEIGHT, MU, RADIUS,
                   STRETCH, THICKNESS)

BENDING = 1.0e-5  # N m
SUBSTEPS, ITERATIONS = 10, 10


def _model(n):
    import newton
    import warp as wp
    from interplay.geometry import shapes
    h = 1.0 / (n - 1)
    x, t = shapes.grid(1.0, 1.0, n, n, origin=(-0.5, -0.5, HEIGHT))
    b = newton.ModelBuilder(up_axis=newton.Axis.Z, gravity=(0.0, 0.0, -9.81))
    cfg = b.default_shape_cfg.copy()
    cfg.ke, cfg.kd, cfg.mu = CONTACT_KE, CONTACT_KD, MU
    b.add_shape_sphere(-1, radius=RADIUS, cfg=cfg)
    mu, lam = STRETCH / (2.0 * h), STRETCH / (np.sqrt(2.0) * h)
    b.add_cloth_mesh(pos=wp.vec3(0.0, 0.0, 0.0), rot=wp.quat_identity(), scale=1.0,
                     vel=wp.vec3(0.0, 0.0, 0.0), vertices=[wp.vec3(*p) for p in x],
                     indices=t.ravel().tolist(), density=DENSITY, tri_ke=mu, tri_ka=lam,
                     tri_kd=1e-4 * mu, edge_ke=BENDING / h, edge_kd=0.0,
                     particle_radius=THICKNESS)
    for i in (0, n - 1):  # pinned: no mass, not integrated
        b.particle_mass[i] = 0.0
        b.particle_flags[i] &= ~newton.ParticleFlags.ACTIVE
    b.color(include_bending=True)  # VBD solves the particles colour by colour
    m = b.finalize(device="cpu")
    m.soft_contact_ke, m.soft_contact_kd, m.soft_contact_mu = CONTACT_KE, CONTACT_KD, MU
    return m


def drape(n, duration=DURATION, substeps=SUBSTEPS, iterations=ITERATIONS):
    """Final particle positions (n*n, 3) m, the substep (s) and the wall seconds of stepping."""
    import newton
    import warp as wp
    with wp.ScopedDevice("cpu"):
        m = _model(n)
        solver = newton.solvers.SolverVBD(m, iterations=iterations)
        pipeline = newton.CollisionPipeline(m)
        contacts = pipeline.contacts()
        s0, s1, control = m.state(), m.state(), m.control()
        dt = FRAME / substeps
        steps = int(round(duration / FRAME)) * substeps
        t0 = time.perf_counter()
        for _ in range(steps):
            s0.clear_forces()
            pipeline.collide(s0, contacts)
            solver.step(s0, s1, control, contacts, dt)
            s0, s1 = s1, s0
        wp.synchronize_device("cpu")
        wall = time.perf_counter() - t0
        return s0.particle_q.numpy(), dt, wall


@functools.cache
def available() -> str | None:
    """None if newton and warp import and step a tiny cloth on the CPU (compiling or loading
    the kernels outside any timing), else a one-line reason."""
    try:
        import warp as wp
        wp.config.log_level = wp.LOG_WARNING  # no per-module load lines
        q, _, _ = drape(4, duration=FRAME)
    except Exception as e:  # noqa: BLE001 - any failure means the peer is unavailable
        return f"newton on CPU: {type(e).__name__}: {(str(e).splitlines() or [''])[0]}"
    return None if np.all(np.isfinite(q)) else "newton on CPU: a 4x4 cloth went non-finite"


def newton_cloth(n, duration=DURATION) -> tuple[float, float, float, float]:
    """(simulated s per wall s, substep dt s, lowest z m, wall s) for Newton's VBD cloth."""
    reason = available()
    if reason:
        raise RuntimeError(reason)
    q, dt, wall = drape(n, duration)
    if not np.all(np.isfinite(q)):
        raise RuntimeError(f"newton VBD {n}^2 went non-finite")
    return duration / wall, dt, float(q[:, 2].min()), wall
