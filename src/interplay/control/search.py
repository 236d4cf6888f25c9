"""Controller parameters by search: simulated annealing over a box (SPEC 2.3; the paper tuned
its gymnast's bounce this way).

The search perturbs a few named parameters inside their bounds, keeps a worse candidate with
probability exp(-(loss increase) / T) and cools T geometrically, so early steps can leave a
poor local basin and late ones refine. Every evaluation is one short simulation, so the budget
is counted in evaluations, and a seeded generator makes a search repeatable.

Several candidates can be evaluated at once (``batch``, through any ``map``-like callable: a
process pool's, the local cores): each batch is proposed from the current point, evaluated
together, then accepted or not one after another in order, so the search depends on the seed
and the batch size only, never on which worker finished first.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np

from ..errors import ParameterError


@dataclass
class SearchResult:
    """best: parameter name -> value; loss: its loss; history: (evaluation, loss, best loss)
    per evaluation; evaluations: per evaluation a dict of its parameters, loss, metrics (what
    the loss returned beside the number, if anything), temperature and whether the chain
    moved there."""
    best: dict
    loss: float
    history: list
    evaluations: list


@dataclass(frozen=True)
class TuneProblem:
    """A scene's controller search (``interplay tune``): field, the scene parameters' field
    holding the controller's parameters; bounds, name -> (low, high) of the tuned ones;
    evaluate((scene params, {name: value}, coupling, duration)) -> (loss, metrics), a
    module-level function so a process pool can run it; starts: coupling -> {name: value},
    where each search begins (fixed, so a search repeats from its seed whatever the current
    defaults are), the couplings it may run in, default first; duration (s) of a trial;
    budget: default evaluations; coordinates: parameters a proposal moves (None: all)."""
    field: str
    bounds: dict
    evaluate: Callable
    starts: dict
    duration: float = 10.0
    budget: int = 100
    coordinates: int | None = None

    @property
    def couplings(self) -> tuple:
        return tuple(self.starts)


def _split(value):
    """A loss's (number, metrics): a bare number has no metrics."""
    if isinstance(value, tuple):
        return float(value[0]), value[1]
    return float(value), {}


def anneal(loss, start: dict, bounds: dict, evaluations: int = 100, seed: int = 0,
           t_start: float = 0.3, t_end: float = 0.003, step: float = 0.25, batch: int = 1,
           map_fn=map, progress=None, coordinates: int | None = None) -> SearchResult:
    """Minimise ``loss(params: dict) -> float`` (or (float, metrics)) from ``start`` over
    ``bounds`` (name -> (lo, hi)); step: the proposal's standard deviation as a fraction of
    each range (shrinking with the temperature); t_start, t_end: the temperature (in units of
    loss) at the first and last evaluation; batch: candidates evaluated together through
    ``map_fn(loss, [params, ...])``; progress(done, evaluations, best loss) after each
    batch; coordinates: how many parameters, chosen at random, a proposal moves (None: all;
    with many parameters a move of all at once rarely improves on a good point, a move of
    a few does)."""
    names = list(bounds)
    missing = [k for k in names if k not in start]
    if missing:
        raise ParameterError(f"anneal: start has no value for {', '.join(missing)}")
    if evaluations < 1:
        raise ParameterError(f"anneal: evaluations must be >= 1, got {evaluations}")
    if batch < 1:
        raise ParameterError(f"anneal: batch must be >= 1, got {batch}")
    lo = np.array([bounds[k][0] for k in names], dtype=float)
    hi = np.array([bounds[k][1] for k in names], dtype=float)
    rng = np.random.default_rng(seed)
    x = np.clip([float(start[k]) for k in names], lo, hi)
    fx, metrics = _split(next(iter(map_fn(loss, [dict(zip(names, x))]))))
    best, fbest = x.copy(), fx
    history = [(0, fx, fbest)]
    records = [{"evaluation": 0, "params": dict(zip(names, x.tolist())), "loss": fx,
                "metrics": metrics, "temperature": t_start, "accepted": True}]
    if progress is not None:
        progress(1, evaluations, fbest)
    i = 1
    while i < evaluations:
        proposals = []
        for b in range(min(batch, evaluations - i)):
            frac = (i + b) / max(evaluations - 1, 1)
            temp = t_start * (t_end / t_start) ** frac
            scale = step * (hi - lo) * math.sqrt(temp / t_start)
            move = rng.normal(0.0, 1.0, len(x)) * scale
            if coordinates is not None and coordinates < len(x):
                keep = np.zeros(len(x), dtype=bool)
                keep[rng.choice(len(x), coordinates, replace=False)] = True
                move[~keep] = 0.0
            proposals.append((np.clip(x + move, lo, hi), temp))
        values = map_fn(loss, [dict(zip(names, y)) for y, _ in proposals])
        for (y, temp), value in zip(proposals, values):
            fy, metrics = _split(value)
            moved = fy <= fx or rng.random() < math.exp(-(fy - fx) / temp)
            if moved:
                x, fx = y, fy
            if fy < fbest:
                best, fbest = y.copy(), fy
            history.append((i, fy, fbest))
            records.append({"evaluation": i, "params": dict(zip(names, y.tolist())),
                            "loss": fy, "metrics": metrics, "temperature": temp,
                            "accepted": bool(moved)})
            i += 1
        if progress is not None:
            progress(i, evaluations, fbest)
    return SearchResult(dict(zip(names, (float(v) for v in best))), fbest, history, records)
