"""A gymnast landing on a floor mat after a vault (SPEC 4), coupled hybrid as in the paper.

The mat is a foam block, a layered spring-mass lattice with volume-keeping braces
(geometry/mat.py), resting on the floor through a ground contact. The gymnast (64.38 kg,
1.70 m; the 17-segment figure) leaves the vault table after a handspring (the second flight:
control/landing.py's take-off state), turns forward over and lands under a landing state
machine that sticks it (prepare, touch-down, hold). Her segments collide with the mat's top
through the generic rigid-parts contact, sub-cycled in the mat's substeps
(interactions/part_contact.py).

Hybrid (default): in her pass her feet land on a grid of vertical spring-dampers that cannot
slide or rotate (interactions/bed_springs.py: vertical force only, fitted by ``interplay
fit-standin mat`` to the mat's measured load-deflection); then her recorded motion drives the
full mat one-way. ``--coupling two-way`` runs both in lock step; ``--set mat.enabled=false``
removes the mat: she lands on a rigid floor at the height of the mat's top.

A take-off that misses the mat is refused before anything runs (her flight is flown alone
first, about a tenth of a second of wall time), naming where she lands and where the mat is.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass, replace

import numpy as np

from ..control.landing import VaultParams, gymnast
from ..control.landing_search import LANDING
from ..errors import SceneError
from ..geometry.anthropometry import SEGMENTS
from ..geometry.mat import FEET_HALF, MAT_COLOR, MatParams, build_mat
from ..interactions.bed_springs import BedSprings, BedSpringsParams, fit_curve
from ..interactions.part_contact import PartContact, PartContactParams
from ..outputs.render.camera import Camera
from ..params import param
from ..scene import Scene
from ..systems.colliders import StaticBox
from ..systems.springmass import SpringNetwork, Springs
from ..systems.static import StaticPlane
from .contract import SceneSpec
from .landing_measures import contrast, landing_figures
from .trampoline import check_explicit

TABLE = (0.6, 0.475)  # m: the vault table's half length (x) and half width (y) (FIG: 1.2 x 0.95)
SOLES = [SEGMENTS.index(s) for s in ("l_foot", "r_foot")]
MARGIN = 0.1  # m: her landing must be this far inside the mat's edges
FIT_LOADS = (0.5, 1.0, 2.0, 4.0, 6.0, 8.0, 10.0, 12.0, 14.0, 16.0)  # body weights: a landing's


@dataclass(frozen=True)
class MatSceneParams:
    """mat: the landing mat; vault: the take-off and landing controller; contact: her segments
    on the mat's top; standin: the vertical
    spring-dampers her pass sees in hybrid (fitted by ``fit-standin``: linear N/m, quadratic
    N/m^2, cubic N/m^3); coupling_dt (s): the step at which she and the mat exchange
    forces; air_density (kg/m^3) of the drag on her segments."""
    mat: MatParams = MatParams()
    vault: VaultParams = VaultParams()
    contact: PartContactParams = PartContactParams(friction=1.0)
    # fitted to MatParams() by `interplay fit-standin mat` (docs/mat.md); tangentially the
    # contact's own friction law (mu and eps as ``contact``: docs/mat.md, the stand-in)
    standin: BedSpringsParams = BedSpringsParams(linear=60774.1, quadratic=148032.0,
                                                 cubic=1146180.0,
                                                 damping=300.0, pocket=0.03,
                                                 friction_damping=2000.0, friction=1.0,
                                                 eps=0.01)
    coupling_dt: float = param(1e-3, "s", gt=0.0, le=0.01)
    air_density: float = param(1.2, "kg/m^3", ge=0.0, le=100.0)


def mat_network(p: MatParams, integrator: str = "implicit", dt: float | None = None):
    """The mat as a network resting on the floor (z = 0 under its bottom layer), its outer
    surface drawn; top points and edges kept on it (``top``, ``top_edges``). An explicit
    step past the lattice's bound is refused before anything runs."""
    lat = build_mat(p)
    net = SpringNetwork("mat", lat.x, lat.masses,
                        Springs(lat.i, lat.j, lat.rest, lat.k, np.zeros(len(lat.i), bool)),
                        dt=dt or p.dt, integrator=integrator, mass_damping=p.mass_damping,
                        stiffness_damping=p.stiffness_damping, triangles=lat.triangles,
                        strain_limit=0.9, color=MAT_COLOR, fixed=lat.bottom)
    if integrator == "explicit":
        check_explicit(net, "mat.dt")
    net.top, net.bottom, net.top_edges = lat.top, lat.bottom, lat.top_edges
    net.rest_height = p.thickness
    return net


def pressed_points(net, half: float = FEET_HALF) -> np.ndarray:
    """Indices of the mat's top points within ``half`` (m) of its top's centre in x and y."""
    top = net.x[net.top]
    c = 0.5 * (top.min(axis=0) + top.max(axis=0))
    near = (np.abs(top[:, 0] - c[0]) <= half + 1e-9) & (np.abs(top[:, 1] - c[1]) <= half + 1e-9)
    return net.top[near]


def press(net, load: float, half: float = FEET_HALF, seconds: float = 0.4,
          damping: float = 100.0, h: float = 1e-2) -> float:
    """Settle the mat ``net`` on a rigid floor (its bottom layer held) under a downward load
    (N) spread evenly over the top points within ``half`` (m) of the centre (two feet side by
    side), by heavily damped backward-Euler steps; returns the depression (m) of the top's
    lowest point below its rest height. Leaves the network at that rest, unloaded."""
    from ..kernels import springs as K
    sel = pressed_points(net, half)
    saved, fixed = net.fext.copy(), net.fixed.copy()
    net.fixed[net.bottom] = True
    net.fext[:] = 0.0
    bundle = net.bundle(alpha=damping)
    scheme = K.Scheme(True, 1.0, False, 1e-10, 4000, net.xp, net.vp)
    n = int(round(seconds / h))
    for k in range(n):
        # the load ramps up over the first half: a sudden load would throw the top
        # layer past where it rests (a lattice can snap through; the foam would not)
        net.fext[sel, 2] = -load / len(sel) * min(1.0, 2.0 * (k + 1) / n)
        K.implicit_step(bundle, net._load, net._f, h, scheme, False)
    net.v[:] = 0.0
    net.fext[:] = saved
    net.fixed[:] = fixed
    return float(net.rest_height - net.x[net.top, 2].min())


def load_deflection(p: MatParams, loads) -> np.ndarray:
    """(load N, depression m) rows of the mat under each load (``press``), each from rest."""
    out = []
    for f in loads:
        net = mat_network(p, "implicit")
        out.append((f, press(net, f)))
    return np.array(out)


def fit(spec, params: MatSceneParams, **build_kw) -> dict:
    """``interplay fit-standin mat``: measure the mat's load-deflection over the landing's
    range (FIT_LOADS body weights on two feet) and fit the stand-in's curve to it
    (bed_springs.fit_curve); the report gives the fit's largest relative error."""
    weight = params.vault.mass * 9.81
    rows = load_deflection(params.mat, [b * weight for b in FIT_LOADS])
    a, b, c = fit_curve(rows[:, 1], rows[:, 0])
    sp = replace(params.standin, linear=a, quadratic=b, cubic=c)
    model = sp.force(rows[:, 1])
    err = np.abs(model - rows[:, 0]) / rows[:, 0]
    return {"fit": {"linear": a, "quadratic": b, "cubic": c},
            "loads_N": rows[:, 0].tolist(), "depressions_m": rows[:, 1].tolist(),
            "fitted_N": model.tolist(), "max_error_rel": float(err.max()),
            "sets": [f"standin.{k}={v:.6g}" for k, v in (("linear", a), ("quadratic", b),
                                                           ("cubic", c))]}


def flight(p: MatSceneParams, h: float) -> tuple:
    """Her flight alone until her feet first reach the mat's top plane: (t s, x m, y m) of the
    middle of her soles then, or None if she never comes down within 3 s."""
    top = p.mat.thickness
    fig = gymnast(p.vault, floor=top, air_density=p.air_density)
    while fig.time < 3.0:
        fig.clear_forces()
        fig.advance(h)
        if fig.data.ncon:
            soles = fig.data.xpos[fig.seg_body[SOLES]].mean(axis=0)
            return fig.time, float(soles[0]), float(soles[1])
    return None


def check_landing(p: MatSceneParams, where):
    """Refuse a take-off whose landing misses the mat (SceneError naming both)."""
    x0, x1, y0, y1 = p.mat.footprint()
    if where is None:
        raise SceneError("mat: the gymnast never comes down to the mat within 3 s; check the "
                         "vault.* take-off (vz, table)")
    t, x, y = where
    if not (x0 + MARGIN <= x <= x1 - MARGIN and y0 + MARGIN <= y <= y1 - MARGIN):
        raise SceneError(
            f"mat: the vault misses the mat: her feet come down at x={x:.2f} m, y={y:.2f} m "
            f"(t={t:.2f} s), and the mat spans x {x0:.2f}..{x1:.2f} m, y {y0:.2f}..{y1:.2f} m "
            f"(landings must be {MARGIN} m inside its edges); move the mat (mat.x0, "
            "mat.length) or change the take-off (vault.vx, vault.vz)")


def build(coupling: str = "hybrid", duration: float = 2.2, fps: float = 60.0,
          integrator: str | None = None, dt: float | None = None,
          params: MatSceneParams = MatSceneParams()) -> Scene:
    """The scene; dt overrides the mat's step (s)."""
    mp = params.mat.validated()
    top = mp.thickness
    scene = Scene("mat", duration=duration, fps=fps, coupling_dt=params.coupling_dt)
    floor_h = top if not mp.enabled else 0.0
    floor = scene.add(StaticPlane("floor", height=floor_h, size=5.0))
    table = scene.add(StaticBox("vault-table", (-TABLE[0], 0.0, 0.5 * params.vault.table),
                                (TABLE[0], TABLE[1], 0.5 * params.vault.table)))
    table.color = (0.75, 0.72, 0.68)
    if mp.enabled:
        check_landing(params, flight(params, params.coupling_dt))
    fig = scene.add(gymnast(params.vault, floor=floor_h, air_density=params.air_density))
    scene.primary = fig
    meta = {"vault": dataclasses.asdict(params.vault), "mat_top": top,
            "mat_enabled": mp.enabled, "footprint": list(mp.footprint()),
            "lattice": [mp.nx, mp.ny, mp.nz]}
    if mp.enabled:
        net = scene.add(mat_network(mp, integrator or "explicit", dt))
        # the stand-in's springs begin where the resting mat's top is, plus the skin
        standin = BedSprings(params.standin, fig, top + params.contact.thickness,
                             params.coupling_dt)
        scene.connect(PartContact("gymnast-mat", fig, net, params.contact, mode=coupling,
                                  standin=standin, elements=net.top_edges))
        scene.main = "gymnast-mat"
    scene.meta = meta
    return scene


SPEC = SceneSpec(
    "mat", "a gymnast lands a vault on a spring-mass floor mat; vertical springs stand in for "
           "the mat, then her motion drives it (hybrid)", build, MatSceneParams,
    couplings=("hybrid", "two-way", "one-way"), duration=2.2, fps=60.0,
    integrators=("explicit", "implicit"), standin="standin", fit=fit, figures=landing_figures,
    searches=(LANDING,),
    debug_ratio=5.0, contrast=contrast,
    # heavy: each trial of its search flies the whole landing twice (seconds)
    camera=Camera((1.9, -6.8, 2.0), (1.9, 0.0, 1.0), 45.0), key_time=0.83, heavy=True)
