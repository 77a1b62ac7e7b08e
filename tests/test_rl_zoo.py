"""RL Zoo with the shipped PPO recipe (skipped where rl_zoo3 is not installed)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

pytest.importorskip("rl_zoo3", reason="rl_zoo3 is not installed (pip install 'neurohover[examples]' rl_zoo3)")

from conftest import ROOT
from rl_zoo3.utils import get_wrapper_class  # noqa: E402

import neurohover as nh  # noqa: E402
from neurohover.envs import SHORT_ENV_IDS  # noqa: E402
from neurohover.integrations.flying import evaluate_callable  # noqa: E402
from neurohover.integrations.rlzoo_ppo import hyperparams  # noqa: E402
from neurohover.integrations.sb3 import rl_zoo_policy  # noqa: E402
from neurohover.wrappers import CrashAwareReward  # noqa: E402


def test_every_short_id_has_the_recipe_and_rl_zoo_builds_its_wrapper() -> None:
    assert set(hyperparams) == set(SHORT_ENV_IDS)
    wrap = get_wrapper_class(dict(hyperparams["neurohover/GHH08-Short-v0"]))
    env = wrap(gym.make("neurohover/GHH08-Short-v0"))
    assert isinstance(env, CrashAwareReward) and (env.gamma, env.scale) == (0.99, 0.1)
    assert eval(hyperparams["neurohover/GHH08-Short-v0"]["normalize"]) == {"norm_obs": True, "norm_reward": False}


def test_rl_zoo_trains_by_id_and_its_run_flies_full_episodes(tmp_path: Path) -> None:
    tiny = ["n_envs:2", "n_steps:128", "batch_size:64", "n_epochs:1"]
    cmd = [sys.executable, "-m", "rl_zoo3.train", "--algo", "ppo", "--env", "neurohover/GHH08-Short-v0", "--gym-packages", "neurohover"]
    cmd += ["--conf-file", "neurohover.integrations.rlzoo_ppo", "-n", "512", "--seed", "0", "--num-threads", "1", "--eval-freq", "-1"]
    cmd += ["-f", str(tmp_path), "--env-kwargs", "mdp:'train:3'", "--hyperparams", *tiny]
    done = subprocess.run(cmd, cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-2000:]
    run = tmp_path / "ppo" / "neurohover-GHH08-Short-v0_1"
    assert (run / "neurohover-GHH08-Short-v0" / "vecnormalize.pkl").is_file()
    act = rl_zoo_policy(run)
    obs = np.zeros((3, 12), dtype=np.float32)
    assert act(obs).shape == (3, 4)
    flown = evaluate_callable(act, nh.get_task_family("ghh08").mdp("train:3"), episodes=2, n_steps=50)
    assert flown.returns.shape == (1, 2) and np.isfinite(flown.returns).all()


def test_a_folder_that_is_no_rl_zoo_run_is_refused(tmp_path: Path) -> None:
    with pytest.raises(nh.NeurohoverError, match="is not an RL Zoo run folder"):
        rl_zoo_policy(tmp_path)
    with pytest.raises(nh.NeurohoverError, match="algo='dqn' is not supported"):
        rl_zoo_policy(tmp_path, algo="dqn")


def test_the_evaluation_example_refuses_a_bad_run_folder(tmp_path: Path) -> None:
    done = subprocess.run([sys.executable, str(ROOT / "examples" / "evaluate_rl_zoo.py"), str(tmp_path)], capture_output=True, text=True, timeout=300)
    assert done.returncode == 2 and "is not an RL Zoo run folder" in done.stderr and "Traceback" not in done.stderr
