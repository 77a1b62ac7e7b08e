"""Issue 38, the eleventh fresh trial: its findings about files, paths, plots, reports and the environment (T3, T4, T5,
T9, S5, S7, S9, U3, U8 in part) each give one clear message (exit 2 / NeurohoverError) or are taken as a user would
expect."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from neurohover.errors import NeurohoverError


@pytest.mark.parametrize("value", ["abc", "2", ""])
def test_the_cuda_simulator_variable_numba_cannot_take_is_named(value: str, tmp_path: Path) -> None:
    """T5: NUMBA_ENABLE_CUDASIM=abc was numba's warning with a traceback, then its default (0), from every command."""
    env = {**os.environ, "NUMBA_ENABLE_CUDASIM": value}
    proc = subprocess.run([sys.executable, "-m", "neurohover", "--help"], env=env, cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2 and proc.stdout == "", proc.stderr
    assert proc.stderr == (
        f"neurohover: error: environment variable NUMBA_ENABLE_CUDASIM={value!r} is not allowed: give 0 or 1 "
        "(1: numba's CUDA simulator stands in for a GPU), or unset it\n"
    )
