"""CMA-ES (pycma) as a population optimiser: its settings and its registry entry."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..cmaes import CMAES, SIGMA0
from . import OptimiserSpec

__all__ = ["CMASettings"]


@dataclass(frozen=True)
class CMASettings:
    """CMA-ES settings: the initial step size (:data:`~neurohover.evolution.cmaes.SIGMA0`, why 0.02)
    and the population (None: pycma's 4 + 3 ln D)."""

    sigma0: float = SIGMA0
    popsize: int | None = None

    def __post_init__(self) -> None:
        s0, pop = self.sigma0, self.popsize
        if isinstance(s0, bool) or not isinstance(s0, (int, float)) or not (math.isfinite(s0) and s0 > 0):
            raise ValueError(f"CMA-ES sigma0={s0!r} must be a finite number > 0")
        if pop is not None and (isinstance(pop, bool) or not isinstance(pop, (int, np.integer)) or pop < 2):
            raise ValueError(f"CMA-ES popsize={pop!r} must be None or an integer >= 2")
        object.__setattr__(self, "sigma0", float(s0))
        object.__setattr__(self, "popsize", None if pop is None else int(pop))


def _make(genome: np.ndarray, settings: CMASettings, seed: int) -> CMAES:
    return CMAES(genome, sigma0=settings.sigma0, seed=seed, popsize=settings.popsize)


OPTIMISER_SPECS = (OptimiserSpec("cma", "CMA-ES (pycma), the step size adapted", CMASettings, _make, min_genes=2, stop_reason="cma-stop", label="cma-es"),)
