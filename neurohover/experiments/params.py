"""Typed unit params, one frozen dataclass per unit kind (what a unit's runner reads).

The planner writes a unit's params as plain data (the store keeps them beside its result); its
runner reads them through :func:`unit_params` into these classes, which refuse a key they do not
declare (tests/test_experiment_settings.py parses every planned unit of every shipped config, so the
planner and these declarations cannot drift apart). Optional keys the planner leaves out are None.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import MISSING, dataclass, field, fields
from typing import Any

from ..errors import NeurohoverError, brief, finite_real, unknown_keys, whole_number
from ..evolution.config import MAX_BUDGET
from ..evolution.seeding import MAX_SEED
from ..models.lr import LEGACY_NOISE_ESTIMATE
from ..models.model import LEGACY_MODEL_SUBSTEPS
from .checks import MAX_EPISODES, MAX_STEPS, choice, resampling


def _whole(low: int, high: int | None = None, high_text: str | None = None) -> Callable[[object], tuple[bool, str]]:
    """A check (as :mod:`.checks` writes them) of a whole number in ``low..high`` (``high_text`` writes ``high``);
    NumPy integers too, as :func:`unit_params` takes them."""
    allowed = f"an integer >= {low}" if high is None else f"an integer in {low}..{high_text or high}"
    return lambda v: (whole_number(v) and low <= v and (high is None or v <= high), allowed)


def _target(t: object) -> tuple[bool, str]:
    """An evolution unit's target: ``{"kind": "mdp", "mdp": {...}}`` or ``{"kind": "family", "task": ...[, ...]}``
    (what the MDP and the family are made of is checked where they are read)."""
    allowed = 'a table {"kind": "mdp", "mdp": {an MDP\'s table}} or {"kind": "family", "task": NAME[, "sigma", "sensor", "drift"]}'
    if not isinstance(t, dict):
        return False, allowed
    if t.get("kind") == "mdp":
        return set(t) == {"kind", "mdp"} and isinstance(t["mdp"], dict), allowed
    return t.get("kind") == "family" and "task" in t, allowed


def checked(check: Callable[[object], tuple[bool, str]], default: Any = MISSING) -> Any:
    """A params field whose value :func:`checked_unit_params` also checks with ``check`` (a :mod:`.checks`-style
    ``value -> (ok, allowed)``), beside its annotation's types."""
    return field(default=default, metadata={"check": check})


@dataclass(frozen=True, kw_only=True)
class EvolveParams:
    """One evolution run: ``target`` is ``{"kind": "mdp", "mdp": ...}`` or ``{"kind": "family", "task", "sigma"[, "sensor"]}``;
    ``budget`` 0: no budget, the plateau stop (the configs' ``policy_budget`` and ``generic_budget`` 0)."""

    target: dict = checked(_target)
    topology: str
    prototype: str | dict
    resampling: str = checked(resampling())
    budget: int = checked(_whole(0, MAX_BUDGET))
    optimiser: dict
    n_steps: int = checked(_whole(1, MAX_STEPS))
    validation_episodes: int = checked(_whole(0, MAX_EPISODES))
    history_points: int = checked(_whole(2), 300)
    validation_mdps: str | None = checked(choice(None, "test"), None)
    validation_seed: int | None = checked(lambda v: (v is None or _whole(0, MAX_SEED)(v)[0], "None or an integer in 0..2**63-1"), None)
    champion_reevaluation: int = checked(_whole(0, MAX_EPISODES), 0)  # fresh episodes that choose the champion again among the last parents (0: not)
    seed: int = checked(_whole(0, MAX_SEED, "2**63-1"))


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
        names = str(f.type).split(" | ")
        if value is not None and {"int", "float"} & set(names) and not _of_types(value, names):
            raise NeurohoverError(f"a {kind!r} unit's params: {f.name} = {brief(value)} is not allowed: give {_types_text(names)}")
    return cls(**params)


#: An annotation's type name -> its test and what it allows (a params field's value is one of the types its annotation
#: names): read by :func:`unit_params` for the number fields and by :func:`checked_unit_params` for every field.
_TYPES: dict[str, tuple[Callable[[object], bool], str]] = {
    "int": (whole_number, "a whole number"),
    "float": (finite_real, "a finite real number"),
    "str": (lambda v: isinstance(v, str), "text"),
    "dict": (lambda v: isinstance(v, dict), "a table (dict)"),
    "list": (lambda v: isinstance(v, list), "a list"),
    "bool": (lambda v: isinstance(v, bool), "true or false"),
    "None": (lambda v: v is None, "None"),
}


def checked_unit_params(kind: str, params: dict, key: str) -> Any:
    """The params of unit ``key`` of ``kind`` as its typed params (:func:`unit_params`), each value checked against its
    field's annotation (None only where it allows None) and the field's own check: what :func:`~.units.run_unit` reads,
    so that a unit edited by hand is refused by unit and param as the config checks refuse a planned one's settings
    (target None was a TypeError, kind 'bogus' flew as a family run, history_points -1 NumPy's error; T44-B11, T44-B12)."""
    try:
        typed = unit_params(kind, params)
    except NeurohoverError as err:
        raise NeurohoverError(f"unit {brief(key)}: {err}") from None
    for f in fields(typed):
        value = getattr(typed, f.name)
        names = str(f.type).split(" | ")
        ok, allowed = f.metadata["check"](value) if "check" in f.metadata else (True, "")
        if not _of_types(value, names) or not ok:
            allowed = allowed or _types_text(names)
            raise NeurohoverError(f"unit {brief(key)}: its param {f.name} = {brief(value)} is not allowed: give {allowed}")
    return typed


def _of_types(value: object, names: list[str]) -> bool:
    """Whether ``value`` is of one of the types an annotation ``names`` (:data:`_TYPES`)."""
    return any(_TYPES[n][0](value) for n in names)


def _types_text(names: list[str]) -> str:
    """What an annotation of the types ``names`` allows, in words ("a whole number or None")."""
    return " or ".join(_TYPES[n][1] for n in names)
