"""Smoothed-aggregation algebraic multigrid: a linear-cost approximate inverse of the constant
local/global matrix A = M (1 + h alpha) + (h^2 + h beta) L (see ``localglobal``), for three
right-hand sides at once.

``hierarchy`` builds the levels with pyamg (setup only) and flattens them into Numba-ready
arrays; ``vcycle`` applies one V-cycle from a zero guess. That operator is linear, symmetric and
positive definite (usable as a CG preconditioner or an L-BFGS initial inverse Hessian) because
the coarse operators are Galerkin (A_{l+1} = P^T A_l P), restriction is P^T, the coarsest level
is solved exactly (dense Cholesky), and the smoother is one damped-Jacobi sweep before and one
after, with damping omega_l / diag(A_l) where omega_l rho(D^-1 A_l) = OMEGA < 2 keeps the sweep
convergent in the A-norm.

Measured on the benchmark cloth (1 m, 0.15 kg, k l0 = 200 N, h = 1/60 s, 32^2-256^2 points):
the A-norm error falls by ~0.38 a cycle at every size, PCG reaches 1e-8 in 9-10 cycles, and a
cycle costs about two sweeps of A_0 (0.7 ms at 128^2, where the sparse L D L^T solve takes
2.4 ms). Two sweeps, or Gauss-Seidel (forward before, backward after), reduce the error more per
cycle but no more per millisecond (128^2: ln(rate) / ms = -1.34 here, -1.34 two Jacobi sweeps,
-1.08 one and -1.40 two Gauss-Seidel), and one Jacobi sweep is the cheapest single application.
"""
from typing import NamedTuple

import numpy as np
import pyamg
from numba import njit
import scipy.sparse as sp

# Strength threshold |a_ij| >= THETA sqrt(a_ii a_jj): on the cloth, theta = 0 keeps the
# ~1e-3-relative couplings in the aggregates and the cycle's rate degrades with size (0.54 at
# 32^2, 0.78 at 64^2); anything in 0.03-0.1 gives the same aggregates and 0.38 at every size.
THETA = 0.05
# Jacobi damping times rho(D^-1 A_l): measured rate 0.44 at 1.4, 0.38 at 1.6, 0.48 at 1.7 (128^2);
# must stay below 2 for the smoother, hence the V-cycle, to be positive definite.
OMEGA = 1.6


class Hierarchy(NamedTuple):
    """Levels 0 (finest, A's own unknowns) to L - 1 (coarsest) stacked into flat arrays.

    sizes (L,) unknowns per level; roff (L + 1,) the first row of each level in stacked level
    vectors (workspace rows). Ap, Ai, Ax: A_0 .. A_{L-2} as one CSR, row r of level l at
    Ap[roff[l] + r] : Ap[roff[l] + r + 1], level-local column indices. Pp, Pi, Px: the
    prolongations P_l (level l rows to level l + 1 columns) stacked the same way. wdinv
    (roff[L - 1],) omega_l / diag(A_l). Lc (sizes[L - 1], sizes[L - 1]) the lower Cholesky factor
    of the coarsest matrix. Units are A's (and 1/A's for wdinv); P is dimensionless."""
    sizes: np.ndarray
    roff: np.ndarray
    Ap: np.ndarray
    Ai: np.ndarray
    Ax: np.ndarray
    Pp: np.ndarray
    Pi: np.ndarray
    Px: np.ndarray
    wdinv: np.ndarray
    Lc: np.ndarray


def _stack(mats):
    """One CSR of the given level matrices' rows, row pointers made global."""
    ptr, ind, val, nnz = [np.zeros(1, np.int64)], [np.zeros(0, np.int32)], [np.zeros(0)], 0
    for M in mats:
        M = sp.csr_matrix(M)
        M.sort_indices()
        ptr.append(M.indptr[1:].astype(np.int64) + nnz)
        ind.append(M.indices.astype(np.int32))  # the sweeps are memory-bound: 12 bytes a nonzero
        val.append(M.data.astype(np.float64))
        nnz += M.nnz
    return np.concatenate(ptr), np.concatenate(ind), np.concatenate(val)


def hierarchy(A, max_coarse=300):
    """Smoothed-aggregation hierarchy of the symmetric positive definite scipy matrix A (n, n),
    near-null space the constant (rigid translation), coarsened until at most max_coarse
    unknowns remain. Deterministic: pyamg's random spectral-radius start vectors are drawn from
    a fixed seed, and NumPy's global random state is restored afterwards."""
    A = sp.csr_matrix(A)
    state = np.random.get_state()
    np.random.seed(0)
    try:
        ml = pyamg.smoothed_aggregation_solver(
            A, B=np.ones((A.shape[0], 1)), symmetry="symmetric",
            strength=("symmetric", {"theta": THETA}), max_coarse=max_coarse,
            coarse_solver="cholesky", keep=False)
        levels = ml.levels
        sizes = np.array([lv.A.shape[0] for lv in levels], dtype=np.int64)
        roff = np.r_[0, np.cumsum(sizes)].astype(np.int64)
        wdinv = [np.zeros(0)]
        for lv in levels[:-1]:
            d = lv.A.diagonal()
            s = sp.diags(1.0 / np.sqrt(d))
            # rho(D^-1 A) from the symmetric D^-1/2 A D^-1/2 (Lanczos, within 1 %)
            rho = pyamg.util.linalg.approximate_spectral_radius(s @ lv.A @ s, symmetric=True)
            wdinv.append(OMEGA / rho / d)
    finally:
        np.random.set_state(state)
    Ap, Ai, Ax = _stack([lv.A for lv in levels[:-1]])
    Pp, Pi, Px = _stack([lv.P for lv in levels[:-1]])
    Lc = np.linalg.cholesky(levels[-1].A.toarray())
    return Hierarchy(sizes, roff, Ap, Ai, Ax, Pp, Pi, Px,
                     np.concatenate(wdinv), np.ascontiguousarray(Lc))


class Workspace(NamedTuple):
    """Scratch for ``vcycle``: three (roff[L], 3) stacked level vectors, the guesses X, the
    corrected guesses Y and the right-hand sides B."""
    X: np.ndarray
    Y: np.ndarray
    B: np.ndarray


def workspace(hier) -> Workspace:
    """``vcycle``'s scratch for a hierarchy, allocated once."""
    rows = int(hier.roff[-1])
    return Workspace(np.zeros((rows, 3)), np.zeros((rows, 3)), np.zeros((rows, 3)))


@njit(cache=True)
def _scale(wdinv, o, b, x):
    """x = W b: the first sweep from a zero guess needs no product with A."""
    for i in range(x.shape[0]):
        w = wdinv[o + i]
        x[i, 0] = w * b[i, 0]
        x[i, 1] = w * b[i, 1]
        x[i, 2] = w * b[i, 2]


@njit(cache=True)
def _restrict_residual(hier, o, b, x, bc):
    """bc = P^T (b - A x), P^T applied by scattering each fine row's residual: fused, so A and P
    are each streamed once and the residual is never stored."""
    Ap, Ai, Ax, Pp, Pi, Px = hier.Ap, hier.Ai, hier.Ax, hier.Pp, hier.Pi, hier.Px
    bc[:] = 0.0
    for i in range(x.shape[0]):
        s0 = b[i, 0]
        s1 = b[i, 1]
        s2 = b[i, 2]
        for e in range(Ap[o + i], Ap[o + i + 1]):
            j = Ai[e]
            a = Ax[e]
            s0 -= a * x[j, 0]
            s1 -= a * x[j, 1]
            s2 -= a * x[j, 2]
        for e in range(Pp[o + i], Pp[o + i + 1]):
            c = Pi[e]
            p = Px[e]
            bc[c, 0] += p * s0
            bc[c, 1] += p * s1
            bc[c, 2] += p * s2


@njit(cache=True)
def _prolong(Pp, Pi, Px, o, xc, x):
    """x += P xc (in place: row i reads only its own x)."""
    for i in range(x.shape[0]):
        s0 = x[i, 0]
        s1 = x[i, 1]
        s2 = x[i, 2]
        for e in range(Pp[o + i], Pp[o + i + 1]):
            c = Pi[e]
            p = Px[e]
            s0 += p * xc[c, 0]
            s1 += p * xc[c, 1]
            s2 += p * xc[c, 2]
        x[i, 0] = s0
        x[i, 1] = s1
        x[i, 2] = s2


@njit(cache=True)
def _jacobi(Ap, Ai, Ax, wdinv, o, b, x, y):
    """y = x + W (b - A x): out of place, Jacobi needs every neighbour's old value."""
    for i in range(x.shape[0]):
        s0 = b[i, 0]
        s1 = b[i, 1]
        s2 = b[i, 2]
        for e in range(Ap[o + i], Ap[o + i + 1]):
            j = Ai[e]
            a = Ax[e]
            s0 -= a * x[j, 0]
            s1 -= a * x[j, 1]
            s2 -= a * x[j, 2]
        w = wdinv[o + i]
        y[i, 0] = x[i, 0] + w * s0
        y[i, 1] = x[i, 1] + w * s1
        y[i, 2] = x[i, 2] + w * s2


@njit(cache=True)
def _cholesky_solve(Lc, b, x):
    """x = (Lc Lc^T)^-1 b, Lc dense lower triangular; both passes read Lc by rows."""
    n = b.shape[0]
    for i in range(n):
        s0 = b[i, 0]
        s1 = b[i, 1]
        s2 = b[i, 2]
        for j in range(i):
            c = Lc[i, j]
            s0 -= c * x[j, 0]
            s1 -= c * x[j, 1]
            s2 -= c * x[j, 2]
        d = 1.0 / Lc[i, i]
        x[i, 0] = s0 * d
        x[i, 1] = s1 * d
        x[i, 2] = s2 * d
    for i in range(n - 1, -1, -1):
        d = 1.0 / Lc[i, i]
        x[i, 0] *= d
        x[i, 1] *= d
        x[i, 2] *= d
        for j in range(i):
            c = Lc[i, j]
            x[j, 0] -= c * x[i, 0]
            x[j, 1] -= c * x[i, 1]
            x[j, 2] -= c * x[i, 2]


@njit(cache=True)
def vcycle(hier, work, b, out):
    """out (n, 3) = one V-cycle on A out = b (n, 3) from a zero guess: a symmetric positive
    definite approximation of A^-1 b (units of b over A's). hier: a Hierarchy, work: its
    Workspace; out must not alias b. Allocates nothing."""
    sizes, roff, Ap, Ai, Ax, Pp, Pi, Px, wdinv, Lc = hier
    X, Y, B = work
    L = sizes.shape[0]
    for l in range(L - 1):
        o = roff[l]
        bl = b if l == 0 else B[o:o + sizes[l]]
        x = X[o:o + sizes[l]]
        _scale(wdinv, o, bl, x)
        _restrict_residual(hier, o, bl, x, B[roff[l + 1]:roff[l + 2]])
    oc = roff[L - 1]
    if L == 1:
        _cholesky_solve(Lc, b, out)
        return
    _cholesky_solve(Lc, B[oc:oc + sizes[L - 1]], Y[oc:oc + sizes[L - 1]])
    for l in range(L - 2, -1, -1):
        o = roff[l]
        bl = b if l == 0 else B[o:o + sizes[l]]
        x = X[o:o + sizes[l]]
        _prolong(Pp, Pi, Px, o, Y[roff[l + 1]:roff[l + 2]], x)
        _jacobi(Ap, Ai, Ax, wdinv, o, bl, x, out if l == 0 else Y[o:o + sizes[l]])
