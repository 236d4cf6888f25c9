"""Errors a user can cause. Each message says what is wrong, the value, and what to do.

The CLI prints ``str(error)`` on one line and exits non-zero; nothing here carries a traceback
worth showing to an animator.
"""
import math


class InterplayError(Exception):
    """Base class of every error Interplay raises on purpose."""


class ParameterError(InterplayError, ValueError):
    """A parameter is out of range or of the wrong type."""


class SceneError(InterplayError):
    """A scene cannot be built or scheduled (unknown scene, bad coupling graph, ...)."""


class StabilityError(InterplayError):
    """A setting is known to be unstable (a step above the explicit bound) or a run blew up."""


class CostError(InterplayError):
    """A run would need more memory or steps than the budget; ``--force`` goes on anyway."""


class OutputError(InterplayError):
    """A saved run or checkpoint is missing, damaged, of another run, or cannot be written."""


def require_positive(owner: str, name: str, value, unit: str = "") -> float:
    """Return ``value`` as float, or raise ParameterError if it is not finite and > 0."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ParameterError(f"{owner}: {name} must be a number, got {value!r}") from None
    if not (v > 0.0) or v == float("inf"):
        u = f" {unit}" if unit else ""
        raise ParameterError(f"{owner}: {name} must be a positive finite number{u}, got {value!r}")
    return v


def require_nonnegative(owner: str, name: str, value, unit: str = "") -> float:
    """Return ``value`` as float, or raise ParameterError if it is negative or not finite."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ParameterError(f"{owner}: {name} must be a number, got {value!r}") from None
    if not (v >= 0.0) or v == float("inf"):
        u = f" {unit}" if unit else ""
        raise ParameterError(f"{owner}: {name} must be zero or positive{u}, got {value!r}")
    return v


def usable_below(bound: float) -> str:
    """A limit (a stable step's) rounded down to 3 significant digits, as a message's advice:
    rounded to nearest, "use dt <= 0.000125" could name the very step refused at a bound of
    1.2499e-4."""
    e = 10.0 ** (math.floor(math.log10(bound)) - 2)
    return f"{math.floor(bound / e) * e:.3g}"
