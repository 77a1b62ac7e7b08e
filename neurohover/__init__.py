"""neurohover: generalized helicopter hovering (Koppejan & Whiteson 2011), fast and faithful.

Data flows one way: task family -> MDP -> batched rollouts of policies -> returns and flight data
-> evolution / model learning -> agents -> experiments.
"""

from __future__ import annotations

import importlib.metadata
import os
import sys


def _interrupted(kind, value, tb) -> None:
    if issubclass(kind, KeyboardInterrupt):  # Ctrl-C or SIGTERM while NumPy and numba import, before main() can catch it
        terminated = issubclass(kind, Terminated)
        print(f"neurohover: {'terminated' if terminated else 'interrupted'}", file=sys.stderr, flush=True)
        os._exit(143 if terminated else 130)  # as main() ends them (Python would end by the signal itself)
    else:
        sys.__excepthook__(kind, value, tb)


from .command import running_as_command  # noqa: E402  (stdlib only: before NumPy and numba import)
from .errors import Terminated, raise_terminated  # noqa: E402

if running_as_command():
    import signal

    sys.excepthook = _interrupted
    signal.signal(signal.SIGTERM, raise_terminated)  # from the first import on, SIGTERM ends the command as Ctrl-C does (fourth trial)

from .errors import NeurohoverError  # noqa: E402


def _whole_at_least_1(value: str) -> bool:
    return value.strip().isascii() and value.strip().isdigit() and int(value) >= 1


#: The numba variables our docs name, read by numba as it imports: each one's test and what it allows. A value numba
#: cannot parse was its warning with a traceback, then its default (tenth trial: NUMBA_NUM_THREADS; eleventh: CUDASIM).
_NUMBA_VARIABLES = {
    "NUMBA_NUM_THREADS": (_whole_at_least_1, "give a whole number >= 1 (numba's threads), or unset it"),
    "NUMBA_ENABLE_CUDASIM": (lambda value: value.strip() in ("0", "1"), "give 0 or 1 (1: numba's CUDA simulator stands in for a GPU), or unset it"),
}


def _check_numba_variables() -> None:
    """The numba variables of :data:`_NUMBA_VARIABLES` set in the environment, each refused by name where it does not
    pass its test (the command line's exit 2, a NeurohoverError on import): 0 threads or less was numba's traceback
    from every command, --help too, and other text its warning, then its default."""
    for name, (allowed, what) in _NUMBA_VARIABLES.items():
        value = os.environ.get(name)
        if value is None or allowed(value):
            continue
        message = f"environment variable {name}={value!r:.40} is not allowed: {what}"
        if running_as_command():
            print(f"neurohover: error: {message}", file=sys.stderr, flush=True)
            sys.exit(2)
        raise NeurohoverError(message)


_check_numba_variables()

from .evaluate import DangerousState, Evaluation, PolicyTable, Safeguard, evaluate, evaluate_jobs  # noqa: E402
from .flightdata import FlightData  # noqa: E402
from .policies import Policy, baseline_policy, load_policy, prototype, save_policy  # noqa: E402
from .tasks import FGHH, GHH08, GHH09, MDP, Drift, Sensor, get_task_family  # noqa: E402

try:
    __version__ = importlib.metadata.version("neurohover")  # one source of truth: pyproject.toml, as installed
except importlib.metadata.PackageNotFoundError:  # a source tree on sys.path that was never installed
    __version__ = "0+unknown"

__all__ = [
    "FGHH",
    "GHH08",
    "GHH09",
    "MDP",
    "Sensor",
    "Drift",
    "Evaluation",
    "FlightData",
    "NeurohoverError",
    "Policy",
    "DangerousState",
    "PolicyTable",
    "Safeguard",
    "baseline_policy",
    "evaluate",
    "evaluate_jobs",
    "get_task_family",
    "load_policy",
    "prototype",
    "save_policy",
]

from . import envs as _envs  # noqa: E402,F401  (registers the Gymnasium environments)
