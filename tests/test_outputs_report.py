"""The HTML reports and the command line's outputs: sections present, every link resolves,
every printed path exists; bad output options fail with one line."""
import json
from html.parser import HTMLParser
from pathlib import Path

import pytest

from interplay.cli.command import main

SMALL = ["--size", "320x180", "--video-fps", "15", "--quiet"]


class _Links(HTMLParser):
    def __init__(self):
        super().__init__()
        self.links, self.ids, self.tags = [], set(), []

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        self.tags.append(tag)
        if "id" in a:
            self.ids.add(a["id"])
        for key in ("src", "href"):
            if a.get(key):
                self.links.append(a[key])


def parse_report(path: Path) -> _Links:
    p = _Links()
    p.feed(path.read_text(encoding="utf-8"))
    return p


def assert_links_resolve(path: Path, parsed: _Links):
    for link in parsed.links:
        assert "://" not in link, f"{path}: external link {link}"
        assert (path.parent / link).exists(), f"{path}: broken link {link}"


def run_cli(capsys, *argv):
    code = main(list(argv))
    out = capsys.readouterr()
    return code, out.out, out.err


def printed_paths(out: str) -> list[Path]:
    return [Path(line.split("wrote ", 1)[1].strip()) for line in out.splitlines()
            if line.startswith("wrote ")]


def test_run_writes_every_output_and_report(tmp_path, capsys):
    code, out, err = run_cli(capsys, "run", "basketball", "--coupling", "hybrid",
                             "--duration", "0.35", "--out", str(tmp_path), "--obj", *SMALL)
    assert code == 0, err
    paths = printed_paths(out)
    for name in ("summary.json", "tracks.npz", "scene.json", "run.usdc", "obj",
                 "preview.mp4", "report.html"):
        assert tmp_path / name in paths
    assert all(p.exists() for p in paths)
    assert paths[-1] == tmp_path / "report.html"  # the last thing printed
    rep = parse_report(tmp_path / "report.html")
    assert {"video", "interactions", "table-i", "advice", "timings", "diagnostics",
            "files"} <= rep.ids
    assert "video" in rep.tags and "img" in rep.tags
    assert_links_resolve(tmp_path / "report.html", rep)
    text = (tmp_path / "report.html").read_text()
    assert "paper, Table I" in text and "59.9" in text  # the paper's ball/net row beside ours
    assert "stand-in" in text and "Primary debug-cycle time" in text
    assert "<style>" in text and "stylesheet" not in text  # self-contained CSS
    assert not list(tmp_path.rglob("*.part"))
    # every file readable by all, as any file the user writes (mkstemp alone gives 0600)
    import os
    mask = os.umask(0o022)
    os.umask(mask)
    modes = {p.name: p.stat().st_mode & 0o777 for p in tmp_path.rglob("*") if p.is_file()}
    assert set(modes.values()) == {0o666 & ~mask}, modes


def test_obj_is_opt_in(tmp_path, capsys):
    code, out, err = run_cli(capsys, "run", "basketball", "--duration", "0.1", "--out",
                             str(tmp_path), "--no-video", "--no-report", "--quiet")
    assert code == 0, err
    assert (tmp_path / "run.usdc").exists() and not (tmp_path / "obj").exists()


def test_compare_writes_side_by_side_video_and_report(tmp_path, capsys):
    code, out, err = run_cli(capsys, "compare", "basketball", "--duration", "0.3",
                             "--out", str(tmp_path), "--no-obj", "--usda", *SMALL)
    assert code == 0, err
    paths = printed_paths(out)
    assert paths[-1] == tmp_path / "report.html"
    for mode in ("two-way", "one-way", "hybrid"):
        assert (tmp_path / mode / "report.html").exists()
        assert (tmp_path / mode / "run.usda").exists()
        assert not (tmp_path / mode / "obj").exists()
    assert (tmp_path / "compare.mp4").exists() and (tmp_path / "plot_height.png").exists()
    rep = parse_report(tmp_path / "report.html")
    assert {"video", "height", "modes", "advice", "runs"} <= rep.ids
    assert_links_resolve(tmp_path / "report.html", rep)
    assert sum("report.html" in link for link in rep.links) == 3
    assert "paper: ball / net" in (tmp_path / "report.html").read_text()
    assert json.loads((tmp_path / "compare.json").read_text())["scene"] == "basketball"


def test_no_video_report_says_so(tmp_path, capsys):
    code, out, err = run_cli(capsys, "run", "basketball", "--duration", "0.2", "--out",
                             str(tmp_path), "--no-video", "--no-usd", "--no-obj", "--quiet")
    assert code == 0, err
    assert not (tmp_path / "preview.mp4").exists()
    text = (tmp_path / "report.html").read_text()
    assert "--no-video" in text and "<video" not in text


@pytest.mark.parametrize("args, words", [
    (["--camera", "1,2"], "--camera '1,2': expected"),
    (["--camera", "0,0,1:0,0,1"], "same point"),
    (["--size", "big"], "--size big: expected WIDTHxHEIGHT"),
    (["--size", "321x200"], "must be even"),
    (["--video-fps", "0"], "--video-fps 0: out of range; --video-fps must be a finite number >= 1 and <= 240"),
])
def test_bad_output_options_fail_in_one_line(tmp_path, capsys, args, words):
    code, out, err = run_cli(capsys, "run", "basketball", "--out", str(tmp_path), *args)
    assert code == 2
    assert err.count("\n") == 1 and err.startswith("interplay: error: ") and words in err
    assert not list(tmp_path.iterdir())  # refused before anything ran or was written


def test_unwritable_out_fails_before_simulating(tmp_path, capsys):
    blocker = tmp_path / "file"
    blocker.write_text("x")
    code, out, err = run_cli(capsys, "run", "basketball", "--out", str(blocker / "sub"))
    assert code == 2 and err.count("\n") == 1
    assert "cannot write to output directory" in err and "--out" in err
    code, out, err = run_cli(capsys, "compare", "basketball", "--out", str(blocker / "sub"))
    assert code == 2 and "cannot write to output directory" in err


def test_view_of_a_directory_without_a_run(tmp_path, capsys):
    code, out, err = run_cli(capsys, "view", str(tmp_path))
    assert code == 2 and err.count("\n") == 1 and "scene.json" in err


def test_missing_gl_driver_fails_before_simulating(tmp_path, capsys, monkeypatch):
    moderngl = pytest.importorskip("moderngl")
    from interplay.outputs.render import gl, worker

    def no_egl(**kw):
        raise Exception("libEGL.so.1: cannot open shared object file")
    monkeypatch.setattr(gl, "_CTX", None)
    monkeypatch.setattr(worker, "_WORKER", None)  # a fresh renderer process makes the check
    monkeypatch.setattr(moderngl, "create_context", no_egl)
    code, out, err = run_cli(capsys, "run", "basketball", "--out", str(tmp_path))
    assert code == 2 and err.count("\n") == 1
    assert "headless OpenGL" in err and "libegl-mesa0" in err and "--no-video" in err
    assert not list(tmp_path.iterdir())


def test_viewer_moves_every_system_with_the_slider(tmp_path, capsys):
    pytest.importorskip("viser")
    import socket
    from interplay.outputs.rundata import load_run
    from interplay.cli.viewer import Viewer
    assert main(["run", "basketball", "--duration", "0.2", "--out", str(tmp_path), "--quiet",
                 "--no-video", "--no-usd", "--no-obj", "--no-report"]) == 0
    run = load_run(tmp_path)
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    v = Viewer(run, port=port, log=lambda m: None)
    try:
        assert v.url == f"http://127.0.0.1:{port}"
        last = len(run.times) - 1
        v.set_frame(last)
        kinds = {kind: h for kind, key, h in v.handles}
        assert set(kinds) == {"pose", "segments"}
        assert kinds["pose"].position == pytest.approx(tuple(run.pose("ball", last)[0]))
        seg = run.shape("net").segments
        assert kinds["segments"].points == pytest.approx(run.points("net", last)[seg], abs=1e-6)
        assert v.clock.value == pytest.approx(run.times[last], abs=1e-3)
    finally:
        v.stop()
