"""MeshContact with an articulated figure's segments: a ball dropped on the head."""
import numpy as np
import pytest

pytest.importorskip("mujoco")

from interplay.interactions.mesh_contact import MeshContact, MeshContactParams  # noqa: E402
from interplay.systems.figure import Figure, FigureParams  # noqa: E402
from interplay.systems.rigid import Sphere, SphereParams  # noqa: E402

H = 1e-3  # s


def test_ball_lands_on_the_figure_and_the_head_takes_the_reaction():
    fig = Figure("gymnast", FigureParams(), fixed_base=True, gravity=False)
    verts, _ = fig.surface()
    crown = verts[np.argmax(verts[:, 2])]  # the top of the head (m)
    ball = Sphere("ball", SphereParams(radius=0.1, mass=0.6, dt=H),
                  position=crown + [0.0, 0.0, 0.15])
    contact = MeshContact("ball-figure", ball, fig, MeshContactParams())
    contact.prepare(H)
    seen = 0
    for _ in range(600):
        ball.clear_forces()
        fig.clear_forces()
        f, _, on = contact.exchange(True, True)
        if on:
            seen += 1
            # what the ball gets, the figure's segments lose (MuJoCo's applied wrenches)
            assert np.allclose(fig.segment_wrenches()[:, :3].sum(axis=0) + ball.force, 0.0,
                               atol=1e-9)
        ball.advance(H)
        fig.advance(H)
    assert seen > 100
    verts, _ = fig.surface()
    # the ball rests on the head, which the servos hold: its lowest point at the contact
    # thickness above the crown, within the skin (and the icosphere's 0.1% facet depth)
    p = contact.p
    gap = ball.lowest_z() - verts[:, 2].max()
    assert p.thickness - p.skin < gap < p.thickness + p.skin
    assert np.linalg.norm(ball.v) < 1e-3
