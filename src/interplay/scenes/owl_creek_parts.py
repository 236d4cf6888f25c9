"""The owl-creek scene's other pieces: the vest he wears, the drapes in the breeze behind him,
and the measures of the noose (its stretch against manila's range, how deep it pressed into him,
whether the loop held, and whether a one-way run let him fall through it)."""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..geometry import shapes
from ..geometry.anthropometry import SEGMENTS
from ..geometry.garment import FABRICS, Garment
from ..geometry.setpieces import merge, rod
from ..geometry.vest import CORNER, VestParams, vest_mesh
from ..interactions.aero import AeroParams, Aerodynamics
from ..interactions.part_contact import PartContact, PartContactParams
from ..outputs.geometry import quat_rotate
from ..params import param
from ..systems.colliders import StaticMesh
from ..systems.garments import spring_set
from ..systems.springmass import SpringNetwork
from .flags import FlagParams, GustyWind, wind_field

#: manila rope breaks at about 10-12 % elongation (docs/owl-creek.md): beyond it the rope
#: would have parted; a one-way run that stretches it further has let the figure through
MANILA_BREAK_STRAIN = 0.12


@dataclass(frozen=True)
class DrapeParams:
    """Cotton drapes on a rod along the bridge's side behind him: their centres (m along the
    bridge), the cloth (width along the bridge, height down; density, stiffness: the flags'
    cotton, heavier) and the breeze (across the bridge, out over the creek)."""
    enabled: bool = param(True, doc="false: no drapes")
    at: tuple = param((2.1, 3.6), "m", ge=-100.0, le=100.0, doc="centres along the bridge")
    cloth: FlagParams = FlagParams(width=1.2, height=1.7, nu=14, nv=20, density=0.3,
                                   stretch=150.0, shear=50.0, bend=0.5)  # curtain cotton
    wind: GustyWind = GustyWind(speed=1.5, heading=0.0, gust=0.6, gust_period=3.0, cross=0.5)
    top: float = param(2.3, "m", ge=0.1, le=10.0, doc="the rod above the deck")


#: the vest against his torso: a thin skin (the fabric's ~2 mm), wool on cloth friction
# the torso and pelvis boxes rounded as the vest's rings are cut round them (CORNER): a
# strap over a sharp shoulder edge was folded over it and thrown off it at the rope's jerk
VEST_CONTACT = PartContactParams(thickness=0.002, friction=0.5, contact_steps=3.0,
                                 rounding=CORNER)


def vest(scene, fig, p: VestParams, opens: float):
    """Dress the figure in the vest (geometry/vest.py), cut round his torso and pelvis boxes
    where they stand now, and connect it to all his parts (his arms brush it) by the
    rigid-parts contact in ``p.coupling``; its mass is the paper's, spread by area (an areal
    density of ~2.1 kg/m^2: a heavy lined vest with its buttons and pockets), its fabric's
    stiffness scaled by the same factor.
    Its measures: ``vest_figures``."""
    if not p.enabled:
        return None
    view = fig.contact_view()
    origin, R = view.poses()
    t, pv = SEGMENTS.index("torso"), SEGMENTS.index("pelvis")
    tp, pp = view.primitives[t], view.primitives[pv]
    pelvis_c = R[t].T @ (origin[pv] + R[pv] @ np.asarray(pp.centre) - origin[t])
    top = tp.centre[2] + tp.axes[2]
    x, tris = vest_mesh(p, (tp.centre, tp.axes), (pelvis_c, pp.axes), top)
    x = origin[t] + x @ R[t].T
    area = 0.5 * float(np.linalg.norm(np.cross(x[tris[:, 1]] - x[tris[:, 0]],
                                               x[tris[:, 2]] - x[tris[:, 0]]), axis=1).sum())
    f = FABRICS[p.fabric]
    scale = p.mass / area / f.density  # as stiff per kg/m^2 as its fabric
    cloth = replace(f, name=f"vest of {f.name}", density=p.mass / area,
                    tensile=scale * f.tensile, shear=scale * f.shear,
                    bending=scale * f.bending, thickness=VEST_CONTACT.thickness)
    springs, _, masses = spring_set(Garment("vest", x, tris, cloth))
    net = scene.add(SpringNetwork("vest", x, masses, springs, dt=p.dt, integrator="implicit",
                                  cg_tolerance=p.cg_tolerance, mass_damping=0.5,
                                  stiffness_damping=p.damping, triangles=tris,
                                  color=(0.36, 0.20, 0.12)))  # a brown wool
    it = scene.connect(PartContact("vest", fig, net, VEST_CONTACT, mode=p.coupling))
    it.period_from = opens  # Table I's row, as the noose's: from the drop on
    return it


def drapes(scene, p: DrapeParams, deck: float, edge: float):
    """Hang the drapes from their rod (pinned along the top edge) in the breeze, one-way."""
    if not p.enabled or not p.at:
        return
    wind = scene.add(wind_field(p.wind))
    c = p.cloth
    x, z = edge - 0.12, deck + p.top
    ys = np.asarray(p.at, float)
    lo, hi = ys.min() - 0.5 * c.width - 0.2, ys.max() + 0.5 * c.width + 0.2
    scene.add(StaticMesh("drape-rod", *merge(rod([x, lo, z], [x, hi, z], 0.02),
                                             rod([x, lo, deck], [x, lo, z + 0.05], 0.04),
                                             rod([x, hi, deck], [x, hi, z + 0.05], 0.04)),
                         color=(0.30, 0.22, 0.14), material="wood"))
    colors = ((0.45, 0.05, 0.06), (0.62, 0.55, 0.40))  # a deep red and an undyed cotton
    for k, y in enumerate(ys):
        pts, tris = shapes.grid(c.width, c.height, c.nu, c.nv,
                                origin=(x, y - 0.5 * c.width, z - 0.03), u=(0, 1, 0),
                                v=(0, 0, -1))
        pts[:, 0] += 2e-3 * np.sin(np.pi * np.arange(len(pts)) / c.nu)  # no cloth hangs flat
        net = SpringNetwork.from_mesh(f"drape-{k}", pts, tris, c.density * c.width * c.height,
                                      c.stretch, c.shear, c.bend, dt=c.dt,
                                      integrator=c.integrator, mass_damping=c.mass_damping,
                                      stiffness_damping=c.stiffness_damping,
                                      cg_tolerance=c.cg_tolerance, fixed=np.arange(c.nu))
        net.color = colors[k % len(colors)]
        scene.add(net)
        scene.connect(Aerodynamics(f"breeze-{k}", wind, net, AeroParams(), mode="one-way"))


def rope_figures(result) -> dict:
    """The noose's measures: its largest stretch against manila's break elongation, the
    deepest it pressed into the figure (mm, beyond its own radius), whether the loop is still
    round the neck at the end, and the verdict: held, or (a one-way run) violated: the figure
    fell through where the rope should have stopped it."""
    if "noose" not in result.frames or "alien" not in result.frames:
        return {}
    strain = float(result.diagnostics.get("noose", {}).get("max_strain", 0.0))
    it = result.interaction("noose")
    rope, body = result.frames["noose"], result.frames["alien"]
    ring = rope["points"][:, -_ring_size(result):]
    head = body["segment_positions"][:, SEGMENTS.index("head")]
    off = np.linalg.norm(ring.mean(axis=1) - head, axis=1)
    arm = np.asarray(result.meta["arm"], float)
    reach = result.meta["rope_rest_length_m"] * (1.0 + MANILA_BREAK_STRAIN)
    below = float(np.max(np.linalg.norm(head - arm, axis=1)) - reach)
    out = {"rope stretch max (%)": 100.0 * strain,
           "manila breaks at (%)": 100.0 * MANILA_BREAK_STRAIN,
           "noose into the neck max (mm)": 1000.0 * float(it.get("deepest_m", 0.0)),
           "loop round the neck at the end": bool(off[-1] < 0.15),
           "lowest centre of mass (m above the creek)": float(body["com"][:, 2].min())}
    if strain > MANILA_BREAK_STRAIN or below > 0.0:
        out["constraint"] = (f"violated: the neck went {max(below, 0.0):.2f} m past where the "
                             f"rope stops it (stretched {100 * strain:.0f}%, manila breaks at "
                             f"{100 * MANILA_BREAK_STRAIN:.0f}%): under {it['mode']} coupling "
                             "nothing held the figure up")
    else:
        out["constraint"] = "held: the rope stopped the fall within manila's stretch"
    return out


def vest_figures(result) -> dict:
    """The vest's measures: its largest stretch, the deepest it went into him (mm, beyond its
    skin) and how far it slid on him over the run (m: its centre in his torso's frame)."""
    if "vest" not in result.frames or "alien" not in result.frames:
        return {}
    it, body, t = result.interaction("vest"), result.frames["alien"], SEGMENTS.index("torso")
    # the vest's centre in his torso's frame (he tilts as he hangs), against where it began
    conj = body["segment_orientations"][:, t] * [1.0, -1.0, -1.0, -1.0]
    on_him = quat_rotate(conj, result.frames["vest"]["points"].mean(axis=1)
                         - body["segment_positions"][:, t])
    slid = np.linalg.norm(on_him - on_him[0], axis=1)
    return {"vest stretch max (%)":
            100.0 * float(result.diagnostics.get("vest", {}).get("max_strain", 0.0)),
            "vest into the body max (mm)": 1000.0 * float(it.get("deepest_m", 0.0)),
            "vest slid on him max (m)": float(slid.max())}


def figures(result) -> dict:
    """The scene's key figures: the noose's and the vest's."""
    return {**rope_figures(result), **vest_figures(result)}


def _ring_size(result) -> int:
    return int(result.meta["noose_loop_points"])
