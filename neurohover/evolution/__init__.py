"""Optimisers over flat genome vectors: neuroevolution, selection races, CMA-ES.

All optimisers MAXIMISE returns (negative in the helicopter domain) and use an
ask/tell interface; fitness evaluation is left to the caller.
"""

from .cmaes import CMAES
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
    "fixed_resampling",
    "mutate",
    "roulette_weights",
    "selection_race",
]
