"""What a landing run shows (the floor-mat scene, issue 17), measured from the Result alone.

Her vertical load is measured the same way in every coupling and on the rigid floor: her
recorded motion (the track, one sample per coupling step) is replayed through a copy of her
model and the ground's push is F = dp/dt + m g, p her momentum (N; in the air it is zero but
for the air's drag). Peak force, and the loading rate as the steepest rise over LOAD_WINDOW
before the peak. The mat's depression is its top's lowest point below its rest height; the
replay's penetration is how far the lowest corners of her feet went below the mat's
deformed top surface (interpolated over its top points) at the output frames; the stick is
read from the output frames (upright, still over the feet within 1 s, no step) and her
feet's corners (no hop).
"""
from __future__ import annotations

import numpy as np

from ..control.landing import VaultParams, gymnast
from ..geometry.anthropometry import SEGMENTS
from ..interactions.bed_springs import support_points

G = 9.81
LOAD_WINDOW = 0.005  # s: the loading rate's rise is measured over this (a 1 ms step is noise)
FEET = [SEGMENTS.index(s) for s in ("l_foot", "r_foot", "l_toes", "r_toes")]
SOLES = [SEGMENTS.index(s) for s in ("l_foot", "r_foot")]
STICK = {"speed": 0.15, "lead": 0.12, "tilt": 0.35, "moved": 0.05}  # m/s, m, rad, m
HOP = 0.01  # m: feet rising more than this after touch-down left the mat (its rebound is mm)


def _replica(meta):
    """Her model (no controller runs: states are imposed) built from the run's meta."""
    return gymnast(VaultParams(**meta["vault"]), floor=None)


def vertical_load(result):
    """(t s, F_z N): the ground's (or the mat's, or the stand-in's) vertical push on her,
    from her track: F = dp/dt + m g, p her momentum."""
    tr = result.tracks.get("gymnast")
    if tr is None or len(tr.t) < 3:
        return None
    fig = _replica(result.meta)
    pz = np.empty(len(tr.t))
    for k in range(len(tr.t)):
        fig.set_generalized_state(tr.x[k], tr.xdot[k])
        pz[k] = fig.momentum()[2]
    t = tr.t
    f = np.gradient(pz, t) + fig.mass * G
    return t, f


def load_figures(t, f, weight) -> dict:
    k = int(np.argmax(f))
    dt = float(np.median(np.diff(t)))
    w = max(1, int(round(LOAD_WINDOW / dt)))
    rate = (f[w:k + 1] - f[:k + 1 - w]) / (t[w:k + 1] - t[:k + 1 - w]) if k >= w else None
    return {"peak vertical force (N)": float(f[k]),
            "peak vertical force (body weights)": float(f[k] / weight),
            "time of peak force (s)": float(t[k]),
            "peak loading rate (N/s)": float(rate.max()) if rate is not None and len(rate)
            else None}


def feet_corners(result, times):
    """(len(times), m, 3) world positions of the corners of her feet's boxes (soles, toes)
    at the given times, from her track."""
    fig = _replica(result.meta)
    view = fig.contact_view()
    local, part = [], []
    for j in FEET:
        q, _ = support_points(view.primitives[j])
        local.append(q)
        part.append(np.full(len(q), j))
    local, part = np.concatenate(local), np.concatenate(part)
    out = np.empty((len(times), len(local), 3))
    tr = result.tracks["gymnast"]
    for k, t in enumerate(times):
        x, xd = tr.sample(float(t))
        fig.set_generalized_state(x, xd)
        origin, R = view.poses()
        out[k] = np.einsum("kij,kj->ki", R[part], local) + origin[part]
    return out


def penetration(result) -> float | None:
    """(m) the deepest her replayed feet went below the mat's deformed top (one-way replay
    and two-way alike: positive means through it), over the output frames."""
    from scipy.interpolate import LinearNDInterpolator
    net = result.frames.get("mat")
    if net is None:
        return None
    nx, ny, nz = result.meta["lattice"]
    top = np.arange(nx * ny) * nz + nz - 1
    times = net["t"]
    corners = feet_corners(result, times)
    worst = -np.inf
    for k in range(len(times)):
        pts = net["points"][k][top]
        c = corners[k]
        near = c[:, 2] < pts[:, 2].max() + 0.02
        if not near.any():
            continue
        surf = LinearNDInterpolator(pts[:, :2], pts[:, 2])(c[near, :2])
        ok = np.isfinite(surf)
        if ok.any():
            worst = max(worst, float(np.max(surf[ok] - c[near][ok, 2])))
    return None if worst == -np.inf else worst


def stuck(fr) -> dict:
    """From the output frames: touch-down (s: the first frame an ankle is within 3 cm of its
    height at the end, standing), then how far the soles moved (m) from 0.15 s after it (a step
    or a slide), and from 1 s after it to the run's end the centre of mass's largest
    horizontal speed (m/s), its largest distance from over the middle of the soles (m) and the
    pelvis's largest tilt (rad): "balanced within 1 s"; stuck when all are within STICK."""
    t, com, seg = fr["t"], fr["com"], fr["segment_positions"]
    low = seg[:, SOLES, 2].min(axis=1)
    # the ankles come within 3 cm of where they stand at the end (or lowest, if lower)
    k0 = int(np.flatnonzero(low <= min(low[-1], low.min() + 0.03) + 0.03)[0])
    td = float(t[k0])
    out = {"touch-down (s)": td}
    after = t - td
    settle = np.flatnonzero(after >= 0.15)
    win = np.flatnonzero(after >= 1.0)  # balanced within 1 s: from then to the run's end
    if not len(settle) or len(win) < 2:
        return out
    feet = seg[:, SOLES, :2]
    moved = float(np.abs(feet[settle] - feet[settle[0]]).max())
    v = np.gradient(com, t, axis=0)
    speed = float(np.hypot(v[win, 0], v[win, 1]).max())
    mid = feet[win].mean(axis=1)
    lead = float(np.hypot(*(com[win, :2] - mid).T).max())
    q = fr["segment_orientations"][win, 0]  # the pelvis (w, x, y, z)
    upz = 1.0 - 2.0 * (q[:, 1] ** 2 + q[:, 2] ** 2)
    tilt = float(np.arccos(np.clip(upz.min(), -1.0, 1.0)))
    out.update({"feet moved after touch-down (m)": moved,
                "speed from 1 s after touch-down (m/s)": speed,
                "centre of mass off the feet (m)": lead, "pelvis tilt (rad)": tilt,
                "stuck": bool(speed < STICK["speed"] and lead < STICK["lead"]
                              and tilt < STICK["tilt"] and moved < STICK["moved"])})
    return out


def hop(t, lowest, touch_down: float) -> float:
    """(m) how high her feet's lowest corner rose, from 0.15 s after touch-down (s), above
    where it is at the end (standing): she left the mat (a heel lifting alone leaves the
    toes' corners down). ``stuck``'s measures are horizontal and do not see it."""
    after = np.asarray(t) - touch_down >= 0.15
    return float((lowest[after] - lowest[-1]).max()) if after.any() else 0.0


HOP_KEY = "feet's lowest corner rise after touch-down (m)"


def stick(result) -> dict:
    """``stuck``'s measures from her frames and the hop (``hop``, m); "balanced" is
    ``stuck``'s verdict on the horizontal measures, "stuck" that and no hop past HOP."""
    fr = result.frames["gymnast"]
    out = stuck(fr)
    if "feet moved after touch-down (m)" in out:
        lowest = feet_corners(result, fr["t"])[:, :, 2].min(axis=1)
        out[HOP_KEY] = hop(fr["t"], lowest, out["touch-down (s)"])
        out["balanced"] = out["stuck"]
        out["stuck"] = bool(out["balanced"] and out[HOP_KEY] <= HOP)
    return out


def landing_figures(result) -> dict:
    """The scene's key figures (summary.json, compare's table)."""
    fr = result.frames.get("gymnast")
    if fr is None:
        return {}
    meta = result.meta
    out = {}
    load = vertical_load(result)
    if load is not None:
        out.update(load_figures(*load, VaultParams(**meta["vault"]).mass * G))
    net = result.frames.get("mat")
    if net is not None:
        nx, ny, nz = meta["lattice"]
        top = np.arange(nx * ny) * nz + nz - 1
        out["mat depression (m)"] = float(meta["mat_top"] - net["points"][:, top, 2].min())
        out["feet below the mat's top (m)"] = penetration(result)
    out.update(stick(result))
    out["warnings"] = []
    if out.get("feet below the mat's top (m)") is not None and \
            out["feet below the mat's top (m)"] > 0.01:
        out["warnings"].append(
            f"her replayed feet went {out['feet below the mat' + chr(39) + 's top (m)']:.3f} m "
            "into the mat (one-way replay: the mat cannot push back on recorded motion)")
    if "stuck" in out and not out["stuck"]:
        out["warnings"].append("she did not stick the landing (see the stick figures)")
    if out.get("balanced") and out[HOP_KEY] > HOP:  # a fall is its own story
        out["warnings"].append(f"she hopped: her feet left the mat by {out[HOP_KEY]:.3f} m "
                               "after touch-down")
    return out


def contrast(results: dict) -> dict:
    """Across couplings (``compare``): the hybrid and one-way centre-of-mass paths against
    two-way's (largest distance, m, over the output frames) and the peak forces' ratio."""
    ref = results.get("two-way")
    if ref is None or "gymnast" not in ref.frames:
        return {}
    out = {}
    c0 = ref.frames["gymnast"]["com"]
    f0 = landing_figures(ref).get("peak vertical force (N)")
    for mode, r in results.items():
        if mode == "two-way" or "gymnast" not in r.frames:
            continue
        c = r.frames["gymnast"]["com"]
        n = min(len(c), len(c0))
        out[f"{mode}: centre-of-mass path off two-way's (m)"] = float(
            np.linalg.norm(c[:n] - c0[:n], axis=1).max())
        f = landing_figures(r).get("peak vertical force (N)")
        if f and f0:
            out[f"{mode}: peak force over two-way's"] = float(f / f0)
    return out
