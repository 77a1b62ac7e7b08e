"""Bad input, trial 23: a time limit given to gymnasium.make below the environment's episode_steps (T23-17).

``gymnasium.make(id, episode_steps=100, max_episode_steps=50)``: Gymnasium's TimeLimit truncates every episode at 50
steps while the environment charges a crash for the steps left of its 100, and nothing was said. It is warned of as an
episode_steps above the id's own limit is (envs.arguments.check_against_id): truncating early stays allowed (the vector
environment documents it), so a warning, not a refusal."""

from __future__ import annotations

import warnings

import gymnasium as gym
import numpy as np
import pytest

import neurohover  # noqa: F401  (registers the ids)
from neurohover import baseline_policy

SHORTER = "max_episode_steps=50 is shorter than episode_steps=100"


def _time_limit_warnings(make) -> list[str]:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        make()
    return [str(w.message) for w in caught if "time limit" in str(w.message) or "max_episode_steps" in str(w.message)]


@pytest.mark.parametrize(
    "make",
    [
        lambda: gym.make("neurohover/GHH08-v0", episode_steps=100, max_episode_steps=50),
        lambda: gym.make("neurohover/FGHH-Short-v0", episode_steps=100, max_episode_steps=50),
        lambda: gym.make("neurohover/GHH09-RL-v0", episode_steps=100, max_episode_steps=50),
        lambda: gym.make_vec("neurohover/GHH08-v0", num_envs=2, vectorization_mode="vector_entry_point", episode_steps=100, max_episode_steps=50),
    ],
)
def test_a_time_limit_below_episode_steps_is_warned_of(make) -> None:
    said = _time_limit_warnings(make)
    assert len(said) == 1, said
    assert SHORTER in said[0] and "truncated at 50 steps while a crash is still charged for the steps left of 100" in said[0]
    assert "give episode_steps=50" in said[0] and "or max_episode_steps=100" in said[0]


def test_what_the_warning_says_is_what_happens() -> None:
    """Gymnasium's TimeLimit ends the episode at 50 steps, though the environment's own episode is 100 long."""
    with pytest.warns(UserWarning, match=SHORTER):
        env = gym.make("neurohover/GHH08-v0", episode_steps=100, max_episode_steps=50, mdp="zero")
    assert env.unwrapped.episode_steps == 100
    policy = baseline_policy()
    obs, _ = env.reset(seed=0)
    steps, truncated = 0, False
    while not truncated:
        obs, _, terminated, truncated, _ = env.step(np.array(policy.act(obs)))
        steps += 1
        assert not terminated
    assert steps == 50


@pytest.mark.parametrize(
    "make",
    [
        lambda: gym.make("neurohover/GHH08-v0", episode_steps=100, max_episode_steps=100),  # the limit and the episode agree
        lambda: gym.make("neurohover/GHH08-v0", episode_steps=50, max_episode_steps=100),  # the environment ends first
        lambda: gym.make("neurohover/GHH08-v0", episode_steps=7000, max_episode_steps=-1),  # no TimeLimit at all
        lambda: gym.make("neurohover/GHH08-v0", episode_steps=100),  # below the id's 6000
        lambda: gym.make_vec("neurohover/GHH08-v0", num_envs=2, vectorization_mode="vector_entry_point", episode_steps=100, max_episode_steps=100),
    ],
)
def test_no_warning_where_nothing_is_cut_early(make) -> None:
    assert _time_limit_warnings(make) == []


def test_the_ids_own_limit_is_still_warned_of() -> None:
    said = _time_limit_warnings(lambda: gym.make("neurohover/GHH08-Short-v0", episode_steps=2000))
    assert len(said) == 1 and "episode_steps=2000 is longer than the id's time limit of 1000 steps" in said[0]
