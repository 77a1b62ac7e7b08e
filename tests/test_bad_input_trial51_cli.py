"""Bad-input trial 51, the command line: a TQDM_BAR_FORMAT tqdm cannot draw ('{bogus}', '{l_bar', '{rate:.2f}' on the
first frame) was a KeyError/ValueError/TypeError traceback when the first bar was drawn, mid-command, leaving the
store's session 'running' (T51-A01): it is refused by name before any work, as the other TQDM_* variables are."""

from __future__ import annotations

from pathlib import Path

import pytest


@pytest.mark.parametrize("bar_format", ["{bogus}", "{l_bar", "{n:Z}", "{rate:.2f}", "{0}", "{postfix[0]}"])
def test_a01_a_bar_format_tqdm_cannot_draw_is_refused_before_any_work(cli, monkeypatch, tmp_path: Path, bar_format: str) -> None:
    monkeypatch.setenv("TQDM_BAR_FORMAT", bar_format)
    store = tmp_path / "tq.sqlite"
    rc, out, err = cli("reproduce", "table4", "--scale", "quick", "--store", str(store), "--progress")
    assert rc == 2 and "Traceback" not in err and out == "", err
    assert f"environment variable TQDM_BAR_FORMAT={bar_format!r} is not allowed: tqdm (the progress bar) cannot draw a bar with it (" in err
    assert not store.exists()


DRAWN = ["{l_bar}{bar}{r_bar}", "{desc}: {percentage:3.0f}%|{bar}|", "{n_fmt}/{total_fmt} [{elapsed}<{remaining}, {rate_fmt}{postfix}]"]


@pytest.mark.parametrize("bar_format", DRAWN)
def test_a01_bar_formats_tqdm_draws_are_taken(cli, monkeypatch, bar_format: str) -> None:
    monkeypatch.setenv("TQDM_BAR_FORMAT", bar_format)
    rc, out, err = cli("fly", "--task", "ghh08", "--episodes", "1")
    assert rc == 0 and "episodes_per_second" in out, err


def test_a02_a_hand_built_store_names_the_missing_mark_and_how_to_merge(tmp_path: Path, cli) -> None:
    """T51-A02: a fresh file given a store's tables and rows (a hand merge) was refused as "not a neurohover results
    store" without a word of what marks one; now the message names the application_id and where merging is said."""
    import sqlite3

    from neurohover.experiments import Store

    real = tmp_path / "real.sqlite"
    Store(real).close()
    with sqlite3.connect(real) as c:
        schema = [sql for (sql,) in c.execute("SELECT sql FROM sqlite_master WHERE sql IS NOT NULL AND name NOT LIKE 'sqlite_%'")]
    merged = tmp_path / "merged.sqlite"
    with sqlite3.connect(merged) as c:
        for sql in schema:
            c.execute(sql)
        c.execute("PRAGMA user_version = 1")
    rc, _, err = cli("results", "table4", "--store", str(merged))
    assert rc == 2 and "(its PRAGMA application_id is 0, a store's 1313361750); give another --store file, or merge stores into a copy" in err, err
    glossary = (Path(__file__).parents[1] / "docs" / "glossary.md").read_text(encoding="utf-8")
    assert "PRAGMA application_id = 1313361750" in glossary
    with sqlite3.connect(merged) as c:  # the glossary's mark, set by hand: a store
        c.execute("PRAGMA application_id = 1313361750")
    rc, _, err = cli("results", "table4", "--store", str(merged))
    assert rc == 2 and "holds no experiment 'table4'; it holds: nothing yet" in err, err
