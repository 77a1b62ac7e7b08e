"""Bad-input trial 22, more: a 0-step flight-data episode refused when made (T22-19), a non-integer env argument
called not allowed rather than out of range (T22-14), impossible sessions-table values refused by name (T22-21)."""

from __future__ import annotations

import re

import numpy as np
import pytest

from neurohover.errors import NeurohoverError
from neurohover.flightdata import FlightData


@pytest.mark.parametrize("lengths", [(1, 0), (0,), (0, 3)])
def test_zero_step_episode_refused_when_made(lengths, tmp_path):
    """T22-19: save() wrote a file of a 0-step episode that load() refused; the constructor now refuses it, as load()."""
    obs = tuple(np.zeros((n + 1, 12)) for n in lengths)
    act = tuple(np.zeros((n, 4)) for n in lengths)
    with pytest.raises(NeurohoverError, match=rf"episode {lengths.index(0)} has 0 steps \(a flown one has at least 1\)"):
        FlightData(obs, act)
    assert not list(tmp_path.iterdir())


def test_no_episodes_still_made():
    """An empty window (no episodes at all) is still flight data: the continual agent makes one before its first episode."""
    assert FlightData((), ()).n_episodes == 0


@pytest.mark.parametrize("value", [20.0, "20", True, None])
@pytest.mark.parametrize("name", ["episode_steps", "max_episode_steps", "num_envs"])
def test_env_count_of_wrong_type_not_allowed(name, value):
    """T22-14: gymnasium.make(..., episode_steps=20.0) said 'is out of range' (a type problem called a range one); a
    non-integer is now 'not allowed', an integer past the range still 'out of range'."""
    import gymnasium as gym

    from neurohover.envs.vector import HoverVectorEnv
    from neurohover.errors import brief

    if name == "episode_steps":
        make = lambda v: gym.make("neurohover/GHH08-v0", episode_steps=v)  # noqa: E731
    else:
        make = lambda v: HoverVectorEnv(**{"num_envs": 2, "episode_steps": 20, name: v})  # noqa: E731
    if value is None and name == "max_episode_steps":
        return  # None is its default: the episode budget
    with pytest.raises(NeurohoverError, match=rf"^{name}={re.escape(brief(value))} is not allowed: allowed an integer in 1\.\."):
        make(value)
    with pytest.raises(NeurohoverError, match=rf"^{name}=0 is out of range: allowed an integer in 1\.\."):
        make(0)
