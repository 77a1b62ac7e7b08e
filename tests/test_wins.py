"""The competition simulator (neurohover.experiments.wins): win odds from stored test runs."""

from __future__ import annotations

import numpy as np
import pytest

from neurohover.errors import NeurohoverError
from neurohover.experiments.wins import win_probabilities


def test_a_dominant_agent_always_wins_and_identical_agents_share() -> None:
    better = {f"m{i}": [-100.0 - i, -120.0] for i in range(5)}
    worse = {f"m{i}": [-200.0 - i] for i in range(5)}
    for n in (1, 7, 20):
        odds = win_probabilities({"a": better, "b": worse}, n, draws=2000)
        assert odds == {"a": 1.0, "b": 0.0} and odds.n_runs == n and odds.mdps == 5
    same = win_probabilities({"a": worse, "b": worse}, 5, draws=500)
    assert same == {"a": 0.5, "b": 0.5}  # every simulated competition a tie: shared


def test_a_risky_agent_wins_short_competitions_and_loses_long_ones() -> None:
    # On each MDP the risky agent's ten runs: nine good, one crash; the careful one is steady but worse.
    risky = {f"m{i}": [-100.0] * 9 + [-1e7] for i in range(20)}
    careful = {f"m{i}": [-1000.0] for i in range(20)}
    for n, p in ((1, 0.9), (5, 0.9**5), (20, 0.9**20)):
        odds = win_probabilities({"risky": risky, "careful": careful}, n, draws=20_000, seed=3)
        assert abs(odds["risky"] - p) < 4 * odds.standard_error("risky") + 1e-12, (n, odds)
        assert odds["risky"] + odds["careful"] == pytest.approx(1.0)


def test_only_the_mdps_every_agent_flew_take_part_and_the_seed_decides() -> None:
    a = {"m0": [-1.0], "m1": [-5.0], "only-a": [-1e9]}
    b = {"m0": [-2.0], "m1": [-4.0]}
    odds = win_probabilities({"a": a, "b": b}, 3, draws=4000, seed=1)
    assert odds.mdps == 2 and 0.0 < odds["a"] < 1.0  # a's disaster on its own MDP never enters
    assert win_probabilities({"a": a, "b": b}, 3, draws=4000, seed=1) == odds
    assert win_probabilities({"a": a, "b": b}, 3, draws=4000, seed=2) != odds


@pytest.mark.parametrize(
    "runs, n, draws, message",
    [
        ({"a": {"m": [1.0]}}, 5, 10, "at least two agents"),
        ({"a": {"m": [1.0]}, "b": {"n": [1.0]}}, 5, 10, "no MDP in common"),
        ({"a": {"m": [1.0]}, "b": {"m": [1.0]}}, 0, 10, "n_runs=0 is out of range"),
        ({"a": {"m": [1.0]}, "b": {"m": [1.0]}}, 5, True, "draws=True is not allowed"),  # a type, not a range (T24-11)
        ({"a": {"m": [np.nan]}, "b": {"m": [1.0]}}, 5, 10, "'a' has a run whose score is not a finite number"),
        ({"a": {"m": [1.0]}, "b": {"m": [1.0]}}, 10_000, 10_000, "too large"),
    ],
)
def test_bad_input_is_refused_with_one_clear_message(runs, n, draws, message) -> None:
    with pytest.raises(NeurohoverError, match=message):
        win_probabilities(runs, n, draws=draws)


@pytest.mark.slow
def test_the_wins_command_gives_each_agents_odds_from_a_stores_test_runs(cli, tmp_path) -> None:
    import json

    store = str(tmp_path / "s.sqlite")
    assert cli("reproduce", "fig11", "--store", store, "--no-progress")[0] == 0
    rc, out, err = cli("wins", "fig11", "--store", store, "--runs", "1,4", "--json")
    assert rc == 0, err
    rows = json.loads(out)["rows"]
    assert sorted(r["agent"] for r in rows) == ["hybrid", "hybrid-baseline", "model-free"]
    assert all(r["mdps"] == 2 for r in rows)  # the quick scale's test MDPs 0-1, flown by every group
    for n in ("1", "4"):
        assert sum(r[n] for r in rows) == pytest.approx(1.0)
    rc, out, _ = cli("wins", "fig11", "--store", store, "--against", "model-free", "--runs", "3", "--json")
    head = json.loads(out)["rows"]
    assert rc == 0 and sorted(r["agent"] for r in head) == ["hybrid", "hybrid-baseline"] and all(0 <= r["3"] <= 1 for r in head)
    rc, out, _ = cli("wins", "fig11", "--store", store)
    assert rc == 0 and "N = 20" in out.splitlines()[1]
    for args, message in (
        (("--runs", "0,5"), "--runs '0,5' is not allowed: give whole numbers >= 1"),
        (("--agents", "hybrid,nobody"), "agent 'nobody' has no test runs in 'fig11' (quick): allowed"),
        (("--against", "nobody"), "agent 'nobody' has no test runs"),
        (("--against", "hybrid", "--agents", "hybrid"), "--against hybrid leaves no other agent to compare with it"),  # was a traceback
        (("--agents", "hybrid,hybrid"), "--agents 'hybrid,hybrid' names an agent twice"),
        (("--runs", "5,5"), "--runs '5,5' names a number twice"),
        (("--agents", ""), "--agents '': an agent's label is empty"),
        (("--against", ""), "--against '': an agent's label is empty"),
    ):
        rc, _, err = cli("wins", "fig11", "--store", store, *args)
        assert rc == 2 and message in err, err
        assert "None" not in err  # the option not given is not named (fifth trial)
    rc, _, err = cli("wins", "fig2", "--store", store)
    assert rc == 2 and "fig2" in err
