"""The results store: one embedded SQLite file (Python's sqlite3, no server).

Tables (schema version :data:`SCHEMA_VERSION`, kept in ``PRAGMA user_version``; the file is marked
as a neurohover store by ``PRAGMA application_id``)::

    experiments(name, scale, config_hash, config, created)        one row per (name, scale)
    units(name, scale, key, kind, config_hash, params, result,    one row per finished unit
          seconds, worker, finished)
    sessions(id, name, scale, config_hash, executor, cores,       one row per `reproduce` call
             started, wall_seconds, units_run, units_before, status)

One store holds any number of experiments, keyed by name and scale. An experiment's config hash
is fixed when it is first written: running the same name and scale with a different config is
refused (never silently mixed), as is a store of another schema version or a file that is not a
neurohover store.

Durability: each finished unit is written in its own transaction (with its session's counters)
the moment it finishes, so an interrupted run (Ctrl-C or SIGKILL) loses no finished unit, and
running again with the same store skips every finished unit.

One writer: a run holds an OS lock (``flock``) on ``STORE.lock`` beside the store, and on the store's file itself (a
hard link has another lock file), from its first write until it closes the store, and writes its pid there; a second
run is refused, naming that pid. Closing the store (or dropping it unclosed) removes the file; the kernel drops the lock
when its process dies, so a killed run (which leaves the file) never blocks the next one.
Readers (``results``, ``report``) take no lock.
"""

from __future__ import annotations

import json
import os
import socket
import sqlite3
import weakref
from collections.abc import Iterable
from pathlib import Path
from typing import Any

from ..errors import NeurohoverError, brief, check_flag
from ..filekinds import refuse_long_store_name, refuse_sqlite_name
from ..jsontext import JSONError, strict_json
from ..paths import WriterLock
from .put_checks import planned_problem, put_arguments
from .store_checks import (
    HELD_SQL,
    MAX_CORES,
    SESSION_STATUSES,
    TIME_ALLOWED,
    GuardedConnection,
    StoreWriteError,
    bad_session,
    check_executor,
    check_experiment,
    check_store_file,
    check_tables,
    check_text,
    config_differs,
    config_problem,
    experiment_problem,
    let_go,
    missing_text,
    new_store,
    object_text,
    refuse_moved,
    refuse_wrong_cells,
    session_problem,
    sqlite_says,
    stored_count,
    take_writer_lock,
)
from .store_checks import transaction as _transaction
from .store_clock import WALL_SQL, SessionClocks, clock_time, stored_seconds, stored_time

SCHEMA_VERSION = 1

APPLICATION_ID = 0x4E484F56  # "NHOV"

_SCHEMA = """
CREATE TABLE experiments (
    name TEXT NOT NULL, scale TEXT NOT NULL, config_hash TEXT NOT NULL, config TEXT NOT NULL,
    created REAL NOT NULL, PRIMARY KEY (name, scale));
CREATE TABLE units (
    name TEXT NOT NULL, scale TEXT NOT NULL, key TEXT NOT NULL, kind TEXT NOT NULL,
    config_hash TEXT NOT NULL, params TEXT NOT NULL, result TEXT NOT NULL, seconds REAL NOT NULL,
    worker TEXT NOT NULL, finished REAL NOT NULL, PRIMARY KEY (name, scale, key));
CREATE TABLE sessions (
    id INTEGER PRIMARY KEY AUTOINCREMENT, name TEXT NOT NULL, scale TEXT NOT NULL,
    config_hash TEXT NOT NULL, executor TEXT NOT NULL, cores INTEGER NOT NULL, started REAL NOT NULL,
    wall_seconds REAL NOT NULL, units_run INTEGER NOT NULL, units_before INTEGER NOT NULL,
    status TEXT NOT NULL);
"""


def _dumps(obj: Any) -> str:
    return json.dumps(obj, separators=(",", ":"), allow_nan=False)


class Store:
    """A results store file (created if missing).

    >>> store = Store("results.sqlite")
    >>> store.experiments()          # [(name, scale, config_hash, units), ...]
    """

    def __init__(self, path: str | Path, *, create: bool = True) -> None:
        from ..paths import checked_path, make_dirs

        create = check_flag(create, "create", "make the store if missing")  # create='no' was true (sixth trial)

        self.path = checked_path(path, "results store", "results store's file path", file=True)  # None, 3, NUL, too long, 'x/', __fspath__ 5 (T32-B08, T47-B07)
        refuse_sqlite_name(path, "results store")  # ':memory:' and 'file:' URIs: never a file (as given: './file:x' is one; T32-A01, T32-A02)
        if create:  # its -journal too (a reader writes none; T31-A03)
            refuse_long_store_name(path, "results store")
        check_store_file(self.path, path, create)  # what SQLite would open, or delete beside it, before it does
        if create and new_store(self.path):  # a clock its readers refuse: no store made (T50-A03)
            clock_time(f"cannot create the results store {str(self.path)!r}")
        self._clocks = SessionClocks()  # its sessions' wall seconds, on the monotonic clock (T50-A02)
        make_dirs(self.path.parent, "results store", str(path))  # a file as its parent was pathlib's FileExistsError (fifteenth trial, T15-10)
        self._lock = WriterLock(self.lock_path)
        new = new_store(self.path)
        try:
            # By its absolute path: SQLite reads a name beginning 'file:' as a URI, whatever uri= says (T32-A02).
            self.conn = sqlite3.connect(os.path.abspath(self.path), timeout=30.0, isolation_level=None, check_same_thread=False, factory=GuardedConnection)
            self.conn.store = str(self.path)  # as given, in a failed write's message (T32-A04)
            self.conn.execute("PRAGMA synchronous = FULL")
            self._check_schema()
            opened = os.stat(self.path)  # its file, as later reads and writes check (T32-B10)
            self._file, self._ident = Path(os.path.abspath(self.path)), (opened.st_dev, opened.st_ino)
        except (sqlite3.OperationalError, OSError, StoreWriteError) as err:
            if new:  # it could not be made (disk full, read-only): no empty file left that a later run takes for a store
                self._close_quietly()
                for made in (self.path, self.path.with_name(self.path.name + "-journal")):
                    made.unlink(missing_ok=True)
                raise NeurohoverError(f"cannot create the results store {str(self.path)!r} ({getattr(err, 'reason', err)}); no file is left") from None
            if isinstance(err, StoreWriteError):
                raise
            raise NeurohoverError(f"results store {str(self.path)!r} cannot be read ({err})") from None
        except sqlite3.DatabaseError as err:
            raise NeurohoverError(f"{str(self.path)!r} is not a neurohover results store (SQLite says: {err})") from None
        except NeurohoverError:
            self._close_quietly()  # refused (another schema, a damaged table): its file not left open
            raise

    _closed = False
    _held: int | None = None  # the descriptor of the store's file flocked while writing (-1: no locks here)
    _let_go: weakref.finalize | None = None  # drops the writer lock: close(), or the garbage collector (T34-B14)

    @property
    def conn(self) -> GuardedConnection:
        """The store's open connection; once :meth:`close` ran, one NeurohoverError saying so (a closed Store was
        reported as a damaged file, which may lead a user to delete a good store; eleventh trial)."""
        if self._closed:
            raise NeurohoverError(f"this Store ({str(self.path)!r}) was closed: open it again with Store(path)")
        return self._conn

    @conn.setter
    def conn(self, value: GuardedConnection) -> None:
        self._conn = value

    def _close_quietly(self) -> None:
        """Close the connection if one was opened (a failed open's cleanup)."""
        conn = getattr(self, "_conn", None)
        if conn is not None:
            conn.close()

    def close(self) -> None:
        """Close the file and drop the writer lock; closing again does nothing."""
        if self._closed:
            return
        self.conn.close()
        if self._let_go is not None:
            self._let_go()
        self._closed = True

    # ------------------------------------------------------------------ one writer

    @property
    def lock_path(self) -> Path:
        """The lock file beside the store's own file (``STORE.lock``, symbolic links followed), there while a run writes it.

        Through a link to the store, a second run locked a lock file of the link's name and wrote beside the first
        (ninth trial); two hard links to one file are still two names (give one store one name)."""
        real = Path(os.path.realpath(self.path))
        return real.with_name(real.name + ".lock")

    def lock(self) -> None:
        """Make this Store the file's only writer until :meth:`close` (does nothing if it already is). Every write calls it
        first: a second Store put and started sessions while the first held the lock (T29-B06).

        Two runs writing one store would each compute every unit the other has not finished yet.
        The lock is an OS advisory lock on :attr:`lock_path`, which the kernel releases when the
        holder's process ends in any way, so a lock can never be left behind.

        Raises
        ------
        NeurohoverError
            If another live process (or another Store in this one) holds the lock; the message names
            the store and the holder's pid.
        """
        with self.conn.guard:  # a closed Store refused by name before it locks the file; one thread at a time (T32-B09)
            refuse_moved(self.path, self._file, self._ident)
            self._held = take_writer_lock(self._lock, self.path, self._file, self._held)
            if self._let_go is None:  # dropped unclosed, the Store lets go when collected (T34-B14)
                self._let_go = weakref.finalize(self, let_go, self._lock, self._held, os.getpid())
            self.check_sound()

    _sound = False  # SQLite's own check passed, once per open for writing

    def check_sound(self) -> None:
        """Refuse to write into a file SQLite itself calls malformed (:func:`~.store_checks.sqlite_says`): garbage over
        one experiment's pages was refused for that experiment, while compete and reproduce of another wrote on into it
        (T27-A09). Once per open, before its first write."""
        if not self._sound:
            said = sqlite_says(self.conn)
            if said:
                raise NeurohoverError(
                    f"results store {str(self.path)!r} is damaged: SQLite's quick_check says {brief(said)}; nothing was written "
                    "into it: give another --store file (or a sound copy of it)"
                )
            self._sound = True

    def __reduce__(self):  # copy.deepcopy, pickle: "cannot pickle 'GuardedConnection' object" (T38-B04)
        raise NeurohoverError(
            f"a Store ({str(self.path)!r}) holds an open SQLite connection and cannot be pickled or copied: pass its path and open Store(path) where it is used"
        )

    def __enter__(self) -> Store:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    # ------------------------------------------------------------------ schema

    def _check_schema(self) -> None:
        c = self.conn
        version = c.execute("PRAGMA user_version").fetchone()[0]
        app = c.execute("PRAGMA application_id").fetchone()[0]
        tables = c.execute("SELECT count(*) FROM sqlite_master").fetchone()[0]
        if version == 0 and app == 0 and tables == 0:
            with _transaction(c):
                if c.execute("SELECT count(*) FROM sqlite_master").fetchone()[0] == 0:
                    for statement in _SCHEMA.split(";"):
                        if statement.strip():
                            c.execute(statement)
                    c.execute(f"PRAGMA user_version = {SCHEMA_VERSION}")
                    c.execute(f"PRAGMA application_id = {APPLICATION_ID}")
            return self._check_schema()
        if app != APPLICATION_ID:  # which mark is missing, and how a hand merge keeps it (T51-A02)
            raise NeurohoverError(
                f"{str(self.path)!r} is an SQLite file but not a neurohover results store (its PRAGMA application_id is {app}, a store's "
                f"{APPLICATION_ID}); give another --store file, or merge stores into a copy of one neurohover wrote (docs/glossary.md, Store)"
            )
        if version != SCHEMA_VERSION:
            newer = "a newer" if version > SCHEMA_VERSION else "an older"
            raise NeurohoverError(
                f"results store {str(self.path)!r} has schema version {version}, written by {newer} neurohover; "
                f"this version reads schema version {SCHEMA_VERSION}. Use a new --store file "
                f"(or the neurohover version that wrote it); results of different schemas are never mixed"
            )
        made = c.execute("SELECT type, name FROM sqlite_master WHERE type IN ('trigger', 'view') OR (type = 'index' AND sql IS NOT NULL)").fetchone()
        if made is not None:  # a trigger that dropped each unit written made compete fail with "results holds none" (T33-B14)
            raise NeurohoverError(f"results store {str(self.path)!r} holds a {made[0]} {made[1]!r} neurohover did not make; give another --store file")
        check_tables(c, str(self.path), _SCHEMA)  # each table's columns (T19-04, T35-B06) and keys (T46-B03)

    # ------------------------------------------------------------------ experiments

    def begin(self, name: str, scale: str, config_hash: str, config: dict, *, fresh: bool = False) -> None:
        """Register experiment (name, scale) with its config hash, or check that it matches.

        ``fresh`` deletes the experiment's stored units and sessions first (a deliberate restart).
        Takes the writer lock first (see :meth:`lock`). ``config`` must be what the readers read: an ExperimentConfig's
        ``to_dict()`` at ``scale``, hashing to ``config_hash`` (:func:`~.store_checks.config_problem`; T29-B07).
        """
        where = self._where("begin")
        check_experiment(name, scale, where)
        check_text(config_hash, "config_hash", where)
        text = object_text(config, "config", where)
        self._check_config(config, scale, config_hash, where)
        fresh = check_flag(fresh, "fresh", "delete the experiment's stored units first")
        if not fresh:  # its row kept: a damaged one named (T22-09)
            self._check_created(name)
        now = clock_time(where)  # a time its readers take, or nothing written (T50-A03)
        self.lock()
        c = self.conn
        with _transaction(c):
            if fresh:
                for table in ("experiments", "units", "sessions"):
                    c.execute(f"DELETE FROM {table} WHERE name = ? AND scale = ?", (name, scale))
            row = c.execute("SELECT config_hash, config FROM experiments WHERE name = ? AND scale = ?", (name, scale)).fetchone()
            other = c.execute("SELECT name FROM experiments WHERE lower(name) = lower(?) AND name != ? LIMIT 1", (name, name)).fetchone()
            if row is None and other is not None:  # one file of figures where case is ignored, one report anchor (T28-A10)
                raise NeurohoverError(
                    f"results store {str(self.path)!r} already holds experiment {other[0]!r}, and {name!r} differs from it only in case: their "
                    "figures would be one file where case is ignored; give the experiment another name (or another --store)"
                )
            if row is None:
                c.execute("INSERT INTO experiments VALUES (?, ?, ?, ?, ?)", (name, scale, config_hash, text, now))
            elif row[0] != config_hash:
                raise NeurohoverError(config_differs(str(self.path), name, scale, row[0], row[1], config_hash, config))
            else:  # same settings: keep the latest title and paper numbers (they do not change results)
                c.execute("UPDATE experiments SET config = ? WHERE name = ? AND scale = ?", (text, name, scale))

    def update(self, name: str, scale: str, config_hash: str, config: dict, keep: Iterable[str]) -> int:
        """Register a changed config of experiment (name, scale), keeping the stored units named in ``keep``.

        In one transaction: the units not kept and the experiment's sessions are deleted, and the kept
        units and the experiment take ``config_hash``. The caller chooses ``keep`` (units the new config
        plans with the same key, kind and params: :func:`neurohover.experiments.runner.unchanged_units`).
        Returns the number of units kept.
        """
        where = self._where("update")
        check_experiment(name, scale, where)
        check_text(config_hash, "config_hash", where)
        text = object_text(config, "config", where)
        given = list(keep) if isinstance(keep, Iterable) and not isinstance(keep, (str, bytes, dict)) else None
        if given is None or not all(isinstance(k, str) for k in given):  # None was a TypeError; a text would be kept letter by letter
            raise NeurohoverError(f"{where}: keep = {brief(keep)} is not allowed: give a list or set of unit keys (text) to keep")
        self._check_config(config, scale, config_hash, where)
        kept = set(given)
        clock_time(where)  # a run follows, its times refused: nothing deleted first (T50-A03)
        self.lock()
        c = self.conn
        with _transaction(c):
            if c.execute("SELECT 1 FROM experiments WHERE name = ? AND scale = ?", (name, scale)).fetchone() is None:
                raise NeurohoverError(self.missing_message(name, scale))
            stored = [k for (k,) in c.execute("SELECT key FROM units WHERE name = ? AND scale = ?", (name, scale))]
            gone = [k for k in stored if k not in kept]
            c.executemany("DELETE FROM units WHERE name = ? AND scale = ? AND key = ?", [(name, scale, k) for k in gone])
            c.execute("DELETE FROM sessions WHERE name = ? AND scale = ?", (name, scale))
            c.execute("UPDATE units SET config_hash = ? WHERE name = ? AND scale = ?", (config_hash, name, scale))
            c.execute("UPDATE experiments SET config_hash = ?, config = ? WHERE name = ? AND scale = ?", (config_hash, text, name, scale))
        return len(stored) - len(gone)

    def forget_if_empty(self, name: str, scale: str) -> bool:
        """Remove experiment (name, scale) and its sessions if it holds no unit (a run refused after it was registered
        leaves the store as it was); whether it was removed."""
        check_experiment(name, scale, self._where("forget_if_empty"))
        self.lock()
        c = self.conn
        with _transaction(c):
            if c.execute("SELECT 1 FROM units WHERE name = ? AND scale = ? LIMIT 1", (name, scale)).fetchone() is not None:
                return False
            c.execute("DELETE FROM sessions WHERE name = ? AND scale = ?", (name, scale))
            c.execute("DELETE FROM experiments WHERE name = ? AND scale = ?", (name, scale))
        return True

    def _rows(self, sql: str, params: tuple, what: str) -> list[tuple]:
        """The rows of a read, a damaged file named with what could not be read (SQLite's message named a column and
        printed raw bytes; fourth trial). Names and scales must be text, without NUL or a lone surrogate, as the writes
        refuse them (a lone surrogate, '\\udcff', was SQLite's UnicodeEncodeError; T36-B01)."""
        for value in params:
            if not isinstance(value, str):
                raise NeurohoverError(f"{value!r:.60} is not allowed as an experiment name or scale: give text (e.g. 'fig7', 'paper')")
            check_text(value, "experiment name or scale", f"results store {str(self.path)!r}", empty=True)
        try:
            with self.conn.guard:
                refuse_moved(self.path, self._file, self._ident)
                return self.conn.execute(sql, params).fetchall()
        except sqlite3.DatabaseError as err:
            raise NeurohoverError(f"results store {str(self.path)!r} is damaged: {what} cannot be read ({str(err)[:60]})") from None

    def orphan_units(self, name: str | None = None) -> list[tuple[str, str, int, str]]:
        """``(name, scale, count, first key)`` of the finished units stored at an experiment and scale the store holds no
        config row for (of experiment ``name`` only, if given): units whose config is gone, so nothing can check them."""
        sql = (
            "SELECT u.name, u.scale, count(*), min(u.key) FROM units u WHERE NOT EXISTS "
            "(SELECT 1 FROM experiments e WHERE e.name = u.name AND e.scale = u.scale)"
            + (" AND u.name = ?" if name is not None else "")
            + " GROUP BY u.name, u.scale ORDER BY u.name, u.scale"
        )
        rows = [tuple(r) for r in self._rows(sql, () if name is None else (name,), "its list of units")]
        odd = next((r[:2] for r in rows if not (isinstance(r[0], str) and isinstance(r[1], str))), None)
        if odd is not None:  # a BLOB name was returned as bytes (as results() keys were, T47-B03)
            raise NeurohoverError(f"results store {str(self.path)!r} is damaged: its table units holds units of experiment {brief(odd[0])}, "
                                  f"scale {brief(odd[1])}, not the text neurohover writes there (a hand edit?); give another --store file")  # fmt: skip
        return rows

    def experiments(self) -> list[tuple[str, str, str, int]]:
        """(name, scale, config_hash, finished units) of every experiment in the store."""
        sql = (
            "SELECT e.name, e.scale, e.config_hash, (SELECT count(*) FROM units u WHERE u.name = e.name AND u.scale = e.scale) "
            "FROM experiments e ORDER BY e.created"
        )
        self._check_created()
        return [tuple(r) for r in self._rows(sql, (), "its list of experiments")]

    def _check_created(self, name: str | None = None) -> None:
        """Refuse an experiment row (of ``name`` only, if given) whose created time, which orders the experiments, is no
        number: 'yesterday' was taken, and sorted after every number (T22-09); nor a time (-5 was taken; T45-B02)."""
        sql = "SELECT name, scale, created FROM experiments WHERE (typeof(created) NOT IN ('integer', 'real') OR NOT (created >= 1e9 AND created < 4294967296))"
        refuse_wrong_cells(self._rows, str(self.path), _SCHEMA, name, None)  # a BLOB name listed as bytes (T47-B03)
        rows = self._rows(sql + (" AND name = ?" if name is not None else "") + " LIMIT 1", () if name is None else (name,), "its list of experiments")
        if rows:
            bad, scale, created = rows[0]
            said = "no number: allowed seconds since 1970" if not isinstance(created, (int, float)) else f"not allowed: {TIME_ALLOWED}"
            raise NeurohoverError(
                f"results store {str(self.path)!r} is damaged: experiment {brief(bad)} ({brief(scale)})'s created time {brief(created)} is "
                f"{said} (give another --store file, or reproduce --fresh to start it over)"
            )

    def config_hash(self, name: str, scale: str) -> str | None:
        """The config hash of experiment (name, scale), None when the store does not hold it."""
        rows = self._rows("SELECT config_hash FROM experiments WHERE name = ? AND scale = ?", (name, scale), f"experiment {name} ({scale})")
        return rows[0][0] if rows else None

    def config(self, name: str, scale: str) -> dict:
        rows = self._rows("SELECT config FROM experiments WHERE name = ? AND scale = ?", (name, scale), f"experiment {name} ({scale})'s config")
        if not rows:
            raise NeurohoverError(self.missing_message(name, scale))
        return self._json(rows[0][0], f"experiment {name} ({scale})'s config")

    def missing_message(self, name: str | None, scale: str | None) -> str:
        """The message for an experiment (None: any experiment; at ``scale``, if given) this store does not hold,
        listing what it holds (any was "holds no experiment '(any)'"; eleventh trial)."""
        return missing_text(str(self.path), [f"{n} ({s})" for n, s, _, _ in self.experiments()], name, scale)

    def _refuse_unheld(self, name: str, scale: str, missing_ok: object) -> None:
        """Refuse experiment (name, scale) the store holds no config or unit of, listing what it holds as :meth:`config`
        does: 'FIG7', 'fig7 ' or 'QUICK' read as no units, without a word (T38-B05). ``missing_ok``: read as nothing
        stored yet (reproduce's sources, an experiment interrupted before its first unit)."""
        if not check_flag(missing_ok, "missing_ok", "read an experiment not stored as one without units"):
            if not self._rows(HELD_SQL, (name, scale), f"experiment {name} ({scale})")[0][0]:
                raise NeurohoverError(self.missing_message(name, scale))
        refuse_wrong_cells(self._rows, str(self.path), _SCHEMA, name, scale)  # a BLOB key returned as bytes (T47-B03)

    def scales(self, name: str) -> list[str]:
        self._check_created(name)
        return [r[0] for r in self._rows("SELECT scale FROM experiments WHERE name = ? ORDER BY created", (name,), f"experiment {name}'s scales")]

    # ------------------------------------------------------------------ units

    def results(self, name: str, scale: str, *, missing_ok: bool = False) -> dict[str, dict]:
        """key -> result of every finished unit (an experiment the store does not hold refused unless ``missing_ok``)."""
        self._refuse_unheld(name, scale, missing_ok)
        rows = self._rows("SELECT key, result FROM units WHERE name = ? AND scale = ?", (name, scale), f"experiment {name} ({scale})'s results")
        return {k: self._json(r, f"experiment {name} ({scale}), unit {k}'s result") for k, r in rows}

    def unit_config_hashes(self, name: str, scale: str, *, missing_ok: bool = False) -> dict[str, Any]:
        """key -> the config hash each finished unit was run under (as stored: a damaged one may be no text); as :meth:`results`."""
        self._refuse_unheld(name, scale, missing_ok)
        rows = self._rows("SELECT key, config_hash FROM units WHERE name = ? AND scale = ?", (name, scale), f"experiment {name} ({scale})'s units")
        return dict(rows)

    def units(self, name: str, scale: str, *, missing_ok: bool = False) -> list[dict]:
        """Every finished unit: key, kind, params, result, seconds, worker, finished (time); as :meth:`results`."""
        self._refuse_unheld(name, scale, missing_ok)
        rows = self._rows(
            "SELECT key, kind, params, result, seconds, worker, finished FROM units WHERE name = ? AND scale = ? ORDER BY key",
            (name, scale),
            f"experiment {name} ({scale})'s units",
        )
        return [
            {
                "key": k,
                "kind": kind,
                "params": self._json(p, f"experiment {name} ({scale}), unit {k}'s params"),
                "result": self._json(r, f"experiment {name} ({scale}), unit {k}'s result"),
                "seconds": stored_seconds(self.path, s, f"experiment {name} ({scale}), unit {k}'s seconds"),
                "worker": w,
                "finished": stored_time(self.path, f, f"experiment {name} ({scale}), unit {k}'s finished time"),
            }
            for k, kind, p, r, s, w, f in rows
        ]

    def _json(self, text: str, what: str) -> dict:
        """A stored JSON object, or one clear error naming the damaged row (the rest of the store stays readable): every
        config, params and result is one (a list was a TypeError in results, a BLOB a UnicodeDecodeError; sixth trial)."""
        try:  # strictly: nested 100,000 deep or an integer of 5,000 digits was a traceback (ninth trial)
            value = strict_json(text)
        except JSONError as err:
            raise NeurohoverError(f"results store {str(self.path)!r}: {what} is damaged (not JSON: {str(err)[:80]})") from None
        if not isinstance(value, dict):
            raise NeurohoverError(f"results store {str(self.path)!r}: {what} is damaged (a JSON {type(value).__name__}, not an object)")
        return value

    def _check_config(self, config: dict, scale: str, config_hash: str, where: str) -> None:
        """Refuse a config the readers would call damaged (:func:`~.store_checks.config_problem`; T29-B07)."""
        problem = config_problem(config, scale, config_hash)
        if problem:
            raise NeurohoverError(f"{where}: config = {brief(config)} is not allowed: {problem}; give the config's to_dict()")

    def _where(self, method: str) -> str:
        """Where a write's arguments are refused, for its messages."""
        return f"results store {str(self.path)!r}, {method}"

    def put(self, name: str, scale: str, config_hash: str, unit, result: dict, seconds: float, worker: str = "", session: int | None = None) -> bool:
        """Record one finished unit in its own transaction; False if it was already there.

        Every argument is checked before anything is written (a NaN ``seconds`` bound as NULL, and the unit was
        dropped without a word: a lost result; fourteenth trial, T14-5).
        """
        where = self._where("put")
        params, text, session = put_arguments(where, name, scale, config_hash, unit, result, seconds, worker, session)
        now = clock_time(where)
        self.lock()
        c = self.conn
        with _transaction(c):
            row = c.execute("SELECT config_hash, config FROM experiments WHERE name = ? AND scale = ?", (name, scale)).fetchone()
            if row is None or row[0] != config_hash:
                raise NeurohoverError(
                    f"refusing to record unit {unit.key!r}: experiment {name!r} ({scale}) in "
                    f"{str(self.path)!r} has config hash {row[0] if row else None}, not {config_hash}"
                )
            problem = planned_problem(self._json(row[1], f"experiment {name} ({scale})'s config"), scale, unit)
            if problem:  # every reader then refused the whole experiment as damaged (T55-B09)
                raise NeurohoverError(f"{where}: unit {brief(unit.key)} is not allowed: {problem}; give a unit of the plan of {name} ({scale})")
            problem = "" if session is None else session_problem(c, session, (name, scale, config_hash))
            if problem:  # another experiment's session, or an ended one, counted the unit (T29-B05)
                raise NeurohoverError(f"{where}: {problem}")
            cur = c.execute(
                "INSERT OR IGNORE INTO units VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?)",
                (name, scale, unit.key, unit.kind, config_hash, params, text, float(seconds), worker, now),
            )
            if c.execute("SELECT 1 FROM units WHERE name = ? AND scale = ? AND key = ?", (name, scale, unit.key)).fetchone() is None:
                raise NeurohoverError(  # a trigger or an index of someone else's dropped it, and the unit was lost (T33-B14)
                    f"results store {str(self.path)!r} did not keep unit {unit.key!r} of {name} ({scale}): its write was dropped "
                    "(a trigger or index neurohover did not make?); give another --store file"
                )
            if session is not None and cur.rowcount:
                c.execute(f"UPDATE sessions SET units_run = units_run + 1, {WALL_SQL} WHERE id = ?", (*self._clocks.wall(session), session))
        return bool(cur.rowcount)

    # ------------------------------------------------------------------ sessions

    def start_session(self, name: str, scale: str, config_hash: str, executor: str, cores: int, units_before: int) -> int:
        """Record the start of a run of experiment (name, scale) on ``cores`` cores of ``executor``; its session id.

        Arguments are checked first (cores=0 was stored, and :meth:`sessions` then called the store damaged; T14-5)."""
        where = self._where("start_session")
        check_experiment(name, scale, where)
        check_text(config_hash, "config_hash", where)
        check_executor(executor, where)
        cores = stored_count(cores, "cores", where, 1, MAX_CORES)
        units_before = stored_count(units_before, "units_before", where, 0)
        now = clock_time(where)
        self.lock()
        c = self.conn
        with _transaction(c):  # a session sessions() would call damaged is refused (T29-B04)
            problem = experiment_problem(c, name, scale, config_hash)
            stored = c.execute("SELECT COUNT(*) FROM units WHERE name = ? AND scale = ?", (name, scale)).fetchone()[0]
            if not problem and units_before > stored:
                problem = f"units_before = {units_before} is not allowed: experiment {name} ({scale}) stores {stored} units"
            if problem:
                raise NeurohoverError(f"{where}: {problem}")
            cur = c.execute(
                "INSERT INTO sessions (name, scale, config_hash, executor, cores, started, wall_seconds, units_run, units_before, status) "
                "VALUES (?, ?, ?, ?, ?, ?, 0, 0, ?, 'running')",
                (name, scale, config_hash, executor, cores, now, units_before),
            )
        assert cur.lastrowid is not None  # an INSERT always sets it
        self._clocks.start(cur.lastrowid)
        return cur.lastrowid

    def end_session(self, session: int, status: str) -> None:
        """Record how session ``session`` (:meth:`start_session`'s id) ended: ``status`` (one of :data:`SESSION_STATUSES`) and its wall time."""
        where = self._where("end_session")
        session = stored_count(session, "session", where, 1)
        check_text(status, "status", where)  # object() was sqlite3's ProgrammingError (T14-5)
        if status not in SESSION_STATUSES:  # free text was stored, and shown by the report as a session's end (fifteenth trial, T15-22)
            raise NeurohoverError(f"{where}: status = {brief(status)} is not allowed: give one of {', '.join(map(repr, SESSION_STATUSES))}")
        self.lock()
        c = self.conn
        with _transaction(c):  # an id start_session never gave (T15-22), or a session already ended (T29-B05)
            problem = session_problem(c, session)
            if problem:
                raise NeurohoverError(f"{where}: {problem}")
            c.execute(f"UPDATE sessions SET status = ?, {WALL_SQL} WHERE id = ?", (status, *self._clocks.wall(session), session))

    def sessions(self, name: str, scale: str, *, missing_ok: bool = False) -> list[dict]:
        """Every recorded run of experiment (name, scale) (:meth:`start_session`), checked; as :meth:`results`."""
        self._refuse_unheld(name, scale, missing_ok)
        cols = ("id", "executor", "cores", "started", "wall_seconds", "units_run", "units_before", "status")
        rows = self._rows(
            f"SELECT {', '.join(cols)} FROM sessions WHERE name = ? AND scale = ? ORDER BY id", (name, scale), f"experiment {name} ({scale})'s sessions"
        )
        sessions = [dict(zip(cols, r)) for r in rows]
        stored = self._rows("SELECT COUNT(*) FROM units WHERE name = ? AND scale = ?", (name, scale), f"experiment {name} ({scale})'s units")[0][0]
        seen: dict[tuple, int] = {}
        for session in sessions:  # what the report sums and prints: numbers, or the damaged row named
            session["wall_seconds"] = stored_seconds(self.path, session["wall_seconds"], f"experiment {name} ({scale}), session {session['id']}'s wall seconds")
            bad = bad_session(session, stored)  # units_run 99 of 4, status 'zzz', started 1e12 were reported (T22-21)
            twin = seen.setdefault(tuple(session[c] for c in cols[1:]), session["id"])
            bad = bad or (f"it repeats session {twin} field for field (one run is recorded once)" if twin != session["id"] else "")
            if bad:
                raise NeurohoverError(f"results store {str(self.path)!r}: experiment {name} ({scale}), session {session['id']} is damaged: {bad}")
        return sessions


def worker_name() -> str:
    return f"{socket.gethostname()}:{os.getpid()}"
