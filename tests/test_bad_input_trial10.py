"""Issue 37, the tenth fresh trial: each case it found gives one clear message (exit 2 / NeurohoverError) or is
taken as a user would expect; the Python API's (equality, SB3VecEnv) are in test_bad_input_trial10_api.py."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from neurohover.errors import NeurohoverError


@pytest.mark.parametrize("value", ["0", "-3", "abc", "", "٣"])
def test_numba_threads_of_the_environment_that_numba_cannot_take_are_named(value: str, tmp_path: Path) -> None:
    """T1: NUMBA_NUM_THREADS=0 was numba's traceback from every command, --help too; 'abc' its warning, then its default."""
    env = {**os.environ, "NUMBA_NUM_THREADS": value}
    proc = subprocess.run([sys.executable, "-m", "neurohover", "--help"], env=env, cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2 and proc.stdout == "", proc.stderr
    assert (
        proc.stderr
        == f"neurohover: error: environment variable NUMBA_NUM_THREADS={value!r} is not allowed: give a whole number >= 1 (numba's threads), or unset it\n"
    )
    code = "import neurohover"
    proc = subprocess.run([sys.executable, "-c", code], env=env, cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 1 and proc.stderr.strip().endswith(
        f"NeurohoverError: environment variable NUMBA_NUM_THREADS={value!r} is not allowed: give a whole number >= 1 (numba's threads), or unset it"
    )


def test_an_agent_made_for_one_family_is_not_run_on_another() -> None:
    """S2: a model-free agent made for GHH-08 flew FGHH's MDPs with GHH-08's policies (make_agent refuses it for FGHH)."""
    import neurohover as nh
    from neurohover.agents import run_test
    from neurohover.agents.registry import make_agent

    g8, fghh = nh.get_task_family("ghh08"), nh.get_task_family("fghh")
    agent = make_agent("model-free", g8)
    with pytest.raises(NeurohoverError, match=r"agent 'model-free' was made for ghh08, but the run's family is fghh \(sigma 0.3\): make the agent"):
        run_test(agent, fghh, fghh.test_mdps()[0], episodes=1, n_steps=10)
    assert run_test(agent, g8, g8.test_mdps()[0], episodes=1, n_steps=10).returns.shape == (1,)
