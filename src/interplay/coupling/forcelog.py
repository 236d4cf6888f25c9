"""The force an interaction exerts on its primary, logged at every coupling step."""
from __future__ import annotations

import numpy as np

GAP = 0.05  # s: an inactive spell shorter than this does not split a period of contact


class ForceLog:
    """Per coupling step: time (s), force (N) and torque (N m) on the primary, contact flag,
    and the peak force magnitude (N) within the step.

    When the secondary sub-cycles the interaction, force and torque are the step's means
    (impulse / h, exact for momentum) and the peak is the largest substep force; otherwise
    the peak is |force|.

    The force is what the full interaction computes on the primary, whether or not the coupling
    mode applies it (one-way and hybrid compute it in the secondary's pass); a hybrid run also
    logs what its stand-in applied in the primary's pass (``standin``).
    """

    def __init__(self, name, primary, secondary, mode, primary_mass, period_from=0.0):
        self.name, self.primary, self.secondary, self.mode = name, primary, secondary, mode
        self.primary_mass = float(primary_mass)
        self.period_from = float(period_from)  # s: see Interaction.period_from
        self.t = np.zeros(0)
        self.force = np.zeros((0, 3))
        self.torque = np.zeros((0, 3))
        self.active = np.zeros(0, dtype=bool)
        self.peak = np.zeros(0)
        self.standin: ForceLog | None = None
        self._n = 0

    def allocate(self, n: int):
        self.t = np.empty(n)
        self.force = np.empty((n, 3))
        self.torque = np.empty((n, 3))
        self.active = np.empty(n, dtype=bool)
        self.peak = np.empty(n)
        self._n = 0

    def record(self, t, force, torque, active, peak=None):
        i = self._n
        self.t[i] = t
        self.force[i] = force
        self.torque[i] = torque
        self.active[i] = active
        self.peak[i] = peak if peak is not None else np.sqrt(force[0] ** 2 + force[1] ** 2
                                                             + force[2] ** 2)
        self._n = i + 1

    def trim(self):
        n = self._n
        self.t, self.force = self.t[:n], self.force[:n]
        self.torque, self.active, self.peak = self.torque[:n], self.active[:n], self.peak[:n]

    @property
    def magnitude(self) -> np.ndarray:
        return np.linalg.norm(self.force, axis=1)

    def episodes(self, gap: float = None) -> list[tuple[float, float]]:
        """Periods of contact (start, end) in s; inactive spells shorter than ``gap`` s (a cord
        flicking off the ball for a moment) do not split a period."""
        gap = GAP if gap is None else gap
        idx = np.flatnonzero(self.active)
        if len(idx) == 0:
            return []
        t = self.t[idx]
        breaks = np.flatnonzero(np.diff(t) > gap)
        starts = np.concatenate([[0], breaks + 1])
        ends = np.concatenate([breaks, [len(t) - 1]])
        return [(float(t[a]), float(t[b])) for a, b in zip(starts, ends)]

    def contact_period(self) -> tuple[float, float] | None:
        """The period of contact Table I reports, or None if never: the first; with
        ``period_from`` the first that starts at or after it and lasts at least GAP (the knocks
        of a slack noose falling with him are not its work), else the one going on then, from
        then on."""
        eps = self.episodes()
        t0 = self.period_from
        later = [e for e in eps if e[0] >= t0 and (t0 <= 0.0 or e[1] - e[0] >= GAP)]
        if later:
            return later[0]
        during = [(t0, e[1]) for e in eps if e[1] >= t0]
        return during[0] if during else None
