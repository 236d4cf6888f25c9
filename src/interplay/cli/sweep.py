"""`interplay sweep` (a wedge of variants of one scene), `interplay tune` (a scene's search) and
`interplay warm` (every scene's kernels compiled into the cache), on the executor: the local
cores by default, a Ray cluster with --ray [ADDRESS] (sweep, tune).

Everything is checked before anything runs: every variant's parameters (each is built once),
the outputs, the workers; a mistake is one line and exit 2. A sweep exits 1 when a variant
failed (the table says which and why) and 0 when all ran.
"""
from __future__ import annotations

from pathlib import Path


def add_parsers(sub, scene_options, output_options):
    """The sweep and tune verbs, with every `run` option (scene_options, output_options: the
    command's own option groups)."""
    sw = sub.add_parser("sweep", help="run variants of a scene (a wedge) on every core or on "
                                      "a Ray cluster: table, contact sheet")
    scene_options(sw)
    sw.add_argument("--coupling", default=None, help="as for run (or vary it: --vary "
                                                     "coupling=two-way,one-way)")
    g = sw.add_argument_group("the wedge (docs/sweeps.md)")
    g.add_argument("--vary", action="append", default=[], metavar="KEY=V1,V2|LO:HI:N",
                   help="values of a --set key (or coupling, integrator, dt); tuples split by "
                        "/; several --vary make a grid")
    g.add_argument("--sample", action="append", default=[], metavar="KEY=LO:HI",
                   help="a range to draw --samples values from")
    g.add_argument("--samples", type=int, default=None, metavar="N",
                   help="how many points the --sample ranges give")
    g.add_argument("--seed", type=int, default=0, help="the samples' seed")
    g.add_argument("--design", default="lhs", metavar="lhs|random",
                   help="Latin hypercube (default) or uniform random samples")
    g.add_argument("--retry-failed", action="store_true",
                   help="also rerun variants that failed in an earlier sweep into this --out")
    g.add_argument("--still-at", type=float, default=None, metavar="S",
                   help="time of every variant's still on the contact sheet (default: half "
                        "the duration)")
    g.add_argument("--no-stills", action="store_true", help="a contact sheet without stills")
    _executor_options(g)
    output_options(sw)
    tune = sub.add_parser("tune", help="run a scene's parameter search (simulated annealing) "
                                       "on every core or on a Ray cluster")
    scene_options(tune)
    tune.add_argument("--coupling", default=None, help="as for run")
    g = tune.add_argument_group("the search (docs/sweeps.md)")
    g.add_argument("--search", default=None, help="which of the scene's searches (default: "
                                                  "its first)")
    g.add_argument("--budget", type=int, default=None, metavar="N",
                   help="evaluations (default: the search's own)")
    g.add_argument("--seed", type=int, default=0)
    g.add_argument("--chains", type=int, default=None, metavar="K",
                   help="chains annealed side by side, one candidate each per batch (the "
                        "result depends on K and the seed, not on --workers)")
    _executor_options(g)
    warm = sub.add_parser("warm", help="compile every scene's kernels into Numba's cache on "
                                       "every core, so that first runs do not wait")
    warm.add_argument("scenes", nargs="*", help="the scenes (default: all)")
    warm.add_argument("--workers", type=int, default=None, metavar="N",
                      help="local worker processes (default: one per core)")
    warm.add_argument("--quiet", action="store_true", help="no line per scene")


def _executor_options(g):
    g.add_argument("--workers", type=int, default=None, metavar="N",
                   help="local worker processes (default: one per core)")
    g.add_argument("--ray", nargs="?", const=True, default=None, metavar="ADDRESS",
                   help="run on a Ray cluster (ADDRESS host:port; none: $RAY_ADDRESS, the "
                        "cluster `ray start` began here, or a local instance)")


def _request(args):
    from ..batch.variants import RunRequest
    return RunRequest(args.scene, args.coupling, tuple(args.sets), args.duration, args.fps,
                      args.integrator, args.dt, bool(getattr(args, "force", False)))


def _log(args, console):
    if args.quiet:
        return lambda line: None
    return lambda line: console.print(line, markup=False, highlight=False, soft_wrap=True)


def cmd_sweep(args, console) -> int:
    from dataclasses import asdict

    from .command import _help_params
    if _help_params(args, console):  # the keys a wedge may vary
        return 0

    from ..batch.executor import make_executor
    from ..batch.sheet import render_stills, write_sheet
    from ..batch.sweep import run_sweep
    from ..batch.variants import design, plan
    from ..errors import ParameterError
    from ..outputs.writer import preflight
    from .command import _outputs
    base = _request(args)
    spec, _, kw = base.resolve()
    points = design(kw["params"], args.vary, args.sample, args.samples, args.seed, args.design)
    variants = plan(base, points)
    if args.still_at is not None and not 0.0 <= args.still_at <= kw["duration"]:
        raise ParameterError(f"--still-at {args.still_at:g}: choose a time from 0 to the "
                             f"duration, {kw['duration']:g} s")
    out = Path(args.out or f"out/{args.scene}-sweep")
    options = _outputs(args, spec)
    preflight(out, options)
    if not args.no_stills:
        from ..outputs.render.gl import gl_context
        gl_context()  # the stills need it: fail now, not after the runs
    executor = make_executor(args.workers, args.ray)
    meta = {"scene": spec.name, "keys": list(points[0]), "base": asdict(base),
            "design": {"vary": args.vary, "sample": args.sample, "samples": args.samples,
                       "seed": args.seed, "method": args.design}}
    log = _log(args, console)
    doc = run_sweep(variants, out, options, executor, meta, args.retry_failed, log)
    stills = {} if args.no_stills else render_stills(out, doc["variants"], args.still_at,
                                                     options.camera)
    sheet = write_sheet(out, doc, stills)
    c = doc["counts"]
    console.print(f"{c['ok']} of {len(variants)} variants ran"
                  + (f", {c['error']} failed (see sweep.csv)" if c["error"] else ""),
                  markup=False)
    for p in (out / "sweep.csv", out / "sweep.json", sheet):
        console.print(f"wrote {p}", markup=False, soft_wrap=True)
    return 1 if c["error"] else 0


def cmd_tune(args, console) -> int:
    from .command import _help_params
    if _help_params(args, console):
        return 0
    from ..batch.executor import make_executor
    from ..batch.tune import run_search
    from ..outputs.writer import ensure_writable
    base = _request(args)
    out = Path(args.out or f"out/{args.scene}-tune")
    ensure_writable(out)
    executor = make_executor(args.workers, args.ray)
    doc = run_search(base, args.search, out, executor, args.budget, args.seed, args.chains,
                     _log(args, console))
    console.print(f"{doc['scene']} {doc['search']}: loss {doc['start_loss']:.6g} at the start, "
                  f"{doc['loss']:.6g} at the best ({doc['evaluations']} evaluations, "
                  f"{doc['from_log']} from the log, {doc['wall_s']:.1f} s)", markup=False,
                  soft_wrap=True)
    console.print(f"run it: interplay run {doc['scene']} "
                  + " ".join(f"--set {s}" for s in (*base.sets, *doc["set"])), markup=False,
                  soft_wrap=True)
    console.print(f"wrote {out / 'tune.json'}", markup=False, soft_wrap=True)
    return 0


def cmd_warm(args, console) -> int:
    import time

    from ..batch.executor import Failure, LocalPool
    from ..batch.warm import tasks, warm_scene
    todo = tasks(args.scenes)  # an unknown scene is one line here, before any worker starts
    log = _log(args, console)
    t0, failed = time.perf_counter(), 0
    with LocalPool(args.workers) as pool:
        # the first scene alone: the kernels most scenes share (springs, collision trees,
        # rigid bodies) are then compiled once, not once per worker
        done = [(0, r) for _, r in pool.map_unordered(warm_scene, todo[:1])]
        rest = ((i + 1, r) for i, r in pool.map_unordered(warm_scene, todo[1:]))
        for i, r in (*done, *rest):
            t = todo[i]
            if isinstance(r, Failure):
                failed += 1
                log(f"{t.scene} {t.coupling}: failed: {r.message}")
            else:
                log(f"{t.scene} {t.coupling}: {r['kernels']} kernels compiled, "
                    f"{r['compile_s']:.1f} s compiling ({r['wall_s']:.1f} s)")
    log(f"warmed {len(todo) - failed} of {len(todo)} scene couplings in "
        f"{time.perf_counter() - t0:.1f} s on {pool.workers} workers")
    return 1 if failed else 0
