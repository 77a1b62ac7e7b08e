"""neurohover: generalized helicopter hovering (Koppejan & Whiteson 2011), fast and faithful.

Data flows one way: task family -> MDP -> batched rollouts of policies -> returns and flight data
-> evolution / model learning -> agents -> experiments.
"""

from __future__ import annotations

import importlib.metadata

from .errors import NeurohoverError
from .evaluate import DangerousState, Evaluation, PolicyTable, Safeguard, evaluate, evaluate_jobs
from .flightdata import FlightData
from .policies import Policy, baseline_policy, load_policy, prototype, save_policy
from .tasks import FGHH, GHH08, GHH09, MDP, Drift, Sensor, get_task_family

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
