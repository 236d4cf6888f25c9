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
from ..control import landing_search
from ..errors import SceneError
from ..geometry.anthropometry import SEGMENTS
from ..geometry.mat import FEET_HALF, MAT_COLOR, MatParams, build_mat
from ..interactions.bed_springs import BedSprings, BedSpringsParams
from ..interactions.part_contact import PartContact, PartContactParams
from ..outputs.render.camera import Camera
from ..params import param
from ..scene import Scene
from ..systems.colliders import StaticBox
from ..systems.relaxation import relax
from ..systems.springmass import SpringNetwork, Springs
from ..systems.static import StaticPlane
from .contract import SceneSpec
from .landing_measures import contrast, landing_figures
from .trampoline import EXPLICIT_SHARE

TABLE = (0.6, 0.475)  # m: the vault table's half length (x) and half width (y) (FIG: 1.2 x 0.95)
SOLES = [SEGMENTS.index(s) for s in ("l_foot", "r_foot")]
MARGIN = 0.1  # m: her landing must be this far inside the mat's edges
# m: a rigid sole's depths over the landing's loads (0.5 to ~16 body weights of 64.38 kg); past
# 0.09 m (45% of the thickness) the linear lattice gives way under a rigid sole's edge (load
# falling, measured: 10 kN at 0.09 m, 7 kN at 0.1) where real foam densifies (docs/mat.md)
FIT_DEPTHS = (0.005, 0.01, 0.02, 0.03, 0.04, 0.05, 0.06, 0.07, 0.08, 0.09)
FIT_DROPS = (0.5, 1.0, 1.5, 2.0)  # m: impactor drops of a landing's impact speeds (3-6 m/s)


@dataclass(frozen=True)
class MatSceneParams:
    """mat: the landing mat; vault: the take-off and landing controller; contact: her segments
    on the mat's top; standin: the vertical
    spring-dampers her pass sees in hybrid (fitted by ``fit-standin``: linear N/m, quadratic
    N/m^2, cubic N/m^3); coupling_dt (s): the step at which she and the mat exchange
    forces; air_density (kg/m^3) of the drag on her segments."""
    mat: MatParams = MatParams()
    vault: VaultParams = VaultParams()
    # friction that sticks: under the regularised law a planted foot crept over the foam's
    # points at F dt / m_point (docs/mat.md, "Friction that sticks")
    contact: PartContactParams = PartContactParams(friction=1.0, stick=True)
    # fitted to MatParams() by `interplay fit-standin mat` (docs/mat.md): the curve, its
    # damping and, tangentially, each point anchored where it touched down by the mat's
    # shear stiffness under a sole (mu as ``contact``)
    standin: BedSpringsParams = BedSpringsParams(linear=70776.7, quadratic=505032.0,
                                                 cubic=0.0, damping=284.152, pocket=0.03,
                                                 friction=1.0, stick=82110.0,
                                                 stick_damping=246.33)
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
                        stiffness_damping=p.stiffness_damping, spring_damping=lat.kd,
                        triangles=lat.triangles,
                        strain_limit=0.9, color=MAT_COLOR, fixed=lat.bottom,
                        stability_share=EXPLICIT_SHARE, dt_key="mat.dt",
                        step_cure="less mat.foam_damping, mat.brace_damping or "
                        "mat.stiffness_damping")
    net.top, net.bottom, net.top_edges = lat.top, lat.bottom, lat.top_edges
    net.rest_height = p.thickness
    return net


def pressed_points(net, half: float = FEET_HALF, half_y: float | None = None) -> np.ndarray:
    """Indices of the mat's top points within ``half`` (m) of its top's centre in x and
    ``half_y`` (default ``half``) in y."""
    half_y = half if half_y is None else half_y
    top = net.x[net.top]
    c = 0.5 * (top.min(axis=0) + top.max(axis=0))
    near = ((np.abs(top[:, 0] - c[0]) <= half + 1e-9)
            & (np.abs(top[:, 1] - c[1]) <= half_y + 1e-9))
    return net.top[near]


def pressure_loads(net, load: float, half: float = FEET_HALF) -> np.ndarray:
    """(n,) N downward on each top point: ``load`` (N) as a uniform pressure over the square
    of side 2 ``half`` (m) at the top's centre, each point taking the pressure on its share
    of the square (its tributary cell, half a spacing either side, within the top), so the
    same load reaches the mat at any resolution."""
    top = net.x[net.top]
    lo, hi = top.min(axis=0), top.max(axis=0)
    c = 0.5 * (lo + hi)
    share = np.ones(len(top))
    for axis in (0, 1):
        u = np.unique(np.round(top[:, axis], 9))
        spacing = (u[-1] - u[0]) / (len(u) - 1)
        a = np.clip(top[:, axis] - 0.5 * spacing, lo[axis], hi[axis])
        b = np.clip(top[:, axis] + 0.5 * spacing, lo[axis], hi[axis])
        share *= np.clip(np.minimum(b, c[axis] + half) - np.maximum(a, c[axis] - half), 0.0, None)
    f = np.zeros(len(net.x))
    f[net.top] = load * share / share.sum()
    return f


def press(net, load: float, half: float = FEET_HALF, seconds: float = 0.4,
          damping: float = 100.0, h: float = 1e-2) -> float:
    """Settle the mat ``net`` on a rigid floor (its bottom layer held) under a downward load
    (N) as a uniform pressure over the square of side 2 ``half`` (m) at the centre (two feet
    side by side; ``pressure_loads``), by heavily damped backward-Euler steps; returns the
    depression (m) of the top's lowest point below its rest height. Leaves the network at
    that rest, unloaded."""
    f = pressure_loads(net, load, half)
    saved, fixed = net.fext.copy(), net.fixed.copy()
    net.fixed[net.bottom] = True
    net.fext[:] = 0.0

    def ramp(k, n):
        # the load ramps up over the first half: a sudden load would throw the top
        # layer past where it rests (a lattice can snap through; the foam would not)
        net.fext[:, 2] = -f * min(1.0, 2.0 * (k + 1) / n)
    relax(net, seconds, h, damping, 4000, ramp)
    net.fext[:] = saved
    net.fixed[:] = fixed
    return float(net.rest_height - net.x[net.top, 2].min())


def press_flat(net, depth: float, half: float = FEET_HALF, seconds: float = 0.4,
               damping: float = 100.0, h: float = 1e-2) -> float:
    """Press the top points within ``half`` (m) of the centre ``depth`` (m) down as one rigid
    flat sole that does not slide (held: two feet's soles, the impactor's base), the rest of
    the mat relaxed by damped backward Euler, bottom layer held; returns the load (N) the
    sole carries then (the springs' push on the held points less their weight). Leaves the
    network at rest, unloaded."""
    sel = pressed_points(net, half)
    return float(held_sole(net, sel, depth, (0.0, 0.0), seconds, damping, h)[:, 2].sum())


def held_sole(net, sel, depth: float, shift=(0.0, 0.0), seconds: float = 0.4,
              damping: float = 100.0, h: float = 1e-2) -> np.ndarray:
    """(len(sel),3) N: the forces the top points ``sel`` carry, held as one rigid flat sole
    that does not slide, lowered ``depth`` m and moved ``shift`` (x, y) m, the rest of the mat
    relaxed by damped backward Euler, bottom layer held (the springs' push on the held points
    less their weight). Leaves the network at rest, unloaded."""
    x0, fixed = net.x.copy(), net.fixed.copy()
    net.fixed[net.bottom] = True
    net.fixed[sel] = True

    def lower(k, n):
        # lowered over the first half, as ``press`` ramps its load (no snap-through)
        s = min(1.0, 2.0 * (k + 1) / n)
        net.x[sel, 2] = x0[sel, 2] - depth * s
        net.x[sel, 0] = x0[sel, 0] + shift[0] * s
        net.x[sel, 1] = x0[sel, 1] + shift[1] * s
    relax(net, seconds, h, damping, 4000, lower)
    f = net.internal_forces()[sel]
    net.x[:], net.fixed[:] = x0, fixed
    return f


def fit_stick(params: "MatSceneParams", standin: BedSpringsParams, shift: float = 0.005) -> dict:
    """The stand-in's tangential springs (``BedSpringsParams.stick``): the mat's sideways
    stiffness under one of her soles (her foot's box, its top points held flat at the depth
    where the stand-in's curve carries her standing weight, moved ``shift`` m along x and
    along y: the mean of the two) over the four corners by which the stand-in holds a flat
    box; their damping the foam's retardation time times that (kd = tau k, as the lattice's
    foam springs). Returns the fit and what it was fitted to."""
    from scipy.optimize import brentq
    fig = gymnast(params.vault, floor=params.mat.thickness)
    view = fig.contact_view()
    weight = float(np.sum(view.masses)) * 9.81
    foot = view.primitives[SEGMENTS.index("l_foot")].axes
    full = standin.force(params.mat.thickness)
    if full < weight:
        raise SceneError(f"mat: the stand-in's curve carries {full:.0f} N at the mat's full "
                         f"thickness ({params.mat.thickness:g} m), less than "
                         f"her standing weight {weight:.0f} N: the mat is too soft to stand on; "
                         "stiffen it (mat.modulus, mat.cover) or thicken it (mat.thickness)")
    depth = brentq(lambda d: standin.force(d) - weight, 0.0, params.mat.thickness)
    net = mat_network(params.mat, "implicit")
    sel = pressed_points(net, foot[0], foot[1])
    k = [-held_sole(net, sel, depth, s)[:, axis].sum() / shift
         for axis, s in ((0, (shift, 0.0)), (1, (0.0, shift)))]
    stick = float(np.mean(k)) / 4.0
    return {"stick": stick, "stick_damping": params.mat.foam_damping * stick,
            "sole_points": int(len(sel)), "standing_depth_m": float(depth),
            "sole_shear_N_per_m": [float(v) for v in k]}


def load_deflection(p: MatParams, depths) -> np.ndarray:
    """(load N, depression m) rows of the mat pressed by a rigid flat sole to each depth
    (``press_flat``), each from rest."""
    return np.array([(press_flat(mat_network(p, "implicit"), d), d) for d in depths])


def fit_damping(standin: BedSpringsParams, mat_rows, impactor=None) -> tuple:
    """The stand-in's damping (N s/m) whose impactor drops (``mat_impact.standin_drop``)
    best reproduce the mat's (``mat_rows``, from ``drop_test``): least squares over the drops
    of the relative errors of the peak force (1 ms mean) and of the rebound speed. Returns
    (damping, the stand-in's rows)."""
    from scipy.optimize import minimize_scalar
    from .mat_impact import Impactor, standin_drop
    impactor = impactor or Impactor()
    drops = [r["drop_m"] for r in mat_rows]

    def rows(c):
        return standin_drop(replace(standin, damping=c), drops, impactor)

    def loss(c):
        return sum(((s["peak_mean_force_N"] - m["peak_mean_force_N"]) / m["peak_mean_force_N"])
                   ** 2 + ((s["rebound_m_s"] - m["rebound_m_s"]) / m["rebound_m_s"]) ** 2
                   for s, m in zip(rows(c), mat_rows))
    c = float(minimize_scalar(loss, bounds=(0.0, 5000.0), method="bounded",
                              options={"xatol": 1.0}).x)
    return c, rows(c)


def fit(spec, params: MatSceneParams, **build_kw) -> dict:
    """``interplay fit-standin mat``: the stand-in's curve fitted (non-negative least squares of
    the relative errors) to the mat's load-deflection under a rigid flat sole over the
    landing's range (FIT_DEPTHS),
    then its damping to the mat's impactor drops (FIT_DROPS: peak force and rebound,
    ``fit_damping``); the report gives both fits' largest relative errors."""
    from .mat_impact import drop_test
    from scipy.optimize import nnls
    rows = load_deflection(params.mat, FIT_DEPTHS)
    # non-negative coefficients: the curve must rise over all depths (BedSpringsParams
    # checks 0-1.5 m), and an unconstrained cubic through a 0-0.1 m press turns down past
    # it (measured: c = -4e5 N/m^3, falling from 0.6 m); the mat's secant stiffness rises
    # with depth, so a, b, c >= 0 fits it (the report gives the error). Each depth is
    # weighted by 1 / its load, so it is the relative error that is least squares (the
    # stand-in's bar is relative: absolute least squares left 13% at 0.005 m, 4% at most so)
    d = rows[:, 1]
    basis = np.stack([d, d * d, d ** 3], axis=1)
    a, b, c = (float(v) for v in nnls(basis / rows[:, :1], np.ones(len(d)))[0])
    sp = replace(params.standin, linear=a, quadratic=b, cubic=c)
    model = sp.force(rows[:, 1])
    err = np.abs(model - rows[:, 0]) / rows[:, 0]
    mat_drops = drop_test(params.mat, FIT_DROPS)
    damping, standin_drops = fit_damping(sp, mat_drops)
    shear = fit_stick(params, sp)

    def rel(key):
        return max(abs(s[key] - m[key]) / m[key] for s, m in zip(standin_drops, mat_drops))
    fitted = {"linear": a, "quadratic": b, "cubic": c, "damping": damping,
              "stick": shear.pop("stick"), "stick_damping": shear.pop("stick_damping")}
    return {"fit": fitted, "loads_N": rows[:, 0].tolist(), "depressions_m": rows[:, 1].tolist(),
            "fitted_N": model.tolist(), "max_error_rel": float(err.max()), "shear": shear,
            "drops": {"mat": mat_drops, "standin": standin_drops,
                      "peak_error_rel": rel("peak_mean_force_N"),
                      "rebound_error_rel": rel("rebound_m_s")},
            "sets": [f"standin.{k}={v:.6g}" for k, v in fitted.items()]}


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
    searches=(landing_search.LANDING, landing_search.MARGIN),
    debug_ratio=5.0, contrast=contrast,
    # heavy: each trial of its search flies the whole landing twice (seconds)
    camera=Camera((1.9, -6.8, 2.0), (1.9, 0.0, 1.0), 45.0), key_time=0.83, heavy=True)
