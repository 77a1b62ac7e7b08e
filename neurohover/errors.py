"""The one exception type for bad input, so the CLI can print its message and exit with status 2."""

from __future__ import annotations


class NeurohoverError(ValueError):
    """Bad input: the message names the bad value and what is allowed."""
