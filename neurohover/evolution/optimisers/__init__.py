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
reads (one without it registered too), while a record of a shipped optimiser's name is checked against the registry.
"""

from __future__ import annotations

import dataclasses
import importlib
import pkgutil
import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from ...errors import NeurohoverError, brief, settings_from_dict

__all__ = ["NE", "OPTIMISERS", "SHIPPED", "USER_NAME", "OptimiserSpec", "optimiser_names", "population_settings", "recorded_names"]

NE = "ne"  # the paper's neuroevolution: not a population optimiser of this registry


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
        A frozen dataclass of its settings, with defaults; its ``__post_init__`` raises
        ValueError on a bad value.
    make : callable
        ``make(prototype genome, settings, seed)`` -> an optimiser with ``ask``, ``tell(fitness, info)``,
        ``stop``, ``champion_genome``, ``champion_return``, ``state_dict`` and a
        ``from_state_dict`` classmethod (:class:`~neurohover.evolution.common.Optimiser`).
    min_genes : int
        The shortest genome it can search.
    stop_reason : str
        What a run records when the optimiser's own ``stop()`` ends it.
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

#: The optimisers every process knows: this package's modules'. A policy's record names one as it is.
SHIPPED: frozenset[str] = frozenset(OPTIMISERS)

#: How a policy's record names an optimiser registered at run time (``OPTIMISERS[name] = OptimiserSpec(...)`` in a
#: script, not a module here), which another process has not registered: ``user:`` and a one-line name of at most 64
#: letters, digits and ``._+-``, read by every process (T40-B14: "its method 'my-es' is not allowed" everywhere else).
USER_NAME = re.compile(r"user:[A-Za-z0-9][A-Za-z0-9._+-]{0,63}")


def recorded_names(name: str) -> tuple[str, str]:
    """The ``(method, optimizer)`` a champion's record of a run of population optimiser ``name`` says: its label and its
    name where it is :data:`SHIPPED`, else both prefixed ``user:`` (a record every process reads; a name
    :data:`USER_NAME` does not take is refused as the policy is saved)."""
    spec = OPTIMISERS[name]
    return (spec.label, name) if name in SHIPPED else (f"user:{spec.label}", f"user:{name}")


def optimiser_names() -> tuple[str, ...]:
    """Every optimiser an evolution run takes: the paper's ``ne`` first, then the registry's."""
    return (NE, *OPTIMISERS)


def population_settings(name: str, settings: Any) -> Any:
    """The checked settings object of population optimiser ``name`` from None (the defaults), an
    object of its settings class, or a dict of overrides (NeurohoverError on a bad key or value)."""
    if not isinstance(name, str) or name not in OPTIMISERS:  # a list or an array was "unhashable type" (sixteenth trial)
        raise NeurohoverError(f"unknown optimizer {brief(name)}: allowed {', '.join(optimiser_names())}")
    cls = OPTIMISERS[name].settings
    if settings is None:
        return cls()
    if type(settings) is cls:  # exactly its class: a subclass's settings (UH-CMA-ES's of CMA-ES's) belong to another optimiser
        return settings
    if not isinstance(settings, Mapping):
        fields = [f.name for f in dataclasses.fields(cls)]
        raise NeurohoverError(f"settings for optimizer {name!r} must be a {cls.__name__} or a dict with keys {', '.join(fields)}")
    return settings_from_dict(cls, settings, unknown_what=name, bad_what=f"{name} settings")
