"""The basketball's ball-net contact through the general MeshContact path ("mesh") against the
specialised sphere-cord contact ("cords")."""
from dataclasses import replace

import numpy as np
import pytest

from interplay.errors import ParameterError
from interplay.interactions.contact import SphereCordContact
from interplay.interactions.mesh_contact import MeshContact
from interplay.scenes import basketball as B


def build(model, duration=0.02):
    p = replace(B.BasketballParams(), contact_model=model, coupling_dt=1e-5, settle=False)
    return B.build(duration=duration, params=p)


def test_contact_model_swaps_the_ball_net_interaction():
    assert isinstance(build("cords").interactions[0], SphereCordContact)
    scene = build("mesh")
    assert isinstance(scene.interactions[0], MeshContact)
    assert scene.coupling_dt == pytest.approx(1e-5)  # lock step: the mesh path does not sub-cycle
    with pytest.raises(ParameterError, match=r"basketball: contact_model must be 'cords' or "
                                             r"'mesh', got 'nets'"):
        build("nets")


@pytest.mark.slow
def test_mesh_path_agrees_with_the_sphere_cord_contact():
    # 0.45 s: the ball enters the net at 0.25 s and leaves it by 0.41 s
    runs = {}
    for model in ("cords", "mesh"):
        p = replace(B.BasketballParams(), contact_model=model, coupling_dt=1e-5)
        res = B.build(duration=0.45, params=p).simulate()
        st = [s for s in res.interaction_stats() if s["name"] == "ball-net"][0]
        runs[model] = (st, res.state_at("ball", 0.45)[0][:3])
    (sc, xc), (sm, xm) = runs["cords"], runs["mesh"]
    # measured (docs/collision.md): mean force within 5%, contact period within 5 ms, the
    # ball within 2 cm at 0.45 s; the icosphere's facets and the stick friction differ
    assert sm["force_N"]["mean"] == pytest.approx(sc["force_N"]["mean"], rel=0.05)
    assert abs(sm["contact_s"][0] - sc["contact_s"][0]) < 5e-3
    assert abs(sm["contact_s"][1] - sc["contact_s"][1]) < 5e-3
    assert np.linalg.norm(xm - xc) < 0.02
