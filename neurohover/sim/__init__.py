"""Simulation stage: the compiled kernel, its random streams and the plain-Python reference."""

from . import _cache

# Before any cached function of the package is compiled: a cached kernel must match all of sim/.
_cache.install()
