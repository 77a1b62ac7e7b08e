"""Typed results of the experiment units, one frozen dataclass per unit kind, and the parser of unit keys.

A unit (:mod:`~neurohover.experiments.units`) builds its result as one of these types and the
store keeps its :meth:`~UnitResult.to_dict`; the report and the export read stored results back
with :func:`result_from_dict`. ``to_dict`` writes exactly the JSON the store has always held
(same keys in the same order, same values), so ``result_from_dict(kind, d).to_dict() == d`` for
every stored result, and new results are stored as before.

Conventions of the stored JSON, kept by the types:

* numbers that may be non-finite (returns) are :data:`Num`: a float, or one of the strings
  ``"nan"``, ``"inf"``, ``"-inf"`` (:func:`num`); ``float()`` reads both;
* lists become tuples in the types (so results are immutable) and lists again in ``to_dict``;
* wall-clock measurements are in a ``timing`` part, which takes no part in ``==``: two runs of
  the same unit give equal results;
* keys that older stores lack are optional fields, None when absent, and stay absent.

:class:`UnitKey` parses the unit keys of :mod:`~neurohover.experiments.plans` (stage, group, MDP,
repetition), in this one place.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np

from ..errors import NeurohoverError
from .keys import UnitKey  # re-exported: results are read by key
from .result_checks import KIND_CHECKS, evolve_inconsistency, model_inconsistency, robustness_inconsistency, run_inconsistency, seconds_problem

__all__ = [
    "DiagnosticResult",
    "EvolveResult",
    "EvolveTiming",
    "ModelResult",
    "ModelTiming",
    "Num",
    "RESULT_TYPES",
    "RobustnessResult",
    "SafetyResult",
    "StoredPolicy",
    "TestRunResult",
    "TestRunTiming",
    "UnitKey",
    "UnitResult",
    "num",
    "result_from_dict",
]

#: A JSON-safe float: finite values as floats, non-finite ones as ``"nan"``, ``"inf"`` or ``"-inf"``.
Num = float | str


def num(x: float) -> Num:
    """``x`` as a JSON-safe :data:`Num` (non-finite values as strings). Internal: called with a number that a run gave
    (README, Python API, What is public)."""
    x = float(x)
    return x if math.isfinite(x) else ("nan" if math.isnan(x) else ("inf" if x > 0 else "-inf"))


def _tuples(value: Any) -> Any:
    """Lists (nested) as tuples; anything else as it is."""
    return tuple(_tuples(v) for v in value) if isinstance(value, (list, tuple)) else value


def _lists(value: Any) -> Any:
    """Tuples (nested) as lists; anything else as it is."""
    return [_lists(v) for v in value] if isinstance(value, (list, tuple)) else value


class _Record:
    """``to_dict`` / ``from_dict`` for a frozen dataclass whose fields, in order, are its JSON keys.

    ``_NESTED`` names the fields that are records themselves; ``_OPTIONAL`` the keys older stores
    lack (None: absent); ``_RAW`` the fields kept exactly as JSON gives them (no tuple conversion)."""

    _NESTED: ClassVar[dict[str, type[_Record]]] = {}
    _OPTIONAL: ClassVar[tuple[str, ...]] = ()
    _RAW: ClassVar[tuple[str, ...]] = ()

    def __post_init__(self) -> None:
        for f in dataclasses.fields(self):  # type: ignore[arg-type]
            value = getattr(self, f.name)
            if f.name in self._NESTED:
                if value is None and f.name in self._OPTIONAL:
                    continue
                if not isinstance(value, self._NESTED[f.name]):
                    raise NeurohoverError(f"{type(self).__name__}.{f.name} must be a {self._NESTED[f.name].__name__}, got {type(value).__name__}")
            elif f.name not in self._RAW:
                object.__setattr__(self, f.name, _tuples(value))

    def to_dict(self) -> dict:
        """The JSON dict of this record, as the results store holds it.

        Returns
        -------
        dict
            Keys in field order (optional ones left out when None), tuples as lists, parts as dicts.
        """
        out = {}
        for f in dataclasses.fields(self):  # type: ignore[arg-type]
            value = getattr(self, f.name)
            if value is None and f.name in self._OPTIONAL:
                continue
            out[f.name] = value.to_dict() if f.name in self._NESTED else value if f.name in self._RAW else _lists(value)
        return out

    @classmethod
    def from_dict(cls, d: dict, what: str | None = None):
        """Read a dict written by :meth:`to_dict` (``from_dict(d).to_dict() == d``).

        Parameters
        ----------
        d : dict
            The stored JSON object.
        what : str, optional
            What it is, for error messages (default: the class name).

        Raises
        ------
        NeurohoverError
            ``d`` is not a dict, lacks a key, or has a key this type does not know.
        """
        what = what or cls.__name__
        if not isinstance(d, dict):
            raise NeurohoverError(f"{what}: expected a JSON object, got {type(d).__name__}")
        names = [f.name for f in dataclasses.fields(cls)]  # type: ignore[arg-type]
        missing = [n for n in names if n not in d and n not in cls._OPTIONAL]
        unknown = [k for k in d if k not in names]
        if missing or unknown:
            raise NeurohoverError(
                f"{what}: "
                + "; ".join(
                    ([f"missing key(s) {', '.join(missing)}"] if missing else [])
                    + ([f"unknown key(s) {', '.join(unknown)} (written by another neurohover version?)"] if unknown else [])
                )
            )
        for f in dataclasses.fields(cls):  # type: ignore[arg-type]
            check = KIND_CHECKS.get(str(f.type))
            if check is not None and f.name in d and not check(d[f.name]):  # a score "x" was a ValueError in report (sixth trial)
                raise NeurohoverError(f"{what}: {f.name} = {d[f.name]!r:.40} is not {f.type}")
        values = {n: cls._NESTED[n].from_dict(d[n], f"{what}.{n}") if n in cls._NESTED and n in d else d.get(n) for n in names}
        return cls(**values)

    def columns(self) -> dict[str, Any]:
        """Flat columns (for CSV), one plain value each: :func:`flat_cells`'s rules."""
        out: dict[str, Any] = {}
        for name, value in self.to_dict().items():
            flat_cells(name, value, out)
        return out


# --------------------------------------------------------------------------------- parts


SHORT_LIST = 8  # lists up to this long (an MDP's parameters, the safe policies) get a column per entry


def _plain(value) -> bool:
    return isinstance(value, (int, float, str, bool)) or value is None


def flat_cells(prefix: str, value, out: dict) -> None:
    """``value`` as plain cells named from ``prefix``, for a CSV row (``neurohover results``).

    A dict becomes dotted columns (``target.mdp.label``); a list of at most ``SHORT_LIST`` plain
    values one column per entry (``.0``, ``.1``); a longer list of numbers its count and mean
    (``.n``, ``.mean``; flags: ``.n``, ``.sum``); any other list (a history, a genome, episodes
    of several MDPs) its count alone. The store's JSON keeps every list in full.
    """
    if isinstance(value, dict):
        for k, v in value.items():
            flat_cells(f"{prefix}.{k}" if prefix else str(k), v, out)
    elif isinstance(value, (list, tuple)):
        if all(_plain(v) for v in value) and len(value) <= SHORT_LIST:
            for i, v in enumerate(value):
                out[f"{prefix}.{i}"] = v
            return
        out[f"{prefix}.n"] = len(value)
        if prefix.endswith("genome") or not all(isinstance(v, (int, float)) for v in value):
            return  # a genome's weights, or nested lists: no summary means anything
        if all(isinstance(v, bool) for v in value):
            out[f"{prefix}.sum"] = sum(value)
        else:
            out[f"{prefix}.mean"] = sum(value) / len(value)
    else:
        out[prefix] = value


@dataclass(frozen=True)
class StoredPolicy(_Record):
    """A policy as results and params hold it: ``{"topology", "genome"}``.

    Attributes
    ----------
    topology : str
    genome : tuple of float
    """

    topology: str
    genome: tuple[float, ...]

    @classmethod
    def of(cls, policy) -> StoredPolicy:
        """The stored form of a :class:`~neurohover.policies.Policy`."""
        return cls(policy.topology, tuple(float(x) for x in policy.genome))

    def policy(self):
        """The :class:`~neurohover.policies.Policy` (no metadata)."""
        from ..policies import Policy

        return Policy(self.topology, np.array(self.genome, dtype=float))


class _Timing(_Record):
    """Wall-clock seconds, each a finite number >= 0 (a test run's seconds -5 was exported; T22-09) and at most 100 years
    (1e300 was taken; T24-07), each part of another at most it (result_checks: a test run's offline seconds, T23-14; an
    evolution run's kernel seconds, T24-09)."""

    def __post_init__(self) -> None:
        super().__post_init__()
        problem = seconds_problem(self)
        if problem:
            raise NeurohoverError(problem)


@dataclass(frozen=True)
class EvolveTiming(_Timing):
    """Wall-clock seconds of an evolution run, and of its kernel calls."""

    seconds: float
    kernel_seconds: float


@dataclass(frozen=True)
class ModelTiming(_Timing):
    """Wall-clock seconds to learn the model and to evolve the policy on it."""

    learn_seconds: float
    evolve_seconds: float


@dataclass(frozen=True)
class TestRunTiming(_Timing):
    """Wall-clock seconds of a test run, and of the agent's work between episodes."""

    __test__ = False  # not a pytest test class

    seconds: float
    offline_seconds: float


# --------------------------------------------------------------------------------- unit results


@dataclass(frozen=True, kw_only=True)
class Reevaluation(_Record):
    """The champion of an ``evolve`` unit chosen again (:func:`neurohover.evolution.evolve.reevaluated_champion`).

    Attributes
    ----------
    champion : StoredPolicy
        The last generation's selected parent of best mean fitness over ``episodes`` fresh episodes.
    parent : int
        Its index among the candidates (the last parents, or the run's best generation champions).
    episodes : int
        Fresh episodes every parent flew.
    estimate : Num
        Its mean fitness over them (on the run's scale).
    validation, validation_crashed : tuple or None
        It flown as the run's champion is validated (None: no validation asked for).
    """

    _NESTED: ClassVar[dict[str, type[_Record]]] = {"champion": StoredPolicy}
    _OPTIONAL: ClassVar[tuple[str, ...]] = ("validation", "validation_crashed")

    champion: StoredPolicy
    parent: int
    episodes: int
    estimate: Num
    validation: tuple[Num, ...] | None = None
    validation_crashed: tuple[bool, ...] | None = None


@dataclass(frozen=True, kw_only=True)
class EvolveResult(_Record):
    """Result of an ``evolve`` unit: one evolution run (paper Section 3.1 / 5).

    Attributes
    ----------
    champion : StoredPolicy
    champion_return : Num
        The champion's fitness estimate at the end of the run.
    episodes, evaluations, generations : int
    stop_reason : str
    champion_crashed : bool or None
        Whether the final champion's own evaluation crashed (None: a store written before it was recorded).
    history : tuple of (int, Num)
        (episodes, champion return) records, subsampled.
    validation : tuple of Num or None
        Returns of the champion on fresh validation episodes (None: no validation asked for).
    validation_crashed : tuple of bool or None
        Whether each validation episode crashed (None: not recorded, stores before FGHH's paper scale).
    fitness : str or None
        The scale of ``champion_return`` and ``history`` (:mod:`neurohover.evolution.fitness`):
        ``inv-log-error`` or ``return`` (None: raw returns, as every run before the scale existed).
    reevaluated, reevaluated_best_ever : Reevaluation or None
        The champion chosen again on fresh episodes among the last generation's parents, and among the run's best
        generation champions (the evolution setting ``champion_reevaluation``; None: not asked for).
    timing : EvolveTiming
        Wall-clock; not part of ``==``.
    """

    _NESTED: ClassVar[dict[str, type[_Record]]] = {
        "champion": StoredPolicy,
        "timing": EvolveTiming,
        "reevaluated": Reevaluation,
        "reevaluated_best_ever": Reevaluation,
    }
    _OPTIONAL: ClassVar[tuple[str, ...]] = ("champion_crashed", "validation", "validation_crashed", "fitness", "reevaluated", "reevaluated_best_ever")

    champion: StoredPolicy
    champion_return: Num
    episodes: int
    evaluations: int
    generations: int
    stop_reason: str
    champion_crashed: bool | None = None
    history: tuple[tuple[int, Num], ...]
    validation: tuple[Num, ...] | None = None
    validation_crashed: tuple[bool, ...] | None = None
    fitness: str | None = None
    reevaluated: Reevaluation | None = None
    reevaluated_best_ever: Reevaluation | None = None
    timing: EvolveTiming = field(compare=False)

    def __post_init__(self) -> None:
        super().__post_init__()
        problem = evolve_inconsistency(self)
        if problem:  # a hand-edited run (stop_reason 'bogus', a champion its history contradicts) was reported (T23-08)
            raise NeurohoverError(f"evolution run is inconsistent: {problem}")

    @property
    def final_score(self) -> float:
        """The run's score: mean validation return if validated, else the champion's return."""
        if self.validation is not None:
            return float(np.mean([float(x) for x in self.validation]))
        return float(self.champion_return)


@dataclass(frozen=True, kw_only=True)
class RobustnessResult(_Record):
    """Result of a ``robustness`` unit (Table 3): one policy flown on each of several MDPs.

    Attributes
    ----------
    returns : tuple of tuple of Num
        Per MDP, the return of each episode.
    crashes : tuple of int
        Per MDP, the crashed episodes.
    own : int
        Index of the MDP the policy was evolved on.
    """

    returns: tuple[tuple[Num, ...], ...]
    crashes: tuple[int, ...]
    own: int

    def __post_init__(self) -> None:
        super().__post_init__()
        problem = robustness_inconsistency(self)
        if problem:  # positive returns, more crashes than episodes were reported (T23-08)
            raise NeurohoverError(f"robustness result is inconsistent: {problem}")


@dataclass(frozen=True, kw_only=True)
class SafetyResult(_Record):
    """Result of a ``safety`` unit: the specialised policies' crash matrix and the safe ones.

    Attributes
    ----------
    crashes : tuple of tuple of int
        Crashed episodes of policy i on training MDP j.
    mean_returns : tuple of tuple of Num
        Mean return of policy i on training MDP j.
    safe : tuple of int
        Indices of the safe policies.
    """

    crashes: tuple[tuple[int, ...], ...]
    mean_returns: tuple[tuple[Num, ...], ...]
    safe: tuple[int, ...]


@dataclass(frozen=True, kw_only=True)
class ModelResult(_Record):
    """Result of a ``model`` unit (Table 4): learn a model, evolve a policy on it, test it.

    Attributes
    ----------
    method : str
        ``"lr"``, ``"lr-gls"``, ``"ec-meno"`` or ``"ec-mer"``.
    mdp : str
        Label of the true MDP.
    generic_return : Num
        Return of the generic policy's episode that gave the flight data.
    generic_crashed : bool
    model_params, model_noise_std : tuple of Num
        The learned model's 11 parameters and 6 noise standard deviations.
    predicted_return : Num
        The evolved champion's return on the model.
    test_returns : tuple of Num
        Returns of the evolved policy in the true MDP.
    test_mean : Num
    test_crashes : int
    policy_episodes : int
        Episodes the policy's evolution flew.
    timing : ModelTiming
        Wall-clock; not part of ``==``.
    own_one_step_error, exact_one_step_error : Num or None
        With exact checks (a sensor condition): the model's one-step error on the flight data it learned
        from, and on an episode of exact flight data of the generic policy in the true MDP.
    param_relative_errors : tuple of Num or None
        With exact checks: ``|learned - true| / |true|`` of the 11 dynamics parameters.
    exact_test_returns : tuple of Num or None
        With exact checks: the evolved policy in the true MDP with exact sensors (the same gusts as
        ``test_returns``, which it flew through the condition's sensors).
    exact_test_crashes : int or None
    test_w_sd : Num or None
        Standard deviation of the vertical body velocity w over every step of the test episodes: about
        0.03 m/s for a policy that hovers, about 1.5 for one whose collective loop oscillates (None: a
        unit stored before it was recorded, 2026-12-04).
    flown_substeps : int or None
        The substeps the policy evolved on the model in, where they differ from the unit's ``model_substeps``:
        1 for a model with an axis that has no ten-substep equivalent (``LearnedModel.flyable_substeps``).
    """

    _NESTED: ClassVar[dict[str, type[_Record]]] = {"timing": ModelTiming}
    _OPTIONAL: ClassVar[tuple[str, ...]] = (
        "own_one_step_error",
        "exact_one_step_error",
        "param_relative_errors",
        "exact_test_returns",
        "exact_test_crashes",
        "test_w_sd",
        "flown_substeps",
    )

    method: str
    mdp: str
    generic_return: Num
    generic_crashed: bool
    model_params: tuple[Num, ...]
    model_noise_std: tuple[Num, ...]
    predicted_return: Num
    test_returns: tuple[Num, ...]
    test_mean: Num
    test_crashes: int
    policy_episodes: int
    timing: ModelTiming = field(compare=False)
    own_one_step_error: Num | None = None
    exact_one_step_error: Num | None = None
    param_relative_errors: tuple[Num, ...] | None = None
    exact_test_returns: tuple[Num, ...] | None = None
    exact_test_crashes: int | None = None
    test_w_sd: Num | None = None
    flown_substeps: int | None = None

    def __post_init__(self) -> None:
        super().__post_init__()
        problem = model_inconsistency(self)
        if problem:  # model_params of 3 numbers, noise sds of -1.0 were reported (T25-10)
            raise NeurohoverError(f"model result is inconsistent: {problem}")


@dataclass(frozen=True, kw_only=True)
class TestRunResult(_Record):
    """Result of a ``test_run`` unit: one agent's episodes on one MDP it does not know.

    Attributes
    ----------
    agent : str
    mdp : str
        Label of the MDP.
    score : Num
        Cumulative return of the run.
    returns : tuple of Num
        Return of each episode.
    crash_episodes, safeguard_episodes : tuple of int
        Episodes that crashed, and episodes in which the safeguard fired.
    policy_changes : tuple of (int, str)
        (episode, policy) wherever the flown policy changed (episode 0 first).
    learning_episodes : int
        Episodes before the agent settled (see :func:`neurohover.agents.protocol.after_learning_start`).
    mean_return_after_learning : Num
    crash_steps : tuple of int or None
        The control step at which each crash episode ended, in the order of ``crash_episodes``
        (None: a store written before it was recorded).
    timing : TestRunTiming
        Wall-clock; not part of ``==``.
    """

    __test__ = False  # not a pytest test class
    _NESTED: ClassVar[dict[str, type[_Record]]] = {"timing": TestRunTiming}
    _OPTIONAL: ClassVar[tuple[str, ...]] = ("crash_steps",)

    agent: str
    mdp: str
    score: Num
    returns: tuple[Num, ...]
    crash_episodes: tuple[int, ...]
    safeguard_episodes: tuple[int, ...]
    policy_changes: tuple[tuple[int, str], ...]
    learning_episodes: int
    mean_return_after_learning: Num
    crash_steps: tuple[int, ...] | None = None
    timing: TestRunTiming = field(compare=False)

    def __post_init__(self) -> None:
        super().__post_init__()
        problem = run_inconsistency(self)
        if problem:  # a stored run with returns [] was a NumPy ValueError in report (seventh trial)
            raise NeurohoverError(f"test run of {self.agent} on {self.mdp} is inconsistent: {problem}")


@dataclass(frozen=True, kw_only=True)
class DiagnosticResult(_Record):
    """Result of a ``diagnostic`` unit (executor tests): the value and seed it was given, as given."""

    _RAW: ClassVar[tuple[str, ...]] = ("value", "seed")

    value: Any
    seed: Any


UnitResult = EvolveResult | RobustnessResult | SafetyResult | ModelResult | TestRunResult | DiagnosticResult

#: The result type of each unit kind.
RESULT_TYPES: dict[str, type[_Record]] = {
    "evolve": EvolveResult,
    "robustness": RobustnessResult,
    "safety": SafetyResult,
    "model": ModelResult,
    "test_run": TestRunResult,
    "diagnostic": DiagnosticResult,
}


def result_from_dict(kind: str, d: dict, key: str | None = None) -> UnitResult:
    """The typed result of a unit from its stored dict.

    Parameters
    ----------
    kind : str
        The unit's kind (a key of :data:`RESULT_TYPES`).
    d : dict
        The result as the store holds it.
    key : str, optional
        The unit's key, for error messages.

    Returns
    -------
    EvolveResult, RobustnessResult, SafetyResult, ModelResult, TestRunResult or DiagnosticResult

    Raises
    ------
    NeurohoverError
        An unknown kind, or a dict that is not a result of that kind.
    """
    return result_type(kind).from_dict(d, f"result of {kind} unit {key!r}" if key else None)


def result_type(kind: Any) -> type[_Record]:
    """The result class of a unit kind (:data:`RESULT_TYPES`), or NeurohoverError naming the kinds: the readers' check,
    which Store.put makes too (a unit of kind 'banana' was stored, then called damaged; T30-B03)."""
    cls = RESULT_TYPES.get(kind) if isinstance(kind, str) else None
    if cls is None:
        raise NeurohoverError(f"unknown unit kind {kind!r}: allowed {', '.join(RESULT_TYPES)}")
    return cls
