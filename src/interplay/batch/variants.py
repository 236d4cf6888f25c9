"""A wedge: the variants of one scene that a sweep runs, each checked before any runs.

``--vary KEY=V1,V2,...`` lists values and ``--vary KEY=LO:HI:N`` spaces N over [LO, HI]
(both ends included); several ``--vary`` make a grid (every combination). ``--sample
KEY=LO:HI`` with ``--samples N --seed S`` adds N points drawn over the box of the sampled keys,
Latin-hypercube by default (each key's range cut into N strata, each stratum used once) or
uniformly at random; combined with ``--vary``, every grid point gets every sample. KEY is any
``--set`` key of the scene, or a run option: ``coupling``, ``integrator``, ``dt``. A tuple
key takes its values separated by ``/``: ``--vary ball.velocity=0,0,-5/0,0,-8``.

Each variant is identified by a stable hash of everything that decides its result (the scene,
the coupling, every parameter after ``--set`` and the variant's own values, the duration, the
output rate, the integrator and step): the same run gets the same id in any sweep, which is
how an interrupted sweep finds what it finished.
"""
from __future__ import annotations

import argparse
import dataclasses
import hashlib
import itertools
import json
import math
from dataclasses import dataclass

import numpy as np

from ..errors import InterplayError, ParameterError
from .executor import Failure

#: run options a wedge may vary besides the scene's parameters
RUN_KEYS = {"coupling": str, "integrator": str, "dt": float}
DESIGNS = ("lhs", "random")


@dataclass(frozen=True)
class RunRequest:
    """What ``interplay run`` is asked, as data: scene, coupling (None: the scene's default),
    sets ("KEY=VALUE" strings, applied in order), duration (s), fps, integrator, dt (s);
    None takes the scene's own; force: run past the cost budget (``--force``; it decides
    whether a run starts, not its result, so it is not part of a run's id)."""
    scene: str
    coupling: str | None = None
    sets: tuple = ()
    duration: float | None = None
    fps: float | None = None
    integrator: str | None = None
    dt: float | None = None
    force: bool = False

    def with_values(self, values: dict) -> "RunRequest":
        """This request with a variant's values: run options replaced, parameters appended
        to the sets (so they win over the base ``--set``)."""
        run = {k: (float(v) if RUN_KEYS[k] is float else v)
               for k, v in values.items() if k in RUN_KEYS}
        sets = self.sets + tuple(f"{k}={v}" for k, v in values.items() if k not in RUN_KEYS)
        return dataclasses.replace(self, sets=sets, **run)

    def resolve(self):
        """(spec, coupling, build keywords), every value checked as ``interplay run`` checks
        it (the same code: the results are the same)."""
        from ..cli.command import _build_kwargs
        ns = argparse.Namespace(scene=self.scene, sets=list(self.sets), duration=self.duration,
                                fps=self.fps, integrator=self.integrator, dt=self.dt,
                                force=self.force, help_params=None)
        spec, kw = _build_kwargs(ns)
        return spec, spec.check_coupling(self.coupling), kw


@dataclass(frozen=True)
class Variant:
    """id (stable hash), values: the varied keys' values as text, in the wedge's key order;
    request: the whole run."""
    id: str
    values: dict
    request: RunRequest

    def label(self) -> str:
        return ", ".join(f"{k}={v}" for k, v in self.values.items())


def run_id(spec_name: str, coupling: str, kw: dict, extra: dict | None = None) -> str:
    """The stable id of a run: a hash of the scene, the coupling and its resolved build
    keywords (every parameter, not only those set), plus ``extra`` (what else decides the
    result, e.g. a search's name)."""
    doc = {"scene": spec_name, "coupling": coupling, "extra": extra or {},
           **{k: (dataclasses.asdict(v) if dataclasses.is_dataclass(v) else v)
              for k, v in kw.items()}}
    text = json.dumps(doc, sort_keys=True, default=repr)
    return "v" + hashlib.sha256(text.encode()).hexdigest()[:12]


def default_of(params, key: str, flag: str = "--vary"):
    """The current value of a dotted key; an unknown key raises the --set error, naming
    ``flag``."""
    from .. import params as P
    if key in RUN_KEYS:
        return None
    v = params
    for part in key.split("."):
        if not hasattr(v, part):
            try:
                P.override(params, key, "0")  # the one-line unknown-key error, listing keys
            except ParameterError as e:
                raise ParameterError(f"{flag} {str(e).removeprefix('--set ')}") from None
        v = getattr(v, part)
    return v


def _number(text: str, what: str) -> float:
    try:
        v = float(text)
    except ValueError:
        raise ParameterError(f"{what}: {text!r} is not a number") from None
    if not math.isfinite(v):
        raise ParameterError(f"{what}: {text!r} must be finite")
    return v


def _text(v: float, integer: bool) -> str:
    return str(int(round(v))) if integer else format(v, ".12g")


def parse_vary(item: str, params) -> tuple[str, list[str]]:
    """``KEY=V1,V2,...`` or ``KEY=LO:HI:N`` -> (key, values as text)."""
    key, eq, spec = item.partition("=")
    key, spec = key.strip(), spec.strip()
    if not eq or not key or not spec:
        raise ParameterError(f"--vary {item}: expected KEY=V1,V2,... or KEY=LO:HI:N")
    default = default_of(params, key)
    if spec.count(":") == 2 and not isinstance(default, (tuple, str, bool)):
        lo, hi, n = spec.split(":")
        count = _number(n, f"--vary {item}")
        if count != int(count) or not 2 <= count <= 10000:
            raise ParameterError(f"--vary {item}: N must be a whole number from 2 to 10000")
        lo_v, hi_v = _number(lo, f"--vary {item}"), _number(hi, f"--vary {item}")
        grid = np.linspace(lo_v, hi_v, int(count))
        integer = isinstance(default, int)
        if integer and np.any(grid != np.round(grid)):
            raise ParameterError(f"--vary {item}: {key} takes whole numbers and these steps are "
                                 f"not whole ({', '.join(format(g, 'g') for g in grid[:4])}...); "
                                 "choose N so that (HI-LO)/(N-1) is whole, or list the values")
        values = [_text(g, integer) for g in grid]
    else:
        values = [v.strip() for v in spec.split("/" if isinstance(default, tuple) else ",")]
    if any(not v for v in values):
        raise ParameterError(f"--vary {item}: an empty value in the list")
    if len(set(values)) < len(values):
        raise ParameterError(f"--vary {item}: a value is listed twice")
    return key, values


def parse_sample(item: str, params) -> tuple[str, float, float, bool]:
    """``KEY=LO:HI`` -> (key, lo, hi, whether the key takes whole numbers)."""
    key, eq, spec = item.partition("=")
    key = key.strip()
    parts = spec.split(":")
    if not eq or not key or len(parts) != 2:
        raise ParameterError(f"--sample {item}: expected KEY=LO:HI")
    default = default_of(params, key, "--sample")
    if key in RUN_KEYS and RUN_KEYS[key] is not float or isinstance(default, (bool, str, tuple)):
        raise ParameterError(f"--sample {item}: {key} is not a number; use --vary with its "
                             "values")
    lo, hi = (_number(p, f"--sample {item}") for p in parts)
    if not lo < hi:
        raise ParameterError(f"--sample {item}: LO must be below HI")
    if isinstance(default, int) and (lo != int(lo) or hi != int(hi)):
        raise ParameterError(f"--sample {item}: {key} takes whole numbers; give whole LO and HI")
    return key, lo, hi, isinstance(default, int)


def unit_samples(n: int, d: int, seed: int, design: str) -> np.ndarray:
    """(n, d) points in [0, 1)^d: Latin hypercube (every key's range in n strata, each used
    once, jittered inside) or uniform."""
    rng = np.random.default_rng(seed)
    if design == "random":
        return rng.random((n, d))
    u = np.empty((n, d))
    for j in range(d):
        u[:, j] = (rng.permutation(n) + rng.random(n)) / n
    return u


def design(params, varies=(), samples=(), n: int | None = None, seed: int = 0,
           method: str = "lhs") -> list[dict]:
    """Every variant's values {key: text}: the grid of ``varies`` times ``n`` samples of
    ``samples`` (see the module's docstring)."""
    if not varies and not samples:
        raise ParameterError("nothing to vary: give --vary KEY=V1,V2,... or --sample KEY=LO:HI "
                             "with --samples N")
    if method not in DESIGNS:
        raise ParameterError(f"--design {method}: choose {' or '.join(DESIGNS)}")
    axes = [parse_vary(v, params) for v in varies]
    ranges = [parse_sample(s, params) for s in samples]
    keys = [k for k, _ in axes] + [r[0] for r in ranges]
    if len(set(keys)) < len(keys):
        twice = sorted({k for k in keys if keys.count(k) > 1})
        raise ParameterError(f"{', '.join(twice)}: varied twice; give each key once")
    if ranges and (n is None or n < 1):
        raise ParameterError("--sample needs --samples N (N >= 1)")
    if n is not None and not ranges:
        raise ParameterError("--samples applies to --sample KEY=LO:HI; none was given")
    drawn = [{}]
    if ranges:
        u = unit_samples(n, len(ranges), seed, method)
        drawn = []
        for row in u:
            point = {}
            for (key, lo, hi, integer), x in zip(ranges, row):
                v = min(math.floor(lo + x * (hi - lo + 1)), hi) if integer else lo + x * (hi - lo)
                point[key] = _text(v, integer)
            drawn.append(point)
    grid = [dict(zip([k for k, _ in axes], combo))
            for combo in itertools.product(*(vals for _, vals in axes))]
    return [{**g, **d} for g in grid for d in drawn]


def plan(base: RunRequest, points: list[dict], build: bool = True) -> list[Variant]:
    """The variants of ``points`` on ``base``, each resolved and (build=True) built once
    without running, so that a bad value in any variant stops the sweep before any run, with
    the variant named."""
    variants = []
    for values in points:
        req = base.with_values(values)
        try:
            spec, coupling, kw = req.resolve()
            if build:
                spec.build(coupling, **kw)
        except Exception as e:  # one line naming the variant, whatever the build raised
            label = ", ".join(f"{k}={v}" for k, v in values.items())
            cls = type(e) if isinstance(e, InterplayError) else InterplayError
            raise cls(f"variant {label}: {Failure.of(e).message}") from None
        variants.append(Variant(run_id(spec.name, coupling, kw), values, req))
    ids = [v.id for v in variants]
    if len(set(ids)) < len(ids):
        same = [v.label() for v in variants if ids.count(v.id) > 1]
        raise ParameterError(f"variants {' and '.join(same[:2])} are the same run; vary each key "
                             "over different values")
    return variants
