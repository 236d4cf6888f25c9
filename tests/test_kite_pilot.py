"""The stunt pilot (issue 18) without a kite simulation: a kite stand-in is placed in the wind
window by hand and the controller's answers are checked against what a flyer does. A turn is
a steering difference that follows a commanded heading rate (feedback on the measured
heading), a nose flipping through in a turn is counted on in the turn, the inner hand pulls
back while the outer holds, and the flyer steps back, no faster than it walks, when the kite
comes towards it (a line going slack) and walks home while it pulls. Each test runs in well
under a second."""
import math
from dataclasses import replace

import numpy as np
import pytest

from interplay.control.kite_pilot import StuntPilot, StuntPilotParams, heading
from interplay.systems.pilot import Pilot, PilotParams

LINE = 25.0  # m


class KiteStandIn:
    """A kite frame's contact view reduced to what the pilot reads: one part's pose and
    velocity, set by the test. The nose is the part's local x axis."""

    def __init__(self):
        self.pos = np.zeros((1, 3))
        self.R = np.eye(3)[None]
        self.vel = np.zeros((1, 3))

    def place(self, hands, phi_deg, eps_deg, chi_deg, radial_speed=0.0):
        """At azimuth phi and elevation eps (deg) on the window LINE m from ``hands``, its
        nose at heading chi (deg: 0 up, + to the pilot's left), moving outwards at
        radial_speed (m/s; negative: towards the hands)."""
        phi, eps, chi = (math.radians(a) for a in (phi_deg, eps_deg, chi_deg))
        out = np.array([math.cos(eps) * math.cos(phi), math.cos(eps) * math.sin(phi),
                        math.sin(eps)])
        up = np.array([-math.sin(eps) * math.cos(phi), -math.sin(eps) * math.sin(phi),
                       math.cos(eps)])
        left = np.cross(up, out)  # +y at phi = 0: the pilot's left
        nose = math.cos(chi) * up + math.sin(chi) * left
        self.pos[0] = hands + LINE * out
        self.R[0] = np.stack([nose, np.cross(out, nose), out], axis=1)
        self.vel[0] = radial_speed * out

    def poses(self):
        return self.pos.copy(), self.R.copy()

    def velocities(self, parts=None):
        return self.vel.copy(), np.zeros((1, 3))


def flyer(walk=4.0, **control):
    kite = KiteStandIn()
    pilot = Pilot("pilot", PilotParams(walk=walk))
    ctl = StuntPilot(kite, (1.0, 0.0, 0.0), replace(StuntPilotParams(), **control))
    pilot.controller = ctl
    return pilot, ctl, kite


def look(pilot, ctl, t):
    """One look of the controller at time t (s); the handle targets it asks for."""
    ctl.next = t
    return ctl.targets(pilot, t)


def test_the_stand_in_reads_back_its_heading():
    # the controller's window coordinates are what the stand-in was placed at (round-off)
    pilot, ctl, kite = flyer()
    kite.place(pilot.rest.mean(axis=0), 12.0, 35.0, 40.0)
    phi, eps, chi = ctl.observe(pilot.rest.mean(axis=0))
    assert np.degrees([phi, eps, chi]) == pytest.approx([12.0, 35.0, 40.0], abs=1e-9)
    assert math.degrees(heading(kite.R[0][:, 0], phi, eps)) == pytest.approx(40.0, abs=1e-9)


def test_a_turn_follows_its_commanded_heading_rate():
    """Parked high with the nose up, the loop begins: the command is full steering to the
    left while the nose lags the commanded heading; a nose that turns faster than 2 pi /
    period is steered back (feedback, not a fixed pull)."""
    pilot, ctl, kite = flyer(manoeuvre="loop", start=0.0, ready=30.0, period=4.0)
    c = pilot.rest.mean(axis=0)
    kite.place(c, 0.0, 40.0, 0.0)
    look(pilot, ctl, 1.0)
    assert ctl.phase == 1 and ctl.u == 1.0  # turning, to the left, fully
    kite.place(c, 0.0, 40.0, 30.0)  # 30 deg in 0.05 s: 600 deg/s, far ahead of 90 deg/s
    look(pilot, ctl, 1.05)
    assert ctl.u < 0.0
    kite.place(c, 0.0, 40.0, 31.0)  # then it stalls: by 1.5 s the command (45 deg) is ahead
    for k in range(2, 11):
        look(pilot, ctl, 1.0 + 0.05 * k)
    assert ctl.u == 1.0


def test_a_nose_flipping_through_in_a_turn_counts_on():
    # a left turn's heading jumping from +120 deg to -60 deg in one look went on through
    # the bottom (+180 deg the turn's way), not back by 180
    pilot, ctl, kite = flyer(manoeuvre="loop", start=0.0, ready=30.0)
    c = pilot.rest.mean(axis=0)
    kite.place(c, 0.0, 40.0, 0.0)
    look(pilot, ctl, 1.0)
    for k, chi in enumerate((40.0, 80.0, 120.0, -60.0)):
        kite.place(c, 0.0, 40.0, chi)
        look(pilot, ctl, 1.05 + 0.05 * k)
    assert math.degrees(ctl.turned) == pytest.approx(300.0, abs=1e-9)


def test_the_inner_hand_pulls_and_the_outer_holds():
    pilot, ctl, kite = flyer(outer=0.0, throw=0.15, brace=0.1, manoeuvre="hold")
    fwd = pilot.facing
    ctl.u, ctl.next = 1.0, 1e9  # steering held between looks
    left, right = (ctl.targets(pilot, 0.0) - pilot.rest) @ fwd
    assert left == pytest.approx(-0.30) and right == pytest.approx(0.0)  # holding: no brace
    ctl.phase = 1
    left, right = (ctl.targets(pilot, 0.0) - pilot.rest) @ fwd
    assert left == pytest.approx(-0.40) and right == pytest.approx(-0.10)  # braced in a turn
    ctl.phase, ctl.u = 0, -0.5
    left, right = (ctl.targets(pilot, 0.0) - pilot.rest) @ fwd
    assert left == pytest.approx(0.0) and right == pytest.approx(-0.15)


def test_the_flyer_steps_back_as_a_line_slackens_and_walks_home():
    """The kite coming towards the hands at 3 m/s: the flyer walks back at its walking speed
    (1.5 m/s: 0.15 m in 0.1 s, to round-off), never farther than ``walk``; with the kite
    pulling again it walks home at home_speed."""
    pilot, ctl, kite = flyer(walk=0.5, manoeuvre="hold")
    c = pilot.rest.mean(axis=0)
    kite.place(c, 0.0, 40.0, 0.0, radial_speed=-3.0)
    start = pilot.base.copy()
    for _ in range(24):  # 0.1 s in the pilot's own steps
        pilot.step(1.0 / 240.0)
    back = float((start - pilot.base) @ pilot.facing)
    assert back == pytest.approx(0.15, abs=1.5 * 0.05 + 1e-9)  # within one look's walk
    assert np.allclose(pilot.base - start, -back * pilot.facing)
    for _ in range(120):
        pilot.step(1.0 / 240.0)
    assert pilot.back == pytest.approx(pilot.params.walk)  # as far as it may go
    kite.place(pilot.rest.mean(axis=0), 0.0, 40.0, 0.0, radial_speed=0.0)
    for _ in range(240):
        pilot.step(1.0 / 240.0)
    assert pilot.params.walk - pilot.back == pytest.approx(0.3, abs=0.3 * 0.05 + 1e-9)
