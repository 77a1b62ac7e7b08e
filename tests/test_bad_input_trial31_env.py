"""Bad-input trial 31 (31a), the environment and the locale: T31-A01 (characters the plot font lacks leaked matplotlib's
"Glyph ... missing" UserWarnings), T31-A05 (under an ASCII locale a config's non-ASCII path was "no such directory", with an
unquoted suggested command), T31-A06 (NUMBA_DISABLE_JIT=1 leaked the RNG's uint64 overflow RuntimeWarnings, a traceback under
PYTHONWARNINGS=error), T31-A07 (a wind of -0.0 made another MDP label, so --resume called the same run "a different run"),
and the borderline note: under NUMBA_NUM_THREADS the --threads range names the variable that limits it."""

from __future__ import annotations

import os
import subprocess
import sys


def _neurohover(*args: str, env: dict[str, str] | None = None, cwd=None) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "neurohover", *args], env={**os.environ, **(env or {})}, cwd=cwd, capture_output=True, text=True, timeout=120)


def test_a06_the_pure_python_kernel_wraps_its_uint64_arithmetic_silently() -> None:
    """T31-A06: NUMBA_DISABLE_JIT=1 (numba's documented pure-Python switch) printed "overflow encountered" from sim/rng.py's
    SplitMix64 and xoshiro256**, whose uint64 products wrap on purpose; under PYTHONWARNINGS=error ``fly`` was a traceback."""
    run = _neurohover("fly", "--task", "ghh08", "--episodes", "1", env={"NUMBA_DISABLE_JIT": "1", "PYTHONWARNINGS": "error"})
    assert run.returncode == 0 and "Traceback" not in run.stderr, run.stderr[-2000:]
    assert "overflow" not in run.stderr and "RuntimeWarning" not in run.stderr, run.stderr[-2000:]
    assert "mean_return: -962.946" in run.stdout, run.stdout  # the compiled kernel's return: the same streams


def test_a06_the_compiled_streams_are_still_numbas() -> None:
    from numba.core.registry import CPUDispatcher

    from neurohover.sim import rng

    assert all(isinstance(f, CPUDispatcher) for f in (rng.splitmix64, rng.seed_stream, rng.next_u64))
