"""The bounce's two balance modes and how fast each grows, bounce to bounce: the measure that
found the controller's sideways gains, and the loss of the bounce-growth search
(docs/trampoline.md, "The modes' growth, and search 13").

Her straight bounce is a periodic orbit of the bounce-to-bounce map (takeoff state to the next
takeoff's). Two modes leave it:

* sideways: her figure and the bed are mirror-symmetric, so on the orbit her roll momentum and
  sideways speed are zero; off it they grow or shrink by a factor each bounce. A trial drops
  her with a sideways speed SIDE_SEED (far above round-off, far below where the mode turns
  nonlinear) and the factor is the mean ratio of successive takeoffs' sideways states;
* fore-aft: nothing makes its orbit's state zero (she is not front-back symmetric), but the
  drop is a perturbation of it, and the map contracts it or not: the factor is the mean ratio
  of successive differences between one takeoff's fore-aft state and the last's.

A state is a momentum (kg m^2/s) and a speed (m/s), weighed by SWAY_ARM (kg m): her roll
momentum is about SWAY_ARM times her sideways speed in the growing mode, measured, so both
count. Factors below 1: the orbit is stable in that mode. Measured (docs): search 10's
controller x23 sideways and x2.7 fore-aft; search 13's (the defaults) x3.9 and x2.3.
"""
from __future__ import annotations

import math

import numpy as np

from .bounce_search import rises, trial
from .search import Search

SIDE_SEED = 1e-6  # m/s: the sideways speed a growth trial drops her with
SWAY_ARM = 15.0  # kg m: a speed's weight against a momentum in a mode's state
LINEAR = (0.05, 0.5)  # kg m^2/s: beyond this a mode's state is no longer small (sideways,
#                       fore-aft differences: the fore-aft orbit itself carries ~0.2)
TAKEOFFS = 7  # a growth trial's length: the drop's takeoff and six bounces
UNMEASURED = math.e ** 3  # a mode's factor when no ratio counts (LINEAR): x20 a bounce


def factors(modes) -> tuple[float, float, int]:
    """(sideways, fore-aft growth per bounce, ratios counted) from a trial's modes (rows of
    roll momentum, sideways speed, pitch momentum, forward speed at each takeoff): each the
    geometric mean of the ratios of successive states (sideways) or of successive differences
    (fore-aft), from the second takeoff on (the first ends the drop), while the state is
    small (LINEAR). nan where no ratio counts."""
    m = np.asarray(modes, float).reshape(-1, 4)[1:]
    side = np.hypot(m[:, 0], SWAY_ARM * m[:, 1])
    fore = np.hypot(np.diff(m[:, 2]), SWAY_ARM * np.diff(m[:, 3]))

    def mean_growth(s, small):
        logs = [math.log(s[i + 1] / s[i]) for i in range(len(s) - 1) if 0.0 < s[i] < small]
        return (math.exp(sum(logs) / len(logs)) if logs else math.nan), len(logs)
    g_side, n_side = mean_growth(side, LINEAR[0])
    g_fore, n_fore = mean_growth(fore, LINEAR[1])
    return g_side, g_fore, min(n_side, n_fore)


def growth_score(rec) -> float:
    """A growth trial's loss: the log of the larger of the two modes' growth factors per
    bounce, plus one for each takeoff short of TAKEOFFS (she fell) and the flights' mean miss
    of the drop's height as a fraction (a stable orbit that no longer bounces as high is not
    the bounce wanted)."""
    g_side, g_fore, _ = factors(rec.modes)
    # a mode whose state was never small enough to count has run away: the worst score
    worst = max(g if math.isfinite(g) else UNMEASURED for g in (g_side, g_fore))
    loss = math.log(worst) + (TAKEOFFS - len(rec.takeoffs))
    rise = rises(rec)
    if len(rise) > 1:
        loss += float(abs(rise[1:].mean() - rise[0]) / rise[0])
    return loss


def growth_loss(coupling: str, kw: dict) -> float:
    """The growth search's loss (module-level: workers import it): ``growth_score`` of a
    TAKEOFFS trial of ``kw["params"]`` dropped with SIDE_SEED sideways."""
    return growth_score(trial(kw["params"], coupling, kw["duration"], sideways=SIDE_SEED,
                              takeoffs=TAKEOFFS))


#: the balance gains (control/bounce.py) and their boxes in the growth search: the posture,
#: timing and thrust stay as the bounce search left them, which set the orbit's height
GROWTH_BOUNDS = {"k_speed": (0.0, 0.6), "k_place": (0.0, 1.0), "k_lead": (0.0, 10.0),
                 "k_drift": (0.0, 3.0), "k_spin": (0.0, 0.1), "k_attitude": (0.0, 1.2),
                 "k_turn": (0.0, 0.05), "k_hip_spin": (-0.1, 0.1), "k_arms": (0.0, 1.5),
                 "aim": (0.0, 4.0), "k_side": (-10.0, 10.0), "k_side_drift": (-10.0, 10.0),
                 "k_roll": (-20.0, 20.0), "k_hip_roll": (-0.3, 0.3),
                 "k_turn_side": (-0.02, 0.02), "k_speed_side": (-0.3, 0.3)}

GROWTH = Search(
    "bounce-growth", "the bounce controller's balance gains: the sideways and fore-aft modes' "
    "growth per bounce", bounds={f"bounce.{k}": v for k, v in GROWTH_BOUNDS.items()},
    loss=growth_loss, budget=200, chains=4, t_start=0.5, t_end=0.01, step=0.05)
