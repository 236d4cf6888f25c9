"""Benchmark: the cost of outputs per frame; writes DIR/bench_outputs.json.

Two workloads:
  basketball   the scene's two-way run (1.5 s at 60 frames/s): a 642-vertex ball, 288 cords
               drawn as instanced tubes with a sphere per knot, the floor
  cloth64      a 64 x 64 cloth (4,096 points, 7,938 triangles) as a deforming surface; its
               motion is a travelling wave written directly (no simulation: only the outputs
               are timed), 1.5 s at 60 frames/s
For each: render ms/frame at 1280x720 with 4x MSAA and soft shadows (median of the video's
frames, GL readback and overlay included), H.264 encode ms/frame (time spent handing frames
to ffmpeg plus finishing the file, divided by the frames), USD .usdc export ms per output
frame, OBJ sequence ms per output frame, and the validators' time. Wall-clock on a shared
2-core machine: orders of magnitude, never a pass/fail test.
Run: ``.venv/bin/python benchmarks/bench_outputs.py --out out/bench [--quick]``.
"""
from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
import common  # noqa: E402  (thread settings before numba, machine facts, the JSON writer)

import argparse  # noqa: E402
import statistics  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

from interplay.outputs.rundata import RunData, Shape, from_result  # noqa: E402

SIZE = (1280, 720)


def cloth_run(n: int = 64, duration: float = 1.5, fps: float = 60.0) -> RunData:
    """A 1.6 m square cloth of n x n points waving above a floor (a mesh, no simulation)."""
    u = np.linspace(-0.8, 0.8, n)
    X, Y = np.meshgrid(u, u, indexing="ij")
    idx = np.arange(n * n).reshape(n, n)
    a, b = idx[:-1, :-1].ravel(), idx[1:, :-1].ravel()
    c, d = idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()
    tris = np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)])
    t = np.arange(int(round(duration * fps)) + 1) / fps
    z = 1.0 + 0.12 * np.sin(4.0 * X[None] - 6.0 * t[:, None, None]) * (X[None] + 0.8) / 1.6
    pts = np.stack([np.broadcast_to(X, z.shape), np.broadcast_to(Y, z.shape), z], axis=-1)
    floor = Shape("floor", "static", (0.55, 0.55, 0.57),
                  verts=np.array([[-10, -10, 0], [10, -10, 0], [10, 10, 0], [-10, 10, 0.0]]),
                  tris=np.array([[0, 1, 2], [0, 2, 3]]))
    cloth = Shape("cloth", "surface", (0.80, 0.25, 0.25), triangles=tris)
    return RunData("cloth64", "none", fps, duration, [cloth, floor],
                   {"cloth": {"t": t, "points": pts.reshape(len(t), n * n, 3)}}, "cloth")


def basketball_run(duration: float) -> RunData:
    from interplay.scenes import spec
    return from_result(spec("basketball").build("two-way", duration=duration).simulate())


def bench_render(run, video_fps: float, tmp: Path) -> dict:
    from interplay.outputs.render.gl import Renderer, frame_times
    from interplay.outputs.render.overlay import draw_label
    from interplay.outputs.render.video import video_writer
    times = frame_times(run.duration, video_fps)
    t0 = time.perf_counter()
    r = Renderer(run, SIZE)
    setup = time.perf_counter() - t0
    r.render(run, 0.0)  # first frame compiles the shaders' draw state: not timed
    per_frame, timer = [], {"encode_s": 0.0}
    with video_writer(tmp / f"{run.scene}.mp4", SIZE, video_fps, timer) as write:
        for t in times:
            t1 = time.perf_counter()
            img = draw_label(r.render(run, t), [run.scene, f"t = {t:.3f} s"])
            per_frame.append(time.perf_counter() - t1)
            write(img)
    r.release()
    return {"frames": len(times), "size": list(SIZE), "msaa": 4, "setup_s": setup,
            "render_ms_per_frame_median": 1e3 * statistics.median(per_frame),
            "render_ms_per_frame_min": 1e3 * min(per_frame),
            "encode_ms_per_frame": 1e3 * timer["encode_s"] / len(times),
            "mp4_bytes": (tmp / f"{run.scene}.mp4").stat().st_size}


def bench_export(run, tmp: Path) -> dict:
    from interplay.outputs.obj import write_obj_sequence
    from interplay.outputs.usd import validate, write_usd
    nf = len(run.times)
    t0 = time.perf_counter()
    path = write_usd(run, tmp / f"{run.scene}.usdc")
    usd_s = time.perf_counter() - t0
    t0 = time.perf_counter()
    errors = validate(path)
    validate_s = time.perf_counter() - t0
    t0 = time.perf_counter()
    write_obj_sequence(run, tmp / f"obj_{run.scene}")
    obj_s = time.perf_counter() - t0
    return {"output_frames": nf, "usd_ms_per_frame": 1e3 * usd_s / nf,
            "usd_bytes": path.stat().st_size, "validators_s": validate_s,
            "validator_errors": len(errors), "obj_ms_per_frame": 1e3 * obj_s / nf}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="out/bench")
    ap.add_argument("--quick", action="store_true", help="0.5 s runs instead of 1.5 s")
    ap.add_argument("--video-fps", type=float, default=30.0)
    args = ap.parse_args(argv)
    duration = 0.5 if args.quick else 1.5
    runs = {"basketball": basketball_run(duration), "cloth64": cloth_run(duration=duration)}
    report = {"what": "render+encode per frame at 1280x720, export per output frame",
              "machine": common.machine(),
              "workloads": {}}
    with tempfile.TemporaryDirectory() as d:
        tmp = Path(d)
        for name, run in runs.items():
            w = {"points": int(sum(len(fr["points"][0]) for fr in run.frames.values()
                                   if "points" in fr)),
                 **bench_render(run, args.video_fps, tmp), **bench_export(run, tmp)}
            report["workloads"][name] = w
            print(f"{name}: render {w['render_ms_per_frame_median']:.1f} ms/frame, encode "
                  f"{w['encode_ms_per_frame']:.1f} ms/frame, USD {w['usd_ms_per_frame']:.2f} "
                  f"ms/frame, OBJ {w['obj_ms_per_frame']:.2f} ms/frame, validator errors "
                  f"{w['validator_errors']}")
    try:
        from interplay.outputs.render.gl import gl_context
        report["gl_renderer"] = gl_context().info["GL_RENDERER"]
    except Exception as e:  # the numbers above already say whether GL worked
        report["gl_renderer"] = str(e)
    print(f"wrote {common.write_json(args.out, 'bench_outputs.json', report)}")


if __name__ == "__main__":
    main()
