"""The coupling modes (SPEC 1): the one list every part of Interplay checks against."""

MODES = ("two-way", "one-way", "hybrid")
