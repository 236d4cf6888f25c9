"""Diagnostic of the trampoline's stance chatter (issue 15): the horizontal contact force under
the gymnast's feet, at every 1 ms coupling step. Prints a table and writes JSON; nothing passes
or fails.

Runs the default two-way scene (or one with ``--set KEY=VALUE`` overrides, the CLI's keys) for
``--duration`` s through the Python API and records, at every coupling step, the contact's mean
force on each of her segments (``PartContact.segment_forces``) and her pitch angular momentum
about her centre of mass. Per stance (a run of steps with any segment on the bed): the
horizontal force's rms on the feet (feet and toes) and on the rest, its spectrum's main peaks
(1 kHz sampling: up to 500 Hz, unaliased by the 5 ms control ticks), the vertical force's mean,
and L at touchdown, its range, and at takeoff (the first step in the air after).

With ``--box``, instead of the gymnast a foot-sized box pressed into the bed by 1000 N, free
and uncontrolled, on the same bed through the same contact (``planted_box``): the contact and
bed alone. With ``--tilt N_M ...`` the same box with each pitch torque (an ankle pressing the
forefoot in): how far a foot tilts on the bed under an ankle's torque, and at what torque it
capsizes onto its edge (``--load N ...``: the loads).

    PYTHONPATH=src python benchmarks/tramp_chatter.py [--duration 2.5] [--set KEY=VALUE ...]
        [--strap-damping N_S_PER_M] [--sole N_PER_M N_S_PER_M] [--box] [--tilt N_M ...] [--load N ...]
        [--out out/chatter.json]
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

from interplay.geometry.anthropometry import SEGMENTS
from interplay.geometry.trampoline import build_bed
from interplay.interactions.part_contact import PartContact
from interplay.kernels.contact import DAMPING, STIFFNESS
from interplay.kernels.rigid import quat_to_matrix
from interplay.params import apply
from interplay.scenes import trampoline as T

FEET = [SEGMENTS.index(s) for s in ("l_foot", "r_foot", "l_toes", "r_toes")]


def record(params, duration: float, strap_damping: float = 0.0, sole=None):
    """Run the two-way scene; per coupling step: time (s), forces (k,3) N on each segment, and
    the pitch angular momentum (kg m^2/s, > 0 forward) about the centre of mass, and the
    soles' mean pitch (rad, > 0 heel up: the foot rolled onto its front edge).
    strap_damping (N s/m): added to each of the bed's straps' own damping (the weave's
    in-plane damping); sole: (stiffness N/m, damping N s/m) of the contact law on the feet and
    toes (per touch) instead of the per-contact default."""
    import mujoco
    scene = T.build("two-way", duration=duration, params=params)
    contact = next(it for it in scene.interactions if isinstance(it, PartContact))
    fig = scene.primary
    if strap_damping:
        net = contact.secondary
        kind = build_bed(params.bed).kind
        net.kd[kind == 0] += strap_damping
        net.check_step(net.dt)
    if sole is not None:
        feet = np.isin(contact.owner, FEET)
        contact.parts.law[feet, STIFFNESS] = sole[0]
        contact.parts.law[feet, DAMPING] = sole[1]
    rows = []
    complete, exchange = contact.complete, contact.exchange

    soles = fig.seg_body[[SEGMENTS.index(s) for s in ("l_foot", "r_foot")]]

    def log(forces):
        mujoco.mj_subtreeVel(fig.model, fig.data)
        fwd, left = fig.heading_axes()
        up = fig.data.xmat[soles].reshape(-1, 3, 3)[:, :, 2].mean(axis=0)  # the soles' normal
        rows.append((fig.time, forces, float(fig.data.subtree_angmom[fig.root] @ left),
                     float(np.arctan2(-(up @ fwd), up[2]))))

    def logged(to_primary):
        out = complete(to_primary)
        log(contact.segment_forces().copy())
        return out

    def exchanged(to_primary, to_secondary):
        out = exchange(to_primary, to_secondary)
        if out is not None and len(out) == 3:  # nothing within reach: no contact this step
            log(np.zeros((fig.contact_view().count, 3)))
        return out

    contact.complete, contact.exchange = logged, exchanged
    scene.simulate(force=True)
    t = np.array([r[0] for r in rows])
    f = np.array([r[1] for r in rows])
    L = np.array([r[2] for r in rows])
    pitch = np.array([r[3] for r in rows])
    return t, f, L, pitch


def peaks(x, dt: float, n: int = 3):
    """The ``n`` strongest spectral peaks (Hz, amplitude N) of x sampled at dt (s), Hann
    windowed. Over a 0.46 s stance the bins are 2.2 Hz apart, so the strongest is usually the
    stance's own slow swing at the lowest bins; the next ones are the oscillations in it."""
    x = x - x.mean()
    w = np.hanning(len(x))
    spec = np.abs(np.fft.rfft(x * w)) * 2.0 / max(w.sum(), 1.0)
    freq = np.fft.rfftfreq(len(x), dt)
    local = [i for i in range(1, len(spec) - 1)
             if spec[i] >= spec[i - 1] and spec[i] >= spec[i + 1]]
    local.sort(key=lambda i: -spec[i])
    return [[round(float(freq[i]), 1), round(float(spec[i]), 1)] for i in local[:n]]


#: rad: soles pitched past this are on their front edges (the thrust's plantarflexion)
ROLLED = 0.1


def rms_where(x, sel):
    """rms (N) of x about its mean where sel, or None."""
    return round(float(np.std(x[sel])), 1) if sel.sum() > 1 else None


def stances(t, f, L, pitch, dt: float) -> list[dict]:
    on = np.abs(f).sum(axis=(1, 2)) > 0.0
    edges = np.flatnonzero(np.diff(np.r_[0, on.astype(int), 0]))
    out = []
    for a, b in zip(edges[::2], edges[1::2]):
        if b - a < 50:  # a graze, not a stance
            continue
        b = min(b, len(t) - 1)  # the first step in the air after it (or the run's last)
        feet = f[a:b][:, FEET].sum(axis=1)
        rest = f[a:b].sum(axis=1) - feet
        hx, hy = feet[:, 0], feet[:, 1]
        out.append({
            "t0": round(float(t[a]), 3), "t1": round(float(t[b - 1]), 3),
            "feet_horizontal_rms_N": round(float(np.sqrt(np.mean(hx ** 2 + hy ** 2))), 1),
            "feet_fx_mean_N": round(float(hx.mean()), 1),
            "feet_fx_rms_N": round(float(np.sqrt(np.mean((hx - hx.mean()) ** 2))), 1),
            "feet_fx_rms_flat_N": rms_where(hx, np.abs(pitch[a:b]) < ROLLED),
            "feet_fx_rms_rolled_N": rms_where(hx, np.abs(pitch[a:b]) >= ROLLED),
            "sole_pitch_max": round(float(np.abs(pitch[a:b]).max()), 3),
            "rest_horizontal_rms_N": round(float(np.sqrt(np.mean(rest[:, 0] ** 2
                                                               + rest[:, 1] ** 2))), 1),
            "vertical_mean_N": round(float(f[a:b, :, 2].sum(axis=1).mean()), 1),
            "fx_peaks_Hz_N": peaks(hx, dt),
            "L_touchdown": round(float(L[a]), 3),
            "L_min": round(float(L[a:b].min()), 3), "L_max": round(float(L[a:b].max()), 3),
            "L_takeoff": round(float(L[b]), 3)})
    return out


def planted_box(params, load: float = 1000.0, mass: float = 10.0, seconds: float = 3.0,
                torque: float = 0.0) -> dict:
    """A foot-sized box (the figure's foot: 0.25 x 0.094 x 0.06 m) of ``mass`` (kg) pressed
    into the bed by ``load`` (N, as its weight: gravity load / mass, so the contact's
    constraint term sees it), free in all six degrees of freedom, through the same contact
    (``params.contact``) on the same bed (``params.bed``), stepped at ``params.coupling_dt``:
    no controller, no figure. ``torque`` (N m) about the box's width (toes down: an ankle's
    plantarflexion pressing the forefoot in) is ramped in over the first second. Returns the
    contact force's horizontal rms (N, about its mean, along the box's length x and across it
    y) and the box's tilt (rad, mean and rms over the second half of the run: past a few
    tenths of a radian the box has capsized onto its edge) and depth below the bed's top
    (m)."""
    from interplay.geometry.primitive import Primitive
    from interplay.systems.colliders import box_surface
    from interplay.systems.rigid import RigidBody
    h = params.coupling_dt
    net = T.bed(params.bed)
    half = np.array([0.125, 0.047, 0.03])
    inertia = mass / 3.0 * np.array([half[1] ** 2 + half[2] ** 2, half[0] ** 2 + half[2] ** 2,
                                     half[0] ** 2 + half[1] ** 2])
    top = net.x[:net.bed_points, 2].max()
    box = RigidBody("foot", mass, inertia, h, position=(0.0, 0.0, top + half[2] + 0.02),
                    surface=box_surface(half), primitive=Primitive("box", axes=tuple(half)),
                    gravity=(0.0, 0.0, -load / mass))
    contact = PartContact("foot-bed", box, net, params.contact)
    contact.prepare(h)
    n = int(round(seconds / h))
    f = np.zeros((n, 3))
    tilt = np.zeros(n)
    for k in range(n):
        box.clear_forces()
        net.clear_forces()
        box.add_wrench(np.zeros(3), torque=(0.0, torque * min(1.0, k * h), 0.0))
        res = contact.exchange(True, True)
        net.advance(h, net.dt)
        if res is None:
            res = contact.complete(True)
        box.advance(h)
        f[k] = res[0]
        R = quat_to_matrix(box.q)
        tilt[k] = np.arctan2(-R[2, 0], R[0, 0])  # > 0: the box's +x end down
    late = f[n // 2:]
    return {"load_N": load, "mass_kg": mass, "torque_N_m": torque,
            "vertical_mean_N": round(float(late[:, 2].mean()), 1),
            "fx_rms_N": round(float(late[:, 0].std()), 1),
            "fy_rms_N": round(float(late[:, 1].std()), 1),
            "tilt_mean_rad": round(float(tilt[n // 2:].mean()), 4),
            "tilt_rms_rad": round(float(tilt[n // 2:].std()), 4),
            "depth_m": round(float(top - box.x[2]), 3)}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--duration", type=float, default=2.5)
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    ap.add_argument("--strap-damping", type=float, default=0.0, metavar="N_S_PER_M")
    ap.add_argument("--sole", type=float, nargs=2, metavar=("N_PER_M", "N_S_PER_M"))
    ap.add_argument("--box", action="store_true",
                    help="a loaded foot-sized box on the bed instead of the gymnast")
    ap.add_argument("--tilt", type=float, nargs="+", metavar="N_M",
                    help="the loaded box with these pitch torques: its tilt on the bed")
    ap.add_argument("--load", type=float, nargs="+", default=[1000.0], metavar="N",
                    help="the box's loads (N), with --box or --tilt")
    ap.add_argument("--out", type=Path)
    a = ap.parse_args(argv)
    sets = dict(s.split("=", 1) for s in a.set)
    params = apply(T.TrampolineParams(), sets)
    if a.box or a.tilt:
        runs = [planted_box(params, load, torque=tq) for load in a.load
                for tq in (a.tilt or [0.0])]
        res = {"sets": sets, "box": runs}
        for r in runs:
            print(r)
        if a.out:
            a.out.parent.mkdir(parents=True, exist_ok=True)
            a.out.write_text(json.dumps(res, indent=1))
        return res
    t, f, L, pitch = record(params, a.duration, a.strap_damping, a.sole)
    res = {"sets": sets, "strap_damping": a.strap_damping, "sole": a.sole,
           "duration_s": a.duration,
           "stances": stances(t, f, L, pitch, params.coupling_dt)}
    for s in res["stances"]:
        print(f"{s['t0']:.3f}-{s['t1']:.3f} s: feet horizontal {s['feet_horizontal_rms_N']} N rms "
              f"(fx mean {s['feet_fx_mean_N']}; fx rms flat {s['feet_fx_rms_flat_N']}, rolled "
              f"{s['feet_fx_rms_rolled_N']}), rest {s['rest_horizontal_rms_N']} N, vertical "
              f"mean {s['vertical_mean_N']} N, fx peaks {s['fx_peaks_Hz_N']}, L "
              f"{s['L_touchdown']} [{s['L_min']}, {s['L_max']}] -> {s['L_takeoff']}")
    if a.out:
        a.out.parent.mkdir(parents=True, exist_ok=True)
        a.out.write_text(json.dumps(res, indent=1))
    return res


if __name__ == "__main__":
    sys.exit(0 if main() else 1)
