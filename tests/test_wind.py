"""Flow primitives: each matches its closed form, the field is their linear sum, gusts and
paths move them."""
import numpy as np
import pytest

from interplay.errors import ParameterError
from interplay.systems.path import Path, PathFollower, Prop
from interplay.systems.wind import FlowPrimitive, WindField

RNG = np.random.default_rng(4)
PTS = RNG.uniform(-2, 2, size=(50, 3))


def field(*prims):
    return WindField("w", prims)


def g(r, rc):
    return r / (r * r + rc * rc)


def test_uniform():
    v = field(FlowPrimitive("uniform", axis=(3, 4, 0), strength=5.0)).velocity(PTS, 0.0)
    assert np.allclose(v, [3.0, 4.0, 0.0])


@pytest.mark.parametrize("kind,sign", [("source", 1.0), ("sink", -1.0)])
def test_source_and_sink(kind, sign):
    c, q, rc = np.array([0.3, -0.2, 0.5]), 2.0, 0.4
    v = field(FlowPrimitive(kind, position=tuple(c), strength=q, core=rc)).velocity(PTS, 0.0)
    d = PTS - c
    r = np.linalg.norm(d, axis=1, keepdims=True)
    expect = sign * q / (4 * np.pi) * d / r * g(r, rc) ** 2
    assert np.allclose(v, expect, rtol=1e-12, atol=1e-15)
    # far from the core the regularized field is the point source's q / (4 pi r^2)
    far = field(FlowPrimitive(kind, strength=q, core=1e-3)).velocity([[10.0, 0, 0]], 0.0)
    assert far[0, 0] == pytest.approx(sign * q / (4 * np.pi * 100.0), rel=1e-6)


def test_vortex():
    c, a, gam, rc = np.array([0.1, 0.2, 0.0]), np.array([0.0, 0.6, 0.8]), 1.5, 0.3
    v = field(FlowPrimitive("vortex", position=tuple(c), axis=tuple(a), strength=gam,
                            core=rc)).velocity(PTS, 0.0)
    d = PTS - c
    dp = d - (d @ a)[:, None] * a
    r = np.linalg.norm(dp, axis=1, keepdims=True)
    theta = np.cross(a, dp) / r
    assert np.allclose(v, gam / (2 * np.pi) * g(r, rc) * theta, rtol=1e-12, atol=1e-15)
    assert np.allclose(v @ a, 0.0, atol=1e-14)  # no flow along the axis
    # the speed peaks at r = r_c with Gamma / (4 pi r_c), and the centre is still
    w = field(FlowPrimitive("vortex", axis=(0, 0, 1), strength=gam, core=rc))
    assert np.linalg.norm(w.velocity([[rc, 0, 0]], 0.0)) == pytest.approx(gam / (4 * np.pi * rc))
    assert np.allclose(w.velocity([[0, 0, 0.7]], 0.0), 0.0)


def test_sum_is_linear():
    prims = [FlowPrimitive("uniform", axis=(1, 0, 0), strength=2.0),
             FlowPrimitive("source", position=(1, 1, 0), strength=0.7, core=0.2),
             FlowPrimitive("sink", position=(-1, 0, 1), strength=0.3, core=0.1),
             FlowPrimitive("vortex", position=(0, 0, 0), axis=(0, 0, 1), strength=2.0, core=0.5)]
    total = field(*prims).velocity(PTS, 0.0)
    parts = sum(field(p).velocity(PTS, 0.0) for p in prims)
    assert np.allclose(total, parts, rtol=1e-13, atol=1e-15)
    doubled = [FlowPrimitive(p.kind, p.position, p.axis, 2 * p.strength, p.core) for p in prims]
    assert np.allclose(field(*doubled).velocity(PTS, 0.0), 2 * total)


def test_drift_gust_and_path():
    src = FlowPrimitive("source", position=(0, 0, 0), strength=1.0, core=0.1, velocity=(1, 0, 0))
    w = field(src)
    # drifting 1 m/s: at t = 2 s the source sits at x = 2 m
    assert np.allclose(w.velocity([[2.5, 0, 0]], 2.0), field(
        FlowPrimitive("source", (2, 0, 0), strength=1.0, core=0.1)).velocity([[2.5, 0, 0]], 0))
    gusty = FlowPrimitive("uniform", strength=10.0, gust=0.3, gust_period=2.0)
    speeds = [field(gusty).velocity([[0, 0, 0]], t)[0, 0] for t in np.linspace(0, 20, 400)]
    assert 7.0 <= min(speeds) < 9.0 and 11.0 < max(speeds) <= 13.0
    # a vortex riding a path heading +y: its axis (x forward in the path frame) turns to +y
    path = Path([0.0, 2.0], [[0, 0, 0], [0, 4, 0]])
    ride = FlowPrimitive("vortex", position=(-0.5, 0, 0.3), axis=(1, 0, 0), strength=1.0,
                         path=path)
    kind, centre, axis, strength, core = field(ride).arrays(1.0)
    assert np.allclose(centre[0], path.position(1.0) + [0, -0.5, 0.3])
    assert np.allclose(axis[0], [0, 1, 0])
    bike = PathFollower("bike", path, Prop([[1.0, 0, 0], [0, 0, 0], [0, 0, 1]], [[0, 1, 2]]))
    bike.advance(1.0)
    pos, rot = bike.world_parts()
    assert np.allclose(rot[0] @ [1.0, 0, 0] + pos[0], path.position(1.0) + [0, 1, 0])
    assert np.allclose(bike.generalized_state()[1][:3], path.velocity(1.0))


@pytest.mark.parametrize("prim,message", [
    (FlowPrimitive("jet"), r"unknown flow primitive 'jet'"),
    (FlowPrimitive("vortex", axis=(0, 0, 0)), r"vortex axis must be a non-zero 3-vector"),
    (FlowPrimitive("source", core=-1.0), r"source core must be zero or positive"),
    (FlowPrimitive("uniform", gust=0.5, gust_period=0.0), r"gusting uniform needs gust_period"),
])
def test_bad_primitives(prim, message):
    with pytest.raises(ParameterError, match=message):
        field(prim)


def test_bad_path():
    with pytest.raises(ParameterError, match="strictly increasing"):
        Path([0.0, 0.0], [[0, 0, 0], [1, 0, 0]])
    with pytest.raises(ParameterError, match="points must hold x, y, z for each of the 2"):
        Path([0.0, 1.0], [[0, 0, 0]])
