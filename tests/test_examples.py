"""examples/ppo_ghh08.py runs end to end (needs the examples extra: pip install -e '.[examples]')."""

from __future__ import annotations

import importlib.util
import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from conftest import ROOT

pytest.importorskip("stable_baselines3")

import gymnasium as gym  # noqa: E402

from neurohover.sim.constants import CRASH_STEP_PENALTY  # noqa: E402
from neurohover.wrappers import CrashAwareReward  # noqa: E402

SCRIPT = Path(__file__).resolve().parents[1] / "examples" / "ppo_ghh08.py"


def _load_script():
    spec = importlib.util.spec_from_file_location("ppo_ghh08", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_ppo_script_trains_evaluates_and_writes_results(tmp_path):
    out = tmp_path / "run"
    cmd = [sys.executable, str(SCRIPT), "--mdp", "train:3", "--total-steps", "256", "--n-envs", "2", "--n-steps", "64"]
    cmd += ["--eval-episodes", "2", "--test-mdps", "test:0", "--seed", "1", "--out", str(out)]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert "mean return" in proc.stdout
    results = json.loads((out / "results.json").read_text())
    assert (out / "model.zip").exists() and (out / "vecnormalize.pkl").exists()
    assert results["training"]["steps"] == 256 and results["training"]["curve"]
    assert all(e["length"] <= 1000 for e in results["training"]["curve"])
    rows = {(r["policy"], r["mdp"]): r for r in results["evaluation"]}
    assert set(rows) == {("ppo", "train:3"), ("baseline", "train:3"), ("ppo", "test:0"), ("baseline", "test:0")}
    for r in rows.values():
        assert r["episodes"] == 2 and len(r["returns"]) == 2 and np.all(np.isfinite(r["returns"]))
        assert 0 <= r["crashes"] <= 2 and 1 <= r["mean_steps"] <= 6000
    # The baseline flies the gusts of `neurohover fly --seed 0`: it never crashes and earns about -23,000 on train:3.
    assert rows[("baseline", "train:3")]["crashes"] == 0 and -3e4 < rows[("baseline", "train:3")]["mean_return"] < -1.5e4


def test_squashed_reward_keeps_a_crash_worse_than_flying_on():
    script = _load_script()
    assert script.CrashAwareReward is CrashAwareReward  # the script trains with the package's wrapper
    gamma, scale, steps = 0.99, 0.1, 1000
    env = gym.make(script.ENV_ID, mdp="zero", obs_dtype="float32", episode_steps=steps, max_episode_steps=steps)
    wrapped = CrashAwareReward(gym.wrappers.RecordEpisodeStatistics(env), gamma, scale)
    obs, _ = wrapped.reset(seed=0)
    assert obs.dtype == np.float32
    rewards, info = [], {}
    for _ in range(steps):  # no collective: it falls and crashes within a few steps
        obs, reward, terminated, truncated, info = wrapped.step(np.zeros(4))
        rewards.append(reward)
        if terminated or truncated:
            break
    assert terminated and info["crashed"]
    t = len(rewards)
    worst = math.log1p(CRASH_STEP_PENALTY)
    assert rewards[-1] == pytest.approx(-scale * worst * (1 - gamma ** (steps - t)) / (1 - gamma))  # the steps left after the crash
    # Ordinary steps are squashed into (-worst, 0]; the crash is worse than the worst step forever after.
    assert all(-scale * worst <= r <= 0 for r in rewards[:-1])
    assert rewards[-1] < -scale * worst / (1 - gamma) * 0.99
    # The statistics inside the transform keep the environment's raw return.
    assert info["episode"]["r"] < -1e6


def test_make_images_help_describes_and_draws_nothing(tmp_path: Path) -> None:
    images = ROOT / "docs" / "images"
    before = {p.name: p.stat().st_mtime_ns for p in images.glob("*.png")}
    proc = subprocess.run([sys.executable, str(images / "make_images.py"), "--help"], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0 and "usage: make_images.py" in proc.stdout
    assert {p.name: p.stat().st_mtime_ns for p in images.glob("*.png")} == before


@pytest.mark.skipif(importlib.util.find_spec("stable_baselines3") is not None, reason="the examples extra is installed")
def test_the_ppo_example_without_its_extra_says_what_to_install() -> None:
    proc = subprocess.run([sys.executable, str(ROOT / "examples" / "ppo_ghh08.py"), "--help"], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2 and "Traceback" not in proc.stderr
    assert proc.stderr.strip().splitlines() == [
        f"examples/ppo_ghh08.py needs {'torch' if importlib.util.find_spec('torch') is None else 'stable_baselines3'}: "
        "pip install 'neurohover[examples]' (for a CPU build of torch first: pip install torch==2.13.0)"
    ]


@pytest.mark.skipif(importlib.util.find_spec("stable_baselines3") is not None, reason="the examples extra is installed")
def test_the_rl_zoo_evaluation_example_without_its_extra_says_what_to_install() -> None:
    proc = subprocess.run([sys.executable, str(ROOT / "examples" / "evaluate_rl_zoo.py"), "--help"], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2 and "Traceback" not in proc.stderr
    assert "needs stable_baselines3: pip install 'neurohover[examples]'" in proc.stderr


@pytest.mark.skipif(importlib.util.find_spec("evotorch") is not None, reason="evotorch is installed")
def test_the_evotorch_example_without_its_extra_says_what_to_install() -> None:
    proc = subprocess.run([sys.executable, str(ROOT / "examples" / "evotorch_snes.py"), "--help"], capture_output=True, text=True, timeout=120)
    needs = "needs evotorch" if importlib.util.find_spec("torch") is not None else "needs torch"  # torch alone: evotorch is what is missing
    assert proc.returncode == 2 and "Traceback" not in proc.stderr and f"{needs}: pip install 'neurohover[evotorch]'" in proc.stderr
