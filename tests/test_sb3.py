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


def test_sb3vecenv_over_an_rl_id_steps_it_with_its_transforms() -> None:
    """Issue 36: the RL id's scaling and crash-aware reward hold on SB3's native vector env as on gym.make."""
    env = SB3VecEnv("neurohover/GHH08-RL-v0", num_envs=2, mdp="train:3")
    env.seed(5)
    obs = env.reset()
    single = gym.make("neurohover/GHH08-RL-v0", mdp="train:3")
    one, _ = single.reset(seed=5)
    np.testing.assert_allclose(obs[0], one)
    action = np.array([0.3, -0.2, 0.1, 0.05], dtype=np.float32)
    for _ in range(5):
        obs, rewards, _, _ = env.step(np.tile(action, (2, 1)))
        one, r, *_ = single.step(action)
        np.testing.assert_allclose(obs[0], one, rtol=1e-6)
        assert rewards[0] == pytest.approx(r, rel=1e-6)


def test_a_recurrent_model_keeps_each_episodes_state_when_flown_in_a_batch(tmp_path) -> None:
    """Issue 36: evaluate-agent --algo ppo_lstm: a RecurrentPPO flown on several episodes at once acts in each as it
    does flown alone from that episode's first step."""
    sb3_contrib = pytest.importorskip("sb3_contrib", reason="sb3-contrib is not installed")
    from neurohover.integrations.flying import evaluate_callable
    from neurohover.integrations.sb3 import RecurrentPolicy, sb3_policy

    model = sb3_contrib.RecurrentPPO("MlpLstmPolicy", gym.make("neurohover/GHH08-Short-v0"), n_steps=64, batch_size=64, seed=0, device="cpu")
    model.learn(64)
    model.save(tmp_path / "lstm.zip")
    act = sb3_policy(tmp_path / "lstm.zip", algo="ppo_lstm", deterministic=True)
    assert isinstance(act, RecurrentPolicy)
    mdps = [neurohover.get_task_family("ghh08").mdp(f"test:{i}") for i in range(3)]
    batch = evaluate_callable(act, mdps, episodes=1, seed=2, n_steps=40, obs_dtype="float32", indexed=True)
    for i, mdp in enumerate(mdps):  # alone: a fresh state, the same gusts (stream (seed, i))
        fresh = sb3_policy(tmp_path / "lstm.zip", algo="ppo_lstm")
        alone = evaluate_callable(fresh, [mdp], episodes=1, seed=2, n_steps=40, obs_dtype="float32", indexed=True, first_episode=i)
        assert float(np.ravel(alone.returns)[0]) == pytest.approx(float(np.ravel(batch.returns)[i]), rel=1e-9)
    memoryless = evaluate_callable(lambda obs: model.predict(obs, deterministic=True)[0], mdps, episodes=1, seed=2, n_steps=40, obs_dtype="float32")
    assert not np.allclose(np.ravel(memoryless.returns), np.ravel(batch.returns), rtol=1e-9, atol=0)  # the state is carried


def test_a_file_that_is_no_saved_model_is_refused_by_name(tmp_path) -> None:
    """The fuzz test's case with SB3 installed: --sb3 FILE of garbage gave zipfile's traceback."""
    from neurohover.integrations.sb3 import sb3_policy

    (tmp_path / "m.zip").write_text("garbage")
    with pytest.raises(NeurohoverError, match="is not a Stable-Baselines3 model file"):
        sb3_policy(tmp_path / "m.zip")
    pytest.importorskip("sb3_contrib", reason="sb3-contrib is not installed")
    from stable_baselines3 import PPO

    PPO("MlpPolicy", gym.make("neurohover/GHH08-Short-v0"), device="cpu").save(tmp_path / "ppo.zip")
    with pytest.raises(NeurohoverError, match="cannot be loaded as a TQC model"):  # another algorithm's model: TQC's AttributeError
        sb3_policy(tmp_path / "ppo.zip", algo="tqc")
