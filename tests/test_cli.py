"""The command line: runs that write the documented summary, and one-line errors."""
import json

import numpy as np
import pytest

from interplay.cli.command import main


def run_cli(capsys, *argv):
    code = main(list(argv))
    out = capsys.readouterr()
    return code, out.out, out.err


def test_run_writes_summary_and_tracks(tmp_path, capsys):
    code, out, err = run_cli(capsys, "run", "basketball", "--coupling", "hybrid", "--duration",
                             "0.7", "--out", str(tmp_path), "--quiet", "--no-video", "--no-obj",
                             "--no-usd", "--no-report")
    assert code == 0, err
    s = json.loads((tmp_path / "summary.json").read_text())
    for key in ("scene", "coupling", "duration_s", "systems", "timings", "interactions",
                "advice", "diagnostics", "primary_checkpoints"):
        assert key in s
    assert s["coupling"] == "hybrid" and s["duration_s"] == 0.7
    assert {"primary_pass_s", "secondary_pass_s", "total_s"} <= set(s["timings"])
    net = next(x for x in s["systems"] if x["name"] == "net")
    assert net["type"] == "SpringNetwork" and net["role"] == "dynamic" and net["mass_kg"] == pytest.approx(0.03)
    assert net["integrator"] == "explicit" and net["dt_s"] > 0
    it = next(x for x in s["interactions"] if x["name"] == "ball-net")
    assert set(it["force_N"]) == {"min", "max", "mean"} and len(it["contact_s"]) == 2
    assert "standin" in it  # the damping field's own statistics
    assert {"mode", "reasons"} <= set(s["advice"])
    d = s["diagnostics"]["net"]
    assert {"kinetic_energy_J", "lowest_z_m", "max_strain", "instability"} <= set(d)
    assert [c["t"] for c in s["primary_checkpoints"]] == [0.2, 0.3, 0.4, 0.5, 0.6]
    with np.load(tmp_path / "tracks.npz", allow_pickle=False) as z:
        pts = z["net/points"]
        assert pts.shape[1:] == (156, 3) and pts.shape[0] == len(z["net/t"])
        assert z["ball/position"].shape == (len(z["ball/t"]), 3)
    assert not list(tmp_path.glob("*.part"))  # no temporary files left behind


def test_list(capsys):
    code, out, _ = run_cli(capsys, "list")
    assert code == 0 and "basketball" in out


BAD = [
    (["run", "nowhere"], "unknown scene 'nowhere'"),
    (["run", "basketball", "--coupling", "sideways"], "unknown coupling"),
    (["run", "basketball", "--set", "ball.mass=-1"], "ball.mass=-1: out of range; ball.mass "
     "must be a finite number >= 0.0001 and <= 1e+06 kg"),
    (["run", "basketball", "--set", "ball.mass=0"], "ball.mass must be a finite number >= 0.0001"),
    (["run", "basketball", "--set", "ball.radius=0"], "ball.radius must be a finite number >= 0.001"),
    (["run", "basketball", "--set", "net.cord_ea=-5"], "net.cord_ea must be a finite number >= 0.001"),
    (["run", "basketball", "--set", "contact.stiffness=0"], "contact.stiffness must be"),
    (["run", "basketball", "--dt", "0"], "--dt 0: out of range; --dt must be a finite number "
     ">= 1e-12 and <= 1 s"),
    (["run", "basketball", "--duration", "-1"], "--duration must be a finite number >= 1e-06"),
    (["run", "basketball", "--duration", "0"], "--duration must be a finite number >= 1e-06"),
    (["run", "basketball", "--set", "net.colour=red"], "unknown parameter; valid keys"),
    (["run", "basketball", "--set", "ball.mass=heavy"], "'heavy' is not a number"),
    (["run", "basketball", "--set", "nomass"], "expected KEY=VALUE"),
    (["run", "basketball", "--integrator", "rk4"], "choose one of explicit, implicit, localglobal"),
    (["run", "basketball", "--integrator", "explicit", "--dt", "1e-3"],
     "above the explicit stability bound"),
    (["run", "basketball", "--duration", "soon"], "--duration soon: 'soon' is not a number"),
    (["run", "basketball", "--set", "ball.position=0,0,nan"], "ball.position=0,0,nan: not finite"),
    (["run", "flags", "--set", "cotton.nu=2147483648"], "cotton.nu must be a whole number >= 2"),
    (["run", "leaves", "--set", "leaves.seed=-1"], "leaves.seed must be a whole number >= 0"),
    (["run", "bungee", "--set", "jumper.mass=1e-308"], "jumper.mass must be a finite number >= "
     "10 and <= 500 kg"),
    (["run", "pond", "--set", "basin.size_x=1e-308"], "basin.size_x must be"),
    (["run", "basketball", "--fps", "1e308"], "--fps must be a finite number >= 0.01 and <= 10000"),
]


@pytest.mark.parametrize("argv,message", BAD, ids=[" ".join(a[2:]) or a[1] for a, _ in BAD])
def test_bad_input_gives_one_clear_line(argv, message, capsys, tmp_path):
    try:
        code = main(argv + ["--out", str(tmp_path), "--quiet"])
    except SystemExit as e:  # argparse's own errors
        code = e.code
    err = capsys.readouterr().err
    assert code == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("interplay: error:"), err
    assert message in lines[0]
    assert "Traceback" not in err
    assert not (tmp_path / "summary.json").exists()


def test_stability_error_suggests_the_implicit_integrator(capsys, tmp_path):
    code, _, err = run_cli(capsys, "run", "basketball", "--integrator", "explicit", "--dt",
                           "1e-3", "--out", str(tmp_path))
    assert code == 2 and "--integrator implicit" in err and "bound" in err


def test_unwritable_output_directory(capsys, tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("not a directory")
    code, _, err = run_cli(capsys, "run", "basketball", "--duration", "0.1", "--out",
                           str(blocker / "sub"), "--quiet")
    assert code == 2 and "cannot write" in err and len(err.strip().splitlines()) == 1


def test_run_without_coupling_uses_the_scenes_own(tmp_path, capsys):
    # the puddle's primary is animation: its scene defaults to one-way
    code, _, err = run_cli(capsys, "run", "puddle", "--duration", "0.1", "--out", str(tmp_path),
                           "--quiet", "--no-video", "--no-obj", "--no-usd", "--no-report")
    assert code == 0, err
    assert json.loads((tmp_path / "summary.json").read_text())["coupling"] == "one-way"
