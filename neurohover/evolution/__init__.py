"""Optimisers over flat genome vectors: neuroevolution, selection races, CMA-ES.

All optimisers MAXIMISE returns (negative in the helicopter domain) and use an
ask/tell interface; fitness evaluation is left to the caller.
"""

from .cmaes import CMAES
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
from .neuroevolution import (
    ROULETTE_ERROR_FLOOR,
    ChampionRecord,
    GenerationalNE,
    GenerationalSettings,
    GenerationRecord,
    SteadyStateNE,
    SteadyStateSettings,
    roulette_weights,
)
from .operators import crossover, mutate
from .races import (
    RaceResult,
    ResamplingResult,
    bayes_mean_bounds,
    fixed_resampling,
    selection_race,
)

__all__ = [
    "CMAES",
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
