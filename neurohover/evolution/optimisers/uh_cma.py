"""Uncertainty-handling CMA-ES (Hansen, Niederberger, Guzzella & Koumoutsakos 2009) through pycma's
:class:`cma.NoiseHandler`, as an ask/tell population optimiser (issue 35: the standard baseline beside
selection races for noisy fitness).

pycma's noise handler re-evaluates a few solutions of each generation, measures how much their ranks
move (the uncertainty), and answers by raising the step size and the evaluations per solution when the
ranks are noise, lowering the evaluations again when they are not. pycma drives it with an objective
function it calls itself; here the re-evaluations are one more ask/tell round, so the episodes still
fly in the kernel in batches and the run's budget counts every one of them:

1. ``ask`` returns the generation, each solution repeated ``evaluations`` times (pycma's current
   ``NoiseHandler.evaluations``, rounded); ``tell`` takes the median return of each solution's rows
   (pycma's ``aggregate``), tells pycma the generation and picks the solutions to re-evaluate
   (``NoiseHandler.indices``: the first ones and the best of the rest).
2. ``ask`` returns those, each repeated ``evaluations`` times at a point ``epsilon`` from it (pycma's
   ``ask(1, x, epsilon)``); ``tell`` gives their medians to pycma's ``update_measure`` and ``treat``,
   and the step size is multiplied by the factor ``treat`` returns.

``NoiseHandler.indices`` rounds the number of re-evaluations at random with NumPy's global generator:
it is called with that generator seeded from the optimiser's own (and its state restored), so runs are
reproducible and leave ``np.random`` as they found it. The champion is the best single return told, as
for CMA-ES, re-evaluations included.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ...errors import NeurohoverError, brief, whole_number
from ..common import TellInfo, check_settings, require_std
from . import OptimiserSpec
from .cma import CMAES, CMASettings, losses_of, pycma

__all__ = ["UHCMAES", "UHCMASettings"]


@dataclass(frozen=True)
class UHCMASettings(CMASettings):
    """Settings of uncertainty-handling CMA-ES: CMA-ES's (``sigma0``, ``popsize``: :class:`CMASettings`, which checks
    them) and the noise handler's.

    Attributes
    ----------
    min_evaluations, max_evaluations : int
        Evaluations (episodes) per solution, between these (it starts at the minimum).
    reevaluations : int or None
        Solutions re-evaluated a generation (1 to popsize; None: pycma's ``2 + popsize / 20``).
    epsilon : float
        The perturbation of a re-evaluated point (pycma's 1e-7).
    """

    min_evaluations: int = 1
    max_evaluations: int = 20
    reevaluations: int | None = None
    epsilon: float = 1e-7

    def __post_init__(self) -> None:
        super().__post_init__()
        lo, hi, re, eps = self.min_evaluations, self.max_evaluations, self.reevaluations, self.epsilon

        def integer(v) -> bool:
            return whole_number(v)  # np.timedelta64 is a np.integer (T17-1)

        if not integer(lo) or not integer(hi) or not 1 <= lo <= hi:
            raise NeurohoverError(f"UH-CMA-ES min_evaluations={brief(lo)} and max_evaluations={brief(hi)} must be integers with 1 <= min <= max")
        if re is not None and (not integer(re) or re < 1):
            raise NeurohoverError(f"UH-CMA-ES reevaluations={brief(re)} must be None or an integer >= 1")
        if re is not None and self.popsize is not None and re > self.popsize:  # pycma indexed past the generation (eleventh trial)
            raise NeurohoverError(f"UH-CMA-ES reevaluations={brief(re)} must be at most popsize={self.popsize}: it re-evaluates solutions of one generation")
        object.__setattr__(self, "epsilon", require_std("UH-CMA-ES epsilon", eps))  # -0.0 as 0.0, as every spread


class UHCMAES(CMAES):
    """CMA-ES with pycma's noise handler, ask/tell in two rounds a generation (module docstring)."""

    def __init__(self, prototype: np.ndarray, settings: UHCMASettings, seed: int = 0, budget: int | None = None) -> None:
        settings = check_settings(settings, UHCMASettings)  # CMASettings() was an AttributeError (fourteenth trial)
        super().__init__(prototype, sigma0=settings.sigma0, seed=seed, popsize=settings.popsize, budget=budget)
        s = settings
        if s.reevaluations is not None and s.reevaluations > self.popsize:  # pycma's default popsize is known only here
            why = "" if s.popsize is not None else f" (pycma's 4 + 3 ln D for D={self._es.N} genes)"
            raise NeurohoverError(
                f"UH-CMA-ES reevaluations={s.reevaluations} must be at most popsize={self.popsize}{why}: it re-evaluates solutions of one"
                " generation; give a smaller reevaluations or a larger popsize"
            )
        evals = [s.min_evaluations, s.min_evaluations, s.max_evaluations]  # minimum, start, maximum
        self._noise = pycma().NoiseHandler(self._es.N, maxevals=evals, reevals=s.reevaluations, epsilon=s.epsilon)
        self._round: dict[str, Any] | None = None  # the generation waiting for its re-evaluations

    @property
    def evaluations_per_solution(self) -> int:
        """Episodes each solution of the next generation is flown (the noise handler's current number)."""
        return max(1, int(round(self._noise.evaluations)))

    def _ask(self) -> np.ndarray:
        """The next batch: a generation (each solution repeated), or the last generation's re-evaluations."""
        n = self.evaluations_per_solution
        if self._round is None:
            solutions = [np.asarray(x, dtype=np.float64) for x in self._es.ask()]
        else:
            eps = self._noise.epsilon
            solutions = [np.asarray(self._es.ask(1, self._round["X"][i], eps)[0] if eps else self._round["X"][i], dtype=np.float64) for i in self._round["idx"]]
        self._repeats = n
        return np.vstack([x for x in solutions for _ in range(n)])

    def _tell(self, rows: np.ndarray, returns: np.ndarray, info: TellInfo | None) -> None:
        """pycma's update (a generation) or the noise handler's (its re-evaluations); ``info`` is not used."""
        losses = losses_of(np.median(returns.reshape(-1, self._repeats), axis=1))  # pycma's aggregate over a solution's rows
        if self._round is None:
            X = [rows[i * self._repeats] for i in range(len(losses))]
            self._es.tell(X, losses.tolist())
            idx = self._indices(losses)
            self._round = {"X": X, "fit": losses.tolist(), "idx": idx} if len(idx) else None
            return
        noise, r = self._noise, self._round
        noise.fit, noise.fitre, noise.idx = list(r["fit"]), list(r["fit"]), np.asarray(r["idx"])
        for i, loss in zip(r["idx"], losses, strict=True):
            noise.fitre[i] = float(loss)
        noise.update_measure()
        self._es.sigma *= noise.treat()
        self._round = None

    def _indices(self, losses: np.ndarray) -> list[int]:
        """The solutions to re-evaluate (``NoiseHandler.indices``), with NumPy's global generator seeded from ours."""
        state = np.random.get_state()
        np.random.seed(int(self._rng.integers(2**32)))
        try:
            return [int(i) for i in self._noise.indices(losses.tolist())]
        finally:
            np.random.set_state(state)

    @property
    def noise_measure(self) -> float:
        """pycma's smoothed uncertainty measure ``noiseS`` (> 0: the ranks are noise)."""
        return float(self._noise.noiseS)


def _make(genome: np.ndarray, settings: UHCMASettings, seed: int) -> UHCMAES:
    return UHCMAES(genome, settings, seed=seed)


OPTIMISER_SPECS = (
    OptimiserSpec("uh-cma", "uncertainty-handling CMA-ES (pycma's NoiseHandler)", UHCMASettings, _make, min_genes=2, stop_reason="cma-stop", label="uh-cma-es"),
)
