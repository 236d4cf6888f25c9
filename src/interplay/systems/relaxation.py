"""A spring network brought to rest: the way a net is let sag before a scene starts and a bed
or mat is pressed to measure its load-deflection (its static shape under a load, without
integrating the oscillation).

``relax`` takes damped backward-Euler steps with heavy mass damping (a caller may ramp a load
or a held position on before each); ``settle`` is the sag under gravity alone, found as the
minimum of the potential energy by Newton's method on the springs' stiffness (``static_rest``:
exact to round-off, and no Numba kernel to compile, which an explicit scene's first run would
otherwise pay for the implicit solver, ~10 s: docs/first-run.md). It is a pure function of the
network, remembered for the process: compare's builds of one scene, a sweep worker's runs and
the tests settle each distinct network once.
"""
from __future__ import annotations

import hashlib
from collections import OrderedDict

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import spsolve

from ..errors import SceneError
from ..kernels import springs as K

#: settled positions by network digest (oldest dropped first); a few networks' worth
SETTLED_KEPT = 8
_SETTLED: OrderedDict[bytes, np.ndarray] = OrderedDict()


def _digest(*parts) -> bytes:
    """A digest of arrays, tuples of them (the kernels' bundles) and scalars."""
    h = hashlib.blake2b(digest_size=20)

    def feed(o):
        if isinstance(o, np.ndarray):
            h.update(f"{o.dtype}{o.shape}".encode())
            h.update(np.ascontiguousarray(o).tobytes())
        elif isinstance(o, tuple):
            for e in o:
                feed(e)
        else:
            h.update(repr(o).encode())
    for p in parts:
        feed(p)
    return h.digest()


def relax(net, seconds: float, h: float, damping: float, max_iter: int = 1000,
          each_step=None) -> None:
    """``seconds`` (s) of backward-Euler steps of h (s) with mass damping ``damping`` (1/s) in
    place of the network's own, each solved to a 1e-10 residual (at most ``max_iter`` CG
    iterations); ``each_step(k, n)`` runs before step k of n (a load or a held position
    ramped on: a sudden one would throw a lattice past where it rests). v = 0 after."""
    bundle = net.bundle(alpha=damping)
    scheme = K.Scheme(True, 1.0, False, 1e-10, max_iter, net.xp, net.vp)
    n = int(round(seconds / h))
    for k in range(n):
        if each_step is not None:
            each_step(k, n)
        K.implicit_step(bundle, net._load, net._f, h, scheme, False)
    net.v[:] = 0.0


def _energy(net, x, free):
    """The potential energy (J) of positions x (n,3) m: the springs' (slack tension-only cords
    store none), the anchors' and gravity's; its gradient on the ``free`` points (k,3) N; and
    the springs' stretch e (m), lengths (m) and unit vectors, for the Hessian."""
    d = x[net.si] - x[net.sj]
    ln = np.linalg.norm(d, axis=1)
    e = ln - net.l0
    e[net.tension_only & (e < 0.0)] = 0.0
    u = d / np.where(ln > 0.0, ln, 1.0)[:, None]
    g = np.zeros_like(x)
    pull = (net.k * e)[:, None] * u
    np.add.at(g, net.si, pull)
    np.add.at(g, net.sj, -pull)
    a = x[net.a_idx] - net.a_pos
    np.add.at(g, net.a_idx, net.a_k[:, None] * a)
    g -= net.m[:, None] * net.gravity
    energy = (0.5 * float(net.k @ (e * e)) + 0.5 * float(net.a_k @ (a * a).sum(axis=1))
              - float((net.m[:, None] * net.gravity * x).sum()))
    return energy, g[free], (e, ln, u)


def _stiffness(net, springs, free_slot, n_free):
    """The energy's Hessian (3k,3k) N/m on the free points, each spring's block made positive
    semi-definite (k [u u^T + max(0, 1 - l0/l) (I - u u^T)]: a compressed spring's negative
    transverse term is dropped, a slack cord has none), so each Newton step goes downhill."""
    e, ln, u = springs
    active = (e != 0.0) | ~net.tension_only
    trans = np.clip(1.0 - net.l0 / np.where(ln > 0.0, ln, 1.0), 0.0, None)
    uu = u[:, :, None] * u[:, None, :]
    blk = net.k[:, None, None] * ((1.0 - trans)[:, None, None] * uu
                                  + trans[:, None, None] * np.eye(3))
    blk[~active] = 0.0
    rows, cols, vals = [], [], []

    def put(a, b, sign):
        keep = (free_slot[a] >= 0) & (free_slot[b] >= 0)
        ra, rb = free_slot[a][keep], free_slot[b][keep]
        for r in range(3):
            for c in range(3):
                rows.append(3 * ra + r)
                cols.append(3 * rb + c)
                vals.append(sign * blk[keep, r, c])
    put(net.si, net.si, 1.0)
    put(net.sj, net.sj, 1.0)
    put(net.si, net.sj, -1.0)
    put(net.sj, net.si, -1.0)
    slot = free_slot[net.a_idx]
    keep = slot >= 0
    for c in range(3):
        rows.append(3 * slot[keep] + c)
        cols.append(3 * slot[keep] + c)
        vals.append(net.a_k[keep])
    return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                         shape=(3 * n_free, 3 * n_free))


def static_rest(net, tol: float = 1e-6, max_iter: int = 1000) -> float:
    """Move the network's free points to the minimum of its potential energy under gravity
    (springs, anchors; no external force): Newton steps on the semi-definite stiffness plus
    a vanishing mu M (mu = 1e-9 k_max / m_min: a point hanging only on slack cords still has
    a direction, a fall), each shortened by halving until the energy falls enough (Armijo):
    a slack cord falls until it catches, then the steps are Newton's. Stops when the largest
    residual force is below ``tol`` times the heaviest point's weight; returns that force
    (N). v = 0 after. A network that cannot rest (a free point on no taut spring, falling
    for ever) raises SceneError."""
    free = np.flatnonzero(~net.fixed)
    free_slot = np.full(len(net.x), -1)
    free_slot[free] = np.arange(len(free))
    if not len(free):
        return 0.0
    weight = float(np.max(net.m[free]) * np.linalg.norm(net.gravity))
    mu = 1e-9 * float(np.max(net.k, initial=np.max(net.a_k, initial=1.0))) / float(
        np.min(net.m[free]))
    reg = sp.diags(np.repeat(mu * net.m[free], 3))
    x = net.x.copy()
    energy, g, springs = _energy(net, x, free)
    for _ in range(max_iter):
        residual = float(np.abs(g).max())
        if residual <= tol * weight:
            break
        d = -spsolve((_stiffness(net, springs, free_slot, len(free)) + reg).tocsc(),
                     g.ravel()).reshape(-1, 3)
        slope = float((g * d).sum())  # < 0: the direction goes downhill
        alpha = 1.0
        for _ in range(60):
            trial = x.copy()
            trial[free] += alpha * d
            e_new, g_new, s_new = _energy(net, trial, free)
            # (the last term: near the rest the energy's change falls below its round-off,
            # and the full Newton step, converging on the force, is taken)
            if e_new <= energy + 1e-4 * alpha * slope + 1e-13 * abs(energy):
                break
            alpha *= 0.5
        x, energy, g, springs = trial, e_new, g_new, s_new
    else:
        raise SceneError(f"network {net.name!r}: found no rest under gravity in {max_iter} "
                         f"Newton steps (largest residual force {residual:.3g} N); a point "
                         "hanging on no taut spring falls for ever: fix or anchor it")
    net.x[:] = x
    net.v[:] = 0.0
    return residual


def settle(net, relaxed: float | None = None) -> None:
    """The network's sag to rest under gravity alone (its held forces set aside): its
    ``static_rest``, or with ``relaxed`` (s) that long a damped relaxation (h 2 ms, mass
    damping 30/s: near rest, not at it; kept where a tuned result depends on that very state,
    the trampoline's bed); found once per distinct network and restored from memory after."""
    key = _digest(net.bundle(alpha=0.0), relaxed)
    if key not in _SETTLED:
        if relaxed is None:
            static_rest(net)
        else:
            saved = net.fext.copy()
            net.fext[:] = 0.0
            try:
                relax(net, relaxed, 2e-3, 30.0)
            finally:
                net.fext[:] = saved
        _SETTLED[key] = net.x.copy()
        while len(_SETTLED) > SETTLED_KEPT:
            _SETTLED.popitem(last=False)
    net.x[:] = _SETTLED[key]
    net.v[:] = 0.0
    net.has_prev = False
