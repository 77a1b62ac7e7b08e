"""One kernel launch: the single place that chooses how a batch of episodes flies, and flies it.

A batch flies in the SIMD lanes (:func:`neurohover.sim.lanes.rollout_lanes`: CPU, at least
``LANES`` jobs, no recording or safeguard, rows alike in substeps and wind), in the CUDA build of
the kernel (``device="cuda"``), or in the scalar kernel (:func:`neurohover.sim.kernel.rollout_batch`);
all three give the same returns (the lanes and the scalar kernel bit for bit). :func:`launch` makes
that choice and the call on a :class:`Batch` (the jobs, checked once) into a :class:`Flown` (the
outputs); :func:`neurohover.evaluate_jobs` (validated, any jobs),
:class:`neurohover.flyer.KernelFlyer` (an evolution's fast path) and the warm-ups all fly through
it. The vector environment steps its helicopters one control step at a time instead; :func:`stepper`
chooses its path (the CPU's :func:`neurohover.sim.step.step_batch` or the CUDA build) here too.
A per-job input of the task (such as the sensor model) lives in the MDP row, so it reaches
every path without a new argument.
"""

from __future__ import annotations

import contextlib
import importlib
import os
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field

import numba
import numpy as np

from .errors import NeurohoverError, brief, whole_in, whole_number
from .flightmeta import compared_by_value
from .sim.constants import MAX_EPISODE_STEPS, MDP_ROW_LEN, ROW_SUBSTEPS, ROW_WIND_KIND, SAFEGUARD_LIMITS
from .sim.jobs import PARK_F, PARK_U, Extras, Flown, Jobs, Parking
from .sim.kernel import GENOME_WIDTH, POLICY_MLP, POLICY_SLP, rollout_batch
from .sim.lanes import LANES, rollout_lanes, rollout_lanes_parked
from .sim.rng import MAX_SEED
from .sim.step import step_batch

__all__ = [
    "DEVICES", "KIND", "MAX_EPISODES_PER_CALL", "MAX_SEED", "Batch", "Flown", "Parking", "check_device", "check_job_indices", "launch", "launch_parked",
    "load_kernel", "num_threads", "rows_alike", "Stepper", "stepper", "use_lanes",
]  # fmt: skip

#: The kernel's code of each policy topology.
KIND = {"slp": POLICY_SLP, "mlp": POLICY_MLP}

#: The most episodes one call flies: each holds about 60 bytes of job and result arrays in memory (6 GB at
#: this bound), so a larger run is refused up front with this number rather than failing to allocate
#: (evaluate_jobs and KernelFlyer.fly; here, below both: evaluate.py is at the module size limit).
MAX_EPISODES_PER_CALL = 100_000_000


#: Set in a process forked after its parent flew on numba's GNU OpenMP threads: the pid of that parent (T34-B13).
_forked_from_omp: int | None = None


def _note_fork() -> None:
    """In a forked child: note a parent whose numba OpenMP (GNU libgomp) pool ran, as libgomp does not survive fork."""
    global _forked_from_omp
    try:
        layer = numba.threading_layer()
    except ValueError:  # no parallel kernel ran yet: the child starts its own pool, as a spawned one does
        return
    if layer == "omp" and getattr(importlib.import_module("numba.np.ufunc.omppool"), "openmp_vendor", "GNU") == "GNU":
        _forked_from_omp = _forked_from_omp or os.getppid()


if hasattr(os, "register_at_fork"):
    os.register_at_fork(after_in_child=_note_fork)


def refuse_forked_openmp() -> None:
    """Refuse to fly on the CPU in a process forked after its parent flew on numba's OpenMP threads: numba printed
    "Terminating: fork() called from a process already using GNU OpenMP" and killed the child, and a multiprocessing
    Pool (fork, Linux's default start method) started another, forever (T34-B13)."""
    if _forked_from_omp is not None:
        raise NeurohoverError(
            f"cannot fly in a process forked from one that flew (pid {_forked_from_omp}): numba's OpenMP threads do not survive fork; "
            "start the workers with multiprocessing.get_context('spawn') or 'forkserver', or set NUMBA_THREADING_LAYER=workqueue "
            "before importing neurohover (docs/performance.md, Many processes)"
        )


@contextlib.contextmanager
def num_threads(threads: int | None) -> Iterator[None]:
    """Run the kernel on ``threads`` threads (None: all cores) inside the block."""
    if threads is None:
        yield
        return
    limit = numba.config.NUMBA_NUM_THREADS  # type: ignore[attr-defined]  # numba.config sets it at import, from the environment
    cores = numba.config.NUMBA_DEFAULT_NUM_THREADS  # type: ignore[attr-defined]
    # the variable named where it, not the machine, limits the range ("allowed 1..1 on this machine" of 2 cores; trial 31a, borderline)
    where = "on this machine" if limit == cores else f"under NUMBA_NUM_THREADS={limit} (this machine has {cores} cores)"
    if not whole_number(threads):  # True was one thread; np.int64(1) is one (thirteenth trial, F8)
        raise NeurohoverError(f"threads={brief(threads)} is not allowed: give an integer in 1..{limit} {where}")
    if not 1 <= threads <= limit:
        raise NeurohoverError(f"threads={brief(threads)} is out of range: allowed 1..{limit} {where}")
    previous = numba.get_num_threads()
    numba.set_num_threads(int(threads))
    try:
        yield
    finally:
        numba.set_num_threads(previous)


@numba.njit(cache=True)
def _ends(index: np.ndarray) -> tuple[int, int]:  # min and max in one compiled pass: NumPy's two calls cost more than small batches fly
    lowest = highest = index[0]
    for v in index[1:]:
        lowest, highest = min(lowest, v), max(highest, v)
    return lowest, highest


def check_job_indices(index: np.ndarray, low: int, upper: int | None, what: str) -> None:
    """Refuse a 1-D int64 array of job indices holding a value below ``low`` or at or above ``upper`` (None: no bound):
    the one range check of every launch's indices (:class:`Batch`; :func:`neurohover.evaluate_jobs` reaches it there)."""
    if not index.size:
        return
    lowest, highest = _ends(index)
    if lowest < low and low == 0:
        raise NeurohoverError(f"{what} holds negative values (min {lowest}); allowed >= 0")
    if lowest < low or (upper is not None and highest >= upper):
        raise NeurohoverError(f"{what} holds {lowest if lowest < low else highest}, out of range: allowed {low}..{'' if upper is None else upper - 1}")


def _check_out(out: object, n_jobs: int) -> None:
    """Refuse an ``out`` the kernel cannot write one entry per job into: an array shorter than the batch was written
    past its end, corrupting memory (the process aborted; fourteenth session, beside the thirteenth trial's F1)."""
    if not isinstance(out, Flown):
        raise NeurohoverError(f"out={brief(out)} is not allowed: give a Flown of four 1-d arrays, one entry per job (Flown.empty(n_jobs))")
    for name, dtype in (("returns", np.float64), ("crashed", np.bool_), ("steps", np.int64), ("safeguard_step", np.int64)):
        a = getattr(out, name)
        if not isinstance(a, np.ndarray) or a.ndim != 1 or a.dtype != dtype or a.shape[0] < n_jobs or not a.flags.writeable:
            shown = f"a {'' if a.flags.writeable else 'read-only '}{a.ndim}-d {a.dtype} array of shape {a.shape}" if isinstance(a, np.ndarray) else brief(a)
            raise NeurohoverError(
                f"Flown.{name}={shown} is not allowed: give a writeable 1-d {np.dtype(dtype)} array of at least {n_jobs} entries (one per job)"
            )


def _check_parking(slots: object, n_required: object, parking: object, n_jobs: int) -> None:
    """Refuse parking arguments the lanes would index past: a slot outside ``parking`` or a wrong-sized state was read and
    written out of bounds (issue 37's last note left these unchecked)."""
    if not isinstance(parking, Parking):
        raise NeurohoverError(f"parking={brief(parking)} is not allowed: give a Parking (Parking.empty(n_slots))")
    n_slots = parking.steps.shape[0] if isinstance(parking.steps, np.ndarray) else -1
    for name, a, shape, dtype in (
        ("floats", parking.floats, (n_slots, PARK_F), np.float64),
        ("streams", parking.streams, (n_slots, PARK_U), np.uint64),
        ("steps", parking.steps, (n_slots,), np.int64),
    ):
        if not isinstance(a, np.ndarray) or a.shape != shape or a.dtype != dtype or not a.flags.writeable:
            shown = f"a {a.dtype} array of shape {a.shape}" if isinstance(a, np.ndarray) else brief(a)
            raise NeurohoverError(f"Parking.{name}={shown} is not allowed: give a writeable {np.dtype(dtype)} array of shape {shape} (Parking.empty)")
    if not isinstance(slots, np.ndarray) or slots.dtype != np.int64 or slots.shape != (n_jobs,):
        raise NeurohoverError(f"slots={brief(slots)} is not allowed: give a 1-d int64 numpy array, one parking slot per job ({n_jobs})")
    check_job_indices(slots, 0, n_slots, "slots")
    whole_in(n_required, "n_required", 0, n_jobs, f"{n_jobs} (the batch's jobs)")


#: Each array of a :class:`Batch`: its dimensions, dtype and column count (None: any).
_LAYOUT = {
    "rows": (2, np.float64, MDP_ROW_LEN),
    "kinds": (1, np.int64, None),
    "genomes": (2, np.float64, GENOME_WIDTH),
    "policy_index": (1, np.int64, None),
    "mdp_index": (1, np.int64, None),
    "episode_index": (1, np.int64, None),
    "limits": (1, np.float64, None),
}


def _check_array(what: str, a: object, ndim: int, dtype: type, width: int | None) -> None:
    """Refuse anything but a numpy array of the layout the kernel reads (a list was an AttributeError, a wrong width a
    plain ValueError; thirteenth trial, F18)."""
    if not isinstance(a, np.ndarray) or a.ndim != ndim or a.dtype != dtype or (width is not None and a.shape[1] != width):
        shown = f"a {a.ndim}-d {a.dtype} array of shape {a.shape}" if isinstance(a, np.ndarray) else brief(a)
        columns = f" with {width} columns" if width else ""
        raise NeurohoverError(f"{what}={shown} is not allowed: give a {ndim}-d {np.dtype(dtype)} numpy array{columns}")


@compared_by_value  # == by value: arrays whole (T46-B08)
@dataclass(frozen=True, eq=False)
class Batch:
    """The jobs of one kernel launch, as the kernel reads them; checked once, here, by shape and dtype.

    Job j flies policy ``policy_index[j]`` (a row of ``kinds`` / ``genomes``) on MDP row
    ``mdp_index[j]`` (the row holds the MDP's dynamics, wind and sensor model) with the gusts of
    episode ``episode_index[j]`` of ``seed``. ``fallback`` (per job, -1: none) with ``limits`` is the
    safeguard; ``slots`` (per job, -1: not recorded) with ``obs_out`` / ``act_out`` the recording.
    Callers that fly many small batches pass their own all -1 arrays; ``safeguard`` and
    ``recording`` (None: look at those arrays) say whether any job has either.
    """

    rows: np.ndarray
    kinds: np.ndarray
    genomes: np.ndarray
    policy_index: np.ndarray
    mdp_index: np.ndarray
    episode_index: np.ndarray
    seed: int | np.uint64
    n_steps: int
    fallback: np.ndarray | None = None
    limits: np.ndarray = field(default_factory=lambda: SAFEGUARD_LIMITS)
    slots: np.ndarray | None = None
    obs_out: np.ndarray | None = None
    act_out: np.ndarray | None = None
    safeguard: bool | None = None
    recording: bool | None = None

    def __post_init__(self) -> None:
        for name in ("rows", "kinds", "genomes", "policy_index", "mdp_index", "episode_index", "limits"):
            _check_array(f"Batch.{name}", getattr(self, name), *_LAYOUT[name])
        n = self.policy_index.shape[0]
        for name, per_job in (("mdp_index", self.mdp_index), ("episode_index", self.episode_index), ("fallback", self.fallback), ("slots", self.slots)):
            if per_job is not None and (not isinstance(per_job, np.ndarray) or per_job.dtype != np.int64):
                raise NeurohoverError(f"Batch.{name}={brief(per_job)} is not allowed: give a 1-D int64 numpy array, one entry per job")
            if per_job is not None and per_job.shape != (n,):
                raise NeurohoverError(f"Batch.{name} has shape {per_job.shape}, expected ({n},): one entry per job")
        if self.safeguard is None:
            object.__setattr__(self, "safeguard", self.fallback is not None and bool((self.fallback >= 0).any()))
        if self.recording is None:
            object.__setattr__(self, "recording", self.slots is not None and bool((self.slots >= 0).any()))
        if self.recording and (self.obs_out is None or self.act_out is None):
            raise NeurohoverError("Batch: jobs record flight data but obs_out / act_out are missing: give both")
        self._check_values()

    def _check_values(self) -> None:
        """The values the kernel indexes by, checked in one vectorised pass each before it runs: an index out of range
        read past an array and killed the process (SIGSEGV), a kind 99 flew, n_steps=-5 flew nothing (thirteenth trial, F1)."""
        whole_in(self.n_steps, "n_steps", 1, MAX_EPISODE_STEPS)  # T24-11: 1.5 or True "is not allowed", 0 out of range
        whole_in(self.seed, "seed", 0, MAX_SEED, "2**63-1")
        # the kernel compiles once per argument type: np.uint16(5) steps compiled it again, 30-50 s (eighteenth trial, T18-1)
        object.__setattr__(self, "n_steps", int(self.n_steps))  # (the seed goes to the kernel as np.uint64 always: jobs())
        kinds = self.kinds
        if kinds.shape[0] != self.genomes.shape[0]:
            raise NeurohoverError(f"Batch.kinds has {kinds.shape[0]} entries but genomes {self.genomes.shape[0]} rows: give one kind per genome")
        lowest, highest = _ends(kinds) if kinds.size else (0, 0)
        if not min(KIND.values()) <= lowest <= highest <= max(KIND.values()):
            bad = kinds[(kinds < min(KIND.values())) | (kinds > max(KIND.values()))][0]
            raise NeurohoverError(f"Batch.kinds holds {bad}, not a policy kind: allowed {', '.join(f'{v} ({k})' for k, v in KIND.items())}")
        check_job_indices(self.policy_index, 0, kinds.shape[0], "policy_index")
        check_job_indices(self.mdp_index, 0, self.rows.shape[0], "mdp_index")
        check_job_indices(self.episode_index, 0, None, "episode_index")
        if self.safeguard and self.fallback is not None:  # without the safeguard the kernel never reads it
            check_job_indices(self.fallback, -1, kinds.shape[0], "fallback")
            if self.limits.shape != SAFEGUARD_LIMITS.shape:  # a shorter one was read past its end
                raise NeurohoverError(
                    f"Batch.limits of shape {self.limits.shape} is not allowed: give {SAFEGUARD_LIMITS.shape[0]} limits (sim.constants.SAFEGUARD_LIMITS)"
                )
        if self.recording and self.slots is not None and self.obs_out is not None and self.act_out is not None:
            _check_array("Batch.obs_out", self.obs_out, 3, np.float64, None)  # another dtype was numba's TypingError
            _check_array("Batch.act_out", self.act_out, 3, np.float64, None)
            n_rec = min(self.obs_out.shape[0], self.act_out.shape[0])
            check_job_indices(self.slots, -1, n_rec, "slots")
            if self.obs_out.shape[1:] != (self.n_steps + 1, 12) or self.act_out.shape[1:] != (self.n_steps, 4):
                raise NeurohoverError(
                    f"Batch.obs_out / act_out of shapes {self.obs_out.shape} / {self.act_out.shape} are not allowed: "
                    f"give ({n_rec}, {self.n_steps + 1}, 12) and ({n_rec}, {self.n_steps}, 4)"
                )

    @property
    def n_jobs(self) -> int:
        return int(self.policy_index.shape[0])

    def jobs(self) -> Jobs:
        """The jobs in the kernel's layout (every path reads them)."""
        # a PolicyTable's read-only arrays (T35-B01) copied: numba compiled the kernel again for read-only arrays
        kinds, genomes = (a if a.flags.writeable else a.copy() for a in (self.kinds, self.genomes))
        return Jobs(self.rows, kinds, genomes, self.policy_index, self.mdp_index, self.episode_index, np.uint64(self.seed), self.n_steps)

    def extras(self) -> Extras:
        """The safeguard and the recording in the kernel's layout (the scalar and CUDA kernels read them)."""
        if self.fallback is None and self.slots is None:
            return Extras.none(self.n_jobs, self.limits)
        none = np.full(self.n_jobs, -1, dtype=np.int64)
        return Extras(
            none if self.fallback is None else self.fallback, bool(self.safeguard), self.limits, none if self.slots is None else self.slots,
            np.zeros((0, 1, 12)) if self.obs_out is None else self.obs_out, np.zeros((0, 1, 4)) if self.act_out is None else self.act_out,
        )  # fmt: skip

    @classmethod
    def empty(cls) -> Batch:
        """No jobs (one zero MDP row and policy): what the warm-ups launch to load the compiled code."""
        none = np.zeros(0, dtype=np.int64)
        return cls(np.zeros((1, MDP_ROW_LEN)), np.zeros(1, dtype=np.int64), np.zeros((1, GENOME_WIDTH)), none, none, none, 0, 1)


def _fly_lanes(b: Batch, out: Flown) -> None:
    refuse_forked_openmp()
    rollout_lanes(b.jobs(), numba.get_num_threads(), out)


def _fly_kernel(rollout: Callable[..., None], b: Batch, out: Flown) -> None:
    """The one call of the scalar kernel (``rollout``: the CPU kernel or the CUDA launcher, same arguments)."""
    if rollout is rollout_batch:
        refuse_forked_openmp()
    rollout(b.jobs(), b.extras(), out)


_loaded: set[str] = set()


def load_kernel() -> None:
    """Load (or compile) the scalar kernel and the lanes with an empty batch, so ``seconds`` times only flying."""
    if "cpu" not in _loaded:
        _fly_kernel(rollout_batch, Batch.empty(), Flown.empty(0))
        load_lanes()  # with the scalar kernel, so that a warm-up call of either path loads both (about 0.03 s from the cache)
        _loaded.add("cpu")


def load_lanes() -> None:
    """Load (or compile) the lanes path with an empty batch, so ``seconds`` times only flying."""
    if "lanes" not in _loaded:
        _fly_lanes(Batch.empty(), Flown.empty(0))
        _loaded.add("lanes")


def use_lanes(device: str, rows: np.ndarray, m_idx: np.ndarray, fb: np.ndarray | None = None, rec: np.ndarray | None = None) -> bool:
    """Whether the jobs fly in SIMD lanes (:func:`neurohover.sim.lanes.rollout_lanes`) rather than the scalar kernel.

    Any CPU batch of at least LANES jobs (below that a thread's lanes would mostly idle) without
    recording or safeguard (the lanes implement neither); policies, MDP rows and their sensor models may differ per job.
    Restriction: the jobs' rows must share the substep count (learned models 1, true MDPs 10) and
    whether there is wind, because the packed substep loop takes both as constants; per-lane
    values would turn it into per-lane branches that no longer vectorize. Results are the same
    bits either way.
    """
    if not isinstance(device, str) or device not in DEVICES:  # an array: NumPy's "truth value is ambiguous" (T16-12)
        raise NeurohoverError(f"device={brief(device)} is unknown: allowed 'cpu' or 'cuda'")
    if not isinstance(m_idx, np.ndarray) or m_idx.ndim != 1:  # None was an AttributeError (thirteenth trial, F18)
        raise NeurohoverError(f"m_idx={brief(m_idx)} is not allowed: give a 1-D numpy array of each job's MDP row")
    n_jobs = m_idx.shape[0]
    if device != "cpu" or n_jobs < LANES or (fb is not None and (fb >= 0).any()) or (rec is not None and rec.any()):
        return False
    return rows_alike(rows, m_idx)


def rows_alike(rows: np.ndarray, m_idx: np.ndarray | None = None) -> bool:
    """Whether the MDP rows (those ``m_idx`` lists, if given) share the substep count and whether there is
    wind: what one call of the lanes needs."""
    if not isinstance(rows, np.ndarray) or rows.ndim != 2 or rows.shape[0] == 0 or rows.shape[1] != MDP_ROW_LEN:  # thirteenth trial, F18
        shown = f"an array of shape {rows.shape}" if isinstance(rows, np.ndarray) else brief(rows)
        raise NeurohoverError(f"rows={shown} is not allowed: give a numpy array of MDP rows, shape (M >= 1, {MDP_ROW_LEN}) (neurohover.evaluate.mdp_rows)")
    sub, windy = rows[:, ROW_SUBSTEPS], rows[:, ROW_WIND_KIND] != 0.0
    if (sub == sub[0]).all() and (windy == windy[0]).all():
        return True  # every row alike: no need to look at the jobs
    if m_idx is None:
        return False
    used = np.unique(m_idx)  # sorted: its ends are the range
    if used.size == 0:
        return True  # no jobs: nothing differs
    if used.dtype.kind not in "iu" or used[0] < 0 or used[-1] >= rows.shape[0]:
        bad = used[-1] if used.dtype.kind not in "iu" or used[0] >= 0 else used[0]
        raise NeurohoverError(f"m_idx holds {brief(bad)}, not allowed: give integers in 0..{rows.shape[0] - 1}, rows of rows")
    return bool((sub[used] == sub[used[0]]).all()) and bool((windy[used] == windy[used[0]]).all())


DEVICES = ("cpu", "cuda")


def check_device(device: str) -> None:
    """Refuse an unknown device, or ``"cuda"`` where no GPU (nor numba's CUDA simulator) is usable.

    Raises
    ------
    NeurohoverError
        With one message that names the problem; ``"cpu"`` never imports numba.cuda.
    """
    if not isinstance(device, str) or device not in DEVICES:  # an array was NumPy's "truth value is ambiguous" (T16-12)
        raise NeurohoverError(f"device={brief(device)} is unknown: allowed 'cpu' or 'cuda'")
    if device == "cuda":
        from .sim import cuda as sim_cuda  # numba.cuda is imported only when asked for

        problem = sim_cuda.cuda_problem()
        if problem is not None:
            raise NeurohoverError(
                f"device='cuda' cannot run here: {problem}. It needs an NVIDIA GPU with its driver and "
                "pip install 'neurohover[cuda]' (numba-cuda); NUMBA_ENABLE_CUDASIM=1 runs numba's CUDA simulator instead"
            )


def launch_parked(batch: Batch, out: Flown, slots: np.ndarray, n_required: int, parking: Parking) -> float:
    """Fly the batch's first ``n_required`` jobs to their end and its later jobs in the lanes they leave idle
    (:func:`neurohover.sim.lanes.rollout_lanes_parked`); returns the kernel's wall seconds.

    Job j's episode is kept in slot ``slots[j]`` of ``parking`` if the call ends while it flies, and
    resumes there when a later call lists that slot: its return is the same bits as in one call.
    ``out.steps[j]`` is 0 for an optional job not over. CPU only, with rows alike in substeps and
    wind and no safeguard or recording (:func:`use_lanes`; the caller checks).
    """
    _check_out(out, batch.n_jobs)
    _check_parking(slots, n_required, parking, batch.n_jobs)
    load_parked()
    t0 = time.perf_counter()
    _fly_parked(batch, out, slots, n_required, parking)
    return time.perf_counter() - t0


def _fly_parked(b: Batch, out: Flown, slots: np.ndarray, n_required: int, parking: Parking) -> None:
    refuse_forked_openmp()
    rollout_lanes_parked(b.jobs(), slots, n_required, numba.get_num_threads(), parking, out)


def load_parked() -> None:
    """Load (or compile) :func:`neurohover.sim.lanes.rollout_lanes_parked` with an empty batch."""
    if "parked" not in _loaded:
        _fly_parked(Batch.empty(), Flown.empty(0), np.zeros(0, dtype=np.int64), 0, Parking.empty(0))
        _loaded.add("parked")


def launch(batch: Batch, out: Flown, device: str = "cpu") -> float:
    """Fly the batch's jobs, writing ``out``; returns the kernel's wall seconds.

    The one place that chooses the path: a CPU batch without safeguard or recording may fly in the
    lanes (:func:`use_lanes`), the rest in the scalar kernel, or on the GPU with ``device="cuda"``.
    The compiled code is loaded (compiled or read from the cache) before the clock starts.
    """
    _check_out(out, batch.n_jobs)
    if not batch.safeguard and not batch.recording and use_lanes(device, batch.rows, batch.mdp_index):
        load_lanes()
        t0 = time.perf_counter()
        _fly_lanes(batch, out)
        return time.perf_counter() - t0
    rollout: Callable[..., None]
    if device == "cuda":
        from .sim import cuda as sim_cuda  # numba.cuda is imported only when asked for

        sim_cuda.load_kernel()
        rollout = sim_cuda.rollout_batch_cuda
    else:
        load_kernel()
        rollout = rollout_batch
    t0 = time.perf_counter()
    _fly_kernel(rollout, batch, out)
    return time.perf_counter() - t0


class _CpuSteps:
    """One control step of every helicopter of a vector environment on the CPU; the arrays are the env's own."""

    def __init__(self, rows: np.ndarray, index: np.ndarray, state: np.ndarray, noise: np.ndarray, rng: np.ndarray, steps: np.ndarray) -> None:
        self.rows, self.index, self.state, self.noise, self.rng, self.steps = rows, index, state, noise, rng, steps

    def set_rows(self, idx: np.ndarray, rows: np.ndarray, state: np.ndarray, noise: np.ndarray, rng: np.ndarray, steps: np.ndarray) -> None:
        """Nothing to copy: the env wrote the reset rows into the arrays this steps."""

    def step(self, actions: np.ndarray, n_steps: int, obs: np.ndarray, reward: np.ndarray, crash: np.ndarray) -> None:
        step_batch(self.rows, self.index, self.state, self.noise, self.rng, self.steps, actions, n_steps, obs, reward, crash)


class _CudaSteps:
    """The same on the GPU (:class:`neurohover.sim.cuda.StepBatch`): the device holds the flying state;
    the host's step counts are kept in step here."""

    def __init__(self, rows: np.ndarray, index: np.ndarray, state: np.ndarray, noise: np.ndarray, rng: np.ndarray, steps: np.ndarray) -> None:
        from .sim import cuda as sim_cuda  # numba.cuda is imported only when asked for

        self.gpu = sim_cuda.StepBatch(rows, index, state, noise, rng, steps)
        self.steps = steps

    def set_rows(self, idx: np.ndarray, rows: np.ndarray, state: np.ndarray, noise: np.ndarray, rng: np.ndarray, steps: np.ndarray) -> None:
        """Copy the reset helicopters' rows (``idx``) to the device."""
        self.gpu.set_rows(idx, rows, state, noise, rng, steps)

    def step(self, actions: np.ndarray, n_steps: int, obs: np.ndarray, reward: np.ndarray, crash: np.ndarray) -> None:
        self.gpu.step(actions, n_steps, obs, reward, crash)
        self.steps += 1  # as the kernel counts every helicopter's step


Stepper = _CpuSteps | _CudaSteps


def stepper(device: str, rows: np.ndarray, index: np.ndarray, state: np.ndarray, noise: np.ndarray, rng: np.ndarray, steps: np.ndarray) -> Stepper:
    """The one choice of path for a vector environment's control steps: ``step(actions, n_steps, obs,
    reward, crash)`` advances every helicopter (helicopter i on MDP row ``rows[index[i]]``, its state,
    gust noise, streams and step count in row i of the others, updated in place on the CPU) and
    ``set_rows(idx, ...)`` takes the rows of reset helicopters. ``device="cuda"`` keeps the flying
    state on the GPU (docs/gpu.md)."""
    check_device(device)
    return (_CudaSteps if device == "cuda" else _CpuSteps)(rows, index, state, noise, rng, steps)
