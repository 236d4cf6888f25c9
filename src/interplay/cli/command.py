"""The ``interplay`` command: list, run, compare, fit-standin, view; sweep and tune (sweep.py).

Errors a user can cause print one line (no traceback) and exit with status 2.
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from dataclasses import dataclass

from .. import params as P
from ..errors import CostError, InterplayError, ParameterError, StabilityError
from ..params import param
from .sweep import add_parsers, cmd_sweep, cmd_tune, cmd_warm


#: the smallest preview the captions fit in (the overlay's text is ~130 px wide, 34 px high)
MIN_SIZE = (160, 90)


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # one line, not usage + traceback
        print(f"interplay: error: {message}", file=sys.stderr)
        raise SystemExit(2)


@dataclass(frozen=True)
class RunOptions:
    """The command line's numeric options, declared like scene parameters (params.param):
    parsed, bounded and explained by the same domains."""
    duration: float | None = param(None, "s", ge=1e-6, le=1e6, doc="simulated time")
    fps: float | None = param(None, "frames/s", ge=0.01, le=10_000.0)
    dt: float | None = param(None, "s", ge=1e-12, le=1.0, doc="spring-mass step")
    video_fps: float = param(24.0, "frames/s", ge=1.0, le=240.0)
    checkpoint_every: float | None = param(None, "s", gt=0.0, le=1e6,
                                           doc="simulated seconds between checkpoints")
    checkpoint_minutes: float = param(5.0, "min", ge=0.0, le=1e4,
                                      doc="wall minutes between checkpoints (0: never)")


def _options(args) -> RunOptions:
    """RunOptions from the parsed command line (strings), each checked by its domain."""
    opts = RunOptions()
    for key in ("duration", "fps", "dt", "video_fps", "checkpoint_every", "checkpoint_minutes"):
        text = getattr(args, key, None)
        if text is not None:
            try:
                opts = P.override(opts, key, text)
            except ParameterError as e:  # named as on the command line: --video-fps
                flag = "--" + key.replace("_", "-")
                raise ParameterError(str(e).replace(f"{key}=", f"{flag} ", 1)
                                     .replace(f"; {key} must", f"; {flag} must", 1)) from None
    return opts


def _scene_options(p):
    p.add_argument("scene", help="scene name (see `interplay list`)")
    p.add_argument("--duration", default=None, help="simulated seconds (default: the scene's)")
    p.add_argument("--fps", default=None,
                   help="output frames per second (default: the scene's)")
    p.add_argument("--integrator", default=None,
                   help="explicit | implicit | localglobal (spring-mass systems)")
    p.add_argument("--dt", default=None, help="spring-mass step in seconds")
    p.add_argument("--set", dest="sets", action="append", default=[], metavar="KEY=VALUE",
                   help="override a scene parameter, e.g. --set net.cord_ea=300")
    p.add_argument("--out", default=None, help="output directory (default out/SCENE)")
    p.add_argument("--quiet", action="store_true", help="no progress bars")
    p.add_argument("--force", action="store_true",
                   help="run even when the estimated memory or steps exceed the budget")
    p.add_argument("--help-params", nargs="?", const="table", choices=("table", "json"),
                   help="print every --set key with unit, default and range (json: the JSON "
                        "schema) and exit")


def _resume_options(p):
    p.add_argument("--resume", action="store_true",
                   help="continue the interrupted run whose checkpoint is in --out")
    p.add_argument("--checkpoint-every", default=None, metavar="SECONDS",
                   help="save a checkpoint every SECONDS of simulated time")
    p.add_argument("--checkpoint-minutes", default=None, metavar="MIN",
                   help="save a checkpoint every MIN minutes of wall time (default 5; 0: never)")


def _output_options(p):
    g = p.add_argument_group("outputs (USD, OBJ, preview video, report)")
    g.add_argument("--camera", default=None, metavar="EYE:TARGET[:FOV]",
                   help='preview camera "eye_x,eye_y,eye_z:target_x,target_y,target_z[:fov_deg]"'
                        " in m and degrees (default: frame every system)")
    g.add_argument("--size", default="960x540", metavar="WxH",
                   help="video size in pixels (default 960x540; 1280x720 costs twice as much)")
    g.add_argument("--video-fps", default=None,
                   help="video frames per second (default 24, animation's rate)")
    g.add_argument("--usda", action="store_true", help="write text .usda instead of .usdc")
    g.add_argument("--obj", action="store_true",
                   help="also write OBJ sequences (a file per frame per system; off by default)")
    for name in ("usd", "obj", "video", "report"):
        g.add_argument(f"--no-{name}", action="store_true", help=f"skip the {name} output")


def _outputs(args, spec=None):
    """OutputOptions from the command line (checked before any simulation runs); the scene's
    own camera unless --camera is given."""
    from ..outputs.writer import OutputOptions
    from ..outputs.render.camera import parse_camera
    w, x, h = args.size.lower().partition("x")
    if not x or not w.isdigit() or not h.isdigit():
        raise ParameterError(f"--size {args.size}: expected WIDTHxHEIGHT in pixels, e.g. 1280x720")
    from ..outputs.render.video import check_size
    if len(w) > 6 or len(h) > 6:
        raise ParameterError(f"--size {args.size}: at most 999999 pixels a side")
    if (not args.no_video or not args.no_report) and (int(w) < MIN_SIZE[0]
                                                      or int(h) < MIN_SIZE[1]):
        raise ParameterError(f"--size {args.size}: the preview and its captions need at least "
                             f"{MIN_SIZE[0]}x{MIN_SIZE[1]} pixels")
    size = check_size((int(w), int(h)))
    return OutputOptions(usd=not args.no_usd, usd_format="usda" if args.usda else "usdc",
                         obj=args.obj and not args.no_obj, video=not args.no_video,
                         report=not args.no_report,
                         size=size, video_fps=_options(args).video_fps,
                         camera=(parse_camera(args.camera) if args.camera
                                 else spec.camera if spec is not None else None),
                         quiet=args.quiet)


def _parser():
    ap = _Parser(prog="interplay", description="Secondary motion by coupled simulations.")
    sub = ap.add_subparsers(dest="command", required=True, parser_class=_Parser)
    sub.add_parser("list", help="list the scenes")
    run = sub.add_parser("run", help="simulate one scene in one coupling mode")
    _scene_options(run)
    run.add_argument("--coupling", default=None,
                     help="two-way | one-way | hybrid (default: the scene's own)")
    run.add_argument("--controller", default=None, metavar="FILE",
                     help="a controller from `interplay tune` (its tune.json)")
    _resume_options(run)
    _output_options(run)
    cmp_ = sub.add_parser("compare", help="run the three coupling modes side by side")
    _scene_options(cmp_)
    _output_options(cmp_)
    fit = sub.add_parser("fit-standin", help="fit the hybrid stand-in to a two-way run")
    _scene_options(fit)
    view = sub.add_parser("view", help="serve a saved run in a web viewer on localhost")
    view.add_argument("dir", help="a run directory, e.g. out/basketball/two-way")
    view.add_argument("--port", type=int, default=8080, help="TCP port (default 8080)")
    view.add_argument("--host", default="127.0.0.1", help="address to listen on")
    add_parsers(sub, _scene_options, _output_options)
    return ap


def _build_kwargs(args):
    """(the scene's SceneSpec, the build keywords) from the command line, every value checked
    against the spec and the parameters' domains (defaults too) before anything runs, and the
    parameters' element counts against the budget (CostError unless --force)."""
    from ..scenes import spec as scene_spec
    spec = scene_spec(args.scene)
    assignments = {}
    for item in args.sets:
        key, eq, value = item.partition("=")
        if not eq or not key.strip():
            raise ParameterError(f"--set {item[:80]}: expected KEY=VALUE")
        assignments[key.strip()] = value.strip()
    if getattr(args, "controller", None):  # a tuned controller; --set still overrides it
        from .controller import controller_sets
        assignments = {**controller_sets(spec, args.controller), **assignments}
    try:
        params = P.apply(spec.params(), assignments)
    except ParameterError as e:
        raise ParameterError(f"--set {e}") from None
    # a default's own check (the puddle's clip, where no mocap folder is) warns: the scene
    # has its fallback; what the user set is checked strictly above
    notes = P.validate(params, trusted=set(P.keys(params)) - set(assignments))
    args.notes = [f"{spec.name}: {n}" for n in notes]
    if getattr(args, "help_params", None) is None:
        P.check_cost(params, spec.name, args.force, default=spec.params())
    opts = _options(args)
    kw = {"params": params, "fps": opts.fps or spec.fps,
          "duration": opts.duration if opts.duration is not None else spec.duration}
    integrator = spec.check_integrator(args.integrator)
    if integrator is not None:
        kw["integrator"] = integrator
    if opts.dt is not None:
        kw["dt"] = opts.dt
    return spec, kw


def build_scene(spec, mode, kw):
    """The scene, built; a MemoryError while allocating is one line with what to lower."""
    try:
        return spec.build(spec.check_coupling(mode), **kw)
    except MemoryError:
        raise CostError(f"{spec.name}: out of memory while building the scene; lower the "
                        "parameters that set element counts (see --help-params, the x-cost "
                        "column)") from None


def run_scene(spec, mode, kw, quiet=True, force=False, checkpointer=None, resume=None,
              given: str = ""):
    """Build and simulate one scene in one coupling mode (checked against its spec).
    given: what the command line set ("--dt 1e-9, --set net.loops=40"), named in front of
    an error the build or the run raises (a stability bound, a cost), since it is the cause."""
    from ..coupling import compilation
    from .progress import CompileNotice, PassProgress
    notice, c0 = CompileNotice(quiet), compilation.seconds()
    try:
        with compilation.watching(notice):
            scene = build_scene(spec, mode, kw)
            try:
                result = scene.simulate(progress=PassProgress(scene.duration, quiet),
                                        force=force, checkpointer=checkpointer, resume=resume)
            except MemoryError:
                raise CostError(f"{spec.name}: out of memory while simulating; shorten "
                                "--duration, lower --fps, or lower the element counts") from None
        notice.finish(compilation.seconds() - c0)
        return result
    except InterplayError as e:
        if given:
            raise type(e)(f"with {given}: {e}") from None
        raise


def _given(args) -> str:
    """The options and --set assignments the command line gave, as typed."""
    out = [f"--{k} {getattr(args, k)}" for k in ("duration", "fps", "dt", "integrator")
           if getattr(args, k, None) is not None]
    return ", ".join(out + [f"--set {s}" for s in args.sets])


def scene_summary(spec, result, **advice_kw) -> dict:
    """summary.json: the generic summary plus the scene's own key figures."""
    summary = result.summary(**advice_kw)
    if spec.figures is not None:
        summary["figures"] = spec.figures(result)
    return summary


def cmd_list(args, console):
    from ..scenes import all_specs
    for spec in all_specs():
        console.print(f"[bold]{spec.name}[/bold]  {spec.description}")


def _request(args) -> dict:
    """What a run was asked for: its checkpoint and manifest keep it, --resume repeats it."""
    return {"scene": args.scene, "coupling": args.coupling, "sets": list(args.sets),
            "duration": args.duration, "fps": args.fps, "dt": args.dt,
            "integrator": args.integrator, "force": bool(args.force)}


def _help_params(args, console) -> bool:
    if args.help_params is None:
        return False
    from ..scenes import spec as scene_spec
    spec = scene_spec(args.scene)
    if args.help_params == "json":
        print(json.dumps(P.json_schema(spec.params(), f"{spec.name} parameters"), indent=1))
        return True
    from rich.table import Table
    t = Table(title=f"{spec.name}: --set KEY=VALUE")
    for col in ("key", "unit", "default", "accepts", ""):
        t.add_column(col)
    for row in P.table(spec.params()):
        t.add_row(*row)
    console.print(t)
    return True


def cmd_run(args, console):
    if _help_params(args, console):
        return
    out = Path(args.out or f"out/{args.scene}")
    from ..coupling import checkpoint as C
    resume = None
    if args.resume:
        header, arrays = C.read(out / C.FILE)
        req = header["request"]
        if req.get("scene") != args.scene:
            raise ParameterError(f"--resume: the checkpoint in {out} is of scene "
                                 f"{req.get('scene')}, not {args.scene}")
        for key in ("coupling", "sets", "duration", "fps", "dt", "integrator", "force"):
            setattr(args, key, req.get(key))
        resume = (header, arrays)
    spec, kw = _build_kwargs(args)
    mode = spec.check_coupling(args.coupling)
    options = _outputs(args, spec)
    from ..outputs.runfolder import new_run_id
    from ..outputs.writer import preflight, write_outputs
    from ..outputs.runfolder import Lock, claim
    preflight(out, options)
    opts = _options(args)
    run_id = resume[0]["request"].get("run_id") if resume else new_run_id()
    ckpt = C.Checkpointer(out / C.FILE, dict(_request(args), run_id=run_id),
                          opts.checkpoint_every, 60.0 * opts.checkpoint_minutes or None)
    with Lock(out):
        claim(out)
        try:
            result = run_scene(spec, mode, kw, args.quiet, args.force, ckpt, resume,
                               _given(args))
        except StabilityError:  # resuming would only repeat it
            (out / C.FILE).unlink(missing_ok=True)
            raise
        result.warnings[:0] = args.notes
        summary = scene_summary(spec, result)
        paths = write_outputs(result, out, options, summary, run_id, _request(args),
                              locked=True)
        (out / C.FILE).unlink(missing_ok=True)
    from .text import print_run
    print_run(console, result, summary.get("figures"))
    for p in paths:
        console.print(f"wrote {p}", markup=False, soft_wrap=True)


def cmd_compare(args, console):
    from .compare import compare_modes
    spec, kw = _build_kwargs(args)
    spec.check_compare()
    out = Path(args.out or f"out/{args.scene}")
    compare_modes(spec, kw, out, args.quiet, console, _outputs(args, spec))


def cmd_fit(args, console):
    from ..analysis.fitting import fit_standin
    from ..io.atomic import atomic_path
    spec, kw = _build_kwargs(args)
    spec.check_fit()
    params = kw.pop("params")
    if spec.fit is not None:  # the scene's own fit (the mat's: to its load-deflection)
        fit = spec.fit(spec, params, **kw)
        for line in fit["sets"]:
            console.print(f"fitted {line}", markup=False)
        console.print(f"largest error of the fit over the measured loads: "
                      f"{100 * fit['max_error_rel']:.2f}%")
        return _write_fit(args, console, fit)
    console.print("running the two-way reference, then fitting the stand-in ...")
    fit = fit_standin(spec, params, **kw)
    console.print(f"fitted {spec.standin}.linear = {fit['linear']:.6g} N s/m, "
                  f"{spec.standin}.angular = {fit['angular']:.6g} N m s")
    console.print(f"velocity at t={fit['fit_time_s']} s: two-way "
                  f"{_vec(fit['two_way_velocity'])} m/s, hybrid {_vec(fit['hybrid_velocity'])} "
                  f"m/s: speed error {100 * fit['speed_error_rel']:.2f}%, direction off by "
                  f"{fit['direction_error_deg']:.1f} deg ({fit['spin']})")
    _write_fit(args, console, fit)


def _write_fit(args, console, fit):
    from ..io.atomic import atomic_path
    out = Path(args.out or f"out/{args.scene}") / "standin_fit.json"
    with atomic_path(out) as tmp:
        tmp.write_text(json.dumps(fit, indent=2))
    console.print(f"wrote {out}", markup=False, soft_wrap=True)


def _vec(v):
    return "(" + ", ".join(f"{x:.3f}" for x in v) + ")"


def cmd_view(args, console):
    from .viewer import serve
    serve(args.dir, host=args.host, port=args.port, log=lambda m: print(m, flush=True))


COMMANDS = {"list": cmd_list, "run": cmd_run, "compare": cmd_compare, "fit-standin": cmd_fit,
            "view": cmd_view, "sweep": cmd_sweep, "tune": cmd_tune, "warm": cmd_warm}


def _argv(argv):
    """Join an option and a value that starts with '-' (``--camera -2,-6,2:0,0,1``), which
    argparse would take for another option."""
    out, it = [], iter(argv)
    for a in it:
        if a in ("--camera", "--set", "--size") :
            nxt = next(it, None)
            if nxt is not None and nxt.startswith("-") and not nxt.startswith("--"):
                out.append(f"{a}={nxt}")
                continue
            out.append(a)
            if nxt is not None:
                out.append(nxt)
        else:
            out.append(a)
    return out


class Terminated(KeyboardInterrupt):
    """SIGTERM, handled like Ctrl-C: temporaries are removed, the checkpoint stays."""


def _on_sigterm(signum, frame):
    raise Terminated()


#: MuJoCo's warnings of this process (quiet_mujoco), newest last
MUJOCO_WARNINGS: list = []


def quiet_mujoco():
    """MuJoCo writes MUJOCO_LOG.TXT into the working directory on a warning; nothing is
    written outside --out, so its warnings are kept in MUJOCO_WARNINGS instead (the one it
    gives for an unstable figure, NaN in its state, is the figure's health() report too)."""
    try:
        import mujoco
    except ImportError:
        return
    mujoco.set_mju_user_warning(lambda msg: MUJOCO_WARNINGS.append(msg.strip()))


def main(argv=None) -> int:
    import os
    import signal
    from rich.console import Console
    args = _parser().parse_args(_argv(sys.argv[1:] if argv is None else list(argv)))
    console = Console()
    previous = signal.getsignal(signal.SIGTERM)
    try:
        signal.signal(signal.SIGTERM, _on_sigterm)
    except ValueError:  # not the main thread
        previous = None
    quiet_mujoco()
    try:
        code = COMMANDS[args.command](args, console)
    except InterplayError as e:
        print(f"interplay: error: {e}", file=sys.stderr)
        return 2
    except KeyboardInterrupt as e:
        how = "terminated" if isinstance(e, Terminated) else "interrupted"
        print(f"interplay: {how}; `interplay run ... --resume` continues from the last "
              "checkpoint", file=sys.stderr)
        return 143 if isinstance(e, Terminated) else 130
    except BrokenPipeError:  # the reader (head, less) stopped reading: not a failure
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 141
    except Exception as e:  # noqa: BLE001 - a bug, not the user's input: one line, exit 3
        if os.environ.get("INTERPLAY_DEBUG"):
            raise
        print(f"interplay: internal error (a bug, not your input): {type(e).__name__}: "
              f"{str(e).splitlines()[0][:200] if str(e) else ''}; rerun with INTERPLAY_DEBUG=1 "
              "for the traceback", file=sys.stderr)
        return 3
    finally:
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)
    return code or 0


if __name__ == "__main__":
    sys.exit(main())
