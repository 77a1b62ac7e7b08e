"""Typed unit params, one frozen dataclass per unit kind (what a unit's runner reads).

The planner writes a unit's params as plain data (the store keeps them beside its result); its
runner reads them through :func:`unit_params` into these classes, which refuse a key they do not
declare (tests/test_experiment_settings.py parses every planned unit of every shipped config, so the
planner and these declarations cannot drift apart). Optional keys the planner leaves out are None.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import MISSING, dataclass, fields
from typing import Any

from ..errors import NeurohoverError, brief, finite_real, unknown_keys, whole_number
from ..models.lr import LEGACY_NOISE_ESTIMATE
from ..models.model import LEGACY_MODEL_SUBSTEPS


@dataclass(frozen=True, kw_only=True)
class EvolveParams:
    """One evolution run: ``target`` is ``{"kind": "mdp", "mdp": ...}`` or ``{"kind": "family", "task", "sigma"[, "sensor"]}``."""

    target: dict
    topology: str
    prototype: str | dict
    resampling: str
    budget: int
    optimiser: dict
    n_steps: int
    validation_episodes: int
    history_points: int = 300
    validation_mdps: str | None = None
    validation_seed: int | None = None
    champion_reevaluation: int = 0  # fresh episodes that choose the champion again among the last parents (0: not)
    seed: int


@dataclass(frozen=True, kw_only=True)
class RobustnessParams:
    """One champion (or a policy set's specialised policy) flown on every training MDP (Table 3)."""

    policy: dict
    source: str
    own: int
    mdps: list
    episodes: int
    n_steps: int
    seed: int


@dataclass(frozen=True, kw_only=True)
class SafetyParams:
    """The specialised policies flown on every training MDP, to find the safe ones."""

    policies: list
    mdps: list
    episodes: int
    n_steps: int
    seed: int


@dataclass(frozen=True, kw_only=True)
class ModelParams:
    """One learned model of one MDP, and the policy evolved on it."""

    method: str
    mdp: dict
    generic: dict
    n_steps: int
    model_budget: int
    ec_meno_budget: int
    ec_mer_episodes: int
    policy_budget: int
    prototype: str
    test_episodes: int
    data_episodes: int = 1  # episodes of the generic's flight data the model learns from
    d_u: str = "keep"  # LR as the authors fitted it, each choice apart (neurohover.agents.model_based.ModelEvolution)
    noise: str = LEGACY_NOISE_ESTIMATE  # absent: a unit stored before the default became "rms"
    model_policy: str = "ours"
    authors_generations: int = 500
    model_substeps: int = LEGACY_MODEL_SUBSTEPS  # the policy evolves on the model in one step or the simulator's 10 substeps (absent: 1)
    exact_checks: bool = False  # also check the model and its policy against exact sensors (the MDP has a sensor model)
    seed: int


@dataclass(frozen=True, kw_only=True)
class TestRunParams:
    """One test run of an agent on one MDP; ``hybrid`` / ``agent_settings`` are the agent's own settings (read by its spec)."""

    task: str
    sigma: float | None
    episodes: int
    n_steps: int
    model_budget: int
    predict_episodes: int
    max_learning_episodes: int
    agent: str
    group: str
    mdp: dict
    policies: dict
    estimator: str = "ols"
    wind_model: str = "none"
    d_u: str = "keep"  # LR as the authors fitted it, each choice apart (neurohover.agents.model_based.ModelEvolution)
    noise: str = LEGACY_NOISE_ESTIMATE  # absent: a unit stored before the default became "rms"
    model_policy: str = "ours"
    authors_generations: int = 500
    model_substeps: int = LEGACY_MODEL_SUBSTEPS  # the agents evolve on their models in one step or 10 substeps (absent: 1)
    sensor: dict | None = None
    hybrid: dict | None = None
    agent_settings: dict | None = None
    seed: int


PARAMS: dict[str, type] = {
    "evolve": EvolveParams,
    "robustness": RobustnessParams,
    "safety": SafetyParams,
    "model": ModelParams,
    "test_run": TestRunParams,
}


def unit_params(kind: str, params: dict) -> Any:
    """The params of a unit of ``kind`` as its typed params.

    Raises
    ------
    NeurohoverError
        For a kind of no params class, params that are no dict, or params that hold a key the class does not
        declare or lack one it needs: all of them named in one message (the missing ones were a TypeError of
        ``__init__``; fourteenth trial, T14-23), and for a number param of another type (an int param given 5.5 or
        np.timedelta64; seventeenth trial, T17-1).
    """
    cls = PARAMS.get(kind) if isinstance(kind, str) else None
    if cls is None:
        raise NeurohoverError(f"unit kind {brief(kind)} is not allowed here: give one of {', '.join(PARAMS)}")
    if not isinstance(params, dict):
        raise NeurohoverError(f"a {kind!r} unit's params = {brief(params)} are not allowed: give a dict of {cls.__name__}'s fields")
    declared = fields(cls)
    unknown = unknown_keys(params, {f.name for f in declared})
    missing = [f.name for f in declared if f.name not in params and f.default is MISSING and f.default_factory is MISSING]
    if unknown or missing:
        wrong = [f"hold {unknown}, which {cls.__name__} does not declare"] if unknown else []
        wrong += [f"lack {', '.join(missing)}, which {cls.__name__} needs"] if missing else []
        raise NeurohoverError(f"a {kind!r} unit's params {' and '.join(wrong)}")
    for f in declared:  # a number's type, before a runner uses it (np.timedelta64 passed as an int into NumPy's TypeError; T17-1)
        value = params.get(f.name)  # None: left to the runner, as before (a structure-only check passes None everywhere)
        number = _NUMBERS.get(str(f.type))
        if value is not None and number is not None and not number[0](value):
            raise NeurohoverError(f"a {kind!r} unit's params: {f.name} = {brief(value)} is not allowed: give {number[1]}")
    return cls(**params)


# A number field's annotation -> its test and what it allows.
_NUMBERS: dict[str, tuple[Callable[[object], bool], str]] = {
    "int": (whole_number, "a whole number"),
    "int | None": (whole_number, "a whole number or None"),
    "float": (finite_real, "a finite real number"),
    "float | None": (finite_real, "a finite real number or None"),
}
