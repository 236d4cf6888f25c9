"""The floor mat (issue 17): the mat's statics against a static solve; the stand-in's fitted
curve against the mat's measured load-deflection; the hybrid coupling invariants (her pass
never reads the mat); equal and opposite forces in two-way; a vault that misses the mat.
Slow: the default run's landing."""
from dataclasses import replace

import numpy as np
import pytest

pytest.importorskip("mujoco")

from interplay.cli.command import main  # noqa: E402
from interplay.errors import SceneError  # noqa: E402
from interplay.geometry.mat import MatParams  # noqa: E402
from interplay.scenes import mat as M  # noqa: E402
from contact_checks import equal_and_opposite_every_step  # noqa: E402
from static_reference import rest_under_load  # noqa: E402

G = 9.81
H = 1e-3  # s, the coupling step
SMALL = MatParams(length=0.6, width=0.4, nx=7, ny=5, nz=3)  # 105 points: a statics test


def _static_solve(net, load):
    """A slow reference: the mat's rest under the load as the minimum of its potential energy
    (springs, gravity, the load) by L-BFGS from the unloaded block, bottom held."""
    free = np.setdiff1d(np.arange(len(net.x)), net.bottom)
    f = np.zeros_like(net.x)
    f[:, 2] = -M.pressure_loads(net, load)
    f[:, 2] -= net.m * G
    return rest_under_load(net, f, free, gtol=1e-8, ftol=1e-16)


def test_mat_under_load_rests_at_the_static_solution():
    """Two feet's worth of load (a 64 kg gymnast standing, 631 N, over the central 0.3 m
    square) on a small mat: its relaxation (damped backward Euler, the load ramped) and a
    static solve agree on the depression. Tolerance: both end with residual forces r below
    0.01 N per point; the mat's vertical stiffness there is K ~ 4e4 N/m (load / depression),
    so they agree to 2 r / K < 1e-6 m; 1e-5 m leaves room for the relaxation's last step."""
    load = 631.0
    net = M.mat_network(SMALL, "implicit")
    got = M.press(net, load, seconds=1.0)
    x_ref, residual = _static_solve(M.mat_network(SMALL, "implicit"), load)
    ref = SMALL.thickness - x_ref[net.top, 2].min()
    assert residual < 0.01
    assert abs(got - ref) < 1e-5
    assert 0.005 < got < 0.1  # foam, not a trampoline: centimetres under a standing gymnast


def _centre_sag(p, load, half):
    """The depression (m) of the top's centre point under ``load`` (N) as a pressure over the
    central square of side 2 ``half`` (m; the whole top if it is larger), less its sag under
    its own weight."""
    def sag(f):
        net = M.mat_network(p, "implicit")
        M.press(net, f, half=half)
        top = net.x[net.top]
        c = np.argmin(np.hypot(top[:, 0] - top[:, 0].mean(), top[:, 1]))
        return p.thickness - top[c, 2]
    return sag(load) - sag(0.0)


def test_the_foam_under_an_even_pressure_is_an_isotropic_solid():
    """A pressure p over the whole top of the default mat (bottom held): far from its edges
    (0.8 m, four thicknesses) the block is in uniaxial strain, so its centre sinks
    p T / C33 with C33 = 6 E / 5, the foam's (E, nu = 1/4: geometry/mat.foam_weights) at any
    resolution. A lattice that holds the elastic constants is exact under a uniform strain;
    what is left is the springs' geometric nonlinearity at the 1% strain used (the diagonals'
    stretch is linear in the strain to 1%) and the relaxation: 2%."""
    p = MatParams()
    pressure = 0.01 * 1.2 * p.modulus  # Pa: a 1% strain
    got = _centre_sag(p, pressure * p.length * p.width, 10.0)
    assert got == pytest.approx(pressure * p.thickness / (1.2 * p.modulus), rel=0.02)


def test_the_mats_deflection_does_not_depend_on_its_resolution():
    """Four body weights (2575 N, a landing's standing-to-impact range) as a pressure over
    the central 0.3 m square: the default lattice (46 x 37 x 4 points, top 0.067 x 0.044 m)
    and a coarse one (31 x 17 x 4, 0.1 x 0.1 m) sink alike, the foam's and the cover's
    springs both derived from their materials per cell (foam_weights, cover_springs).
    Tolerance 5%: what the two lattices' discretisation leaves of a load 3 to 7 cells wide
    (measured 1.6%; a finer 61 x 33 x 4 lattice is within 2.2% of both); the springs stated
    per spring, as before (k = cover / length on the top), differed by 45% (ny 17 to 33)."""
    fine = MatParams()
    coarse = replace(fine, nx=31, ny=17)
    a, b = _centre_sag(fine, 2575.0, 0.15), _centre_sag(coarse, 2575.0, 0.15)
    assert 0.02 < a < 0.06  # centimetres: the landing's range, not the lattice's collapse
    assert b == pytest.approx(a, rel=0.05)


def test_shipped_stand_in_reproduces_the_mats_load_deflection():
    """The stand-in's curve (the shipped defaults, ``interplay fit-standin mat``) gives the
    load the default mat carries under a rigid flat sole pressed to the same depth, within
    10%, over the landing's range (0.01, 0.05 and 0.09 m: 1.2 to 16 body weights; the
    default landing's peak is about 11; past 0.09 m the linear lattice gives way under the
    sole's edge, FIT_DEPTHS)."""
    p = M.MatSceneParams()
    rows = M.load_deflection(p.mat, (0.01, 0.05, 0.09))
    model = p.standin.force(rows[:, 1])
    assert np.all(np.abs(model - rows[:, 0]) <= 0.10 * rows[:, 0])
    # and the mat stiffens as foam under a cover does: its secant stiffness rises with load
    assert np.all(np.diff(rows[:, 0] / rows[:, 1]) > 0)


@pytest.mark.slow
def test_shipped_stand_in_reproduces_the_mats_impactor_drops():
    """The stand-in's damping (fitted by ``fit-standin`` to the mat's impactor drops) with
    its curve: the 24 kg impactor dropped 0.5, 1 and 2 m on it (a 1-D drop on the stand-in's
    law, mat_impact.standin_drop) peaks within 10% of the mat's peak force (1 ms mean) and
    rebounds within 10% of the mat's rebound speed (the issue's tolerance for the stand-in's
    fit). The mat's drops are 0.25 s each at its 4e-5 s step."""
    from interplay.scenes.mat_impact import drop_test, standin_drop
    p = M.MatSceneParams()
    mat = drop_test(p.mat, (0.5, 1.0, 2.0))
    stand = standin_drop(p.standin, (0.5, 1.0, 2.0))
    for m, s in zip(mat, stand):
        for key in ("peak_mean_force_N", "rebound_m_s"):
            assert abs(s[key] - m[key]) <= 0.10 * m[key], (key, m, s)


@pytest.mark.slow
def test_shipped_stand_in_is_anchored_by_the_mats_shear_under_a_sole():
    """The stand-in's tangential springs (``stick``, ``stick_damping``) are the mat's measured
    sideways stiffness under one of her soles held flat at her standing depth, over the four
    corners that hold it, and the foam's retardation time times that (``fit_stick``): the
    shipped values within 1% (they were rounded from the fit); and the mat's stiffness
    under a sole is a stiff, local one (within a factor 2 of the same along x and along y,
    above 1e5 N/m: the foam around the sole takes the shear, not only the points under it)."""
    p = M.MatSceneParams()
    fit = M.fit_stick(p, p.standin)
    assert p.standin.stick == pytest.approx(fit["stick"], rel=0.01)
    assert p.standin.stick_damping == pytest.approx(fit["stick_damping"], rel=0.01)
    kx, ky = fit["sole_shear_N_per_m"]
    assert 0.5 < kx / ky < 2.0 and min(kx, ky) > 1e5


def _pass(params, coupling="hybrid", duration=1.0):
    return M.build(coupling, duration=duration, params=params).simulate(primary_only=True)


def test_hybrid_primary_pass_never_reads_the_mat():
    """Her hybrid pass is the same, bit for bit, whatever the mat is (a mat twice as stiff,
    heavier, coarser): the stand-in alone acts on her; and with the stand-in off it is the
    one-way pass (she falls through to the floor)."""
    p = M.MatSceneParams()
    other = replace(p, mat=replace(p.mat, modulus=2.2e5, mass=60.0, nx=31, ny=17, nz=3))
    a, b = _pass(p), _pass(other)
    ta, tb = a.tracks["gymnast"], b.tracks["gymnast"]
    assert np.array_equal(ta.x, tb.x) and np.array_equal(ta.xdot, tb.xdot)
    off = replace(p, standin=replace(p.standin, enabled=False))
    c, d = _pass(off), _pass(p, "one-way")
    tc, td = c.tracks["gymnast"], d.tracks["gymnast"]
    assert np.array_equal(tc.x, td.x) and np.array_equal(tc.xdot, td.xdot)


def test_two_way_forces_are_equal_and_opposite_every_step():
    """Two-way, through the landing: at every coupling step the impulse the mat's points
    received is minus the impulse her segments received (to round-off), and what the figure
    is given is that impulse over the step."""
    touched = equal_and_opposite_every_step(M.build("two-way", duration=1.0), "mat", H, 950)
    assert touched > 50  # she touches down at ~0.8 s: the contact acted on 50+ steps


def test_a_vault_that_misses_the_mat_is_refused_in_one_line(capsys):
    """Too fast off the table she lands past the mat: a SceneError naming where she comes
    down and where the mat is, one line and exit 2 on the command line."""
    p = M.MatSceneParams()
    fast = replace(p, vault=replace(p.vault, vx=6.0))
    with pytest.raises(SceneError, match="misses the mat"):
        M.build(params=fast)
    assert main(["run", "mat", "--set", "vault.vx=6", "--no-video", "--no-usd",
                 "--no-report", "--out", "/nonexistent/never"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "misses the mat" in err[0]


def test_a_hop_is_the_feet_rising_after_touch_down_above_where_they_stand():
    """A lowest foot corner (100 Hz) sinking 6 cm into the mat at touch-down (0.5 s), rising
    3 cm above its standing depth at 0.9-1.0 s and settling there: the hop is 3 cm, read
    from 0.15 s after touch-down (the absorption's rebound of the mat before it is not a
    hop); a landing that only sinks and settles has none."""
    from interplay.scenes.landing_measures import hop
    t = np.arange(251) / 100.0
    low = np.where(t < 0.5, 1.0, -0.02)
    low[(t >= 0.5) & (t < 0.65)] = -0.06
    still = hop(t, low, 0.5)
    low[(t >= 0.9) & (t <= 1.0)] = 0.01
    assert still == 0.0
    assert hop(t, low, 0.5) == pytest.approx(0.03, abs=1e-12)


@pytest.fixture(scope="module")
def default_run():
    return M.build("hybrid").simulate()


@pytest.mark.slow
def test_default_run_sticks_the_landing_and_depresses_the_mat(default_run):
    # stuck: balanced (the horizontal measures) and no hop past 1 cm
    fig = M.landing_figures(default_run)
    assert fig["stuck"], fig
    assert 0.05 <= fig["mat depression (m)"] <= 0.2


@pytest.mark.slow
def test_the_controller_tuned_on_the_stand_in_sticks_on_the_two_way_mat():
    """The paper's point: tuned on the stand-in alone, the controller lands on the full mat
    (two-way, the mat's own step) and sticks there too, no hop, no step."""
    fig = M.landing_figures(M.build("two-way").simulate())
    assert fig["stuck"], fig


class _Here:
    """An executor that evaluates a batch in this process (the search's own order): the
    test's search is two evaluations, not worth a worker's start-up."""
    kind, address, workers = "here", None, 1

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        return False

    def map_unordered(self, fn, tasks):
        for i, t in enumerate(tasks):
            yield i, fn(t)


def test_tune_mat_keeps_or_improves_the_landing_and_its_files_run(tmp_path, monkeypatch):
    """`interplay tune mat` (the landing search on the stand-in) with a budget of 2: the best
    loss is at most the start's (the search keeps its best), the start's loss is the scene's
    own controller, tune.json and the log are readable JSON, and
    `run mat --controller tune.json` resolves to exactly the best values. Each candidate
    flies the vault alone here (the perturbed trials are the same code with other
    parameters), so the test is two 1.9 s hybrid primary passes, ~3 s (1.9 s: the stick
    window needs 1 s after the 0.8 s touch-down)."""
    import json
    from interplay.batch.tune import run_search
    from interplay.batch.variants import RunRequest
    from interplay.cli.controller import controller_sets
    from interplay.control import landing_search
    from interplay.control.landing_search import CLIP, LANDING
    monkeypatch.setattr(landing_search, "TRIALS", (({}, 1.0),))
    base = RunRequest("mat", None, (), 1.9)
    doc = run_search(base, None, tmp_path, _Here(), budget=2, seed=3, chains=1,
                     log=lambda line: None)
    saved = json.loads((tmp_path / "tune.json").read_text())
    lines = [json.loads(x) for x in (tmp_path / "evaluations.jsonl").read_text().splitlines()]
    assert saved["best"] == doc["best"] and len(lines) == 2 == len(saved["history"])
    assert saved["loss"] <= saved["start_loss"]
    spec, coupling, kw = base.resolve()
    # the search starts from the scene's own controller (its defaults)
    assert saved["start"] == {k: getattr(kw["params"].vault, k.split(".")[1])
                              for k in LANDING.bounds}
    assert saved["start_loss"] == saved["history"][0][1] < 4 * CLIP + 1  # it landed
    sets = controller_sets(spec, tmp_path / "tune.json")
    _, _, tuned = RunRequest("mat", None, tuple(f"{k}={v}" for k, v in sets.items())).resolve()
    for key, value in saved["best"].items():
        assert getattr(tuned["params"].vault, key.split(".")[1]) == value


@pytest.mark.slow
def test_impactor_drop_deforms_the_mat_as_the_impact_tests_did():
    """Pain, Mills & Yeadon's impact test (a 24 kg flat impactor, scenes/mat_impact.py),
    dropped from 1, 2 and 3 m: the depression grows with the drop; energy is bounded both
    ways: the contact's mean force over the depression d must carry the impactor's energy,
    so its peak F >= (m v^2 / 2 + m g d) / d, and the impactor cannot rebound faster than it
    came (the mat only dissipates) nor, with the foam's viscosity (mat.foam_damping),
    above 0.8 of it (the lattice without it gave back 0.96, a viscoelastic mat much less:
    docs/mat.md); the published band, 0.088-0.118 m "from various heights" (the heights are
    not in the texts we had), is reached by 3 m of drop."""
    from interplay.scenes.mat_impact import PUBLISHED, Impactor, drop_test
    rows = drop_test(drops=(1.0, 2.0, 3.0))
    m = Impactor().mass
    d = [r["depression_m"] for r in rows]
    assert d[0] < d[1] < d[2]
    for r in rows:
        v, dep = r["impact_speed_m_s"], r["depression_m"]
        assert r["peak_force_N"] >= (0.5 * m * v * v + m * G * dep) / dep
        assert 0.0 <= r["rebound_m_s"] <= 0.8 * v
    assert d[0] < PUBLISHED[0] and PUBLISHED[0] <= d[2] <= PUBLISHED[1]


def test_the_contact_meets_a_mirror_symmetric_top_face():
    """The elements a foot collides with (the top face's edges and both diagonals of each
    cell) map onto themselves under the mirror y -> -y and x -> (x0 + x1) - x: a landing
    square on the mat loads both feet alike (one diagonal per cell did not: the right toes
    took 9x the left's load). Exact: the lattice's points sit on a grid symmetric to
    round-off, matched within 1e-9 m."""
    from interplay.geometry.mat import build_mat
    lat = build_mat(MatParams())
    x = lat.x
    x0, x1 = x[:, 0].min(), x[:, 0].max()
    edges = {tuple(sorted(e)) for e in lat.top_edges.tolist()}
    key = {tuple(np.round(p, 9)): i for i, p in enumerate(x)}
    for flip in (np.array([1.0, -1.0, 1.0]), np.array([-1.0, 1.0, 1.0])):
        shift = np.array([0.0, 0.0, 0.0]) if flip[0] > 0 else np.array([x0 + x1, 0.0, 0.0])
        mirror = np.array([key[tuple(np.round(p * flip + shift, 9))] for p in x])
        assert {tuple(sorted((mirror[a], mirror[b]))) for a, b in edges} == edges


def test_the_capture_point_landing_keeps_its_feet_from_perturbed_takeoffs():
    """The margin the shipped controller was searched for (the margin search, docs/mat.md): on
    the stand-in, from each of the margin search's take-offs (1.6% off in rotation, 3% off in
    forward speed, 0.1 m/s sideways) she stays over her feet, upright, without a step; from
    the vault and from at least four of them she sticks by every measure. Search 6's
    controller fell forward from spin +0.05 rad/s and fell short from vx -0.1 m/s."""
    from dataclasses import replace
    from interplay.control.landing_search import MARGIN_TRIALS
    from interplay.scenes.landing_measures import STICK, stick
    p = M.MatSceneParams()
    stuck = 0
    for dv, _ in MARGIN_TRIALS:
        v = replace(p.vault, **{k: getattr(p.vault, k) + d for k, d in dv.items()})
        fig = stick(M.build("hybrid", params=replace(p, vault=v)).simulate(primary_only=True))
        assert fig["centre of mass off the feet (m)"] < STICK["lead"], (dv, fig)
        assert fig["pelvis tilt (rad)"] < STICK["tilt"], (dv, fig)
        assert fig["feet moved after touch-down (m)"] < 1.2 * STICK["moved"], (dv, fig)
        stuck += fig["stuck"]
    assert stuck >= 4


def _box_pushed_along_the_mat(push, stick, seconds):
    """A foot-sized 32 kg box (0.25 x 0.1 x 0.06 m) set in its rest dent on a 0.6 x 0.4 m mat
    of the default lattice spacing and pushed along x by ``push`` N from the start; its x (m)
    at each 1 ms step."""
    from interplay.geometry.primitive import Primitive
    from interplay.interactions.part_contact import PartContact, PartContactParams
    from interplay.systems.rigid import RigidBody
    from contact_checks import contact_step
    # the default lattice (46 x 37 x 4 over 3 x 1.6 m) cut to 10 x 10 x 4, its mass per point
    p = MatParams(length=0.6, width=0.4, nx=10, ny=10, mass=37.5 * 400 / 6808)
    net = M.mat_network(p, "explicit")
    x0, x1, y0, y1 = p.footprint()
    m, half = 32.0, np.array([0.125, 0.05, 0.03])
    I = m / 3.0 * np.array([half[1] ** 2 + half[2] ** 2, half[0] ** 2 + half[2] ** 2,
                            half[0] ** 2 + half[1] ** 2])
    # 7.8 mm into the mat's top (skin 4 mm): its dent under 314 N, so it starts near rest
    box = RigidBody("box", m, I, H, position=(0.5 * (x0 + x1), 0.5 * (y0 + y1),
                                               p.thickness + half[2] - 0.0038),
                    gravity=(push / m, 0.0, -G), primitive=Primitive("box", axes=tuple(half)))
    contact = PartContact("box-mat", box, net, PartContactParams(friction=1.0, stick=stick),
                          elements=net.top_edges)
    contact.prepare(H)
    xs = []
    for _ in range(int(seconds / H)):
        contact_step(box, net, contact, H)
        box.advance(H)
        xs.append(box.x[0])
    return np.array(xs) - xs[0]


def test_sticking_friction_holds_a_pushed_foot_and_lets_it_slide_past_the_cone():
    """The rigid-parts contact's sticking friction (``stick``): pushed along the mat with a
    sixth of mu m g, a foot-sized box comes to rest on the foam's shear, where the regularised
    law lets it creep without end (a damper of the top points' mass over the substep: ~20
    mm/s on the full mat, docs/mat.md); pushed past mu m g it slides as under the regularised
    law."""
    m, g_mu = 32.0, 1.0 * G
    held = _box_pushed_along_the_mat(m * g_mu / 6, True, 2.0)
    creep = _box_pushed_along_the_mat(m * g_mu / 6, False, 2.0)
    # the held box shears the foam by ~6.5 mm within ~1 s (the foam's and the points' damping),
    # then rests: over the last 0.8 s it moves less than 0.5 mm (the mat's sway; measured 0.05),
    # the regularised one more than twenty times that (measured 17 mm)
    assert abs(held[-1] - held[-800]) < 5e-4
    assert abs(creep[-1] - creep[-800]) > 1e-2
    # past the cone both laws are Coulomb's mu f_n against the slip: pushed with 1.3 mu m g
    # for 0.2 s the box slides ~10 cm under both (twice what (push - mu m g) / m would give
    # on a rigid floor: on the foam the contacts' normals tilt and their sum is not m g; not
    # traced further), and the sticking law's path is the regularised law's within 2%
    # (measured: the same to 0.1 mm)
    slid = _box_pushed_along_the_mat(1.3 * m * g_mu, True, 0.2)[-1]
    assert slid > 0.05
    assert slid == pytest.approx(_box_pushed_along_the_mat(1.3 * m * g_mu, False, 0.2)[-1],
                                 rel=0.02)


def _standing_on_the_stand_in_pushed(standin, push):
    """A figure standing on the stand-in (its rest top at z = 0), after 1 s pushed forward at
    the torso by ``push`` N for 2 s; the middle of her feet's x (m) at each 1 ms step of the
    push, from where it was when the push began."""
    from interplay.control import behaviours as B
    from interplay.control.fsm import Controller
    from interplay.geometry.anthropometry import SEGMENTS, BodyParams
    from interplay.interactions.bed_springs import BedSprings
    from interplay.systems.figure import Figure, FigureParams
    from interplay.systems.figure_model import EnvironmentParams
    fig = Figure("standing", FigureParams(body=BodyParams(mass=64.38, height=1.70),
                                          environment=EnvironmentParams(floor=None)),
                 Controller((B.stand(),)))
    springs = BedSprings(standin, fig, 0.0, H)
    feet = fig.part_body[[SEGMENTS.index("l_foot"), SEGMENTS.index("r_foot")]]
    xs = []
    for k in range(3000):
        fig.clear_forces()
        if k >= 1000:
            fig.add_wrench([push, 0.0, 0.0], body="torso")
        springs.act(fig)
        fig.advance(H)
        if k >= 1000:
            xs.append(fig.data.xipos[feet, 0].mean())
    return np.array(xs) - xs[0]


def test_the_stand_ins_anchored_points_hold_a_pushed_stance():
    """The stand-in's springs cannot slide (``BedSpringsParams.stick``, the shipped fit):
    pushed forward at the torso with 50 N for 2 s, her feet stay within 1 cm of where they
    stood (measured: 4.8 mm at most, as her balance shifts her load, then back to 1.2 mm),
    where the regularised law's cap (the segment's own mass over the step) lets them creep
    on without end (measured: 74 mm)."""
    held = _standing_on_the_stand_in_pushed(M.MatSceneParams().standin, 50.0)
    crept = _standing_on_the_stand_in_pushed(
        replace(M.MatSceneParams().standin, stick=0.0, eps=0.01), 50.0)
    assert np.abs(held).max() < 0.01
    assert crept[-1] > 0.05


def test_fitting_anchors_to_a_mat_too_soft_to_stand_on_is_refused_in_one_line():
    """``fit_stick`` needs her standing depth on the curve: a curve that cannot carry her
    weight within the mat's thickness is named as such, before the mat is built."""
    p = M.MatSceneParams()
    soft = replace(p.standin, linear=1000.0, quadratic=0.0, cubic=0.0)
    with pytest.raises(SceneError, match=r"mat: the stand-in's curve carries 200 N at the "
                                         r"mat's full thickness \(0.2 m\), less than her "
                                         r"standing weight 632 N: the mat is too soft"):
        M.fit_stick(p, soft)
