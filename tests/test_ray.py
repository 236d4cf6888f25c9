"""The Ray executor: a local Ray cluster started here (`ray start --head`) runs the same wedge as
the local pool and gives the same table, its outputs gathered into the sweep's folder bit for
bit. Slow (the cluster takes 10-30 s to start on two busy cores); `make test-all` installs
Ray (the `cluster` extra)."""
import importlib.util
import json
import os

import pytest

from test_sweep import QUICK, SRC, WEDGE, cli, same_run

pytestmark = [pytest.mark.slow,
              # not imported here: the executor sets Ray's authentication mode before it is
              pytest.mark.skipif(importlib.util.find_spec("ray") is None,
                                 reason="Ray is not installed (make test-all installs it)")]


@pytest.fixture(scope="module")
def ray_head():
    from interplay.batch.executor import local_ray_head
    paths = SRC + os.pathsep + os.environ.get("PYTHONPATH", "")
    with local_ray_head(2, {"PYTHONPATH": paths}) as address:
        yield address


FIGURES = ("id", "values", "status", "exit", "coupling", "table", "interactions", "figures",
           "advice", "diagnostics", "warnings")


def test_ray_wedge_gives_the_local_pools_table(ray_head, tmp_path):
    argv = ["sweep", "basketball", *WEDGE, *QUICK, "--no-stills", "--quiet"]
    assert cli(*argv, "--workers", "2", "--out", str(tmp_path / "local")) == 0
    assert cli(*argv, "--ray", ray_head, "--out", str(tmp_path / "ray")) == 0
    local, on_ray = (json.loads((tmp_path / d / "sweep.json").read_text())
                     for d in ("local", "ray"))
    assert on_ray["executor"] == {"kind": "ray", "address": ray_head, "workers": 2}
    assert on_ray["counts"] == {"ok": 4, "error": 0, "pending": 0}
    for a, b in zip(local["variants"], on_ray["variants"]):
        assert {k: a[k] for k in FIGURES} == {k: b[k] for k in FIGURES}
        assert b["worker"]["numba_threads"] == 1 and b["worker"]["pid"] != os.getpid()
        # the outputs came back from the Ray workers into the sweep's folder
        same_run(tmp_path / "local" / a["id"], tmp_path / "ray" / b["id"])
    assert not list((tmp_path / "ray").glob(".*part*"))
