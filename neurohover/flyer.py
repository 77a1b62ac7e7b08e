"""The evolution's fast path through the kernel: batches of one topology's genomes, buffers reused across calls."""

from __future__ import annotations

import sys
from collections.abc import Sequence
from typing import Any

import numba
import numpy as np

from .errors import NeurohoverError, brief, reloaded_text, whole_in, whole_number
from .launch import KIND, MAX_EPISODES_PER_CALL, MAX_SEED, Batch, Flown, Parking, check_device, launch, launch_parked, rows_alike
from .policies import GENOME_LENGTH, TOPOLOGIES, Policy
from .sim.constants import MAX_EPISODE_STEPS, SAFEGUARD_LIMITS
from .sim.kernel import GENOME_WIDTH

__all__ = ["MAX_EPISODE_INDEX", "KernelFlyer", "refuse_other_import"]

#: The last episode index the kernel holds (its episode indices are int64): past it np.add overflowed (T19-01).
MAX_EPISODE_INDEX = 2**63 - 1


class KernelFlyer:
    """Fly batches of one topology's genomes through the kernel with buffers reused across calls.

    The fast path of an evolution run, which flies thousands of small batches: no per-call
    validation, no :class:`Evaluation` objects, no recording and no safeguard. Each call flies its
    jobs with the next unused episode indices (or with indices the caller reserved), so no two
    episodes of one flyer share gust noise; episode ``i`` flies noise stream ``(seed, i)``, so a job's return is
    the one :func:`evaluate_jobs` gives for the same genome, MDP row and episode index.

    Parameters
    ----------
    topology : {"slp", "mlp"}
        Topology of every genome flown.
    seed : int
        Root seed of the episodes' noise streams (0..2**63-1).
    n_steps : int
        Control steps per episode.
    device : {"cpu", "cuda"}
        Where the jobs fly: the CPU kernel (default), or its CUDA build on a GPU (the same gust
        streams; returns agree to within docs/gpu.md's tolerance). Checked here, once.

    Attributes
    ----------
    episodes : int
        Episodes counted so far: every call's jobs, except those of calls with explicit episode
        indices, whose caller counts what it used (:meth:`reserve`). A resumed run sets it, with
        ``next_index``, ``steps`` and ``kernel_seconds``.
    next_index : int
        The next unused episode index (``episodes`` unless indices were reserved).
    flown : int
        Episodes flown to their end so far, counted or not (a race's look-ahead flies some it does not use).
    flown_steps : int
        Control steps flown so far, counted or not, parked episodes' included.
    steps : int
        Control steps of the counted episodes.
    kernel_seconds : float
        Wall time spent inside the kernel.
    crashed : numpy.ndarray of bool
        Crash flags of the last call's jobs (a view like the returns :meth:`fly` gives).
    job_steps : numpy.ndarray of int64
        Control steps of each of the last call's jobs (a view, likewise).
    trace : list or None
        If a list, every :meth:`fly` call appends ``(genomes, rows, policy_index, mdp_index, episode_index)``
        (copies, except the rows), e.g. to replay the same jobs in one batch in a benchmark; a
        caller that flies more than it uses (a race) may replace its calls' entries by what it used.
    """

    def __init__(self, topology: str, seed: int, n_steps: int, device: str = "cpu") -> None:
        check_device(device)
        if topology not in TOPOLOGIES:
            raise NeurohoverError(f"unknown policy topology {topology!r}: allowed {', '.join(TOPOLOGIES)}")
        whole_in(seed, "seed", 0, MAX_SEED, "2**63-1")
        whole_in(n_steps, "n_steps", 1, MAX_EPISODE_STEPS)  # T24-11: 1.5 or True "is not allowed", 0 out of range; np.timedelta64
        self.kind = KIND[topology]
        self.dim = GENOME_LENGTH[topology]
        self.seed = np.uint64(seed)
        self.n_steps = int(n_steps)
        self.device = device
        self.episodes = 0
        self.next_index = 0
        self.flown = 0
        self.flown_steps = 0
        self.steps = 0
        self.kernel_seconds = 0.0
        self.trace: list | None = None
        self.crashed = np.zeros(0, dtype=np.bool_)
        self.job_steps = np.zeros(0, dtype=np.int64)
        self.max_threads = self._threads = 1
        self._p_cap = 0
        self._j_cap = 0
        self._limits = np.asarray(SAFEGUARD_LIMITS, dtype=float)
        self._views: dict[int, tuple] = {}
        self._ensure(64, 512)

    def start(self) -> None:
        """Take the kernel thread count in force now as the most threads to use.

        Call it inside :func:`num_threads`, which restores the count afterwards: :meth:`fly`
        lowers the count to the number of jobs of a smaller call.
        """
        self.max_threads = self._threads = numba.get_num_threads()

    def _ensure(self, n_pol: int, n_jobs: int) -> None:
        if n_pol > self._p_cap:
            self._p_cap = max(n_pol, 2 * self._p_cap)
            self._genomes = np.zeros((self._p_cap, GENOME_WIDTH))
            self._kinds = np.full(self._p_cap, self.kind, dtype=np.int64)
        if n_jobs > self._j_cap:
            self._j_cap = j = max(n_jobs, 2 * self._j_cap)
            self._buffers = (
                np.zeros(j, dtype=np.int64),
                np.arange(j, dtype=np.int64),
                np.zeros(j, dtype=np.int64),
                np.full(j, -1, dtype=np.int64),
                np.zeros(j),
                np.zeros(j, dtype=np.bool_),
                np.zeros(j, dtype=np.int64),
                np.zeros(j, dtype=np.int64),
            )
            self._views = {}

    def _views_for(self, n_jobs: int) -> tuple:
        views = self._views.get(n_jobs)
        if views is None:
            self._ensure(0, n_jobs)
            views = self._views[n_jobs] = tuple(b[:n_jobs] for b in self._buffers)
        return views

    def reserve(self, n: int) -> int:
        """Reserve the next ``n`` episode indices for calls with explicit ``episode_index``; returns the first
        (NeurohoverError where they would pass :data:`MAX_EPISODE_INDEX`, as :meth:`fly` gives)."""
        if not whole_number(n) or n < 0:  # -5 handed out flown indices again, 1.5 a float one (thirteenth trial, F17)
            raise NeurohoverError(f"n={brief(n)} is not allowed: give the number of episode indices to reserve, an integer >= 0")
        n = int(n)
        first = self.next_index
        self._check_room(n)
        self.next_index += n
        return first

    def _check_room(self, n: int) -> None:
        """NeurohoverError unless ``n`` more episode indices from :attr:`next_index` stay within :data:`MAX_EPISODE_INDEX`
        (a resumed next_index of 2**70 was an OverflowError, and 2**63-1 wrapped to negative indices; T19-01)."""
        if self.next_index > MAX_EPISODE_INDEX + 1 - n:
            raise NeurohoverError(
                f"episode indices run out: {n:,} more episodes from index {self.next_index:,} pass the kernel's last episode index 2**63-1; "
                "start a new run instead"
            )

    def _load_genomes(self, genomes: np.ndarray) -> None:
        n_pol = genomes.shape[0]
        if n_pol > self._p_cap:
            self._ensure(n_pol, 0)
        self._genomes[:n_pol, : self.dim] = genomes

    def _set_threads(self, n_jobs: int) -> None:
        # Never more threads than jobs: every thread of a parallel call must check in, and on a busy
        # machine a one-episode call on all cores runs up to 10x slower than on one.
        want = n_jobs if n_jobs < self.max_threads else self.max_threads
        if want != self._threads:
            numba.set_num_threads(want)
            self._threads = want

    def can_park(self, rows: np.ndarray) -> bool:
        """Whether :meth:`fly_parked` can fly jobs on these MDP rows (the CPU lanes: rows alike in substeps and wind)."""
        return self.device == "cpu" and rows_alike(rows)

    def fly(self, genomes: np.ndarray, rows: np.ndarray, policy_index, mdp_index, n_jobs: int, episode_index: np.ndarray | None = None) -> np.ndarray:
        """Fly ``n_jobs`` jobs with the next ``n_jobs`` episode indices (or the given ones).

        Parameters
        ----------
        genomes : numpy.ndarray
            ``(P, D)`` genomes of the flyer's topology.
        rows : numpy.ndarray
            ``(M, MDP_ROW_LEN)`` MDP rows (:func:`mdp_rows`).
        policy_index, mdp_index : numpy.ndarray of int64, None or "range"
            Per job, the genome and the MDP row it flies; None: 0 for every job; ``"range"``:
            job j flies number j.
        n_jobs : int
            The number of jobs, 1..:data:`~neurohover.launch.MAX_EPISODES_PER_CALL`.
        episode_index : numpy.ndarray of int64, optional
            Per job, its episode index, from indices :meth:`reserve` gave: the jobs are then not
            counted in :attr:`episodes` and :attr:`steps` (the caller counts what it uses).

        Returns
        -------
        numpy.ndarray
            The jobs' returns: a view of the flyer's buffer, valid until the next call.
        """
        # whole_in: a Python int (np.int8(5) overflowed in _check_room), at least one job (0 was numba's thread-count error),
        # at most evaluate_jobs' episodes in one call (2**70 was NumPy's "maximum allowed dimension exceeded"); T44-B09
        n_jobs = whole_in(n_jobs, "n_jobs", 1, MAX_EPISODES_PER_CALL, f"{MAX_EPISODES_PER_CALL:,} (episodes in one call)")
        for name, index in (("policy_index", policy_index), ("mdp_index", mdp_index)):  # any other text flew as "range" (T44-B09)
            if isinstance(index, str) and index != "range":
                raise NeurohoverError(f"{name}={brief(index)} is not allowed: give None (0 for every job), 'range' (job j: number j) or an array of indices")
        self._load_genomes(genomes)
        zeros, arange, e, minus, returns, crashed, steps, sg = self._views_for(n_jobs)
        p = zeros if policy_index is None else (arange if isinstance(policy_index, str) else policy_index)
        m = zeros if mdp_index is None else (arange if isinstance(mdp_index, str) else mdp_index)
        if episode_index is None:
            self._check_room(n_jobs)
            np.add(arange, self.next_index, out=e)
        else:
            e[:] = episode_index
        if self.device == "cpu":
            self._set_threads(n_jobs)
        # (CUDA: the launcher copies the inputs to the GPU and the results back on every call,
        # acceptable while a generation's jobs are few; the thread count does not apply.)
        n_pol = genomes.shape[0]  # only the genomes given: the buffer's later rows are stale (a policy_index past them is refused)
        batch = Batch(
            rows, self._kinds[:n_pol], self._genomes[:n_pol], p, m, e, self.seed, self.n_steps, minus, self._limits, minus, safeguard=False, recording=False
        )
        self.kernel_seconds += launch(batch, Flown(returns, crashed, steps, sg), self.device)
        if self.trace is not None:
            self.trace.append((genomes.copy(), rows, p.copy(), m.copy(), e.copy()))
        if episode_index is None:
            self.episodes += n_jobs
            self.next_index += n_jobs
            self.steps += int(steps[0]) if n_jobs == 1 else int(steps.sum())
        self.flown += n_jobs
        self.flown_steps += int(steps.sum())
        self.crashed = crashed
        self.job_steps = steps
        return returns

    def fly_parked(
        self, genomes: np.ndarray, rows: np.ndarray, policy_index: np.ndarray, mdp_index: np.ndarray | None, episode_index: np.ndarray,
        slots: np.ndarray, n_required: int, parking: Parking,
    ) -> np.ndarray:  # fmt: skip
        """Fly the first ``n_required`` jobs to their end and the later ones in the lanes they leave idle,
        parking what is in flight when the required ones are over (:func:`neurohover.launch.launch_parked`).

        Jobs fly reserved episode indices (:meth:`reserve`; not counted in :attr:`episodes`); job j's
        episode is parked in, and resumed from, slot ``slots[j]`` of ``parking``. Only where
        :meth:`can_park` says so.

        Returns
        -------
        numpy.ndarray
            The jobs' returns (a view, valid until the next call); :attr:`job_steps` is 0 for each
            job not over, :attr:`crashed` its crash flags.
        """
        n_jobs = slots.shape[0]
        self._load_genomes(genomes)
        zeros, _, e, minus, returns, crashed, steps, _ = self._views_for(n_jobs)
        e[:] = episode_index
        before = parking.steps[slots]
        self._set_threads(n_jobs)
        m = zeros if mdp_index is None else mdp_index
        n_pol = genomes.shape[0]
        batch = Batch(rows, self._kinds[:n_pol], self._genomes[:n_pol], policy_index, m, e, self.seed, self.n_steps, safeguard=False, recording=False)
        self.kernel_seconds += launch_parked(batch, Flown(returns, crashed, steps, minus), slots, n_required, parking)
        over = steps > 0
        self.flown += int(over.sum())
        self.flown_steps += int(np.where(over, steps, parking.steps[slots]).sum() - before.sum())
        self.crashed = crashed
        self.job_steps = steps
        return returns


def refuse_other_import(policies: Sequence[Any]) -> Sequence[Any]:
    """``policies``, unless one is a Policy of another import of neurohover.policies than the one the package flies: after
    ``importlib.reload(neurohover.policies)`` an earlier Policy was refused as one with "an act of its own" and a fresh one
    as no Policy (T36-B10). Two Policy classes cannot both be flown, so it is refused, by its true cause. (Here, beside
    the kernel's other checks of what it flies: evaluate.py is at the module size limit.)"""
    current = getattr(sys.modules.get(Policy.__module__), "Policy", Policy)
    for p in policies:
        if any(c.__module__ == Policy.__module__ and c.__qualname__ == "Policy" and not (c is Policy is current) for c in type(p).__mro__):
            raise NeurohoverError(f"policy {brief(p)} is not allowed: {reloaded_text(Policy)}")
    return policies
