"""A stunt-kite pilot: watches the kite and moves the two handles as a person flies a two-line
kite: pull one side to turn towards it, both hands together to hold. It reads the kite only
through its frame's contact view (pose and velocity of a rigid part), like an interaction.

Where the kite is: on the wind window, the quarter sphere of the lines' length downwind of the
hands, by its azimuth phi (from the wind's direction, positive to the pilot's left) and
elevation eps. Which way it flies: its heading chi, the direction its nose points within the
window (0 up, +90 deg to the pilot's left), from the frame's orientation. Manoeuvres (a state
machine over the flight):

* ``hold``: park the kite at azimuth ``target`` (deg): the nose is steered towards the target
  azimuth (heading -gain (phi - target), within +-hold_tilt) and the kite climbs to where it
  rests, the window's top over that azimuth;
* ``loop``: from ``start`` (s), one loop every ``every`` seconds, to the left and the right by
  turns, each begun once the kite is parked high (above ``ready`` deg of elevation): the
  pilot commands a heading that turns at 2 pi / ``period`` (rad/s) and steers by the error
  between it and the nose's measured heading (feedback, plus a steady pull ``feed`` on the
  inner side), until the nose has turned a full circle (the turn measured by integrating the
  heading's change), then the kite is held again;
* ``figure8``: a loop one way, the kite brought back up to where it began (``ready``), and a
  loop the other way: two circles meeting at the top of the window, an eight.

The steering command u in [-1, 1] (positive: pull the left handle) sets a difference of 2 u
``throw`` (m) between the hands along the pilot's facing: the inner hand pulls back, the
outer gives forward only its share ``outer`` of it (a flyer pulls; letting a hand forward
slackens that line, and a kite on one slack line turns the wrong way); during a
manoeuvre both are drawn back by ``brace`` as well, so the outer line stays taut. The pilot's
arms (``systems.pilot``) follow it with their own response time. A flyer takes up slack with
the feet: whenever the kite comes towards the hands faster than ``slack`` (m/s: the line
going slack) and through each turn, the pilot steps back (``Pilot``'s walk, at its walking
speed), and walks home again at ``home_speed`` while the kite is held and pulling. The
controller acts at ``rate`` (Hz), a person's reaction cadence.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError, require_positive
from ..params import param

MANOEUVRES = ("hold", "loop", "figure8")


@dataclass(frozen=True)
class StuntPilotParams:
    """manoeuvre: hold | loop | figure8; start (s): when the first manoeuvre begins; every (s):
    the time from one manoeuvre's start to the next; ready (deg): the elevation a loop starts
    from; target (deg): the azimuth held between manoeuvres; gain (-): heading per azimuth
    error when holding; hold_tilt (deg): the largest heading used to hold; hold_limit (-):
    the largest steering used to hold (a full pull on one side leaves the other line slack);
    turn_gain (1/rad): steering per heading error; turn_damping (s/rad): steering per error
    in the heading's rate of turn, so the nose settles; period (s): the commanded time of one
    loop (its heading turns at 2 pi / period); feed (-): the steady steering held on the
    inner side through a turn; throw (m): handle travel at full steering (the difference
    between the hands is twice it); outer (-): the share of the throw the outer hand gives
    forward (0: the inner hand pulls back the whole difference and the outer holds, so the
    outer line stays taut; 1: both hands move alike); brace (m): both handles drawn back
    during a manoeuvre (a flyer leans back in a turn, keeping both lines taut); lead (s): a
    turn is let go this long before the nose completes its circle at the present rate of
    turn (the arms and the kite lag the hands); slack (m/s): the kite coming towards the
    hands faster than this is a line going slack, and the pilot steps back; step_in_turn:
    step back through every turn too; home_speed (m/s): how fast it walks back to its place
    while the kite pulls; rate (Hz): how often the pilot looks and acts."""
    manoeuvre: str = param("loop", "-", choices=MANOEUVRES)
    start: float = param(8.0, "s", ge=0.0, le=1e5)
    every: float = param(12.0, "s", gt=0.0, le=1e5)
    ready: float = param(40.0, "deg", ge=0.0, le=90.0)
    target: float = param(0.0, "deg", ge=-90.0, le=90.0)
    gain: float = param(2.0, "-", ge=0.0, le=100.0)
    hold_tilt: float = param(30.0, "deg", ge=0.0, le=90.0)
    hold_limit: float = param(0.4, "-", ge=0.0, le=1.0)
    turn_gain: float = param(0.8, "1/rad", ge=0.0, le=100.0)
    turn_damping: float = param(0.3, "s/rad", ge=0.0, le=100.0)
    period: float = param(3.5, "s", gt=0.0, le=100.0)
    feed: float = param(1.0, "-", ge=0.0, le=1.0)
    throw: float = param(0.25, "m", ge=0.0, le=1.0)
    brace: float = param(0.1, "m", ge=-1.0, le=1.0)
    lead: float = param(0.2, "s", ge=0.0, le=5.0)
    outer: float = param(1.0, "-", ge=0.0, le=1.0)
    slack: float = param(0.5, "m/s", ge=0.0, le=20.0)
    step_in_turn: bool = param(False, "-")
    home_speed: float = param(0.3, "m/s", ge=0.0, le=5.0)
    rate: float = param(20.0, "Hz", gt=0.0, le=1000.0)


def window_coordinates(position, centre):
    """(azimuth phi, elevation eps) (rad) of ``position`` seen from ``centre`` (m), the wind
    along +x: phi positive towards +y."""
    r = np.asarray(position, float) - np.asarray(centre, float)
    return math.atan2(r[1], r[0]), math.atan2(r[2], math.hypot(r[0], r[1]))


def heading(nose, phi, eps):
    """The nose's direction (rad) in the window's tangent plane at (phi, eps): 0 up, +pi/2
    towards increasing azimuth (the pilot's left)."""
    up = np.array([-math.sin(eps) * math.cos(phi), -math.sin(eps) * math.sin(phi),
                   math.cos(eps)])
    left = np.array([-math.sin(phi), math.cos(phi), 0.0])
    return math.atan2(float(nose @ left), float(nose @ up))


HOLD, TURN, RECOVER = 0, 1, 2  # the pilot's phases: holding, turning a loop, climbing back
SETTLED = math.radians(20.0)  # the nose is near enough straight up to begin a loop
FLIP = math.radians(90.0)  # a turn's heading jumping back this far in one look flipped through
LOW = (math.radians(15.0), math.radians(30.0))  # rad: below the first elevation the nose is
# held straight up (climb first), above the second it may tilt by all of hold_tilt


def _wrap(a):
    return (a + math.pi) % (2.0 * math.pi) - math.pi


class StuntPilot:
    """The controller a ``Pilot`` asks for its handle targets. kite: the kite frame's contact
    view (a BodiesView of one part); nose_axis: the kite's nose in that part's frame. It keeps
    the manoeuvres it flew as ``log``: (kind, direction, start s, end s or None)."""

    def __init__(self, kite_view, nose_axis, params: StuntPilotParams = StuntPilotParams()):
        if params.manoeuvre not in MANOEUVRES:
            raise ParameterError(f"pilot: unknown manoeuvre {params.manoeuvre!r}; choose one "
                                 f"of {', '.join(MANOEUVRES)}")
        self.p = params
        self.kite = kite_view
        self.nose_axis = np.asarray(nose_axis, float)
        self.period = 1.0 / require_positive("pilot", "rate", params.rate, "Hz")
        require_positive("pilot", "every", params.every, "s")
        self.u = 0.0  # the steering held between looks
        self.next = 0.0  # time (s) of the next look
        self.turned = 0.0  # rad the nose has turned in the current turn
        self.last = None  # the heading at the last look
        self.phase = HOLD
        self.since = 0.0  # time (s) the current turn began
        self.back = 0.0  # m the pilot wants to stand back from its place
        self.side = 1  # the side (+1: the pilot's left) the manoeuvre is on now
        self.count = 0  # manoeuvres started
        self.log = []

    # --- what the kite does -------------------------------------------------------------------
    def observe(self, centre):
        """(phi, eps, chi) of the kite now (rad)."""
        pos, R = self.kite.poses()
        phi, eps = window_coordinates(pos[0], centre)
        return phi, eps, heading(R[0] @ self.nose_axis, phi, eps)

    def targets(self, pilot, t):
        """World positions (m) of the two handles at time t (s)."""
        if t >= self.next - 1e-9:
            self.next = t + self.period
            self._decide(pilot, t)
        forward = pilot.R0[:, 0] * np.array([1.0, 1.0, 0.0])
        forward /= np.linalg.norm(forward)
        # the inner hand pulls back, the outer gives forward its share (outer) of the throw
        inner = (2.0 - self.p.outer) * abs(self.u) * self.p.throw
        outer = self.p.outer * abs(self.u) * self.p.throw
        left, right = (inner, -outer) if self.u > 0 else (-outer, inner)
        back = self.p.brace if self.phase != HOLD else 0.0
        return pilot.rest - np.outer([left + back, right + back], forward)

    def stance(self, pilot, t):
        """How far (m) behind its place the pilot wants to stand (``Pilot`` walks there)."""
        return self.back

    def _closing(self, pilot):
        """The kite's speed (m/s) towards the hands: a line going slack."""
        pos, _ = self.kite.poses()
        r = pos[0] - pilot.hx.mean(axis=0)
        v = self.kite.velocities()[0][0] - pilot.hv.mean(axis=0)
        return -float(v @ r) / max(float(np.linalg.norm(r)), 1e-9)

    def _decide(self, pilot, t):
        phi, eps, chi = self.observe(pilot.rest.mean(axis=0))
        rate = 0.0
        if self.last is not None:
            step = _wrap(chi - self.last)
            if self.phase == TURN and self.side * step < -FLIP:
                step += self.side * 2.0 * math.pi  # the nose flipped through, on in the turn
            self.turned += step
            rate = step / self.period
        self.last = chi
        p = self.p
        # the feet: step back while a line goes slack or the kite turns, home while it pulls
        walk = pilot.params.walk_speed * self.period
        if self._closing(pilot) > p.slack or (self.phase != HOLD and p.step_in_turn):
            self.back = min(pilot.back + walk, pilot.params.walk)
        else:
            self.back = max(pilot.back - p.home_speed * self.period, 0.0)
        ready = eps >= math.radians(p.ready) and abs(chi) < SETTLED
        if (self.phase == HOLD and p.manoeuvre != "hold" and ready
                and t >= p.start + self.count * p.every):
            self.side = 1 if self.count % 2 == 0 else -1
            self.count += 1
            self.log.append([p.manoeuvre, self.side, t, None])
            self.phase, self.turned, self.since = TURN, 0.0, t
        elif self.phase == RECOVER and ready:  # the eight's second loop, the other way
            self.side, self.phase, self.turned, self.since = -self.side, TURN, 0.0, t
        if self.phase == TURN:
            # the commanded heading turns at 2 pi / period; steer by the error from it
            w = 2.0 * math.pi / p.period
            want = min(w * (t - self.since), 2.0 * math.pi)
            err = want - self.side * self.turned
            self.u = float(np.clip(self.side * (p.feed + p.turn_gain * err
                                                - p.turn_damping * (self.side * rate - w)),
                                   -1.0, 1.0))
            ahead = max(0.0, self.side * rate) * p.lead
            if self.side * self.turned + ahead >= 2.0 * math.pi:
                eight = p.manoeuvre == "figure8" and self.side == self.log[-1][1]
                self.phase = RECOVER if eight else HOLD
            if self.phase == TURN:
                return
        if (self.phase == HOLD and self.log and self.log[-1][3] is None
                and self.side * self.turned >= 2.0 * math.pi):
            self.log[-1][3] = t  # the nose has come round a full circle: the loop is done
        tilt = math.radians(p.hold_tilt) * float(np.clip((eps - LOW[0]) / (LOW[1] - LOW[0]),
                                                         0.0, 1.0))
        self._steer(float(np.clip(-p.gain * (phi - math.radians(p.target)), -tilt, tilt)),
                    chi, rate)

    def _steer(self, want, chi, rate):
        """Steer the nose towards heading ``want`` (rad), damped by its rate of turn."""
        lim = self.p.hold_limit
        self.u = float(np.clip(self.p.turn_gain * _wrap(want - chi)
                               - self.p.turn_damping * rate, -lim, lim))

    # --- memory, for checkpoints -----------------------------------------------------------------
    def capture(self) -> dict:
        log = np.array([[MANOEUVRES.index(k), s, a, np.nan if b is None else b]
                        for k, s, a, b in self.log]).reshape(-1, 4)
        return {"state": np.array([self.u, self.next, self.turned,
                                   np.nan if self.last is None else self.last,
                                   self.phase, self.side, self.count, self.since,
                                   self.back]), "log": log}

    def restore(self, snap: dict):
        u, nxt, turned, last, phase, side, count, since, back = snap["state"]
        self.since, self.back = float(since), float(back)
        self.u, self.next, self.turned = float(u), float(nxt), float(turned)
        self.last = None if math.isnan(last) else float(last)
        self.phase, self.side, self.count = int(phase), int(side), int(count)
        self.log = [[MANOEUVRES[int(k)], int(s), float(a), None if math.isnan(b) else float(b)]
                    for k, s, a, b in snap["log"]]
