"""The authors' generational EA (their ``eonn`` package) as their GHH-09 agents ran it on a learned model.

Their ``functions.evolve`` (afcarl/ATAA at 1be44a3, ``helicopter/functions.py``, with the ``eonn`` of
``helicopter/site-packages``) on a learned model, which both their GHH-09 model-based agent and their
hybrid agent call with ``epochs=500``, from their ``baseline.net`` (an SLP with the baseline's gains):

==========================  ===============================================================
their code                   here
==========================  ===============================================================
initial pool                 50 copies of the prototype, all but the first mutated with
                             frac 0.5, std 0.5 (``spawn``), each flown one episode
an episode's fitness         ``1 / ln(error)``, ``error = -return`` (``Evaluator.call``)
a genome's fitness           its one episode's: ``evaluate(pool, feval, evals=1)`` flies only
                             the genomes with no episode yet, so a kept genome keeps the
                             estimate it was first given (``Organism.fitness``)
a generation                 the 49 fittest are kept (``keep = 49``); one child of two
                             tournament winners (5 drawn from the whole pool, the fittest
                             wins), crossover then, with probability 0.75, mutation
                             (frac 0.1, std 0.8, replacement 0.25), flown one episode
result                       after 500 generations, the genome of the highest fitness:
                             550 model episodes in all
==========================  ===============================================================

Every episode has its own noise stream (the i-th episode flown is episode ``i`` of ``seed``), as in
their code, where every call drew fresh gusts. The later ``eonn`` of their 2014 work (``eonn/`` at
the repository's root) flies every kept genome again each generation; their helicopter code did not.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import NeurohoverError, brief, finite_real, setting_float, whole_in
from ..evaluate import PolicyTable, evaluate_jobs
from ..policies import Policy
from ..settings_checks import settings_from_dict
from ..sim.constants import EPISODE_STEPS
from ..tasks import MDP, refuse_drift
from .common import MAX_POPULATION, MAX_SPREAD, require_spread, set_field
from .config import MAX_BUDGET
from .fitness import episode_fitness
from .operators import crossover, mutate
from .seeding import check_seed

__all__ = ["EonnResult", "EonnSettings", "eonn_evolve"]


@dataclass(frozen=True)
class EonnSettings:
    """The authors' ``functions.evolve`` settings (defaults: as their GHH-09 agents called it).

    Attributes
    ----------
    pop_size : int
        Population size (2 to 100,000, :data:`~neurohover.evolution.common.MAX_POPULATION`).
    keep : int
        Genomes kept each generation (the rest replaced by offspring; ``keep < pop_size``).
    generations : int
        Generations to run (1 to 10**10; the episodes they fly, :attr:`episodes`, at most
        :data:`~neurohover.evolution.config.MAX_BUDGET`, 10**10, as ``evolve``'s budget).
    tournament_size : int
        Genomes per tournament that picks a parent.
    mutate_prob : float
        The chance an offspring is mutated (as :class:`~neurohover.evolution.steady_state.SteadyStateSettings`'s).
    mutate_frac : float
        Each gene's chance of mutating in a mutated offspring.
    mutate_std : float
        The spread of a mutation's Gaussian, 0 to 1e100 (:data:`~neurohover.evolution.common.MAX_SPREAD`): 0 (none) or from 2**-52.
    mutate_repl : float
        A mutated gene's chance of being replaced by the Gaussian draw (else the draw is added).
    averaging_prob : float
        Crossover's per-gene chance of averaging the two parents' genes (else one parent's is taken).
    spawn_frac : float
        Each gene's chance of mutating in the prototype's copies that make the initial population.
    spawn_std : float
        The spread of that initial mutation's Gaussian (0 to 1e100, as ``mutate_std``'s).
    """

    pop_size: int = 50
    keep: int = 49
    generations: int = 500
    tournament_size: int = 5
    mutate_prob: float = 0.75
    mutate_frac: float = 0.1
    mutate_std: float = 0.8
    mutate_repl: float = 0.25
    averaging_prob: float = 0.5
    spawn_frac: float = 0.5
    spawn_std: float = 0.5

    def __post_init__(self) -> None:
        # pop_size 10**18 grew the first population without end, as generations would have flown (T50-B04): evolve's bounds
        bounds = {"pop_size": (2, MAX_POPULATION), "keep": (0, 2**63 - 1), "generations": (1, MAX_BUDGET), "tournament_size": (1, 2**63 - 1)}
        for name, (low, high) in bounds.items():
            # whole_in: NumPy's integers too, stored as Python ints, as GenerationalSettings' (T44-B22); 1.5 or True
            # "is not allowed" (a type; it said out of range, T24-11)
            set_field(self, name, whole_in(getattr(self, name), name, low, high, "2**63-1" if high == 2**63 - 1 else f"{high:,}"))
        if self.keep >= self.pop_size:
            raise NeurohoverError(
                f"keep={brief(self.keep)} is out of range: allowed 0..pop_size - 1 = {self.pop_size - 1} (at least one offspring a generation)"
            )
        if self.tournament_size > self.pop_size:
            raise NeurohoverError(f"tournament_size={brief(self.tournament_size)} is out of range: allowed 1..pop_size = {self.pop_size}")
        if self.episodes > MAX_BUDGET:  # evolve's largest budget
            most = (MAX_BUDGET - self.pop_size) // (self.pop_size - self.keep)
            raise NeurohoverError(
                f"generations={brief(self.generations)} is out of range: with pop_size={self.pop_size} and keep={self.keep} it flies "
                f"{self.episodes:,} episodes; allowed at most {MAX_BUDGET:,} episodes (as evolve's budget), so generations in 1..{most:,}"
            )
        for name in ("mutate_prob", "mutate_frac", "mutate_repl", "averaging_prob", "spawn_frac"):
            v = getattr(self, name)
            if not finite_real(v) or not 0.0 <= float(v) <= 1.0:
                raise NeurohoverError(f"{name}={brief(v)} is out of range: allowed a probability in [0, 1]")
            set_field(self, name, setting_float(v))  # a Python float, as GenerationalSettings stores (T44-B22): np.float32(0.3) as 0.3 (T57-B01)
        for name in ("mutate_std", "spawn_std"):  # 10**400 was NumPy's TypeError, 1e308 overflowed the genes (eleventh trial)
            v = getattr(self, name)
            # float(v) compared: np.float32's comparison with MAX_SPREAD cast 1e100 to float32 and warned (T44-B23)
            if not finite_real(v) or not 0.0 <= float(v) <= MAX_SPREAD:
                raise NeurohoverError(f"{name}={brief(v)} is out of range: allowed a number in [0, {MAX_SPREAD:g}] (a larger one overflows the genes)")
            set_field(self, name, require_spread(name, v))  # -0.0 as 0.0: NumPy's normal() refused it mid-run (fourteenth trial)

    @property
    def episodes(self) -> int:
        """Episodes a run flies: the first pool, then the offspring of every generation."""
        return self.pop_size + self.generations * (self.pop_size - self.keep)


@dataclass(frozen=True)
class EonnResult:
    """The champion (highest fitness at the end), its ``1/ln(error)``, and the episodes flown."""

    champion: Policy
    fitness: float
    episodes: int


def _child(pool: np.ndarray, fitness: np.ndarray, rng: np.random.Generator, s: EonnSettings) -> np.ndarray:
    """One offspring: crossover of two tournament winners, then mutation with probability ``mutate_prob``."""
    mom, dad = (max(rng.choice(len(pool), s.tournament_size, replace=False), key=lambda i: fitness[i]) for _ in range(2))
    child = crossover(pool[mom], pool[dad], rng, s)
    return mutate(child, rng, s) if rng.random() < s.mutate_prob else child


def _check_arguments(mdp: object, prototype: object, settings: object) -> EonnSettings:
    """:func:`eonn_evolve`'s settings as an :class:`EonnSettings`, once ``mdp`` and ``prototype`` are checked."""
    if not isinstance(mdp, MDP):
        raise NeurohoverError(f"mdp={brief(mdp)} is not allowed: eonn_evolve flies one MDP (an MDP of a task, or a learned model's .mdp())")
    refuse_drift(mdp, "eonn_evolve")
    if not isinstance(prototype, Policy):
        raise NeurohoverError(f"prototype={brief(prototype)} is not allowed: give a Policy (e.g. neurohover.baseline_policy())")
    if settings is None:
        return EonnSettings()
    if isinstance(settings, Mapping):
        return settings_from_dict(EonnSettings, settings, unknown_what="eonn", bad_what="eonn settings")
    if not isinstance(settings, EonnSettings):
        raise NeurohoverError(f"settings={brief(settings)} is not allowed: give an EonnSettings, a dict of its fields or None (its defaults)")
    return settings


def eonn_evolve(
    mdp: MDP,
    prototype: Policy,
    *,
    settings: EonnSettings | Mapping[str, Any] | None = None,
    seed: int = 0,
    n_steps: int = EPISODE_STEPS,
    threads: int | None = 1,
    device: str = "cpu",
) -> EonnResult:
    """Evolve a policy of ``prototype``'s topology on ``mdp`` as the authors' ``eonn`` did (module docstring).

    ``mdp`` is one MDP (a learned model's ``.mdp()`` included), ``prototype`` a :class:`~neurohover.policies.Policy`,
    ``settings`` an :class:`EonnSettings`, a dict of its fields or None (its defaults), as ``evolve_topology`` takes
    its settings; anything else is one NeurohoverError (each was an AttributeError; T44-B21)."""
    s = _check_arguments(mdp, prototype, settings)
    rng = np.random.default_rng(check_seed(seed))
    spawn = dataclasses.replace(s, mutate_frac=s.spawn_frac, mutate_std=s.spawn_std)  # spawn's mutation of the first pool
    start = np.asarray(prototype.genome, dtype=np.float64)
    pool = np.stack([start] + [mutate(start, rng, spawn) for _ in range(s.pop_size - 1)])
    rows = np.array([mdp.row()])
    fitness = np.empty(0)
    episodes = 0
    for gen in range(s.generations + 1):
        if gen:
            children = [_child(pool, fitness, rng, s) for _ in range(s.pop_size - s.keep)]
            kept = np.argsort(-fitness, kind="stable")[: s.keep]
            pool = np.concatenate([np.stack(children), pool[kept]])  # eonn's Pool(offspring + elite)
            fitness = fitness[kept]
        new = pool[: s.pop_size - fitness.size]  # the genomes without an episode yet: the offspring (all of the first pool)
        table = PolicyTable.from_policies([Policy(prototype.topology, g) for g in new])
        n = len(new)
        ev = evaluate_jobs(
            table, rows, np.arange(n), np.zeros(n, dtype=np.int64), episodes + np.arange(n), seed=seed, n_steps=n_steps, threads=threads, device=device
        )
        fitness = np.concatenate([episode_fitness(ev.returns, "inv-log-error"), fitness])
        episodes += n
    best = int(np.argmax(fitness))
    return EonnResult(Policy(prototype.topology, pool[best], {"method": "eonn", "generations": s.generations}), float(fitness[best]), episodes)
