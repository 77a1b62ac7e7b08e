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
        ({"a": {"m": [1.0]}, "b": {"m": [1.0]}}, 5, True, "draws=True is out of range"),
        ({"a": {"m": [np.nan]}, "b": {"m": [1.0]}}, 5, 10, "'a' has a run whose score is not a finite number"),
        ({"a": {"m": [1.0]}, "b": {"m": [1.0]}}, 10_000, 10_000, "too large"),
    ],
)
def test_bad_input_is_refused_with_one_clear_message(runs, n, draws, message) -> None:
    with pytest.raises(NeurohoverError, match=message):
        win_probabilities(runs, n, draws=draws)
