"""Controller parameters by search: simulated annealing over a box (SPEC 2.3; the paper tuned
its gymnast's bounce this way).

The search perturbs a few named parameters inside their bounds, keeps a worse candidate with
probability exp(-(loss increase) / T) and cools T geometrically, so early steps can leave a
poor local basin and late ones refine. Every evaluation is one short simulation, so the budget
is counted in evaluations, and a seeded generator makes a search repeatable.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError


@dataclass
class SearchResult:
    """best: parameter name -> value; loss: its loss; history: (evaluation, loss, best loss)
    per evaluation."""
    best: dict
    loss: float
    history: list


def anneal(loss, start: dict, bounds: dict, evaluations: int = 100, seed: int = 0,
           t_start: float = 0.3, t_end: float = 0.003, step: float = 0.25) -> SearchResult:
    """Minimise ``loss(params: dict) -> float`` from ``start`` over ``bounds`` (name -> (lo,
    hi)); step: the proposal's standard deviation as a fraction of each range (shrinking with
    the temperature); t_start, t_end: the temperature (in units of loss) at the first and last
    evaluation."""
    names = list(bounds)
    missing = [k for k in names if k not in start]
    if missing:
        raise ParameterError(f"anneal: start has no value for {', '.join(missing)}")
    if evaluations < 1:
        raise ParameterError(f"anneal: evaluations must be >= 1, got {evaluations}")
    lo = np.array([bounds[k][0] for k in names], dtype=float)
    hi = np.array([bounds[k][1] for k in names], dtype=float)
    rng = np.random.default_rng(seed)
    x = np.clip([float(start[k]) for k in names], lo, hi)
    fx = float(loss(dict(zip(names, x))))
    best, fbest = x.copy(), fx
    history = [(0, fx, fbest)]
    for i in range(1, evaluations):
        frac = i / max(evaluations - 1, 1)
        temp = t_start * (t_end / t_start) ** frac
        scale = step * (hi - lo) * math.sqrt(temp / t_start)
        y = np.clip(x + rng.normal(0.0, 1.0, len(x)) * scale, lo, hi)
        fy = float(loss(dict(zip(names, y))))
        if fy <= fx or rng.random() < math.exp(-(fy - fx) / temp):
            x, fx = y, fy
        if fy < fbest:
            best, fbest = y.copy(), fy
        history.append((i, fy, fbest))
    return SearchResult(dict(zip(names, (float(v) for v in best))), fbest, history)
