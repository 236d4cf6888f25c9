"""Damped relaxation of a spring network to rest: backward-Euler steps with heavy mass damping,
the way a net is let sag before a scene starts and a bed or mat is pressed to measure its
load-deflection (its static shape under a load, without integrating the oscillation).

``relax`` takes the steps (a caller may ramp a load or a held position on before each);
``settle`` is the sag under gravity alone, a pure function of the network, remembered for the
process: compare's builds of one scene, a sweep worker's runs and the tests settle each
distinct network once (a trampoline bed takes seconds).
"""
from __future__ import annotations

import hashlib
from collections import OrderedDict

import numpy as np

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


def settle(net, seconds: float = 1.0, h: float = 2e-3, damping: float = 30.0) -> None:
    """The network's sag to rest under gravity alone (its held forces set aside), ``relax``ed
    once per distinct network, step and load Jacobians and restored from memory after."""
    key = _digest(net.bundle(alpha=damping), net._load[1:], seconds, h)  # fext zeroed here
    if key not in _SETTLED:
        saved = net.fext.copy()
        net.fext[:] = 0.0
        try:
            relax(net, seconds, h, damping)
        finally:
            net.fext[:] = saved
        _SETTLED[key] = net.x.copy()
        while len(_SETTLED) > SETTLED_KEPT:
            _SETTLED.popitem(last=False)
    net.x[:] = _SETTLED[key]
    net.v[:] = 0.0
    net.has_prev = False
