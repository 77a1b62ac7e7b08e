"""Keeps numba's on-disk cache of neurohover's compiled functions from ever running stale code.

numba keys a cached function on the source of its own file only, but the kernel inlines and links
code and constants from :mod:`neurohover.sim.rng` and :mod:`neurohover.sim.constants` (and
:mod:`neurohover.envs.vector` links :func:`neurohover.sim.rng.seed_stream`). :func:`install`
therefore adds a hash of every ``neurohover/sim/*.py`` to the freshness stamp numba stores with
each cached function of the package: an edit anywhere in the simulator recompiles, an unchanged
tree loads from the cache as before. Compiled code of the package may call into its own module
and :mod:`neurohover.sim` only (tests/test_kernel_cache.py checks the simulator's side of that).
"""

from __future__ import annotations

import hashlib
from pathlib import Path

from numba.core import caching

SIM_DIR = Path(__file__).resolve().parent
PACKAGE_DIR = SIM_DIR.parent

# numba 0.68 made the implementation class public; older releases keep it private. Both by getattr:
# mypy checks against the installed numba, which lacks one of the two names.
_CacheImpl = getattr(caching, "CacheImpl", None) or getattr(caching, "_CacheImpl")  # noqa: B009


def sim_source_hash(sim_dir: Path = SIM_DIR) -> str:
    """SHA-256 of the names and contents of the ``*.py`` files in ``sim_dir``, in name order."""
    h = hashlib.sha256()
    for path in sorted(sim_dir.glob("*.py")):
        h.update(path.name.encode() + b"\0" + path.read_bytes() + b"\0")
    return h.hexdigest()


class SimSourceLocator(caching._CacheLocator):
    """numba's own locator for a neurohover function, with :func:`sim_source_hash` in its stamp."""

    _sim_hash: str | None = None

    def __init__(self, inner: caching._CacheLocator):
        self._inner = inner

    def ensure_cache_path(self):
        self._inner.ensure_cache_path()

    def get_cache_path(self):
        return self._inner.get_cache_path()

    def get_source_stamp(self):
        if SimSourceLocator._sim_hash is None:  # once per process: the files do not change under a running kernel
            SimSourceLocator._sim_hash = sim_source_hash()
        return (self._inner.get_source_stamp(), SimSourceLocator._sim_hash)

    def get_disambiguator(self):
        return self._inner.get_disambiguator()

    @classmethod
    def from_function(cls, py_func, py_file):
        try:
            Path(py_file).resolve().relative_to(PACKAGE_DIR)
        except (OSError, ValueError):
            return None  # not ours: numba's locators take it as usual
        for other in _CacheImpl._locator_classes:
            if other is not cls:
                inner = other.from_function(py_func, py_file)
                if inner is not None:
                    return cls(inner)
        return None


def install() -> None:
    """Put :class:`SimSourceLocator` first in numba's locators (idempotent); must run before any
    ``njit(cache=True)`` of the package is decorated, which ``neurohover/sim/__init__.py`` ensures."""
    if SimSourceLocator not in _CacheImpl._locator_classes:
        _CacheImpl._locator_classes.insert(0, SimSourceLocator)


def compiled_on_disk(dispatcher) -> bool:
    """Whether numba's on-disk cache holds a fresh compilation of ``dispatcher`` (an index whose stamp,
    :func:`sim_source_hash` included, matches): if not, its first call compiles, which takes tens of seconds.
    Any failure to read the cache counts as not compiled."""
    try:
        return bool(dispatcher.signatures) or bool(dispatcher._cache._cache_file._load_index())
    except Exception:  # numba's cache layout is its own: never let a check of it stop a run
        return False
