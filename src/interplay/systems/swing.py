"""A playground swing with a child on it, in one MuJoCo model (issue 16's child on a swing).

The swing is a seat hung from the top bar by two chains. Taut chains under a seated child
carry her weight (tension ~ m g cos(amplitude) > 0 for any swing below 90 deg), so they stay
straight: the seat and both chains move as one rigid body on one hinge at the top bar, a
compound pendulum. (What this leaves out: the kink a real chain takes at her hands when she
leans back, and the chains' slack at amplitudes near 90 deg.)

She sits on the seat by MuJoCo's contact (her thighs and buttocks on it, friction 1) and
holds the chains: each hand is tied to its chain by a ball-joint equality (``connect``: the
grip point on the hand and on the chain coincide; the hand may turn about it). She is the
standard Figure (systems/figure.py) at a child's mass and height; the swing is added to her
model through its ``extend`` hook, so her servos, the seat's contact and the grips are solved
together in every MuJoCo step.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..control.fsm import pose_vector
from ..errors import ParameterError, require_positive
from ..geometry.anthropometry import SEGMENTS
from ..geometry.primitive import Primitive
from ..geometry.setpieces import box, merge, rod
from ..params import param
from .figure import Figure, FigureParams
from .figure_model import FIGURE_GROUP, WORLD_GROUP, build_model
from .shape import figure_shape

HEAD_CLEARANCE = 0.10  # m: the least room between the top of her head and the bar


@dataclass(frozen=True)
class SwingParams:
    """A residential playground swing: bar (m) the top bar's height; chain (m) from the bar to
    the seat (2.0 m: a 2.4-2.5 m beam with the seat 0.45-0.6 m above the ground, the usual
    residential and playground set); chain_mass (kg) each (galvanized 4/0 swing chain,
    ~0.4 kg/m); seat_mass (kg; a rubber belt seat, 1-2 kg); width (m) between the chains;
    depth, thickness (m) of the seat; damping (N m s/rad) of the bar's bearings; start (rad):
    the swing's angle at t = 0 (positive: forward, the way she faces); sit_gap (m): how far
    above the seat her thighs rest (the seat's MuJoCo contact margin): the room the fabric she
    sits on takes, kept by the cloth's contacts with her skin and with the seat (5 mm each,
    scenes/swing.py), so a skirt under her is not pinched between them."""
    bar: float = param(2.5, "m", gt=0.0, le=20.0)
    chain: float = param(2.0, "m", gt=0.0, le=19.0)
    chain_mass: float = param(0.8, "kg", gt=0.0, le=100.0)
    seat_mass: float = param(1.5, "kg", gt=0.0, le=100.0)
    width: float = param(0.46, "m", gt=0.1, le=2.0)
    depth: float = param(0.17, "m", gt=0.02, le=1.0)
    thickness: float = param(0.02, "m", gt=0.002, le=0.2)
    damping: float = param(0.05, "N m s/rad", ge=0.0, le=100.0)
    start: float = param(0.1, "rad", ge=-1.2, le=1.2)
    sit_gap: float = param(0.012, "m", ge=0.0, le=0.05)


#: her seated pose on the swing (rad): thighs along the seat, shanks hanging, upright; the
#: hands hold the chains at her chest (0.24 m above the seat: upper arms back along her sides,
#: elbows bent up), where a child grips them, so that her arms have a lever about the seat
#: to turn her against the chains (gripping beside her hips, at the seat's height, the same
#: pumping raised the amplitude 0.29 deg a cycle instead of ~1: docs/swing.md)
SEATED = (("hip_flex", 1.57), ("knee", 1.57), ("ankle", 0.0), ("waist_flex", 0.0),
          ("shoulder_flex", -1.0), ("shoulder_abd", 0.18), ("elbow", 2.4))


def swing_body(spec, p: SwingParams, grips=()):
    """Add the swing to an MjSpec: one body on a hinge about the bar (axis -y: a positive
    angle carries the seat forward, +x), the chains as capsules of their mass, the seat a box
    its top at z = bar - chain when hanging still; grips: world points (m, at the hanging
    pose) where sites ``grip_k`` are put on it. Returns the body."""
    import mujoco
    for name, v in (("bar", p.bar), ("chain", p.chain), ("chain_mass", p.chain_mass),
                    ("seat_mass", p.seat_mass), ("width", p.width)):
        require_positive("swing", name, v, "kg" if "mass" in name else "m")
    if p.chain >= p.bar:
        raise ParameterError(f"swing: chain {p.chain} m reaches the ground from a bar at "
                             f"{p.bar} m; use a chain shorter than the bar (e.g. bar - 0.5 m)")
    top = np.array([0.0, 0.0, p.bar])
    body = spec.worldbody.add_body(name="swing", pos=top)
    body.add_joint(name="swing", type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0.0, -1.0, 0.0],
                   damping=p.damping)
    w = 0.5 * p.width
    for side in (1.0, -1.0):
        body.add_geom(type=mujoco.mjtGeom.mjGEOM_CAPSULE, size=[0.006, 0.0, 0.0],
                      fromto=[0.0, side * w, 0.0, 0.0, side * w, -p.chain], mass=p.chain_mass,
                      contype=0, conaffinity=0)
    body.add_geom(name="seat", type=mujoco.mjtGeom.mjGEOM_BOX,
                  size=[0.5 * p.depth, w, 0.5 * p.thickness],
                  pos=[0.0, 0.0, -p.chain - 0.5 * p.thickness], mass=p.seat_mass,
                  contype=WORLD_GROUP, conaffinity=FIGURE_GROUP, friction=[1.0, 0.005, 1e-4],
                  margin=p.sit_gap)
    for k, g in enumerate(grips):
        body.add_site(name=f"grip_{k}", pos=np.asarray(g, float) - top)
    return body


class SwingFigure(Figure):
    """A Figure seated on a swing, holding its chains. Her segments are the Figure's; the
    swing's angle (rad, forward positive) and rate (rad/s) are ``swing_angle`` and
    ``swing_rate``; its frame adds the swing as an 18th part (segment_positions and
    orientations), drawn with her."""

    def __init__(self, name: str, params: FigureParams, swing: SwingParams = SwingParams(),
                 controller=None, feedback=None):
        self.swing = swing
        root, hands = _seated(params, swing)
        params = replace(params, position=tuple(root))

        def extend(spec, bodies):
            import mujoco
            swing_body(spec, swing, grips=hands)
            for k, hand in enumerate(("l_hand", "r_hand")):
                bodies[hand].add_site(name=f"palm_{k}", pos=_palm(self.plan, hand))
                spec.add_equality(type=mujoco.mjtEq.mjEQ_CONNECT, objtype=mujoco.mjtObj.mjOBJ_SITE,
                                  name1=f"palm_{k}", name2=f"grip_{k}")

        super().__init__(name, params, controller, feedback=feedback, extend=extend)
        import mujoco
        m = self.model
        j = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, "swing")
        self._sq, self._sv = int(m.jnt_qposadr[j]), int(m.jnt_dofadr[j])
        self.swing_body = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "swing")
        self.swing_mass = float(m.body_mass[self.swing_body])
        # contacts see the swing as one more part, its seat a box (the skirt on the seat)
        self.add_part("swing", self.swing_body, swing_mesh(swing), seat_primitive(swing))
        self._pose(swing.start)

    def _pose(self, angle: float):
        """Seat her at the seated pose on the swing hanging at ``angle`` (rad): the pose's
        joint angles, the whole body turned with the swing about the bar."""
        import mujoco
        d = self.data
        q = pose_vector(SEATED, self.joints)
        d.qpos[self.qadr] = q
        pivot = np.array([0.0, 0.0, self.swing.bar])
        c, s = np.cos(angle), np.sin(angle)
        R = np.array([[c, 0.0, -s], [0.0, 1.0, 0.0], [s, 0.0, c]])  # about -y by angle
        d.qpos[:3] = pivot + R @ (d.qpos[:3] - pivot)
        d.qpos[3:7] = [np.cos(-angle / 2), 0.0, np.sin(-angle / 2), 0.0]
        d.qpos[self._sq] = angle
        d.qvel[:] = 0.0
        self.targets[:] = q
        mujoco.mj_forward(self.model, d)
        self._plan(0.0)

    def swing_angle(self) -> float:
        return float(self.data.qpos[self._sq])

    def swing_rate(self) -> float:
        return float(self.data.qvel[self._sv])

    def swing_inertia(self) -> tuple[float, float]:
        """(I about the bar (kg m^2), first moment M d (kg m): mass times its centre's distance
        below the bar) of the swing and of her at the present pose, for the compound
        pendulum's period 2 pi sqrt(I / (M g d))."""
        m, d = self.model, self.data
        pivot = np.array([0.0, 0.0, self.swing.bar])
        I = Md = 0.0
        for b in range(1, m.nbody):
            r = d.xipos[b] - pivot
            R = d.ximat[b].reshape(3, 3)
            Iy = float((R @ np.diag(m.body_inertia[b]) @ R.T)[1, 1])
            I += Iy + m.body_mass[b] * (r[0] ** 2 + r[2] ** 2)
            Md += -m.body_mass[b] * r[2]
        return I, Md

    def frame(self):
        out = super().frame()
        d, b = self.data, self.swing_body
        out["segment_positions"] = np.vstack([out["segment_positions"], d.xpos[b]])
        out["segment_orientations"] = np.vstack([out["segment_orientations"], d.xquat[b]])
        return out

    def shapes(self):
        shape = figure_shape(self.name, self.plan, self.color)
        shape.parts = list(shape.parts) + [swing_mesh(self.swing)]
        shape.part_names = shape.part_names + ("swing",)
        shape.part_parents = shape.part_parents + (-1,)
        if shape.part_colors is not None:
            shape.part_colors = np.vstack([shape.part_colors, SWING_COLOR])
        return [shape]


SWING_COLOR = (0.20, 0.20, 0.22)  # black rubber seat, dark galvanized chain


def swing_mesh(p: SwingParams):
    """The swing in its body frame (origin on the bar): two chains and the seat."""
    w = 0.5 * p.width
    return merge(rod([0.0, w, 0.0], [0.0, w, -p.chain], 0.008, sections=6),
                 rod([0.0, -w, 0.0], [0.0, -w, -p.chain], 0.008, sections=6),
                 box([-0.5 * p.depth, -w - 0.01, -p.chain - p.thickness],
                     [0.5 * p.depth, w + 0.01, -p.chain]))


def seat_primitive(p: SwingParams, below: float = 0.0) -> Primitive:
    """The seat as a box in the swing's body frame (origin on the bar), m; below (m): the box
    reaching that much further down (a pedestal under the board: what is inside it is nearer
    the top or a side than the bottom, so a contact pushes it up onto the seat or out past
    its edge, never down through it)."""
    h = p.thickness + below
    return Primitive("box", axes=(0.5 * p.depth, 0.5 * p.width, 0.5 * h),
                     centre=(0.0, 0.0, -p.chain - 0.5 * h))


def _palm(plan, hand: str) -> np.ndarray:
    """The grip point on a hand (its body frame, m): halfway down it."""
    seg = plan[SEGMENTS.index(hand)]
    return 0.5 * np.asarray(seg.bone, float)


def _seated(params: FigureParams, p: SwingParams):
    """Where she sits on the swing hanging still: (her Figure position (m): where her pelvis's
    rest position is carried to, grip points (2,3) m on her hands). Her thighs rest on the
    seat's top and her hands are on the chains' line (x = 0); the grips are where her hands
    are (the chains are drawn at +-width/2, her seated hands ~1 cm inside them)."""
    import mujoco
    from ..geometry.anthropometry import body_plan, joint_names
    plan = body_plan(params.body)
    model = build_model(plan, params.environment, params.dt, mass=params.body.mass)
    data = mujoco.MjData(model)
    names = joint_names(plan)
    jid = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, j) for j in names]
    data.qpos[model.jnt_qposadr[jid]] = pose_vector(SEATED, names)
    mujoco.mj_kinematics(model, data)
    body = {s: mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, s) for s in SEGMENTS}
    grips = np.array([data.xpos[body[h]] + data.xmat[body[h]].reshape(3, 3) @ _palm(plan, h)
                      for h in ("l_hand", "r_hand")])
    thigh = plan[SEGMENTS.index("l_thigh")]
    hip_z = data.xpos[body["l_thigh"]][2]
    seat_top = p.bar - p.chain + p.sit_gap
    shift = np.array([-grips[:, 0].mean(), 0.0, seat_top - (hip_z - thigh.shape[1])])
    grips = grips + shift
    head = plan[SEGMENTS.index("head")]
    crown = data.xpos[body["head"]][2] + head.shape[2][2] + head.shape[1] + shift[2]
    if p.bar - crown < HEAD_CLEARANCE:
        raise ParameterError(f"swing: chain {p.chain} m is too short for a {params.body.height}"
                             f" m child: seated, the top of her head would be "
                             f"{crown - p.bar:+.2f} m from the bar; use a chain of at least "
                             f"{p.chain + crown - p.bar + HEAD_CLEARANCE:.2f} m")
    return shift, grips
