"""Sorting inside kernels, without Numba's own sort.

Numba compiles np.argsort(kind="mergesort") for ~0.8-0.9 s on a first run (an empty cache)
for each key type: half the collision tree's build, two thirds of the water's lid grouping.
A merge sort written out compiles in a fraction of that and gives the same permutation.
"""
import numpy as np
from numba import njit


@njit(cache=True)
def stable_argsort(keys):
    """The permutation that sorts ``keys`` (n,) ascending, equal keys in their given order:
    np.argsort(kind="mergesort")'s, by a bottom-up merge sort written out."""
    n = keys.shape[0]
    a = np.arange(n)
    b = np.empty(n, np.int64)
    width = 1
    while width < n:
        for lo in range(0, n, 2 * width):
            mid = min(lo + width, n)
            hi = min(lo + 2 * width, n)
            i, j = lo, mid
            for k in range(lo, hi):
                # the left run's key wins ties: stable
                if i < mid and (j >= hi or keys[a[i]] <= keys[a[j]]):
                    b[k] = a[i]
                    i += 1
                else:
                    b[k] = a[j]
                    j += 1
        a, b = b, a
        width *= 2
    return a
