"""The scene contract: every scene registers one ``SceneSpec``, and the command line checks a
request against it before anything is simulated."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

from ..coupling.modes import MODES
from ..errors import ParameterError, SceneError


@dataclass(frozen=True)
class SceneSpec:
    """What a scene is and what it supports.

    name, description (one line, for ``interplay list``); build(coupling, duration, fps,
    integrator, dt, params) -> Scene; params: its parameter dataclass (``--set`` keys);
    couplings: the coupling modes it supports, default first; duration (s) and fps: defaults;
    integrators: the ``--integrator`` values that apply (empty: none does, e.g. the water has
    one); standin: the params field holding its hybrid stand-in's coefficients when
    ``interplay fit-standin`` can fit them, with fit_time (s): the time at which the
    primary's velocity is matched; camera: its default preview camera (an
    outputs.render.camera Camera or TrackingCamera; None: frame every system); key_time (s):
    the moment its figure shows (the ball in the net), the gallery's still; figures: result ->
    {label: value}, the scene's own key figures (the basketball's exit speed) for summaries
    and compare tables; searches: the ``control.search.Search``es ``interplay tune`` can run
    on it (the first is the default); heavy: its build or each trial of its search takes
    seconds (the runner cuts and dresses garments; the diver flies his dive against still
    water, a different dive for each fuzzed parameter; a trampoline bounce trial), so the
    every-scene tests that build it many times (the fuzz, every CLI verb) run it only in the
    slow suite, its own tests covering it in the default one; fit: (spec, params, **build
    keywords) -> report, a scene's own stand-in fit for ``fit-standin`` instead of matching
    the velocity at fit_time (the mat's: its curve to the mat's load-deflection; the report's
    "sets" are the fitted --set lines); debug_ratio: its primary is tuned by hand, so
    ``compare``'s advisor wants its debug cycle at most 1/debug_ratio of two-way's
    (analysis/advisor.py; None: the advisor counts work only); contrast: {mode: Result} ->
    {label: value}, figures across the couplings for ``compare`` (the mat's: hybrid's
    centre-of-mass path off two-way's); warm_time (s): how far ``interplay warm`` runs it so
    that every kernel of a run compiles, past the moment its interactions first act (the
    ball reaching the net); None: two output frames, when they act from the start.
    """
    name: str
    description: str
    build: Callable
    params: type
    couplings: tuple = MODES
    duration: float = 1.5
    fps: float = 60.0
    integrators: tuple = ()
    standin: str | None = None
    fit_time: float | None = None
    camera: object = None
    key_time: float | None = None
    figures: Callable | None = field(default=None, compare=False)
    searches: tuple = field(default=(), compare=False)
    heavy: bool = False
    fit: Callable | None = field(default=None, compare=False)
    debug_ratio: float | None = None
    contrast: Callable | None = field(default=None, compare=False)
    warm_time: float | None = None

    @property
    def default_coupling(self) -> str:
        return self.couplings[0]

    def check_coupling(self, mode: str | None) -> str:
        """The coupling to run (the default for None); one-line errors for the others."""
        if mode is None:
            return self.default_coupling
        if mode not in MODES:
            raise ParameterError(f"--coupling {mode}: unknown coupling; choose one of "
                                 f"{', '.join(MODES)}")
        if mode not in self.couplings:
            raise SceneError(f"{self.name} supports {_list(self.couplings)} coupling, not {mode}"
                             f"{self._why(mode)}")
        return mode

    def _why(self, mode) -> str:
        if mode == "hybrid":
            return " (it has no stand-in for hybrid)"
        return ""

    def check_integrator(self, integrator: str | None) -> str | None:
        if integrator is None:
            return None
        if not self.integrators:
            raise ParameterError(f"{self.name}: --integrator {integrator} does not apply: its "
                                 "systems have one integrator each; leave it out")
        if integrator not in self.integrators:
            raise ParameterError(f"--integrator {integrator}: choose one of "
                                 f"{', '.join(self.integrators)}")
        return integrator

    def check_compare(self):
        """compare runs every supported coupling; a scene with one has nothing to compare."""
        if len(self.couplings) < 2:
            raise SceneError(f"{self.name} supports only {_list(self.couplings)} coupling: "
                             "there is nothing to compare; use `interplay run "
                             f"{self.name}`")

    def search(self, name: str | None = None):
        """The Search called ``name`` (None: the scene's first); one line when there is none."""
        if not self.searches:
            from . import all_specs
            have = [s.name for s in all_specs() if s.searches]
            raise SceneError(f"{self.name} offers no search to tune; scenes with one: "
                             f"{', '.join(have) or 'none'}")
        if name is None:
            return self.searches[0]
        for s in self.searches:
            if s.name == name:
                return s
        raise ParameterError(f"--search {name}: {self.name} has no such search; choose "
                             f"{_list([s.name for s in self.searches])}")

    def check_fit(self):
        if self.standin is None or (self.fit_time is None and self.fit is None):
            raise SceneError(f"{self.name} has no stand-in that fit-standin can fit"
                             f"{'' if 'hybrid' in self.couplings else ' (no hybrid coupling)'}"
                             "; scenes with one: "
                             f"{', '.join(s.name for s in fittable())}")


def _list(items) -> str:
    items = list(items)
    return items[0] if len(items) == 1 else ", ".join(items[:-1]) + " or " + items[-1]


def fittable():
    from . import all_specs
    return [s for s in all_specs() if s.standin is not None
            and (s.fit_time is not None or s.fit is not None)]
