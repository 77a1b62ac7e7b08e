"""The times and durations a results store records, and the clocks its writer reads them from (T50-A02, T50-A03).

A store records stamps (an experiment's creation, a session's start, a unit's finish), read from the system clock, and
durations (a unit's seconds, a session's wall seconds). A duration is measured in the writing process on a monotonic
clock: a unit's seconds are the executor's ``perf_counter`` (``executors.timed_run``, compete's runs too), a session's
wall seconds :class:`SessionClocks`'. A session's was the difference of two stamps, and a clock stepped back during a run
(an NTP correction, a resumed virtual machine) stored a negative one that every reader then called damaged (T50-A02).

A stamp is written only where its readers take it (:func:`~.store_checks.time_allowed`: 2001 to 2106, fixed bounds).
A machine whose clock reads outside them (one never set reads 1970) wrote stores no reader accepted (T50-A03): such a
writer is refused before it makes or writes anything (:func:`clock_time`: one message naming what the clock reads; set
the system clock), while the readers keep their window: a store read where the clock lags is no damage.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

from ..errors import NeurohoverError, brief
from ..sim.constants import MAX_SECONDS, seconds_allowed
from .store_checks import TIME_ALLOWED, seconds_said, time_allowed

#: A session's wall seconds as an UPDATE sets them from :meth:`SessionClocks.wall`'s two values: the monotonic seconds
#: this writer measured, or (a session another Store started) now minus its start, within 0 .. MAX_SECONDS.
WALL_SQL = f"wall_seconds = COALESCE(?, MIN(MAX(? - started, 0), {MAX_SECONDS!r}))"


def clock_time(where: str) -> float:
    """The system clock's time, for a stamp a writer records, refused (``where`` names the store) when the store's
    readers would call it damaged (:data:`~.store_checks.TIME_ALLOWED`)."""
    now = time.time()
    if time_allowed(now):
        return now
    try:
        shown = time.strftime("%Y-%m-%d %H:%M:%S UTC, ", time.gmtime(now))
    except (OverflowError, OSError, ValueError):
        shown = ""
    raise NeurohoverError(
        f"{where}: the system clock's time {brief(now)} ({shown}seconds since 1970) is not allowed: a results store records "
        f"times from 2001 to 2106, as its readers require; set the system clock (nothing was written)"
    )


class SessionClocks:
    """The monotonic time at which each session this writer started began (:meth:`Store.start_session`)."""

    def __init__(self) -> None:
        self._started: dict[int, float] = {}

    def start(self, session: int) -> None:
        self._started[session] = time.monotonic()

    def wall(self, session: int) -> tuple[float | None, float]:
        """The two values :data:`WALL_SQL` takes: the session's seconds so far on the monotonic clock (None where
        another Store started it), and the system clock's time."""
        started = self._started.get(session)
        return (None if started is None else max(0.0, time.monotonic() - started)), time.time()


def stored_seconds(store: Path, value: Any, what: str) -> float:
    """A stored duration, or one error naming the damaged row (text was a TypeError in report, seventh trial; 1e300 exported, T45-B02)."""
    if seconds_allowed(value):
        return value
    raise NeurohoverError(f"results store {str(store)!r}: {what} is damaged ({seconds_said(value)})")


def stored_time(store: Path, value: Any, what: str) -> float:
    """A stored time (:data:`~.store_checks.TIME_ALLOWED`), or one error naming the damaged row (1e12 exported; T45-B02)."""
    if not time_allowed(value):
        raise NeurohoverError(f"results store {str(store)!r}: {what} {brief(value)} is damaged: {TIME_ALLOWED}")
    return value
