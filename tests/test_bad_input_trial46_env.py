"""Bad-input trial 46 (46a), the environment: T46-A03 (under NUMBA_DISABLE_JIT=1 every evolution ended in "<intrinsic
_fetch_add> is not usable in pure-python": the lanes' atomic queue, fence and packed fma had no pure-Python form)."""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys

import numpy as np
import pytest


def _neurohover(*args: str, env: dict[str, str] | None = None, cwd=None) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "neurohover", *args], env={**os.environ, **(env or {})}, cwd=cwd, capture_output=True, text=True, timeout=120)


def test_a03_an_evolution_runs_as_plain_python_with_the_compiled_runs_champion(tmp_path, cli) -> None:
    """T46-A03: ``NUMBA_DISABLE_JIT=1 neurohover evolve`` (ne, cma; build-policies, reproduce's evolve units) was a traceback
    from sim/lanes.py's queue. Its champion is the compiled run's, its returns the same to rounding (the compiled kernel
    contracts some ``a*b + c`` into FMAs, plain Python does not)."""
    args = ("evolve", "--task", "ghh08", "--budget", "10", "--episode-steps", "5", "--validation-episodes", "1")
    run = _neurohover(*args, "--out", str(tmp_path / "python.json"), env={"NUMBA_DISABLE_JIT": "1"})
    assert run.returncode == 0 and "Traceback" not in run.stderr, run.stderr[-2000:]
    rc, _, err = cli(*args, "--out", str(tmp_path / "compiled.json"))
    assert rc == 0, err
    python, compiled = (json.loads((tmp_path / f"{name}.json").read_text()) for name in ("python", "compiled"))
    assert python["genome"] == compiled["genome"] and python["episodes"] == compiled["episodes"] == 50
    for key in ("champion_return", "validation_return"):
        assert python[key] == pytest.approx(compiled[key], rel=1e-12), key


def test_a03_the_pure_python_fma_rounds_once_and_the_queue_counts() -> None:
    from neurohover.sim.lanes import _python_fetch_add
    from neurohover.sim.packed import _python_fma

    assert _python_fma(1 + 2**-52, 1 - 2**-52, -1.0) == -(2.0**-104)  # a*b + c rounded twice is 0.0
    assert _python_fma(1e308, 10.0, -1e308) == math.inf and _python_fma(-1e308, 10.0, 0.0) == -math.inf  # past the largest float
    assert _python_fma(1e-200, 1e-200, 1.0) == 1.0 and _python_fma(1e300, 1e-300, -1.0) == pytest.approx(1e300 * 1e-300 - 1.0)
    assert str(_python_fma(-0.0, 1.0, -0.0)) == "-0.0" and str(_python_fma(2.0, 3.0, -6.0)) == "0.0"
    counter = np.array([5], dtype=np.int64)
    assert _python_fetch_add(counter, 1) == 5 and counter[0] == 6 and _python_fetch_add(counter, -1) == 6 and counter[0] == 5
