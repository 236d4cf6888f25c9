"""Linear blend skinning over sparse weights (geometry/skinning.py) against the dense sum it
replaces: every segment's transform applied to every point, weighted."""
import numpy as np
from scipy.spatial.transform import Rotation

from interplay.geometry.skinning import Skinning


def _dense(x0, W, A, b):
    return sum(W[:, k, None] * (x0 @ A[k].T + b[k]) for k in range(len(A)))


def test_sparse_blend_equals_the_dense_sum_for_positions_and_velocities():
    rng = np.random.default_rng(3)
    n, k = 500, 17
    x0 = rng.normal(size=(n, 3))
    W = rng.random((n, k)) * (rng.random((n, k)) < 0.2)  # a few segments per point
    W[np.arange(n), rng.integers(0, k, n)] += 0.1  # every point carried by one at least
    W /= W.sum(axis=1, keepdims=True)
    A = Rotation.random(k, random_state=4).as_matrix()
    b = rng.normal(size=(k, 3))
    lin, ang, centres = rng.normal(size=(3, k, 3))
    s = Skinning(x0, W)
    assert len(s.w) == np.count_nonzero(W)
    # the sums differ only in their order: round-off of a few ulps of |x| ~ 3 m
    np.testing.assert_allclose(s.positions(A, b), _dense(x0, W, A, b), rtol=0, atol=1e-13)
    # velocity: d/dt of the blend for segments moving rigidly, by central differences of
    # the dense positions over a step dt (error ~ dt^2 |ang|^2 |r| < 1e-9)
    dt = 1e-6
    rot = Rotation.from_rotvec(ang * dt).as_matrix()
    A1 = np.einsum("kij,kjl->kil", rot, A)
    b1 = np.einsum("kij,kj->ki", rot, b - centres) + centres + lin * dt
    rot0 = Rotation.from_rotvec(-ang * dt).as_matrix()
    A0 = np.einsum("kij,kjl->kil", rot0, A)
    b0 = np.einsum("kij,kj->ki", rot0, b - centres) + centres - lin * dt
    fd = (_dense(x0, W, A1, b1) - _dense(x0, W, A0, b0)) / (2 * dt)
    np.testing.assert_allclose(s.velocities(A, b, lin, ang, centres), fd, rtol=0, atol=1e-7)
