"""Batched evaluation: fly many (policy, MDP, episode) jobs in parallel through the kernel.

Every episode draws its gust noise from its own stream derived from (seed, episode index), so a
result never depends on batch size, order or thread count. Jobs with the same episode index see
the same noise (common random numbers), which makes comparisons between policies fairer.

Example
-------
>>> from neurohover import evaluate, baseline_policy, get_task_family
>>> ev = evaluate([baseline_policy()], get_task_family("ghh08").training_mdps(), episodes=2, seed=1)
>>> ev.returns.shape            # (policies, MDPs, episodes)
(1, 10, 2)
"""

from __future__ import annotations

import contextlib
import time
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numba
import numpy as np

from .errors import NeurohoverError
from .flightdata import FlightData
from .policies import GENOME_LENGTH, TOPOLOGIES, Policy, load_policy
from .sim.constants import (
    EPISODE_STEPS,
    MDP_ROW_LEN,
    SAFEGUARD_BOX,
    SAFEGUARD_KIND_BOX,
    SAFEGUARD_KIND_RATIO,
    SAFEGUARD_LAYOUT_LEN,
    SAFEGUARD_LIMITS,
    SAFEGUARD_RATIO_LIMITS,
    SAFEGUARD_RATIO_THRESHOLD,
    SAFEGUARD_TILT,
)
from .sim.kernel import GENOME_WIDTH, POLICY_MLP, POLICY_SLP, rollout_batch
from .sim.lanes import LANES, rollout_lanes
from .tasks import MDP

_KIND = {"slp": POLICY_SLP, "mlp": POLICY_MLP}
_MAX_SEED = 2**63 - 1


def as_policies(policies) -> list[Policy]:
    """``policies`` as a list of :class:`Policy`: a Policy, a policy file's path or ``"baseline"``
    (as wherever a policy file is accepted), or a sequence of these; anything else is refused."""

    def one(p) -> Policy:
        if isinstance(p, Policy):
            return p
        if isinstance(p, (str, Path)):
            return load_policy(p)
        raise NeurohoverError(f"policy {p!r} is not allowed: give a Policy, a policy file's path or 'baseline' (or a sequence of these, or a PolicyTable)")

    if isinstance(policies, (Policy, str, Path)):
        return [one(policies)]
    if isinstance(policies, Sequence):
        return [one(p) for p in policies]
    raise NeurohoverError(f"policies={policies!r} is not allowed: give a Policy, a policy file's path or 'baseline' (or a sequence of these, or a PolicyTable)")


@dataclass(frozen=True)
class PolicyTable:
    """Policies as the kernel reads them: a kind per row and genomes padded to 42 columns."""

    kinds: np.ndarray  # (P,) int64
    genomes: np.ndarray  # (P, 42) float64

    @classmethod
    def from_policies(cls, policies: Sequence[Policy]) -> PolicyTable:
        if len(policies) == 0:
            raise NeurohoverError("no policies given: need at least one")
        kinds = np.array([_KIND[p.topology] for p in policies], dtype=np.int64)
        genomes = np.zeros((len(policies), GENOME_WIDTH))
        for i, p in enumerate(policies):
            genomes[i, : p.genome.size] = p.genome
        return cls(kinds, genomes)

    @classmethod
    def from_genomes(cls, genomes: np.ndarray, topology: str) -> PolicyTable:
        """A table of genomes (P, D) of one topology (the evolution fast path)."""
        if topology not in TOPOLOGIES:
            raise NeurohoverError(f"unknown policy topology {topology!r}: allowed {', '.join(TOPOLOGIES)}")
        g = np.asarray(genomes, dtype=float)
        n = GENOME_LENGTH[topology]
        if g.ndim != 2 or g.shape[1] != n or g.shape[0] == 0:
            raise NeurohoverError(f"{topology} genomes must be an array of shape (P >= 1, {n}), got {g.shape}")
        table = np.zeros((g.shape[0], GENOME_WIDTH))
        table[:, :n] = g
        return cls(np.full(g.shape[0], _KIND[topology], dtype=np.int64), table)

    def __len__(self) -> int:
        return self.kinds.shape[0]


@dataclass(frozen=True)
class Evaluation:
    """Outcome of a batch of episodes; arrays share the shape of the jobs.

    Attributes
    ----------
    returns : numpy.ndarray
        Undiscounted return of each episode (minus the paper's "error").
    crashed : numpy.ndarray of bool
    steps : numpy.ndarray of int
        Control steps flown (6000 for a full episode; the crashing step counts).
    safeguard_step : numpy.ndarray of int
        Control step at which the safeguard handed over to the fallback, or -1.
    flight_data : FlightData or None
        Flight data of the recorded episodes, in job order.
    seconds : float
        Wall time of the kernel call (not part of ``==``).
    """

    returns: np.ndarray
    crashed: np.ndarray
    steps: np.ndarray
    safeguard_step: np.ndarray
    flight_data: FlightData | None
    seconds: float = field(compare=False)  # wall-clock, not part of the outcome

    @property
    def episodes(self) -> int:
        return int(self.returns.size)

    @property
    def episodes_per_second(self) -> float:
        return self.episodes / self.seconds if self.seconds > 0 else float("inf")

    def reshape(self, shape: tuple[int, ...]) -> Evaluation:
        return Evaluation(
            self.returns.reshape(shape),
            self.crashed.reshape(shape),
            self.steps.reshape(shape),
            self.safeguard_step.reshape(shape),
            self.flight_data,
            self.seconds,
        )


@contextlib.contextmanager
def num_threads(threads: int | None) -> Iterator[None]:
    """Run the kernel on ``threads`` threads (None: all cores) inside the block."""
    if threads is None:
        yield
        return
    limit = numba.config.NUMBA_NUM_THREADS  # type: ignore[attr-defined]  # numba.config sets it at import, from the environment
    if not isinstance(threads, int) or not 1 <= threads <= limit:
        raise NeurohoverError(f"threads={threads!r} is out of range: allowed 1..{limit} on this machine")
    previous = numba.get_num_threads()
    numba.set_num_threads(threads)
    try:
        yield
    finally:
        numba.set_num_threads(previous)


def mdp_rows(mdps: MDP | Sequence[MDP] | np.ndarray) -> np.ndarray:
    """MDPs as the (M, 29) float64 array the kernel reads."""
    if isinstance(mdps, MDP):
        return mdps.row()[None, :]
    if isinstance(mdps, np.ndarray):
        if mdps.ndim != 2 or mdps.shape[1] != MDP_ROW_LEN or not np.all(np.isfinite(mdps)):
            raise NeurohoverError(f"MDP rows must be a finite array of shape (M, {MDP_ROW_LEN}), got {mdps.shape}")
        return np.ascontiguousarray(mdps, dtype=float)
    if len(mdps) == 0 or not all(isinstance(m, MDP) for m in mdps):
        raise NeurohoverError("mdps must be an MDP or a non-empty sequence of MDPs")
    return np.stack([m.row() for m in mdps])


def _index_array(values, n_jobs: int | None, upper: int | None, what: str) -> np.ndarray:
    arr = np.asarray(values)
    if arr.size and not np.issubdtype(arr.dtype, np.integer):
        raise NeurohoverError(f"{what} must hold integers, got dtype {arr.dtype}")
    arr = arr.astype(np.int64).reshape(-1)
    if n_jobs is not None and arr.shape[0] != n_jobs:
        raise NeurohoverError(f"{what} has {arr.shape[0]} entries but there are {n_jobs} jobs")
    if arr.size and arr.min() < 0:
        raise NeurohoverError(f"{what} holds negative values (min {arr.min()}); allowed >= 0")
    if upper is not None and arr.size and arr.max() >= upper:
        raise NeurohoverError(f"{what} holds {arr.max()}, out of range: allowed 0..{upper - 1}")
    return arr


_kernel_loaded = False


def _load_kernel() -> None:
    """Load (or compile) the kernel with an empty batch, so ``seconds`` times only flying."""
    global _kernel_loaded
    if not _kernel_loaded:
        empty = np.zeros(0, dtype=np.int64)
        rollout_batch(
            np.zeros((1, MDP_ROW_LEN)),
            np.zeros(1, dtype=np.int64),
            np.zeros((1, GENOME_WIDTH)),
            empty,
            empty,
            empty,
            empty,
            np.uint64(0),
            1,
            False,
            SAFEGUARD_LIMITS,
            empty,
            np.zeros((0, 2, 12)),
            np.zeros((0, 1, 4)),
            np.zeros(0),
            np.zeros(0, dtype=np.bool_),
            empty,
            empty,
        )
        _load_lanes()  # with the scalar kernel, so that a warm-up call of either path loads both (about 0.03 s from the cache)
        _kernel_loaded = True


_lanes_loaded = False


def _load_lanes() -> None:
    """Load (or compile) the lanes path with an empty batch, so ``seconds`` times only flying."""
    global _lanes_loaded
    if not _lanes_loaded:
        empty = np.zeros(0, dtype=np.int64)
        rollout_lanes(
            np.zeros((1, MDP_ROW_LEN)),
            np.zeros(1, dtype=np.int64),
            np.zeros((1, GENOME_WIDTH)),
            empty,
            empty,
            empty,
            np.uint64(0),
            1,
            1,
            np.zeros(0),
            np.zeros(0, dtype=np.bool_),
            empty,
            empty,
        )
        _lanes_loaded = True


def _use_lanes(device: str, rows: np.ndarray, m_idx: np.ndarray, fb: np.ndarray | None = None, rec: np.ndarray | None = None) -> bool:
    """Whether the jobs fly in SIMD lanes (:func:`neurohover.sim.lanes.rollout_lanes`) rather than the scalar kernel.

    Any CPU batch of at least LANES jobs (below that a thread's lanes would mostly idle) without
    recording or safeguard (the lanes implement neither); policies and MDP rows may differ per job.
    Restriction: the jobs' rows must share the substep count (learned models 1, true MDPs 10) and
    whether there is wind, because the packed substep loop takes both as constants; per-lane
    values would turn it into per-lane branches that no longer vectorize. Results are the same
    bits either way.
    """
    n_jobs = m_idx.shape[0]
    if device != "cpu" or n_jobs < LANES or (fb is not None and (fb >= 0).any()) or (rec is not None and rec.any()):
        return False
    sub, windy = rows[:, 17], rows[:, 19] != 0.0
    if (sub == sub[0]).all() and (windy == windy[0]).all():
        return True  # every row alike: no need to look at the jobs
    used = np.unique(m_idx)
    return bool((sub[used] == sub[used[0]]).all()) and bool((windy[used] == windy[used[0]]).all())


DEVICES = ("cpu", "cuda")


def check_device(device: str) -> None:
    """Refuse an unknown device, or ``"cuda"`` where no GPU (nor numba's CUDA simulator) is usable.

    Raises
    ------
    NeurohoverError
        With one message that names the problem; ``"cpu"`` never imports numba.cuda.
    """
    if device not in DEVICES:
        raise NeurohoverError(f"device={device!r} is unknown: allowed 'cpu' or 'cuda'")
    if device == "cuda":
        from .sim import cuda as sim_cuda  # numba.cuda is imported only when asked for

        problem = sim_cuda.cuda_problem()
        if problem is not None:
            raise NeurohoverError(
                f"device='cuda' cannot run here: {problem}. It needs an NVIDIA GPU with its driver and "
                "pip install 'neurohover[cuda]' (numba-cuda); NUMBA_ENABLE_CUDASIM=1 runs numba's CUDA simulator instead"
            )


def evaluate_jobs(
    policies: Sequence[Policy] | PolicyTable,
    mdps: MDP | Sequence[MDP] | np.ndarray,
    policy_index,
    mdp_index,
    episode_index,
    *,
    seed: int = 0,
    fallback_index=None,
    safeguard_limits: Sequence[float] | np.ndarray | None = None,
    record=None,
    n_steps: int = EPISODE_STEPS,
    threads: int | None = None,
    device: str = "cpu",
) -> Evaluation:
    """Fly the jobs ``(policy_index[j], mdp_index[j], episode_index[j])`` in parallel.

    Parameters
    ----------
    policies : sequence of Policy or PolicyTable
    mdps : MDP, sequence of MDP, or (M, 29) array of MDP rows
    policy_index, mdp_index, episode_index : array_like of int, shape (J,)
        Which policy flies which MDP, and the episode index that (with ``seed``) fixes the noise.
    seed : int
        Root seed of every episode's noise stream.
    fallback_index : array_like of int, optional
        Per job, the policy the safeguard hands control to (-1: no safeguard for that job).
    safeguard_limits : sequence or array of 24 floats, optional
        The dangerous-state test in the kernel's layout (:meth:`DangerousState.limits`): limits on
        |u|, |v|, |w|, |x|, |y|, |z|, |p|, |q|, |r|, the tilt threshold on qw (inf: no tilt
        condition), the test's kind, the ratio-sum threshold and limits. Default:
        ``DangerousState()``, the authors' GHH-09 test.
    record : array_like of bool, optional
        Per job, whether to record its flight data.
    n_steps : int
        Control steps per episode (6000 in the benchmark).
    threads : int, optional
        Kernel threads (default: all cores). Results do not depend on it. Unused on ``"cuda"``.
    device : {"cpu", "cuda"}
        Where the kernel runs: the CPU kernel, or the CUDA build of the same source on a GPU
        (one thread per job, the same gust streams; returns agree with the CPU's to about 1e-12
        relative, see docs/gpu.md). ``seconds`` then includes the copies to and from the GPU.
    """
    check_device(device)
    table = policies if isinstance(policies, PolicyTable) else PolicyTable.from_policies(policies)
    rows = mdp_rows(mdps)
    if not isinstance(seed, (int, np.integer)) or not 0 <= int(seed) <= _MAX_SEED:
        raise NeurohoverError(f"seed={seed!r} is out of range: allowed an integer in 0..2**63-1")
    if not isinstance(n_steps, (int, np.integer)) or not 1 <= n_steps <= 10**7:
        raise NeurohoverError(f"n_steps={n_steps!r} is out of range: allowed an integer in 1..10000000")
    p_idx = _index_array(policy_index, None, len(table), "policy_index")
    n_jobs = p_idx.shape[0]
    m_idx = _index_array(mdp_index, n_jobs, rows.shape[0], "mdp_index")
    e_idx = _index_array(episode_index, n_jobs, None, "episode_index")
    if fallback_index is None:
        fb = np.full(n_jobs, -1, dtype=np.int64)
    else:
        fb = np.asarray(fallback_index, dtype=np.int64).reshape(-1)
        if fb.shape[0] != n_jobs or (fb.size and (fb.min() < -1 or fb.max() >= len(table))):
            raise NeurohoverError(f"fallback_index must have {n_jobs} entries in -1..{len(table) - 1}")
    limits = SAFEGUARD_LIMITS if safeguard_limits is None else np.asarray(safeguard_limits, dtype=float)
    if limits.shape != (SAFEGUARD_LAYOUT_LEN,) or not np.all(np.delete(limits, 10) > 0) or np.isnan(limits).any() or limits[10] not in (0.0, 1.0):
        raise NeurohoverError(
            f"safeguard_limits must be {SAFEGUARD_LAYOUT_LEN} numbers in the layout of DangerousState.limits() (9 box limits, the tilt "
            f"threshold, the kind 0 or 1, the ratio threshold, 12 ratio limits; all but the kind > 0), got {limits.tolist()}"
        )
    rec = np.zeros(n_jobs, dtype=bool) if record is None else np.asarray(record, dtype=bool).reshape(-1)
    if rec.shape[0] != n_jobs:
        raise NeurohoverError(f"record must have one flag per job ({n_jobs}), got {rec.shape[0]}")
    slots = np.full(n_jobs, -1, dtype=np.int64)
    slots[rec] = np.arange(int(rec.sum()))
    n_rec = int(rec.sum())
    obs_out = np.zeros((n_rec, n_steps + 1, 12))
    act_out = np.zeros((n_rec, n_steps, 4))
    returns = np.empty(n_jobs)
    crashed = np.empty(n_jobs, dtype=np.bool_)
    steps = np.empty(n_jobs, dtype=np.int64)
    sg_step = np.empty(n_jobs, dtype=np.int64)
    if _use_lanes(device, rows, m_idx, fb, rec):
        _load_lanes()
        start = time.perf_counter()
        with num_threads(threads):
            rollout_lanes(
                rows,
                table.kinds,
                table.genomes,
                p_idx,
                m_idx,
                e_idx,
                np.uint64(seed),
                n_steps,
                numba.get_num_threads(),
                returns,
                crashed,
                steps,
                sg_step,
            )
        return Evaluation(returns, crashed, steps, sg_step, None, time.perf_counter() - start)
    rollout: Callable[..., None]  # the CPU kernel (a numba dispatcher) or the CUDA launcher, same arguments
    if device == "cuda":
        from .sim import cuda as sim_cuda  # numba.cuda is imported only when asked for

        sim_cuda.load_kernel()
        rollout = sim_cuda.rollout_batch_cuda
    else:
        _load_kernel()
        rollout = rollout_batch
    start = time.perf_counter()
    with num_threads(threads):
        rollout(
            rows,
            table.kinds,
            table.genomes,
            p_idx,
            m_idx,
            e_idx,
            fb,
            np.uint64(seed),
            n_steps,
            bool((fb >= 0).any()),
            limits,
            slots,
            obs_out,
            act_out,
            returns,
            crashed,
            steps,
            sg_step,
        )
    seconds = time.perf_counter() - start
    flight = None
    if n_rec:
        rec_steps = steps[rec]
        flight = FlightData(
            tuple(obs_out[i, : rec_steps[i] + 1].copy() for i in range(n_rec)),
            tuple(act_out[i, : rec_steps[i]].copy() for i in range(n_rec)),
        )
    return Evaluation(returns, crashed, steps, sg_step, flight, seconds)


def evaluate(
    policies: Policy | Sequence[Policy] | PolicyTable,
    mdps: MDP | Sequence[MDP] | np.ndarray,
    *,
    episodes: int = 1,
    seed: int = 0,
    first_episode: int = 0,
    record: bool = False,
    safeguard: Safeguard | None = None,
    n_steps: int = EPISODE_STEPS,
    threads: int | None = None,
    device: str = "cpu",
) -> Evaluation:
    """Fly every policy on every MDP for ``episodes`` episodes; arrays are shaped (P, M, E).

    Episode e on MDP m has episode index ``first_episode + m * episodes + e`` for every policy,
    so all policies meet the same gusts. ``device="cuda"`` flies them on a GPU (:func:`evaluate_jobs`).
    """
    table = policies if isinstance(policies, PolicyTable) else PolicyTable.from_policies(as_policies(policies))
    rows = mdp_rows(mdps)
    if not isinstance(episodes, (int, np.integer)) or episodes < 1:
        raise NeurohoverError(f"episodes={episodes!r} is out of range: allowed an integer >= 1")
    if not isinstance(first_episode, (int, np.integer)) or first_episode < 0:
        raise NeurohoverError(f"first_episode={first_episode!r} is out of range: allowed an integer >= 0")
    n_pol, n_mdp = len(table), rows.shape[0]
    p_idx, m_idx, e = np.meshgrid(np.arange(n_pol), np.arange(n_mdp), np.arange(episodes), indexing="ij")
    episode_index = first_episode + m_idx * episodes + e
    fallback = None
    limits = None
    if safeguard is not None:
        table = PolicyTable(
            np.append(table.kinds, _KIND[safeguard.fallback.topology]), np.vstack([table.genomes, PolicyTable.from_policies([safeguard.fallback]).genomes])
        )
        fallback = np.full(p_idx.size, n_pol, dtype=np.int64)
        limits = safeguard.dangerous.limits()
    ev = evaluate_jobs(
        table,
        rows,
        p_idx.ravel(),
        m_idx.ravel(),
        episode_index.ravel(),
        seed=seed,
        fallback_index=fallback,
        safeguard_limits=limits,
        record=np.full(p_idx.size, record),
        n_steps=n_steps,
        threads=threads,
        device=device,
    )
    return ev.reshape((n_pol, n_mdp, episodes))


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
        Episodes flown so far, counted or not (a race's look-ahead flies some it does not use).
    steps : int
        Control steps of the counted episodes.
    kernel_seconds : float
        Wall time spent inside the kernel.
    crashed : numpy.ndarray of bool
        Crash flags of the last call's jobs (a view like the returns :meth:`fly` gives).
    job_steps : numpy.ndarray of int64
        Control steps of each of the last call's jobs (a view, likewise).
    trace : list or None
        If a list, every call appends ``(genomes, rows, policy_index, mdp_index, episode_index)``
        (copies, except the rows), e.g. to replay the same jobs in one batch in a benchmark.
    trace_unused : list
        While tracing, the episode indices a caller flew but did not use (a race's look-ahead).
    """

    def __init__(self, topology: str, seed: int, n_steps: int, device: str = "cpu") -> None:
        check_device(device)
        if topology not in TOPOLOGIES:
            raise NeurohoverError(f"unknown policy topology {topology!r}: allowed {', '.join(TOPOLOGIES)}")
        if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or not 0 <= int(seed) <= _MAX_SEED:
            raise NeurohoverError(f"seed={seed!r} is out of range: allowed an integer in 0..2**63-1")
        if isinstance(n_steps, bool) or not isinstance(n_steps, (int, np.integer)) or not 1 <= n_steps <= 10**7:
            raise NeurohoverError(f"n_steps={n_steps!r} is out of range: allowed an integer in 1..10000000")
        self.kind = _KIND[topology]
        self.dim = GENOME_LENGTH[topology]
        self.seed = np.uint64(seed)
        self.n_steps = int(n_steps)
        self.device = device
        self.episodes = 0
        self.next_index = 0
        self.flown = 0
        self.steps = 0
        self.kernel_seconds = 0.0
        self.trace: list | None = None
        self.trace_unused: list[int] = []
        self.crashed = np.zeros(0, dtype=np.bool_)
        self.job_steps = np.zeros(0, dtype=np.int64)
        self.max_threads = self._threads = 1
        self._p_cap = 0
        self._j_cap = 0
        self._limits = np.asarray(SAFEGUARD_LIMITS, dtype=float)
        self._obs = np.zeros((0, 1, 12))
        self._act = np.zeros((0, 1, 4))
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
        """Reserve the next ``n`` episode indices for calls with explicit ``episode_index``; returns the first."""
        first = self.next_index
        self.next_index += n
        return first

    def fly(self, genomes: np.ndarray, rows: np.ndarray, policy_index, mdp_index, n_jobs: int, episode_index: np.ndarray | None = None) -> np.ndarray:
        """Fly ``n_jobs`` jobs with the next ``n_jobs`` episode indices (or the given ones).

        Parameters
        ----------
        genomes : numpy.ndarray
            ``(P, D)`` genomes of the flyer's topology.
        rows : numpy.ndarray
            ``(M, 29)`` MDP rows (:func:`mdp_rows`).
        policy_index, mdp_index : numpy.ndarray of int64, None or "range"
            Per job, the genome and the MDP row it flies; None: 0 for every job; ``"range"``:
            job j flies number j.
        n_jobs : int
        episode_index : numpy.ndarray of int64, optional
            Per job, its episode index, from indices :meth:`reserve` gave: the jobs are then not
            counted in :attr:`episodes` and :attr:`steps` (the caller counts what it uses).

        Returns
        -------
        numpy.ndarray
            The jobs' returns: a view of the flyer's buffer, valid until the next call.
        """
        n_pol = genomes.shape[0]
        if n_pol > self._p_cap:
            self._ensure(n_pol, 0)
        self._genomes[:n_pol, : self.dim] = genomes
        zeros, arange, e, minus, returns, crashed, steps, sg = self._views_for(n_jobs)
        p = zeros if policy_index is None else (arange if isinstance(policy_index, str) else policy_index)
        m = zeros if mdp_index is None else (arange if isinstance(mdp_index, str) else mdp_index)
        if episode_index is None:
            np.add(arange, self.next_index, out=e)
        else:
            e[:] = episode_index
        rollout: Callable[..., None] = rollout_batch
        lanes = self.device == "cpu" and _use_lanes("cpu", rows, m)
        if self.device == "cuda":
            # The CUDA launcher copies the inputs to the GPU and the results back on every call
            # (acceptable for now: a generation's jobs are few); buffers kept on the GPU between
            # calls would save those copies. The thread count does not apply.
            from .sim import cuda as sim_cuda

            sim_cuda.load_kernel()
            rollout = sim_cuda.rollout_batch_cuda
        else:
            # Never more threads than jobs: every thread of a parallel call must check in, and on a busy
            # machine a one-episode call on all cores runs up to 10x slower than on one.
            want = n_jobs if n_jobs < self.max_threads else self.max_threads
            if want != self._threads:
                numba.set_num_threads(want)
                self._threads = want
        if lanes:
            _load_lanes()
        t0 = time.perf_counter()
        if lanes:
            # The same bits as the scalar kernel (neurohover/sim/lanes.py), LANES episodes per thread.
            rollout_lanes(rows, self._kinds, self._genomes, p, m, e, self.seed, self.n_steps, numba.get_num_threads(), returns, crashed, steps, sg)
        else:
            rollout(
                rows,
                self._kinds,
                self._genomes,
                p,
                m,
                e,
                minus,
                self.seed,
                self.n_steps,
                False,
                self._limits,
                minus,
                self._obs,
                self._act,
                returns,
                crashed,
                steps,
                sg,
            )
        self.kernel_seconds += time.perf_counter() - t0
        if self.trace is not None:
            self.trace.append((genomes.copy(), rows, p.copy(), m.copy(), e.copy()))
        if episode_index is None:
            self.episodes += n_jobs
            self.next_index += n_jobs
            self.steps += int(steps[0]) if n_jobs == 1 else int(steps.sum())
        self.flown += n_jobs
        self.crashed = crashed
        self.job_steps = steps
        return returns


SAFEGUARD_RULES = ("code", "paper", "ratio-sum")


@dataclass(frozen=True)
class DangerousState:
    """When the safeguard hands control to the fallback (docs/model.md, Safeguard).

    Parameters
    ----------
    rule : {"code", "paper", "ratio-sum"}
        ``"code"`` (default, as the authors' GHH-09 code ran it): the helicopter is tilted, qw <
        ``tilt``, and some velocity, position or angular-rate entry of the observation lies outside
        [-box, box]. ``"paper"``: the paper's text, the box test alone. ``"ratio-sum"`` (the
        authors' FGHH agent): the signed sum over the 12 observation entries of entry / limit
        (limits 5 m/s, 20 m, 4 pi rad/s, 1) exceeds ``threshold``.
    box : float
        Bound on |u|, |v|, |w|, |x|, |y|, |z|, |p|, |q|, |r| (> 0; 0.5 in the paper).
    tilt : float
        qw below this counts as tilted, in (0, 1] (0.99 in the authors' code); used by ``"code"`` only.
    threshold : float
        The ``"ratio-sum"`` test's threshold (> 0; 0.15 in the authors' FGHH agent).
    """

    rule: str = "code"
    box: float = SAFEGUARD_BOX
    tilt: float = SAFEGUARD_TILT
    threshold: float = SAFEGUARD_RATIO_THRESHOLD

    def __post_init__(self) -> None:
        if self.rule not in SAFEGUARD_RULES:
            raise NeurohoverError(f"unknown safeguard rule {self.rule!r}: allowed {', '.join(SAFEGUARD_RULES)}")
        if not (isinstance(self.box, (int, float)) and np.isfinite(self.box) and self.box > 0):
            raise NeurohoverError(f"safeguard box={self.box!r} is out of range: allowed a finite number > 0")
        if not (isinstance(self.tilt, (int, float)) and 0 < self.tilt <= 1):
            raise NeurohoverError(f"safeguard tilt={self.tilt!r} is out of range: allowed 0 < tilt <= 1 (qw threshold)")
        if not (isinstance(self.threshold, (int, float)) and np.isfinite(self.threshold) and self.threshold > 0):
            raise NeurohoverError(f"safeguard threshold={self.threshold!r} is out of range: allowed a finite number > 0")

    def limits(self) -> np.ndarray:
        """The test in the kernel's layout (sim/constants.SAFEGUARD_LIMITS): 9 box limits, the tilt
        threshold (inf: no tilt condition), the kind (0 box, 1 ratio sum), the ratio threshold and limits."""
        kind = SAFEGUARD_KIND_RATIO if self.rule == "ratio-sum" else SAFEGUARD_KIND_BOX
        tilt = float(self.tilt) if self.rule == "code" else np.inf
        return np.array([float(self.box)] * 9 + [tilt, kind, float(self.threshold), *SAFEGUARD_RATIO_LIMITS])


@dataclass(frozen=True)
class Safeguard:
    """The hybrid agent's safeguard: once the state is dangerous, ``fallback`` flies the rest of the episode."""

    fallback: Policy
    dangerous: DangerousState = DangerousState()
