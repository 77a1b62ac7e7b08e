"""The deep-RL variants (``neurohover/<NAME>-Short-v0``) and the crash-aware reward wrapper."""

from __future__ import annotations

import math
import warnings

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import neurohover  # noqa: F401  (registers the environments)
from neurohover import NeurohoverError
from neurohover.envs import SHORT_ENV_IDS
from neurohover.sim.constants import CRASH_STEP_PENALTY
from neurohover.wrappers import CrashAwareReward, crash_aware


@pytest.mark.parametrize("env_id", list(SHORT_ENV_IDS))
def test_a_short_variant_is_float32_with_1000_step_episodes_and_passes_the_checker(env_id: str) -> None:
    env = gym.make(env_id)
    assert env.observation_space.dtype == np.float32 and env.action_space.dtype == np.float32
    assert env.spec.max_episode_steps == 1000 and env.unwrapped.episode_steps == 1000
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        check_env(env.unwrapped, skip_render_check=True)
    assert not [w for w in caught if "float" in str(w.message).lower() or "dtype" in str(w.message).lower()]
    obs, _ = env.reset(seed=1)
    assert obs.dtype == np.float32


def test_a_crash_in_a_short_episode_is_charged_the_steps_left_of_it() -> None:
    env = gym.make("neurohover/GHH08-Short-v0")
    env.reset(seed=0)
    full = np.ones(4, dtype=np.float32)
    t, terminated, truncated = 0, False, False
    while not (terminated or truncated):
        _, reward, terminated, truncated, _ = env.step(full)
        t += 1
    assert terminated and t < 20
    assert -reward == pytest.approx(CRASH_STEP_PENALTY * (1000 - t), rel=1e-3)  # not the 6000 - t of the long episode


def test_the_vector_variant_takes_the_same_settings() -> None:
    envs = gym.make_vec("neurohover/FGHH-Short-v0", num_envs=3, vectorization_mode="vector_entry_point")
    assert envs.single_observation_space.dtype == np.float32 and envs.single_action_space.dtype == np.float32
    assert envs.unwrapped.episode_steps == 1000
    obs, _ = envs.reset(seed=2)
    assert obs.shape == (3, 12) and obs.dtype == np.float32


def test_the_crash_aware_reward_keeps_a_crash_worse_than_flying_on() -> None:
    assert crash_aware(-0.5) == pytest.approx(-math.log1p(0.5))
    crash = -CRASH_STEP_PENALTY * 999
    gamma = 0.99
    expected = -math.log1p(CRASH_STEP_PENALTY) * (1 - gamma**999) / (1 - gamma)
    assert crash_aware(crash, gamma) == pytest.approx(expected)
    assert crash_aware(crash, gamma) < sum(gamma**k * crash_aware(-1000.0) for k in range(999))  # worse than 999 terrible steps
    np.testing.assert_allclose(crash_aware(np.array([-0.5, crash]), gamma, 0.1), [0.1 * -math.log1p(0.5), 0.1 * expected])
    env = CrashAwareReward(gym.make("neurohover/GHH08-Short-v0"), gamma=gamma)
    env.reset(seed=0)
    _, reward, *_ = env.step(np.zeros(4, dtype=np.float32))
    assert -math.log1p(CRASH_STEP_PENALTY) < reward <= 0
    with pytest.raises(NeurohoverError, match="gamma=1.5 is out of range"):
        CrashAwareReward(gym.make("neurohover/GHH08-Short-v0"), gamma=1.5)


def test_a_bad_action_dtype_is_refused() -> None:
    with pytest.raises(NeurohoverError, match="action_dtype='int8' is not allowed: use 'float64' or 'float32'"):
        gym.make("neurohover/GHH08-v0", action_dtype="int8")


def test_the_crash_aware_function_wraps_a_vector_environment() -> None:
    from gymnasium.wrappers.vector import TransformReward

    def make():
        return gym.make_vec("neurohover/GHH08-Short-v0", num_envs=2, vectorization_mode="vector_entry_point")

    raw, wrapped = make(), TransformReward(make(), crash_aware)
    raw.reset(seed=0)
    wrapped.reset(seed=0)
    for action in (np.zeros((2, 4), dtype=np.float32), np.ones((2, 4), dtype=np.float32)):
        _, r, *_ = raw.step(action)
        _, w, *_ = wrapped.step(action)
        np.testing.assert_allclose(w, crash_aware(r))
