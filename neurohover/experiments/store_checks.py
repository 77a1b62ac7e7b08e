"""Checks of a results store's file and rows that :class:`~neurohover.experiments.store.Store` makes before it reads or
writes (kept apart from the store's own module, which holds its reads and writes)."""

from __future__ import annotations

import sqlite3

from ..errors import brief, finite_real, whole_number

#: How a session can end (:meth:`Store.end_session`; the runner's statuses). A session is "running" until then.
SESSION_STATUSES = ("finished", "selection finished", "interrupted", "failed")
#: The executors that run sessions (the ``name`` of executors.LocalExecutor and RayExecutor; importing them here is slow).
EXECUTORS = ("local", "ray")


def sqlite_says(conn: sqlite3.Connection) -> str:
    """What SQLite's own ``PRAGMA quick_check`` finds wrong with the file of ``conn`` ('' where it says ok): its pages and
    indexes read back, without the full integrity check's comparison of every index entry. About 0.1 s on the 230 MB
    paper-scale store (docs/reproduction/results.sqlite), so it runs before a store is written, not before it is read."""
    try:
        said = [str(r[0]) for r in conn.execute("PRAGMA quick_check").fetchall()]
    except sqlite3.DatabaseError as err:  # a page it cannot even walk: "database disk image is malformed"
        said = [str(err)]
    return "" if said == ["ok"] else "; ".join(said)


def bad_session(session: dict, stored: int) -> str:
    """What is impossible in a sessions row (checked by :meth:`Store.sessions`), or '': a status no run ends with, an
    executor that runs none, a start before 2001 or after 2106 (not "now": a clock that lags is no damage), unit counts
    below 0, or more units before and run than the experiment stores (only ``update`` and ``fresh`` delete units, and
    both delete the sessions with them). A session killed by SIGKILL stays 'running', and is allowed."""
    statuses = ("running", *SESSION_STATUSES)
    value = session["status"]
    if not isinstance(value, str) or value not in statuses:
        return f"status {brief(value)} is not allowed: allowed {', '.join(map(repr, statuses))}"
    value = session["executor"]
    if not isinstance(value, str) or value not in EXECUTORS:
        return f"executor {brief(value)} is not allowed: allowed {', '.join(map(repr, EXECUTORS))}"
    value = session["started"]
    if not finite_real(value) or not 1e9 <= value < 2**32:  # fixed bounds: a store read on a machine whose clock lags is no damage
        return f"started {brief(value)} is not allowed: allowed a time (seconds since 1970) from 2001 to 2106"
    for field in ("units_before", "units_run"):
        if not whole_number(session[field]) or session[field] < 0:
            return f"{field} {brief(session[field])} is not allowed: allowed a whole number >= 0"
    if session["units_before"] + session["units_run"] > stored:
        counts = f"units_before {session['units_before']} and units_run {session['units_run']}"
        return f"{counts} are not allowed: together at most the {stored} units the experiment stores"
    return ""
