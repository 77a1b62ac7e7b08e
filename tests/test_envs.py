"""Gymnasium environments: registration, checker, seeding, kernel parity, episode ends, vector env."""

from __future__ import annotations

import importlib
import warnings

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env
from gymnasium.vector import AutoresetMode, SyncVectorEnv

import neurohover
from neurohover import MDP, NeurohoverError, baseline_policy, evaluate_jobs, get_task_family
from neurohover.envs import ENV_IDS, HoverEnv, HoverVectorEnv
from neurohover.sim.constants import CRASH_STEP_PENALTY, crash_penalty

TASK_OF = {"neurohover/GHH08-v0": "ghh08", "neurohover/GHH09-v0": "ghh09", "neurohover/FGHH-v0": "fghh"}
FALL = np.zeros(4)  # collective 0: the helicopter drops past 5 m/s within a few steps
BASELINE = baseline_policy()


def _fly(env: gym.Env, actions, seed: int | None = None, options: dict | None = None):
    """Observations, rewards and end flags of one episode flown with ``actions(obs)``."""
    obs, _ = env.reset(seed=seed, options=options)
    observations, rewards = [obs], []
    while True:
        obs, reward, terminated, truncated, info = env.step(actions(obs))
        observations.append(obs)
        rewards.append(reward)
        if terminated or truncated:
            return np.array(observations), np.array(rewards), terminated, truncated, info


def _baseline(obs: np.ndarray) -> np.ndarray:
    return np.array(BASELINE.act(obs))


# -- registration and the Gymnasium checker ---------------------------------------------------


@pytest.mark.parametrize("env_id", sorted(TASK_OF))
def test_make_and_spaces(env_id: str) -> None:
    env = gym.make(env_id)
    assert env.observation_space == gym.spaces.Box(-np.inf, np.inf, (12,), np.float64)
    assert env.action_space == gym.spaces.Box(-1.0, 1.0, (4,), np.float64)
    obs, info = env.reset(seed=0)
    assert obs.dtype == np.float64 and obs.shape == (12,) and not obs.any()
    assert info["mdp"] == f"{TASK_OF[env_id]}/sample" and info["crashed"] is False  # "mdp_info": tests/test_env_info.py
    obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
    assert obs.dtype == np.float64 and isinstance(reward, float) and reward < 0
    assert env.unwrapped.mdp.family == TASK_OF[env_id]
    assert env.spec.max_episode_steps == 6000


@pytest.mark.parametrize("env_id", sorted(TASK_OF))
def test_gymnasium_env_checker_passes(env_id: str) -> None:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        check_env(gym.make(env_id).unwrapped, skip_render_check=True)
    # The observation space is unbounded by design (docs/model.md, Simulator); anything else the checker says is a bug.
    other = [str(w.message) for w in caught if "infinity" not in str(w.message)]
    assert other == []


def test_fghh_sigma_kwarg() -> None:
    assert gym.make("neurohover/FGHH-v0").unwrapped.family.sigma == 0.3
    assert gym.make("neurohover/FGHH-v0", sigma=0.2).unwrapped.family.sigma == 0.2


@pytest.mark.parametrize(
    "make",
    [
        lambda: gym.make("neurohover/GHH08-v0", task="ghh09"),
        lambda: gym.make("neurohover/GHH08-RL-v0", task="fghh"),
        lambda: gym.make_vec("neurohover/GHH08-v0", num_envs=2, vectorization_mode="vector_entry_point", task="ghh09"),
    ],
)
def test_a_task_that_is_not_the_ids_is_refused(make) -> None:
    """Gymnasium merges make()'s kwargs over the id's: a GHH-09 env under a GHH-08 id was built without a word (bad-input trial)."""
    with pytest.raises(NeurohoverError, match="is the ghh08 task family: task='(ghh09|fghh)' conflicts with it"):
        make()
    assert gym.make("neurohover/GHH08-v0", task="ghh08").unwrapped.family.name == "ghh08"  # the id's own task is no conflict


def test_episodes_longer_than_the_ids_time_limit_are_warned_of() -> None:
    """An episode_steps above the id's TimeLimit was truncated silently (bad-input trial); with the limit raised too, no warning."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        gym.make("neurohover/GHH08-Short-v0", episode_steps=6000)
        gym.make_vec("neurohover/GHH08-Short-v0", num_envs=2, vectorization_mode="vector_entry_point", episode_steps=6000)
    said = [str(w.message) for w in caught if "longer than the id's time limit of 1000 steps" in str(w.message)]
    assert len(said) == 2 and "max_episode_steps=6000" in said[0]
    with pytest.warns(UserWarning, match="longer than the id's time limit"):
        short = gym.make("neurohover/GHH08-Short-v0", episode_steps=6000, mdp="zero")
    _, rewards, terminated, truncated, _ = _fly(short, lambda o: _baseline(o.astype(float)).astype(np.float32), seed=0)
    assert len(rewards) == 1000 and truncated and not terminated  # what the warning says: the id's limit cuts the episode
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        gym.make_vec("neurohover/GHH08-Short-v0", num_envs=2, vectorization_mode="vector_entry_point", episode_steps=6000, max_episode_steps=6000)
    assert not [w for w in caught if "time limit" in str(w.message)]


def test_reimport_does_not_register_twice() -> None:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        importlib.reload(neurohover.envs)
    assert not [w for w in caught if "Overriding" in str(w.message)]
    assert all(env_id in gym.registry for env_id in ENV_IDS)


# -- seeding and MDP choice ---------------------------------------------------------------


def test_reset_seed_is_deterministic() -> None:
    a, b = HoverEnv("ghh09", episode_steps=40), HoverEnv("ghh09", episode_steps=40)
    run_a = _fly(a, _baseline, seed=5)
    run_b = _fly(b, _baseline, seed=5)
    assert a.mdp == b.mdp and a.noise_stream == b.noise_stream
    np.testing.assert_array_equal(run_a[0], run_b[0])
    np.testing.assert_array_equal(run_a[1], run_b[1])
    run_c = _fly(b, _baseline, seed=6)
    assert b.mdp != a.mdp and not np.array_equal(run_c[0], run_a[0])
    # Unseeded resets continue the seeded generator: a fresh MDP and fresh gusts each episode.
    first = (a.mdp, a.noise_stream)
    a.reset()
    assert (a.mdp, a.noise_stream) != first


@pytest.mark.parametrize("task", ["ghh08", "ghh09", "fghh"])
def test_options_pick_the_mdp(task: str) -> None:
    family = get_task_family(task)
    env = HoverEnv(task, episode_steps=10)
    env.reset(seed=0, options={"mdp": "train:3"})
    assert env.mdp == family.training_mdps()[3]
    env.reset()  # the choice holds for later episodes
    assert env.mdp == family.training_mdps()[3]
    _, info = env.reset(options={"mdp": "test:42"})
    assert env.mdp == family.test_mdps()[42] and info["mdp"] == f"{task}/test:42"
    env.reset(options={"mdp": "zero"})
    assert env.mdp == family.zero()
    explicit = family.sample(123)
    env.reset(options={"mdp": explicit})
    assert env.mdp is explicit
    env.reset(options={"mdp": "sample"})
    sampled = env.mdp
    env.reset()
    assert env.mdp != sampled


def test_constructor_mdp_argument() -> None:
    env = gym.make("neurohover/GHH08-v0", mdp="test:7")
    env.reset(seed=0)
    assert env.unwrapped.mdp == get_task_family("ghh08").test_mdps()[7]


# -- parity with the batched kernel rollout -------------------------------------------------


@pytest.mark.parametrize("task", ["ghh08", "ghh09", "fghh"])
def test_trajectory_equals_kernel_rollout(task: str) -> None:
    n_steps = 300
    env = HoverEnv(task, mdp="train:0", episode_steps=n_steps)
    obs, rewards, terminated, truncated, _ = _fly(env, _baseline, seed=11)
    assert truncated and not terminated
    seed, episode = env.noise_stream
    ev = evaluate_jobs([BASELINE], env.mdp, [0], [0], [episode], seed=seed, record=[True], n_steps=n_steps)
    # The env's policy runs in Python, the rollout's in the kernel (with fused multiply-adds).
    np.testing.assert_allclose(obs, ev.flight_data.observations[0], rtol=1e-7, atol=1e-9)
    assert rewards.sum() == pytest.approx(ev.returns[0], rel=1e-9)
    # Another noise seed flies other gusts.
    other = evaluate_jobs([BASELINE], env.mdp, [0], [0], [episode], seed=seed + 1, record=[True], n_steps=n_steps)
    assert not np.allclose(obs, other.flight_data.observations[0])


def test_noise_option_replays_an_evaluation_episode() -> None:
    mdp = get_task_family("ghh08").training_mdps()[2]
    env = HoverEnv("ghh08", mdp=mdp, episode_steps=100)
    obs, *_ = _fly(env, _baseline, seed=0, options={"noise": (7, 11)})
    assert env.noise_stream == (7, 11)
    ev = evaluate_jobs([BASELINE], mdp, [0], [0], [11], seed=7, record=[True], n_steps=100)
    np.testing.assert_allclose(obs, ev.flight_data.observations[0], rtol=1e-7, atol=1e-9)


# -- episode ends ------------------------------------------------------------------------


def test_crash_terminates_with_the_penalty() -> None:
    env = HoverEnv("ghh08", mdp="zero", episode_steps=6000)
    obs, rewards, terminated, truncated, info = _fly(env, lambda o: FALL, seed=0)
    t = len(rewards)
    assert terminated and not truncated and info["crashed"] and t <= 10
    assert abs(obs[-1, 2]) > 5.0  # it fell through the 5 m/s limit
    assert rewards[-1] == pytest.approx(-CRASH_STEP_PENALTY * (6000 - t))
    assert rewards[-1] == pytest.approx(crash_penalty(t))
    assert np.all(rewards[:-1] > -1e3)
    with pytest.raises(NeurohoverError, match="reset"):
        env.step(FALL)


def test_non_finite_action_is_a_crash() -> None:
    env = HoverEnv("ghh08", mdp="zero", episode_steps=500)
    env.reset(seed=0)
    env.step(np.array([0.02, 0.0, 0.0, 0.23]))
    obs, reward, terminated, truncated, info = env.step(np.array([0.0, np.nan, 0.0, 0.23]))
    assert terminated and info["crashed"] and not truncated
    assert reward == pytest.approx(-CRASH_STEP_PENALTY * (500 - 2))
    assert np.all(np.isfinite(obs))


def test_step_limit_truncates() -> None:
    env = gym.make("neurohover/GHH09-v0", mdp="zero", episode_steps=50)
    _, rewards, terminated, truncated, info = _fly(env, _baseline, seed=0)
    assert len(rewards) == 50 and truncated and not terminated and not info["crashed"]


def test_actions_are_clipped() -> None:
    a, b = HoverEnv("ghh08", mdp="zero"), HoverEnv("ghh08", mdp="zero")
    a.reset(seed=1)
    b.reset(seed=1)
    big = np.array([3.0, -7.0, 0.5, 2.0])
    np.testing.assert_array_equal(a.step(big)[0], b.step(np.clip(big, -1, 1))[0])


# -- vector environment --------------------------------------------------------------------


def _policy_batch(obs: np.ndarray, step: int) -> np.ndarray:
    """Baseline, but a third of the helicopters drop (and crash) in each 12-step block."""
    actions = np.array([BASELINE.act(o) for o in obs])
    falling = (np.arange(len(obs)) + step // 12) % 3 == 0
    actions[falling] = FALL
    return actions


@pytest.mark.parametrize("env_id", sorted(TASK_OF))
def test_make_vec_shapes(env_id: str) -> None:
    envs = gym.make_vec(env_id, num_envs=8, vectorization_mode="vector_entry_point")
    assert isinstance(envs.unwrapped, HoverVectorEnv)
    assert envs.metadata["autoreset_mode"] == AutoresetMode.NEXT_STEP
    assert envs.single_observation_space.shape == (12,) and envs.single_action_space.shape == (4,)
    assert envs.observation_space.shape == (8, 12) and envs.action_space.shape == (8, 4)
    obs, info = envs.reset(seed=0)
    assert obs.shape == (8, 12) and obs.dtype == np.float64 and info["_mdp"].all()
    obs, rewards, terminated, truncated, info = envs.step(envs.action_space.sample())
    assert obs.shape == (8, 12) and obs.dtype == np.float64
    assert rewards.shape == (8,) and rewards.dtype == np.float64
    assert terminated.dtype == np.bool_ and truncated.dtype == np.bool_
    assert info["crashed"].shape == (8,)


@pytest.mark.parametrize("task", ["ghh08", "ghh09", "fghh"])
def test_vector_env_equals_sync_vector_env_of_single_envs(task: str) -> None:
    # Gymnasium's own SyncVectorEnv of HoverEnvs defines NEXT_STEP autoreset and per-env seeding
    # (seed + i); the native vector env must agree with it bit for bit, crashes, truncations and
    # autoresets included.
    n, steps = 6, 70
    native = HoverVectorEnv(n, task=task, episode_steps=25)
    reference = SyncVectorEnv([lambda: HoverEnv(task, episode_steps=25) for _ in range(n)])
    obs_n, _ = native.reset(seed=3)
    obs_r, _ = reference.reset(seed=3)
    np.testing.assert_array_equal(obs_n, obs_r)
    saw = {"terminated": 0, "truncated": 0}
    for k in range(steps):
        actions = _policy_batch(obs_n, k)
        obs_n, rew_n, term_n, trunc_n, info_n = native.step(actions)
        obs_r, rew_r, term_r, trunc_r, info_r = reference.step(actions)
        np.testing.assert_array_equal(obs_n, obs_r)
        np.testing.assert_array_equal(rew_n, rew_r)
        np.testing.assert_array_equal(term_n, term_r)
        np.testing.assert_array_equal(trunc_n, trunc_r)
        np.testing.assert_array_equal(info_n["crashed"], info_r["crashed"])
        saw["terminated"] += term_n.sum()
        saw["truncated"] += trunc_n.sum()
    assert saw["terminated"] > 0 and saw["truncated"] > 0
    # Sub-env i flies the MDPs that HoverEnv i drew.
    assert native.mdps == [e.mdp for e in reference.envs]
    np.testing.assert_array_equal(native.noise_streams, [e.noise_stream for e in reference.envs])


def test_vector_next_step_autoreset_semantics() -> None:
    envs = gym.make_vec("neurohover/GHH08-v0", num_envs=4, vectorization_mode="vector_entry_point", mdp="zero")
    envs.reset(seed=0)
    actions = np.tile([0.02, 0.0, 0.0, 0.23], (4, 1))
    actions[1] = FALL
    for t in range(1, 20):  # noqa: B007 - t is read after the loop
        obs, rewards, terminated, truncated, info = envs.step(actions)
        if terminated[1]:
            break
    assert terminated.tolist() == [False, True, False, False] and not truncated.any()
    assert rewards[1] == pytest.approx(-CRASH_STEP_PENALTY * (6000 - t))
    assert "mdp" not in info
    # The next step ignores env 1's action and starts its new episode.
    obs, rewards, terminated, truncated, info = envs.step(actions)
    assert not obs[1].any() and rewards[1] == 0.0
    assert not terminated.any() and not truncated.any()
    assert info["_mdp"].tolist() == [False, True, False, False] and info["mdp"][1] == "ghh08/zero"
    assert envs.unwrapped.steps.tolist() == [t + 1, 0, t + 1, t + 1]
    obs, rewards, terminated, truncated, info = envs.step(actions)
    assert obs[1].any() and rewards[1] < 0 and envs.unwrapped.steps[1] == 1


def test_vector_truncation_and_max_episode_steps() -> None:
    envs = gym.make_vec("neurohover/GHH08-v0", num_envs=3, vectorization_mode="vector_entry_point", mdp="zero", max_episode_steps=5)
    envs.reset(seed=0)
    actions = np.tile([0.02, 0.0, 0.0, 0.23], (3, 1))
    for _ in range(4):
        assert not envs.step(actions)[3].any()
    assert envs.step(actions)[3].all()


def test_vector_mdp_and_noise_options() -> None:
    family = get_task_family("ghh09")
    train = family.training_mdps()
    envs = HoverVectorEnv(3, task="ghh09", mdp=["train:0", "zero", train[5]], episode_steps=40)
    envs.reset(seed=1, options={"noise": (7, 20)})
    assert envs.mdps == [train[0], family.zero(), train[5]]
    assert envs.noise_streams.tolist() == [[7, 20], [7, 21], [7, 22]]
    obs = [envs.reset(options={"noise": (7, 20)})[0]]
    for _ in range(40):
        obs.append(envs.step(np.array([BASELINE.act(o) for o in obs[-1]]))[0])
    ev = evaluate_jobs([BASELINE], [train[0], family.zero(), train[5]], [0, 0, 0], [0, 1, 2], [20, 21, 22], seed=7, record=[True] * 3, n_steps=40)
    for i in range(3):
        np.testing.assert_allclose(np.array(obs)[:, i], ev.flight_data.observations[i], rtol=1e-7, atol=1e-9)
    # Per-env noise pairs, a new MDP for all, and a partial reset.
    envs.reset(options={"noise": [(1, 0), (2, 0), (3, 0)], "mdp": "test:4"})
    assert envs.noise_streams.tolist() == [[1, 0], [2, 0], [3, 0]]
    assert envs.mdps == [family.test_mdps()[4]] * 3
    envs.step(np.zeros((3, 4)))
    before = envs.steps
    obs, info = envs.reset(options={"reset_mask": np.array([False, True, False]), "mdp": "sample"})
    assert envs.steps.tolist() == [before[0], 0, before[2]] and info["_mdp"].tolist() == [False, True, False]
    assert envs.mdps[1].label == "ghh09/sample" and envs.mdps[0] == family.test_mdps()[4]


# -- bad input ---------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("make", "match"),
    [
        (lambda: HoverEnv("ghh10"), "unknown task 'ghh10'.*allowed ghh08, ghh09, fghh"),
        (lambda: HoverEnv("ghh08", sigma=0.2), "sigma applies to the fghh task only"),
        (lambda: HoverEnv("fghh", sigma=5.0), "sigma=5.0 is out of range"),
        (lambda: HoverEnv("ghh08", mdp="train:10"), r"train:10.*out of range: allowed 0..9"),
        (lambda: HoverEnv("ghh08", mdp="medium"), "unknown MDP 'medium'.*allowed zero, sample"),
        (lambda: HoverEnv("ghh08", mdp=3), "mdp=3 is not allowed.*MDP instance"),
        (lambda: HoverEnv("ghh08", episode_steps=0), "episode_steps=0 is out of range"),
        (lambda: HoverEnv("ghh08", render_mode="ansi"), "render_mode='ansi' is not supported.*'human', 'rgb_array'"),
        (lambda: HoverVectorEnv(2, render_mode="rgb_array"), "render_mode='rgb_array' is not supported"),
        (lambda: HoverVectorEnv(0), "num_envs=0 is out of range"),
        (lambda: HoverVectorEnv(2, mdp=["zero"]), "mdp has 1 entries but there are num_envs=2"),
        (lambda: HoverVectorEnv(2, max_episode_steps=0), "max_episode_steps=0 is out of range"),  # was named episode_steps (second trial)
        (lambda: gym.make_vec("neurohover/GHH08-v0", num_envs=2, vectorization_mode="vector_entry_point", task="x"), "unknown task 'x'"),
    ],
)
def test_bad_construction_raises(make, match: str) -> None:
    with pytest.raises(NeurohoverError, match=match):
        make()


def test_bad_reset_and_step_input_raises() -> None:
    env = HoverEnv("ghh08", mdp="zero")
    with pytest.raises(NeurohoverError, match="reset"):
        env.step(np.zeros(4))
    env.reset(seed=0)
    with pytest.raises(NeurohoverError, match=r"unknown MDP 'test:x'"):
        env.reset(options={"mdp": "test:x"})
    assert env.mdp.label == "ghh08/zero"  # a rejected reset changes nothing
    with pytest.raises(NeurohoverError, match="unknown reset option.*mpd.*allowed mdp, noise"):
        env.reset(options={"mpd": "zero"})
    with pytest.raises(NeurohoverError, match=r"noise seed=-1 is out of range"):
        env.reset(options={"noise": (-1, 0)})
    with pytest.raises(NeurohoverError, match=r"noise=5 is not allowed"):
        env.reset(options={"noise": 5})
    env.reset()
    with pytest.raises(NeurohoverError, match=r"action has shape \(3,\), expected \(4,\)"):
        env.step(np.zeros(3))
    with pytest.raises(NeurohoverError, match=r"action 'up' is not allowed"):
        env.step("up")

    envs = HoverVectorEnv(4, task="ghh08")
    with pytest.raises(NeurohoverError, match="before reset"):
        envs.step(np.zeros((4, 4)))
    with pytest.raises(NeurohoverError, match="first reset"):
        envs.reset(options={"reset_mask": np.array([True, False, False, False])})
    envs.reset(seed=0)
    with pytest.raises(NeurohoverError, match=r"actions have shape \(3, 4\), expected \(4, 4\)"):
        envs.step(np.zeros((3, 4)))
    with pytest.raises(NeurohoverError, match=r"seed=-2 is out of range"):
        envs.reset(seed=-2)
    with pytest.raises(NeurohoverError, match=r"seed=\[1, 2\] is not allowed"):
        envs.reset(seed=[1, 2])
    with pytest.raises(NeurohoverError, match="reset_mask must be a bool numpy array of shape \\(4,\\)"):
        envs.reset(options={"reset_mask": [True, False, True, True]})
    with pytest.raises(NeurohoverError, match="noise has 2 .* num_envs=4"):
        envs.reset(options={"noise": [(1, 0), (2, 0)]})
    # Actions that are lists or float32 are accepted (copied into float64).
    assert envs.step(np.zeros((4, 4), dtype=np.float32))[0].dtype == np.float64
    assert envs.step([[0.0] * 4] * 4)[0].shape == (4, 12)


def test_explicit_model_mdp_is_flyable() -> None:
    # A learned model (one 0.1 s substep) flies in the environment like any other MDP.
    model = MDP("model", substeps=1, dt=0.1, label="model")
    env = HoverEnv("fghh", mdp=model, episode_steps=20)
    _, rewards, terminated, truncated, _ = _fly(env, _baseline, seed=0)
    assert truncated and not terminated and len(rewards) == 20
