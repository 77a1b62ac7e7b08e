"""The one exception type for bad input, so the CLI can print its message and exit with status 2."""

from __future__ import annotations

import dataclasses
from typing import Any


class NeurohoverError(ValueError):
    """Bad input: the message names the bad value and what is allowed."""


class Terminated(KeyboardInterrupt):
    """SIGTERM arrived where the command handles it (like Ctrl-C: finished work kept, one line, status 143)."""


def raise_terminated(signum, frame) -> None:
    """A SIGTERM handler: the signal as :class:`Terminated` in the main thread."""
    raise Terminated(f"signal {signum}")


def settings_from_dict(cls: type, values: Any, *, unknown_what: str, bad_what: str) -> Any:
    """An instance of the settings dataclass ``cls`` from a dict of some of its fields: unknown keys and
    values ``cls`` refuses (TypeError, ValueError) become one NeurohoverError each, naming them."""
    fields = [f.name for f in dataclasses.fields(cls)]
    unknown = sorted(set(values) - set(fields))
    if unknown:
        raise NeurohoverError(f"unknown {unknown_what} setting(s) {', '.join(unknown)}: allowed {', '.join(fields)}")
    try:
        return cls(**values)
    except (TypeError, ValueError) as err:
        raise NeurohoverError(f"bad {bad_what}: {err}") from None
