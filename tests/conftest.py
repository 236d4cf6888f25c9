"""Test settings: keep Numba and BLAS from fighting over the two cores (DESIGN.md)."""
import os

os.environ.setdefault("NUMBA_THREADING_LAYER", "workqueue")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

# MuJoCo's warnings (an unstable figure in a test) go to stderr, not to MUJOCO_LOG.TXT in the
# working directory, as in the command line
from interplay.cli.command import quiet_mujoco  # noqa: E402

quiet_mujoco()
