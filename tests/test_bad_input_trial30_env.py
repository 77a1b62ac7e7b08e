"""Bad-input trial 30, T30-A01: with PYTHONOPTIMIZE=2 (python -OO) every command, ``--version`` too, was a traceback:
pycma, imported with neurohover, reads its own docstrings, which -OO strips, and so do the commands' help texts. The
command line refuses the setting by name; pycma is imported where a CMA optimiser is made, with one message."""

from __future__ import annotations

import os
import subprocess
import sys

OO = {**os.environ, "PYTHONOPTIMIZE": "2"}


def test_the_command_line_refuses_python_oo_by_name() -> None:
    run = subprocess.run([sys.executable, "-m", "neurohover", "--version"], env=OO, capture_output=True, text=True, timeout=120)
    assert run.returncode == 2 and "Traceback" not in run.stderr, run.stderr
    assert run.stderr.strip() == (
        "neurohover: error: PYTHONOPTIMIZE=2 (python -OO) is not allowed: it strips the docstrings neurohover's help and pycma read; "
        "unset it, or set it to 1"
    )


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
