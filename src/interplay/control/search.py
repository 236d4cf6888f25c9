"""Controller parameters by search: simulated annealing over a box (SPEC 2.3; the paper tuned
its gymnast's bounce this way).

The search perturbs a few named parameters inside their bounds, keeps a worse candidate with
probability exp(-(loss increase) / T) and cools T geometrically, so early steps can leave a
poor local basin and late ones refine. Every evaluation is one short simulation, so the budget
is counted in evaluations, and a seeded generator makes a search repeatable.

``anneal_batched`` runs several chains side by side (population annealing): each generation
every chain proposes one candidate, the whole batch is evaluated at once (in parallel, by
``interplay tune`` on the executor), then each chain accepts or rejects its own. A few times
over the schedule the chains are resampled by their Boltzmann weights exp(-(loss - best)/T),
so chains stuck in poor basins move to good ones. Every random draw is made here, in a fixed
order, and a batch's losses come back in candidate order, so the result depends on the seed
and the number of chains only, never on how many workers evaluated the batches. With one
chain it is ``anneal`` exactly.

A scene offers a search to ``interplay tune`` by listing a ``Search`` in its SceneSpec.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from ..errors import ParameterError


@dataclass
class SearchResult:
    """best: parameter name -> value; loss: its loss; history: (evaluation, loss, best loss)
    per evaluation."""
    best: dict
    loss: float
    history: list


@dataclass(frozen=True)
class Search:
    """A search a scene offers to ``interplay tune SCENE``.

    name, description (one line); bounds: {dotted parameter key (a float field, as for
    ``--set``): (lo, hi) in its unit}; the search starts from the scene's parameters (defaults
    and ``--set``); loss(coupling, kw) -> float to minimise, where kw are the scene's build
    keywords (params, duration, fps, and integrator and dt when given): a module-level
    function, so that worker processes and Ray nodes can import it; budget: evaluations by
    default; chains: parallel chains by default (the batch size; the result depends on it, not
    on the number of workers); t_start, t_end, step: as ``anneal``."""
    name: str
    description: str
    bounds: dict = field(compare=False)
    loss: Callable = field(compare=False)
    budget: int = 100
    chains: int = 4
    t_start: float = 0.3
    t_end: float = 0.003
    step: float = 0.25


class _Chain:
    """One annealing chain: its own generator, current point and loss."""

    def __init__(self, rng, x, fx):
        self.rng, self.x, self.fx = rng, x, fx

    def propose(self, lo, hi, scale):
        return np.clip(self.x + self.rng.normal(0.0, 1.0, len(self.x)) * scale, lo, hi)

    def consider(self, y, fy, temp):
        """Metropolis: keep y if it is no worse, else with probability exp(-(fy - fx)/T)."""
        if fy <= self.fx or self.rng.random() < math.exp(-(fy - self.fx) / temp):
            self.x, self.fx = y, fy


def check_budget(start, bounds, evaluations, chains):
    """One line for a start missing a bound's value, no evaluations or a chain count that
    does not fit in them."""
    missing = [k for k in bounds if k not in start]
    if missing:
        raise ParameterError(f"anneal: start has no value for {', '.join(missing)}")
    if evaluations < 1:
        raise ParameterError(f"anneal: evaluations (--budget) must be >= 1, got {evaluations}")
    if not 1 <= chains <= max(evaluations - 1, 1):
        raise ParameterError(f"anneal: chains (--chains) must be from 1 to the evaluations - 1 "
                             f"({max(evaluations - 1, 1)}), got {chains}")


def anneal_batched(evaluate, start: dict, bounds: dict, evaluations: int = 100, seed: int = 0,
                   chains: int = 1, t_start: float = 0.3, t_end: float = 0.003,
                   step: float = 0.25, resamples: int = 3) -> SearchResult:
    """Minimise over ``bounds`` (name -> (lo, hi)) from ``start`` with ``chains`` chains;
    ``evaluate(list of {name: value}) -> list of losses`` (same order) is called once for the
    start, then once per generation with one candidate per chain: 1 + chains * ((evaluations
    - 1) // chains) evaluations in all. step: the proposal's standard deviation as a fraction
    of each range (shrinking with the temperature); t_start, t_end: the temperature (in units
    of loss) at the first and last generation; resamples: how many times the chains are
    resampled by their Boltzmann weights (evenly over the schedule; none with one chain)."""
    check_budget(start, bounds, evaluations, chains)
    names = list(bounds)
    lo = np.array([bounds[k][0] for k in names], dtype=float)
    hi = np.array([bounds[k][1] for k in names], dtype=float)
    x0 = np.clip([float(start[k]) for k in names], lo, hi)
    as_dict = lambda v: dict(zip(names, (float(a) for a in v)))  # noqa: E731
    f0 = float(evaluate([as_dict(x0)])[0])
    # chain 0 draws from default_rng(seed), as the one-chain search always has
    pool = [_Chain(np.random.default_rng(seed if k == 0 else [seed, k]), x0.copy(), f0)
            for k in range(chains)]
    mixer = np.random.default_rng([seed, chains, 2 ** 32])  # the resampling's own draws
    best, fbest = x0.copy(), f0
    history = [(0, f0, fbest)]
    generations = (evaluations - 1) // chains
    every = max(generations // (resamples + 1), 1) if chains > 1 and resamples > 0 else 0
    for g in range(1, generations + 1):
        temp = t_start * (t_end / t_start) ** (g / max(generations, 1))
        scale = step * (hi - lo) * math.sqrt(temp / t_start)
        ys = [c.propose(lo, hi, scale) for c in pool]
        fys = [float(f) for f in evaluate([as_dict(y) for y in ys])]
        for k, (c, y, fy) in enumerate(zip(pool, ys, fys)):
            c.consider(y, fy, temp)
            if fy < fbest:
                best, fbest = y.copy(), fy
            history.append((1 + (g - 1) * chains + k, fy, fbest))
        if every and g % every == 0 and g < generations:
            _resample(pool, temp, mixer)
    return SearchResult(as_dict(best), fbest, history)


def _resample(pool, temp, rng):
    """Population annealing's step: each chain restarts from a chain drawn with probability
    proportional to exp(-(loss - best)/T); the chains keep their own generators."""
    f = np.array([c.fx for c in pool])
    finite = np.isfinite(f)
    if not finite.any():
        return
    w = np.where(finite, np.exp(-(np.where(finite, f, 0.0) - f[finite].min()) / temp), 0.0)
    picks = rng.choice(len(pool), size=len(pool), p=w / w.sum())
    states = [(pool[j].x.copy(), pool[j].fx) for j in picks]
    for c, (x, fx) in zip(pool, states):
        c.x, c.fx = x, fx


def anneal(loss, start: dict, bounds: dict, evaluations: int = 100, seed: int = 0,
           t_start: float = 0.3, t_end: float = 0.003, step: float = 0.25) -> SearchResult:
    """Minimise ``loss(params: dict) -> float`` from ``start`` over ``bounds`` (name -> (lo,
    hi)), one candidate at a time (``anneal_batched`` with one chain)."""
    return anneal_batched(lambda batch: [loss(c) for c in batch], start, bounds, evaluations,
                          seed, 1, t_start, t_end, step)
