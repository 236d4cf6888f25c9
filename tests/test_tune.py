"""`interplay tune`: a scene's search on the executor gives the same result from the same seed
on one worker or two, resumes from its log, and with one chain is the serial annealing."""
import json

import numpy as np
import pytest

from interplay.cli.command import main
from interplay.control.search import anneal, anneal_batched
from interplay.scenes import bungee as B

TUNE = ["tune", "bungee", "--budget", "9", "--chains", "4", "--seed", "5", "--quiet"]


def tune(out, *extra):
    try:
        code = main([*TUNE, *extra, "--out", str(out)])
    except SystemExit as e:
        code = e.code
    assert code == 0
    return json.loads((out / "tune.json").read_text())


@pytest.fixture(scope="module")
def on_two(tmp_path_factory):
    """The search on two workers: (its folder, its tune.json)."""
    out = tmp_path_factory.mktemp("two")
    return out, tune(out, "--workers", "2")


def test_same_seed_same_search_on_one_and_two_workers(tmp_path, on_two):
    """The bungee leap's search (the figure alone, 5 leaps per evaluation): 4 chains, 2
    generations, the same candidates and losses in the same order whatever the workers."""
    one = tune(tmp_path / "one", "--workers", "1")
    two = on_two[1]
    assert one["best"] == two["best"] and one["loss"] == two["loss"]
    assert one["history"] == two["history"] and len(one["history"]) == 9
    assert one["ran"] == two["ran"] == 9 and one["from_log"] == 0
    assert one["executor"]["workers"] == 1 and two["executor"]["workers"] == 2
    assert one["loss"] <= one["start_loss"]
    # the start is the scene's own parameters, as `interplay run` would use them
    assert one["start"] == {k: getattr(B.JumperParams(), k.split(".")[1])
                            for k in B.LEAP_SEARCH.bounds}
    assert one["start_loss"] == B.leap_loss(B.JumperParams())


def test_interrupted_search_resumes_from_its_log(tmp_path, on_two):
    """A search killed after 5 of its 9 evaluations (the log cut there, its last line half
    written) reruns only the 4 missing ones and ends where the uninterrupted search does."""
    folder, full = on_two
    cut = tmp_path / "cut"
    cut.mkdir()
    lines = (folder / "evaluations.jsonl").read_text().splitlines()
    (cut / "evaluations.jsonl").write_text("\n".join(lines[:5]) + "\n" + lines[5][:40])
    again = tune(cut, "--workers", "2")
    assert again["from_log"] == 5 and again["ran"] == 4
    assert again["best"] == full["best"] and again["history"] == full["history"]


def test_one_chain_is_the_serial_annealing(tmp_path):
    """`interplay tune bungee --chains 1` is bungee.tune_leap, value for value."""
    doc = tune(tmp_path, "--workers", "2", "--chains", "1", "--budget", "4")
    best, res = B.tune_leap(4, seed=5)
    assert doc["best"] == {f"jumper.{k}": v for k, v in res.best.items()}
    assert [h[1] for h in doc["history"]] == [h[1] for h in res.history]


def test_population_annealing_finds_a_bowls_minimum():
    """Four chains with resampling on a 2-D bowl with a ripple (minimum 0 at (0.3, -0.2)):
    within 0.05 of it in 201 evaluations; the batch's evaluation order does not matter."""
    def f(d):
        a, b = d["a"] - 0.3, d["b"] + 0.2
        return a * a + b * b + 0.02 * (1 - np.cos(20 * a))
    bounds, start = {"a": (-1, 1), "b": (-1, 1)}, {"a": 0.9, "b": 0.9}
    res = anneal_batched(lambda batch: [f(c) for c in batch], start, bounds, 201, 7, chains=4)
    backwards = anneal_batched(lambda batch: [f(c) for c in batch[::-1]][::-1], start, bounds,
                               201, 7, chains=4)
    assert res.best == backwards.best
    assert abs(res.best["a"] - 0.3) < 0.05 and abs(res.best["b"] + 0.2) < 0.05
    assert len(res.history) == 201
    assert anneal(f, start, bounds, 50, 7).history == anneal_batched(
        lambda batch: [f(c) for c in batch], start, bounds, 50, 7, chains=1).history


BAD = [
    (["tune", "basketball"], "basketball offers no search to tune; scenes with one: bungee"),
    (["tune", "bungee", "--search", "dive"], "--search dive: bungee has no such search"),
    (["tune", "bungee", "--budget", "0"], "evaluations (--budget) must be >= 1"),
    (["tune", "bungee", "--budget", "9", "--chains", "12"], "chains (--chains) must be from 1"),
    (["tune", "bungee", "--set", "jumper.tuck=soon"], "'soon' is not a number; jumper.tuck must be"),
]


@pytest.mark.parametrize("argv,message", BAD, ids=[" ".join(a[1:]) for a, _ in BAD])
def test_bad_search_request_is_one_line(argv, message, tmp_path, capsys):
    assert main([*argv, "--out", str(tmp_path), "--quiet"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and message in err[0], err
    assert not (tmp_path / "evaluations.jsonl").exists()
