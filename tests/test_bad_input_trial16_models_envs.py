"""The sixteenth bad-input trial's findings in the learned models, the environments and the competition odds: each bad
value is one NeurohoverError naming it and what is allowed, and the good value beside it still works."""

from __future__ import annotations

import re

import gymnasium as gym
import numpy as np
import pytest

import neurohover as nh
from neurohover.errors import NeurohoverError
from neurohover.models import LearnedModel, equivalent_params, one_substep_params, parameter_table
from neurohover.models.model import DEFAULT_NOISE_STD, DEFAULT_PARAMS, check_vector

PARAMS, NOISE = np.array(DEFAULT_PARAMS, dtype=float), np.array(DEFAULT_NOISE_STD, dtype=float)
MASKED = "(real numbers, not a masked array)"


def _hide_first(values: np.ndarray) -> np.ma.MaskedArray:
    """``values`` with the first entry masked and set to 5.0: a use of the hidden value shows."""
    shown = values.copy()
    shown[0] = 5.0
    return np.ma.masked_array(shown, mask=[True] + [False] * (values.size - 1))


@pytest.mark.parametrize(
    ("call", "good"),
    [
        (lambda p, n: equivalent_params(p), lambda: equivalent_params(PARAMS)),
        (lambda p, n: equivalent_params(PARAMS, n), lambda: equivalent_params(PARAMS, NOISE)),
        (lambda p, n: one_substep_params(p), lambda: one_substep_params(PARAMS)),
        (lambda p, n: one_substep_params(PARAMS, n), lambda: one_substep_params(PARAMS, NOISE)),
        (lambda p, n: LearnedModel(p, NOISE, "lr"), lambda: LearnedModel(PARAMS, NOISE, "lr")),
        (lambda p, n: LearnedModel(PARAMS, n, "lr"), lambda: LearnedModel(PARAMS, NOISE, "lr")),
        (lambda p, n: check_vector(n, 6, "noise"), lambda: check_vector(NOISE, 6, "noise")),
        (lambda p, n: parameter_table(LearnedModel(PARAMS, NOISE, "lr"), p), lambda: parameter_table(LearnedModel(PARAMS, NOISE, "lr"), PARAMS)),
        (
            lambda p, n: parameter_table(LearnedModel(PARAMS, NOISE, "lr"), nh.get_task_family("fghh").mdp("zero"), n),
            lambda: parameter_table(LearnedModel(PARAMS, NOISE, "lr"), nh.get_task_family("fghh").mdp("zero"), NOISE),
        ),
    ],
)
def test_the_models_refuse_masked_arrays(call, good) -> None:
    """T16-9: the models' vectors (equivalent_params, one_substep_params, LearnedModel, check_vector, parameter_table)
    dropped a masked array's mask and used its hidden values."""
    with pytest.raises(NeurohoverError, match=re.escape(MASKED)):
        call(_hide_first(PARAMS), _hide_first(NOISE))
    assert good() is not None


def test_the_environments_refuse_masked_arrays() -> None:
    """T16-9: env.step flew a masked action's hidden 5.0; the vector env's step and its reset_mask and noise options did
    the same with their masked entries."""
    masked = "not a masked array"
    env = gym.make("neurohover/GHH08-v0", episode_steps=20, max_episode_steps=20)
    env.reset(seed=0)
    with pytest.raises(NeurohoverError, match=re.escape(masked)):
        env.step(np.ma.masked_array(np.full(4, 5.0), mask=[1, 0, 0, 0]))
    assert env.step(np.zeros(4))[0].shape == (12,)
    vec = gym.make_vec("neurohover/GHH08-v0", num_envs=2, vectorization_mode="vector_entry_point", episode_steps=20)
    vec.reset(seed=0)
    with pytest.raises(NeurohoverError, match=re.escape(masked)):
        vec.step(np.ma.masked_array(np.full((2, 4), 5.0), mask=[[1, 0, 0, 0], [0, 0, 0, 0]]))
    with pytest.raises(NeurohoverError, match=re.escape("reset_mask must be a bool numpy array of shape (2,) with at least one True (not a masked array)")):
        vec.reset(options={"reset_mask": np.ma.masked_array([True, True], mask=[False, True])})
    with pytest.raises(NeurohoverError, match=re.escape("is not allowed: give a (seed, episode) pair or 2 of them, not a masked array")):
        vec.reset(options={"noise": np.ma.masked_array([1, 2], mask=[False, False])})
    assert vec.step(np.zeros((2, 4)))[0].shape == (2, 12)
    assert vec.reset(options={"reset_mask": np.array([True, False]), "noise": np.array([1, 2])})[0].shape == (2, 12)


def test_a_callable_agent_that_returns_a_masked_array_is_refused() -> None:
    """T16-9: evaluate-agent --callable flew the hidden values of a masked array that the function returned (its
    actions pass through the environments' real_values)."""
    from neurohover.integrations.flying import evaluate_callable

    mdp = nh.get_task_family("ghh08").mdp("zero")
    with pytest.raises(NeurohoverError, match=re.escape("not a masked array")):
        evaluate_callable(lambda obs: np.ma.masked_array(np.full((len(obs), 4), 5.0), mask=True), mdp, n_steps=5)
    assert evaluate_callable(lambda obs: np.zeros((len(obs), 4)), mdp, n_steps=5).steps.shape == (1, 1)


@pytest.mark.parametrize(
    ("scores", "what"),
    [
        (np.ma.masked_array([-5.0, -1.0], mask=[True, False]), "not a masked array"),
        (np.array(["1", "2"]), "not text"),
        ("12", "not text"),
        ([True, False], "not booleans"),
        ([1 + 0j], "not complex numbers"),
    ],
)
def test_win_probabilities_refuses_scores_that_are_no_real_numbers(scores, what: str) -> None:
    """T16-9, T16-11: win_probabilities took text ('12' as 12.0), booleans and a masked array's hidden values as scores."""
    from neurohover.experiments.wins import win_probabilities

    with pytest.raises(NeurohoverError, match=re.escape(f"agent 'a' has a run whose score is not a finite number: {scores!r:.20}")) as err:
        win_probabilities({"a": {"m": scores}, "b": {"m": [1.5]}}, 1, draws=10)
    assert what in str(err.value)
    assert sum(win_probabilities({"a": {"m": np.array([1.0, 2.0])}, "b": {"m": [1.5]}}, 1, draws=10).values()) == pytest.approx(1.0)


@pytest.mark.parametrize("seed", [2**64, np.uint64(2**64 - 1), 2**63])
def test_win_probabilities_refuses_a_seed_past_2_63(seed) -> None:
    """T16-17: win_probabilities took seeds past 2**63-1 (2**64, np.uint64(2**64-1)), which every other seed refuses."""
    from neurohover.experiments.wins import win_probabilities

    runs = {"a": {"m": [1.0, 2.0]}, "b": {"m": [1.5]}}
    with pytest.raises(NeurohoverError, match=re.escape("is out of range: allowed an integer in 0..2**63-1")):
        win_probabilities(runs, 2, draws=10, seed=seed)
    assert win_probabilities(runs, 2, draws=10, seed=2**63 - 1).draws == 10


def test_learn_ec_mer_refuses_a_bool_true_return() -> None:
    """T16-18: learn_ec_mer(fd, policy, True) took true_return=True as 1.0."""
    from neurohover.models import learn_ec_mer

    base = nh.baseline_policy()
    fd = nh.evaluate(base, nh.get_task_family("ghh08").zero(), episodes=1, record=True, n_steps=20).flight_data
    for bad in (True, np.bool_(True), "1"):
        with pytest.raises(NeurohoverError, match=re.escape(f"true_return={bad!r} must be a finite number")):
            learn_ec_mer(fd, base, bad, budget=2)
    assert learn_ec_mer(fd, base, np.float32(-1.0), budget=2).stats["true_return"] == -1.0


def test_the_vector_env_refuses_a_0d_seed_array_as_the_single_env_does() -> None:
    """T16-5: the vector env's reset(seed=np.array(3)) was len()'s TypeError; the single env refuses it."""
    vec = gym.make_vec("neurohover/GHH08-v0", num_envs=2, vectorization_mode="vector_entry_point", episode_steps=20)
    with pytest.raises(NeurohoverError, match=re.escape("seed=array(3) is not allowed: give None, an integer in 0..2**63-2, or a list of 2")):
        vec.reset(seed=np.array(3))
    with pytest.raises(NeurohoverError, match=re.escape("seed=masked_array(")):
        vec.reset(seed=np.ma.masked_array([3, 4], mask=[False, False]))
    env = gym.make("neurohover/GHH08-v0", episode_steps=20, max_episode_steps=20)
    with pytest.raises(NeurohoverError, match=re.escape("seed=array(3)")):
        env.reset(seed=np.array(3))
    assert vec.reset(seed=np.array([3, 4]))[0].shape == (2, 12) and vec.reset(seed=np.int64(3))[0].shape == (2, 12)


def test_sigma_beside_the_zero_setting_is_refused_by_the_environments() -> None:
    """T16-6: gym.make('neurohover/FGHH-v0', sigma=0.2, mdp='zero') was accepted, its sigma doing nothing (the command
    line refuses it)."""
    from neurohover.envs.arguments import refuse_idle_sigma

    message = "sigma=0.2 does nothing with mdp='zero': sigma is the breadth of the MDPs drawn from FGHH's G"
    with pytest.raises(NeurohoverError, match=re.escape(message)):
        gym.make("neurohover/FGHH-v0", sigma=0.2, mdp="zero")
    for mdp in ("zero", ["zero", "zero"]):
        with pytest.raises(NeurohoverError, match=re.escape("sigma=0.2 does nothing with mdp=")):
            gym.make_vec("neurohover/FGHH-v0", num_envs=2, vectorization_mode="vector_entry_point", sigma=0.2, mdp=mdp)
    with pytest.raises(NeurohoverError, match=re.escape("--sigma 0.5 does nothing with --mdp zero (the default): ")):
        refuse_idle_sigma(0.5, "zero", flags=True, default=True)
    assert gym.make("neurohover/FGHH-v0", sigma=0.2, mdp="sample").unwrapped.family.sigma == 0.2
    assert gym.make("neurohover/FGHH-v0", mdp="zero").unwrapped.family.sigma == 0.3
    vec = gym.make_vec("neurohover/FGHH-v0", num_envs=2, vectorization_mode="vector_entry_point", sigma=0.2, mdp=["zero", "train:0"])
    assert vec.family.sigma == 0.2
