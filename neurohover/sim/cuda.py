"""The CUDA build of the simulation kernel: the CPU kernel's own Python source, compiled for the GPU.

Nothing here is physics. :func:`device_function` takes a compiled CPU function of the simulator
(its ``.py_func``: the very function object numba compiled for the CPU) and builds a CUDA device
function from the same code object, with every compiled simulator function it calls replaced by
that callee's device version, recursively. The CPU kernel is untouched (same machine code, same
on-disk cache); the GPU runs :func:`neurohover.sim.kernel.fly_job`, the body of the CPU kernel's
parallel loop, one thread per job, with the same ``(seed, episode)`` gust streams. Global NumPy
arrays the source reads (the ziggurat tables ``ZIG_X``, ``ZIG_F``) become device constant arrays:
numba's CUDA target places global arrays in constant memory.

The one target-specific piece is a primitive, not physics: ``_product`` (a product that must not
be fused into an FMA, for the competition's clock) maps to libdevice's ``dmul_rn`` on a real GPU,
whose compiler contracts ``a * b + c`` into an FMA by default.

Tolerance against the CPU kernel: under numba's CUDA simulator (``NUMBA_ENABLE_CUDASIM=1``, plain
Python, no FMA) returns agree to 1e-9 relative (in practice about 1e-13: the CPU kernel contracts
some products into FMAs); on a GPU, FMA placement and libdevice's ``exp``/``sin``/``log`` (within
2 ulp of glibc's) give about 1e-12 relative over a 6000-step episode. Crash flags and steps agree
except for a trajectory that meets a crash bound within that rounding.

The module imports without CUDA; :func:`cuda_problem` says why the GPU cannot be used.
"""

from __future__ import annotations

import contextlib
import types
import warnings

import numpy as np
from numba.core.registry import CPUDispatcher

from . import kernel, rng, step
from .constants import MDP_ROW_LEN, ROW_DT, ROW_SUBSTEPS, SAFEGUARD_LIMITS, SENSOR_SCRATCH
from .jobs import Extras, Flown, Jobs

# numba-cuda 0.30.4 (the newest) registers an overload of np.row_stack when it builds its first kernel, and
# NumPy 2.5 removed that deprecated alias of np.vstack: without it no kernel compiles (seen on an H200, 2026-12-04).
if not hasattr(np, "row_stack"):
    np.row_stack = np.vstack

try:  # numba-cuda (``pip install 'neurohover[cuda]'``) or numba's built-in target; may be broken or absent
    from numba import cuda
except Exception as exc:  # pragma: no cover - depends on the installation
    cuda = None  # type: ignore[assignment]  # no numba.cuda: every use follows cuda_problem(), which reports it
    _IMPORT_ERROR: Exception | None = exc
else:
    _IMPORT_ERROR = None

THREADS_PER_BLOCK = 128
SIM_MODULES = (kernel.__name__, step.__name__, rng.__name__)  # compiled functions from these modules are retargeted


def simulating() -> bool:
    """Whether numba's CUDA simulator stands in for a GPU (``NUMBA_ENABLE_CUDASIM=1`` at numba's import)."""
    from numba.core import config

    return bool(config.ENABLE_CUDASIM)  # type: ignore[attr-defined]  # numba.config sets it at import, from the environment


@contextlib.contextmanager
def _wraparound_quiet():
    """Under the simulator the device code runs as Python on NumPy scalars, whose uint64 products in ``sim.rng`` wrap on
    purpose (as they do on a GPU) and warned "overflow encountered" 8 lines a run (T30-A03); on a GPU: nothing to do."""
    if not simulating():
        yield
        return
    with warnings.catch_warnings():  # process-wide filters: the simulator's threads see them
        warnings.filterwarnings("ignore", "overflow encountered", RuntimeWarning, r"neurohover\.sim\.rng")
        yield


def cuda_problem() -> str | None:
    """Why ``device="cuda"`` cannot run here, or None when a GPU (or the simulator) is usable."""
    if cuda is None:
        return f"numba.cuda cannot be imported ({type(_IMPORT_ERROR).__name__}: {_IMPORT_ERROR})"
    if simulating():
        return None
    try:
        if cuda.is_available():
            return None
    except Exception as exc:  # pragma: no cover - driver errors vary
        return f"the CUDA driver failed ({type(exc).__name__}: {exc})"
    return "numba finds no usable CUDA GPU (numba.cuda.is_available() is False)"


def _product_rn(a, b):
    # Round-to-nearest product that the GPU compiler may not contract into an FMA.
    return libdevice.dmul_rn(float(a), float(b))


libdevice = None  # numba.cuda.libdevice, loaded with the first device function on a real GPU
_PRIMITIVES: dict = {}  # per-target replacements of primitives, by the callee's name in the source
_DEVICE: dict = {}


def _global_names(code: types.CodeType) -> set[str]:
    names = set(code.co_names)
    for const in code.co_consts:
        if isinstance(const, types.CodeType):
            names |= _global_names(const)
    return names


def _rebind(py_func: types.FunctionType) -> types.FunctionType:
    """``py_func`` (same code object) with globals of its own: each simulator function it calls is its device version."""
    source = py_func.__globals__
    g = {"__builtins__": source["__builtins__"], "__name__": source["__name__"]}
    for name in _global_names(py_func.__code__):
        if name in _PRIMITIVES:
            g[name] = _PRIMITIVES[name]
        elif name in source:
            value = source[name]
            if isinstance(value, CPUDispatcher) and value.py_func.__module__ in SIM_MODULES:
                value = device_function(value)
            g[name] = value
    f = types.FunctionType(py_func.__code__, g, py_func.__name__, py_func.__defaults__, py_func.__closure__)
    f.__qualname__ = py_func.__qualname__
    f.__doc__ = py_func.__doc__
    return f


def device_function(func):
    """The CUDA device function compiled from simulator function ``func`` (a CPU dispatcher or plain function).

    Parameters
    ----------
    func : numba CPUDispatcher or function
        A function of :mod:`neurohover.sim.kernel` or :mod:`neurohover.sim.rng`.

    Returns
    -------
    numba CUDA dispatcher
        Built once per function and cached in this process.
    """
    py_func = getattr(func, "py_func", func)
    built = _DEVICE.get(py_func)
    if built is None:
        _require()
        built = _DEVICE[py_func] = cuda.jit(device=True)(_rebind(py_func))
    return built


def _rollout_thread(jobs, extras, out):
    """One CUDA thread per job: the CPU kernel's loop body with a thread-local stream state."""
    j = cuda.grid(1)
    if j < jobs.policy.shape[0]:
        state = cuda.local.array(4, np.uint64)
        sensor_state = cuda.local.array(4, np.uint64)
        scratch = cuda.local.array(SENSOR_SCRATCH, np.float64)
        fly_job(j, state, sensor_state, scratch, jobs, extras, out)


fly_job = kernel.fly_job  # the CPU dispatcher; _rebind hands the kernel its device version
_KERNEL = None


def _step_thread(mdp_rows, env_mdp, states, noise, rngs, steps, actions, n_steps, obs_out, rew_out, crash_out):
    """One CUDA thread per helicopter: the CPU ``step_batch`` loop body."""
    i = cuda.grid(1)
    if i < states.shape[0]:
        step_one(i, mdp_rows, env_mdp, states, noise, rngs, steps, actions, n_steps, obs_out, rew_out, crash_out)


def _reset_thread(idx, rows, states, noise, rngs, steps, mdp_rows, d_states, d_noise, d_rngs, d_steps):
    """Plumbing, not physics: copy the host's rows of the reset sub-environments ``idx`` into the device arrays."""
    t = cuda.grid(1)
    if t < idx.shape[0]:
        i = idx[t]
        for m in range(rows.shape[1]):
            mdp_rows[i, m] = rows[t, m]
        for m in range(states.shape[1]):
            d_states[i, m] = states[t, m]
        for m in range(noise.shape[1]):
            d_noise[i, m] = noise[t, m]
        for m in range(rngs.shape[1]):
            d_rngs[i, m] = rngs[t, m]
        d_steps[i] = steps[t]


step_one = step.step_one  # the CPU dispatcher; _rebind hands the kernel its device version
_STEP_KERNEL = None
_RESET_KERNEL = None


def _require() -> None:
    """Raise RuntimeError unless a GPU (or the simulator) is usable; set up the target's primitives."""
    global libdevice
    problem = cuda_problem()
    if problem is not None:
        raise RuntimeError(problem)
    if libdevice is None and not simulating():  # plain Python (the simulator) never fuses a product
        from numba.cuda import libdevice as lib

        libdevice = lib
        _PRIMITIVES["_product"] = cuda.jit(device=True)(_product_rn)


def rollout_kernel():
    """The CUDA kernel (built on first use): same arguments as :func:`neurohover.sim.kernel.rollout_batch`."""
    global _KERNEL
    if _KERNEL is None:
        _require()
        _KERNEL = cuda.jit(_rebind(_rollout_thread))
    return _KERNEL


_loaded = False


def load_kernel() -> None:
    """Compile the CUDA kernel now (one job of one step), so that later calls time only flying."""
    global _loaded
    if not _loaded:
        one = np.zeros(1, dtype=np.int64)
        row = np.zeros((1, MDP_ROW_LEN))
        row[0, ROW_SUBSTEPS], row[0, ROW_DT] = 1.0, 0.01
        jobs = Jobs(row, one, np.zeros((1, kernel.GENOME_WIDTH)), one, one, one, np.uint64(0), 1)
        rollout_batch_cuda(jobs, Extras.none(1, SAFEGUARD_LIMITS), Flown.empty(1))
        _loaded = True


def rollout_batch_cuda(jobs: Jobs, extras: Extras, out: Flown, threads_per_block: int | None = None) -> None:
    """:func:`~neurohover.sim.kernel.rollout_batch` on the GPU: copy in, one thread per job, copy back.

    Arguments and outputs are host NumPy arrays, exactly as the CPU kernel takes them; outputs
    (and ``extras.obs_out`` / ``extras.act_out`` where jobs record) are filled in place. Raises RuntimeError when
    no GPU (and no simulator) is usable. ``threads_per_block`` defaults to :data:`THREADS_PER_BLOCK`.
    """
    n_jobs = jobs.policy.shape[0]
    k = rollout_kernel()
    if n_jobs == 0:
        return

    def to(a):  # to_device copies one contiguous buffer; a strided view of the caller's would not do
        return cuda.to_device(np.ascontiguousarray(a))

    recording = extras.obs_out.shape[0] > 0
    # A zero-size device array is avoided: no job writes flight data when none records.
    d_obs = to(extras.obs_out) if recording else cuda.device_array((1, 1, 12))
    d_act = to(extras.act_out) if recording else cuda.device_array((1, 1, 4))
    d_jobs = Jobs(
        to(jobs.rows), to(jobs.kinds), to(jobs.genomes), to(jobs.policy), to(jobs.mdp), to(jobs.episode), np.uint64(jobs.seed), int(jobs.n_steps)
    )  # fmt: skip
    d_extras = Extras(to(extras.fallback), bool(extras.safeguard), to(extras.limits), to(extras.slots), d_obs, d_act)
    d_out = [cuda.device_array(n_jobs, dtype=host.dtype) for host in out]  # returns, crash flags, steps, safeguard steps
    tpb = threads_per_block or THREADS_PER_BLOCK
    with _wraparound_quiet():
        k[(n_jobs + tpb - 1) // tpb, tpb](d_jobs, d_extras, Flown(*d_out))
    for device_array, host in zip(d_out, out, strict=True):
        device_array.copy_to_host(host)
    if recording:
        d_obs.copy_to_host(extras.obs_out)
        d_act.copy_to_host(extras.act_out)
    cuda.synchronize()


def step_kernel():
    """The CUDA kernel (built on first use): same arguments as :func:`neurohover.sim.step.step_batch`."""
    global _STEP_KERNEL
    if _STEP_KERNEL is None:
        _require()
        _STEP_KERNEL = cuda.jit(_rebind(_step_thread))
    return _STEP_KERNEL


def _reset_kernel():
    global _RESET_KERNEL
    if _RESET_KERNEL is None:
        _require()
        _RESET_KERNEL = cuda.jit(_reset_thread)
    return _RESET_KERNEL


class StepBatch:
    """:func:`~neurohover.sim.step.step_batch` on the GPU with its per-helicopter arrays kept there.

    The MDP rows, states, noise, stream states and step counters of ``n`` helicopters live in
    device memory between steps; :meth:`step` copies the actions in and the observations, rewards
    and crash flags out; :meth:`set_rows` overwrites the rows of some helicopters (their resets)
    from host arrays. Raises RuntimeError when no GPU (and no simulator) is usable.
    """

    def __init__(self, mdp_rows, env_mdp, states, noise, rngs, steps, threads_per_block: int | None = None) -> None:
        self._kernel = step_kernel()
        self._n = states.shape[0]
        self._tpb = threads_per_block or THREADS_PER_BLOCK

        def to(a):
            return cuda.to_device(np.ascontiguousarray(a))

        self.rows, self.env_mdp, self.states, self.noise, self.rngs, self.steps = (to(a) for a in (mdp_rows, env_mdp, states, noise, rngs, steps))
        self._actions = cuda.device_array((self._n, 4), dtype=np.float64)
        self._obs = cuda.device_array((self._n, 12), dtype=np.float64)
        self._rew = cuda.device_array(self._n, dtype=np.float64)
        self._crash = cuda.device_array(self._n, dtype=np.bool_)

    def set_rows(self, idx, mdp_rows, states, noise, rngs, steps) -> None:
        """Helicopters ``idx`` take row ``t`` of each host array (``mdp_rows[t]`` etc., one row per entry of ``idx``)."""
        n = len(idx)
        if n == 0:
            return

        def to(a):
            return cuda.to_device(np.ascontiguousarray(a))

        blocks = (n + self._tpb - 1) // self._tpb
        with _wraparound_quiet():
            _reset_kernel()[blocks, self._tpb](
                to(np.asarray(idx, dtype=np.int64)),
                to(mdp_rows),
                to(states),
                to(noise),
                to(rngs),
                to(steps),
                self.rows,
                self.states,
                self.noise,
                self.rngs,
                self.steps,
            )

    def step(self, actions, n_steps, obs_out, rew_out, crash_out) -> None:
        """One control step of every helicopter: ``actions`` (n, 4) in, the host outputs filled in place."""
        self._actions.copy_to_device(np.ascontiguousarray(actions))
        with _wraparound_quiet():
            self._kernel[(self._n + self._tpb - 1) // self._tpb, self._tpb](
                self.rows,
                self.env_mdp,
                self.states,
                self.noise,
                self.rngs,
                self.steps,
                self._actions,
                np.int64(n_steps),
                self._obs,
                self._rew,
                self._crash,
            )
        self._obs.copy_to_host(obs_out)
        self._rew.copy_to_host(rew_out)
        self._crash.copy_to_host(crash_out)
        cuda.synchronize()
