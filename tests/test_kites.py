"""Kites (issue 18): a flat plate on its lines settles where lift, drag, weight and tension
balance (computed here independently of the simulation); the ties between a kite's
components are equal and opposite; a carried sail moves with its frame; a tension-only line
never pushes; the tail's drag follows its law; bad input (a line too short, a wind too weak,
a bridle point off the spine) is refused with a message or reported as the kite coming down.
Long flights are marked slow."""
import math

import numpy as np
import pytest
from scipy.optimize import brentq

from interplay.errors import ParameterError
from interplay.geometry.kite import DiamondParams, StuntParams, diamond, frame_inertia, stunt
from interplay.interactions.aero import AeroParams, CordDrag, CordDragParams
from interplay.interactions.attachment import AttachmentParams, SegmentAttachment
from interplay.kernels.rigid import quat_to_matrix
from interplay.params import apply
from interplay.scene import Scene
from interplay.scenes import kite_parts as KP
from interplay.scenes import kites, stunt_kite
from interplay.systems.rigid import RigidBody
from interplay.systems.springmass import SpringNetwork, Springs
from interplay.systems.static import StaticPlane
from interplay.systems.wind import FlowPrimitive, WindField

G = np.array([0.0, 0.0, -9.81])


def uniform_wind(speed):
    return WindField("wind", [FlowPrimitive("uniform", axis=(1, 0, 0), strength=speed)])


# --- a flat plate on its lines ----------------------------------------------------------------
PLATE = StuntParams(dihedral=0.0, ballast=0.1, tow=0.36, tow_height=0.6)  # a stunt design
SAIL = KP.SailParams(slack=0.0, resolution=4)  # cut to its frame: as flat as the cloth allows


def sail_loads(x, tris, speed, aero=AeroParams()):
    """Per-triangle drag and lift (SPEC 2.2) on a sail at rest, points x (n,3) m, in a wind of
    ``speed`` m/s along +x: (forces (t,3) N, centroids (t,3) m). Plain NumPy."""
    cr = np.cross(x[tris[:, 1]] - x[tris[:, 0]], x[tris[:, 2]] - x[tris[:, 0]])
    s = 0.5 * np.linalg.norm(cr, axis=1)
    n = cr / (2.0 * s[:, None])
    v = np.array([-speed, 0.0, 0.0])  # the air's velocity relative to the sail
    vn = n @ v
    f = (-aero.drag * s[:, None] * speed * vn[:, None] * n
         - aero.friction * s[:, None] * (v - vn[:, None] * n))
    return f, x[tris].mean(axis=1)


def balance(x, tris, masses, frame_mass, frame_centre, tow, speed):
    """The moment (N m) about ``tow`` of the air on the sail and the sail's and the frame's
    weights, and the force (N) the line must balance."""
    f, c = sail_loads(x, tris, speed)
    moment = (np.cross(c - tow, f).sum(0) + np.cross(x - tow, masses[:, None] * G).sum(0)
              + np.cross(frame_centre - tow, frame_mass * G))
    return moment, f.sum(0) + (masses.sum() + frame_mass) * G


def plate_equilibrium(g, speed):
    """The design's sail flat: the pitch (rad, of the spine from downwind +x, in the x-z
    plane) at which the moment about the axis through the two towing points vanishes and is
    restoring, and there the line's elevation (rad, along the force the tension balances)
    and the tension (N)."""
    fi = frame_inertia(g.spars, g.spar_radius, g.spar_density, g.ballast)
    m = KP.sail_network("s", g, SAIL, np.zeros(3), np.eye(3), None).contact_view().masses
    pivot = 0.5 * (g.bridles[0][1] + g.bridles[1][1])

    def loads(th):
        nose = np.array([math.cos(th), 0.0, math.sin(th)])
        face = np.array([-math.sin(th), 0.0, math.cos(th)])  # the windward normal
        R = np.stack([nose, np.cross(face, nose), face], axis=1)
        return balance(g.sail @ R.T, g.triangles, m, fi.mass, R @ fi.centre, R @ pivot, speed)

    grid = np.radians(np.linspace(91.0, 179.5, 300))
    my = np.array([loads(t)[0][1] for t in grid])
    # restoring: a pitch up (theta growing) meets a moment about +y that grows (turns it back)
    roots = [brentq(lambda t: loads(t)[0][1], a, b) for a, b, ma, mb in
             zip(grid[:-1], grid[1:], my[:-1], my[1:]) if ma < 0.0 < mb]
    assert len(roots) == 1
    total = loads(roots[0])[1]
    return roots[0], math.atan2(total[2], total[0]), float(np.linalg.norm(total))


def test_flat_plate_on_its_lines_settles_at_the_equilibrium_angle():
    speed, g = 6.0, stunt(PLATE, n=4)
    pitch, elevation, _ = plate_equilibrium(g, speed)
    scene = Scene("plate", duration=16.0, fps=20.0, coupling_dt=1.0 / 240.0)
    ground = scene.add(StaticPlane("ground"))
    wind = scene.add(uniform_wind(speed))
    # a short light line without drag: straight, so its elevation is the tension's direction
    parts = KP.KiteParams(sail=SAIL, line=KP.LineParams(length=6.0, segments=6, density=1e-5),
                          tail=KP.TailParams(length=0.0),
                          cord_air=CordDragParams(drag=0.0, friction=0.0))
    pivot = 0.5 * (g.bridles[0][1] + g.bridles[1][1])
    anchors = [np.array([0.0, b[1][1], 0.0]) for b in g.bridles]  # staked under each line
    pos, R = KP.launch_pose(np.zeros(3), 6.0, 45.0, pivot, pitch_deg=-60.0)
    kite = KP.build_kite(scene, "plate", g, parts, wind, ground, pos, R, anchors)
    res = scene.simulate()
    fr, fi = res.frames["plate-frame"], kite.frame.inertia
    late = fr["t"] >= 8.0  # after the launch's swing: two periods of its slight rocking
    masses = kite.sail.contact_view().masses
    pitches, elevations, moments, totals = [], [], [], []
    for p, q, x in zip(fr["position"][late], fr["orientation"][late],
                       np.asarray(res.frames["plate-sail"]["points"])[late]):
        Rk = quat_to_matrix(q) @ fi.axes.T  # kite coordinates to the world
        pitches.append(math.atan2(Rk[2, 0], Rk[0, 0]))
        tow = p + Rk @ (pivot - fi.centre)
        elevations.append(math.atan2(tow[2], math.hypot(tow[0], tow[1])))
        m, total = balance(x, g.triangles, masses, fi.mass, p, tow, speed)
        moments.append(m)
        totals.append(total)
    # 1. Against the flat plate: the cloth billows and its free trailing edge luffs, which
    # moves its centre of pressure by about a centimetre, ~2 deg of pitch by this balance's
    # sensitivity; the time step's error is far below that (a 1/240 s coupling step on a
    # ~4 s rocking, averaged over two periods of +-0.5 deg).
    assert math.degrees(abs(np.mean(pitches) - pitch)) < 2.5
    assert math.degrees(abs(np.mean(elevations) - elevation)) < 2.5
    # 2. Against the sail's own shape as simulated (the same law in plain NumPy on the
    # recorded points): the moment about the towing axis vanishes (below 1% of the air's
    # force times the 0.85 m chord), the line lies along the force it balances (the rocking
    # averages to 0.5 deg) and pulls the frame with it (2%): the ties, the carried sail and
    # the bridle pass the loads on whole. (Its tension, 3.3 N, is the cloth's: the flat
    # plate's is 5.3 N.)
    total = np.mean(totals, axis=0)
    chord = 0.85 * np.linalg.norm(total)
    assert abs(np.mean(moments, axis=0)[1]) < 0.01 * chord
    assert math.degrees(abs(math.atan2(total[2], total[0]) - np.mean(elevations))) < 0.5
    bridle = res.logs["plate-bridle"]
    pull = np.linalg.norm(bridle.force[bridle.t >= 8.0].mean(axis=0))
    assert pull == pytest.approx(np.linalg.norm(total), rel=0.02)


# --- the ties between components ---------------------------------------------------------------
def cord(name, start, n=6, seg=0.2, mass=0.01, k=400.0):
    x = np.asarray(start, float) + np.outer(np.arange(n), [0.0, 0.0, -seg])
    springs = Springs(np.arange(n - 1), np.arange(1, n), np.full(n - 1, seg),
                      np.full(n - 1, k), np.ones(n - 1, dtype=bool))
    return SpringNetwork(name, x, mass, springs, dt=1.0 / 240.0, integrator="implicit",
                         stiffness_damping=1e-3, cg_tolerance=1e-12)


def momentum(res, body, net, masses, M):
    """Total linear momentum (kg m/s) at every coupling sample: the body's and the network's."""
    tb, tn = res.tracks[body], res.tracks[net]
    pb = M * tb.xdot[:, :3]
    pn = (masses[None, :, None] * tn.xdot.reshape(len(tn.t), -1, 3)).sum(axis=1)
    return tb.t, pb + pn


def test_ties_are_equal_and_opposite():
    # A tumbling body (1 kg, 0.05 kg m^2: heavy beside what its ties drag along in a step,
    # k h^2 << I / r^2, as the explicit side of a tie needs) with a cord tied to two of its
    # points, in gravity, no air: every tie force on the cord is returned on the body, so
    # the total momentum changes by the weight alone. Exact up to the cord's conjugate-
    # gradient tolerance (1e-12) and round-off: relative 1e-9.
    scene = Scene("ties", duration=1.0, fps=30.0, coupling_dt=1.0 / 240.0)
    M = 1.0
    body = scene.add(RigidBody("body", M, [0.05, 0.05, 0.05], 1.0 / 240.0,
                               position=(0, 0, 5.0), velocity=(1.0, 0.5, 2.0),
                               angular_velocity=(1.0, -1.0, 2.0)))
    net = scene.add(cord("cord", (0.3, 0.0, 5.0)))  # from the body's point (0.3, 0, 0)
    scene.connect(SegmentAttachment("tie", body, net, [(0, "body"), (5, "body")],
                                    np.array([[0.3, 0.0, 0.0], [0.3, 0.0, -1.0]]),
                                    AttachmentParams(stiffness=300.0, damping=0.5)))
    res = scene.simulate()
    masses = net.contact_view().masses
    t, p = momentum(res, "body", "cord", masses, M)
    expected = p[0] + np.outer(t - t[0], (M + masses.sum()) * G)
    assert res.logs["tie"].peak.max() > 0.1  # N: the ties pulled
    np.testing.assert_allclose(p, expected, atol=1e-9 * np.abs(p).max())


def test_a_carried_sail_falls_with_its_frame():
    # Carried (carry=True), the frame moves as frame and sail joined: in free fall, no air
    # and no mass damping on the sail (it would be a drag), both fall at g and the sail
    # stays where it was tied (to the sail's CG tolerance, 1e-6, and round-off).
    g = diamond(DiamondParams(), n=4)
    scene = Scene("carried", duration=0.5, fps=30.0, coupling_dt=1.0 / 240.0)
    pos, R = np.array([0.0, 0.0, 10.0]), np.eye(3)
    frame = scene.add(KP.frame_body("frame", g, pos, R, 1.0 / 240.0))
    sail = scene.add(KP.sail_network("sail", g, KP.SailParams(slack=0.0, mass_damping=0.0),
                                     pos, R, None))
    local = (g.sail[g.ties] - frame.inertia.centre) @ frame.inertia.axes
    scene.connect(SegmentAttachment("ties", frame, sail, [(int(i), "frame") for i in g.ties],
                                    local, KP.SailParams().ties, carry=True))
    x0 = sail.x.copy()
    res = scene.simulate()
    t = res.tracks["frame"].t
    np.testing.assert_allclose(res.tracks["frame"].xdot[:, 2], G[2] * t, atol=1e-9)
    # it hardly turns: the sail's weight is offset from the frame's centre (S = sum m r,
    # ~0.6 g m), and carried without its mass moment's drag (I alpha = tau - S x a) it would
    # turn the frame by ~10 deg in this half second (a quaternion component of ~0.09). The
    # drag is taken over the last step, so the first step, with none yet, leaves a spin of
    # S g h / I: 0.23 deg by the end (a component of 2.0e-3).
    q = res.tracks["frame"].x[:, 3:7]
    assert np.abs(q - q[0]).max() < 3e-3
    # and the sail falls with it: its mean drop to 0.5 mm, its shape to within the implicit
    # step's own free-fall error, g h t / 2 = 10 mm (the frame's step is exact)
    d = sail.x - x0
    assert abs(d[:, 2].mean() - 0.5 * G[2] * t[-1] ** 2) < 5e-4
    assert np.abs(d - d.mean(axis=0)).max() < 0.5 * 9.81 * t[-1] / 240.0


# --- a tension-only line ---------------------------------------------------------------------
@pytest.mark.parametrize("tension_only", [True, False])
def test_a_tension_only_line_never_pushes(tension_only):
    # The flying line as the kites build it, laid out at half its length (every segment
    # compressed to half its rest length), its hand end fixed, no gravity: a tension-only
    # line lies where it is, untouched; one that could push springs out (the control case).
    net, index = KP.line_network("line", [np.array([0.0, 0.0, 0.0])],
                                 [np.array([5.0, 0.0, 0.0])], KP.LineParams(length=10.0,
                                                                            segments=10),
                                 [np.array([[0.05, 0.0, 0.1], [-0.05, 0.0, 0.1]])])
    net.tension_only[:] = tension_only
    net.gravity[:] = 0.0
    net.fixed[index[0][2]] = True
    x0 = net.x.copy()
    for _ in range(48):
        net.clear_forces()
        net.advance(1.0 / 240.0)
    moved = np.abs(net.x - x0).max()
    if tension_only:
        assert moved == 0.0
    else:
        assert moved > 0.1


# --- the tail's drag ---------------------------------------------------------------------------
def test_the_tails_drag_matches_its_law():
    # A straight tail at rest, at 30 deg to a 7 m/s wind: each string segment feels the
    # cross-flow drag of a cylinder on the wind across it, 1/2 rho C_D d l |u_n| u_n, and skin
    # friction along it, 1/2 rho C_f pi d l |u_t| u_t (Hoerner 1965); each bow the drag of a
    # bluff body, 1/2 rho C_D A |u| u. Closed form to round-off.
    p = KP.TailParams(length=2.0, segments=8, bow_every=2, bow_area=0.01)
    a = math.radians(30.0)
    direction = np.array([math.cos(a), 0.0, -math.sin(a)])
    tail, bows = KP.tail_network("tail", (0.0, 0.0, 3.0), direction, p, None)
    air = CordDragParams(bow_area=p.bow_area)
    drag = CordDrag("air", uniform_wind(7.0), tail, air, bows)
    _, _, total = drag.forces()
    u = np.array([7.0, 0.0, 0.0])
    ut = (u @ direction) * direction
    un = u - ut
    d = 2.0 * p.radius
    string = 0.5 * air.density * p.length * (air.drag * d * np.linalg.norm(un) * un
                                             + air.friction * math.pi * d
                                             * np.linalg.norm(ut) * ut)
    bow = 0.5 * air.density * air.bow_drag * p.bow_area * np.linalg.norm(u) * u * len(bows)
    assert len(bows) == 4
    np.testing.assert_allclose(total, string + bow, rtol=1e-12)


# --- bad input ---------------------------------------------------------------------------------
def test_a_line_too_short_is_refused():
    with pytest.raises(ParameterError, match=r"kite diamond: a 5\.0 m line .* at least 9\.\d m"):
        kites.build(duration=1.0, params=apply(kites.KitesParams(),
                                               {"diamond_parts.line.length": "5"}))


def test_a_bridle_off_the_spine_is_refused():
    # the towing point past the spine's foot: by its domain from the command line, by the
    # design itself when built in code
    with pytest.raises(ParameterError, match=r"kite\.tow=1\.4: out of range.* <= 1"):
        apply(stunt_kite.StuntKiteParams(), {"kite.tow": "1.4"})
    with pytest.raises(ParameterError, match="stunt: tow must be a fraction in"):
        stunt(StuntParams(tow=1.4))


def test_a_wind_too_weak_lets_the_kites_down():
    # 1 m/s at 10 m: too little lift for any of them; each is reported as coming down
    params = apply(kites.KitesParams(), {"wind.speed": "1.0"})
    res = kites.build(duration=8.0, fps=10.0, params=params).simulate()
    for name in kites.KITES:
        f = kites.flight(res, name)
        assert f["crashed"] and f["flew_s"] < 8.0, (name, f)


# --- the scenes' flights (long) --------------------------------------------------------------
@pytest.mark.slow
def test_the_single_line_kites_fly_and_the_diamond_needs_its_tail():
    res = kites.build(duration=120.0, fps=10.0).simulate()
    for name in kites.KITES:
        f = kites.flight(res, name)
        assert not f["crashed"] and f["flew_s"] >= 120.0, (name, f)
        assert 40.0 <= f["elevation_mean_deg"] <= 65.0, (name, f)
    # without its tail the diamond comes down: in the surface layer's turbulence it wanders
    # off, dives and hits the ground within 30 s (measured 26 s, docs/kites.md); with it, the
    # same gusts keep it up for the whole 120 s (asserted above)
    bare = kites.flight(kites.build(duration=60.0, fps=10.0, kites=("diamond",), params=apply(
        kites.KitesParams(), {"diamond_parts.tail.length": "0"})).simulate(), "diamond")
    assert bare["crashed"] and bare["flew_s"] < 60.0, bare


@pytest.mark.slow
def test_the_stunt_kite_flies_a_figure_8():
    """Gust seed 5, the figure-8: both loops done and the kite up, both lines taut (pulling
    more than five times their weight) at least 95% of the time after the launch (measured
    over seeds 0-9 in docs/kites.md)."""
    p = apply(stunt_kite.StuntKiteParams(), {"wind.seed": "5", "control.manoeuvre": "figure8"})
    res = stunt_kite.build(duration=20.0, fps=10.0, params=p).simulate()
    figures = stunt_kite.figures(res)
    assert figures["figure8 1 (left) s"] is not None, figures
    assert figures["came down at s"] is None, figures
    assert min(figures["l_handle taut share"], figures["r_handle taut share"]) >= 0.95, figures


@pytest.mark.slow
def test_the_stunt_kite_over_ten_gust_seeds():
    """The issue's measure over gust seeds 0-9, the loop manoeuvre: in every seed the first
    loop (to the left, from 8 s) takes 4 s or less and the second (to the right, from 20 s)
    is under way; the kite stays up and both lines stay taut at least 95% of the time after
    the launch."""
    for seed in range(10):
        p = apply(stunt_kite.StuntKiteParams(), {"wind.seed": str(seed)})
        res = stunt_kite.build(duration=22.0, fps=10.0, params=p).simulate()
        figures = stunt_kite.figures(res)
        assert figures["loop 1 (left) s"] is not None, (seed, figures)
        assert figures["loop 1 (left) s"] <= 4.0, (seed, figures)
        assert figures["came down at s"] is None, (seed, figures)
        assert min(figures["l_handle taut share"], figures["r_handle taut share"]) >= 0.95, \
            (seed, figures)
