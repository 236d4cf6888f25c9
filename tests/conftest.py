"""Test settings: keep Numba and BLAS from fighting over the two cores (DESIGN.md)."""
import os

os.environ.setdefault("NUMBA_THREADING_LAYER", "workqueue")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
