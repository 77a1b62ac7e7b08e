"""A selection race's samples flown through the kernel, each a fixed episode, with the lanes kept busy.

Candidate i's t-th sample of a race of n candidates is slot ``t * n + i``: episode index ``base + slot``
and, on a task family, MDP row ``slot`` (all reserved and drawn when the race starts), so no
result depends on how the samples are grouped into kernel calls. Two ways to keep the SIMD lanes
busy at the end of a call, where a round's few episodes would leave most lanes idle
(docs/performance.md, Selection races):

- **parking** (the CPU lanes): a call flies the samples the round asks for and, in the lanes they
  leave idle, the same candidates' later samples; when the asked-for ones are over, the later ones
  still in flight are parked and resumed by whichever call asks for them
  (:meth:`~neurohover.flyer.KernelFlyer.fly_parked`). A round whose samples are all over already
  needs no call.
- **look-ahead** (elsewhere, e.g. CUDA): the race lists each undecided candidate's next samples at
  once (``selection_race(batch=...)``), and later rounds use them.
"""

from __future__ import annotations

import numba
import numpy as np

from ..flyer import KernelFlyer
from ..launch import Parking
from .fitness import episode_fitness

__all__ = ["RaceSampler"]


class RaceSampler:
    """The ``sample_fn`` of one race (:func:`~neurohover.evolution.races.selection_race`).

    Parameters
    ----------
    flyer : KernelFlyer
        Flies the episodes; ``base`` .. ``base + n * t_limit - 1`` are reserved with it.
    genomes : numpy.ndarray
        ``(n, D)`` the candidates.
    rows : numpy.ndarray
        The MDP rows: ``n * t_limit`` (one per slot) with ``per_slot``, else one row for every sample.
    base : int
        The race's first episode index.
    per_slot : bool
        Whether each slot has its own MDP row.
    fitness : str
        The fitness scale of one episode (:func:`~neurohover.evolution.fitness.episode_fitness`).
    t_limit : int
        The most samples a candidate gets.
    mu : int
        How many candidates the race selects (the parked samples' order: :meth:`_contested_first`).
    look_ahead : int
        The race's look-ahead in episodes per call, where there is no parking.
    parking : Parking or None
        Slots for parked episodes (at least ``n * t_limit``; cleared here), or None for the look-ahead.

    Attributes
    ----------
    batch : int
        The look-ahead to give the race: 0 with parking.
    slot_steps : numpy.ndarray
        Control steps of each slot's sample over (0: not over).
    """

    def __init__(
        self, flyer: KernelFlyer, genomes: np.ndarray, rows: np.ndarray, base: int, per_slot: bool, fitness: str, t_limit: int,
        mu: int, look_ahead: int, parking: Parking | None,
    ) -> None:  # fmt: skip
        n = genomes.shape[0]
        self.flyer, self.genomes, self.rows, self.base, self.per_slot, self.fitness = flyer, genomes, rows, base, per_slot, fitness
        self.n, self.t_limit, self.mu, self.parking = n, t_limit, mu, parking
        self.batch = 0 if parking is not None else look_ahead
        self.asked = np.zeros(n, dtype=np.int64)  # samples asked for per candidate
        self._over = np.zeros(n * t_limit, dtype=bool)
        self._fitness = np.zeros(n * t_limit)
        self.slot_steps = np.zeros(n * t_limit, dtype=np.int64)
        if parking is not None:
            parking.clear()

    def __call__(self, idx: np.ndarray) -> np.ndarray:
        """Each listed candidate's next sample (a candidate listed again: the one after), as fitness."""
        idx = np.asarray(idx, dtype=np.int64)
        listed = np.bincount(idx, minlength=self.n)
        if listed.max() == 1:
            t = self.asked[idx]
        else:  # the q-th listing of candidate i asks for its sample asked[i] + q: rank each listing among its candidate's
            order = np.argsort(idx, kind="stable")
            ranked = idx[order]
            t = np.empty_like(idx)
            t[order] = self.asked[ranked] + np.arange(idx.size) - np.searchsorted(ranked, ranked)
        self.asked += listed
        slots = t * self.n + idx
        if self.parking is None:
            returns = self.flyer.fly(self.genomes, self.rows, idx, slots if self.per_slot else None, slots.shape[0], episode_index=self.base + slots)
            self._keep(slots, returns, self.flyer.job_steps)
        else:
            need = slots[~self._over[slots]]
            if need.size:
                self._fly_parked(need, np.flatnonzero(listed))
        return self._fitness[slots]

    def used(self, n_samples: np.ndarray) -> np.ndarray:
        """The slots a race used, given its ``n_samples`` per candidate (ascending)."""
        t = np.arange(self.t_limit)
        return np.flatnonzero((t[:, None] < n_samples[None, :]).ravel())

    def _fly_parked(self, need: np.ndarray, candidates: np.ndarray) -> None:
        # The optional jobs: the asked candidates' later samples (the race keeps its undecided candidates in
        # lockstep), round by round, most contested first within a round: a candidate the race decides
        # leaves its later samples unused, and one whose mean lies near the selection boundary is decided last.
        t_next = int(self.asked[candidates].max())
        later = (np.arange(t_next, self.t_limit)[:, None] * self.n + self._contested_first(candidates)[None, :]).ravel()
        jobs = np.concatenate([need, later[~self._over[later]]])
        assert self.parking is not None  # _fly_parked is called only with parking
        returns = self.flyer.fly_parked(
            self.genomes, self.rows, jobs % self.n, jobs if self.per_slot else None, self.base + jobs, jobs, need.shape[0], self.parking
        )
        over = self.flyer.job_steps > 0
        self._keep(jobs[over], returns[over], self.flyer.job_steps[over])

    def _contested_first(self, candidates: np.ndarray) -> np.ndarray:
        """The candidates by the distance of their mean from the selection boundary (between the mu-th and
        (mu+1)-th best means of all candidates), in standard errors, nearest first (a speed heuristic)."""
        if self.asked[candidates].min() < 2 or self.n <= self.mu:
            return candidates
        return _contested_order(self._fitness, self.asked, candidates, self.n, self.mu)

    def _keep(self, slots: np.ndarray, returns: np.ndarray, steps: np.ndarray) -> None:
        self._over[slots] = True
        self._fitness[slots] = episode_fitness(returns, self.fitness)
        self.slot_steps[slots] = steps


@numba.njit(cache=True, error_model="numpy")  # x / 0 is inf or NaN, as in NumPy
def _contested_order(fitness, asked, candidates, n, mu):
    """:meth:`RaceSampler._contested_first` in one compiled call (it ran between every two kernel calls of a
    race): each candidate's mean and variance over its samples asked so far (slot ``t * n + i``)."""
    means = np.empty(n)
    var = np.empty(n)
    for i in range(n):
        count = max(asked[i], 1)
        total = 0.0
        for t in range(asked[i]):
            total += fitness[t * n + i]
        means[i] = total / count
        squares = 0.0
        for t in range(asked[i]):
            d = fitness[t * n + i] - means[i]
            squares += d * d
        var[i] = squares / max(count - 1, 1)
    ranked = np.sort(means)[::-1]  # NaN sorts last, so first here, as in NumPy
    boundary = (ranked[mu - 1] + ranked[mu]) / 2.0
    z = np.empty(candidates.shape[0])
    for q in range(candidates.shape[0]):
        i = candidates[q]
        zq = abs(means[i] - boundary) / np.sqrt(var[i] / max(asked[i], 1))
        # As numpy.nan_to_num(z, nan=inf): an undefined distance last, an infinite one just before.
        z[q] = np.inf if np.isnan(zq) else (np.finfo(np.float64).max if zq == np.inf else zq)
    return candidates[np.argsort(z, kind="mergesort")]
