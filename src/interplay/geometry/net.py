"""A regulation basketball net: a tapered tube of diamond mesh hanging from the rim."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError, require_nonnegative, require_positive
from ..params import param
from ..systems.springmass import SpringNetwork, Springs


@dataclass(frozen=True)
class NetParams:
    """The net and its cords.

    rim_radius, rim_height, length, bottom_radius: m; loops: knots around the rim; rows: rows of
    knots (two knot rows make one row of diamonds); mass: kg (spread over the knots by cord length); cord_ea: the cords' stress/strain
    ratio E*A (N), so k = EA / l0 for each cord; rim_stiffness: N/m and rim_damping: N s/m of
    the springs tying the top knots to the rim; mass_damping: 1/s; stiffness_damping: s;
    dt: s; integrator: explicit | implicit; cord_radius: m (contact skin); scheme: the implicit
    integrator, bdf2 or theta; theta: for the theta scheme (1 backward Euler, 1/2 trapezoidal).
    """
    rim_radius: float = param(0.2286, "m", ge=0.01, le=5.0)
    rim_height: float = param(3.05, "m", ge=0.01, le=100.0)
    length: float = param(0.40, "m", ge=0.01, le=10.0)
    bottom_radius: float = param(0.11, "m", ge=0.005, le=5.0)
    loops: int = param(12, "knots", ge=3, le=256, cost="points", doc="knots around the rim")
    # knot rows below the rim: 6 rows of diamonds
    rows: int = param(12, "knots", ge=1, le=256, cost="points", doc="knot rows below the rim")
    mass: float = param(0.03, "kg", ge=1e-5, le=100.0)
    cord_ea: float = param(300.0, "N", ge=1e-3, le=1e9, doc="cords' stress/strain ratio E A")
    rim_stiffness: float = param(2.0e3, "N/m", ge=1e-3, le=1e9)
    # explicit stability of a 2.5 g knot at 1e-5 s needs c < 2 m / dt = 500 N s/m
    rim_damping: float = param(1.0, "N s/m", ge=0.0, le=100.0)
    mass_damping: float = param(1.0, "1/s", ge=0.0, le=1e4)
    stiffness_damping: float = param(2.0e-4, "s", ge=0.0, le=1.0)
    # explicit, the paper's two-way step: with friction 1.0 the ball's path converges at 1e-5 s
    # (2e-5 s is 0.5 mm away, 5e-5 s 2 cm at t = 0.6 s) and the contact goes unstable at 1e-4
    dt: float = param(1e-5, "s", ge=1e-9, le=0.1, doc="the net's largest step")
    integrator: str = param("explicit", choices=("explicit", "implicit", "localglobal"))
    cord_radius: float = param(0.003, "m", ge=1e-4, le=0.1, doc="contact skin")
    # backward Euler (theta = 1), Baraff & Witkin; or "bdf2"
    scheme: str = param("theta", choices=("theta", "bdf2"), doc="the implicit scheme")
    theta: float = param(1.0, "-", ge=0.5, le=1.0, doc="1 backward Euler, 1/2 trapezoidal")


def net_knots(p: NetParams) -> tuple[np.ndarray, np.ndarray]:
    """Knot positions ((rows+1)*loops, 3) and cord index pairs (2*rows*loops, 2).

    Row i sits at height rim_height - length*i/rows with a radius tapering linearly to
    bottom_radius; odd rows are turned half a loop, and each knot ties to the two nearest knots
    of the next row, which makes the diamonds.
    """
    owner = "net"
    for name in ("rim_radius", "length", "bottom_radius", "mass", "cord_ea", "rim_stiffness"):
        require_positive(owner, name, getattr(p, name))
    require_nonnegative(owner, "rim_damping", p.rim_damping)
    if int(p.loops) < 3 or int(p.rows) < 1:
        raise ParameterError(f"net: needs loops >= 3 and rows >= 1, got loops={p.loops}, "
                             f"rows={p.rows}")
    L, R = int(p.loops), int(p.rows)
    rows = np.arange(R + 1)
    z = p.rim_height - p.length * rows / R
    r = p.rim_radius + (p.bottom_radius - p.rim_radius) * rows / R
    ang = 2 * np.pi * (np.arange(L)[None, :] + 0.5 * (rows[:, None] % 2)) / L
    x = np.stack([r[:, None] * np.cos(ang), r[:, None] * np.sin(ang),
                  np.broadcast_to(z[:, None], ang.shape)], axis=-1).reshape(-1, 3)
    idx = np.arange((R + 1) * L).reshape(R + 1, L)
    pairs = []
    for i in range(R):
        step = -1 if i % 2 == 0 else 1
        for j in range(L):
            pairs.append((idx[i, j], idx[i + 1, j]))
            pairs.append((idx[i, j], idx[i + 1, (j + step) % L]))
    return x, np.array(pairs, dtype=np.int64)


def basketball_net(p: NetParams = NetParams(), name: str = "net") -> SpringNetwork:
    """The net as a tension-only cord network tied to the fixed rim by springs."""
    x, pairs = net_knots(p)
    cords = Springs.from_ratio(x, pairs, p.cord_ea, tension_only=True)
    # lump each cord's mass (proportional to its length) half on each end
    m = np.zeros(len(x))
    cord_mass = p.mass * cords.rest / cords.rest.sum()
    np.add.at(m, pairs[:, 0], 0.5 * cord_mass)
    np.add.at(m, pairs[:, 1], 0.5 * cord_mass)
    top = np.arange(int(p.loops))
    anchors = (top, x[top].copy(), p.rim_stiffness, p.rim_damping)
    return SpringNetwork(name, x, m, cords, dt=p.dt, integrator=p.integrator,
                         mass_damping=p.mass_damping, stiffness_damping=p.stiffness_damping,
                         anchors=anchors, scheme=p.scheme,
                         theta=p.theta)
