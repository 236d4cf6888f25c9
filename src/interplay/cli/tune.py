"""``interplay tune SCENE``: a scene's controller found by simulated annealing (control/
search.py) on its own simulation, candidates evaluated in parallel on the local cores; and
``--controller FILE`` for ``interplay run``: the parameters a search wrote.

The search writes DIR/controller.json (the best parameters, every field of the controller's
parameter dataclass, with the search's settings and the best trial's metrics) and
DIR/history.json (every evaluation: parameters, loss, metrics, temperature, accepted). It
depends only on the scene's parameters, the seed, the budget and the batch size (the
workers), so it repeats from its seed.
"""
from __future__ import annotations

import dataclasses
import json
import os
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

from ..errors import ParameterError, SceneError

CONTROLLER_FILE = "controller.json"


class _Trial:
    """The search's loss as a picklable callable: a candidate's values -> (loss, metrics)."""

    def __init__(self, evaluate, params, coupling, duration):
        self.evaluate, self.params = evaluate, params
        self.coupling, self.duration = coupling, duration

    def __call__(self, values):
        return self.evaluate((self.params, values, self.coupling, self.duration))


def problem(spec):
    """The scene's TuneProblem, or a one-line SceneError naming the scenes that have one."""
    if spec.tune is None:
        from ..scenes import all_specs
        have = ", ".join(s.name for s in all_specs() if s.tune is not None) or "none"
        raise SceneError(f"{spec.name} has no controller search; scenes with one: {have}")
    return spec.tune


def check(spec, coupling, budget, workers):
    """The coupling to search in and the worker count, checked before any trial runs."""
    tp = problem(spec)
    coupling = coupling or tp.couplings[0]
    if coupling not in tp.couplings:
        raise ParameterError(f"--coupling {coupling}: the {spec.name} search runs "
                             f"{' or '.join(tp.couplings)}")
    if budget is not None and budget < 1:
        raise ParameterError(f"--budget {budget}: give at least 1 evaluation")
    cores = os.cpu_count() or 1
    workers = cores if workers is None else workers
    if not 1 <= workers <= 4 * cores:
        raise ParameterError(f"--workers {workers}: choose 1 to {4 * cores} (this machine has "
                             f"{cores} cores)")
    return coupling, workers


def tune(spec, params, coupling=None, budget=None, seed=0, workers=None, log=print,
         start=None):
    """Run the scene's search in ``params`` (the scene's other parameters) from the problem's
    start for the coupling, updated by ``start`` ({name: value}); returns (controller.json's
    content, the SearchResult)."""
    from ..control.search import anneal
    coupling, workers = check(spec, coupling, budget, workers)
    tp = problem(spec)
    budget = budget or tp.budget
    values = {**tp.starts[coupling], **(start or {})}
    base = dataclasses.replace(getattr(params, tp.field), **values)
    params = dataclasses.replace(params, **{tp.field: base})
    trial = _Trial(tp.evaluate, params, coupling, tp.duration)
    t0 = time.perf_counter()

    def progress(done, total, best):
        log(f"{done}/{total} evaluations, best loss {best:.4f}, "
            f"{time.perf_counter() - t0:.0f} s")
    if workers == 1:
        res = anneal(trial, values, tp.bounds, budget, seed, t_start=1.0, t_end=0.01,
                     progress=progress, coordinates=tp.coordinates)
    else:
        with ProcessPoolExecutor(max_workers=workers) as pool:
            res = anneal(trial, values, tp.bounds, budget, seed, t_start=1.0, t_end=0.01,
                         batch=workers, map_fn=pool.map, progress=progress,
                         coordinates=tp.coordinates)
    best = dataclasses.replace(base, **res.best)
    metrics = next(r["metrics"] for r in res.evaluations if r["loss"] == res.loss)
    doc = {"scene": spec.name, "field": tp.field, "params": dataclasses.asdict(best),
           "loss": res.loss, "metrics": metrics, "search": {
               "coupling": coupling, "seed": seed, "budget": budget, "batch": workers,
               "trial_s": tp.duration, "wall_s": time.perf_counter() - t0,
               "tuned": list(tp.bounds), "bounds": tp.bounds}}
    return doc, res


def write(doc, res, out) -> list[Path]:
    """controller.json and history.json in ``out``."""
    from ..io.atomic import atomic_path
    out = Path(out)
    paths = []
    for name, content in ((CONTROLLER_FILE, doc), ("history.json", res.evaluations)):
        path = out / name
        with atomic_path(path) as tmp:
            tmp.write_text(json.dumps(content, indent=1))
        paths.append(path)
    return paths


def controller_sets(spec, path) -> dict:
    """``--set`` assignments for the controller parameters in a controller file (written by
    ``interplay tune``, or its "params" object alone); a one-line error for a file that is
    missing, unreadable, of another scene, or whose parameters are unknown or missing."""
    tp = problem(spec)
    try:
        doc = json.loads(Path(path).read_text())
    except OSError as e:
        raise ParameterError(f"--controller {path}: cannot read it ({e.strerror})") from None
    except json.JSONDecodeError as e:
        raise ParameterError(f"--controller {path}: not JSON ({e.msg}, line {e.lineno})") \
            from None
    if not isinstance(doc, dict):
        raise ParameterError(f"--controller {path}: expected a JSON object of parameters")
    if "scene" in doc and doc["scene"] != spec.name:
        raise ParameterError(f"--controller {path}: a controller for {doc['scene']}, not "
                             f"{spec.name}")
    values = doc.get("params", doc)
    names = [f.name for f in dataclasses.fields(getattr(spec.params(), tp.field))]
    unknown = sorted(set(values) - set(names))
    missing = [n for n in names if n not in values]
    if unknown or missing:
        what = "; ".join(s for s in (
            f"unknown {', '.join(unknown)}" if unknown else "",
            f"missing {', '.join(missing)}" if missing else "") if s)
        raise ParameterError(f"--controller {path}: {what}; a {spec.name} controller has "
                             f"{', '.join(names)}")
    return {f"{tp.field}.{k}": str(v) for k, v in values.items()}


def cmd_tune(args, console):
    from .command import _build_kwargs
    spec, kw = _build_kwargs(args)
    coupling, workers = check(spec, args.coupling, args.budget, args.workers)
    out = Path(args.out or f"out/{args.scene}/tune")
    console.print(f"searching the {spec.name} controller: {coupling}, "
                  f"{args.budget or problem(spec).budget} evaluations on {workers} workers, "
                  f"seed {args.seed}")
    tp = problem(spec)
    given = {}  # the controller values set on the command line: they replace the start's
    for item in args.sets:
        key, _, value = item.partition("=")
        field, _, name = key.strip().partition(".")
        if field == tp.field:
            given[name] = getattr(getattr(kw["params"], tp.field), name)
    doc, res = tune(spec, kw["params"], coupling, args.budget, args.seed, workers,
                    log=(lambda m: None) if args.quiet else console.print, start=given)
    console.print(f"best loss {doc['loss']:.4f}: {doc['metrics']}")
    for p in write(doc, res, out):
        console.print(f"wrote {p}")


def add_parser(sub):
    """The ``tune`` verb's options (registered by cli/command.py)."""
    from .command import _scene_options
    tp = sub.add_parser("tune", help="find a scene's controller by simulated annealing")
    _scene_options(tp)
    tp.add_argument("--budget", type=int, default=None,
                    help="evaluations (default: the scene's)")
    tp.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    tp.add_argument("--coupling", default=None,
                    help="two-way | hybrid: what each trial simulates (default: the scene's)")
    tp.add_argument("--workers", type=int, default=None,
                    help="trials run at once, one process each (default: the cores)")
    return tp
