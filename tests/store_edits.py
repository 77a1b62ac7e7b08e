"""Helpers of the tests that damage a results store and read what a command said of it (trials 19 and 21), and of
those that edit a copy of a shipped policy set's manifest (trials 22 and 37)."""

from __future__ import annotations

import dataclasses
import functools
import json
import shutil
import sqlite3
import tempfile
from pathlib import Path

#: One tiny competition (baseline on ghh08, one run of two 20-step episodes): the store tests damage copies of.
COMPETE = ("compete", "--task", "ghh08", "--agent", "baseline", "--runs", "1", "--episodes", "2", "--episode-steps", "20")


def competed_store(where: Path) -> Path:
    """The store one tiny compete run (:data:`COMPETE`) writes under ``where``."""
    from neurohover.cli import main

    assert main([*COMPETE, "--out", str(where / "c"), "--store", str(where / "s.sqlite")]) == 0
    return where / "s.sqlite"


@functools.cache
def _tiny():
    from conftest import tiny_test_runs

    from neurohover.experiments.config import load_config

    with tempfile.TemporaryDirectory() as where:
        path = Path(where) / "tr1.toml"
        path.write_text(tiny_test_runs("baseline"))
        return load_config(str(path), "quick")


def tiny_config(name: str = "tr1", scale: str = "quick"):
    """A tiny test-runs config (conftest's, flying the baseline) named ``name`` at ``scale`` (a compete run's
    settings-HASH too): one :meth:`Store.begin` takes, as it takes only configs the store's readers read (T29-B07)."""
    return dataclasses.replace(_tiny(), name=name, scale=scale)


def begin(store, name: str = "tr1", scale: str = "quick", **kw) -> str:
    """Register experiment ``name`` at ``scale`` in ``store`` with :func:`tiny_config`; its config hash."""
    config = tiny_config(name, scale)
    store.begin(name, scale, config.hash, config.to_dict(), **kw)
    return config.hash


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


def edited_policy_set(tmp_path: Path, task: str, change) -> Path:
    """A copy of the shipped ``task`` set under ``tmp_path/pd`` whose manifest ``change`` (a function of the dict) edited;
    the copy's parent folder (a policy directory)."""
    from neurohover.policysets import SHIPPED

    shutil.copytree(SHIPPED / task, tmp_path / "pd" / task)
    path = tmp_path / "pd" / task / "manifest.json"
    manifest = json.loads(path.read_text())
    change(manifest)
    path.write_text(json.dumps(manifest))
    return tmp_path / "pd"
