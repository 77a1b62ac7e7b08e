"""One kernel launch: the single place that chooses how a batch of episodes flies, and flies it.

A batch flies in the SIMD lanes (:func:`neurohover.sim.lanes.rollout_lanes`: CPU, at least
``LANES`` jobs, no recording or safeguard, rows alike in substeps and wind), in the CUDA build of
the kernel (``device="cuda"``), or in the scalar kernel (:func:`neurohover.sim.kernel.rollout_batch`);
all three give the same returns (the lanes and the scalar kernel bit for bit). :func:`launch` makes
that choice and the call; :func:`neurohover.evaluate_jobs` (validated, any jobs) and
:class:`neurohover.flyer.KernelFlyer` (an evolution's fast path) both fly through it.
"""

from __future__ import annotations

import contextlib
import time
from collections.abc import Callable, Iterator

import numba
import numpy as np

from .errors import NeurohoverError
from .sim.constants import MDP_ROW_LEN, ROW_SUBSTEPS, ROW_WIND_KIND, SAFEGUARD_LIMITS
from .sim.kernel import GENOME_WIDTH, POLICY_MLP, POLICY_SLP, rollout_batch
from .sim.lanes import LANES, rollout_lanes

__all__ = ["DEVICES", "KIND", "MAX_SEED", "check_device", "launch", "load_kernel", "num_threads", "use_lanes"]

#: The kernel's code of each policy topology.
KIND = {"slp": POLICY_SLP, "mlp": POLICY_MLP}
MAX_SEED = 2**63 - 1


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


_kernel_loaded = False


def load_kernel() -> None:
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
        load_lanes()  # with the scalar kernel, so that a warm-up call of either path loads both (about 0.03 s from the cache)
        _kernel_loaded = True


_lanes_loaded = False


def load_lanes() -> None:
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


def use_lanes(device: str, rows: np.ndarray, m_idx: np.ndarray, fb: np.ndarray | None = None, rec: np.ndarray | None = None) -> bool:
    """Whether the jobs fly in SIMD lanes (:func:`neurohover.sim.lanes.rollout_lanes`) rather than the scalar kernel.

    Any CPU batch of at least LANES jobs (below that a thread's lanes would mostly idle) without
    recording or safeguard (the lanes implement neither); policies, MDP rows and their sensor models may differ per job.
    Restriction: the jobs' rows must share the substep count (learned models 1, true MDPs 10) and
    whether there is wind, because the packed substep loop takes both as constants; per-lane
    values would turn it into per-lane branches that no longer vectorize. Results are the same
    bits either way.
    """
    n_jobs = m_idx.shape[0]
    if device != "cpu" or n_jobs < LANES or (fb is not None and (fb >= 0).any()) or (rec is not None and rec.any()):
        return False
    sub, windy = rows[:, ROW_SUBSTEPS], rows[:, ROW_WIND_KIND] != 0.0
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


def launch(
    rows: np.ndarray,
    kinds: np.ndarray,
    genomes: np.ndarray,
    policy_index: np.ndarray,
    mdp_index: np.ndarray,
    episode_index: np.ndarray,
    seed: np.uint64,
    n_steps: int,
    returns: np.ndarray,
    crashed: np.ndarray,
    steps: np.ndarray,
    safeguard_step: np.ndarray,
    *,
    device: str = "cpu",
    fallback: np.ndarray | None = None,
    safeguard: bool = False,
    limits: np.ndarray = SAFEGUARD_LIMITS,
    slots: np.ndarray | None = None,
    recording: bool = False,
    obs_out: np.ndarray | None = None,
    act_out: np.ndarray | None = None,
) -> float:
    """Fly the jobs (arrays already checked, int64 indices, outputs preallocated); returns the kernel's wall seconds.

    ``fallback`` (per job, -1: none) with ``safeguard`` (whether any job has one) and ``limits``
    are the safeguard; ``slots`` (per job, -1: not recorded) with ``recording`` and ``obs_out`` /
    ``act_out`` the recording. A CPU batch with neither may fly in the lanes (:func:`use_lanes`).
    Arrays left None are all -1 (a caller flying many small batches passes its own). The kernel is
    loaded (compiled or read from the cache) before the clock starts.
    """
    if not safeguard and not recording and use_lanes(device, rows, mdp_index):
        load_lanes()
        t0 = time.perf_counter()
        threads = numba.get_num_threads()
        rollout_lanes(rows, kinds, genomes, policy_index, mdp_index, episode_index, seed, n_steps, threads, returns, crashed, steps, safeguard_step)
        return time.perf_counter() - t0
    rollout: Callable[..., None]  # the CPU kernel (a numba dispatcher) or the CUDA launcher, same arguments
    if device == "cuda":
        from .sim import cuda as sim_cuda  # numba.cuda is imported only when asked for

        sim_cuda.load_kernel()
        rollout = sim_cuda.rollout_batch_cuda
    else:
        load_kernel()
        rollout = rollout_batch
    none = None if fallback is not None and slots is not None else np.full(policy_index.shape[0], -1, dtype=np.int64)
    fb = none if fallback is None else fallback
    rec = none if slots is None else slots
    obs = np.zeros((0, 1, 12)) if obs_out is None else obs_out
    act = np.zeros((0, 1, 4)) if act_out is None else act_out
    t0 = time.perf_counter()
    rollout(
        rows, kinds, genomes, policy_index, mdp_index, episode_index, fb, seed, n_steps, safeguard,
        limits, rec, obs, act, returns, crashed, steps, safeguard_step,
    )  # fmt: skip
    return time.perf_counter() - t0
