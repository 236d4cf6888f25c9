"""Slow checks in real consumers: the report and the web viewer in headless Chromium (over
the DevTools protocol), the USD stage in Blender (the `bpy` wheel in its own venv, since it
pins numpy 1.26). Each is skipped when its tool is not installed."""
import base64
import io
import json
import os
import re
import shutil
import socket
import subprocess
import sys
import tempfile
import time
import urllib.request
from pathlib import Path

import numpy as np
import pytest

pytestmark = pytest.mark.slow

CHROMIUM_FLAGS = ["--headless", "--no-sandbox", "--disable-gpu",
                  "--disable-background-networking", "--disable-component-update",
                  "--disable-sync", "--no-first-run"]
BPY_PYTHON = os.environ.get("INTERPLAY_BPY_PYTHON", "/tmp/bpyvenv/bin/python")


def _chromium():
    for name in ("chromium", "chromium-browser", "google-chrome"):
        if shutil.which(name):
            return shutil.which(name)
    pytest.skip("no chromium (apt-get install -y chromium)")


class Browser:
    """Headless Chromium driven over the DevTools protocol (websockets, synchronous)."""

    def __init__(self, extra_flags=()):
        ws = pytest.importorskip("websockets.sync.client")
        self.profile = tempfile.mkdtemp(prefix="interplay-chromium-")
        self.proc = subprocess.Popen(
            [_chromium(), *CHROMIUM_FLAGS, *extra_flags, "--remote-debugging-port=0",
             f"--user-data-dir={self.profile}", "--window-size=1280,900", "about:blank"],
            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        port = None
        deadline = time.time() + 30
        while time.time() < deadline and port is None:
            line = self.proc.stderr.readline()
            m = re.search(r"DevTools listening on ws://[^:]+:(\d+)/", line)
            port = int(m.group(1)) if m else None
        assert port, "chromium did not open its DevTools port"
        targets = json.loads(urllib.request.urlopen(f"http://127.0.0.1:{port}/json/list").read())
        page = next(t for t in targets if t["type"] == "page")
        self.ws = ws.connect(page["webSocketDebuggerUrl"], max_size=2 ** 26)
        self.next_id, self.events = 0, []
        for method in ("Page.enable", "Runtime.enable", "Log.enable"):
            self.call(method)

    def call(self, method, **params):
        self.next_id += 1
        self.ws.send(json.dumps({"id": self.next_id, "method": method, "params": params}))
        while True:
            msg = json.loads(self.ws.recv(timeout=60))
            if msg.get("id") == self.next_id:
                assert "error" not in msg, msg
                return msg.get("result", {})
            self.events.append(msg)

    def pump(self, seconds):
        end = time.time() + seconds
        while time.time() < end:
            try:
                self.events.append(json.loads(self.ws.recv(timeout=max(end - time.time(), 0.01))))
            except TimeoutError:
                break

    def eval(self, js):
        r = self.call("Runtime.evaluate", expression=js, returnByValue=True, awaitPromise=True)
        return r["result"].get("value")

    def wait_for(self, js, timeout=30):
        end = time.time() + timeout
        while time.time() < end:
            if self.eval(js):
                return True
            self.pump(0.25)
        return False

    def errors(self):
        out = []
        for e in self.events:
            p = e.get("params", {})
            if e.get("method") == "Runtime.exceptionThrown":
                out.append(p["exceptionDetails"].get("text", "exception"))
            elif e.get("method") == "Runtime.consoleAPICalled" and p.get("type") == "error":
                out.append(" ".join(str(a.get("value", a.get("description"))) for a in p["args"]))
            elif e.get("method") == "Log.entryAdded" and p["entry"]["level"] == "error":
                out.append(p["entry"]["text"])
        return out

    def screenshot(self) -> np.ndarray:
        from PIL import Image
        data = base64.b64decode(self.call("Page.captureScreenshot", format="png")["data"])
        return np.asarray(Image.open(io.BytesIO(data)).convert("RGB"))

    def close(self):
        try:
            self.ws.close()
        finally:
            self.proc.terminate()
            self.proc.wait(timeout=20)
            shutil.rmtree(self.profile, ignore_errors=True)


@pytest.fixture(scope="module")
def saved_run(tmp_path_factory):
    from interplay.cli.command import main
    out = tmp_path_factory.mktemp("run")
    assert main(["run", "basketball", "--duration", "0.5", "--out", str(out), "--quiet"]) == 0
    return out


def test_report_loads_in_chromium(saved_run):
    b = Browser()
    try:
        b.call("Page.navigate", url=(saved_run / "report.html").as_uri())
        assert b.wait_for("document.readyState === 'complete'")
        assert b.wait_for("[...document.images].length > 0 && [...document.images].every("
                          "i => i.complete && i.naturalWidth > 0)"), "a plot did not load"
        ok = b.wait_for("(() => { const v = document.querySelector('video');"
                        " return v && v.readyState >= 2 && v.videoWidth === 1280; })()")
        assert ok, b.eval("(() => { const v = document.querySelector('video'); return "
                          "v ? 'readyState ' + v.readyState + ' error ' + (v.error && "
                          "v.error.code) : 'no video element'; })()")
        img = b.screenshot()
        assert img.std() > 20, "blank screenshot"
        b.pump(0.5)
        assert b.errors() == []
    finally:
        b.close()


def _free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_viewer_serves_the_scene_to_chromium(saved_run):
    pytest.importorskip("viser")
    port = _free_port()
    exe = Path(sys.executable).with_name("interplay")
    proc = subprocess.Popen([str(exe), "view", str(saved_run), "--port", str(port)],
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    b = None
    try:
        seen = []
        for line in proc.stdout:  # viser prints its own banner first
            seen.append(line)
            if line.startswith("viewer:"):
                break
        m = re.search(r"(http://\S+)", seen[-1] if seen else "")
        assert m, f"viewer printed no URL: {''.join(seen)!r}"
        b = Browser(["--enable-unsafe-swiftshader", "--use-angle=swiftshader"])
        b.call("Page.navigate", url=m.group(1))
        assert "a browser connected" in proc.stdout.readline()
        assert b.wait_for("document.querySelector('canvas') !== null", timeout=60)
        # the scene has arrived when the GUI shows the run's markdown and time control
        assert b.wait_for("document.body.innerText.includes('basketball')", timeout=60)
        assert b.wait_for("document.body.innerText.includes('time (s)')", timeout=30)
        b.pump(2.0)
        img = b.screenshot()
        assert img.std() > 10, "blank viewer"
        assert [e for e in b.errors() if "WebGL" not in e] == []
    finally:
        if b is not None:
            b.close()
        proc.terminate()
        proc.wait(timeout=20)


BLENDER_SCRIPT = r"""
import json, sys, bpy
bpy.ops.wm.read_factory_settings(use_empty=True)
assert bpy.ops.wm.usd_import(filepath=sys.argv[-2]) == {"FINISHED"}
frames = [int(f) for f in sys.argv[-1].split(",")]
out = {"objects": {}, "samples": {}}
for ob in bpy.data.objects:
    out["objects"][ob.name] = {
        "type": ob.type,
        "constraints": [c.type for c in ob.constraints],
        "modifiers": [m.type for m in getattr(ob, "modifiers", [])]}
sc = bpy.context.scene
for f in frames:
    sc.frame_set(f)
    dg = bpy.context.evaluated_depsgraph_get()
    s = {}
    for ob in bpy.data.objects:
        e = ob.evaluated_get(dg)
        if ob.type == "MESH":
            s[ob.name] = {"origin": list(e.matrix_world.translation),
                          "v0": list(e.matrix_world @ e.data.vertices[0].co)}
        elif ob.type == "CURVES":
            s[ob.name] = {"points": [list(p.position) for p in e.data.points]}
    out["samples"][str(f)] = s
print("RESULT" + json.dumps(out))
"""


def test_usd_imports_into_blender_with_every_system_animated(saved_run, tmp_path):
    if not Path(BPY_PYTHON).exists():
        pytest.skip(f"no bpy interpreter at {BPY_PYTHON} (python3 -m venv /tmp/bpyvenv && "
                    "/tmp/bpyvenv/bin/pip install bpy; or set INTERPLAY_BPY_PYTHON)")
    from interplay.outputs.obj import quat_matrix
    from interplay.outputs.rundata import load_run
    run = load_run(saved_run)
    script = tmp_path / "import.py"
    script.write_text(BLENDER_SCRIPT)
    frames = [0, len(run.times) // 2, len(run.times) - 1]
    proc = subprocess.run([BPY_PYTHON, str(script), str(saved_run / "run.usdc"),
                           ",".join(map(str, frames))], capture_output=True, text=True,
                          timeout=300)
    line = next((ln for ln in proc.stdout.splitlines() if ln.startswith("RESULT")), None)
    assert line, proc.stdout[-2000:] + proc.stderr[-2000:]
    res = json.loads(line[len("RESULT"):])
    objs = res["objects"]
    # the ball's Xform and its mesh merge into one object moved by a transform cache
    ball = next(n for n, o in objs.items() if "TRANSFORM_CACHE" in o["constraints"])
    assert objs["net"]["type"] == "CURVES" and "MESH_SEQUENCE_CACHE" in objs["net"]["modifiers"]
    animated = {n for n, o in objs.items()
                if "TRANSFORM_CACHE" in o["constraints"] or "MESH_SEQUENCE_CACHE" in o["modifiers"]}
    assert animated == {ball, "net"}  # every moving system; the floor stays still
    seg = run.shape("net").segments.reshape(-1)
    body = run.shape("ball").verts
    for f in frames:
        s = res["samples"][str(f)]
        pos, q = run.pose("ball", f)
        np.testing.assert_allclose(s[ball]["origin"], pos, atol=1e-5)
        np.testing.assert_allclose(s[ball]["v0"], quat_matrix(q) @ body[0] + pos, atol=1e-5)
        np.testing.assert_allclose(s["net"]["points"], run.points("net", f)[seg], atol=1e-5)
