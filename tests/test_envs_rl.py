"""The deep-RL ids ``neurohover/<NAME>-RL-v0`` (neurohover.envs.rl, issue 36): the short episodes with the observation
and action scaling and the crash-aware reward built in, on one environment and the native vector environment alike."""

from __future__ import annotations

import json
import warnings

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import neurohover  # noqa: F401  (registers the environments)
from neurohover.envs import RL_ENV_IDS
from neurohover.envs.rl import ACTION_AUTHORITY, ACTION_OFFSET, OBS_LIMITS, RL_GAMMA, RL_REWARD_SCALE, controls, rl_policy, scale_observation
from neurohover.integrations.flying import compare_agent
from neurohover.tasks import get_task_family
from neurohover.wrappers import crash_aware

ACTIONS = np.random.default_rng(7).uniform(-1.2, 1.2, size=(40, 4)).astype(np.float32)  # some beyond [-1, 1]: clipped


@pytest.mark.parametrize("env_id", list(RL_ENV_IDS))
def test_an_rl_id_is_float32_with_1000_step_episodes_and_passes_the_checker(env_id: str) -> None:
    env = gym.make(env_id)
    assert env.observation_space.dtype == np.float32 and env.action_space.dtype == np.float32
    assert env.spec.max_episode_steps == 1000 and env.unwrapped.episode_steps == 1000
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        check_env(env, skip_render_check=True)
    assert not [w for w in caught if "dtype" in str(w.message).lower()]


def _fly(env_id: str, actions: np.ndarray) -> tuple[list, list, bool]:
    env = gym.make(env_id, mdp="train:3")
    obs, _ = env.reset(seed=5)
    seen, rewards, over = [obs], [], False
    for a in actions:
        obs, r, terminated, truncated, _ = env.step(a)
        seen.append(obs)
        rewards.append(r)
        if terminated or truncated:
            over = terminated
            break
    return seen, rewards, over


def test_an_rl_id_is_the_short_episode_seen_through_its_scaling() -> None:
    """Action a flies controls(a); the observation is the short id's divided by the crash limits; the reward is the
    crash-aware transform of the short id's, crash included."""
    crash = np.ones((40, 4), dtype=np.float32)
    for actions in (ACTIONS, crash):  # the second: full authority, a crash within a few steps
        short_actions = controls(actions, "ghh08").astype(np.float32)
        seen, rewards, over = _fly("neurohover/GHH08-RL-v0", actions)
        raw, raw_rewards, raw_over = _fly("neurohover/GHH08-Short-v0", short_actions)
        assert over == raw_over and len(rewards) == len(raw_rewards)
        np.testing.assert_allclose(np.array(seen), np.array(raw) / OBS_LIMITS, rtol=1e-6, atol=1e-9)
        np.testing.assert_allclose(rewards, crash_aware(np.array(raw_rewards), RL_GAMMA, RL_REWARD_SCALE), rtol=1e-9)


def test_an_rl_policy_flies_the_papers_observations() -> None:
    seen = []

    def act(obs):
        seen.append(obs)
        return np.zeros((obs.shape[0], 4), dtype=np.float32)

    obs = np.arange(24, dtype=np.float64).reshape(2, 12)
    np.testing.assert_allclose(rl_policy(act, "ghh08")(obs), np.tile(ACTION_OFFSET, (2, 1)))  # a = 0: the baseline's action at rest
    np.testing.assert_allclose(seen[0], scale_observation(obs.astype(np.float32)))


def test_the_action_map_is_gentle_near_zero_and_reaches_the_familys_authority() -> None:
    for task, authority in ACTION_AUTHORITY.items():
        np.testing.assert_allclose(controls(np.zeros(4), task), ACTION_OFFSET)
        np.testing.assert_allclose(controls(np.ones(4), task), ACTION_OFFSET + authority)
        np.testing.assert_allclose(controls(-2 * np.ones(4), task), ACTION_OFFSET - authority)  # clipped to -1
        small = controls(np.full(4, 1e-4), task) - ACTION_OFFSET
        np.testing.assert_allclose(small, authority * 1e-4 / 5, rtol=1e-6)
    a = np.linspace(-1, 1, 201)[:, None].repeat(4, axis=1)
    assert np.all(np.diff(controls(a, "ghh09"), axis=0) > 0)  # monotone: every control reachable once


def test_the_vector_rl_id_steps_as_the_single_one() -> None:
    envs = gym.make_vec("neurohover/GHH08-RL-v0", num_envs=2, vectorization_mode="vector_entry_point", mdp="train:3")
    obs, _ = envs.reset(seed=5)
    single = gym.make("neurohover/GHH08-RL-v0", mdp="train:3")
    one, _ = single.reset(seed=5)
    assert obs.dtype == np.float32 and obs.shape == (2, 12)
    np.testing.assert_allclose(obs[0], one)
    for a in ACTIONS[:10]:
        obs, r, _, _, _ = envs.step(np.tile(a, (2, 1)))
        one, r1, *_ = single.step(a)
        np.testing.assert_allclose(obs[0], one, rtol=1e-6)
        assert r[0] == pytest.approx(r1, rel=1e-9)


def test_evaluate_agent_flies_an_rl_id_policy_through_its_scaling(cli, tmp_path, monkeypatch) -> None:
    """A callable trained on an RL id that always answers 0 flies the baseline's action at rest; --rl-id with a
    neurohover policy file is refused."""
    (tmp_path / "zero_agent.py").write_text("import numpy as np\n\ndef act(obs):\n    return np.zeros((obs.shape[0], 4), dtype=np.float32)\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    rc, out, err = cli(
        "evaluate-agent", "--task", "ghh08", "--callable", "zero_agent:act", "--rl-id", "--n-mdps", "2", "--episode-steps", "50",
        "--json", str(tmp_path / "rows.json"),
    )  # fmt: skip
    assert rc == 0, err
    rows = {r["name"]: r for r in json.loads((tmp_path / "rows.json").read_text())["rows"]}
    at_rest = compare_agent(
        lambda obs: np.tile(ACTION_OFFSET, (obs.shape[0], 1)), [get_task_family("ghh08").mdp(f"test:{i}") for i in range(2)], episodes=1, seed=0, n_steps=50
    )
    assert rows["agent"]["return_per_episode"] == pytest.approx(at_rest[0].return_per_episode, rel=1e-9)
    rc, _, err = cli("evaluate-agent", "--task", "ghh08", "--policy", "baseline", "--rl-id", "--n-mdps", "1")
    assert rc == 2 and "--rl-id applies to an agent trained on a neurohover/<NAME>-RL-v0 id" in err


def test_an_rl_id_refuses_a_wrong_action_with_one_clear_error() -> None:
    """The action map runs before the environment's own check: it checks the shape itself (bad-input trial)."""
    from neurohover import NeurohoverError

    env = gym.make("neurohover/GHH08-RL-v0", mdp="zero")
    env.reset(seed=0)
    for bad in (np.zeros(5, np.float32), "abcd", 1.0):
        with pytest.raises(NeurohoverError, match="action"):
            env.step(bad)
    vec = gym.make_vec("neurohover/GHH08-RL-v0", num_envs=2, vectorization_mode="vector_entry_point")
    vec.reset(seed=0)
    with pytest.raises(NeurohoverError, match=r"action has shape \(2, 3\)"):
        vec.step(np.zeros((2, 3)))
