"""Optimisers over flat genome vectors: neuroevolution, selection races, CMA-ES.

All optimisers MAXIMISE returns (negative in the helicopter domain) and share one ask/tell
protocol (:class:`Optimiser`); fitness evaluation is left to the caller.

Modules: ``steady_state`` and ``generational`` (the paper's neuroevolution), ``optimisers`` (CMA-ES, OpenAI-ES, ...), ``common``
(the protocol and what the optimisers share), ``operators`` (mutation, crossover), ``races``
(fitness under noise); whole runs: ``evolve`` (the public entry point), ``config``, ``run``,
``records``, ``seeding``.
"""

from ..errors import CheckpointReplaced
from .common import ChampionRecord, Optimiser
from .evolve import (
    EvolutionInterrupted,
    EvolutionResult,
    HistoryRecord,
    ProgressInfo,
    Resampling,
    evolve,
    parse_resampling,
    validation_return,
)
from .generational import GenerationalNE, GenerationalSettings, GenerationRecord
from .operators import crossover, mutate
from .optimisers.cma import CMAES
from .races import (
    RaceResult,
    ResamplingResult,
    bayes_mean_bounds,
    fixed_resampling,
    selection_race,
)
from .steady_state import ROULETTE_ERROR_FLOOR, SteadyStateNE, SteadyStateSettings, roulette_weights

__all__ = [
    "CMAES",
    "CheckpointReplaced",
    "EvolutionInterrupted",
    "EvolutionResult",
    "HistoryRecord",
    "ProgressInfo",
    "Resampling",
    "ROULETTE_ERROR_FLOOR",
    "ChampionRecord",
    "GenerationRecord",
    "GenerationalNE",
    "GenerationalSettings",
    "Optimiser",
    "RaceResult",
    "ResamplingResult",
    "SteadyStateNE",
    "SteadyStateSettings",
    "bayes_mean_bounds",
    "crossover",
    "evolve",
    "fixed_resampling",
    "mutate",
    "parse_resampling",
    "roulette_weights",
    "selection_race",
    "validation_return",
]
