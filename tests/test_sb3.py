"""Stable-Baselines3 on the native vector environment (skipped where SB3 is not installed)."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

pytest.importorskip("stable_baselines3", reason="the examples extra (stable-baselines3) is not installed")

import neurohover  # noqa: E402, F401  (registers the environments)
from neurohover import NeurohoverError  # noqa: E402
from neurohover.integrations.sb3 import SB3VecEnv  # noqa: E402


def test_sb3_steps_the_native_vector_env_with_sb3s_reset_conventions() -> None:
    env = SB3VecEnv("neurohover/GHH08-Short-v0", num_envs=4, episode_steps=30, max_episode_steps=30)
    env.seed(3)
    obs = env.reset()
    assert obs.shape == (4, 12) and obs.dtype == np.float32
    native = gym.make_vec("neurohover/GHH08-Short-v0", num_envs=4, vectorization_mode="vector_entry_point", episode_steps=30, max_episode_steps=30)
    native_obs, _ = native.reset(seed=3)
    np.testing.assert_array_equal(obs, native_obs)
    baseline = neurohover.baseline_policy()
    crashed_once = False
    for _ in range(30):
        # Sub-environment 0 crashes within a few steps; the others fly the baseline to the time limit.
        actions = np.array([[1.0] * 4] + [baseline.act(o) for o in obs[1:]], dtype=np.float32)
        obs, rewards, dones, infos = env.step(actions)
        _, n_rewards, *_ = native.step(actions) if not crashed_once else (None, None)
        if not crashed_once:
            np.testing.assert_allclose(rewards, n_rewards.astype(np.float32))
        if dones[0] and not crashed_once:
            crashed_once = True
            assert infos[0]["crashed"] and not infos[0]["TimeLimit.truncated"]
            assert "terminal_observation" in infos[0] and np.any(infos[0]["terminal_observation"] != 0)
            np.testing.assert_array_equal(obs[0], np.zeros(12))  # reset at once: the start state observes as zeros
    assert crashed_once and dones[1:].all()  # step 30: the time limit
    assert all(info["TimeLimit.truncated"] for info in infos[1:])


def test_ppo_learns_on_it() -> None:
    from stable_baselines3 import PPO
    from stable_baselines3.common.vec_env import VecMonitor

    env = VecMonitor(SB3VecEnv("neurohover/GHH08-Short-v0", num_envs=16, episode_steps=50, max_episode_steps=50))
    model = PPO("MlpPolicy", env, n_steps=16, batch_size=64, n_epochs=1, device="cpu", seed=0)
    model.learn(512)
    assert model.num_timesteps >= 512


def test_only_neurohover_ids_are_taken() -> None:
    with pytest.raises(NeurohoverError, match="is not a neurohover environment"):
        SB3VecEnv("CartPole-v1", num_envs=2)
