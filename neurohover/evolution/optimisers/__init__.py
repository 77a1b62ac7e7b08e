"""Population optimisers by name: the registry that ``evolve``, ``build-policies``, experiment configs and the CLI read.

The paper's neuroevolution (``"ne"``: steady state on one MDP, generational with resampling or
selection races over a family) is the evolution run's own. Any other optimiser that asks a
generation of genomes and is told their returns is a **population optimiser**: every module of
this package that declares ``OPTIMISER_SPECS`` (a sequence of :class:`OptimiserSpec`) is found
here, so adding one is one new module plus its tests (``openai_es.py`` shows how). The run flies
each generation with fixed resampling, keeps on one MDP the best single return ever told as
champion, and over a task family the best estimate of the last generation.

An optimiser registered at run time instead (``OPTIMISERS["my-es"] = OptimiserSpec("my-es", ...)`` in a script) runs
the same; its champions record it as method and optimizer ``user:my-es`` (:func:`recorded_names`), which every process
reads (one without it registered too), while a record of a shipped optimiser's name is checked against the shipped spec.
Where the registry is used (:func:`optimiser_spec`: ``evolve``, an experiment config, a run's record) its entry must be
an :class:`OptimiserSpec` under its own name, a shipped name must hold its shipped spec (:data:`SHIPPED_SPECS`), and a
run-time name is one line of at most 64 letters, digits and ``._+-`` (what :data:`USER_NAME` reads back; not ``ne``
nor one of :data:`NE_METHODS`) whose label is its name: ``label`` is how a shipped optimiser names its method (``cma``
evolves by ``cma-es``), and a run-time optimiser's method is its name (T41-B02..B04). A bad entry is refused by name
where it is used, and no other run or policy file is the worse for it.
"""

from __future__ import annotations

import dataclasses
import importlib
import pkgutil
import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any

import numpy as np

from ...errors import NeurohoverError, brief, frozen_dataclass_class, refused_signature, registry_entry_problem, whole_number
from ...settings_checks import checked_settings, settings_defaults_problem, settings_from_dict

__all__ = [
    "NE",
    "NE_METHODS",
    "OPTIMISERS",
    "SHIPPED",
    "SHIPPED_SPECS",
    "USER_NAME",
    "OptimiserSpec",
    "entry_problem",
    "optimiser_names",
    "optimiser_spec",
    "population_settings",
    "recorded_names",
    "runtime_name",
    "usable_specs",
]

NE = "ne"  # the paper's neuroevolution: not a population optimiser of this registry
#: The methods of the paper's neuroevolution, which an evolution run tells from a population optimiser's by name: no
#: run-time optimiser's name (one named 'generational' was an AttributeError, 'steady-state' an AssertionError, T55-B08).
NE_METHODS = ("steady-state", "generational")


@dataclass(frozen=True)
class OptimiserSpec:
    """One population optimiser.

    Attributes
    ----------
    name : str
        What ``evolve(optimizer=...)``, ``--optimizer`` and a config's ``optimizer.name`` say.
    summary : str
        One line for help texts.
    settings : type
        A frozen dataclass of its settings, with defaults of plain JSON values; its ``__post_init__`` raises
        ValueError on a bad value (a value given that is not its field's type, where that is int, float, bool or
        text, or that is no finite number, is refused before the optimiser is made).
    make : callable
        ``make(prototype genome, settings, seed)`` -> an optimiser with ``ask``, ``tell(fitness, info)``,
        ``stop``, ``champion_genome``, ``champion_return``, ``state_dict`` and a
        ``from_state_dict`` classmethod (:class:`~neurohover.evolution.common.Optimiser`).
    min_genes : int
        The shortest genome it can search.
    stop_reason : str
        What a run records when the optimiser's own ``stop()`` (a bool) ends it: one printable line, not ``'budget'``.
    label : str
        The ``method`` written in a champion's metadata (default: the name).
    stops_itself : bool
        Whether ``stop()`` can ever fire; an optimiser without a criterion of its own needs a budget.
    """

    name: str
    summary: str
    settings: type
    make: Callable[[np.ndarray, Any, int], Any]
    min_genes: int = 1
    stop_reason: str = "optimiser-stop"
    label: str = ""
    stops_itself: bool = True

    def __post_init__(self) -> None:
        if not self.label:
            object.__setattr__(self, "label", self.name)


def _discover() -> dict[str, OptimiserSpec]:
    specs: dict[str, OptimiserSpec] = {}
    for module in sorted(m.name for m in pkgutil.iter_modules(__path__)):
        for spec in getattr(importlib.import_module(f"{__name__}.{module}"), "OPTIMISER_SPECS", ()):
            if spec.name in specs or spec.name == NE:
                raise RuntimeError(f"optimiser {spec.name!r} is declared twice (module {module!r} and another)")
            specs[spec.name] = spec
    return specs


#: Every population optimiser by name (modules in name order: cma, openai_es, ...).
OPTIMISERS: dict[str, OptimiserSpec] = _discover()

#: The optimisers every process knows, as this package's modules declare them: what a shipped name holds wherever the
#: registry is used, and what a policy's record of one is checked against (a slot replaced in one process is not; T41-B03).
SHIPPED_SPECS: Mapping[str, OptimiserSpec] = MappingProxyType(dict(OPTIMISERS))

#: The optimisers every process knows: this package's modules'. A policy's record names one as it is.
SHIPPED: frozenset[str] = frozenset(SHIPPED_SPECS)

#: How a policy's record names an optimiser registered at run time (``OPTIMISERS[name] = OptimiserSpec(...)`` in a
#: script, not a module here), which another process has not registered: ``user:`` and a one-line name of at most 64
#: letters, digits and ``._+-``, read by every process (T40-B14: "its method 'my-es' is not allowed" everywhere else).
USER_NAME = re.compile(r"user:[A-Za-z0-9][A-Za-z0-9._+-]{0,63}")


def runtime_name(name: object) -> bool:
    """Whether ``name`` may name an optimiser registered at run time: one line of at most 64 letters, digits and ``._+-``
    that :data:`USER_NAME` reads back, not NE's name nor one of its methods (run.py compares a run's method with those)."""
    return isinstance(name, str) and name not in (NE, *NE_METHODS) and USER_NAME.fullmatch(f"user:{name}") is not None


def entry_problem(name: object, spec: object) -> str:
    """What is wrong with the registry entry ``OPTIMISERS[name] = spec`` ('' when nothing): no :class:`OptimiserSpec`
    (5 or None was an AttributeError in evolve and in every later load_policy, T41-B02), a shipped name holding another
    spec (``OPTIMISERS["cma"] = OPTIMISERS["openai-es"]`` ran OpenAI-ES as cma, T41-B03), or a run-time entry under a key
    other than its spec's name, a key :data:`USER_NAME` does not read back, or a label other than its name (they recorded
    ``user:openai-es`` beside ``user:other-name``, T41-B04)."""
    shared = registry_entry_problem("OPTIMISERS", name, spec, OptimiserSpec, SHIPPED_SPECS, "optimiser", "spec")
    if shared or (isinstance(name, str) and name in SHIPPED):
        return shared
    assert isinstance(spec, OptimiserSpec)  # the shared checks refused anything else
    entry = f"OPTIMISERS[{brief(name)}] = {brief(spec)} is not allowed"
    if not runtime_name(name):
        taken = ", ".join(map(repr, (NE, *NE_METHODS)))
        return f"{entry}: a run-time optimiser's name is one line of at most 64 letters, digits and ._+- (not {taken}), which its records name as user:NAME"
    if spec.label != name:
        return f"{entry}: its label {brief(spec.label)} is not its name; a run-time optimiser records its name as its method (user:{name}): leave label out"
    return _parts_problem(entry, spec)


def _parts_problem(entry: str, spec: OptimiserSpec) -> str:
    """What is wrong with a run-time spec's make, settings, min_genes, stops_itself and stop_reason ('' when nothing): a make of
    the wrong arity or none was a TypeError at the run's start, a settings class that is no frozen dataclass or has a
    default JSON cannot write one in its config (or a NaN or wrong-type one, T56-B01), a truthy stops_itself='no' ran without a budget for ever, and a
    stop_reason 'budget' recorded a run its optimiser stopped as one its budget stopped (T52-B08, B09, B11)."""
    make, cls = spec.make, spec.settings
    if not callable(make):
        return f"{entry}: its make {brief(make)} is no callable: give make(prototype, settings, seed) answering the optimiser (its class, or a function)"
    refused = refused_signature(make, 3)
    if refused:
        return (
            f"{entry}: its make of signature {brief(refused)} cannot be called as a run calls it, make(prototype genome, settings, seed): give one taking those"
        )
    if not frozen_dataclass_class(cls):
        return (
            f"{entry}: its settings {brief(cls)} is no frozen dataclass class: give the frozen dataclass of its settings, with defaults (not an object of it)"
        )
    # a field without one, NaN or 'x' for an int (T56-B01), or no plain JSON value whatever the field's type (T60-B02):
    # the agents' check too, the one check of defaults
    defaults = settings_defaults_problem(cls)
    if defaults:
        return f"{entry}: its settings {defaults}"
    if not whole_number(spec.min_genes) or spec.min_genes < 1:  # '40' and None were a TypeError, NaN no minimum at all (T61-B04)
        return f"{entry}: its min_genes {brief(spec.min_genes)} is no whole number >= 1: give the fewest genes a genome it searches may have (1: any)"
    if not isinstance(spec.stops_itself, (bool, np.bool_)):
        return f"{entry}: its stops_itself {brief(spec.stops_itself)} is no bool: give True (its stop() can end a run) or False (it needs a budget)"
    reason = spec.stop_reason
    if not isinstance(reason, str) or not reason.isprintable() or not reason.strip() or reason == "budget":
        return (
            f"{entry}: its stop_reason {brief(reason)} names no stop of its own: give a non-empty text (one line, printable) naming its own stop, "
            "other than 'budget' (a run's stop by its budget)"
        )
    return ""


def optimiser_spec(name: str) -> OptimiserSpec:
    """The registry's spec of population optimiser ``name``, its entry checked (:func:`entry_problem`; NeurohoverError
    naming a bad one, or an unknown name)."""
    if not isinstance(name, str) or name not in OPTIMISERS:
        raise NeurohoverError(f"unknown optimizer {brief(name)}: allowed {', '.join(optimiser_names())}")
    spec = OPTIMISERS[name]
    problem = entry_problem(name, spec)
    if problem:
        raise NeurohoverError(problem)
    return spec


def usable_specs() -> dict[str, OptimiserSpec]:
    """The registry's entries that :func:`optimiser_spec` takes: what a listing of every optimiser reads, so that one bad
    entry breaks only its own use."""
    return {name: spec for name, spec in list(OPTIMISERS.items()) if not entry_problem(name, spec)}


def recorded_names(name: str) -> tuple[str, str]:
    """The ``(method, optimizer)`` a champion's record of a run of population optimiser ``name`` says: its label and its
    name where it is :data:`SHIPPED` (from :data:`SHIPPED_SPECS`), else ``user:NAME`` for both (a record every process
    reads; the entry is checked by :func:`optimiser_spec`)."""
    if isinstance(name, str) and name in SHIPPED:
        return SHIPPED_SPECS[name].label, name
    optimiser_spec(name)
    return f"user:{name}", f"user:{name}"


def optimiser_names() -> tuple[str, ...]:
    """Every optimiser an evolution run takes: the paper's ``ne`` first, then the registry's (its text keys)."""
    return (NE, *(name for name in list(OPTIMISERS) if isinstance(name, str)))


def population_settings(name: str, settings: Any) -> Any:
    """The checked settings object of population optimiser ``name`` from None (the defaults), an
    object of its settings class, or a dict of overrides (NeurohoverError on a bad key or value)."""
    # a list or an array was "unhashable type" (sixteenth trial); a bad entry is named (T41-B02), a shipped name's settings
    # are its shipped spec's (a record of one reads alike in every process: evolve refuses a replaced slot, T41-B03)
    cls = SHIPPED_SPECS[name].settings if isinstance(name, str) and name in SHIPPED else optimiser_spec(name).settings
    if settings is None:
        return cls()
    if type(settings) is cls:  # exactly its class: a subclass's settings (UH-CMA-ES's of CMA-ES's) belong to another optimiser
        # an object of its class was flown unchecked, where a dict of the same values is refused (T56-B01's rest); plain values (T57-B02)
        return checked_settings(settings, bad_what=f"{name} settings")
    if not isinstance(settings, Mapping):
        fields = [f.name for f in dataclasses.fields(cls)]
        raise NeurohoverError(f"settings for optimizer {name!r} must be a {cls.__name__} or a dict with keys {', '.join(fields)}")
    return settings_from_dict(cls, settings, unknown_what=name, bad_what=f"{name} settings")
