"""The thirteenth trial's findings on selection and report helpers (F14, F15, F20, F21): each bad input gives one clear
NeurohoverError naming the value and what is allowed, instead of a traceback or a silent wrong answer."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from neurohover.errors import NeurohoverError


@pytest.mark.parametrize("names", [[], ()])
def test_write_report_refuses_an_empty_list_of_names(names, tmp_path: Path) -> None:
    """F21: names=[] was read as None and wrote a report of every experiment in the store; None still means all."""
    from neurohover.experiments.report import write_report
    from neurohover.experiments.store import Store

    store = Store(tmp_path / "r.sqlite")
    with pytest.raises(NeurohoverError, match=r"names=(\[\]|\(\)) is not allowed: give one or more experiment names, or None for all"):
        write_report(store, tmp_path / "out", names=names)
    assert not (tmp_path / "out").exists()
    with pytest.raises(NeurohoverError, match="holds no experiment"):  # None: all of them (here none), not refused
        write_report(store, tmp_path / "out", names=None)


@pytest.mark.parametrize(
    ("sample_fn", "fragment"),
    [
        (lambda idx: np.zeros(1), r"sample_fn returned shape \(1,\) for 4 candidates; expected \(4,\)"),
        (lambda idx: np.zeros(len(idx) + 2), r"sample_fn returned shape \(6,\) for 4 candidates; expected \(4,\)"),
        (lambda idx: np.zeros((len(idx), 2)), r"sample_fn returned shape \(4, 2\) for 4 candidates; expected \(4,\)"),
        (lambda idx: ["a"] * len(idx), r"sample_fn's returns=\['a', 'a', 'a', 'a'\] is not allowed: give 4 numbers, one per candidate"),
        (lambda idx: np.full(len(idx), np.inf), r"sample_fn returned \+inf; returns must be finite, NaN or -inf"),
    ],
)
def test_top_mu_bandit_checks_sample_fns_answer_as_a_race_does(sample_fn, fragment: str) -> None:
    """F14: a wrong length or a 2-D answer was NumPy's IndexError / broadcast error, text its ValueError, and +inf was
    scored as 0 (selection_race refuses it); the bandit now shares the race's check of the answer."""
    from neurohover.evolution.bandits import top_mu_bandit
    from neurohover.evolution.races import selection_race

    with pytest.raises(NeurohoverError, match=fragment):
        top_mu_bandit(sample_fn, 4, 1, 0.1)
    with pytest.raises(NeurohoverError, match=fragment):
        selection_race(sample_fn, 4, 1, 0.9, t_limit=1)  # one round: 4 indices in its one call


def test_top_mu_bandit_still_scores_nan_and_minus_inf_as_zero() -> None:
    """F14: the shared check keeps the bandit's documented rewards (NaN and -inf count as 0; NumPy scalars taken)."""
    from neurohover.evolution.bandits import top_mu_bandit

    result = top_mu_bandit(lambda idx: np.where(idx == 2, 0.5, np.where(idx == 0, np.nan, -np.inf)), 4, np.int64(1), np.float32(0.1))
    assert result.selected.tolist() == [2]


@pytest.mark.parametrize("which", ["top_mu_bandit", "selection_race", "fixed_resampling"])
def test_a_sample_fn_that_cannot_be_called_is_refused_up_front(which: str) -> None:
    """F14: sample_fn=None was a TypeError from the first call in top_mu_bandit, selection_race and fixed_resampling."""
    from neurohover.evolution import bandits, races

    call = {
        "top_mu_bandit": lambda: bandits.top_mu_bandit(None, 4, 1, 0.1),
        "selection_race": lambda: races.selection_race(None, 4, 1, 0.9),
        "fixed_resampling": lambda: races.fixed_resampling(None, 4, 1),
    }[which]
    with pytest.raises(NeurohoverError, match="sample_fn=None is not allowed: give a function of an array of candidate indices"):
        call()


@pytest.mark.parametrize(
    ("samples", "delta", "fragment"),
    [
        ([1.0, 2.0], 1.5, r"delta=1\.5 must be a confidence level strictly between 0 and 1"),
        ([1.0, 2.0], -0.5, r"delta=-0\.5 must be a confidence level strictly between 0 and 1"),
        ([1.0, 2.0], "x", r"delta='x' is not a number: allowed a confidence level strictly between 0 and 1"),
        ([1.0, np.nan], 0.9, r"samples=\[1\.0, nan\] is not allowed: give finite returns or -inf, no NaN and no \+inf"),
        ([1.0, np.inf], 0.9, r"samples=\[1\.0, inf\] is not allowed: give finite returns or -inf"),
        (["a", "b"], 0.9, r"samples=\['a', 'b'\] is not allowed: give an array of returns"),
    ],
)
def test_bayes_mean_bounds_refuses_a_level_outside_0_1_and_nan_samples(samples, delta, fragment: str) -> None:
    """F15: delta=1.5 and a NaN sample gave (nan, nan) silently; 'x' and text samples were NumPy's ValueError."""
    from neurohover.evolution.races import bayes_mean_bounds

    with pytest.raises(NeurohoverError, match=fragment):
        bayes_mean_bounds(samples, delta)


def test_bayes_mean_bounds_still_takes_crashes_and_numpy_levels() -> None:
    """F15: -inf (a crash) keeps giving (-inf, -inf); a float32 level is taken as a float."""
    from neurohover.evolution.races import bayes_mean_bounds

    assert bayes_mean_bounds([1.0, -np.inf], 0.9) == (-np.inf, -np.inf)
    assert bayes_mean_bounds([1.0, 2.0], np.float32(0.9)) == pytest.approx(bayes_mean_bounds([1.0, 2.0], float(np.float32(0.9))))


@pytest.mark.parametrize(
    ("args", "fragment"),
    [
        (([1], 1, 2, 0), r"delta=0 must be an error probability strictly between 0 and 1"),
        (([1], 1, 2, 2.0), r"delta=2\.0 must be an error probability strictly between 0 and 1"),
        (([1], 0, 2, 0.1), r"t=0 must be an integer >= 1"),
        (([1], 1, 0, 0.1), r"n=0 must be an integer >= 1"),
        (([0], 1, 2, 0.1), r"samples=\[0\.0\] is not allowed: give a 1-D array of sample counts >= 1"),
    ],
)
def test_lucb_radius_refuses_what_its_formula_cannot_take(args, fragment: str) -> None:
    """F15: delta=0 was a ZeroDivisionError, t=0 a math domain error, and delta=2.0 was taken silently."""
    from neurohover.evolution.bandits import lucb_radius

    samples, t, n, delta = args
    with pytest.raises(NeurohoverError, match=fragment):
        lucb_radius(np.array(samples), t, n, delta)
    assert lucb_radius(np.array([1, 3]), np.int64(4), np.int64(2), np.float32(0.5)).shape == (2,)  # NumPy scalars taken


@pytest.mark.parametrize(
    ("means", "samples", "kwargs", "fragment"),
    [
        ([0.5, 0.2], [1, 2, 3], {"level": 1.0}, r"means=\[0\.5, 0\.2\] is not allowed: give 3 finite mean\(s\), one per entry of samples"),
        ([0.5], [1], {"level": -1.0}, r"level=-1\.0 is not allowed: give a finite number >= 0"),
        ([0.5], [1], {"level": 1.0, "iterations": -1}, r"iterations=-1 must be an integer >= 1"),
        ([np.nan], [1], {"level": 1.0}, r"means=\[nan\] is not allowed: give 1 finite mean"),
    ],
)
def test_kl_bounds_refuses_mismatched_arrays_a_negative_level_and_no_halving(means, samples, kwargs, fragment: str) -> None:
    """F15: arrays of different lengths were NumPy's broadcast error; a negative level and iterations=-1 were taken."""
    from neurohover.evolution.bandits import kl_bounds

    with pytest.raises(NeurohoverError, match=fragment):
        kl_bounds(np.array(means), np.array(samples), **kwargs)


@pytest.mark.parametrize(
    ("crashes", "episodes", "fragment"),
    [
        (1, 0, r"episodes=0 is not allowed: give a whole number of episodes >= 1"),
        (5, 2, r"crashes=5 is not allowed: give a whole number of crashed episodes from 0 to episodes=2"),
        (-1, 2, r"crashes=-1 is not allowed: give a whole number of crashed episodes from 0 to episodes=2"),
        (1.5, 2, r"crashes=1\.5 is not allowed"),
    ],
)
def test_crash_rate_refuses_counts_that_are_no_fraction(crashes, episodes, fragment: str) -> None:
    """F20: crash_rate(1, 0) was a ZeroDivisionError, (5, 2) gave '250%' and (-1, 2) '-50%' silently."""
    from neurohover.experiments.report_testruns import crash_rate

    with pytest.raises(NeurohoverError, match=fragment):
        crash_rate(crashes, episodes)
    assert crash_rate(np.int64(1), np.int64(20_000)) == "0.005%"  # NumPy counts taken


@pytest.mark.parametrize(
    ("runs", "fragment"),
    [
        ({"a": {"m": ["x"]}, "b": {"m": [1.0]}}, r"agent 'a' has a run whose score is not a finite number: \['x'\] on MDP 'm'"),
        ([1, 2], r"runs=\[1, 2\] is not allowed: give a dict of agent -> \{MDP -> cumulative rewards of its runs\}"),
        ({"a": [1.0], "b": {"m": [1.0]}}, r"runs=\{'a': \[1\.0\], 'b': \{'m': \[1\.0\]\}\} is not allowed: give a dict of agent"),
    ],
)
def test_win_probabilities_refuses_text_scores_and_runs_that_are_no_table(runs, fragment: str) -> None:
    """F20: a text score was NumPy's "could not convert string to float" (NaN was refused clearly), and runs=[1, 2]
    an AttributeError 'items'."""
    from neurohover.experiments.wins import win_probabilities

    with pytest.raises(NeurohoverError, match=fragment):
        win_probabilities(runs, 2, draws=10)
