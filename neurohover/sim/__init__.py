"""Simulation stage: the compiled kernel, its random streams and the plain-Python reference."""

from . import _cache

# Before any cached function of the package is compiled: a cached kernel must match all of sim/.
_cache.install()


def kernel_compiled() -> bool:
    """Whether the CPU kernel (:func:`neurohover.sim.lanes.rollout_lanes`) is compiled in this process or in
    numba's on-disk cache; if not, the first flight compiles it (tens of seconds, once per machine and version).
    Under ``NUMBA_DISABLE_JIT=1`` nothing is compiled: True (the note said it compiled on every run; trial 31)."""
    from numba.core import config

    if getattr(config, "DISABLE_JIT", 0):  # set from the environment at import; untyped in numba
        return True
    from .lanes import fly_queue

    return _cache.compiled_on_disk(fly_queue)
