"""The ``interplay`` command: list, run, compare, fit-standin, tune (cli/tune.py) and view.

Errors a user can cause print one line (no traceback) and exit with status 2.
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from ..errors import InterplayError, ParameterError


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # one line, not usage + traceback
        print(f"interplay: error: {message}", file=sys.stderr)
        raise SystemExit(2)


def _scene_options(p):
    p.add_argument("scene", help="scene name (see `interplay list`)")
    p.add_argument("--duration", type=float, default=None,
                   help="simulated seconds (default: the scene's)")
    p.add_argument("--fps", type=float, default=None,
                   help="output frames per second (default: the scene's)")
    p.add_argument("--integrator", default=None,
                   help="explicit | implicit | localglobal (spring-mass systems)")
    p.add_argument("--dt", type=float, default=None, help="spring-mass step in seconds")
    p.add_argument("--set", dest="sets", action="append", default=[], metavar="KEY=VALUE",
                   help="override a scene parameter, e.g. --set net.cord_ea=300")
    p.add_argument("--out", default=None, help="output directory (default out/SCENE)")
    p.add_argument("--quiet", action="store_true", help="no progress bars")


def _output_options(p):
    g = p.add_argument_group("outputs (USD, OBJ, preview video, report)")
    g.add_argument("--camera", default=None, metavar="EYE:TARGET[:FOV]",
                   help='preview camera "eye_x,eye_y,eye_z:target_x,target_y,target_z[:fov_deg]"'
                        " in m and degrees (default: frame every system)")
    g.add_argument("--size", default="1280x720", metavar="WxH", help="video size in pixels")
    g.add_argument("--video-fps", type=float, default=30.0, help="video frames per second")
    g.add_argument("--usda", action="store_true", help="write text .usda instead of .usdc")
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
    size = check_size((int(w), int(h)))
    if not 1.0 <= args.video_fps <= 240.0:
        raise ParameterError(f"--video-fps {args.video_fps:g}: choose 1 to 240 frames/s")
    return OutputOptions(usd=not args.no_usd, usd_format="usda" if args.usda else "usdc",
                         obj=not args.no_obj, video=not args.no_video, report=not args.no_report,
                         size=size, video_fps=args.video_fps,
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
                     help="controller parameters from `interplay tune` (controller.json)")
    _output_options(run)
    cmp_ = sub.add_parser("compare", help="run the three coupling modes side by side")
    _scene_options(cmp_)
    _output_options(cmp_)
    fit = sub.add_parser("fit-standin", help="fit the hybrid stand-in to a two-way run")
    _scene_options(fit)
    from .tune import add_parser as add_tune
    add_tune(sub)
    view = sub.add_parser("view", help="serve a saved run in a web viewer on localhost")
    view.add_argument("dir", help="a run directory, e.g. out/basketball/two-way")
    view.add_argument("--port", type=int, default=8080, help="TCP port (default 8080)")
    view.add_argument("--host", default="127.0.0.1", help="address to listen on")
    return ap


def _build_kwargs(args):
    """(the scene's SceneSpec, the build keywords) from the command line, every value checked
    against the spec before anything runs."""
    from .. import params as P
    from ..scenes import spec as scene_spec
    spec = scene_spec(args.scene)
    assignments = {}
    for item in args.sets:
        key, eq, value = item.partition("=")
        if not eq or not key:
            raise ParameterError(f"--set {item}: expected KEY=VALUE")
        assignments[key.strip()] = value.strip()
    if getattr(args, "controller", None):  # a tuned controller; --set still overrides it
        from .tune import controller_sets
        assignments = {**controller_sets(spec, args.controller), **assignments}
    kw = {"params": P.apply(spec.params(), assignments), "fps": args.fps or spec.fps,
          "duration": args.duration if args.duration is not None else spec.duration}
    integrator = spec.check_integrator(args.integrator)
    if integrator is not None:
        kw["integrator"] = integrator
    if args.dt is not None:
        kw["dt"] = args.dt
    return spec, kw


def run_scene(spec, mode, kw, quiet=True):
    """Build and simulate one scene in one coupling mode (checked against its spec)."""
    from .progress import PassProgress
    scene = spec.build(spec.check_coupling(mode), **kw)
    return scene.simulate(progress=PassProgress(scene.duration, quiet))


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


def cmd_run(args, console):
    spec, kw = _build_kwargs(args)
    mode = spec.check_coupling(args.coupling)
    out = Path(args.out or f"out/{args.scene}")
    options = _outputs(args, spec)
    from ..outputs.writer import preflight, write_outputs
    preflight(out, options)
    result = run_scene(spec, mode, kw, args.quiet)
    paths = write_outputs(result, out, options, scene_summary(spec, result))
    from .text import print_run
    print_run(console, result)
    for p in paths:
        console.print(f"wrote {p}")


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
    console.print("running the two-way reference, then fitting the stand-in ...")
    fit = fit_standin(spec, params, **kw)
    console.print(f"fitted {spec.standin}.linear = {fit['linear']:.6g} N s/m, "
                  f"{spec.standin}.angular = {fit['angular']:.6g} N m s")
    console.print(f"velocity at t={fit['fit_time_s']} s: two-way "
                  f"{_vec(fit['two_way_velocity'])} m/s, hybrid {_vec(fit['hybrid_velocity'])} "
                  f"m/s: speed error {100 * fit['speed_error_rel']:.2f}%, direction off by "
                  f"{fit['direction_error_deg']:.1f} deg ({fit['spin']})")
    out = Path(args.out or f"out/{args.scene}") / "standin_fit.json"
    with atomic_path(out) as tmp:
        tmp.write_text(json.dumps(fit, indent=2))
    console.print(f"wrote {out}")


def _vec(v):
    return "(" + ", ".join(f"{x:.3f}" for x in v) + ")"


def cmd_tune(args, console):
    from .tune import cmd_tune as tune
    tune(args, console)


def cmd_view(args, console):
    from .viewer import serve
    serve(args.dir, host=args.host, port=args.port, log=lambda m: print(m, flush=True))


COMMANDS = {"list": cmd_list, "run": cmd_run, "compare": cmd_compare, "fit-standin": cmd_fit,
            "tune": cmd_tune, "view": cmd_view}


def main(argv=None) -> int:
    from rich.console import Console
    args = _parser().parse_args(argv)
    console = Console()
    try:
        COMMANDS[args.command](args, console)
    except InterplayError as e:
        print(f"interplay: error: {e}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("interplay: interrupted", file=sys.stderr)
        return 130
    return 0


if __name__ == "__main__":
    sys.exit(main())
