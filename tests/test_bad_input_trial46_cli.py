"""Bad-input trial 46, side A (the command line): ``plot --compete`` takes a compete folder whose summary's store path
now holds no results store (an empty file, a text file, another program's SQLite file) as one whose store is gone, and
does not read it (T46-A01); reproduce's refusal of a setting added to one's own config (a sensor, an optimizer's name)
is the ordinary "settings differ" one with its remedies, the older-neurohover story kept for a setting a newer version
writes in at its default (T46-A02); no file or folder is made directly in /dev or under /proc or /sys, by any output
(``plot /dev/stdin`` wrote its figures into /dev, ``results --out /dev/stdout.csv`` made a file there; T46-A05).

The /dev tests never write there: the writing steps are replaced by a guard that raises, so that a refusal missed
(or this test run on the code before the fix) ends at the guard with nothing made."""

from __future__ import annotations

import dataclasses
import json
import os
import sqlite3
from pathlib import Path

import pytest
import store_edits as SE
from flight_edits import recorded
from test_bad_input_trial34_cli import _again  # a second begin of tr1, its message

from neurohover.errors import NeurohoverError
from neurohover.experiments import Store

# T46-A01 ------------------------------------------------------------------------------------------------------------


@pytest.fixture
def competed(tmp_path: Path) -> tuple[Path, Path]:
    """A compete folder tmp/c whose results went to --store tmp/st.sqlite (its summary records that path)."""
    from neurohover.compete import compete

    compete("ghh08", "baseline", runs=1, episodes=2, n_steps=10, out=tmp_path / "c", store=tmp_path / "st.sqlite")
    return tmp_path / "c", tmp_path / "st.sqlite"


def _another_programs_sqlite(path: Path) -> None:
    with sqlite3.connect(path) as conn:
        conn.execute("CREATE TABLE notes(a)")
    conn.close()


@pytest.mark.parametrize("holds", ["empty", "text", "sqlite"])
def test_a_recorded_store_path_that_now_holds_no_store_is_not_read(competed: tuple[Path, Path], holds: str, cli) -> None:
    from neurohover.compete import check_against_store

    folder, store = competed
    store.unlink()
    if holds == "sqlite":
        _another_programs_sqlite(store)
    else:
        store.write_text("" if holds == "empty" else "my notes\n")
    check_against_store(folder)  # as for a store that is gone
    rc, out, err = cli("plot", "--compete", str(folder), "--out", str(folder.parent / "o"))
    assert rc == 0 and "error" not in err and (folder.parent / "o" / "compete.png").is_file()


def test_the_recorded_store_is_still_read_where_the_own_file_is_no_store(competed: tuple[Path, Path]) -> None:
    """An own results.sqlite that is no store (an empty file) is passed over for the store the summary names."""
    from neurohover.compete import check_against_store

    folder, store = competed
    (folder / "results.sqlite").write_bytes(b"")
    check_against_store(folder)
    summary = json.loads((folder / "summary.json").read_text())
    (folder / "summary.json").write_text(json.dumps({**summary, "seed": 7}))
    with pytest.raises(NeurohoverError, match=f"its store {str(store)!r} holds"):
        check_against_store(folder)
    (folder / "summary.json").write_text(json.dumps({**summary, "store": f"{store}/"}))  # names no file
    check_against_store(folder)


# T46-A02 ------------------------------------------------------------------------------------------------------------


def test_a_setting_added_to_ones_own_config_is_a_change_of_settings(tmp_path: Path) -> None:
    with Store(tmp_path / "s.sqlite") as store:
        SE.begin(store)
        base = SE.tiny_config().settings
        message = _again(store, {**base, "sensor": {"level": 0.5}})
    assert "the settings differ (sensor: stored absent, given {'level': 0.5}), so the results would not be comparable" in message
    assert "restore the old config" in message and "--fresh" in message
    assert "older neurohover" not in message and "newer neurohover" not in message


def test_a_store_an_older_neurohover_wrote_is_told_apart_from_a_setting_added(tmp_path: Path) -> None:
    """Its stored config lacks a group's estimator (written in at "ols" today): with a sensor added too, only the
    estimator is called the older neurohover's."""
    older = SE.tiny_config().settings
    group = {k: v for k, v in older["groups"][0].items() if k != "estimator"}
    config = dataclasses.replace(SE.tiny_config(), settings={**older, "groups": [group]})
    with Store(tmp_path / "s.sqlite") as store:
        store.begin("tr1", "quick", config.hash, config.to_dict())
        assert "an older neurohover wrote this store" in _again(store, older)
        message = _again(store, {**older, "sensor": {"level": 0.5}})
    assert "; groups 'baseline'.estimator: a setting the older neurohover that wrote the store did not have, at its default)" in message
    assert "restore the old config" in message and "--fresh" in message


# T46-A05 ------------------------------------------------------------------------------------------------------------


class Reached(Exception):
    """A step that writes was reached: the path was not refused (and nothing was written)."""


def _guard(*_args, **_kwargs):
    raise Reached


@pytest.fixture
def guarded(monkeypatch):
    """The steps of output_file and output_dir that make a directory or a file, replaced by :func:`_guard`."""
    import neurohover.paths as paths

    monkeypatch.setattr(paths, "make_dirs", _guard)
    monkeypatch.setattr(paths, "_probe", _guard)
    return paths


@pytest.mark.parametrize(
    ("path", "says"),
    [
        ("/dev/stdout.csv", "cannot create a file in '/dev'"),
        ("/dev/neurohover-no-such-dir/x.csv", "cannot create a folder in '/dev'"),
        ("/proc/x.csv", "cannot create a file in '/proc'"),
        ("/sys/neurohover-x/y.csv", "cannot create a folder in '/sys'"),
        ("/dev/fd/999/x.csv", "cannot create a folder in '/proc/"),
    ],
)
def test_no_file_is_made_in_dev_proc_or_sys(guarded, path: str, says: str) -> None:
    with pytest.raises(NeurohoverError) as err:
        guarded.output_file(path, "--out")
    assert says in str(err.value) and "a pseudo file system" in str(err.value) and "give --out FILE elsewhere" in str(err.value)
    assert not os.path.lexists(path) and (os.path.dirname(path) in ("/dev", "/proc") or not os.path.lexists(os.path.dirname(path)))


@pytest.mark.parametrize("path", ["/dev", "/dev/neurohover-no-such-dir", "/proc/self", "/sys/kernel"])
def test_no_output_folder_is_made_or_written_in_dev_proc_or_sys(guarded, path: str) -> None:
    with pytest.raises(NeurohoverError, match="a pseudo file system") as err:
        guarded.output_dir(path, "--out")
    assert "give --out DIR elsewhere" in str(err.value)
    assert path != "/dev/neurohover-no-such-dir" or not os.path.lexists(path)


def test_dev_shm_and_existing_dev_files_are_taken_as_before(guarded) -> None:
    with pytest.raises(Reached):  # a real tmpfs: on to the writing steps (here the guard)
        guarded.output_dir("/dev/shm", "--out")
    with pytest.raises(Reached):
        guarded.output_file("/dev/shm/neurohover-x.csv", "--out")
    with pytest.raises(NeurohoverError, match=r"^--out '/dev/null' is not a regular file"):  # as before
        guarded.output_file("/dev/null", "--out")


def test_plot_of_dev_stdin_writes_no_figure_into_dev(tmp_path: Path, monkeypatch, cli) -> None:
    """``neurohover plot /dev/stdin < f.npz``: plot's default --out is FLIGHT's folder, here /dev."""
    import neurohover.paths as paths

    flight = recorded(tmp_path, 1)
    monkeypatch.setattr(paths, "output_dir", _guard)
    saved = os.dup(0)
    try:
        with open(flight, "rb") as f:
            os.dup2(f.fileno(), 0)
        rc, out, err = cli("plot", "/dev/stdin")
    finally:
        os.dup2(saved, 0)
        os.close(saved)
    assert rc == 2 and ".png" not in out
    assert "plot's default --out (FLIGHT's folder) '/dev': cannot write files in '/dev'" in err and "give --out DIR" in err
    assert not os.path.lexists("/dev/stdin-episode0.png")
