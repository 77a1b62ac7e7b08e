"""Checks of a results store's file and rows that :class:`~neurohover.experiments.store.Store` makes before it reads or
writes (kept apart from the store's own module, which holds its reads and writes)."""

from __future__ import annotations

import contextlib
import functools
import os
import socket
import sqlite3
import threading
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

from ..errors import NeurohoverError, brief, finite_real, refuse_non_text_keys, whole_number
from ..filekinds import SQLITE_HEADER, refuse_sqlite_side_files
from ..jsontext import json_text
from ..locks import WriterLock, hold_file
from ..paths import refuse_dangling_link
from ..sim.constants import MAX_SECONDS
from .config import ExperimentConfig, check_name, check_scale
from .config_changes import config_differs as config_differs  # where store.py takes it from (moved out, T56-A03)
from .result_checks import identity_problem, params_problem
from .results import result_from_dict, result_type
from .units import Unit

#: Whether a store holds experiment (name, scale): its config row, or units of it (orphans, which their readers name).
HELD_SQL = "SELECT EXISTS (SELECT 1 FROM experiments WHERE name = ?1 AND scale = ?2) OR EXISTS (SELECT 1 FROM units WHERE name = ?1 AND scale = ?2)"


def missing_text(store: str, present: list[str], name: str | None, scale: str | None) -> str:
    """:meth:`Store.missing_message`'s words: ``store`` (its path) holds ``present`` (``"NAME (SCALE)"`` each)."""
    at = f" at scale {scale!r}" if scale is not None else ""  # '' too: its clause dropped, the message contradicted itself (T17-10)
    if name is None and not present:
        return f"results store {store!r} holds no experiment yet"
    what = f"no experiment {brief(name)}{at}" if name is not None else f"nothing{at}"
    return f"results store {store!r} holds {what}; it holds: " + (", ".join(present) if present else "nothing yet")


@functools.cache
def table_columns(schema: str) -> dict[str, list[str]]:
    """Each table's columns, as ``schema`` (the store's) makes them (read from an empty store in memory: written down once)."""
    with contextlib.closing(sqlite3.connect(":memory:")) as c:
        c.executescript(schema)
        tables = [t for (t,) in c.execute("SELECT name FROM sqlite_master WHERE type = 'table' AND name NOT LIKE 'sqlite_%'")]
        return {t: [r[1] for r in c.execute(f"PRAGMA table_info({t})")] for t in tables}


def table_keys(conn: sqlite3.Connection, table: str) -> tuple[tuple[str, ...], frozenset[tuple[str, ...]], tuple[str, ...]]:
    """Table ``table``'s primary key (its columns in key order), the columns of each of its unique indexes, and its NOT
    NULL columns, as ``conn`` holds them."""
    info = list(conn.execute(f"PRAGMA table_info({table})"))
    key = tuple(r[1] for r in sorted((r for r in info if r[5]), key=lambda r: r[5]))
    unique = frozenset(tuple(i[2] for i in conn.execute(f"PRAGMA index_info({r[1]!r})")) for r in conn.execute(f"PRAGMA index_list({table})") if r[2])
    return key, unique, tuple(r[1] for r in info if r[3])


@functools.cache
def schema_keys(schema: str) -> dict[str, tuple[tuple[str, ...], frozenset[tuple[str, ...]], tuple[str, ...]]]:
    """Each table's :func:`table_keys` as ``schema`` (the store's) makes them (read from an empty store in memory)."""
    with contextlib.closing(sqlite3.connect(":memory:")) as c:
        c.executescript(schema)
        return {t: table_keys(c, t) for t in table_columns(schema)}


def check_tables(conn: sqlite3.Connection, store: str, schema: str) -> None:
    """Refuse a store whose tables are not the ones ``schema`` (the store's) makes: a column missing (T19-04) or one
    neurohover did not make (T35-B06), or a table rebuilt without its primary key, unique or NOT NULL constraints (a hand
    merge of two stores, or a restore by CREATE TABLE ... AS SELECT): a unit, session or experiment held twice was listed,
    counted and its seconds summed twice, and a second experiment row under another config hash was not seen (T46-B03, T46-B04)."""
    for table, columns in table_columns(schema).items():
        have = [r[1] for r in conn.execute(f"PRAGMA table_info({table})")]
        lacking = [col for col in columns if col not in have]
        if lacking:
            what = "is missing" if not have else f"lacks column(s) {', '.join(lacking)}"
            raise NeurohoverError(f"results store {store!r} is damaged: its table {table} {what}; give another --store file")
        extra = ", ".join(repr(col) for col in have if col not in columns)
        if extra:
            raise NeurohoverError(
                f"results store {store!r} holds column(s) {extra} in its table {table} that neurohover did not make; give another --store file"
            )
        key, unique, not_null = schema_keys(schema)[table]
        held = table_keys(conn, table)
        if held == (key, unique, not_null):
            continue
        rebuilt = "rebuilt without neurohover's constraints, by a hand merge or a restore with CREATE TABLE ... AS SELECT?"
        fix = "give another --store file, or copy the rows (each key once) into the tables of a store neurohover made"
        if held[:2] == (key, unique):
            lax = ", ".join(c for c in not_null if c not in held[2])
            raise NeurohoverError(
                f"results store {store!r} is damaged: its table {table} lets column(s) {lax} hold NULL (its NOT NULL is gone: {rebuilt}); {fix}"
            )
        what = "lacks its primary key" if not held[0] else "lacks the primary key and unique constraints neurohover makes,"
        twice = conn.execute(f"SELECT {', '.join(key)} FROM {table} GROUP BY {', '.join(key)} HAVING count(*) > 1 LIMIT 1").fetchone()
        said = f", and holds the row of {', '.join(f'{k} {brief(v)}' for k, v in zip(key, twice))} more than once" if twice else ""
        raise NeurohoverError(
            f"results store {store!r} is damaged: its table {table} {what} ({', '.join(key)}){said} ({rebuilt}): a row held twice is "
            f"read and counted twice; {fix}"
        )


@functools.cache
def text_columns(schema: str) -> dict[str, tuple[str, ...]]:
    """Each table's TEXT columns, as ``schema`` (the store's) makes them."""
    with contextlib.closing(sqlite3.connect(":memory:")) as c:
        c.executescript(schema)
        return {t: tuple(r[1] for r in c.execute(f"PRAGMA table_info({t})") if r[2] == "TEXT") for t in table_columns(schema)}


def refuse_wrong_cells(read: Callable[[str, tuple, str], list], store: str, schema: str, name: str | None, scale: str | None) -> None:
    """Refuse a store whose TEXT column holds a cell of another storage class (SQLite keeps a hand-written BLOB as it is
    there), naming its table, row and column: a BLOB key was returned by results() as bytes and was export's TypeError, a
    BLOB worker json's (T47-B03). ``read`` is the store's reader (sql, params, what). ``scale`` given: every text cell of
    experiment (name, scale)'s rows in each table; else the experiments table's listed cells (of experiment ``name``, if given)."""
    tables = text_columns(schema) if scale is not None else {"experiments": ("name", "scale", "config_hash")}
    params = (name, scale) if scale is not None else (name,) if name is not None else ()
    where = " AND name = ?1" + (" AND scale = ?2" if scale is not None else "") if params else ""
    for table, columns in tables.items():
        odd = " OR ".join(f"typeof({col}) != 'text'" for col in columns)
        sql = f"SELECT rowid, {', '.join(columns)} FROM {table} WHERE ({odd}){where} LIMIT 1"
        for rowid, *cells in read(sql, params, f"its table {table}"):
            col, value = next((c, v) for c, v in zip(columns, cells) if not isinstance(v, str))
            what = "a BLOB" if isinstance(value, bytes) else "NULL" if value is None else "a number"
            key = dict(zip(columns, cells)).get("key")
            unit = f" (unit {key!r})" if isinstance(key, str) else ""
            raise NeurohoverError(
                f"results store {store!r} is damaged: its table {table}, row {rowid}{unit}, column {col} holds {what} ({brief(value)}), "
                "not the text neurohover writes there (a hand edit?); give another --store file, or reproduce --fresh to run the experiment over"
            )


#: How a session can end (:meth:`Store.end_session`; the runner's statuses). A session is "running" until then.
SESSION_STATUSES = ("finished", "selection finished", "interrupted", "failed")
#: The times a store records (a session's start, a unit's finish, an experiment's creation), in seconds since 1970: fixed
#: bounds, not "now" (a store read on a machine whose clock lags is no damage; one whose clock reads outside them writes
#: none: store_clock.clock_time, T50-A03). 0 and 1e12 were taken (T45-B02).
TIME_ALLOWED = "allowed a time (seconds since 1970) from 2001 to 2106"


def time_allowed(value: Any) -> bool:
    """Whether ``value`` is a time a store may record (:data:`TIME_ALLOWED`)."""
    return finite_real(value) and 1e9 <= value < 2**32


def seconds_said(value: Any) -> str:
    """What is wrong with a stored duration that is no :func:`~neurohover.sim.constants.seconds_allowed` (a unit's
    seconds, a session's wall seconds): 1e300 was exported (T45-B02)."""
    if finite_real(value) and value > 0:
        return f"{brief(value)} is more than {MAX_SECONDS:.6g} seconds: 100 years at most"
    return f"{value!r:.40} is no number of seconds >= 0"


def unit_seconds_problem(seconds: float, result: Any) -> str:
    """Why a unit's stored ``seconds`` contradict its typed ``result``'s own timing, or '': the store records the
    executor's time of the whole unit (executors.timed_run), which holds the run its result times (units.py), so never
    less (1e300, and 0 for a run of 0.64 s, read alike; T45-B02). A result without timing (a diagnostic's) is not checked."""
    timing = getattr(result, "timing", None)
    if timing is None:
        return ""
    inner = float(timing.learn_seconds) + float(timing.evolve_seconds) if hasattr(timing, "learn_seconds") else float(timing.seconds)
    if inner > seconds * (1 + 1e-9) + 1e-6:
        return (
            f"its seconds {brief(seconds)} are not allowed: the store times the whole unit, which holds its result's own "
            f"timing of {brief(inner)} seconds: allowed at least that"
        )
    return ""


#: The executors that run sessions (the ``name`` of executors.LocalExecutor and RayExecutor; importing them here is slow).
EXECUTORS = ("local", "ray")


class GuardedConnection(sqlite3.Connection):
    """A store's connection, which any thread may use, one statement or transaction at a time (each holds :attr:`guard`):
    a Store opened in one thread and written from another was sqlite3's ProgrammingError, and its reads called the store
    damaged (T32-B09)."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.guard = threading.RLock()
        self.store = str(args[0]) if args else "?"  # the store's name in a failed write's message (the Store sets it as given)


#: SQLite's errors of a write that the disk or a file-size limit refused (EFBIG under ``ulimit -f`` is SQLITE_IOERR_WRITE).
WRITE_ERRORS = ("SQLITE_FULL", "SQLITE_IOERR_WRITE", "SQLITE_IOERR_FSYNC", "SQLITE_IOERR_DIR_FSYNC", "SQLITE_IOERR_TRUNCATE", "SQLITE_IOERR_DELETE")


def write_failed(err: sqlite3.Error) -> bool:
    """Whether SQLite's ``err`` says a write failed (a full disk, a file-size limit), the store itself sound: it was
    called "damaged or no results store" (T32-A04)."""
    return getattr(err, "sqlite_errorname", "") in WRITE_ERRORS or "full" in str(err)


class StoreWriteError(NeurohoverError):
    """A write to a results store that the disk or a file-size limit refused (:func:`write_failure`); ``reason`` is
    SQLite's word for it, which a store being made names in its own message."""

    def __init__(self, message: str, reason: str) -> None:
        super().__init__(message)
        self.reason = reason


def write_failure(store: str, err: sqlite3.Error) -> StoreWriteError:
    """The one message of a write to results store ``store`` that ``err`` (:func:`write_failed`) refused."""
    return StoreWriteError(
        f"cannot write the results store {store!r} ({err}: the disk is full or a file-size limit, ulimit -f, is reached); "
        "its finished units are kept, and the same command resumes once there is room",
        str(err),
    )


def refuse_moved(path: Path, file: Path, opened: tuple[int, int]) -> None:
    """Refuse to read or write store ``path`` once its ``file`` (absolute) names no file, or another file than the one
    opened (device and inode): SQLite wrote into the moved or removed file ('attempt to write a readonly database') and read
    its old rows without a word (T32-B10)."""
    try:
        now = os.stat(file)
        same = (now.st_dev, now.st_ino) == opened
    except OSError:
        same = False
    if not same:
        raise NeurohoverError(
            f"results store {str(path)!r} is gone: its file was moved, removed or replaced since this Store opened it; "
            "nothing was read or written: open it again with Store(path)"
        )


@contextlib.contextmanager
def transaction(c: GuardedConnection) -> Iterator[None]:
    """One write transaction (taking the write lock at once): committed when the block ends, rolled back
    when it raises. A Ctrl-C landing just after the COMMIT stays a Ctrl-C: there is nothing left to roll back. One thread's at a time."""
    with c.guard:
        c.execute("BEGIN IMMEDIATE")
        try:
            yield
            c.execute("COMMIT")
        except BaseException as err:
            if c.in_transaction:
                with contextlib.suppress(sqlite3.Error):  # its own failure is no news: the write failed
                    c.execute("ROLLBACK")
            if isinstance(err, sqlite3.Error) and write_failed(err):
                raise write_failure(c.store, err) from None
            raise


def check_experiment(name: Any, scale: Any, where: str) -> None:
    """Refuse an experiment name or scale that no config has (5 was stored as '5', '' and NUL were taken; fourteenth
    trial, T14-5): names as :func:`~neurohover.experiments.config.check_name` allows, scales quick, paper or settings-HASH."""
    check_name(name, where)
    check_scale(scale, where)


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
    executor that runs none, cores not in 1..:data:`MAX_CORES`, a start before 2001 or after 2106 (not "now": a clock that lags is no damage), unit counts
    below 0, or more units before and run than the experiment stores (only ``update`` and ``fresh`` delete units, and
    both delete the sessions with them). A session killed by SIGKILL stays 'running', and is allowed."""
    statuses = ("running", *SESSION_STATUSES)
    value = session["status"]
    if not isinstance(value, str) or value not in statuses:
        return f"status {brief(value)} is not allowed: allowed {', '.join(map(repr, statuses))}"
    value = session["executor"]
    if not isinstance(value, str) or value not in EXECUTORS:
        return f"executor {brief(value)} is not allowed: allowed {', '.join(map(repr, EXECUTORS))}"
    value = session["cores"]  # 2**62 was read and exported (T47-B12)
    if not whole_number(value) or not 1 <= value <= MAX_CORES:
        return f"cores {brief(value)} is not allowed: allowed a whole number from 1 to {MAX_CORES:,}"
    value = session["started"]
    if not time_allowed(value):
        return f"started {brief(value)} is not allowed: {TIME_ALLOWED}"
    for field in ("units_before", "units_run"):
        if not whole_number(session[field]) or session[field] < 0:
            return f"{field} {brief(session[field])} is not allowed: allowed a whole number >= 0"
    if session["units_before"] + session["units_run"] > stored:
        counts = f"units_before {session['units_before']} and units_run {session['units_run']}"
        return f"{counts} are not allowed: together at most the {stored} units the experiment stores"
    return ""


def read_config(stored: Any, scale: str) -> ExperimentConfig:
    """The experiment config a store row at ``scale`` holds (:meth:`ExperimentConfig.from_dict`), or one NeurohoverError
    naming what is wrong with it: what every reader (``results``, ``report``, reproduce's check) and :meth:`Store.begin`
    require, so the store never takes a config its readers call damaged (T29-B07)."""
    config = ExperimentConfig.from_dict(stored)
    if config.scale != scale:  # a quick config under a 'paper' row was reported as the paper's claims (T21-01)
        raise NeurohoverError(f"its row is at scale {scale!r} but its config is the {brief(config.scale)} one")
    return config


def hash_problem(held: Any, stored: dict, config: ExperimentConfig) -> str:
    """Why the config hash ``held`` of an experiment row cannot be its config's (``stored``, read as ``config``), or '':
    a config_hash set to 'deadbeef' was exported and reported (T20-04); the readers and :meth:`Store.begin` refuse it."""
    if held != config.hash or stored.get("hash") != held:
        return (
            f"its config hashes to {config.hash}, but the store records config hash {brief(held)} (its config: {brief(stored.get('hash'))}): "
            "the config or its hash was changed after its units were run, or another version of neurohover wrote it, so its units "
            "cannot be told to be this config's (reproduce --fresh runs it again)"
        )
    return ""


def config_problem(config: dict, scale: str, config_hash: str) -> str:
    """Why :meth:`Store.begin` or :meth:`Store.update` cannot store ``config`` under ``config_hash`` at ``scale``, or '':
    what :func:`read_config` and :func:`hash_problem` would later call damaged (any JSON object was taken; T29-B07)."""
    try:
        return hash_problem(config_hash, config, read_config(config, scale))
    except NeurohoverError as err:
        return str(err).removeprefix("a stored experiment config is damaged: ")


def experiment_problem(conn: sqlite3.Connection, name: str, scale: str, config_hash: str) -> str:
    """Why a session of experiment (name, scale) under ``config_hash`` cannot be recorded, or '': the store holds no
    such experiment, or holds it under another config hash (the store's own sessions() called such rows damaged; T29-B04)."""
    row = conn.execute("SELECT config_hash FROM experiments WHERE name = ? AND scale = ?", (name, scale)).fetchone()
    if row is None:
        return f"the store holds no experiment {brief(name)} ({scale}): begin registers it first"
    if row[0] != config_hash:
        return f"config_hash = {brief(config_hash)} is not allowed: experiment {name} ({scale}) has config hash {brief(row[0])}"
    return ""


def session_problem(conn: sqlite3.Connection, session: int, of: tuple[str, str, str] | None = None) -> str:
    """Why session ``session`` cannot count a unit of experiment ``of`` (name, scale, config hash; None: end_session's
    any), or end, or '': the store has no such session, it is another experiment's (or another config's),
    or it has already ended (the store's own sessions() called the counts damaged; T29-B05)."""
    row = conn.execute("SELECT name, scale, config_hash, status FROM sessions WHERE id = ?", (session,)).fetchone()
    if row is None:
        return f"session = {session} is not allowed: the store has no such session (start_session gives the id)"
    if of is not None and tuple(row[:3]) != of:
        return (
            f"session = {session} is not allowed: it is a session of experiment {brief(row[0])} ({brief(row[1])}) under config hash "
            f"{brief(row[2])}, not of {of[0]} ({of[1]}) under {of[2]}"
        )
    if row[3] != "running":
        return f"session = {session} is not allowed: it has already ended ({brief(row[3])}); start_session gives a running one"
    return ""


def check_text(value: Any, what: str, where: str, empty: bool = False) -> None:
    """Refuse a stored text field that is no text, empty (unless ``empty``), holding NUL (None was an IntegrityError) or
    a character UTF-8 cannot encode (a lone surrogate, '\\ud800', was SQLite's UnicodeEncodeError; T31-B06)."""
    allowed = "text" if empty else "non-empty text"
    if not isinstance(value, str) or (not value and not empty) or "\x00" in value:
        raise NeurohoverError(f"{where}: {what} = {brief(value)} is not allowed: give {allowed} without NUL characters")
    try:
        value.encode("utf-8")
    except UnicodeEncodeError as err:
        raise NeurohoverError(
            f"{where}: {what} = {brief(value)} is not allowed: it holds {ascii(err.object[err.start : err.end])}, a lone surrogate, "
            f"which UTF-8 cannot store: give {allowed} without lone surrogates"
        ) from None


#: The largest whole number an SQLite INTEGER holds (10**30 cores was Python's OverflowError; T33-B18).
SQLITE_INT_MAX = 2**63 - 1
#: The most cores a session may record (2**20, more than any cluster runs one experiment on): 2**62 was read and exported (T47-B12).
MAX_CORES = 2**20


def stored_count(value: Any, what: str, where: str, least: int, most: int = SQLITE_INT_MAX) -> int:
    """``value`` as an int from ``least`` to ``most`` (:data:`SQLITE_INT_MAX`, or :data:`MAX_CORES`), or one error naming it
    (cores=0 was stored, and read back as damaged)."""
    if not whole_number(value) or not least <= value <= most:
        top = "2**63 - 1, SQLite's largest" if most == SQLITE_INT_MAX else f"{most:,}"
        raise NeurohoverError(f"{where}: {what} = {brief(value)} is not allowed: give a whole number >= {least} (at most {top})")
    return int(value)


def check_executor(executor: Any, where: str) -> None:
    """Refuse an executor no session may hold (:data:`EXECUTORS`): 'LOCAL' was stored, and :meth:`Store.sessions` then
    called the session damaged (T33-B17)."""
    check_text(executor, "executor", where)
    if executor not in EXECUTORS:
        raise NeurohoverError(f"{where}: executor = {brief(executor)} is not allowed: give one of {', '.join(map(repr, EXECUTORS))}")


def unit_texts(unit: Any, result: Any, name: str, where: str) -> tuple[str, str]:
    """A finished unit's params and result as the store writes them (JSON text), or one error naming what its readers
    would call damaged: no Unit, a key, kind or params that cannot be stored, a unit of another experiment (T29-B05), a
    result that is no result of its kind, or that contradicts its unit's params (:func:`~.export.checked_units`' checks of
    one unit: a test run's result {'x': 1} was stored, and every later results and report refused the experiment;
    T33-B17). Whether the stored config plans the unit is the readers' check of the whole experiment."""
    if not isinstance(unit, Unit):
        raise NeurohoverError(f"{where}: unit = {brief(unit)} is not allowed: give the Unit that finished (a plan's)")
    check_text(unit.key, "the unit's key", where)
    check_text(unit.kind, "the unit's kind", where)
    check_unit_kind(unit.key, unit.kind, where)
    params = object_text(unit.params, f"unit {unit.key}'s params", where)
    text = object_text(result, f"unit {unit.key}'s result", where)
    if unit.experiment != name:  # stored under another experiment's name without a word (T29-B05)
        raise NeurohoverError(f"{where}: unit {brief(unit.key)}'s experiment = {brief(unit.experiment)} is not allowed: give a unit of {name} (its plan's)")
    try:
        problem = identity_problem(unit.kind, result, unit.params) or params_problem(result_from_dict(unit.kind, result, unit.key), unit.params)
    except NeurohoverError as err:
        problem = str(err)
    if problem:
        raise NeurohoverError(f"{where}: {problem}: give the result run_unit returned for the unit")
    return params, text


def object_text(value: Any, what: str, where: str) -> str:
    """``value``'s JSON text, if it is a JSON object that reads back (:func:`~neurohover.jsontext.strict_json`), or one error
    naming it: a list was stored and every later read called the store damaged, NaN was json's ValueError (T14-5)."""
    if not isinstance(value, dict):
        raise NeurohoverError(f"{where}: {what} = {brief(value)} is not allowed: give a dict (a JSON object)")
    try:
        text = json_text(value, separators=(",", ":"))  # what is written reads back: no key twice ({1: .., '1': ..}), no NaN
    except (TypeError, ValueError, RecursionError) as err:  # JSONError is a ValueError
        raise NeurohoverError(
            f"{where}: {what} = {brief(value)} is not allowed: give a JSON object of text, finite numbers, bools, None, lists and such objects "
            f"({str(err)[:80]})"
        ) from None
    refuse_non_text_keys(value, f"{where}:", what)  # {1: 2} was stored, and read back as {'1': 2} (T32-B11)
    return text


def check_unit_kind(key: str, kind: Any, where: str) -> None:
    """Refuse a unit of a kind its readers do not know, by their own check (:func:`~neurohover.experiments.results.result_type`):
    a unit of kind 'banana' was stored, and export and results then called the store damaged (T30-B03)."""
    try:
        result_type(kind)
    except NeurohoverError as err:
        raise NeurohoverError(f"{where}: unit {brief(key)}: {err}") from None


def take_writer_lock(lock: WriterLock, path: Path, file: Path, held: int | None) -> int:
    """Take the writer lock of the results store ``path`` (as given): its lock file, then (unless ``held``, the descriptor
    already held) its file ``file`` itself, as a hard link has another lock file (T32-A08). Returns that file's
    descriptor (-1: no locks here). A lock this very process holds, through another open Store, is named as such: it was
    "another run (pid <its own pid>)", and waiting for it never helped (T34-B14)."""
    busy = "wait for that run to end (or stop it), or give another --store file. Reading it (results, report) works meanwhile"
    own = f"pid {os.getpid()} on host {socket.gethostname()}"

    def holder(who: str) -> str:
        if who == own:
            return f"results store {str(path)!r} is in use: another open Store of this process ({own}) is writing it; close() that Store first"
        return f"results store {str(path)!r} is in use: another run ({who}) is writing it; {busy}"

    try:
        lock.acquire(holder)
    except OSError as err:
        raise NeurohoverError(f"cannot open {str(lock.path)!r}, the writer lock of results store {str(path)!r}: {err.strerror}") from None
    if held is not None:
        return held
    try:
        return hold_file(file, f"results store {str(path)!r} is in use: another run is writing it under another name (a hard link); {busy}")
    except (NeurohoverError, OSError):
        lock.release()
        raise


def let_go(lock: WriterLock, held: int, pid: int) -> None:
    """Drop a store's writer lock: close its file's descriptor ``held`` and release ``lock``; in a process forked from the
    holder ``pid``, nothing (its parent still writes). :meth:`Store.close` calls it, and so does the garbage collector for
    a Store dropped unclosed: its lock was kept until the process ended (T34-B14)."""
    if os.getpid() != pid:
        return
    if held >= 0:
        os.close(held)
    lock.release()


#: The longest full path (bytes, symbolic links resolved, as SQLite's unix VFS resolves them) that SQLite opens a store
#: by: its limit is 512 bytes (SQLITE_MAX_PATHNAME, NUL included), and it makes the ``-journal`` name (8 more) from
#: it, read or written. Found by experiment (SQLite 3.40): 504 bytes open, 505 are its bare "unable to open database
#: file", however short --store or each of its names is (a deep working directory; T44-A05).
SQLITE_MAX_PATH = 504


def refuse_long_store_path(path: Path) -> None:
    """Refuse a results store whose full path is longer than SQLite opens (:data:`SQLITE_MAX_PATH`), naming its length."""
    try:
        size = len(os.fsencode(os.path.realpath(path)))
    except (OSError, UnicodeError, ValueError):  # unresolvable or unencodable: refused by name elsewhere, or SQLite says
        return
    if size > SQLITE_MAX_PATH:
        raise NeurohoverError(
            f"results store {brief(str(path))} is too long for SQLite: its full path (the working directory and links "
            f"resolved) is {size:,} bytes, and SQLite opens at most {SQLITE_MAX_PATH} (its limit of 512 less the 8 of "
            f"'-journal'); give a path in a folder nearer the root"
        )


def new_store(path: Path) -> bool:
    """Whether a writer makes a new results store at ``path``: nothing is there, or an empty (0-byte) file. The one
    decision :class:`~neurohover.experiments.Store` and compete share (compete refused the empty file reproduce takes,
    T49-A02); a reader refuses an empty file (:func:`check_store_file`)."""
    return not path.is_file() or path.stat().st_size == 0


def check_store_file(path: Path, given: str | Path, create: bool) -> None:
    """Refuse a results store ``path`` (``given``) that :class:`~neurohover.experiments.Store` cannot open as one, each
    by what it is: missing where it is read, a directory, a device, empty where read, a file of another kind, a link to
    nowhere, or beside a file SQLite would take for its journal and delete (:func:`~neurohover.filekinds.refuse_sqlite_side_files`)."""
    if not path.exists() and not create:
        raise NeurohoverError(f"results store {str(path)!r} does not exist")
    if path.exists() and path.is_dir():
        raise NeurohoverError(f"results store {str(path)!r} is a directory; give a file name")
    if path.exists() and not path.is_file():  # a device was taken for a new store, and deleted (fifth trial)
        raise NeurohoverError(f"results store {str(path)!r} is not a regular file (a device, pipe or socket); give a file name")
    if not create and path.stat().st_size == 0:  # read, it was given the schema: a refused command changed it (seventh trial)
        raise NeurohoverError(f"results store {str(path)!r} is empty (0 bytes): it holds no experiment yet")
    with contextlib.suppress(OSError), open(path, "rb") as f:  # missing or unreadable: SQLite says so
        if f.read(len(SQLITE_HEADER)) not in (b"", SQLITE_HEADER):  # 1 byte: SQLite took it as empty (T31-B01)
            raise NeurohoverError(f"{str(path)!r} is not a neurohover results store (it does not start with SQLite's header {SQLITE_HEADER!r})")
    refuse_dangling_link(path, "results store", given)  # SQLite's "unable to open database file" (T38-B07), as --store says
    refuse_sqlite_side_files(path, given)  # X-journal, another store so named, deleted as X opened (T39-A01, T39-A03)
    refuse_long_store_path(path)  # SQLite's bare "unable to open database file" (T44-A05)
