"""Steady-state and generational neuroevolution (paper Appendices A and B; docs/model.md, Neuroevolution).

Both optimisers work on flat genome vectors (network weights) through an
ask/tell interface in the style of pycma / evosax; the caller evaluates the
asked genomes and tells their returns.

Sign convention
---------------
The optimisers MAXIMISE returns. In the helicopter domain returns are
negative (accumulated negative reward), so "best" means "closest to zero";
the paper's "error" of a genome is ``-return``. Non-finite returns (NaN or
``-inf``, e.g. from a diverged simulation) rank as the worst possible;
``+inf`` is refused.

Checkpointing
-------------
``state_dict()`` returns a plain, strictly JSON-serialisable dict (non-finite
floats are stored as strings) including the ``numpy.random.Generator`` state;
``from_state_dict`` rebuilds an optimiser that continues bit-for-bit
identically, also when saved between ``ask()`` and ``tell()``.
"""

from __future__ import annotations

import dataclasses
import math
import numbers
import time
from bisect import bisect_right
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import NeurohoverError
from .operators import crossover, mutate
from .races import RaceResult, ResamplingResult

__all__ = [
    "PLATEAU_RULES",
    "SELECTIONS",
    "SteadyStateSettings",
    "GenerationalSettings",
    "ChampionRecord",
    "GenerationRecord",
    "ROULETTE_ERROR_FLOOR",
    "roulette_weights",
    "SteadyStateNE",
    "GenerationalNE",
]

#: Errors (``-return``) are clamped to at least this before ``1/ln(error)``:
#: ``ln`` is zero at 1 and negative below, which would give infinite or
#: negative roulette weights. Any genome with return ``>= -ROULETTE_ERROR_FLOOR``
#: therefore gets the maximal weight ``1/ln(1 + 1e-6) ~ 1e6``.
ROULETTE_ERROR_FLOOR = 1.0 + 1e-6

_STATE_VERSION = 1

#: Plateau rules of :class:`SteadyStateSettings` (docs/model.md, Neuroevolution): ``no-crash`` (default) counts
#: evaluations without a new champion only while the champion's own evaluation did not crash;
#: ``literal`` is Appendix A as written (counts every evaluation without a new champion).
PLATEAU_RULES = ("no-crash", "literal")

#: Parent selection of :class:`SteadyStateSettings`: ``roulette`` (Appendix A, weights
#: ``1/ln(error)``) or ``tournament`` (the best of ``tournament_size`` distinct genomes drawn
#: uniformly, as in the authors' ``eonn`` code; docs/model.md, Neuroevolution).
SELECTIONS = ("roulette", "tournament")


# --------------------------------------------------------------------------- settings


def _require_int(name: str, value: Any, minimum: int) -> int:
    if isinstance(value, bool) or not isinstance(value, numbers.Integral) or value < minimum:
        raise ValueError(f"{name}={value!r} must be an integer >= {minimum}")
    return int(value)


def _require_prob(name: str, value: Any) -> float:
    if (
        isinstance(value, bool)
        or not isinstance(value, numbers.Real)
        or not 0.0 <= float(value) <= 1.0
    ):
        raise ValueError(f"{name}={value!r} must be a probability in [0, 1]")
    return float(value)


def _require_std(name: str, value: Any) -> float:
    if (
        isinstance(value, bool)
        or not isinstance(value, numbers.Real)
        or not math.isfinite(float(value))
        or float(value) < 0.0
    ):
        raise ValueError(f"{name}={value!r} must be a finite number >= 0")
    return float(value)


def _normalise(obj: Any, name: str, value: Any) -> None:
    # Frozen dataclass: store plain Python numbers so that asdict() is JSON-able.
    object.__setattr__(obj, name, value)


def _validate_common(obj: Any) -> None:
    _normalise(obj, "pop_size", _require_int("pop_size", obj.pop_size, 2))
    for name in ("crossover_prob", "averaging_prob", "mutate_prob", "mutate_frac", "mutate_repl"):
        _normalise(obj, name, _require_prob(name, getattr(obj, name)))
    _normalise(obj, "mutate_std", _require_std("mutate_std", obj.mutate_std))
    if obj.budget is not None:
        _normalise(obj, "budget", _require_int("budget", obj.budget, 1))


@dataclass(frozen=True)
class SteadyStateSettings:
    """Settings of :class:`SteadyStateNE`; defaults are the paper's Table 6.

    Attributes
    ----------
    pop_size : int
        Population size (>= 2).
    elite_size : int
        Best individuals kept each generation (``0 <= elite_size < pop_size``);
        the other ``pop_size - elite_size`` are replaced by offspring.
    crossover_prob : float
        Probability that an offspring is made by crossover (else a mutated copy).
    averaging_prob : float
        Per-gene probability that crossover averages the parents.
    mutate_prob : float
        Probability that a crossover child is then mutated.
    mutate_frac : float
        Per-gene mutation probability.
    mutate_std : float
        Standard deviation of the Gaussian mutation (finite, >= 0).
    mutate_repl : float
        Probability that a mutated gene is replaced rather than shifted.
    plateau_threshold : int
        Stop after this many counted evaluations without a new champion (>= 1); which
        evaluations count is ``plateau_rule``'s choice.
    budget : int or None
        Optional cap on the number of evaluations (>= 1).
    plateau_rule : {"no-crash", "literal"}
        ``"no-crash"`` (default, a documented deviation, docs/model.md, Neuroevolution): the plateau counter runs only
        while the champion's evaluation completed without crashing (crash flags come through
        ``SteadyStateNE.tell(..., crashed=...)``); a population whose champion still crashes
        never stops at the plateau, so such a run ends only at its budget (give one when the
        prototype may crash, e.g. a zero seed). ``"literal"``: Appendix A as written, every
        evaluation without a new champion counts (about 30% of zero-seeded runs then stop while
        the whole population still crashes). When the champion never crashed, or no crash
        flags are told, both rules give bit-identical runs.
    selection : {"roulette", "tournament"}
        Parent selection: ``"roulette"`` (default, Appendix A) or ``"tournament"`` (the best of
        ``tournament_size`` distinct genomes drawn uniformly; the authors' ``eonn`` code).
    tournament_size : int
        Genomes per tournament (``1 <= tournament_size <= pop_size``; default 5, as in ``eonn``).
    init_mutate_frac, init_mutate_std : float or None
        Mutation of the prototype's copies in the initial population; None (default): as
        ``mutate_frac`` / ``mutate_std`` (Appendix A). ``eonn`` used 0.5 and 0.5.
    mutation_floor : float or None
        None (default): Appendix A's mutation, the same absolute size for every gene. A number
        > 0: gene i's perturbation (and replacement value) is scaled by
        ``max(|prototype gene i|, mutation_floor)`` (an experimental deviation: from the baseline
        seed, the paper's N(0, 0.8) cannot move gains of size 0.02 smoothly; see
        docs/reproduction/discussion/fig2-paper.md).
    """

    pop_size: int = 50
    elite_size: int = 49
    crossover_prob: float = 0.5
    averaging_prob: float = 0.5
    mutate_prob: float = 0.75
    mutate_frac: float = 0.1
    mutate_std: float = 0.8
    mutate_repl: float = 0.25
    plateau_threshold: int = 1000
    budget: int | None = None
    plateau_rule: str = "no-crash"
    selection: str = "roulette"
    tournament_size: int = 5
    init_mutate_frac: float | None = None
    init_mutate_std: float | None = None
    mutation_floor: float | None = None

    def __post_init__(self) -> None:
        _validate_common(self)
        if self.mutation_floor is not None:
            floor = self.mutation_floor
            if isinstance(floor, bool) or not isinstance(floor, (int, float)) or not (math.isfinite(floor) and floor > 0):
                raise NeurohoverError(f"mutation_floor={floor!r} is out of range: allowed None or a finite number > 0")
            _normalise(self, "mutation_floor", float(floor))
        if not isinstance(self.plateau_rule, str) or self.plateau_rule not in PLATEAU_RULES:
            raise NeurohoverError(
                f"unknown plateau_rule {self.plateau_rule!r}: allowed {', '.join(PLATEAU_RULES)}"
            )
        if not isinstance(self.selection, str) or self.selection not in SELECTIONS:
            raise NeurohoverError(
                f"unknown selection {self.selection!r}: allowed {', '.join(SELECTIONS)}"
            )
        size = _require_int("tournament_size", self.tournament_size, 1)
        if size > self.pop_size:
            raise ValueError(f"tournament_size={size} must be in [1, pop_size={self.pop_size}]")
        _normalise(self, "tournament_size", size)
        if self.init_mutate_frac is not None:
            _normalise(self, "init_mutate_frac", _require_prob("init_mutate_frac", self.init_mutate_frac))
        if self.init_mutate_std is not None:
            _normalise(self, "init_mutate_std", _require_std("init_mutate_std", self.init_mutate_std))
        elite = _require_int("elite_size", self.elite_size, 0)
        if elite >= self.pop_size:
            raise ValueError(f"elite_size={elite} must be smaller than pop_size={self.pop_size}")
        _normalise(self, "elite_size", elite)
        _normalise(
            self, "plateau_threshold", _require_int("plateau_threshold", self.plateau_threshold, 1)
        )


@dataclass(frozen=True)
class GenerationalSettings:
    """Settings of :class:`GenerationalNE`; defaults are the paper's Table 7.

    Attributes
    ----------
    pop_size : int
        Population size lambda (>= 2).
    select_size : int
        Parents selected per generation, mu (``1 <= select_size <= pop_size``).
    generations : int
        Number of generations to run (>= 1).
    crossover_prob, averaging_prob, mutate_prob, mutate_frac, mutate_std, mutate_repl
        As in :class:`SteadyStateSettings` (``crossover_prob`` is 1 in the paper).
    budget : int or None
        Optional cap on the total number of episodes (>= 1); not in the paper.
    elitist : bool
        True (default): the ``select_size`` selected parents survive into the next generation,
        where they are evaluated again on fresh episodes, beside ``pop_size - select_size``
        offspring. False: every generation is ``pop_size`` new offspring (no survivors), the
        literal reading of Appendix B. With the paper's mutation strength the non-elitist
        variant loses its progress: on FGHH (sigma 0.3, fixed resampling k=5, MLP from the
        baseline seed) its generation champion fell from about -1,800 to -66,000 in 20
        generations, while the elitist variant rose to about -780 (and -330 with races).
    """

    pop_size: int = 50
    select_size: int = 20
    generations: int = 4000
    crossover_prob: float = 1.0
    averaging_prob: float = 0.5
    mutate_prob: float = 0.75
    mutate_frac: float = 0.1
    mutate_std: float = 0.8
    mutate_repl: float = 0.25
    budget: int | None = None
    elitist: bool = True

    def __post_init__(self) -> None:
        _validate_common(self)
        if not isinstance(self.elitist, bool):
            raise ValueError(f"elitist={self.elitist!r} must be True or False")
        sel = _require_int("select_size", self.select_size, 1)
        if sel > self.pop_size:
            raise ValueError(
                f"select_size={sel} must be in [1, pop_size={self.pop_size}]"
            )
        _normalise(self, "select_size", sel)
        _normalise(self, "generations", _require_int("generations", self.generations, 1))


# --------------------------------------------------------------------------- records


@dataclass(frozen=True)
class ChampionRecord:
    """A new champion: evaluations done so far, its return, seconds since the start, and whether
    its evaluation crashed (as told to ``SteadyStateNE.tell``; False without crash flags)."""

    evaluations: int
    champion_return: float
    wall_seconds: float
    crashed: bool = False


@dataclass(frozen=True)
class GenerationRecord:
    """One generation of :class:`GenerationalNE`.

    Attributes
    ----------
    generation : int
        1-based generation number.
    evaluations : int
        Cumulative episodes spent up to and including this generation.
    episodes : int
        Episodes spent in this generation (e.g. a race's ``episodes_spent``).
    champion_return : float
        Best estimated fitness in this generation.
    wall_seconds : float
        Seconds since the start of the run.
    """

    generation: int
    evaluations: int
    episodes: int
    champion_return: float
    wall_seconds: float


# --------------------------------------------------------------------------- helpers


def _enc_float(x: float) -> float | str:
    x = float(x)
    if math.isfinite(x):
        return x
    return "nan" if math.isnan(x) else ("inf" if x > 0 else "-inf")


def _enc_array(a: np.ndarray | None) -> dict[str, Any] | None:
    if a is None:
        return None
    a = np.asarray(a, dtype=np.float64)
    return {"shape": list(a.shape), "data": [_enc_float(v) for v in a.ravel()]}


def _dec_array(d: dict[str, Any] | None) -> np.ndarray | None:
    if d is None:
        return None
    return np.array([float(v) for v in d["data"]], dtype=np.float64).reshape(d["shape"])


def _rng_from_state(state: dict[str, Any]) -> np.random.Generator:
    bit_generator = getattr(np.random, state["bit_generator"])()
    bit_generator.state = state
    return np.random.Generator(bit_generator)


def _check_version(state: dict[str, Any], kind: str) -> None:
    if state.get("type") != kind:
        raise ValueError(f"state dict is for {state.get('type')!r}, not {kind!r}")
    if state.get("version") != _STATE_VERSION:
        raise ValueError(f"unsupported state version {state.get('version')!r}")


def _check_prototype(prototype: np.ndarray) -> np.ndarray:
    p = np.array(prototype, dtype=np.float64)
    if p.ndim != 1 or p.size == 0:
        raise ValueError(f"prototype must be a non-empty 1-D genome, got shape {p.shape}")
    if not np.all(np.isfinite(p)):
        raise ValueError("prototype must be finite")
    return p


def _check_returns(values: Any, n: int, what: str = "fitness") -> np.ndarray:
    f = np.array(values, dtype=np.float64)
    if f.shape != (n,):
        raise ValueError(
            f"{what} must have shape ({n},), one return per asked genome; got shape {f.shape}"
        )
    if np.count_nonzero(f == np.inf):
        raise ValueError(f"{what} contains +inf; returns must be finite, NaN or -inf")
    return f


def _rank(returns: np.ndarray) -> np.ndarray:
    """Indices best first; NaN/-inf last; ties keep their order (deterministic)."""
    key = np.fmax(returns, -np.inf)  # NaN -> -inf
    return (-key).argsort(kind="stable")


def roulette_weights(returns: np.ndarray) -> np.ndarray:
    """Positive roulette-wheel weights ``1 / ln(error)`` with ``error = -return``.

    This is the transform of the original code. Errors are clamped to at least
    :data:`ROULETTE_ERROR_FLOOR` (slightly above 1) so that every finite
    return gets a finite positive weight; NaN / ``-inf`` returns get weight 0
    (never picked unless every weight is 0, in which case all get weight 1).

    Parameters
    ----------
    returns : np.ndarray
        Returns of the population (maximised; normally negative).

    Returns
    -------
    np.ndarray
        Non-negative weights, same shape.
    """
    r = np.asarray(returns, dtype=np.float64)
    error = np.maximum(-r, ROULETTE_ERROR_FLOOR)
    w = np.divide(1.0, np.log(error), out=np.zeros(r.shape), where=np.isfinite(r))
    if not np.count_nonzero(w):
        w = np.ones_like(r)
    return w


def _spin(cdf: list[float], rng: np.random.Generator) -> int:
    """Spin the roulette wheel given the cumulative weights (a list: bisecting a list is much
    faster than ``np.searchsorted`` for a single value)."""
    return min(bisect_right(cdf, rng.random() * cdf[-1]), len(cdf) - 1)


def _initial_population(
    prototype: np.ndarray, n: int, rng: np.random.Generator, settings: Any, scale: np.ndarray | None = None
) -> np.ndarray:
    # Appendix A: the prototype plus copies of it, each put through the
    # mutation operator once (unconditionally, i.e. not gated by mutate_prob).
    return np.vstack([prototype] + [_mutate(prototype, rng, settings, scale) for _ in range(n - 1)])


def _mutate(genome: np.ndarray, rng: np.random.Generator, settings: Any, scale: np.ndarray | None) -> np.ndarray:
    """``mutate`` with the optional per-gene scale (the plain call when there is none)."""
    return mutate(genome, rng, settings) if scale is None else mutate(genome, rng, settings, scale)


class _Clock:
    """Wall-clock seconds since the start of a run, continued across checkpoints."""

    def __init__(self, elapsed: float = 0.0) -> None:
        self._start = time.perf_counter() - elapsed

    def __call__(self) -> float:
        return time.perf_counter() - self._start


class _ChampionTracker:
    """Best single return ever told, evaluations since it, and its history.

    The champion's crash flag is its history record's (the last one): it is fixed for the
    champion's lifetime, so the ``no-crash`` plateau count is ``since`` or 0 (:meth:`plateau`)
    and needs no state of its own.
    """

    def __init__(self) -> None:
        self.evaluations = 0
        self.genome: np.ndarray | None = None
        self.best = -math.inf
        self.since = 0
        self.history: list[ChampionRecord] = []

    def update(
        self, genomes: np.ndarray, returns: np.ndarray, wall: float, crashed: np.ndarray | None = None
    ) -> None:
        for k, (g, r) in enumerate(zip(genomes, returns)):
            self.evaluations += 1
            if r > self.best:  # strict; NaN compares False
                self.best = float(r)
                self.genome = np.array(g, dtype=np.float64)
                self.since = 0
                hit = crashed is not None and bool(crashed[k])
                self.history.append(ChampionRecord(self.evaluations, self.best, wall, hit))
            else:
                self.since += 1

    @property
    def champion_crashed(self) -> bool:
        return bool(self.history) and self.history[-1].crashed

    def plateau(self, literal: bool) -> int:
        """Evaluations counted towards the plateau: all since the champion (``literal``), or
        only while the champion's evaluation did not crash (``no-crash``)."""
        return self.since if literal or not self.champion_crashed else 0

    def to_dict(self) -> dict[str, Any]:
        return {
            "evaluations": self.evaluations,
            "genome": _enc_array(self.genome),
            "best": _enc_float(self.best),
            "since": self.since,
            "history": [  # a 4th element only for a crashed champion (the format stays as it was)
                [h.evaluations, _enc_float(h.champion_return), h.wall_seconds]
                + ([True] if h.crashed else [])
                for h in self.history
            ],
        }

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> _ChampionTracker:
        t = cls()
        t.evaluations = int(d["evaluations"])
        t.genome = _dec_array(d["genome"])
        t.best = float(d["best"])
        t.since = int(d["since"])
        t.history = [
            ChampionRecord(int(h[0]), float(h[1]), float(h[2]), bool(h[3]) if len(h) > 3 else False)
            for h in d["history"]
        ]
        return t


# --------------------------------------------------------------------------- steady state


class ChampionViews:
    """Read-outs of an optimiser's champion tracking (shared by SteadyStateNE and CMAES)."""

    _tracker: _ChampionTracker

    @property
    def evaluations(self) -> int:
        """Number of returns told so far."""
        return self._tracker.evaluations

    @property
    def champion_genome(self) -> np.ndarray | None:
        """Genome with the best single return ever told (None before any finite return)."""
        return None if self._tracker.genome is None else self._tracker.genome.copy()

    @property
    def champion_return(self) -> float:
        """Best single return ever told (``-inf`` before any finite return)."""
        return self._tracker.best

    @property
    def evaluations_since_champion(self) -> int:
        """Evaluations told since the current champion appeared."""
        return self._tracker.since

    @property
    def champion_crashed(self) -> bool:
        """Whether the champion's evaluation was told as crashed (False without crash flags)."""
        return self._tracker.champion_crashed

    @property
    def history(self) -> list[ChampionRecord]:
        """One record per new champion, in order."""
        return list(self._tracker.history)


class SteadyStateNE(ChampionViews):
    """Steady-state neuroevolution of Appendix A (GHH-08/09), ask/tell, maximising.

    The first :meth:`ask` returns the initial population: the prototype itself
    plus ``pop_size - 1`` copies each mutated once by :func:`mutate`. Every
    later :meth:`ask` returns the ``pop_size - elite_size`` offspring of one
    generation (one with the paper's settings). On :meth:`tell` the
    ``elite_size`` best of the current population are kept and the told
    offspring replace the rest.

    Each offspring is, with probability ``crossover_prob``, the crossover of
    two parents chosen by roulette wheel (two independent spins, so both may
    be the same genome), then mutated with probability ``mutate_prob``;
    otherwise it is a mutated copy of one roulette-selected parent. Parents
    are drawn from the whole current (evaluated) population, with weights
    :func:`roulette_weights` (``1/ln(-return)``).

    The champion is the genome with the best single return ever told; the
    run stops (:meth:`stop`) when ``plateau_threshold`` evaluations passed
    without a strictly better one, or when ``budget`` evaluations were done
    (checked between batches, so the initial population may overshoot a
    budget smaller than ``pop_size``). Under the default ``plateau_rule``
    ``"no-crash"`` an evaluation counts towards the plateau only while the
    champion's own evaluation did not crash (``tell(..., crashed=...)``); see
    :class:`SteadyStateSettings`.

    Parameters
    ----------
    prototype : np.ndarray
        1-D genome the initial population is built from.
    settings : SteadyStateSettings, optional
        Defaults to the paper's Table 6.
    seed : int, default 0
        Seed of the optimiser's own ``numpy.random.Generator``.

    Examples
    --------
    >>> opt = SteadyStateNE(np.zeros(3), SteadyStateSettings(budget=200), seed=1)
    >>> while not opt.stop():
    ...     genomes = opt.ask()
    ...     opt.tell(-np.sum((genomes - 1.0) ** 2, axis=1) - 1.0)
    >>> opt.champion_return > -4.0
    True
    """

    def __init__(
        self,
        prototype: np.ndarray,
        settings: SteadyStateSettings | None = None,
        seed: int = 0,
    ) -> None:
        self.settings = settings if settings is not None else SteadyStateSettings()
        self._prototype = _check_prototype(prototype)
        floor = self.settings.mutation_floor
        self._scale = None if floor is None else np.maximum(np.abs(self._prototype), floor)
        self._rng = np.random.default_rng(seed)
        self._population: np.ndarray | None = None
        self._fitness: np.ndarray | None = None
        self._pending: np.ndarray | None = None
        self._generation = 0
        self._tracker = _ChampionTracker()
        self._clock = _Clock()

    # ----------------------------------------------------------------- ask/tell

    def ask(self) -> np.ndarray:
        """Return the genomes to evaluate next, shape ``(n, D)``.

        Raises
        ------
        RuntimeError
            If the previous batch has not been told yet.
        """
        if self._pending is not None:
            raise RuntimeError("ask() called again before tell() of the previous batch")
        if self._population is None:
            s = self.settings
            init = s
            if s.init_mutate_frac is not None or s.init_mutate_std is not None:
                init = dataclasses.replace(
                    s,
                    mutate_frac=s.mutate_frac if s.init_mutate_frac is None else s.init_mutate_frac,
                    mutate_std=s.mutate_std if s.init_mutate_std is None else s.init_mutate_std,
                )
            batch = _initial_population(self._prototype, s.pop_size, self._rng, init, self._scale)
        else:
            batch = self._breed(self.settings.pop_size - self.settings.elite_size)
        self._pending = batch
        return batch.copy()

    def tell(self, fitness: np.ndarray, crashed: np.ndarray | None = None) -> None:
        """Report the returns of exactly the genomes of the last :meth:`ask`.

        Parameters
        ----------
        fitness : np.ndarray
            One return per asked genome (maximised; NaN/-inf rank worst).
        crashed : np.ndarray of bool, optional
            Whether each genome's evaluation crashed (with a mean over several episodes: whether
            any of them crashed). Only the ``no-crash`` plateau rule uses it; None: no crash.
        """
        if self._pending is None:
            raise RuntimeError("tell() called without a pending ask()")
        f = _check_returns(fitness, len(self._pending))
        if crashed is not None:
            c = np.asarray(crashed)
            if c.shape != f.shape or not (c.dtype == np.bool_ or np.issubdtype(c.dtype, np.integer)):
                raise ValueError(
                    f"crashed must be {f.size} booleans, one per asked genome; got {crashed!r}"
                )
            crashed = c.astype(bool)
        if self._population is None:
            self._population, self._fitness = self._pending, f
        else:
            keep = _rank(self._fitness)[: self.settings.elite_size]
            self._population = np.concatenate((self._population.take(keep, axis=0), self._pending))
            self._fitness = np.concatenate((self._fitness.take(keep), f))
        self._tracker.update(self._pending, f, self._clock(), crashed)
        self._pending = None
        self._generation += 1

    def stop(self) -> bool:
        """True once the plateau threshold (counted by ``plateau_rule``) or the budget is reached."""
        s = self.settings
        if self._tracker.evaluations == 0:
            return False
        if self._tracker.plateau(s.plateau_rule == "literal") >= s.plateau_threshold:
            return True
        return s.budget is not None and self._tracker.evaluations >= s.budget

    def _breed(self, n: int) -> np.ndarray:
        s, rng, pop = self.settings, self._rng, self._population
        if s.selection == "tournament":
            key = np.fmax(self._fitness, -np.inf)  # NaN ranks worst
            size = len(pop)

            def pick() -> int:
                entrants = rng.choice(size, s.tournament_size, replace=False)
                return int(entrants[np.argmax(key[entrants])])  # ties: the first drawn
        else:
            cdf = roulette_weights(self._fitness).cumsum().tolist()

            def pick() -> int:
                return _spin(cdf, rng)
        children = np.empty((n, pop.shape[1]))
        for c in range(n):
            if rng.random() < s.crossover_prob:
                child = crossover(pop[pick()], pop[pick()], rng, s)
                if rng.random() < s.mutate_prob:
                    child = _mutate(child, rng, s, self._scale)
            else:
                child = _mutate(pop[pick()], rng, s, self._scale)
            children[c] = child
        return children

    # ----------------------------------------------------------------- read-outs

    @property
    def plateau_evaluations(self) -> int:
        """Evaluations the plateau rule has counted since the current champion appeared (equal
        to :attr:`evaluations_since_champion`, or 0 while the champion's evaluation crashed under
        the ``no-crash`` rule)."""
        return self._tracker.plateau(self.settings.plateau_rule == "literal")

    @property
    def dim(self) -> int:
        """Genome length D."""
        return self._prototype.size

    @property
    def generation(self) -> int:
        """Number of :meth:`tell` calls so far (the initial population is generation 1)."""
        return self._generation

    @property
    def population(self) -> np.ndarray | None:
        """Current evaluated population ``(pop_size, D)`` (None before the first tell)."""
        return None if self._population is None else self._population.copy()

    @property
    def fitness(self) -> np.ndarray | None:
        """Returns of :attr:`population`."""
        return None if self._fitness is None else self._fitness.copy()

    # ----------------------------------------------------------------- checkpoint

    def state_dict(self) -> dict[str, Any]:
        """Plain JSON-serialisable snapshot of the full optimiser state."""
        return {
            "type": "SteadyStateNE",
            "version": _STATE_VERSION,
            "settings": dataclasses.asdict(self.settings),
            "prototype": _enc_array(self._prototype),
            "population": _enc_array(self._population),
            "fitness": _enc_array(self._fitness),
            "pending": _enc_array(self._pending),
            "generation": self._generation,
            "rng": self._rng.bit_generator.state,
            "tracker": self._tracker.to_dict(),
            "wall_seconds": self._clock(),
        }

    @classmethod
    def from_state_dict(cls, state: dict[str, Any]) -> SteadyStateNE:
        """Rebuild an optimiser from :meth:`state_dict`; it continues identically."""
        _check_version(state, "SteadyStateNE")
        # States written before the plateau rule existed followed the literal rule.
        settings = {"plateau_rule": "literal", **state["settings"]}
        opt = cls(_dec_array(state["prototype"]), SteadyStateSettings(**settings))
        opt._population = _dec_array(state["population"])
        opt._fitness = _dec_array(state["fitness"])
        opt._pending = _dec_array(state["pending"])
        opt._generation = int(state["generation"])
        opt._rng = _rng_from_state(state["rng"])
        opt._tracker = _ChampionTracker.from_dict(state["tracker"])
        opt._clock = _Clock(float(state["wall_seconds"]))
        return opt


# --------------------------------------------------------------------------- generational


class GenerationalNE:
    """Generational neuroevolution of Appendix B (FGHH), ask/tell, maximising.

    :meth:`ask` returns the whole population ``(pop_size, D)``; the first one
    is the prototype plus ``pop_size - 1`` mutated copies. :meth:`tell` takes
    one fitness ESTIMATE per genome (a single return, a mean over ``k``
    episodes, or a race's means), selects ``select_size`` parents (the best
    estimates, or the indices a selection race picked) and breeds the next
    population: the selected parents (re-evaluated next generation) plus
    ``pop_size - select_size`` offspring, or, with ``elitist=False``, a complete
    new population (see :class:`GenerationalSettings` for why elitism is the
    default).

    Each child's two parents are drawn uniformly at random, without
    replacement (the same parent twice only if ``select_size`` is 1), from
    the selected parents. The paper does not say how parents are drawn;
    uniform draws use the selection (e.g. a race's) as a set, without
    trusting the noisy estimates a second time.
    With probability ``crossover_prob`` (1 in the paper) the child is their
    crossover, then mutated with probability ``mutate_prob``; otherwise it is
    a mutated copy of the first parent.

    The generation champion is the genome with the best estimate of that
    generation; :attr:`champion_genome` / :attr:`champion_return` refer to the
    latest generation (a best-ever maximum over noisy estimates would be
    optimistically biased). :attr:`history` holds one
    :class:`GenerationRecord` per generation.

    Parameters
    ----------
    prototype : np.ndarray
        1-D genome the initial population is built from.
    settings : GenerationalSettings, optional
        Defaults to the paper's Table 7.
    seed : int, default 0
        Seed of the optimiser's own ``numpy.random.Generator``.
    """

    def __init__(
        self,
        prototype: np.ndarray,
        settings: GenerationalSettings | None = None,
        seed: int = 0,
    ) -> None:
        self.settings = settings if settings is not None else GenerationalSettings()
        self._prototype = _check_prototype(prototype)
        self._rng = np.random.default_rng(seed)
        self._population = _initial_population(
            self._prototype, self.settings.pop_size, self._rng, self.settings
        )
        self._asked = False
        self._generation = 0
        self._evaluations = 0
        self._champion_genome: np.ndarray | None = None
        self._champion_return = -math.inf
        self._history: list[GenerationRecord] = []
        self._clock = _Clock()

    # ----------------------------------------------------------------- ask/tell

    def ask(self) -> np.ndarray:
        """Return the current population, shape ``(pop_size, D)``."""
        if self._asked:
            raise RuntimeError("ask() called again before tell() of the previous population")
        self._asked = True
        return self._population.copy()

    def tell(
        self,
        fitness_estimates: np.ndarray,
        selected: np.ndarray | None = None,
        episodes: int | None = None,
    ) -> None:
        """Report fitness estimates of the asked population and breed the next one.

        Parameters
        ----------
        fitness_estimates : np.ndarray
            ``(pop_size,)`` estimated returns (maximised; NaN/-inf rank worst).
        selected : np.ndarray, optional
            ``select_size`` distinct indices chosen as parents (e.g.
            ``RaceResult.selected``); default: the best estimates.
        episodes : int, optional
            Episodes spent on this generation, recorded in the history
            (e.g. ``RaceResult.episodes_spent``); default ``pop_size``.
        """
        if not self._asked:
            raise RuntimeError("tell() called without a pending ask()")
        s = self.settings
        f = _check_returns(fitness_estimates, s.pop_size, "fitness_estimates")
        order = _rank(f)
        if selected is None:
            sel = order[: s.select_size]
        else:
            sel = self._check_selected(selected)
        ep = s.pop_size if episodes is None else _require_int("episodes", episodes, 0)

        best = int(order[0])
        self._champion_genome = self._population[best].copy()
        self._champion_return = float(f[best]) if not math.isnan(f[best]) else -math.inf
        self._evaluations += ep
        self._generation += 1
        self._history.append(
            GenerationRecord(
                self._generation, self._evaluations, ep, self._champion_return, self._clock()
            )
        )
        self._population = self._breed(self._population[sel])
        self._asked = False

    def tell_race(self, result: RaceResult) -> None:
        """``tell`` with a selection race's means, selection and episode count."""
        self.tell(result.means, selected=result.selected, episodes=result.episodes_spent)

    def tell_resampled(self, result: ResamplingResult) -> None:
        """``tell`` with fixed-resampling means and episode count."""
        self.tell(result.means, episodes=result.episodes_spent)

    def stop(self) -> bool:
        """True after ``generations`` generations or once ``budget`` episodes are spent."""
        s = self.settings
        if self._generation >= s.generations:
            return True
        return s.budget is not None and self._evaluations >= s.budget

    def _check_selected(self, selected: np.ndarray) -> np.ndarray:
        s = self.settings
        sel = np.asarray(selected)
        if (
            sel.ndim != 1
            or sel.size != s.select_size
            or not np.issubdtype(sel.dtype, np.integer)
            or np.unique(sel).size != sel.size
            or sel.min() < 0
            or sel.max() >= s.pop_size
        ):
            raise ValueError(
                f"selected must be {s.select_size} distinct integer indices in "
                f"[0, {s.pop_size}), got {selected!r}"
            )
        return sel

    def _breed(self, parents: np.ndarray) -> np.ndarray:
        s, rng = self.settings, self._rng
        n_par = len(parents)
        children = [parents] if s.elitist else []
        for _ in range(s.pop_size - n_par if s.elitist else s.pop_size):
            i, j = rng.choice(n_par, size=2, replace=False) if n_par >= 2 else (0, 0)
            if rng.random() < s.crossover_prob:
                child = crossover(parents[i], parents[j], rng, s)
                if rng.random() < s.mutate_prob:
                    child = mutate(child, rng, s)
            else:
                child = mutate(parents[i], rng, s)
            children.append(child)
        return np.vstack(children)

    # ----------------------------------------------------------------- read-outs

    @property
    def dim(self) -> int:
        """Genome length D."""
        return self._prototype.size

    @property
    def generation(self) -> int:
        """Generations completed (tells so far)."""
        return self._generation

    @property
    def evaluations(self) -> int:
        """Total episodes spent so far (sum of the per-generation ``episodes``)."""
        return self._evaluations

    @property
    def champion_genome(self) -> np.ndarray | None:
        """Best-estimated genome of the latest generation (None before the first tell)."""
        return None if self._champion_genome is None else self._champion_genome.copy()

    @property
    def champion_return(self) -> float:
        """Best estimate of the latest generation (``-inf`` before the first tell)."""
        return self._champion_return

    @property
    def history(self) -> list[GenerationRecord]:
        """One record per generation."""
        return list(self._history)

    @property
    def population(self) -> np.ndarray:
        """Population to be evaluated next (or being evaluated)."""
        return self._population.copy()

    # ----------------------------------------------------------------- checkpoint

    def state_dict(self) -> dict[str, Any]:
        """Plain JSON-serialisable snapshot of the full optimiser state."""
        return {
            "type": "GenerationalNE",
            "version": _STATE_VERSION,
            "settings": dataclasses.asdict(self.settings),
            "prototype": _enc_array(self._prototype),
            "population": _enc_array(self._population),
            "asked": self._asked,
            "generation": self._generation,
            "evaluations": self._evaluations,
            "champion_genome": _enc_array(self._champion_genome),
            "champion_return": _enc_float(self._champion_return),
            "history": [
                [
                    r.generation,
                    r.evaluations,
                    r.episodes,
                    _enc_float(r.champion_return),
                    r.wall_seconds,
                ]
                for r in self._history
            ],
            "rng": self._rng.bit_generator.state,
            "wall_seconds": self._clock(),
        }

    @classmethod
    def from_state_dict(cls, state: dict[str, Any]) -> GenerationalNE:
        """Rebuild an optimiser from :meth:`state_dict`; it continues identically."""
        _check_version(state, "GenerationalNE")
        opt = cls(_dec_array(state["prototype"]), GenerationalSettings(**state["settings"]))
        opt._population = _dec_array(state["population"])
        opt._asked = bool(state["asked"])
        opt._generation = int(state["generation"])
        opt._evaluations = int(state["evaluations"])
        opt._champion_genome = _dec_array(state["champion_genome"])
        opt._champion_return = float(state["champion_return"])
        opt._history = [
            GenerationRecord(int(g), int(e), int(ep), float(r), float(w))
            for g, e, ep, r, w in state["history"]
        ]
        opt._rng = _rng_from_state(state["rng"])
        opt._clock = _Clock(float(state["wall_seconds"]))
        return opt
