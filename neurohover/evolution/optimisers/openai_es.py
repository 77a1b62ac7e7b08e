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

from ...errors import NeurohoverError, brief, finite_real
from ...policies import MAX_GENE
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

__all__ = ["MAX_EPSILON", "MAX_L2", "OpenAIES", "OpenAIESSettings"]

#: The largest L2 coefficient. A gradient entry is the ranks' term, at most max|noise| / (2 sigma) <= about 5e100 (noise
#: under 10, sigma >= 1e-100; the returns enter only as ranks in [-0.5, 0.5], so no return, not even -WORST_RETURN, scales
#: it), minus l2 * mean, the mean a genome's (<= policies.MAX_GENE, 1e120): at l2 <= 1e20 an entry stays below 1e140 and
#: its square, Adam's second moment, below 1e280, far below a float's 1.8e308 (l2=1e300 made it inf; T50-B03).
MAX_L2 = 1e20
#: The largest Adam epsilon: 1, the largest in use (TensorFlow's note for Inception; Adam's own 1e-8). It only keeps the
#: step finite where sqrt(v) is 0; far above the gradient's size it, not the gradient, sets the step, which shrinks to
#: nothing (epsilon=1e300 moved the mean by 7.7e-302, without a word; T50-B03).
MAX_EPSILON = 1.0


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
        Adam's denominator offset (> 0 and <= 1, :data:`MAX_EPSILON`).
    l2 : float
        The weight decay of the mean (>= 0 and <= 1e20, :data:`MAX_L2`: Adam's moments stay finite).
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
        for name, low, top in (("epsilon", "> 0", MAX_EPSILON), ("l2", ">= 0", MAX_L2)):  # l2=1e300 made Adam's moment inf (T50-B03)
            value = getattr(self, name)
            if not finite_real(value) or not (0.0 < float(value) if low == "> 0" else 0.0 <= float(value)) or float(value) > top:
                why = f" ({MAX_LIMITS[name]})" if finite_real(value) and float(value) > top else ""
                raise NeurohoverError(f"{name}={brief(value)} must be a finite number {low} and <= {top:g}{why}")
            set_field(self, name, float(value) + 0.0)  # -0.0 as 0.0, as require_std
        for name in ("beta1", "beta2"):
            value = require_std(name, getattr(self, name))
            if not value < 1.0:
                raise NeurohoverError(f"{name}={value!r} must be in [0, 1)")
            set_field(self, name, value)


#: Why each of :class:`OpenAIESSettings`' capped settings is capped (its refusal says so).
MAX_LIMITS = {"epsilon": "a larger one, not the gradient, sets Adam's step, and the mean stops", "l2": "a larger one overflows Adam's moments"}

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
        t = self.generation + 1
        with np.errstate(over="ignore", invalid="ignore"):  # an overflow is refused below, by name
            m = s.beta1 * self._m + (1.0 - s.beta1) * grad
            v = s.beta2 * self._v + (1.0 - s.beta2) * grad * grad
            step = s.learning_rate * math.sqrt(1.0 - s.beta2**t) / (1.0 - s.beta1**t)
            mean = self.mean + step * m / (np.sqrt(v) + s.epsilon)  # ascent: returns are maximised
        _refuse_unresumable(mean, m, v, t)
        self.generation, self._m, self._v, self.mean, self._eps = t, m, v, mean, None

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


def _refuse_unresumable(mean: np.ndarray, m: np.ndarray, v: np.ndarray, generation: int) -> None:
    """NeurohoverError, the state unchanged, where generation ``generation``'s update gave a state :meth:`OpenAIES.from_state_dict`
    refuses (a moment not finite, a mean gene past :data:`~neurohover.policies.MAX_GENE`): it was written as a checkpoint
    its own resume refused (T50-B03); the run stops there, its last checkpoint kept."""
    for name, a, top in (("Adam's first moment", m, math.inf), ("Adam's second moment", v, math.inf), ("the mean", mean, MAX_GENE)):
        bad = np.flatnonzero(~np.isfinite(a) | (np.abs(a) > top))
        if bad.size:
            raise NeurohoverError(
                f"OpenAI-ES stopped at generation {generation}: {name}'s gene {int(bad[0])} became {brief(float(a[bad[0]]))}, which is not allowed: "
                f"allowed finite numbers{'' if top == math.inf else f' in [-{top:g}, {top:g}] (a policy genome)'}; give smaller settings"
            )


def _make(genome: np.ndarray, settings: OpenAIESSettings, seed: int) -> OpenAIES:
    return OpenAIES(genome, settings, seed=seed)


OPTIMISER_SPECS = (
    OptimiserSpec("openai-es", "OpenAI-ES (Salimans et al. 2017): antithetic sampling, centred ranks, Adam", OpenAIESSettings, _make, stops_itself=False),
)
