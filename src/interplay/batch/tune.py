"""``interplay tune SCENE``: a scene's Search (control/search.py) on the executor.

The annealing runs here, in the driver; each generation's candidates (one per chain) go to
the workers as one batch and come back in candidate order, so the search is the same whatever
the number of workers. The start is evaluated first, in this process: it is a batch of one,
and it compiles or loads the Numba kernels once before the workers start.

Every evaluation is appended to ``DIR/evaluations.jsonl`` as it arrives (its id is the hash of
the whole run it made); a re-run with the same arguments replays the search, takes the losses
it finds there instead of running them again, and carries on where the log ends. The result
goes to ``DIR/tune.json``: the best values, their loss and the ``--set`` line that runs them.
"""
from __future__ import annotations

import json
import math
import os
import time
from contextlib import ExitStack
from dataclasses import asdict, dataclass
from pathlib import Path

from ..control.search import anneal_batched, check_budget
from ..errors import InterplayError, ParameterError
from ..io.atomic import atomic_path
from ..result import finite
from .executor import Failure, guarded, worker_info
from .variants import RunRequest, default_of, run_id

LOG = "evaluations.jsonl"


@dataclass(frozen=True)
class Candidate:
    """One evaluation: the run (the base request with the candidate's values set), the
    search's name, its id."""
    request: RunRequest
    search: str
    id: str


def evaluate(task: Candidate) -> dict:
    """The search's loss for one candidate (runs in a worker)."""
    t0 = time.perf_counter()
    spec, coupling, kw = task.request.resolve()
    loss = float(spec.search(task.search).loss(coupling, kw))
    return {"loss": loss, "wall_s": time.perf_counter() - t0, "worker": worker_info()}


def check_search(spec, search, params):
    """Every bound names a float parameter, with lo < hi: one line otherwise, before any
    evaluation."""
    for key, (lo, hi) in search.bounds.items():
        default = default_of(params, key, f"{spec.name} search {search.name}:")
        if not isinstance(default, float):
            raise ParameterError(f"{spec.name} search {search.name}: {key} is not a float "
                                 "parameter; a search varies float parameters only")
        if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
            raise ParameterError(f"{spec.name} search {search.name}: bounds of {key} "
                                 f"({lo}, {hi}) must be finite with lo < hi")


def read_log(path: Path) -> dict:
    """{id: entry} of a search's log; a line cut short by a kill is ignored."""
    out = {}
    try:
        lines = path.read_text().splitlines()
    except OSError:
        return out
    for line in lines:
        try:
            e = json.loads(line)
            out[e["id"]] = e
        except (ValueError, KeyError, TypeError):
            continue
    return out


def run_search(base: RunRequest, name: str | None, out, executor, budget: int | None = None,
               seed: int = 0, chains: int | None = None, log=print) -> dict:
    """Run the scene's search ``name`` (None: its first) from the parameters of ``base``;
    returns what it writes to out/tune.json."""
    spec, coupling, kw = base.resolve()
    search = spec.search(name)
    budget = search.budget if budget is None else budget
    chains = search.chains if chains is None else chains
    check_search(spec, search, kw["params"])
    start = {k: default_of(kw["params"], k) for k in search.bounds}
    check_budget(start, search.bounds, budget, chains)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    log_path = out / LOG
    cache = read_log(log_path)
    reused = 0
    state = {"generation": 0, "ran": 0, "started": False}
    t0 = time.perf_counter()
    generations = (budget - 1) // chains
    stack = ExitStack()

    def candidate(values: dict) -> Candidate:
        req = base.with_values({k: repr(float(v)) for k, v in values.items()})
        _, _, ckw = req.resolve()
        return Candidate(req, search.name, run_id(spec.name, coupling, ckw,
                                                  {"search": search.name}))

    def record(c: Candidate, value):
        if isinstance(value, Failure):
            if value.kind == "worker":
                raise InterplayError(f"evaluation {c.id} stopped: {value.message}; run the "
                                     "same command again to resume from its log")
            entry = {"id": c.id, "set": list(c.request.sets[len(base.sets):]), "loss": None,
                     "error": value.message}
        else:
            entry = {"id": c.id, "set": list(c.request.sets[len(base.sets):]),
                     "loss": value["loss"], "wall_s": value["wall_s"],
                     "worker": value["worker"]}
        with open(log_path, "a") as fh:  # one line per evaluation, on disk before the next
            fh.write(json.dumps(finite(entry)) + "\n")
            fh.flush()
            os.fsync(fh.fileno())
        cache[c.id] = finite(entry)
        state["ran"] += 1

    def batch(values: list) -> list:
        nonlocal reused
        cands = [candidate(v) for v in values]
        todo = [c for c in cands if c.id not in cache]
        reused += len(cands) - len(todo)
        if len(todo) == 1 and state["generation"] == 0:  # the start, here: warms Numba
            record(todo[0], guarded(evaluate, todo[0]))
        elif todo:
            if not state["started"]:
                stack.enter_context(executor)
                state["started"] = True
            for i, value in executor.map_unordered(evaluate, todo):
                record(todo[i], value)
        losses = [math.inf if cache[c.id]["loss"] is None else cache[c.id]["loss"]
                  for c in cands]
        state["best"] = min(state.get("best", math.inf), *losses)
        log(f"generation {state['generation']}/{generations}: {len(todo)} evaluated"
            + (f", {len(cands) - len(todo)} from the log" if len(todo) < len(cands) else "")
            + f"; best loss so far {state['best']:.6g}")
        state["generation"] += 1
        return losses

    with stack:
        res = anneal_batched(batch, start, search.bounds, budget, seed, chains,
                             search.t_start, search.t_end, search.step)
    best_set = [f"{k}={v!r}" for k, v in res.best.items()]
    doc = {"scene": spec.name, "search": search.name, "description": search.description,
           "coupling": coupling, "base": asdict(base), "seed": seed, "chains": chains,
           "budget": budget, "evaluations": len(res.history), "ran": state["ran"],
           "from_log": reused, "executor": {"kind": executor.kind, "address": executor.address,
                                            "workers": executor.workers},
           "start": start, "start_loss": res.history[0][1], "best": res.best,
           "loss": res.loss, "set": best_set, "history": [list(h) for h in res.history],
           "wall_s": time.perf_counter() - t0}
    with atomic_path(out / "tune.json") as tmp:
        tmp.write_text(json.dumps(finite(doc), indent=2, allow_nan=False))
    return doc
