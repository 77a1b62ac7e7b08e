"""Generational neuroevolution of the paper's Appendix B (FGHH; docs/model.md, Neuroevolution).

:class:`GenerationalNE` works on flat genome vectors through the ask/tell interface of
:class:`~neurohover.evolution.common.Optimiser`; the caller tells one fitness ESTIMATE per genome
(a single return, a mean over ``k`` episodes, or a selection race's means, see
:mod:`neurohover.evolution.races`). Returns are maximised; see :mod:`neurohover.evolution.common`
for the sign convention and the checkpoint format.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import NeurohoverError, brief
from .common import (
    ASK_AGAIN,
    MAX_EPISODES,
    STATE_VERSION,
    TELL_FIRST,
    AskTellOrderError,
    Clock,
    EntryError,
    TellInfo,
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
    read_return,
    read_seconds,
    read_settings,
    require_episodes,
    require_int,
    require_prob,
    require_spread,
    required,
    rng_from_state,
    selected_indices,
    set_field,
    validate_variation_settings,
)
from .fitness import FITNESS_SCALES
from .operators import crossover, mutate
from .seeding import check_seed

__all__ = ["GENERATIONAL_PRESETS", "OLD_GENERATIONAL", "GenerationRecord", "GenerationalNE", "GenerationalSettings"]


@dataclass(frozen=True)
class GenerationalSettings:
    """Settings of :class:`GenerationalNE`; defaults are the paper's Table 7 with the authors' FGHH code.

    Attributes
    ----------
    pop_size : int
        Population size lambda (>= 2).
    select_size : int
        Parents selected per generation, mu (``1 <= select_size <= pop_size``).
    generations : int
        Number of generations to run (>= 1).
    crossover_prob : float
        Probability that an offspring is made by crossover, else a mutated copy (1 in the paper).
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
    budget : int or None
        Optional cap on the total number of episodes (>= 1); not in the paper.
    elitist : bool
        False (default, the authors' code and Appendix B): every generation is ``pop_size`` new
        offspring of the selected parents, no survivors. True: the ``select_size`` selected
        parents survive into the next generation, where they are evaluated again on fresh
        episodes, beside ``pop_size - select_size`` offspring.
    fitness : {"inv-log-error", "return"}
        The scale of one episode's fitness (:mod:`neurohover.evolution.fitness`), whose mean over
        a candidate's episodes is its estimate, for fixed resampling and for the races' bounds:
        ``inv-log-error`` (default) is the authors' ``1/ln(error)``, ``return`` the raw return.
        Read by the run that flies the candidates; the optimiser ranks whatever it is told.
    init_mutate_frac, init_mutate_std : float or None
        Mutation of the initial population's copies of the prototype (default 0.5 and 0.5, the
        authors' ``eonn``; None: ``mutate_frac`` / ``mutate_std``).

    :data:`GENERATIONAL_PRESETS` names whole settings: ``table7`` (the defaults), ``authors-script``
    (the sizes of the authors' FGHH script) and ``raw-elitist`` (this library's earlier reading).
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
    elitist: bool = False
    fitness: str = "inv-log-error"
    init_mutate_frac: float | None = 0.5
    init_mutate_std: float | None = 0.5

    def __post_init__(self) -> None:
        validate_variation_settings(self)
        if not isinstance(self.elitist, bool):
            raise NeurohoverError(f"elitist={brief(self.elitist)} must be True or False")
        if not isinstance(self.fitness, str) or self.fitness not in FITNESS_SCALES:  # text first: an array's `in` was NumPy's error (sixteenth trial)
            raise NeurohoverError(f"fitness={brief(self.fitness)} is not a fitness scale: allowed {', '.join(FITNESS_SCALES)}")
        if self.init_mutate_frac is not None:
            set_field(self, "init_mutate_frac", require_prob("init_mutate_frac", self.init_mutate_frac))
        if self.init_mutate_std is not None:
            set_field(self, "init_mutate_std", require_spread("init_mutate_std", self.init_mutate_std))
        sel = require_int("select_size", self.select_size, 1)
        if sel > self.pop_size:
            raise NeurohoverError(f"select_size={brief(sel)} must be in [1, pop_size={brief(self.pop_size)}]")
        set_field(self, "select_size", sel)
        set_field(self, "generations", require_int("generations", self.generations, 1))

    def initial_mutation(self) -> GenerationalSettings:
        """These settings with the initial population's mutation as the mutation."""
        return dataclasses.replace(
            self,
            mutate_frac=self.mutate_frac if self.init_mutate_frac is None else self.init_mutate_frac,
            mutate_std=self.mutate_std if self.init_mutate_std is None else self.init_mutate_std,
        )


#: Named generational settings (``evolve(settings={"preset": NAME, ...})``, configs' ``optimiser``):
#: ``table7``: the paper's Table 7 sizes and mutation, the authors' fitness scale, breeding and
#: initial population (the default); ``authors-script``: the authors' FGHH script (lambda 30, mu 10,
#: their package's mutation defaults frac 0.2 and std 1.0); ``raw-elitist``: mean raw returns,
#: selected parents surviving, the initial copies mutated like offspring (neurohover 0.1's reading).
GENERATIONAL_PRESETS: dict[str, GenerationalSettings] = {
    "table7": GenerationalSettings(),
    "authors-script": GenerationalSettings(pop_size=30, select_size=10, mutate_frac=0.2, mutate_std=1.0),
    "raw-elitist": GenerationalSettings(elitist=True, fitness="return", init_mutate_frac=None, init_mutate_std=None),
}
#: Settings a checkpoint written before a field existed ran with.
#: Every entry a :meth:`GenerationalNE.state_dict` has held ("parents" and "hall_of_fame" since 2026-12-04).
STATE_ENTRIES = (
    "type", "version", "settings", "prototype", "population", "asked", "generation", "evaluations", "champion_genome", "champion_return",
    "parents", "hall_of_fame", "history", "rng", "wall_seconds",
)  # fmt: skip

OLD_GENERATIONAL = {"elitist": True, "fitness": "return", "init_mutate_frac": None, "init_mutate_std": None}


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


class GenerationalNE:
    """Generational neuroevolution of Appendix B (FGHH), ask/tell, maximising.

    :meth:`ask` returns the whole population ``(pop_size, D)``; the first one
    is the prototype plus ``pop_size - 1`` copies mutated with the initial
    mutation (``init_mutate_frac`` / ``init_mutate_std``). :meth:`tell` takes
    one fitness ESTIMATE per genome (a mean over ``k`` episodes, or a race's
    means, on the run's fitness scale), selects ``select_size`` parents (the
    best estimates, or the indices a selection race picked) and breeds the next
    population: ``pop_size`` new offspring (the default, as the authors' code),
    or with ``elitist=True`` the selected parents (re-evaluated next
    generation) plus ``pop_size - select_size`` offspring.

    Each child's two parents are drawn uniformly at random, without
    replacement (the same parent twice only if ``select_size`` is 1), from
    the selected parents, as the authors' FGHH code does (``random.sample``
    of two parents); uniform draws use the selection (e.g. a race's) as a
    set, without trusting the noisy estimates a second time.
    With probability ``crossover_prob`` (1 in the paper) the child is their
    crossover, then mutated with probability ``mutate_prob``; otherwise it is
    a mutated copy of the first parent.

    The generation champion is the selected parent with the best estimate of
    that generation (the authors' ``max(parents)``); :attr:`champion_genome` / :attr:`champion_return` refer to the
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
        self.settings = check_settings(settings, GenerationalSettings)
        self._prototype = check_prototype(prototype)
        self._rng = np.random.default_rng(check_seed(seed))
        # The prototype plus copies of it, each put through the (initial) mutation once, not gated by mutate_prob.
        init = self.settings.initial_mutation()
        self._population = np.vstack([self._prototype] + [mutate(self._prototype, self._rng, init) for _ in range(self.settings.pop_size - 1)])
        self._asked = False
        self._generation = 0
        self._evaluations = 0
        self._champion_genome: np.ndarray | None = None
        self._parents: np.ndarray | None = None  # the last generation's selected parents
        # the run's best generation champions by estimate, best first (at most select_size): a hall of fame
        self._hall: list[tuple[float, np.ndarray]] = []
        self._champion_return = -math.inf
        self._history: list[GenerationRecord] = []
        self._clock = Clock()

    # ----------------------------------------------------------------- ask/tell

    def ask(self) -> np.ndarray:
        """Return the current population, shape ``(pop_size, D)``."""
        if self._asked:
            raise AskTellOrderError(ASK_AGAIN.format(what="population"))
        self._asked = True
        return self._population.copy()

    def tell(
        self,
        fitness_estimates: np.ndarray,
        info: TellInfo | None = None,
        selected: np.ndarray | None = None,
        episodes: int | None = None,
    ) -> None:
        """Report fitness estimates of the asked population and breed the next one.

        Parameters
        ----------
        fitness_estimates : np.ndarray
            ``(pop_size,)`` estimated returns (maximised; NaN/-inf rank worst).
        info : TellInfo, optional
            Its ``selected`` and ``episodes``, as the run tells them (the two below, given directly, win).
        selected : np.ndarray, optional
            ``select_size`` distinct indices chosen as parents (e.g.
            ``RaceResult.selected``); default: the best estimates.
        episodes : int, optional
            Episodes spent on this generation, recorded in the history
            (e.g. ``RaceResult.episodes_spent``); default ``pop_size``.
        """
        if not self._asked:
            raise AskTellOrderError(TELL_FIRST)
        s = self.settings
        f = check_returns(fitness_estimates, s.pop_size, "fitness_estimates", info)
        if info is not None:
            selected = info.selected if selected is None else selected
            episodes = info.episodes if episodes is None else episodes
        order = rank(f)
        if selected is None:
            sel = order[: s.select_size]
        else:
            sel = self._check_selected(selected)
        ep = s.pop_size if episodes is None else require_episodes(episodes)  # 10**30 made evaluations 1e30 (T19-10)
        TellInfo(episodes=ep).check(s.pop_size)  # given directly too: tell(f, episodes=0) never stopped its run (T22-13)

        best = int(sel[rank(f[sel])[0]])  # the best selected parent (a race may select below a discarded mean)
        self._champion_genome = self._population[best].copy()
        self._champion_return = float(f[best]) if not math.isnan(f[best]) else -math.inf
        self._evaluations += ep
        self._generation += 1
        self._history.append(GenerationRecord(self._generation, self._evaluations, ep, self._champion_return, self._clock()))
        self._parents = self._population[sel].copy()
        self._hall = sorted([*self._hall, (self._champion_return, self._champion_genome.copy())], key=lambda h: -h[0])[: s.select_size]
        self._population = self._breed(self._parents)
        self._asked = False

    def stop(self) -> bool:
        """True after ``generations`` generations or once ``budget`` episodes are spent."""
        s = self.settings
        if self._generation >= s.generations:
            return True
        return s.budget is not None and self._evaluations >= s.budget

    def _check_selected(self, selected: np.ndarray) -> np.ndarray:
        """``selected`` as indices of the population (:func:`~neurohover.evolution.common.selected_indices`, which checks
        TellInfo's too), ``select_size`` of them."""
        s = self.settings
        sel = selected_indices(selected, s.pop_size, "selected")
        if sel.size != s.select_size:
            raise NeurohoverError(
                f"selected must be {s.select_size} (select_size) distinct integer indices in 0..{s.pop_size - 1}; got {sel.size}: {brief(selected)}"
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
    def prototype(self) -> np.ndarray:
        """The genome the first population was bred from (a copy)."""
        return self._prototype.copy()

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
    def parents(self) -> np.ndarray | None:
        """The latest generation's ``select_size`` selected parents, one genome a row (None before the first tell)."""
        return None if self._parents is None else self._parents.copy()

    @property
    def hall_of_fame(self) -> np.ndarray | None:
        """The run's best generation champions by their estimates, best first, at most ``select_size`` (a genome a
        row; None before the first tell). Every generation's champion is its best selected parent's estimate."""
        return np.array([g for _, g in self._hall]) if self._hall else None

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
            "version": STATE_VERSION,
            "settings": dataclasses.asdict(self.settings),
            "prototype": enc_array(self._prototype),
            "population": enc_array(self._population),
            "asked": self._asked,
            "generation": self._generation,
            "evaluations": self._evaluations,
            "champion_genome": enc_array(self._champion_genome),
            "champion_return": enc_float(self._champion_return),
            "parents": enc_array(self._parents),
            "hall_of_fame": [[enc_float(r), enc_array(g)] for r, g in self._hall],
            "history": [
                [
                    r.generation,
                    r.evaluations,
                    r.episodes,
                    enc_float(r.champion_return),
                    r.wall_seconds,
                ]
                for r in self._history
            ],
            "rng": self._rng.bit_generator.state,
            "wall_seconds": self._clock(),
        }

    @classmethod
    def from_state_dict(cls, state: dict[str, Any]) -> GenerationalNE:
        """Rebuild an optimiser from :meth:`state_dict`; it continues identically.

        Raises
        ------
        NeurohoverError
            A state that is not one of :meth:`state_dict`, naming its missing or damaged entry.
        """
        check_state(state, "GenerationalNE")
        kind = "GenerationalNE"
        check_entries(state, kind, STATE_ENTRIES)
        names = tuple(f.name for f in dataclasses.fields(GenerationalSettings))  # {}: the defaults were run (T19-09)
        settings = read_entry(state, kind, "settings", lambda s: read_settings(s, GenerationalSettings, names, OLD_GENERATIONAL))
        opt = cls(read_entry(state, kind, "prototype", lambda a: dec_array(a, "prototype")), settings)
        d, n, mu = opt._prototype.size, settings.pop_size, settings.select_size
        # Each array's rows as the settings make them: a pop_size that disagreed with the population was run on (sixteenth trial).
        opt._population = read_entry(  # None was an AttributeError at the first ask() (T19-02)
            state, kind, "population", lambda a: check_genomes(required(dec_array(a, "population"), "population"), d, "population", rows=n)
        )
        opt._asked = read_entry(state, kind, "asked", _flag)
        opt._generation = read_entry(state, kind, "generation", read_count)  # generation -1 was taken (eighth trial)
        opt._evaluations = read_entry(state, kind, "evaluations", read_count)
        opt._champion_genome = read_entry(
            state, kind, "champion_genome", lambda a: check_genomes(dec_array(a, "champion genome"), d, "champion genome", rows=0)
        )
        opt._champion_return = read_entry(state, kind, "champion_return", read_return)  # 'nan' was taken (T19-09)
        # "parents" and "hall_of_fame" are absent from checkpoints written before 2026-12-04
        opt._parents = read_entry(state, kind, "parents", lambda a: check_genomes(dec_array(a, "parents"), d, "parents", rows=mu), None)
        opt._hall = read_entry(
            state,
            kind,
            "hall_of_fame",
            lambda h: [
                (read_return(r), check_genomes(required(dec_array(g, "hall of fame genome"), "hall of fame genome"), d, "hall of fame genome", rows=0))
                for r, g in _rows(h)
            ],
            [],
        )
        opt._history = read_entry(state, kind, "history", lambda h: [_generation_record(g, e, ep, r, w) for g, e, ep, r, w in _rows(h)])
        opt._rng = read_entry(state, kind, "rng", rng_from_state)
        opt._clock = Clock(read_entry(state, kind, "wall_seconds", read_seconds))
        _check_progress(opt)
        return opt


def _rows(value: Any) -> list:
    """A state's list of rows; :class:`~neurohover.evolution.common.EntryError` for a table ({} was read as no rows; T19-09),
    the unpacking's error for other values."""
    if isinstance(value, dict):
        raise EntryError("a table, not a list: allowed a list of rows as state_dict() wrote it")
    return value


def _generation_record(generation: Any, evaluations: Any, episodes: Any, champion_return: Any, wall_seconds: Any) -> GenerationRecord:
    """One :class:`GenerationRecord` of a saved history, each count checked (True and -1 were taken; sixteenth trial; a NaN return, T19-09)."""
    ep = read_count(episodes)
    if ep > MAX_EPISODES:
        raise EntryError(f"episodes={ep} is more than a generation may cost ({MAX_EPISODES:,})")
    return GenerationRecord(read_count(generation), read_count(evaluations), ep, read_return(champion_return), read_seconds(wall_seconds))


def _check_progress(opt: GenerationalNE) -> None:
    """NeurohoverError unless a restored optimiser's history, counts, champion and hall of fame agree as :meth:`GenerationalNE.tell`
    makes them: fewer history rows than generations, a generation of 2**70, and a hall of fame longer than select_size or
    of returns no generation had were taken (T19-08, T19-09)."""
    gen, history, what = opt._generation, opt._history, "GenerationalNE state dict"
    if len(history) != gen:
        raise NeurohoverError(f"{what} has {len(history)} history rows for generation={gen}: one row per generation")
    total = 0
    for number, row in enumerate(history, 1):
        total += row.episodes
        if row.generation != number or row.evaluations != total:
            raise NeurohoverError(
                f"{what}'s history row {number} says generation {row.generation}, evaluations {row.evaluations}: expected generation {number}"
                f" and evaluations {total} (the episodes of its rows so far)"
            )
    if opt._evaluations != total:
        raise NeurohoverError(f"{what} has evaluations={opt._evaluations} where its history's episodes add up to {total}")
    champion = history[-1].champion_return if history else -math.inf
    if (opt._champion_genome is None) != (gen == 0) or opt._champion_return != champion:
        raise NeurohoverError(
            f"{what}'s champion (return {enc_float(opt._champion_return)}, genome {'none' if opt._champion_genome is None else 'given'}) is not"
            f" its last generation's: {'none before the first generation' if gen == 0 else f'return {enc_float(champion)} and a genome'}"
        )
    if opt._parents is not None and gen == 0:
        raise NeurohoverError(f"{what} has parents before its first generation")
    returns = [r for r, _ in opt._hall]
    seen = {row.champion_return for row in history}
    if len(returns) > min(gen, opt.settings.select_size) or returns != sorted(returns, reverse=True) or not seen.issuperset(returns):
        raise NeurohoverError(
            f"{what}'s hall_of_fame returns {brief([enc_float(r) for r in returns])} are not allowed: at most select_size"
            f" ({opt.settings.select_size}) and generation ({gen}) of its generations' champion returns, best first"
        )
    if gen:
        _check_kept(opt, returns, what)


def _check_kept(opt: GenerationalNE, returns: list[float], what: str) -> None:
    """NeurohoverError unless the parents and hall of fame (``returns``, best first) of a restored optimiser past its first
    generation hold its champion as :meth:`GenerationalNE.tell` keeps it: the champion is one of the parents, and it
    entered the hall unless select_size better ones were there ("hall_of_fame": [] beside a champion and its parents
    was taken; T21-11). A checkpoint written before 2026-12-04 has neither (nor does one saved after resuming it but
    before a generation was told): both absent, or null and [], are no contradiction."""
    champion, mu = opt._champion_return, opt.settings.select_size
    if opt._parents is None or not returns:
        if opt._parents is not None or returns:
            given, empty = ("parents", "hall_of_fame is []") if opt._parents is not None else ("hall_of_fame", "parents are null")
            raise NeurohoverError(
                f"{what}'s {empty} at generation={opt._generation} beside its {given} and a champion (return {enc_float(champion)}):"
                " every tell() keeps both, the champion among its parents and in its hall_of_fame (a checkpoint of before"
                " 2026-12-04 has neither)"
            )
        return
    assert opt._champion_genome is not None  # a generation past 0 has a champion (checked above)
    if not any(np.array_equal(parent, opt._champion_genome) for parent in opt._parents):
        raise NeurohoverError(f"{what}'s champion genome is none of its {len(opt._parents)} parents: the champion is its generation's best parent")
    if champion not in returns and not (len(returns) == mu and returns[-1] >= champion):
        raise NeurohoverError(
            f"{what}'s hall_of_fame returns {brief([enc_float(r) for r in returns])} leave out its champion's return {enc_float(champion)}:"
            f" every generation's champion enters the hall, unless select_size ({mu}) better ones are there"
        )


def _flag(value: Any) -> bool:
    """A state's flag: True or False, else :class:`~neurohover.evolution.common.EntryError`."""
    if not isinstance(value, bool):
        raise EntryError("not a flag: allowed true or false")
    return value
