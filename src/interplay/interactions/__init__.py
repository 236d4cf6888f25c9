"""Force exchanges between two systems; each returns equal and opposite forces."""
from .base import MODES, Interaction, StandIn

__all__ = ["MODES", "Interaction", "StandIn"]
