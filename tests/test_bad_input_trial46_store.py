"""Trial 46, side B, a results store rebuilt without its keys and a compete folder moved away.

T46-B03: a store whose ``units`` or ``sessions`` table was rebuilt without its primary key (a hand merge, or a restore by
``CREATE TABLE ... AS SELECT``) read a row held twice twice: the report said "5 finished, complete" for a 4-unit plan and
summed its seconds twice. T46-B04: the same of ``experiments``: the report showed the experiment twice, a second row
under another config hash went unseen, and export named a choice of scales "quick, quick". A store whose tables lack
the keys (or NOT NULL constraints) neurohover makes is refused as damaged, naming the table, its key and a row held twice.

T46-B05: a compete folder moved elsewhere was no longer checked against its store (the summary records its absolute
path), so a summary edited to another sensor was plotted; T46-B06: an untouched folder archived under another name was
refused once a new study ran at its old path, checked against that study's store. The folder's own results.sqlite
(compete's default store, which travels with it) is read where it holds the competition."""

from __future__ import annotations

import json
import re
import shutil
import sqlite3
from pathlib import Path

import pytest
from store_edits import competed_store

from neurohover.errors import NeurohoverError

NAME = "compete-ghh08-baseline"


@pytest.fixture(scope="module")
def store(tmp_path_factory) -> Path:
    """One tiny compete run's store."""
    return competed_store(tmp_path_factory.mktemp("t46"))


def rebuilt(store: Path, at: Path, table: str, twice: bool) -> Path:
    """A copy of ``store`` at ``at`` whose ``table`` was rebuilt by CREATE TABLE ... AS SELECT (its first row twice if ``twice``)."""
    shutil.copyfile(store, at)
    conn = sqlite3.connect(at)
    conn.executescript(f"CREATE TABLE t2 AS SELECT * FROM {table}; DROP TABLE {table}; ALTER TABLE t2 RENAME TO {table};")
    if twice:
        conn.executescript(f"INSERT INTO {table} SELECT * FROM {table} WHERE rowid = 1;")
    conn.close()
    return at


@pytest.mark.parametrize(
    ("table", "key", "row"),
    [
        ("units", "name, scale, key", f"name '{NAME}', scale 'settings-"),
        ("sessions", "id", "id 1 more"),
        ("experiments", "name, scale", f"name '{NAME}', scale 'settings-"),
    ],
)
def test_a_table_rebuilt_without_its_keys_is_refused(store: Path, tmp_path: Path, table: str, key: str, row: str) -> None:
    """T46-B03, T46-B04: the table named with its key, and the row held twice, as every reader opens the store."""
    from neurohover.experiments import Store

    for twice in (True, False):
        path = rebuilt(store, tmp_path / f"{twice}.sqlite", table, twice)
        says = f"results store {str(path)!r} is damaged: its table {table} lacks its primary key ({key})"
        with pytest.raises(NeurohoverError, match=re.escape(says)) as err:
            Store(path, create=False)
        assert (f", and holds the row of {row}" in str(err.value)) == twice, err.value
        assert "give another --store file" in str(err.value)


def test_a_table_without_its_not_null_constraints_is_refused(store: Path, tmp_path: Path) -> None:
    """T46-B03: the keys kept, NOT NULL dropped (a column may hold NULL)."""
    from neurohover.experiments import Store

    path = tmp_path / "n.sqlite"
    shutil.copyfile(store, path)
    conn = sqlite3.connect(path)
    conn.executescript("PRAGMA writable_schema = ON; UPDATE sqlite_master SET sql = replace(sql, 'worker TEXT NOT NULL', 'worker TEXT') WHERE name = 'units';")
    conn.close()
    with pytest.raises(NeurohoverError, match="its table units lets column.s. worker hold NULL \\(its NOT NULL is gone"):
        Store(path, create=False)


def test_the_store_as_written_opens(store: Path) -> None:
    """What neurohover makes still reads."""
    from neurohover.experiments import Store

    with Store(store, create=False) as held:
        assert [e[0] for e in held.experiments()] == [NAME]


def competed(out: Path, n_steps: int = 10, store: Path | None = None) -> Path:
    from neurohover.compete import compete

    compete("ghh08", "baseline", runs=1, episodes=2, n_steps=n_steps, out=out, store=store)
    return out


@pytest.mark.slow
def test_a_moved_compete_folder_is_checked_against_its_own_store(tmp_path: Path) -> None:
    """T46-B05: moved away (its store inside it), a summary edited to another sensor or seed is still refused."""
    from neurohover.compete import check_against_store

    folder = competed(tmp_path / "study").rename(tmp_path / "archive")
    check_against_store(folder)
    summary = json.loads((folder / "summary.json").read_text())
    for edit, named in (({"sensor": {"velocity": 0.5}}, "sensor.velocity: its store's 0.0, given 0.5"), ({"seed": 7}, "seed: its store's 0, given 7")):
        (folder / "summary.json").write_text(json.dumps({**summary, **edit}))
        says = f"is not what its store {str(folder / 'results.sqlite')!r} holds for {NAME}"
        with pytest.raises(NeurohoverError, match=re.escape(says)) as err:
            check_against_store(folder)
        assert named in str(err.value)


@pytest.mark.slow
def test_an_archived_compete_folder_is_not_checked_against_a_new_study_at_its_old_path(tmp_path: Path) -> None:
    """T46-B06: run1 archived as run1_2026, a new study (other settings) at run1: both are checked against their own stores."""
    from neurohover.compete import check_against_store

    archived = competed(tmp_path / "run1").rename(tmp_path / "run1_2026")
    competed(tmp_path / "run1", n_steps=12)
    check_against_store(archived)
    check_against_store(tmp_path / "run1")


@pytest.mark.slow
def test_an_own_store_left_by_an_earlier_compete_is_not_read(tmp_path: Path) -> None:
    """A compete with --store into a folder an earlier compete left its default store in is checked against its --store."""
    from neurohover.compete import check_against_store

    competed(tmp_path / "c", n_steps=12)
    competed(tmp_path / "c", store=tmp_path / "s.sqlite")
    check_against_store(tmp_path / "c")
    summary = json.loads((tmp_path / "c" / "summary.json").read_text())
    (tmp_path / "c" / "summary.json").write_text(json.dumps({**summary, "seed": 7}))
    with pytest.raises(NeurohoverError, match=re.escape(f"its store {str(tmp_path / 's.sqlite')!r} holds")):
        check_against_store(tmp_path / "c")
