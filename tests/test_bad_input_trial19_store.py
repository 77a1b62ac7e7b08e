"""The nineteenth bad-input trial's findings in damaged results stores: a refused reproduce leaves the store as it was
(T19-04); wins refuses the damage results refuses, by the same check (T19-05); compete refuses a damaged config or units
whose config is gone, and does not rewrite it (T19-06); report says each damaged experiment on stderr and exits 2 when
nothing could be reported (T19-07); results' messages name the store and the unit (T19-14)."""

from __future__ import annotations

import shutil
import sqlite3
from pathlib import Path

import pytest
from conftest import CliRun, tiny_test_runs

RUN = "run/baseline/test0/rep0"
COMPETE = ("compete", "--task", "ghh08", "--agent", "baseline", "--runs", "1", "--episodes", "2", "--episode-steps", "20")


@pytest.fixture(scope="module")
def tiny(tmp_path_factory) -> tuple[Path, Path]:
    """A config of two agents (tr1: baseline and generic, one 20-step run of 2 episodes each) and a store holding its
    two finished test runs; tests damage copies of the store."""
    from neurohover.cli import main

    where = tmp_path_factory.mktemp("tiny19")
    config = where / "tr1.toml"
    config.write_text(tiny_test_runs("baseline", "generic"))
    assert main(["reproduce", str(config), "--store", str(where / "s.sqlite"), "--no-progress"]) == 0
    return config, where / "s.sqlite"


@pytest.fixture(scope="module")
def competed(tmp_path_factory) -> Path:
    """A store that one tiny compete run (baseline on ghh08, one run) wrote; tests damage copies of it."""
    from neurohover.cli import main

    where = tmp_path_factory.mktemp("compete19")
    assert main([*COMPETE, "--out", str(where / "c"), "--store", str(where / "s.sqlite")]) == 0
    return where / "s.sqlite"


def _damaged(store: Path, at: Path, sql: str) -> Path:
    """A copy of ``store`` at ``at`` with ``sql`` run on it."""
    shutil.copyfile(store, at)
    with sqlite3.connect(at) as conn:
        conn.execute(sql)
    conn.close()
    return at


def _dump(path: Path) -> list[str]:
    """Every row and table of the store, to see that a refused command left it as it was."""
    with sqlite3.connect(path) as conn:
        rows = list(conn.iterdump())
    conn.close()
    return rows


def _error(err: str, command: str) -> str:
    """The message of ``neurohover COMMAND: error: ...`` on stderr."""
    line = next(ln for ln in err.splitlines() if ln.startswith(f"neurohover {command}: error: "))
    return line.removeprefix(f"neurohover {command}: error: ")


@pytest.mark.parametrize(
    ("sql", "says"),
    [
        (f"UPDATE units SET kind = 'bogus' WHERE key = '{RUN}'", f"unit '{RUN}': unknown unit kind 'bogus'"),
        (f"UPDATE units SET params = '[1,2' WHERE key = '{RUN}'", f"unit {RUN}'s params is damaged (not JSON"),
        (f"UPDATE units SET seconds = -5 WHERE key = '{RUN}'", f"unit {RUN}'s seconds is damaged (-5.0 is no number of seconds >= 0)"),
        (f"UPDATE units SET kind = 'evolve' WHERE key = '{RUN}'", f"result of evolve unit '{RUN}': missing key(s)"),
    ],
)
def test_wins_refuses_the_damage_results_refuses(tiny, tmp_path: Path, cli: CliRun, sql: str, says: str) -> None:
    """T19-05: wins printed a full table (a unit of kind 'bogus' counted as a test run) where results called the store
    damaged; now both read the experiment through one check and say the same."""
    store = _damaged(tiny[1], tmp_path / "s.sqlite", sql)
    rc, out, err = cli("wins", "tr1", "--store", str(store), "--runs", "1", "--draws", "10")
    assert rc == 2 and out == "" and says in err and str(store) in err, err
    rc, _, err_results = cli("results", "tr1", "--store", str(store))
    assert rc == 2 and _error(err_results, "results") == _error(err, "wins")


@pytest.mark.parametrize(
    ("sql", "says"),
    [
        (f"UPDATE units SET kind = 'bogus' WHERE key = '{RUN}'", "unknown unit kind 'bogus'"),
        (
            f"UPDATE units SET result = json_set(result, '$.score', 'nan') WHERE key = '{RUN}'",
            "is inconsistent: its score 'nan' is not the sum of its 2 returns",
        ),
    ],
)
def test_results_names_the_store_and_the_unit(tiny, tmp_path: Path, cli: CliRun, sql: str, says: str) -> None:
    """T19-14: results said "unknown unit kind 'bogus'" and "test run of baseline on ... is inconsistent" naming neither
    the store nor the unit."""
    store = _damaged(tiny[1], tmp_path / "s.sqlite", sql)
    rc, _, err = cli("results", "tr1", "--store", str(store))
    assert rc == 2 and f"results store {str(store)!r}, experiment tr1 (quick), is damaged: unit '{RUN}': " in err and says in err, err
