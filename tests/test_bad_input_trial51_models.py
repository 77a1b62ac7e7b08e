"""Trial 51, side B (models): noise_from_residuals and authors_noise given NaN, infinite or overflowing residuals
(T51-B02), observed_return on a crashed episode, and EC-MER's true return of one (T51-B03), and observed_return on
flight data that hold no episode (T51-B06)."""

from __future__ import annotations

import re
import warnings

import numpy as np
import pytest

import neurohover as nh
from neurohover.errors import NeurohoverError
from neurohover.models import Transitions, authors_noise, learn_ec_mer, noise_from_residuals, observed_return
from neurohover.models.transitions import residual_bound


@pytest.fixture(scope="module")
def flown() -> nh.FlightData:
    """The baseline's 100 uncrashed steps on GHH-08's first training MDP."""
    return nh.evaluate(nh.baseline_policy(), nh.get_task_family("ghh08").mdp("train:0"), record=True, n_steps=100).flight_data


@pytest.fixture(scope="module")
def crashed() -> nh.Evaluation:
    """The zero SLP's 4 episodes of a 100-step budget on the same MDP: each crashes within 7 steps."""
    return nh.evaluate(nh.prototype("slp", "zero"), nh.get_task_family("ghh08").mdp("train:0"), record=True, n_steps=100, episodes=4)


@pytest.mark.parametrize("value", [np.nan, np.inf, -np.inf, 1e200])
@pytest.mark.parametrize("noise", [noise_from_residuals, authors_noise])
def test_b02_residuals_that_are_not_finite_or_overflow_their_squares_are_refused(flown, noise, value) -> None:
    """T51-B02: NaN residuals gave NaN noise and 1e200 inf, with NumPy's overflow warning, without a word."""
    tr = Transitions(flown)
    residuals = np.zeros((tr.n, 6))
    residuals[3, 2] = value
    bound = re.escape(f"{residual_bound(tr.n):.6g}")
    with pytest.raises(NeurohoverError, match=rf"^residuals\[3, w\] .* is not allowed: give finite numbers in \[-{bound}, {bound}\]"):
        noise(tr, residuals)


def test_b02_residuals_within_the_bound_give_finite_noise(flown) -> None:
    """T51-B02: the bound is what the functions compute: residuals of its size give finite noise, without a warning;
    batched residuals are checked too, naming the batch index."""
    tr = Transitions(flown)
    residuals = np.full((tr.n, 6), residual_bound(tr.n))
    residuals[::2] *= -1  # the largest innovations
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        std, stationary = noise_from_residuals(tr, residuals)
        assert np.isfinite(std).all() and np.isfinite(stationary).all() and np.isfinite(authors_noise(tr, residuals)).all()
    batch = np.zeros((2, tr.n, 6))
    batch[1, 5, 0] = np.nan
    with pytest.raises(NeurohoverError, match=r"^residuals\[1, 5, u\] nan is not allowed"):
        noise_from_residuals(tr, batch)


def test_b03_observed_return_is_the_simulators_return_crash_charge_included(flown, crashed) -> None:
    """T51-B03: a crashed episode's return was the partial sum of its readings (-75.7 for -164,434.4); the crash is
    charged as the simulator charges it, so observed_return is evaluate's return, crashed or not."""
    assert crashed.crashed.all()
    for e in range(4):
        assert observed_return(crashed.flight_data, e) == pytest.approx(float(crashed.returns.ravel()[e]), rel=1e-12)
    assert observed_return(crashed.flight_data, 0) < -1e5
    uncrashed = nh.evaluate(nh.baseline_policy(), nh.get_task_family("ghh08").mdp("train:0"), n_steps=100)
    assert not uncrashed.crashed.any()
    assert observed_return(flown, 0) == pytest.approx(float(uncrashed.returns.ravel()[0]), rel=1e-12)


def test_b03_a_crash_without_its_budget_is_refused(crashed) -> None:
    """T51-B03: a crashed episode whose metadata record no episode_steps has no known charge: refused by name."""
    fd = crashed.flight_data
    meta = {k: v for k, v in fd.metadata.items() if k != "episode_steps"}
    with pytest.raises(NeurohoverError, match=r"^flight data, episode 0: its metadata episode_steps=None is not allowed: the episode crashed"):
        observed_return(nh.FlightData(fd.observations, fd.actions, meta), 0)


def test_b03_ec_mer_flies_a_crashed_episode_to_its_budget(crashed) -> None:
    """T51-B03: EC-MER compared a crashed episode's partial sum with model episodes of its 6 recorded steps; the true
    return now holds the crash's charge, so the model's episodes fly the recording's budget (100 steps)."""
    model = learn_ec_mer(crashed.flight_data, nh.prototype("slp", "zero"), budget=10, seed=1)
    assert model.stats["n_steps"] == 100
    assert model.stats["true_return"] == pytest.approx(float(crashed.returns.ravel()[0]), rel=1e-12)
    assert model.stats["return_error"] < 1e3  # the model crashes too, charged over the same budget


@pytest.mark.parametrize("episode", [0, 1.5])
def test_b06_flight_data_holding_no_episode_are_named(episode) -> None:
    """T51-B06: "give an integer in 0..-1" named nothing allowed; an empty FlightData is still made (an agent's empty
    window, tests/test_bad_input_trial22_more.py) and its readers say it holds no episode."""
    empty = nh.FlightData((), (), {})
    with pytest.raises(NeurohoverError, match=r"the flight data hold no episode"):
        observed_return(empty, episode)  # type: ignore[arg-type]
