"""OpenAI-ES (Salimans et al. 2017, "Evolution Strategies as a Scalable Alternative to RL").

A Gaussian search distribution of fixed spread ``sigma`` around a mean, ask/tell over flat
genomes, maximising returns:

- **antithetic sampling**: a generation is ``popsize / 2`` noise vectors ``eps`` and their mirrors,
  genomes ``mean + sigma * eps`` and ``mean - sigma * eps``;
- **centred-rank fitness shaping**: the returns are replaced by their ranks scaled to [-0.5, 0.5]
  (NaN and ``-inf`` rank last), so only their order matters, as in every optimiser here;
- the gradient estimate ``sum_i shaped_i * eps_i / (popsize * sigma)``, minus an L2 decay of the
  mean, is followed by **Adam** on the mean.

The champion, as for CMA-ES, is the genome with the best single return told (on a task family
the evolution run keeps the last generation's best estimate instead). The generator is private
and its state is part of :meth:`OpenAIES.state_dict`, so a resumed run continues bit-for-bit.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, fields
from typing import Any

import numpy as np

from ...errors import NeurohoverError
from ..common import (
    STATE_VERSION,
    ChampionTracker,
    Clock,
    EntryError,
    PopulationOptimiser,
    TellInfo,
    as_returns,
    check_entries,
    check_genomes,
    check_prototype,
    check_settings,
    check_state,
    dec_array,
    enc_array,
    rank,
    read_count,
    read_entry,
    read_seconds,
    read_settings,
    require_population,
    require_spread,
    require_std,
    required,
    rng_from_state,
    set_field,
)
from ..seeding import check_seed
from . import OptimiserSpec

__all__ = ["OpenAIES", "OpenAIESSettings"]


@dataclass(frozen=True)
class OpenAIESSettings:
    """OpenAI-ES settings (``evolve(..., optimizer="openai-es", settings={...})``).

    ``sigma`` 0.01 suits the baseline-seeded policies: at 0.02 (the paper's, and CMA-ES's start,
    :class:`~neurohover.evolution.optimisers.cma.CMASettings`) a 600-episode run on GHH-08
    train:1 (300-step episodes, seed 3) kept a champion that crashed 94 of 100 fresh episodes,
    at 0.01 none. ``learning_rate`` 0.01, Adam's betas and the L2 coefficient 0.005 are the paper's.

    Attributes
    ----------
    popsize : int
        Genomes per generation (even: antithetic pairs).
    sigma : float
        The spread of the perturbations (>= 1e-100 and <= 1e100, :data:`~neurohover.evolution.common.MAX_SPREAD`).
    learning_rate : float
        Adam's step size (>= 1e-100 and <= 1e100).
    beta1, beta2 : float
        Adam's decay rates, in [0, 1).
    epsilon : float
        Adam's denominator offset (> 0).
    l2 : float
        The weight decay of the mean (>= 0).
    """

    popsize: int = 20
    sigma: float = 0.01
    learning_rate: float = 0.01
    beta1: float = 0.9
    beta2: float = 0.999
    epsilon: float = 1e-8
    l2: float = 0.005  # weight decay of the mean

    def __post_init__(self) -> None:
        popsize = require_population("popsize", self.popsize)
        if popsize % 2:
            raise NeurohoverError(f"popsize={popsize} must be even: OpenAI-ES asks antithetic pairs")
        set_field(self, "popsize", popsize)
        for name in ("sigma", "learning_rate"):  # steps in genome units: 1e308 overflowed the genes late in the run (eleventh trial)
            set_field(self, name, require_spread(name, require_std(name, getattr(self, name)), positive=True))  # as a float: sigma=0.0
        value = require_std("epsilon", self.epsilon)
        if value <= 0.0:
            raise NeurohoverError(f"epsilon={value!r} must be a finite number > 0")
        set_field(self, "epsilon", value)
        for name in ("beta1", "beta2"):
            value = require_std(name, getattr(self, name))
            if not value < 1.0:
                raise NeurohoverError(f"{name}={value!r} must be in [0, 1)")
            set_field(self, name, value)
        set_field(self, "l2", require_std("l2", self.l2))


#: Every entry an :meth:`OpenAIES.state_dict` has held.
STATE_ENTRIES = ("type", "version", "settings", "mean", "adam", "generation", "pending", "rng", "tracker", "wall_seconds")


def centred_ranks(returns: np.ndarray) -> np.ndarray:
    """Each return's rank scaled to [-0.5, 0.5], best highest (ties, NaN and ``-inf`` by :func:`~neurohover.evolution.common.rank`).

    Raises
    ------
    NeurohoverError
        Unless ``returns`` is a 1-D array of two or more real numbers (one return has no rank to scale).
    """
    returns = as_returns(returns, "returns", "a 1-D array of 2 or more returns", minimum=2)
    n = returns.size
    shaped = np.empty(n)
    shaped[rank(returns)] = np.arange(n - 1, -1, -1, dtype=np.float64)  # best gets n - 1
    return shaped / (n - 1) - 0.5


class OpenAIES(PopulationOptimiser):
    """OpenAI-ES over flat genomes, ask/tell, maximising returns.

    Parameters
    ----------
    prototype : np.ndarray
        1-D initial mean.
    settings : OpenAIESSettings
    seed : int
        Seed of the private generator of the perturbations.
    """

    def __init__(self, prototype: np.ndarray, settings: OpenAIESSettings | None = None, seed: int = 0) -> None:
        super().__init__()
        self.settings = check_settings(settings, OpenAIESSettings)
        self.mean = check_prototype(prototype)
        self._rng = np.random.default_rng(check_seed(seed))
        self._m = np.zeros_like(self.mean)  # Adam's moments
        self._v = np.zeros_like(self.mean)
        self.generation = 0
        self._eps: np.ndarray | None = None  # the pending generation's noise (popsize / 2, D)

    @property
    def popsize(self) -> int:
        """Genomes per :meth:`ask`."""
        return self.settings.popsize

    def _ask(self) -> np.ndarray:
        """One generation: ``popsize / 2`` perturbations and their mirrors, shape ``(popsize, D)``."""
        if self._eps is None:  # a resumed checkpoint keeps the pending generation's noise: the same genomes
            self._eps = self._rng.standard_normal((self.popsize // 2, self.mean.size))
        sigma = self.settings.sigma
        return np.vstack([self.mean + sigma * self._eps, self.mean - sigma * self._eps])

    def _tell(self, genomes: np.ndarray, returns: np.ndarray, info: TellInfo | None) -> None:
        """An Adam step of the mean up the gradient estimated from the returns (``info`` unused)."""
        assert self._eps is not None  # asked
        s = self.settings
        shaped = centred_ranks(returns)
        half = self.popsize // 2
        weights = shaped[:half] - shaped[half:]  # a pair's two genomes share its noise, with opposite signs
        grad = weights @ self._eps / (self.popsize * s.sigma) - s.l2 * self.mean
        self.generation += 1
        t = self.generation
        self._m = s.beta1 * self._m + (1.0 - s.beta1) * grad
        self._v = s.beta2 * self._v + (1.0 - s.beta2) * grad * grad
        step = s.learning_rate * math.sqrt(1.0 - s.beta2**t) / (1.0 - s.beta1**t)
        self.mean = self.mean + step * self._m / (np.sqrt(self._v) + s.epsilon)  # ascent: returns are maximised
        self._eps = None

    def stop(self) -> bool:
        """OpenAI-ES has no termination criterion of its own: the run's budget stops it."""
        return False

    # ----------------------------------------------------------------- checkpoint

    def state_dict(self) -> dict[str, Any]:
        """Strict-JSON snapshot of the whole state (also between ask and tell)."""
        return {
            "type": "OpenAIES",
            "version": STATE_VERSION,
            "settings": asdict(self.settings),
            "mean": enc_array(self.mean),
            "adam": [enc_array(self._m), enc_array(self._v)],
            "generation": self.generation,
            "pending": enc_array(self._eps),
            "rng": self._rng.bit_generator.state,
            "tracker": self._tracker.to_dict(),
            "wall_seconds": self._clock(),
        }

    @classmethod
    def from_state_dict(cls, state: dict[str, Any]) -> OpenAIES:
        """The optimiser :meth:`state_dict` saved; it continues bit-for-bit identically.

        Raises
        ------
        NeurohoverError
            A state that is not one of :meth:`state_dict`, naming its missing or damaged entry.
        """
        check_state(state, "OpenAIES")
        kind = "OpenAIES"
        check_entries(state, kind, STATE_ENTRIES)
        names = tuple(f.name for f in fields(OpenAIESSettings))
        settings = read_entry(state, kind, "settings", lambda s: read_settings(s, OpenAIESSettings, names, {}))  # {}: the defaults (T19-03)
        opt = cls(read_entry(state, kind, "mean", lambda a: required(dec_array(a, "mean"), "mean")), settings)
        d = opt.mean.size
        opt._m, opt._v = read_entry(state, kind, "adam", lambda a: _moments(a, d))
        opt.generation = read_entry(state, kind, "generation", read_count)
        opt._eps = read_entry(state, kind, "pending", lambda a: check_genomes(dec_array(a, "pending noise"), d, "pending noise", rows=opt.popsize // 2))
        opt._rng = read_entry(state, kind, "rng", rng_from_state)
        opt._tracker = read_entry(state, kind, "tracker", lambda t: ChampionTracker.from_dict(t, d))
        opt._clock = Clock(read_entry(state, kind, "wall_seconds", read_seconds))
        if opt._tracker.evaluations != opt.generation * opt.popsize:  # each generation tells popsize returns
            raise NeurohoverError(
                f"OpenAIES state dict has generation={opt.generation} and tracker evaluations={opt._tracker.evaluations}:"
                f" each generation is popsize={opt.popsize} evaluations, so {opt.generation * opt.popsize}"
            )
        return opt


def _moments(value: Any, size: int) -> tuple[np.ndarray, np.ndarray]:
    """Adam's two moments of a saved state: genomes of ``size`` finite numbers, the second >= 0 (a moment of None was a
    TypeError at the first tell(); T19-03)."""
    if isinstance(value, (list, dict)) and len(value) != 2:  # other values fail at indexing
        raise EntryError("not Adam's two moments: allowed a list of the two arrays state_dict() wrote")
    m, v = (check_genomes(required(dec_array(value[i], "Adam moment"), "Adam moment"), size, "Adam moment", rows=0, genes=False) for i in (0, 1))
    if np.any(v < 0.0):  # a running mean of squares: its square root is taken
        raise EntryError("Adam's second moment holds a negative number: allowed numbers >= 0")
    return m, v


def _make(genome: np.ndarray, settings: OpenAIESSettings, seed: int) -> OpenAIES:
    return OpenAIES(genome, settings, seed=seed)


OPTIMISER_SPECS = (
    OptimiserSpec("openai-es", "OpenAI-ES (Salimans et al. 2017): antithetic sampling, centred ranks, Adam", OpenAIESSettings, _make, stops_itself=False),
)
