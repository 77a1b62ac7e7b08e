"""Env info (the MDP's family, label and parameters) and float32 observations, single and vector envs."""

from __future__ import annotations

import warnings

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env
from gymnasium.vector import SyncVectorEnv

import neurohover
from neurohover import NeurohoverError, get_task_family
from neurohover.envs import HoverEnv, HoverVectorEnv
from neurohover.envs.hover import mdp_info
from neurohover.sim.constants import PARAM_NAMES

BASELINE = neurohover.baseline_policy()
KEYS = {"family", "label", "params", "param_names"}


# -- info["mdp_info"] --------------------------------------------------------------------------


@pytest.mark.parametrize(("task", "n_params", "first_name"), [("ghh08", 2, "wind_u"), ("ghh09", 8, None), ("fghh", 11, "C_u")])
def test_reset_and_step_info_carry_the_mdp(task: str, n_params: int, first_name: str | None) -> None:
    family = get_task_family(task)
    env = HoverEnv(task, mdp="test:5")
    obs, info = env.reset(seed=0)
    mdp = family.test_mdps()[5]
    assert info["mdp"] == mdp.label and info["crashed"] is False  # the keys that were there before
    details = info["mdp_info"]
    assert set(details) == KEYS
    assert details["family"] == task and details["label"] == mdp.label
    assert len(details["params"]) == len(details["param_names"]) == n_params
    assert details["param_names"] == tuple(family.param_names)
    assert first_name is None or details["param_names"][0] == first_name
    # The parameters are the MDP's own: making it again from them gives the same MDP.
    assert family.make(details["params"]) == mdp
    _, _, _, _, step_info = env.step(np.array(BASELINE.act(obs)))
    assert step_info["mdp_info"] == details and step_info["mdp"] == mdp.label and step_info["crashed"] is False


def test_ghh08_params_are_the_wind() -> None:
    env = HoverEnv("ghh08", mdp=get_task_family("ghh08").make([2.5, -1.0]))
    _, info = env.reset(seed=0)
    assert info["mdp_info"]["params"] == (2.5, -1.0)


def test_sampled_mdps_report_their_draw() -> None:
    env = gym.make("neurohover/FGHH-v0", sigma=0.2)
    _, info = env.reset(seed=3)
    mdp = env.unwrapped.mdp
    assert info["mdp_info"]["params"] == tuple(mdp.params) and info["mdp_info"]["label"] == "fghh/sample"
    _, again = env.reset()
    assert again["mdp_info"]["params"] != info["mdp_info"]["params"]  # a fresh MDP each episode


def test_info_is_the_callers_to_change() -> None:
    env = HoverEnv("ghh08", mdp="train:0")
    _, info = env.reset(seed=0)
    info["mdp_info"]["label"] = "mine"
    _, _, _, _, step_info = env.step(np.zeros(4))
    assert step_info["mdp_info"]["label"] == "ghh08/train:0"


def test_zero_setting_and_learned_model_info() -> None:
    assert mdp_info(get_task_family("ghh09").zero())["params"] == (0.0,) * 8
    model = neurohover.MDP("model", params=tuple(range(11)), d_u=0.5, label="lr-model")
    info = mdp_info(model)
    assert info["family"] == "model" and info["label"] == "lr-model"
    assert info["param_names"] == (*PARAM_NAMES, "D_u") and info["params"] == (*map(float, range(11)), 0.5)


def test_vector_env_info_matches_sync_vector_env() -> None:
    n = 3
    native = gym.make_vec("neurohover/GHH09-v0", num_envs=n, vectorization_mode="vector_entry_point")
    reference = SyncVectorEnv([lambda: gym.make("neurohover/GHH09-v0") for _ in range(n)])
    _, info_n = native.reset(seed=4)
    _, info_r = reference.reset(seed=4)
    assert info_n["_mdp_info"].all()
    for key in KEYS:
        assert info_n["mdp_info"][key].tolist() == info_r["mdp_info"][key].tolist(), key
        assert info_n["mdp_info"][f"_{key}"].all()
    # Steps without a reset carry no MDP info; a reset sub-environment does, with its mask.
    _, _, _, _, info = native.step(np.zeros((n, 4)))
    assert "mdp_info" not in info
    for _ in range(30):  # collective 0: every helicopter crashes within a few steps
        _, _, terminated, truncated, _ = native.step(np.zeros((n, 4)))
        if terminated.any():
            break
    _, _, _, _, info = native.step(np.zeros((n, 4)))  # the autoreset step
    mask = info["_mdp_info"]
    assert mask.tolist() == terminated.tolist() and mask.tolist() == info["_mdp"].tolist()
    i = int(np.flatnonzero(mask)[0])
    assert info["mdp_info"]["params"][i] == mdp_info(native.mdps[i])["params"]
    assert info["mdp_info"]["family"][i] == "ghh09" and len(info["mdp_info"]["params"][i]) == 8
    assert all(info["mdp_info"]["params"][j] is None for j in range(n) if not mask[j])


def test_vector_env_info_of_fixed_and_mixed_mdps() -> None:
    family = get_task_family("ghh08")
    model = neurohover.MDP("model", label="m")
    envs = HoverVectorEnv(3, task="ghh08", mdp=["test:2", model, "sample"])
    _, info = envs.reset(seed=0)
    details = info["mdp_info"]
    assert details["label"].tolist() == ["ghh08/test:2", "m", "ghh08/sample"]
    assert details["family"].tolist() == ["ghh08", "model", "ghh08"]
    assert details["params"][0] == tuple(family.test_mdps()[2].wind) and len(details["params"][1]) == 12
    assert details["params"][2] == tuple(envs.mdps[2].wind)


# -- obs_dtype ------------------------------------------------------------------------------------


@pytest.mark.parametrize("env_id", ["neurohover/GHH08-v0", "neurohover/FGHH-v0"])
def test_float32_observations(env_id: str) -> None:
    env = gym.make(env_id, obs_dtype="float32")
    assert env.observation_space == gym.spaces.Box(-np.inf, np.inf, (12,), np.float32)
    obs, _ = env.reset(seed=0)
    assert obs.dtype == np.float32 and obs.shape == (12,)
    obs, reward, *_ = env.step(np.zeros(4))
    assert obs.dtype == np.float32 and isinstance(reward, float)
    assert env.observation_space.contains(obs)


def test_default_stays_float64_and_float32_flies_the_same_episode() -> None:
    assert gym.make("neurohover/GHH08-v0").observation_space.dtype == np.float64
    wide, narrow = HoverEnv("ghh09", mdp="train:1"), HoverEnv("ghh09", mdp="train:1", obs_dtype=np.float32)
    obs64, _ = wide.reset(seed=9)
    obs32, _ = narrow.reset(seed=9)
    for _ in range(40):
        # The policy sees the float64 observation in both: the simulation is the same, only the output is rounded.
        action = np.array(BASELINE.act(obs64))
        obs64, r64, *_ = wide.step(action)
        obs32, r32, *_ = narrow.step(action)
        assert obs64.dtype == np.float64 and obs32.dtype == np.float32
        np.testing.assert_array_equal(obs32, obs64.astype(np.float32))
        assert r32 == r64


def test_float32_env_passes_the_checker() -> None:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        check_env(gym.make("neurohover/GHH09-v0", obs_dtype="float32").unwrapped, skip_render_check=True)
    assert [str(w.message) for w in caught if "infinity" not in str(w.message)] == []


def test_vector_env_float32() -> None:
    envs = gym.make_vec("neurohover/GHH08-v0", num_envs=4, vectorization_mode="vector_entry_point", obs_dtype="float32")
    assert envs.single_observation_space.dtype == np.float32 and envs.observation_space.dtype == np.float32
    obs, _ = envs.reset(seed=0)
    assert obs.dtype == np.float32 and obs.shape == (4, 12)
    for _ in range(20):  # through crashes and autoresets
        obs, rewards, *_ = envs.step(np.zeros((4, 4)))
        assert obs.dtype == np.float32 and rewards.dtype == np.float64
        assert envs.observation_space.contains(obs)
    wide = gym.make_vec("neurohover/GHH08-v0", num_envs=4, vectorization_mode="vector_entry_point")
    narrow = gym.make_vec("neurohover/GHH08-v0", num_envs=4, vectorization_mode="vector_entry_point", obs_dtype="float32")
    wide.reset(seed=1)
    narrow.reset(seed=1)
    for _ in range(10):
        o64, r64, *_ = wide.step(np.full((4, 4), 0.3))
        o32, r32, *_ = narrow.step(np.full((4, 4), 0.3))
        np.testing.assert_array_equal(o32, o64.astype(np.float32))
        np.testing.assert_array_equal(r32, r64)
    # Gymnasium's sync vector env over single envs takes the same argument.
    sync = gym.make_vec("neurohover/GHH08-v0", num_envs=2, vectorization_mode="sync", obs_dtype="float32")
    assert sync.reset(seed=0)[0].dtype == np.float32


@pytest.mark.parametrize("bad", ["float16", "int32", None, "double-ish", 3])
def test_bad_obs_dtype_is_refused(bad) -> None:
    with pytest.raises(NeurohoverError, match="obs_dtype=.* is not allowed: use 'float64' or 'float32'"):
        HoverEnv("ghh08", obs_dtype=bad)
    with pytest.raises(NeurohoverError, match="obs_dtype=.* is not allowed"):
        HoverVectorEnv(2, obs_dtype=bad)
