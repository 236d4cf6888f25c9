"""The gallery: one still per scene, made by the renderer from a default run at the scene's
key moment (``SceneSpec.key_time``), through the scene's own camera, and how much of the
frame's height the scene's subject (its moving systems, spray aside) and its primary fill
there.

``python -m interplay.outputs.gallery --out docs/gallery`` writes <scene>.jpg for every
scene and gallery.json with each still's time, camera and subject fraction.
"""
from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from ..io.atomic import atomic_path


def subject_fraction(run, camera, t: float, aspect: float, only=None) -> float:
    """Share (0..1) of the frame's height that the box around every moving system (or only
    the one named) at time t (s) takes through camera (a Camera), clipped to the frame."""
    from .geometry import quat_matrix
    pts = []
    for s in run.shapes:
        if not s.animated or s.form == "particles" or (only is not None and s.name != only):
            continue
        st = run.sample(s.name, t)
        if s.form == "body":
            pts.append(s.verts @ quat_matrix(st["orientation"]).T + st["position"])
        elif s.form == "parts":
            pts += [v @ quat_matrix(q).T + p for (v, _), p, q in
                    zip(s.parts, st["segment_positions"], st["segment_orientations"])]
        else:
            p = st["points"]
            pts.append(p[np.isfinite(p).all(axis=1)])
    if not pts:
        return 0.0  # nothing of it is drawn (the flags' primary is the wind)
    pts = np.concatenate(pts)
    vp = camera.projection(aspect, 0.01, 1e4) @ camera.view()
    h = vp @ np.c_[pts, np.ones(len(pts))].T
    y = np.clip(h[1] / h[3], -1.0, 1.0)[h[3] > 0]
    return float((y.max() - y.min()) / 2) if len(y) else 0.0


def still(spec, size=(960, 540)):
    """(image (h, w, 3) uint8, its record) of one scene's default run at its key time."""
    from .render.gl import Renderer
    from .render.overlay import draw_label
    from .rundata import from_result
    run = from_result(spec.build(spec.default_coupling, duration=spec.duration, fps=spec.fps,
                                 params=spec.params()).simulate())
    t = spec.key_time if spec.key_time is not None else run.duration / 2
    with Renderer(run, size, spec.camera) as r:
        img = draw_label(r.render(run, t), [f"{spec.name} - {run.coupling}", f"t = {t:.2f} s"])
        cam = r.camera_at(t)
    aspect = size[0] / size[1]
    return img, {"scene": spec.name, "time_s": t, "camera": cam.spec(),
                 "subject_height_fraction": subject_fraction(run, cam, t, aspect),
                 "primary": run.primary,
                 "primary_height_fraction": subject_fraction(run, cam, t, aspect, run.primary)}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="docs/gallery")
    ap.add_argument("--scenes", default=None, help="comma-separated (default: every scene)")
    a = ap.parse_args(argv)
    from PIL import Image
    from ..scenes import all_specs, spec
    specs = [spec(n) for n in a.scenes.split(",")] if a.scenes else all_specs()
    out = Path(a.out)
    index = out / "gallery.json"
    # the stills of scenes not asked for stay listed: --scenes redoes some of the gallery
    kept = {r["scene"]: r for r in (json.loads(index.read_text()) if index.exists() else [])}
    records = []
    for s in specs:
        img, rec = still(s)
        with atomic_path(out / f"{s.name}.jpg") as tmp:
            Image.fromarray(img).save(tmp, format="JPEG", quality=88)
        records.append(rec)
        print(f"{s.name}: t = {rec['time_s']:.2f} s, the moving systems fill "
              f"{rec['subject_height_fraction']:.2f} of the frame's height, the primary "
              f"({rec['primary']}) {rec['primary_height_fraction']:.2f}", flush=True)
    kept.update({r["scene"]: r for r in records})
    with atomic_path(index) as tmp:
        tmp.write_text(json.dumps([kept[k] for k in sorted(kept)], indent=2))


if __name__ == "__main__":
    main()
