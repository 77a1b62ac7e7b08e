"""Helpers of the tests that damage a results store and read what a command said of it (trials 19 and 21)."""

from __future__ import annotations

import shutil
import sqlite3
from pathlib import Path

#: One tiny competition (baseline on ghh08, one run of two 20-step episodes): the store tests damage copies of.
COMPETE = ("compete", "--task", "ghh08", "--agent", "baseline", "--runs", "1", "--episodes", "2", "--episode-steps", "20")


def competed_store(where: Path) -> Path:
    """The store one tiny compete run (:data:`COMPETE`) writes under ``where``."""
    from neurohover.cli import main

    assert main([*COMPETE, "--out", str(where / "c"), "--store", str(where / "s.sqlite")]) == 0
    return where / "s.sqlite"


def damaged(store: Path, at: Path, sql: str) -> Path:
    """A copy of ``store`` at ``at`` with ``sql`` run on it."""
    shutil.copyfile(store, at)
    with sqlite3.connect(at) as conn:
        conn.execute(sql)
    conn.close()
    return at


def dump(path: Path) -> list[str]:
    """Every row and table of the store, to see that a refused command left it as it was."""
    with sqlite3.connect(path) as conn:
        rows = list(conn.iterdump())
    conn.close()
    return rows


def error(err: str, command: str) -> str:
    """The message of ``neurohover COMMAND: error: ...`` on stderr."""
    line = next(ln for ln in err.splitlines() if ln.startswith(f"neurohover {command}: error: "))
    return line.removeprefix(f"neurohover {command}: error: ")


def refused_by_every_command(cli, config: Path, store: Path, name: str, line: str, out: Path) -> None:
    """``results``, ``reproduce --update`` (of ``config``) and ``report`` (into ``out``) each refuse experiment ``name`` of
    ``store`` with the shared check's ``line``, in exit status 2, writing no report and leaving the store as it was."""
    before = dump(store)
    for argv, command in (
        (("results", name, "--store", str(store), "--format", "json"), "results"),
        (("reproduce", str(config), "--store", str(store), "--no-progress", "--update"), "reproduce"),
    ):
        rc, _, err = cli(*argv)
        assert rc == 2 and error(err, command) == line, (argv, err)
    rc, _, err = cli("report", "--store", str(store), "--out", str(out))
    assert rc == 2 and line in err and not out.exists(), err
    assert dump(store) == before
