"""Numba kernels: pure functions over NumPy arrays, no Python objects. Hot loops live here only."""
