"""The landing mat's impact test (issue 17): a rigid flat impactor dropped on the mat.

Pain, Mills & Yeadon (2005, Med. Sci. Sports Exerc. 37: 1754-1760) and Mills, Pain & Yeadon
(2006, J. Appl. Biomech. 22: 103-111) dropped a 24 kg impactor "from various heights" onto a
competition landing mat over a force plate and measured its largest vertical deformation,
0.088-0.118 m over their drops. The drop heights themselves were not in the texts available
to us (docs/mat.md says so), so ``drop_test`` drops the impactor from a range of heights and
reports, per height, the mat's largest depression (the impactor's flat base below the mat's
rest top: the lowest point of the top face under it), the peak force on the impactor (its
momentum's rate, from the contact's force log) and the rebound; the heights whose depression
falls in the published band are the comparison.

The impactor is a rigid box (``Impactor``: 24 kg, a flat square base, level), coupled with
the mat two-way through the same rigid-parts contact her feet use (sub-cycled in the mat's
substeps), so the test measures the very mat and contact the landing runs on.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..geometry.mat import MatParams
from ..geometry.primitive import Primitive
from ..interactions.part_contact import PartContact, PartContactParams
from ..params import param
from ..scene import Scene
from ..systems.rigid import RigidBody

#: the published band of the largest deformation under the 24 kg impactor (m)
PUBLISHED = (0.088, 0.118)


@dataclass(frozen=True)
class Impactor:
    """mass (kg): Pain et al.'s 24 kg; side (m) of its flat square base and height (m) of the
    block (a steel block of that mass and base; the size is our choice: the papers' base was
    not in the texts available to us)."""
    mass: float = param(24.0, "kg", gt=0.0, le=1e4)
    side: float = param(0.25, "m", gt=0.0, le=2.0)
    height: float = param(0.05, "m", gt=0.0, le=2.0)


def impactor_body(p: Impactor, drop: float, top: float, centre) -> RigidBody:
    """The impactor at rest ``drop`` m above the mat's top (``top`` m), its base centred over
    ``centre`` (x, y), moving at the free-fall speed of that drop, sqrt(2 g drop), so that it
    meets the mat at once (the fall is not simulated)."""
    a, h = 0.5 * p.side, 0.5 * p.height
    inertia = p.mass / 3.0 * np.array([a * a + h * h, a * a + h * h, 2 * a * a])
    v = -np.sqrt(2.0 * 9.81 * drop)
    body = RigidBody("impactor", p.mass, inertia, 1e-3,
                     position=(centre[0], centre[1], top + h + 1e-3), velocity=(0, 0, v),
                     primitive=Primitive("box", axes=(a, a, h)))
    return body


def drop_test(mat: MatParams = MatParams(), drops=(0.5, 1.0, 1.5, 2.0),
              impactor: Impactor = Impactor(), seconds: float = 0.25,
              contact: PartContactParams = PartContactParams(friction=1.0),
              integrator: str = "explicit", dt: float | None = None) -> list[dict]:
    """Drop ``impactor`` on the mat (at its centre) from each height in ``drops`` (m above
    its top); per drop: impact speed (m/s), the largest depression (m) of the mat's top under
    the base, the peak force (N) of the contact on the impactor (its largest substep force)
    and the mean force's peak (N, over 1 ms), the time to the deepest point (s) and the
    rebound speed (m/s, the impactor's upward speed when it leaves the mat, 0 if it has not
    left it by ``seconds``). integrator, dt (s): the mat's (default: the scene's explicit
    step)."""
    from .mat import mat_network
    out = []
    x0, x1, y0, y1 = mat.footprint()
    centre = (0.5 * (x0 + x1), 0.5 * (y0 + y1))
    for drop in drops:
        scene = Scene("mat-impact", duration=seconds, fps=1000.0, coupling_dt=1e-3)
        net = scene.add(mat_network(mat, integrator, dt))
        body = scene.add(impactor_body(impactor, drop, mat.thickness, centre))
        scene.connect(PartContact("impactor-mat", body, net, contact, mode="two-way",
                                  elements=net.top_edges))
        scene.primary = body
        res = scene.simulate()
        tr = res.tracks["impactor"]
        base = tr.x[:, 2] - 0.5 * impactor.height  # the base's height, m (1 ms samples)
        log = res.logs["impactor-mat"]
        k = int(np.argmin(base))
        # the log's step i ends at the track's sample i + 1 (the track starts at t = 0)
        free = np.r_[False, ~log.active[:len(base) - 1]]
        left = np.flatnonzero((np.arange(len(base)) > k) & free)
        out.append({"drop_m": float(drop), "impact_speed_m_s": float(np.sqrt(2 * 9.81 * drop)),
                    "depression_m": float(mat.thickness + contact.thickness - base[k]),
                    "peak_force_N": float(log.peak.max()),
                    "peak_mean_force_N": float(np.linalg.norm(log.force, axis=1).max()),
                    "time_to_deepest_s": float(tr.t[k] - tr.t[0]),
                    "rebound_m_s": float(tr.xdot[left[0], 2]) if len(left) else 0.0})
    return out


def standin_drop(standin, drops=(0.5, 1.0, 1.5, 2.0), impactor: Impactor = Impactor(),
                 h: float = 1e-5) -> list[dict]:
    """The same drops on the hybrid stand-in (``BedSpringsParams``): the impactor level on
    its vertical spring-damper, F = curve(D) + damping dD/dt >= 0 (bed_springs.BedSprings's
    law: a level base's corners share one depression, so the 1-D motion is exact), by
    symplectic Euler at h (s; 1e-5 resolves the ~40 ms contact to 1e-4 of its energy).
    Per drop: impact speed (m/s), the largest depression (m), the peak force (N), the time to
    the deepest point (s) and the rebound speed (m/s), as ``drop_test`` reports them."""
    m, out = impactor.mass, []
    for drop in drops:
        v0 = float(np.sqrt(2.0 * 9.81 * drop))
        d, v, t, peak, deepest, t_deep = 0.0, v0, 0.0, 0.0, 0.0, 0.0
        while d >= 0.0 and t < 1.0:  # v: downward speed (m/s), d: depression (m)
            f = max(standin.force(d) + standin.damping * v, 0.0)
            v += h * (9.81 - f / m)
            d += h * v
            t += h
            peak = max(peak, f)
            if d > deepest:
                deepest, t_deep = d, t
        out.append({"drop_m": float(drop), "impact_speed_m_s": v0, "depression_m": deepest,
                    "peak_mean_force_N": peak, "time_to_deepest_s": t_deep,
                    "rebound_m_s": max(-v, 0.0)})
    return out
