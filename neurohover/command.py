"""Whether this process is the ``neurohover`` command itself (its script, or ``python -m neurohover``).

What only the command may do to its process (its signal handling at import and at exit) asks this, so that a
program that imports neurohover, or calls ``neurohover.cli.main`` in-process, keeps its own signals.
"""

from __future__ import annotations

import os
import sys


def running_as_command() -> bool:
    """This process is the ``neurohover`` command (its script, or ``python -m neurohover``), not a program importing us
    nor a worker process the command spawned (which is handed the command's ``sys.argv``, but whose signals are its pool's:
    :mod:`neurohover.procs`; a worker ended by SIGTERM as it imported printed "neurohover: terminated", T26-A01)."""
    argv = list(getattr(sys, "orig_argv", ()))
    if "--multiprocessing-fork" in argv:  # multiprocessing's spawned child (spawn.is_forking)
        return False
    return (argv[argv.index("-m") + 1 : argv.index("-m") + 2] == ["neurohover"] if "-m" in argv else False) or (
        os.path.basename(sys.argv[0] if sys.argv else "") == "neurohover"
    )
