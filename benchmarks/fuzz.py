"""Hostile-input fuzzing of every surface Interplay reads (issue 21): --set on every key of
every scene, the CLI's options, BVH clips, meshes and saved-run folders.

Seeded: the same --seed gives the same cases on any version of the code (the cases are made
from each scene's parameter keys and default values, not from the declared domains), so the
counts before and after a change compare. Every case runs in a forked child with a time limit;
its outcome is one of

  clean     exit 2 with exactly one line "interplay: error: ..." (or one InterplayError)
  vague     that, but the line names neither the key/file nor the value given
  ok        exit 0 and every output finite: summary.json strict JSON, tracks.npz finite
            (spray particles absent as whole NaN rows excepted)
  nan       exit 0 with NaN or inf in summary.json or tracks.npz (silent corruption)
  buried    an error line among other lines (warnings) on stderr
  traceback an unhandled exception (or the CLI's own "internal error" line)
  hang      past the time limit

  python benchmarks/fuzz.py --out out/bench [--seed 0] [--cases N] [--timeout 40]
writes fuzz.json (counts per surface, every non-clean case) through common.py.
"""
from __future__ import annotations

import common  # noqa: F401  (thread settings first)

import dataclasses
import io
import json
import os
import random
import signal
import sys
import tempfile
import time
import traceback
from pathlib import Path

import numpy as np

SHORT = ["--duration", "0.05", "--quiet", "--no-video", "--no-usd", "--no-obj",
         "--no-report"]
FLOATS = ["-1", "0", "nan", "inf", "-inf", "1e308", "-1e308", "1e-308", "1e400", "abc", "",
          "1e6", "-1e6", "2147483648", "1,2"]
INTS = ["0", "-1", "2147483648", "1234567890123456789012345", "1.5", "x", "", "1000000",
        "99999", "1e3"]
BOOLS = ["maybe", "", "2", "nan", "yes"]
STRS = ["", "nonsense", "x" * 5000, "/dev/zero", "../../../etc/passwd", "none"]


def defaults(params, prefix=""):
    """{dotted key: default value} of a nested parameter dataclass (any version)."""
    out = {}
    for f in dataclasses.fields(params):
        v = getattr(params, f.name)
        if dataclasses.is_dataclass(v):
            out.update(defaults(v, f"{prefix}{f.name}."))
        else:
            out[prefix + f.name] = v
    return out


def hostile(value, rng):
    """Hostile texts for a parameter whose default is ``value``."""
    if isinstance(value, bool):
        return BOOLS
    if isinstance(value, int):
        return INTS
    if isinstance(value, float) or value is None:
        return FLOATS
    if isinstance(value, tuple):
        n = max(len(value), 1)
        return [",".join(["nan"] * n), ",".join(["inf"] * n), ",".join(["1e308"] * n),
                ",".join(["-1e6"] * n), ",".join(["0"] * n), ",".join(["1"] * (n + 1)),
                ",".join(["1"] * max(n - 1, 1)), "", "a,b,c", ",".join(["-1"] * n),
                ",".join(str(rng.uniform(-10, 10)) for _ in range(n))]
    return STRS


def set_cases(rng, specs):
    cases = []
    for spec in specs:
        for key, value in defaults(spec.params()).items():
            for text in hostile(value, rng):
                cases.append(("set", ["run", spec.name, "--set", f"{key}={text}", *SHORT],
                              {"key": key, "value": text}))
    return cases


def option_cases(rng, specs):
    cases = []
    opts = {"--duration": ["0", "-1", "nan", "inf", "1e308", "1e-308", "abc", "1e-9"],
            "--fps": ["0", "-1", "nan", "1e308", "1e-308", "abc", "1e6"],
            "--dt": ["0", "-1", "nan", "inf", "1e308", "1e-12", "1e-9", "abc"],
            "--coupling": ["sideways", "", "hybrid", "one-way", "two-way"],
            "--integrator": ["rk4", "", "explicit", "implicit", "localglobal"],
            "--size": ["64x48", "16x16", "0x0", "1x100000", "axb", "100000x100000", "-5x5"],
            "--video-fps": ["0", "nan", "1e308", "-1"],
            "--camera": ["-2,-6,2:0,0,1", "nan,0,0:0,0,0", "1,2:3", "0,0,0:0,0,0",
                         "1,1,1:0,0,0:500", "garbage"]}
    for spec in specs:
        for opt, values in opts.items():
            for v in values:
                argv = ["run", spec.name, f"{opt}={v}", *SHORT]
                if opt in ("--size", "--video-fps", "--camera"):
                    argv = [a for a in argv if a not in ("--no-video", "--no-report")]
                    argv.insert(3, "--size=160x90") if opt != "--size" else None
                cases.append(("option", argv, {"key": opt, "value": v}))
        for verb in ("compare", "fit-standin"):
            cases.append(("option", [verb, spec.name, *SHORT[:3]], {"key": verb, "value": ""}))
    return cases


# --- BVH files -------------------------------------------------------------------------------
def bvh_cases(rng, folder: Path, clip: Path | None, n: int):
    folder.mkdir(parents=True, exist_ok=True)
    base = clip.read_text() if clip is not None and clip.exists() else None
    cases = []
    special = {"dev-zero": "/dev/zero", "dir": str(folder), "missing": str(folder / "nope.bvh"),
               "mistyped": "cmu_02_03_rnu.bvh"}
    fifo = folder / "fifo.bvh"
    if not fifo.exists():
        os.mkfifo(fifo)
    special["fifo"] = str(fifo)
    for name, path in special.items():
        cases.append(("bvh", ["run", "puddle", "--set", f"clip={path}", *SHORT],
                      {"key": "clip", "value": path, "file": name}))
    if base is None:
        return cases
    head, _, motion = base.partition("MOTION")
    lines = motion.strip().splitlines()
    frames = lines[2:]
    for k in range(n):
        kind = rng.choice(["truncate", "garbage", "frames", "frametime", "nan", "channels",
                           "extra", "offset", "empty", "binary"])
        text = base
        if kind == "truncate":
            text = base[: rng.randrange(len(base))]
        elif kind == "garbage":
            i = rng.randrange(len(base))
            text = base[:i] + "".join(rng.choice("{}#$%^ \n\t0123456789e.-") for _ in range(20)) \
                + base[i + 20:]
        elif kind == "frames":
            count = rng.choice(["0", "1", "-5", "x", str(len(frames) + 7), str(len(frames) - 3),
                                "99999999999"])
            text = head + "MOTION\nFrames: " + count + "\n" + lines[1] + "\n" + "\n".join(frames)
        elif kind == "frametime":
            ft = rng.choice(["1e-300", "100", "0", "-0.01", "nan", "inf", "1e-5"])
            text = head + "MOTION\n" + lines[0] + "\nFrame Time: " + ft + "\n" + "\n".join(frames)
        elif kind == "nan":
            j = rng.randrange(len(frames))
            vals = frames[j].split()
            vals[rng.randrange(len(vals))] = rng.choice(["nan", "inf", "-inf", "1e400"])
            frames2 = frames[:j] + [" ".join(vals)] + frames[j + 1:]
            text = head + "MOTION\n" + lines[0] + "\n" + lines[1] + "\n" + "\n".join(frames2)
        elif kind == "channels":
            text = base.replace("CHANNELS 3", "CHANNELS 4", 1) if rng.random() < 0.5 else \
                base.replace("CHANNELS 6", "CHANNELS 2", 1)
        elif kind == "extra":
            j = rng.randrange(len(frames))
            frames2 = list(frames)
            frames2[j] += " 1.0"
            text = head + "MOTION\n" + lines[0] + "\n" + lines[1] + "\n" + "\n".join(frames2)
        elif kind == "offset":
            text = base.replace("OFFSET", "OFFSET 1e308 nan", 1)
        elif kind == "empty":
            text = ""
        p = folder / f"case{k:04d}.bvh"
        if kind == "binary":
            p.write_bytes(bytes(rng.randrange(256) for _ in range(rng.randrange(1, 4000))))
        else:
            p.write_text(text)
        cases.append(("bvh", ["run", "puddle", "--set", f"clip={p}", *SHORT],
                      {"key": "clip", "value": str(p), "file": kind}))
    return cases


# --- meshes (Python API: no scene reads a mesh file from the command line) --------------------
def mesh_cases(rng, folder: Path, n: int):
    folder.mkdir(parents=True, exist_ok=True)
    cases = []
    for k in range(n):
        kind = rng.choice(["truncated", "garbage", "nan", "degenerate", "huge", "index",
                           "empty", "single", "duplicate", "scale", "good"])
        nx = rng.randrange(2, 8)
        xs = np.linspace(0, 1, nx)
        verts = [(x, y, 0.0) for y in xs for x in xs]
        tris = []
        for j in range(nx - 1):
            for i in range(nx - 1):
                a = j * nx + i
                tris += [(a, a + 1, a + nx + 1), (a, a + nx + 1, a + nx)]
        if kind == "nan":
            verts[rng.randrange(len(verts))] = (float("nan"), 0.0, 0.0)
        elif kind == "degenerate":
            tris.append((0, 0, 1))
        elif kind == "index":
            tris.append((0, 1, len(verts) + 5))
        elif kind == "single":
            verts, tris = verts[:3], [(0, 1, 2)] if rng.random() < 0.5 else []
        elif kind == "duplicate":
            tris.append(tris[0])
        elif kind == "scale":
            s = rng.choice([1e-300, 1e300, 1e-12])
            verts = [(x * s, y * s, z * s) for x, y, z in verts]
        lines = [f"v {float(x)!r} {float(y)!r} {float(z)!r}" for x, y, z in verts] + \
                [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in tris]
        text = "\n".join(lines) + "\n"
        if kind == "truncated":
            text = text[: rng.randrange(len(text))]
        elif kind == "garbage":
            text = "".join(rng.choice("vf 0123456789.-e\n/#") for _ in range(rng.randrange(500)))
        elif kind == "empty":
            text = ""
        ext = rng.choice(["obj", "obj", "ply", "stl"]) if kind == "garbage" else "obj"
        p = folder / f"mesh{k:04d}.{ext}"
        p.write_text(text)
        huge = kind == "huge"
        cases.append(("mesh", {"path": str(p), "huge": huge}, {"key": "mesh", "value": str(p),
                                                               "file": kind}))
    return cases


def run_mesh(case):
    """Load, validate and build a network from a mesh file, then step it."""
    from interplay.errors import InterplayError
    from interplay.geometry import mesh
    from interplay.systems.springmass import SpringNetwork
    try:
        if case["huge"]:
            n = 3000
            x = np.random.default_rng(0).uniform(-1, 1, (n, 3))
            t = np.random.default_rng(1).integers(0, n, (20 * n, 3))
            x, t = mesh.validate(x, t, "huge")
        else:
            x, t = mesh.load(case["path"])
        net = SpringNetwork.from_mesh("cloth", x, t, 0.1, 10.0, 5.0, 0.1, dt=1e-3,
                                      integrator="implicit")
        for _ in range(5):
            net.advance(1e-3)
        ok = bool(np.isfinite(net.x).all())
        return ("ok" if ok else "nan"), ""
    except InterplayError as e:
        return "clean", str(e)


# --- saved-run folders ------------------------------------------------------------------------
def folder_cases(rng, good: Path, folder: Path, n: int):
    import shutil
    cases = []
    for k in range(n):
        d = folder / f"run{k:04d}"
        if d.exists():
            shutil.rmtree(d)
        shutil.copytree(good, d)
        kind = rng.choice(["summary-trunc", "scene-trunc", "scene-key", "npz-trunc",
                           "npz-points", "npz-pickle", "npz-dtype", "npz-nan", "npz-missing",
                           "scene-shapes", "empty", "manifest"])
        if kind == "summary-trunc":
            p = d / "summary.json"
            p.write_text(p.read_text()[: rng.randrange(1, 200)])
        elif kind == "scene-trunc":
            p = d / "scene.json"
            p.write_text(p.read_text()[: rng.randrange(1, 400)])
        elif kind == "scene-key":
            doc = json.loads((d / "scene.json").read_text())
            doc.pop(rng.choice(["scene", "fps", "shapes", "coupling", "duration_s"]), None)
            (d / "scene.json").write_text(json.dumps(doc))
        elif kind == "scene-shapes":
            doc = json.loads((d / "scene.json").read_text())
            sh = doc["shapes"][rng.randrange(len(doc["shapes"]))]
            key = rng.choice(list(sh))
            sh[key] = rng.choice([None, "x", -1, [1, 2], {"a": 1}])
            (d / "scene.json").write_text(json.dumps(doc))
        elif kind == "npz-trunc":
            p = d / "tracks.npz"
            b = p.read_bytes()
            p.write_bytes(b[: rng.randrange(1, len(b))])
        else:
            p = d / "tracks.npz"
            with np.load(p) as z:
                arrays = {key: z[key] for key in z.files}
            key = rng.choice([k_ for k_ in arrays if "/" in k_])
            if kind == "npz-points":
                arrays[key] = arrays[key][..., :1]
            elif kind == "npz-pickle":
                arrays[key] = np.array([{"a": 1}, None], dtype=object)
            elif kind == "npz-dtype":
                arrays[key] = arrays[key].astype("U3")
            elif kind == "npz-nan":
                a = arrays[key].astype(float)
                a.flat[rng.randrange(a.size)] = np.nan
                arrays[key] = a
            elif kind == "npz-missing":
                arrays.pop(key)
            elif kind == "empty":
                arrays = {}
            elif kind == "manifest":
                if (d / "manifest.json").exists():
                    (d / "manifest.json").write_text("{")
            with open(p, "wb") as fh:
                np.savez(fh, **arrays, allow_pickle=True) if kind == "npz-pickle" else \
                    np.savez(fh, **arrays)
        if rng.random() < 0.5 and (d / "manifest.json").exists():
            # without the manifest (an older folder, or a deleted one) the contents are checked
            (d / "manifest.json").unlink()
            kind += "-no-manifest"
        cases.append(("folder", {"dir": str(d)}, {"key": "dir", "value": str(d), "file": kind}))
    return cases


def run_folder(case):
    """What `interplay view` does with a folder, without serving it: load, then build every
    frame the viewer would send (on a loopback port the OS picks)."""
    from interplay.errors import InterplayError
    from interplay.outputs.rundata import load_run
    try:
        run = load_run(case["dir"])
        from interplay.cli.viewer import Viewer
        v = Viewer(run, host="127.0.0.1", port=0, log=lambda m: None)
        try:
            for i in range(len(v.times)):
                v.set_frame(i)
        finally:
            v.stop()
        return "ok", ""
    except InterplayError as e:
        return "clean", str(e)


# --- running a case ---------------------------------------------------------------------------
def finite_outputs(out: Path) -> str:
    """'' if every output in ``out`` is finite, else what is not."""
    s = out / "summary.json"
    if s.exists():
        def bad(c):
            raise ValueError(f"{c} in summary.json")
        try:
            json.loads(s.read_text(), parse_constant=bad)
        except ValueError as e:
            return str(e)
    t = out / "tracks.npz"
    if t.exists():
        with np.load(t, allow_pickle=False) as z:
            for key in z.files:
                a = z[key]
                if a.dtype.kind != "f":
                    continue
                if key.endswith("/particles"):
                    rows = np.isfinite(a).all(-1) | np.isnan(a).all(-1)
                    if not rows.all():
                        return f"{key}: a partly non-finite particle"
                elif key.endswith("/particle_radius"):  # NaN past the particle count
                    if np.isinf(a).any():
                        return f"{key}: inf"
                elif not np.isfinite(a).all():
                    return f"{key}: non-finite"
    return ""


def classify_cli(code, err: str, out: Path, meta) -> tuple[str, str]:
    lines = [ln for ln in err.strip().splitlines() if ln.strip()]
    if "Traceback" in err or "internal error" in err:
        return "traceback", (lines[-1] if lines else "")
    if code == 0:
        why = finite_outputs(out)
        return ("nan", why) if why else ("ok", "")
    if code == 2 and len(lines) == 1 and lines[0].startswith("interplay: error:"):
        line = lines[0]
        named = (meta["key"].lstrip("-") in line or meta["key"] in ("compare", "fit-standin")
                 or ("file" in meta and meta["value"] in line))
        value = meta["value"]
        shown = (not value or value[:8] in line or value.lower() in line.lower()
                 or value in ("", "none"))
        return ("clean" if named and shown else "vague"), line
    if any(ln.startswith("interplay: error:") for ln in lines):
        return "buried", " | ".join(lines[-3:])
    return "traceback", " | ".join(lines[-3:])


def child(case, out: Path, result_path: Path):
    """Run one case in this (forked) process and write its outcome."""
    surface, argv, meta = case
    err_path = out.parent / (out.name + ".err")
    fd = os.open(err_path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC)
    os.dup2(fd, 2)
    sys.stderr = io.TextIOWrapper(os.fdopen(2, "wb", buffering=0), write_through=True)
    sys.stdout = open(os.devnull, "w")
    try:
        if surface == "mesh":
            outcome = run_mesh(argv)
        elif surface == "folder":
            outcome = run_folder(argv)
        else:
            from interplay.cli.command import main
            try:
                code = main(argv + ["--out", str(out)])
            except SystemExit as e:
                code = e.code
            sys.stderr.flush()
            outcome = classify_cli(code, err_path.read_text(errors="replace"), out, meta)
    except BaseException as e:  # noqa: BLE001 - what a user would have seen as a traceback
        outcome = ("traceback", f"{type(e).__name__}: {str(e)[:200]}")
        traceback.print_exc()
    result_path.write_text(json.dumps(outcome))
    os._exit(0)


def run_case(case, work: Path, k: int, timeout: float):
    out = work / f"o{k}"
    res = work / f"r{k}.json"
    pid = os.fork()
    if pid == 0:
        child(case, out, res)
    t0 = time.monotonic()
    while True:
        done, status = os.waitpid(pid, os.WNOHANG)
        if done:
            break
        if time.monotonic() - t0 > timeout:
            os.kill(pid, signal.SIGKILL)
            os.waitpid(pid, 0)
            return ("hang", f"over {timeout:g} s"), time.monotonic() - t0
        time.sleep(0.02)
    wall = time.monotonic() - t0
    if not res.exists():
        return ("traceback", f"child died (status {status})"), wall
    outcome = tuple(json.loads(res.read_text()))
    import shutil
    shutil.rmtree(out, ignore_errors=True)
    res.unlink()
    (work / f"o{k}.err").unlink(missing_ok=True)
    return outcome, wall


def good_run(work: Path) -> Path:
    from interplay.cli.command import main
    d = work / "good"
    if not (d / "tracks.npz").exists():
        main(["run", "basketball", "--duration", "0.1", "--quiet", "--no-video", "--no-usd",
              "--no-obj", "--no-report", "--out", str(d)])
    return d


def main():
    def extra(ap):
        ap.add_argument("--seed", type=int, default=0)
        ap.add_argument("--cases", type=int, default=0, help="sample this many (0: all)")
        ap.add_argument("--timeout", type=float, default=40.0)
        ap.add_argument("--surfaces", default="set,option,bvh,mesh,folder")
        ap.add_argument("--label", default="", help="e.g. before / after")
    args, _ = common.parse_args(__doc__, extra)
    from interplay.scenes import all_specs
    from interplay.systems.mocap import clip_path
    rng = random.Random(args.seed)
    machine = common.machine()
    work = Path(tempfile.mkdtemp(prefix="interplay-fuzz-"))
    specs = all_specs()
    surfaces = args.surfaces.split(",")
    cases = []
    if "set" in surfaces:
        cases += set_cases(rng, specs)
    if "option" in surfaces:
        cases += option_cases(rng, specs)
    if "bvh" in surfaces:
        cases += bvh_cases(rng, work / "bvh", clip_path("cmu_02_03_run.bvh"), 400)
    if "mesh" in surfaces:
        cases += mesh_cases(rng, work / "mesh", 600)
    if "folder" in surfaces:
        cases += folder_cases(rng, good_run(work), work / "folders", 400)
    if args.cases:
        cases = random.Random(args.seed + 1).sample(cases, min(args.cases, len(cases)))
    counts: dict = {}
    bad = []
    t0 = time.monotonic()
    for k, case in enumerate(cases):
        outcome, wall = run_case(case, work, k, args.timeout)
        kind, why = outcome
        counts.setdefault(case[0], {}).setdefault(kind, 0)
        counts[case[0]][kind] += 1
        if kind not in ("clean", "ok"):
            argv = case[1] if isinstance(case[1], list) else case[1]
            bad.append({"surface": case[0], "outcome": kind, "case": argv, "meta": case[2],
                        "why": why[:300], "wall_s": round(wall, 2)})
        if k % 50 == 0:
            print(f"{k}/{len(cases)} {time.monotonic() - t0:.0f} s {json.dumps(counts)}",
                  flush=True)
    total = {}
    for c in counts.values():
        for kind, n in c.items():
            total[kind] = total.get(kind, 0) + n
    result = {"label": args.label, "seed": args.seed, "cases": len(cases), "counts": counts,
              "total": total, "wall_s": time.monotonic() - t0, "not_clean": bad,
              "machine": machine}
    name = f"fuzz{'-' + args.label if args.label else ''}.json"
    print(json.dumps(total))
    print("wrote", common.write_json(args.out, name, result))


if __name__ == "__main__":
    main()
