"""The coupling advisor: the decision tree of the paper's Figure 17 (SPEC 3), from measured
figures (the interaction's effective acceleration, one-way stability, the two-way cost)."""
from __future__ import annotations

G = 9.81  # m/s^2, the reference acceleration a primary already feels


#: what makes two-way "unreasonably expensive": state values advanced (substeps x values) in
#: a two-way run; 6e9 is about a minute on the 2026 reference machine (1e8 per second). A
#: count, not a wall time, so the verdict does not change with the machine's speed.
WORK_BUDGET = 6e9


def advise(stats: dict, interaction: dict, one_way_stable: bool | None = None,
           two_way_work: float | None = None, work_budget: float = WORK_BUDGET,
           significant_fraction: float = 0.1, debug_cycle: dict | None = None) -> dict:
    """The decision tree of the paper's Figure 17, with the measured reasons.

    interaction: its ``describe()`` (the primary's role, the stand-in, whether two-way is
    implemented); significant: mean effective acceleration over contact >=
    significant_fraction * g.
    one_way_stable: whether a one-way run of the secondary stayed stable (None: not measured).
    two_way_work: state values a two-way run advanced (None: not measured); expensive above
    work_budget.
    debug_cycle: for a primary tuned by hand (the paper's gymnast), the measured wall times
    {"two_way_s": the two-way run, "primary_s": the stand-in's primary pass, "ratio": how
    many times faster the animator's debug cycle must be than two-way}; two-way is then too
    expensive when it takes more than ratio x the primary pass (None: not a criterion).
    """
    if interaction["primary_role"] != "dynamic":
        return {"mode": "one-way", "reasons": [
            f"{stats['primary']} is prescribed (animation, motion capture or a field): nothing "
            "can push back on it, so only one-way coupling applies"]}
    acc = stats["acceleration_m_s2"]
    ratio = acc["mean"] / G
    reasons = [f"effective acceleration on {stats['primary']} over contact: mean "
               f"{acc['mean']:.2f} m/s^2 ({100 * ratio:.1f}% of g), max {acc['max']:.2f} m/s^2"]
    significant = ratio >= significant_fraction
    if not significant:
        reasons.append(f"below {100 * significant_fraction:.0f}% of g: the interaction does not "
                       "significantly affect the primary")
        if one_way_stable is False:
            reasons.append("but the secondary was unstable under one-way coupling")
        else:
            reasons.append("the secondary stayed stable under one-way coupling" if one_way_stable
                           else "one-way stability not measured in this run (assumed stable)")
            return {"mode": "one-way", "reasons": reasons}
    else:
        reasons.append(f"at or above {100 * significant_fraction:.0f}% of g: the interaction "
                       "significantly affects the primary")
    supported = interaction["two_way_supported"]
    expensive = two_way_work is not None and two_way_work > work_budget
    if two_way_work is not None:
        reasons.append(f"a two-way run advances {two_way_work:.3g} state values (budget "
                       f"{work_budget:.3g})")
    if debug_cycle is not None and debug_cycle.get("two_way_s") and debug_cycle.get("primary_s"):
        t2, tp, r = debug_cycle["two_way_s"], debug_cycle["primary_s"], debug_cycle["ratio"]
        slow = t2 > r * tp
        reasons.append(f"her controller is tuned by hand: two-way took {t2:.2f} s, the "
                       f"stand-in's primary pass {tp:.2f} s ({t2 / tp:.1f}x); a debug cycle "
                       f"must be at most 1/{r:g} of two-way"
                       + (": two-way is too slow to tune with" if slow else ": two-way will do"))
        expensive = expensive or slow
    if supported and not expensive:
        reasons.append("two-way coupling is implemented and affordable")
        return {"mode": "two-way", "reasons": reasons}
    if interaction["standin"] is not None:
        reasons.append(f"two-way is {'too expensive' if expensive else 'not implemented'}; "
                       f"a stand-in ({interaction['standin']}) is available")
        return {"mode": "hybrid", "reasons": reasons}
    reasons.append("no stand-in is available: no good compromise (potential problem)")
    return {"mode": "problem", "reasons": reasons}
