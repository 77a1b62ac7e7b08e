"""Steady-state neuroevolution of the paper's Appendix A (GHH-08/09; docs/model.md, Neuroevolution).

:class:`SteadyStateNE` works on flat genome vectors (network weights) through the ask/tell
interface of :class:`~neurohover.evolution.common.Optimiser`; the caller evaluates the asked
genomes and tells their returns (maximised; see :mod:`neurohover.evolution.common` for the sign
convention and the checkpoint format).
"""

from __future__ import annotations

import dataclasses
from bisect import bisect_right
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import NeurohoverError, brief, finite_real, real_number, setting_float
from .common import (
    ASK_AGAIN,
    MAX_SPREAD,
    STATE_VERSION,
    TELL_FIRST,
    AskTellOrderError,
    ChampionTracker,
    ChampionViews,
    Clock,
    TellInfo,
    as_returns,
    check_entries,
    check_genomes,
    check_prototype,
    check_returns,
    check_settings,
    check_state,
    dec_array,
    enc_array,
    enc_float,
    rank,
    read_count,
    read_entry,
    read_seconds,
    read_settings,
    require_int,
    require_prob,
    require_spread,
    rng_from_state,
    set_field,
    validate_variation_settings,
)
from .fitness import ERROR_FLOOR, episode_fitness
from .operators import crossover, mutate
from .seeding import check_seed

__all__ = [
    "PLATEAU_RULES",
    "ROULETTE_ERROR_FLOOR",
    "SELECTIONS",
    "SteadyStateNE",
    "SteadyStateSettings",
    "roulette_weights",
]

#: Errors (``-return``) are clamped to at least this before ``1/ln(error)`` (:mod:`.fitness`).
ROULETTE_ERROR_FLOOR = ERROR_FLOOR

#: Plateau rules of :class:`SteadyStateSettings` (docs/model.md, Neuroevolution): ``no-crash`` (default) counts
#: evaluations without a new champion only while the champion's own evaluation did not crash;
#: ``literal`` is Appendix A as written (counts every evaluation without a new champion).
PLATEAU_RULES = ("no-crash", "literal")

#: Parent selection of :class:`SteadyStateSettings`: ``roulette`` (Appendix A, weights
#: ``1/ln(error)``) or ``tournament`` (the best of ``tournament_size`` distinct genomes drawn
#: uniformly, as in the authors' ``eonn`` code; docs/model.md, Neuroevolution).
SELECTIONS = ("roulette", "tournament")

#: Genomes per tournament by default (the authors' ``eonn``); the only value roulette selection takes.
TOURNAMENT_SIZE = 5


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
        Standard deviation of the Gaussian mutation, 0 to 1e100 (:data:`~neurohover.evolution.common.MAX_SPREAD`): 0 (none) or from 2**-52.
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
        ``SteadyStateNE.tell(..., TellInfo(crashed=...))``); a population whose champion still crashes
        never stops at the plateau, so such a run ends only at its budget (give one when the
        prototype may crash, e.g. a zero seed). ``"literal"``: Appendix A as written, every
        evaluation without a new champion counts (about 30% of zero-seeded runs then stop while
        the whole population still crashes). When the champion never crashed, or no crash
        flags are told, both rules give bit-identical runs.
    selection : {"roulette", "tournament"}
        Parent selection: ``"roulette"`` (default, Appendix A) or ``"tournament"`` (the best of
        ``tournament_size`` distinct genomes drawn uniformly; the authors' ``eonn`` code).
    tournament_size : int
        Genomes per tournament (``1 <= tournament_size <= pop_size``; default 5, as in ``eonn``); with
        roulette selection another value is refused, as it would be ignored.
    init_mutate_frac, init_mutate_std : float or None
        Mutation of the prototype's copies in the initial population; None (default): as
        ``mutate_frac`` / ``mutate_std`` (Appendix A). ``eonn`` used 0.5 and 0.5.
    mutation_floor : float or None
        None (default): Appendix A's mutation, the same absolute size for every gene. A number
        in (0, 1e100]: gene i's perturbation (and replacement value) is scaled by
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
    tournament_size: int = TOURNAMENT_SIZE
    init_mutate_frac: float | None = None
    init_mutate_std: float | None = None
    mutation_floor: float | None = None

    def __post_init__(self) -> None:
        validate_variation_settings(self)
        if self.mutation_floor is not None:
            floor = self.mutation_floor
            if not real_number(floor) or not (finite_real(floor) and 0 < float(floor) <= MAX_SPREAD):
                raise NeurohoverError(f"mutation_floor={brief(floor)} is out of range: allowed None or a number in (0, {MAX_SPREAD:g}]")
            set_field(self, "mutation_floor", setting_float(floor))  # np.float32(0.3) as 0.3, as every real field (T57-B01)
        if not isinstance(self.plateau_rule, str) or self.plateau_rule not in PLATEAU_RULES:
            raise NeurohoverError(f"unknown plateau_rule {brief(self.plateau_rule)}: allowed {', '.join(PLATEAU_RULES)}")
        if not isinstance(self.selection, str) or self.selection not in SELECTIONS:
            raise NeurohoverError(f"unknown selection {brief(self.selection)}: allowed {', '.join(SELECTIONS)}")
        size = require_int("tournament_size", self.tournament_size, 1)
        if self.selection != "tournament" and size != TOURNAMENT_SIZE:  # ignored without a word (second trial)
            raise NeurohoverError(f"tournament_size={brief(size)} applies to selection='tournament' only, not to selection={brief(self.selection)}")
        if self.selection == "tournament" and size > self.pop_size:  # under roulette the unused default is no limit on pop_size
            raise NeurohoverError(f"tournament_size={brief(size)} must be in [1, pop_size={brief(self.pop_size)}]")
        set_field(self, "tournament_size", size)
        if self.init_mutate_frac is not None:
            set_field(self, "init_mutate_frac", require_prob("init_mutate_frac", self.init_mutate_frac))
        if self.init_mutate_std is not None:
            set_field(self, "init_mutate_std", require_spread("init_mutate_std", self.init_mutate_std))
        elite = require_int("elite_size", self.elite_size, 0)
        if elite >= self.pop_size:
            default = " (its default)" if elite == type(self).elite_size else ""  # a default the user never set, named as such (ninth trial)
            raise NeurohoverError(
                f"elite_size={brief(elite)}{default} must be smaller than pop_size={self.pop_size}: give elite_size below it too (the paper's is pop_size - 1)"
            )
        set_field(self, "elite_size", elite)
        set_field(self, "plateau_threshold", require_int("plateau_threshold", self.plateau_threshold, 1))


#: The settings a state written before a field existed ran with (the class's defaults, but the literal plateau rule).
_OLD_SETTINGS = {
    "plateau_rule": "literal",
    "selection": "roulette",
    "tournament_size": TOURNAMENT_SIZE,
    "init_mutate_frac": None,
    "init_mutate_std": None,
    "mutation_floor": None,
}
#: Every entry a :meth:`SteadyStateNE.state_dict` has held (the format only ever gained entries).
STATE_ENTRIES = ("type", "version", "settings", "prototype", "population", "fitness", "pending", "generation", "rng", "tracker", "wall_seconds")


def roulette_weights(returns: np.ndarray) -> np.ndarray:
    """Positive roulette-wheel weights ``1 / ln(error)`` with ``error = -return``.

    This is the transform of the original code. Errors are clamped to at least
    :data:`ROULETTE_ERROR_FLOOR` (slightly above 1) so that every finite
    return gets a finite positive weight; NaN / ``-inf`` returns get weight 0
    (never picked unless every weight is 0, in which case all get weight 1).
    A ``+inf`` return is refused, as :meth:`SteadyStateNE.tell` refuses it.

    Parameters
    ----------
    returns : np.ndarray
        Returns of the population (maximised; normally negative).

    Returns
    -------
    np.ndarray
        Non-negative weights, same shape.

    Raises
    ------
    NeurohoverError
        ``returns`` that are no non-empty 1-D array of numbers, or hold ``+inf``.
    """
    r = as_returns(returns, "returns", "an array of returns (numbers)")
    r = check_returns(r, r.size, "returns")  # +inf, the best return there is, got weight 0: never picked (T58-B06)
    w = np.where(np.isfinite(r), episode_fitness(r, "inv-log-error"), 0.0)
    if not np.count_nonzero(w):
        w = np.ones_like(r)
    return w


def _spin(cdf: list[float], rng: np.random.Generator) -> int:
    """Spin the roulette wheel given the cumulative weights (a list: bisecting a list is much
    faster than ``np.searchsorted`` for a single value)."""
    return min(bisect_right(cdf, rng.random() * cdf[-1]), len(cdf) - 1)


def _initial_population(prototype: np.ndarray, n: int, rng: np.random.Generator, settings: Any, scale: np.ndarray | None = None) -> np.ndarray:
    # Appendix A: the prototype plus copies of it, each put through the
    # mutation operator once (unconditionally, i.e. not gated by mutate_prob).
    return np.vstack([prototype] + [_mutate(prototype, rng, settings, scale) for _ in range(n - 1)])


def _mutate(genome: np.ndarray, rng: np.random.Generator, settings: Any, scale: np.ndarray | None) -> np.ndarray:
    """``mutate`` with the optional per-gene scale (the plain call when there is none)."""
    return mutate(genome, rng, settings) if scale is None else mutate(genome, rng, settings, scale)


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

    #: :meth:`tell` takes ``crashed=`` flags (the ``no-crash`` plateau rule needs them).

    def __init__(
        self,
        prototype: np.ndarray,
        settings: SteadyStateSettings | None = None,
        seed: int = 0,
    ) -> None:
        self.settings = check_settings(settings, SteadyStateSettings)
        self._prototype = check_prototype(prototype)
        floor = self.settings.mutation_floor
        self._scale = None if floor is None else np.maximum(np.abs(self._prototype), floor)
        self._rng = np.random.default_rng(check_seed(seed))
        self._population: np.ndarray | None = None
        self._fitness: np.ndarray | None = None
        self._pending: np.ndarray | None = None
        self._generation = 0
        self._tracker = ChampionTracker()
        self._clock = Clock()

    # ----------------------------------------------------------------- ask/tell

    def ask(self) -> np.ndarray:
        """Return the genomes to evaluate next, shape ``(n, D)``.

        Raises
        ------
        AskTellOrderError
            If the previous batch has not been told yet (a NeurohoverError and a RuntimeError).
        """
        if self._pending is not None:
            raise AskTellOrderError(ASK_AGAIN.format(what="batch"))
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

    def tell(self, fitness: np.ndarray, info: TellInfo | None = None) -> None:
        """Report the returns of exactly the genomes of the last :meth:`ask`.

        Parameters
        ----------
        fitness : np.ndarray
            One return per asked genome (maximised; NaN/-inf rank worst).
        info : TellInfo, optional
            Its ``crashed`` flags: whether each genome's evaluation crashed (with a mean over
            several episodes: whether any of them crashed). Only the ``no-crash`` plateau rule uses
            them; none: no crash.
        """
        if self._pending is None:
            raise AskTellOrderError(TELL_FIRST)
        f = check_returns(fitness, len(self._pending), info=info)  # and the info's crash flags, one per genome (T21-10)
        crashed = None if info is None or info.crashed is None else np.asarray(info.crashed).astype(bool)
        if self._population is None:
            self._population, self._fitness = self._pending, f
        else:
            assert self._fitness is not None  # set with the population
            keep = rank(self._fitness)[: self.settings.elite_size]
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
        s, rng, pop, fitness = self.settings, self._rng, self._population, self._fitness
        assert pop is not None and fitness is not None  # ask() breeds only after the first tell()
        if s.selection == "tournament":
            key = np.fmax(fitness, -np.inf)  # NaN ranks worst
            size = len(pop)

            def pick() -> int:
                entrants = rng.choice(size, s.tournament_size, replace=False)
                return int(entrants[np.argmax(key[entrants])])  # ties: the first drawn
        else:
            cdf = roulette_weights(fitness).cumsum().tolist()

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
    def prototype(self) -> np.ndarray:
        """The genome the first population was bred from (a copy)."""
        return self._prototype.copy()

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
            "version": STATE_VERSION,
            "settings": dataclasses.asdict(self.settings),
            "prototype": enc_array(self._prototype),
            "population": enc_array(self._population),
            "fitness": enc_array(self._fitness),
            "pending": enc_array(self._pending),
            "generation": self._generation,
            "rng": self._rng.bit_generator.state,
            "tracker": self._tracker.to_dict(),
            "wall_seconds": self._clock(),
        }

    @classmethod
    def from_state_dict(cls, state: dict[str, Any]) -> SteadyStateNE:
        """Rebuild an optimiser from :meth:`state_dict`; it continues identically.

        Raises
        ------
        NeurohoverError
            A state that is not one of :meth:`state_dict`, naming its missing or damaged entry.
        """
        check_state(state, "SteadyStateNE")
        kind = "SteadyStateNE"
        check_entries(state, kind, STATE_ENTRIES)
        # States written before the plateau rule existed followed the literal rule; {} was read as the defaults (T19-09).
        names = tuple(f.name for f in dataclasses.fields(SteadyStateSettings))
        settings = read_entry(state, kind, "settings", lambda s: read_settings(s, SteadyStateSettings, names, _OLD_SETTINGS))
        opt = cls(read_entry(state, kind, "prototype", lambda a: dec_array(a, "prototype")), settings)
        d, n = opt._prototype.size, settings.pop_size
        # Each array's rows as the settings make them: a pop_size that disagreed with the population was run on (sixteenth trial).
        opt._population = read_entry(state, kind, "population", lambda a: check_genomes(dec_array(a, "population"), d, "population", rows=n))
        opt._fitness = read_entry(state, kind, "fitness", lambda a: dec_array(a, "fitness"))
        if (opt._population is None) != (opt._fitness is None) or (opt._fitness is not None and opt._fitness.shape != (n,)):
            raise NeurohoverError(f"fitness has shape {None if opt._fitness is None else opt._fitness.shape}: one return per genome of the population")
        if opt._fitness is not None and np.any(opt._fitness == np.inf):  # tell() refuses +inf
            raise NeurohoverError("fitness holds +inf: returns are finite, NaN or -inf")
        rows = n if opt._population is None else n - settings.elite_size
        opt._pending = read_entry(state, kind, "pending", lambda a: check_genomes(dec_array(a, "pending genomes"), d, "pending genomes", rows=rows))
        opt._generation = read_entry(state, kind, "generation", read_count)
        opt._rng = read_entry(state, kind, "rng", rng_from_state)
        opt._tracker = read_entry(state, kind, "tracker", lambda t: ChampionTracker.from_dict(t, d))
        opt._clock = Clock(read_entry(state, kind, "wall_seconds", read_seconds))
        _check_progress(opt)
        return opt


def steady_state_evaluations(generation: int, pop_size: int, elite_size: int) -> int:
    """The evaluations of a steady-state run after ``generation`` generations: its first is the whole population of
    ``pop_size``, each later one ``pop_size - elite_size`` offspring (pop_size 50, elite 49: generation 1 is 50
    evaluations, generation 15 is 64). The one rule of it: a checkpoint's optimiser state and counters, and a stored
    steady-state unit's generations against its evaluations (T26-B04, T26-B05)."""
    return 0 if generation == 0 else pop_size + (generation - 1) * (pop_size - elite_size)


def _check_progress(opt: SteadyStateNE) -> None:
    """NeurohoverError unless a restored optimiser's generation, evaluations, population and champion agree as
    :meth:`SteadyStateNE.tell` makes them: a generation of 2**70, an all-NaN fitness beside a finite champion and a
    champion's return of -1 below the population's best were taken (T19-08, T19-09)."""
    s, gen, t, what = opt.settings, opt._generation, opt._tracker, "SteadyStateNE state dict"
    evaluations = steady_state_evaluations(gen, s.pop_size, s.elite_size)  # the first batch is the whole population
    if (opt._population is None) != (gen == 0) or t.evaluations != evaluations:
        raise NeurohoverError(
            f"{what} has generation={gen}, tracker evaluations={t.evaluations} and {'no' if opt._population is None else 'a'} population:"
            f" generation {gen} is {evaluations} evaluations (pop_size {s.pop_size}, then {s.pop_size - s.elite_size} a generation),"
            " with a population after the first"
        )
    if opt._fitness is None:
        return
    best = float(np.max(np.fmax(opt._fitness, -np.inf)))  # NaN as -inf, as the tracker ranks it
    if best > t.best or (s.elite_size and best != t.best):  # the elite keeps the champion in the population
        raise NeurohoverError(
            f"{what}'s fitness (best {enc_float(best)}) disagrees with its champion's return {enc_float(t.best)}:"
            f" {'the population keeps the champion' if s.elite_size else 'no return is above the champion'}"
        )
