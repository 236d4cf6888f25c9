"""The search for the bounce controller (SPEC 2.3: the paper found its gymnast's bounce by
simulated annealing, since the two-way simulation is too slow to tune by hand).

A trial drops the gymnast from her first apex onto the trampoline and runs the scene (two-way,
or hybrid: her pass with the bed's stand-in only) for ``duration`` s, stopping early once she
has fallen; a ``BounceRecord`` watching her controller's ticks logs every landing (time,
centre of mass position, pelvis tilt) and every apex. The loss rewards consecutive good
bounces (landed upright, inside the bed's central zone) and, among controllers that keep
bouncing, steady apex heights at the height she started from, landings near the centre and an
upright body.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from ..coupling.forcelog import GAP
from .bounce import BOUNDS
from .search import Search

TILT_GOOD = 0.35  # rad: the pelvis's largest tilt from vertical at a good landing
TILT_FALLEN = 1.0  # rad: past this she has fallen (the trial stops)
HEIGHT_KEPT = 0.75  # a good bounce's flight is at least this share of the first one's
SPIN_SCALE = 5.0  # kg m^2/s: a takeoff spin that turns her ~0.35 rad in a 1 s flight
DURATION = 14.0  # s of a search trial: the drop and about seven bounces


@dataclass
class BounceRecord:
    """What the controller saw, tick by tick: landings [(t s, x m, y m, z m, tilt rad)] of
    the centre of mass at touchdown, apexes (m, its highest point in each flight before a
    landing, the first the drop's), the largest tilt (rad), and whether she touched the
    floor; takeoffs [(t s, horizontal speed m/s, |angular momentum| kg m^2/s)] as each flight
    begins, and modes [(roll momentum about her forward axis, kg m^2/s; sideways speed, m/s;
    pitch momentum about her left, kg m^2/s; forward speed, m/s)] of her centre of mass then:
    the sideways and fore-aft modes' states (control/bounce_modes.py)."""
    landings: list = field(default_factory=list)
    takeoffs: list = field(default_factory=list)
    modes: list = field(default_factory=list)
    apexes: list = field(default_factory=list)
    max_tilt: float = 0.0
    floor: bool = False
    _air: bool = True
    _top: float = -math.inf


class Recorded:
    """A figure's feedback wrapped so its ticks are logged into a BounceRecord (the trial's
    instrument; the wrapped feedback's offsets are returned unchanged)."""

    def __init__(self, feedback, record: BounceRecord):
        self.inner, self.record = feedback, record

    def capture(self):
        return self.inner.capture()

    def restore(self, snap):
        self.inner.restore(snap)

    def offsets(self, fig, sensors):
        r = self.record
        up = fig.data.xmat[fig.root].reshape(3, 3)[:, 2]
        tilt = math.acos(max(-1.0, min(1.0, float(up[2]))))
        r.max_tilt = max(r.max_tilt, tilt)
        r.floor = r.floor or fig.data.ncon > 0  # MuJoCo's floor: the bed let her through
        com = sensors["com"]
        touching = sensors["foot_contact"] or sensors["hand_contact"] or bool(
            fig.touched.any())
        if r._air:
            r._top = max(r._top, float(com[2]))
            if touching and r.takeoffs and fig.time - r.takeoffs[-1][0] < GAP:
                # the recoiling bed caught her toes just after takeoff: the stance goes on
                # (as in the contact log's episodes, record_of)
                r.takeoffs.pop()
                r.modes.pop()
                r._air = False
            elif touching:
                r.apexes.append(r._top)
                r.landings.append((fig.time, float(com[0]), float(com[1]), float(com[2]),
                                   tilt))
                r._air = False
        elif not touching:
            r._air, r._top = True, float(com[2])
            v = sensors["com_vel"]
            r.takeoffs.append((fig.time, float(np.hypot(v[0], v[1])),
                               float(np.linalg.norm(fig.data.subtree_angmom[fig.root]))))
            fwd, left = fig.heading_axes()
            spin = fig.data.subtree_angmom[fig.root]
            r.modes.append((float(spin @ fwd), float(v @ left), float(spin @ left),
                            float(v @ fwd)))
        return self.inner.offsets(fig, sensors)


class _Stop(Exception):
    """A trial ends early: she fell, or the takeoffs asked for are in."""


def trial(params, coupling: str = "two-way", duration: float = DURATION,
          sideways: float = 0.0, takeoffs: int | None = None) -> BounceRecord:
    """Run the trampoline scene with scene parameters ``params`` (TrampolineParams) and log
    the gymnast's bounces; stops early when she has fallen (tilt past TILT_FALLEN, the floor,
    or out of the bed's central zone), or after ``takeoffs`` takeoffs when given. sideways
    (m/s): a sideways speed she is dropped with (a probe of the sideways mode)."""
    from ..scenes.trampoline import CENTRE_ZONE, build
    scene = build(coupling, duration=duration, fps=10.0, params=params)
    fig = scene.primary
    fig.data.qvel[:3] += sideways * fig.heading_axes()[1]
    record = BounceRecord()
    fig.feedback = Recorded(fig.feedback, record)
    zx, zy = CENTRE_ZONE

    def watch(p, t, wall, done=False):
        c = fig.com()
        if record.max_tilt > TILT_FALLEN or record.floor or abs(c[0]) > zx or abs(c[1]) > zy:
            raise _Stop()
        if takeoffs is not None and len(record.takeoffs) >= takeoffs:
            raise _Stop()  # seen enough
    try:
        scene.simulate(progress=watch, primary_only=coupling != "two-way")
    except _Stop:
        pass
    return record


def rises(record: BounceRecord) -> np.ndarray:
    """(m) each flight's height: the apex above the centre of mass at the landing after it."""
    n = min(len(record.apexes), len(record.landings))
    return np.array([record.apexes[i] - record.landings[i][3] for i in range(n)])


def score(record: BounceRecord, centre=(1.0, 0.5)) -> tuple[float, dict]:
    """(loss, metrics) of a trial: minus the good bounces in a row (landed upright, inside the
    central zone of half extents ``centre`` m, from a flight at least HEIGHT_KEPT of the
    first's: she keeps bouncing, not just standing), plus half the mean horizontal speed (m/s)
    and the mean angular momentum over SPIN_SCALE (kg m^2/s) at the takeoffs before the first
    bad landing (what makes the next landing bad: these guide a search that bounces only once or
    twice yet); with at least three, plus twice the spread
    (std / mean) of the flight heights after the second, their mean's miss of the first
    (the drop's) as a fraction, the landings' mean offset from the centre as a fraction of the
    zone, and twice their mean tilt (rad); plus 5 if she reached the floor."""
    zx, zy = centre
    good = 0
    rise = rises(record)
    for k, (t, x, y, z, tilt) in enumerate(record.landings):
        if (tilt > TILT_GOOD or abs(x) > zx or abs(y) > zy
                or (k < len(rise) and rise[k] < HEIGHT_KEPT * rise[0])):
            break
        good += 1
    rise = rise[:good]
    metrics = {"bounces": good, "landings": len(record.landings), "max_tilt": record.max_tilt,
               "floor": record.floor, "rises_m": [float(a) for a in rise]}
    loss = -float(good)
    offs = np.array(record.takeoffs[:good + 1]).reshape(-1, 3)
    if len(offs):
        speed, spin = float(offs[:, 1].mean()), float(offs[:, 2].mean())
        metrics.update(takeoff_speed=speed, takeoff_spin=spin)
        loss += 0.5 * speed + spin / SPIN_SCALE
    if good >= 3:
        later = rise[2:]
        spread = float(np.std(later) / np.mean(later))
        miss = float(abs(np.mean(later) - rise[0]) / rise[0])
        lands = np.array(record.landings[:good])
        off = float(np.mean(np.hypot(lands[:, 1] / zx, lands[:, 2] / zy)))
        tilt = float(np.mean(lands[:, 4]))
        metrics.update(spread=spread, miss=miss, off_centre=off, tilt=tilt)
        loss += 2.0 * spread + miss + off + 2.0 * tilt
    if record.floor:
        loss += 5.0
    return loss, metrics


def bounce_loss(coupling: str, kw: dict) -> float:
    """The search's loss (``control.search.Search``; module-level, so a worker can import it):
    a trial of the scene's parameters ``kw["params"]`` for ``kw["duration"]`` s in
    ``coupling`` (two-way, or hybrid: her pass on the stand-in), scored by ``score``."""
    return score(trial(kw["params"], coupling, kw["duration"]))[0]


#: where the stand-in search starts, set by hand (docs/trampoline.md tells how); the search
#: starts from the scene's parameters, so the command that made the shipped controller sets
#: these (``start_sets``)
HAND_START = {"knee_land": 0.2, "lean": 0.0, "trunk": 0.0, "leg_omega": 12.0,
              "thrust_delay": 0.12, "power": 1.0, "ankle_push": 0.2, "arm_swing": 2.8,
              "arm_land": 0.6, "k_speed": 0.3, "k_place": 0.3, "k_lead": 5.0,
              "k_drift": 0.3, "k_spin": 0.02, "k_attitude": 0.0, "k_turn": 0.0,
              "k_hip_spin": -0.03, "k_arms": 0.0, "ankle_share": 1.0}


#: the second edges-only search's best (the defaults until 2026-12-06): the start of the first
#: search on the bed's faces (docs/trampoline.md)
EDGES_BEST = {
    "knee_land": 0.14445817435485553,
    "lean": -0.0488264489650417,
    "trunk": -0.03840802227306958,
    "leg_omega": 12.8848547499585,
    "ankle_share": 0.7741162175548496,
    "thrust_delay": 0.16237907246390273,
    "power": 0.5841121639613117,
    "ankle_push": 0.35920869840470787,
    "arm_swing": 3.1,
    "arm_land": 0.003616482133918858,
    "k_speed": 0.6,
    "k_place": 0.46001672902920826,
    "k_lead": 4.970550615473857,
    "k_drift": 0.08162544824107555,
    "k_spin": 0.0164970699297445,
    "k_attitude": 0.04171894873496466,
    "k_turn": 0.003324037518460548,
    "k_hip_spin": -0.06,
    "k_arms": 0.05108273094290473}


#: the first search on the bed's faces' best, with sharp feet: the start of the search with her
#: feet rounded (search 4, whose best is ROUNDED_BEST; docs/trampoline.md)
FACES_BEST = {
    "knee_land": 0.1,
    "lean": 0.013067336197741832,
    "trunk": -0.029034583135383374,
    "leg_omega": 13.599290972358455,
    "ankle_share": 0.6594812445410662,
    "thrust_delay": 0.15977712366621083,
    "power": 0.9211436989186281,
    "ankle_push": 0.13960834318473667,
    "arm_swing": 3.031584092430814,
    "arm_land": 0.900846141901059,
    "k_speed": 0.4088016267910487,
    "k_place": 0.44660764515605406,
    "k_lead": 2.9457184109697683,
    "k_drift": 0.11856835722415564,
    "k_spin": 0.025740446690318424,
    "k_attitude": 0.057985445297466166,
    "k_turn": 0.0017583143699759665,
    "k_hip_spin": -0.048651496501968365,
    "k_arms": 0.23585735263605434}


#: search 4's best (her feet rounded; the defaults until search 10): the start of search 5, on the
#: penalty contact with the aim in the box (docs/trampoline.md)
ROUNDED_BEST = {
    "knee_land": 0.24248216393047864,
    "lean": 0.04123097909656632,
    "trunk": -0.15749223801622314,
    "leg_omega": 12.039005719344434,
    "ankle_share": 0.4787877610561425,
    "thrust_delay": 0.10186381131316363,
    "power": 0.3282547105673322,
    "ankle_push": 0.2937119821651646,
    "arm_swing": 2.992458576628844,
    "arm_land": 0.9753128714654313,
    "k_speed": 0.4406028934995885,
    "k_place": 0.44176941099682676,
    "k_lead": 2.1706362907687864,
    "k_drift": 0.018015126063999506,
    "k_spin": 0.01601819208919427,
    "k_attitude": 0.14955399755798174,
    "k_turn": 0.012788720878903427,
    "k_hip_spin": -0.052252244425987575,
    "k_arms": 0.3043088900154914}


#: search 5's best, on the penalty contact: the start of search 6
PENALTY_BEST = {
    "knee_land": 0.12688073428741617,
    "lean": 0.16132444824908726,
    "trunk": -0.06790357045231446,
    "leg_omega": 14.125699182935575,
    "ankle_share": 0.42835246419845086,
    "thrust_delay": 0.20241580986136984,
    "power": 0.49368903761799376,
    "ankle_push": 0.22319232804239644,
    "arm_swing": 3.0714034199646014,
    "arm_land": 0.4837484076881579,
    "k_speed": 0.0106527949992883,
    "k_place": 0.4224230775972595,
    "k_lead": 4.598635519496023,
    "k_drift": 0.5998448944256647,
    "k_spin": 0.04484608380090811,
    "k_attitude": 0.1714621698578907,
    "k_turn": 0.007107471041100739,
    "k_hip_spin": -0.03209944715517113,
    "k_arms": 0.4865828151164402,
    "aim": 0.6506881154713995}


#: search 6's best: the start of search 7 (docs/trampoline.md)
AIMED_BEST = {
    "knee_land": 0.11485230175639055,
    "lean": 0.1953273128847776,
    "trunk": -0.0979983815576149,
    "leg_omega": 15.448189777805759,
    "ankle_share": 0.4478391818543865,
    "thrust_delay": 0.29692977941723087,
    "power": 0.4426029894362917,
    "ankle_push": 0.21067526214394747,
    "arm_swing": 3.011046109958195,
    "arm_land": 0.7696353617190258,
    "k_speed": 0.029170681999973434,
    "k_place": 0.17954322818729754,
    "k_lead": 4.725150609878495,
    "k_drift": 0.8221084873666624,
    "k_spin": 0.04416498014393186,
    "k_attitude": 0.24704378327249002,
    "k_turn": 0.005844314332778585,
    "k_hip_spin": -0.02209927468628369,
    "k_arms": 0.7386520068877024,
    "aim": 0.7054225481355482}


#: search 7's best (steady flights, 0.90-0.93 m; from every drop near the scene's she falls
#: sideways at the 7th-9th landing): the start of search 9, with the sideways hips (k_side,
#: k_side_drift) at zero
STEADY_BEST = {
    "knee_land": 0.14932903121522764,
    "lean": 0.2108107741110194,
    "trunk": -0.12789054439975936,
    "leg_omega": 17.24217702532367,
    "ankle_share": 0.5585378089183403,
    "thrust_delay": 0.3,
    "power": 0.47358617728102625,
    "ankle_push": 0.27778627823774754,
    "arm_swing": 2.773937463235526,
    "arm_land": 0.8052451713027293,
    "k_speed": 0.033077606985032974,
    "k_place": 0.18872671896219803,
    "k_lead": 4.975737781978708,
    "k_drift": 1.1708866693277733,
    "k_spin": 0.040928464202839895,
    "k_attitude": 0.19224451375183957,
    "k_turn": 0.0045958220016454054,
    "k_hip_spin": -0.02701657519764187,
    "k_arms": 0.6995026317658182,
    "aim": 1.1881161784393899}


#: search 9's best (the sideways hips in its box): the start of search 10, whose best are the
#: defaults, with the landing's width and the knees' roll term at zero
SIDE_BEST = {
    "knee_land": 0.14944063544858793,
    "lean": 0.21433967795390688,
    "trunk": -0.12328451937787022,
    "leg_omega": 17.131517267670294,
    "ankle_share": 0.5501210560109899,
    "thrust_delay": 0.3,
    "power": 0.46815571039100884,
    "ankle_push": 0.28492552623268846,
    "arm_swing": 2.776335677749211,
    "arm_land": 0.8106350241991717,
    "k_speed": 0.04306074986335582,
    "k_place": 0.18579111584303462,
    "k_lead": 5.044544165808041,
    "k_drift": 1.1789751554484078,
    "k_spin": 0.04083634571109614,
    "k_attitude": 0.1859750787253058,
    "k_turn": 0.004302345373021194,
    "k_hip_spin": -0.025550732755524955,
    "k_arms": 0.7152400994189753,
    "aim": 1.1512273902136345,
    "k_side": 0.01674685786176071,
    "k_side_drift": -0.0783104532316746}


#: search 10's best (the landing's width and the knees' roll term in its box; the defaults
#: until search 13): with SIDEWAYS_START, the start of search 13 (docs/trampoline.md)
WIDTH_BEST = {
    "knee_land": 0.14955291912535282,
    "lean": 0.21410317625280054,
    "trunk": -0.12009770683850916,
    "leg_omega": 17.217810104363537,
    "ankle_share": 0.5412151404002863,
    "thrust_delay": 0.29590796976707784,
    "power": 0.475055096469051,
    "ankle_push": 0.2837507334131653,
    "arm_swing": 2.763718128566324,
    "arm_land": 0.8165356126476446,
    "k_speed": 0.049960744495031614,
    "k_place": 0.16645562437142422,
    "k_lead": 5.056711983977513,
    "k_drift": 1.1914239063991712,
    "k_spin": 0.042032027454567016,
    "k_attitude": 0.1791730989980489,
    "k_turn": 0.0048070815189191814,
    "k_hip_spin": -0.025185525129380465,
    "k_arms": 0.6894319229289314,
    "aim": 1.2211224295251615,
    "k_side": 0.039228197090094265,
    "k_side_drift": -0.04292187973416589,
    "width": 0.0,
    "k_roll": 0.004119103424828045}


#: the sideways gains search 13 started from: a Nelder-Mead on the modes' growth
#: (control/bounce_modes.py) over these six, on search 10's best, brought the sideways factor from
#: x19 to x2.6 a bounce (docs/trampoline.md, "The modes' growth")
SIDEWAYS_START = {
    "k_side": 1.987,
    "k_side_drift": 4.8641,
    "k_roll": -3.2486,
    "k_hip_roll": 0.0391,
    "k_turn_side": 0.0012,
    "k_speed_side": 0.0145}


def start_sets(values: dict = HAND_START) -> list[str]:
    """``--set`` items that put the search's start at ``values`` ({controller field: value})."""
    return [f"bounce.{k}={v!r}" for k, v in values.items()]


BOUNCE = Search(
    "bounce", "the bounce controller: good bounces in a row, steady apexes, over the centre",
    bounds={f"bounce.{k}": v for k, v in BOUNDS.items()}, loss=bounce_loss, budget=100,
    chains=4, t_start=1.0, t_end=0.01, step=0.1)

#: m: the drops a basin trial starts from, about the scene's: a millimetre moves the shipped
#: controller's second landing by centimetres and decides its third (docs/trampoline.md)
BASIN_DROPS = (0.0, -0.001, 0.001)


def basin_loss(coupling: str, kw: dict) -> float:
    """The basin search's loss: ``bounce_loss`` from each of BASIN_DROPS added to the scene's
    drop, the worst of them, so a controller scores what it keeps over nearby starts, not
    what one trajectory's luck gives it. Costs len(BASIN_DROPS) trials."""
    p = kw["params"]
    return max(bounce_loss(coupling, {**kw, "params": replace(p, gymnast=replace(
        p.gymnast, drop=p.gymnast.drop + d))}) for d in BASIN_DROPS)


BASIN = Search(
    "bounce-basin", "the bounce controller over nearby starts: the worst of three drops a "
    "millimetre apart", bounds=BOUNCE.bounds, loss=basin_loss, budget=100, chains=4,
    t_start=1.0, t_end=0.01, step=0.1)


def record_of(result, bed_height: float) -> tuple[BounceRecord, list, float, tuple]:
    """The BounceRecord of a finished run (a Result), rebuilt from its data: landings and
    takeoffs from the contact's force log (its periods of contact, 1 ms), the centre of mass
    and the pelvis's tilt from the gymnast's output frames (interpolated at the landings;
    apexes are frame maxima: at 60 frames/s within g (1/120 s)^2 / 2 = 0.3 mm), and the floor
    from her segments' lowest mesh point. Also returns each landing's bed depression (m,
    below ``bed_height``, the frames' lowest bed point during the contact), her lowest
    point (m) and where her centre of mass was (x, y, m) when she was lowest."""
    from ..kernels.rigid import quat_to_matrix
    log = result.logs[result.main]
    fr = result.frames["gymnast"]
    t, com = fr["t"], fr["com"]
    quat = fr["segment_orientations"][:, 0]
    tilt = np.array([math.acos(np.clip(quat_to_matrix(q)[2, 2], -1.0, 1.0)) for q in quat])
    parts = next(s for s in result.shapes if s.name == "gymnast").parts
    lowest = np.full(len(t), np.inf)
    for k, (v, _) in enumerate(parts):
        R = np.array([quat_to_matrix(q) for q in fr["segment_orientations"][:, k]])
        z = np.einsum("fj,vj->fv", R[:, 2, :], v) + fr["segment_positions"][:, k, 2:3]
        lowest = np.minimum(lowest, z.min(axis=1))
    bed = result.frames.get("trampoline", {}).get("points")
    rec = BounceRecord(max_tilt=float(tilt.max()), floor=bool(lowest.min() < FLOOR_GAP))
    depressions, last = [], t[0] - 1.0
    for start, end in log.episodes():
        flight = (t > last) & (t < start)
        rec.apexes.append(float(com[flight, 2].max()) if flight.any() else float(com[0, 2]))
        c = [float(np.interp(start, t, com[:, i])) for i in range(3)]
        rec.landings.append((start, c[0], c[1], c[2], float(np.interp(start, t, tilt))))
        during = (t >= start) & (t <= end)
        if bed is not None and during.any():
            depressions.append(float(bed_height - bed[during][:, :, 2].min()))
        last = end
    k = int(np.argmin(lowest))
    return rec, depressions, float(lowest[k]), (float(com[k, 0]), float(com[k, 1]))


FLOOR_GAP = 0.02  # m: her lowest point this near the floor means the bed let her through
