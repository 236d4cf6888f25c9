"""The global step of local/global integration (kernels/localglobal.py): the constant matrix
A = M (1 + h alpha) + (h^2 + h beta) L + h^2 K_anchor + h C_anchor over a network's free points
(``system_matrix``), given either as its sparse L D L^T factor (``factor``: SuperLU without
pivoting, solved by ``ldl_solve``) or as a multigrid hierarchy (kernels/multigrid.py), and A^-1
applied with whichever it has (``apply_inverse``). A depends on the step, the masses, the
springs' stiffness and the damping only, so a network factors it once and reuses it."""
from typing import NamedTuple

import numpy as np
from numba import njit
import scipy.sparse as sp
import scipy.sparse.linalg as sla

from .multigrid import Hierarchy, Workspace, vcycle
from .springs import copy_rows


class Direct(NamedTuple):
    """The factor A[perm][:, perm] = L D L^T: the strict lower part of L in CSC (Lp, Li, Lx),
    dinv = 1 / D and perm (the position of each unknown in the permuted system)."""
    Lp: np.ndarray
    Li: np.ndarray
    Lx: np.ndarray
    dinv: np.ndarray
    perm: np.ndarray


class Factors(NamedTuple):
    """What applies A^-1: fid (n,) each point's unknown (-1 for fixed points), and either the
    Direct factor or a multigrid Hierarchy with its Workspace (the unused one empty)."""
    fid: np.ndarray
    direct: Direct
    mg: Hierarchy
    work: Workspace


def system_matrix(net, beta, h):
    """The global matrix for step h (s) over the free points of a springs.Network, and each
    point's index among them. beta (s): the stiffness-proportional damping. Returns (fid (n,),
    -1 for fixed points; A, scipy CSC, kg)."""
    m, fixed = net.pts.m, net.pts.fixed
    si, sj, k = net.springs.i, net.springs.j, net.springs.k
    a_idx, a_k, a_c = net.anchors.idx, net.anchors.k, net.anchors.c
    alpha = net.alpha
    n = len(m)
    free = ~fixed
    fid = np.full(n, -1, dtype=np.int64)
    fid[free] = np.arange(int(free.sum()))
    w = (h * h + h * beta) * k
    Lap = sp.coo_matrix((np.r_[w, w, -w, -w],
                         (np.r_[si, sj, si, sj], np.r_[si, sj, sj, si])), shape=(n, n)).tocsr()
    diag = m * (1.0 + h * alpha)
    np.add.at(diag, a_idx, h * h * a_k + h * a_c)
    return fid, (sp.diags(diag) + Lap).tocsr()[free][:, free].tocsc()


def factor(A):
    """A = P^T L D L^T P for ``ldl_solve``: (Lp, Li, Lx, dinv, perm)."""
    # A is symmetric positive definite: without row pivoting SuperLU's U is D L^T, so only the
    # unit lower factor and the diagonal are kept (half the memory; at 128^2 the factor then
    # fits in cache and a solve takes 2.4 instead of 4.6 ms)
    lu = sla.splu(A, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                  options={"SymmetricMode": True})
    if not np.array_equal(lu.perm_r, lu.perm_c):
        raise RuntimeError("local/global: SuperLU pivoted a symmetric positive definite matrix")
    Lf = lu.L.tocsc()
    Lf.sort_indices()
    strict = np.ones(Lf.nnz, dtype=bool)
    strict[Lf.indptr[:-1]] = False  # each column's first entry is the unit diagonal
    cols = np.repeat(np.arange(Lf.shape[1]), np.diff(Lf.indptr))
    L = sp.csc_matrix((Lf.data[strict], (Lf.indices[strict], cols[strict])), shape=Lf.shape)
    L.sort_indices()
    # position i of the permuted system holds unknown perm[i]
    perm = np.empty_like(lu.perm_c)
    perm[lu.perm_c] = np.arange(len(perm))
    # 32-bit row indices: the triangular solves are memory-bound (12 instead of 16 bytes a nonzero)
    return Direct(L.indptr.astype(np.int64), L.indices.astype(np.int32), L.data,
                  1.0 / lu.U.diagonal(), perm.astype(np.int64))


# what a preconditioner slot holds when the other one is in use (same types: one compilation)
NO_DIRECT = Direct(np.zeros(1, np.int64), np.zeros(0, np.int32), np.zeros(0), np.zeros(0),
                   np.zeros(0, np.int64))
NO_MULTIGRID = Hierarchy(np.zeros(0, np.int64), np.zeros(1, np.int64), np.zeros(1, np.int64),
                         np.zeros(0, np.int32), np.zeros(0), np.zeros(1, np.int64),
                         np.zeros(0, np.int32), np.zeros(0), np.zeros(0), np.zeros((0, 0)))
NO_WORKSPACE = Workspace(np.zeros((0, 3)), np.zeros((0, 3)), np.zeros((0, 3)))


@njit(cache=True)
def apply_inverse(pre, q, z):
    """q <- A^-1 q (approximately) with the Factors ``pre``: one multigrid V-cycle when it has
    levels, else the factored solve; z is scratch."""
    if pre.mg.sizes.shape[0] > 0:
        vcycle(pre.mg, pre.work, q, z)
        copy_rows(z, q)
    else:
        ldl_solve(pre.direct, q, z, q)


@njit(cache=True)
def ldl_solve(direct, b, z, out):
    """Solve A out = b for three right-hand sides (columns) with the Direct factor; z is
    scratch."""
    Lp, Li, Lx, dinv, perm = direct
    n = b.shape[0]
    for i in range(n):
        r = perm[i]
        z[i, 0] = b[r, 0]
        z[i, 1] = b[r, 1]
        z[i, 2] = b[r, 2]
    for j in range(n):  # L y = b, column by column
        z0 = z[j, 0]
        z1 = z[j, 1]
        z2 = z[j, 2]
        for e in range(Lp[j], Lp[j + 1]):
            i = Li[e]
            z[i, 0] -= Lx[e] * z0
            z[i, 1] -= Lx[e] * z1
            z[i, 2] -= Lx[e] * z2
    for j in range(n - 1, -1, -1):  # L^T out = D^-1 y: column j of L is row j of L^T
        s0 = z[j, 0] * dinv[j]
        s1 = z[j, 1] * dinv[j]
        s2 = z[j, 2] * dinv[j]
        for e in range(Lp[j], Lp[j + 1]):
            i = Li[e]
            s0 -= Lx[e] * z[i, 0]
            s1 -= Lx[e] * z[i, 1]
            s2 -= Lx[e] * z[i, 2]
        z[j, 0] = s0
        z[j, 1] = s1
        z[j, 2] = s2
    for i in range(n):
        r = perm[i]
        out[r, 0] = z[i, 0]
        out[r, 1] = z[i, 1]
        out[r, 2] = z[i, 2]
