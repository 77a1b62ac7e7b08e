"""Whether this process is the ``neurohover`` command itself (its script, or ``python -m neurohover``).

What only the command may do to its process (its signal handling at import and at exit) asks this, so that a
program that imports neurohover, or calls ``neurohover.cli.main`` in-process, keeps its own signals.
"""

from __future__ import annotations

import os
import sys


def running_as_command() -> bool:
    """This process is the ``neurohover`` command (its script, or ``python -m neurohover``), not a program importing us."""
    argv = list(getattr(sys, "orig_argv", ()))
    return (argv[argv.index("-m") + 1 : argv.index("-m") + 2] == ["neurohover"] if "-m" in argv else False) or (
        os.path.basename(sys.argv[0] if sys.argv else "") == "neurohover"
    )
