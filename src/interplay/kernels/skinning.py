"""Linear blend skinning over sparse weights: the hot loops of geometry/skinning.py.

Each point i is carried by the few segments k with a weight (CSR: its entries
start[i]..start[i+1] of seg and w; a body surface's vertex has 2-5 of 17): x_i = sum_k w_ik
(A_k x0_i + b_k), and its velocity sum_k w_ik (lin_k + ang_k x (A_k x0_i + b_k - c_k)).
A (k,3,3), b (k,3): the segments' transforms from the A-pose (geometry.body_surface
``transforms``); x0 (n,3) m the A-pose points; lin (k,3) m/s at the segments' centres c
(k,3) m, ang (k,3) rad/s.
"""
from numba import njit


@njit(cache=True)
def blend_positions(x0, start, seg, w, A, b, out):
    """out (n,3) m: the points carried by their segments' transforms."""
    for i in range(x0.shape[0]):
        x, y, z = x0[i, 0], x0[i, 1], x0[i, 2]
        px = py = pz = 0.0
        for j in range(start[i], start[i + 1]):
            k, wj = seg[j], w[j]
            px += wj * (A[k, 0, 0] * x + A[k, 0, 1] * y + A[k, 0, 2] * z + b[k, 0])
            py += wj * (A[k, 1, 0] * x + A[k, 1, 1] * y + A[k, 1, 2] * z + b[k, 1])
            pz += wj * (A[k, 2, 0] * x + A[k, 2, 1] * y + A[k, 2, 2] * z + b[k, 2])
        out[i, 0], out[i, 1], out[i, 2] = px, py, pz


@njit(cache=True)
def blend_velocities(x0, start, seg, w, A, b, lin, ang, centres, out):
    """out (n,3) m/s: the points' velocities, each segment's rigid motion blended by the
    weights."""
    for i in range(x0.shape[0]):
        x, y, z = x0[i, 0], x0[i, 1], x0[i, 2]
        vx = vy = vz = 0.0
        for j in range(start[i], start[i + 1]):
            k, wj = seg[j], w[j]
            rx = A[k, 0, 0] * x + A[k, 0, 1] * y + A[k, 0, 2] * z + b[k, 0] - centres[k, 0]
            ry = A[k, 1, 0] * x + A[k, 1, 1] * y + A[k, 1, 2] * z + b[k, 1] - centres[k, 1]
            rz = A[k, 2, 0] * x + A[k, 2, 1] * y + A[k, 2, 2] * z + b[k, 2] - centres[k, 2]
            vx += wj * (lin[k, 0] + ang[k, 1] * rz - ang[k, 2] * ry)
            vy += wj * (lin[k, 1] + ang[k, 2] * rx - ang[k, 0] * rz)
            vz += wj * (lin[k, 2] + ang[k, 0] * ry - ang[k, 1] * rx)
        out[i, 0], out[i, 1], out[i, 2] = vx, vy, vz
