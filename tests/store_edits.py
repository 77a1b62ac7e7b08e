"""Helpers of the tests that damage a results store and read what a command said of it (trials 19 and 21)."""

from __future__ import annotations

import shutil
import sqlite3
from pathlib import Path


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
