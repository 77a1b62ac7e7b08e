"""Bad-input trial 30, T30-A01: with PYTHONOPTIMIZE=2 (python -OO) every command, ``--version`` too, was a traceback:
pycma, imported with neurohover, reads its own docstrings, which -OO strips, and so do the commands' help texts. The
command line refuses the setting by name; pycma is imported where a CMA optimiser is made, with one message."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

OO = {**os.environ, "PYTHONOPTIMIZE": "2"}


@pytest.mark.slow
def test_the_command_line_refuses_python_oo_by_name() -> None:
    run = subprocess.run([sys.executable, "-m", "neurohover", "--version"], env=OO, capture_output=True, text=True, timeout=120)
    assert run.returncode == 2 and "Traceback" not in run.stderr, run.stderr
    assert run.stderr.strip() == (
        "neurohover: error: PYTHONOPTIMIZE=2 (python -OO) is not allowed: it strips the docstrings neurohover's help and pycma read; unset it, or set it to 1"
    )


@pytest.mark.slow
def test_the_library_imports_under_python_oo_and_names_pycma_where_it_is_needed() -> None:
    script = (
        "import numpy as np\n"
        "import neurohover as nh\n"
        "from neurohover.evolution.optimisers.cma import CMAES\n"
        "print(nh.get_task_family('ghh08').zero().label)\n"
        "try:\n"
        "    CMAES(np.zeros(40), popsize=4)\n"
        "except nh.NeurohoverError as err:\n"
        "    print(err)\n"
    )
    run = subprocess.run([sys.executable, "-c", script], env=OO, capture_output=True, text=True, timeout=120)
    assert run.returncode == 0 and "Traceback" not in run.stderr, run.stderr
    lines = run.stdout.splitlines()
    assert lines[0] == "ghh08/zero" and lines[1].startswith("the CMA optimisers need pycma, which cannot be imported with PYTHONOPTIMIZE=2"), run.stdout


@pytest.mark.slow
def test_the_cuda_simulator_does_not_warn_of_the_rngs_wraparound() -> None:
    """T30-A03: under NUMBA_ENABLE_CUDASIM=1 (which neurohover's --device cuda refusal suggests) every run printed 8 lines
    of "overflow encountered" from sim/rng.py: its uint64 arithmetic wraps on purpose, as on a GPU."""
    script = (
        "import json, warnings\n"
        "warnings.simplefilter('default')\n"
        "import neurohover as nh\n"
        "ev = nh.evaluate(nh.baseline_policy(), nh.get_task_family('ghh08').zero(), n_steps=3, seed=1, device='cuda')\n"
        "cpu = nh.evaluate(nh.baseline_policy(), nh.get_task_family('ghh08').zero(), n_steps=3, seed=1)\n"
        "print(json.dumps([ev.returns.ravel().tolist(), cpu.returns.ravel().tolist()]))\n"
    )
    env = {**os.environ, "NUMBA_ENABLE_CUDASIM": "1"}
    run = subprocess.run([sys.executable, "-c", script], env=env, capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stderr[-3000:]
    assert "overflow encountered" not in run.stderr and "RuntimeWarning" not in run.stderr, run.stderr[-2000:]
    import json

    gpu, cpu = json.loads(run.stdout.strip().splitlines()[-1])
    assert abs(gpu[0] - cpu[0]) <= 1e-9 * abs(cpu[0])
