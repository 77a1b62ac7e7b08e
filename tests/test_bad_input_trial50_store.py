"""Trial 50, side A, the results store's clocks and compete's plot file.

T50-A02: a wall-clock step back during a run (an NTP correction, a resumed virtual machine) stored a session's wall
seconds as the difference of two wall times, negative, and every reader then called the store damaged; a store's
durations are measured on the monotonic clock in the writing process (store_clock.SessionClocks), wall time only stamps.

T50-A03: a machine whose clock reads before 2001 (never set) wrote stores no reader accepted: a writer whose clock reads
outside the readers' window (2001 to 2106) is refused before it makes or writes anything (store_clock.clock_time),
naming the clock's time; readers keep their window, and read a sound store on such a machine.

T50-A05: compete checked its plot file cumulative.png in --out only after flying every run and storing its results;
it is checked up front, as episodes.csv and summary.json are, by the plot's own checks.
"""

from __future__ import annotations

import os
import re
import shutil
import time
from pathlib import Path

import pytest
from store_edits import COMPETE, begin, competed_store

import neurohover
from neurohover.errors import NeurohoverError

NAME = "compete-ghh08-baseline"
YEAR_1973 = 1.7e9  # what a clock never set lags by, about


def _lagging(monkeypatch, by: float) -> None:
    real = time.time
    monkeypatch.setattr(time, "time", lambda: real() - by)


@pytest.mark.slow
def test_a_clock_stepped_back_during_a_run_leaves_a_store_every_reader_reads(tmp_path: Path, monkeypatch) -> None:
    """T50-A02: the session started, then the clock went back an hour: its wall seconds were -3599.6, and every
    reader refused the store as damaged."""
    from neurohover.experiments import Store

    real, step = time.time, [0.0]
    monkeypatch.setattr(time, "time", lambda: real() - step[0])
    started = Store.start_session

    def start_then_step(self, *args, **kwargs):
        session = started(self, *args, **kwargs)
        step[0] = 3600.0  # every wall time after the session's start is an hour earlier
        return session

    monkeypatch.setattr(Store, "start_session", start_then_step)
    store = competed_store(tmp_path)
    monkeypatch.undo()
    with Store(store, create=False) as held:
        (scale,) = held.scales(NAME)
        sessions = held.sessions(NAME, scale)
        assert held.units(NAME, scale)
    assert len(sessions) == 1 and 0 <= sessions[0]["wall_seconds"] < 600, sessions


def test_a_session_another_store_started_records_no_negative_wall_seconds(tmp_path: Path, monkeypatch) -> None:
    """T50-A02: a session this Store did not start (no monotonic start of its own) takes wall times, at least 0."""
    from neurohover.experiments import Store

    with Store(tmp_path / "s.sqlite") as first:
        config_hash = begin(first)
        session = first.start_session("tr1", "quick", config_hash, "local", 1, 0)
    _lagging(monkeypatch, 3600.0)
    with Store(tmp_path / "s.sqlite") as second:
        second.end_session(session, "finished")
        assert second.sessions("tr1", "quick")[0]["wall_seconds"] == 0.0


def test_a_writer_whose_clock_reads_1973_writes_no_store(tmp_path: Path, monkeypatch, cli) -> None:
    """T50-A03: the second run was refused: "unit ...'s finished time 96642223.0 is damaged"."""
    from neurohover.experiments import Store

    _lagging(monkeypatch, YEAR_1973)
    says = r"the system clock's time 9[0-9.]+ \(1973-.* UTC, seconds since 1970\) is not allowed: .*from 2001 to 2106.*set the system clock"
    with pytest.raises(NeurohoverError, match=rf"cannot create the results store '.*new\.sqlite': {says}"):
        Store(tmp_path / "new.sqlite")
    assert not (tmp_path / "new.sqlite").exists()
    rc, _, err = cli(*COMPETE, "--out", str(tmp_path / "c"), "--store", str(tmp_path / "c.sqlite"))
    assert rc == 2 and "the system clock's time" in err and "set the system clock" in err, err
    assert not (tmp_path / "c").exists() and not (tmp_path / "c.sqlite").exists()
    rc, _, err = cli(*COMPETE, "--out", str(tmp_path / "d"))
    assert rc == 2 and "compete's results store: the system clock's time" in err and not (tmp_path / "d").exists(), err


@pytest.mark.slow
def test_a_store_is_neither_written_nor_changed_where_the_clock_reads_1973_but_is_read(tmp_path: Path, monkeypatch) -> None:
    """T50-A03: a sound store, read where the clock lags, is no damage; a write into it (begin, update, a session, a
    unit) is refused before anything changes."""
    from neurohover.experiments import Store

    store = competed_store(tmp_path)
    before = store.read_bytes()
    _lagging(monkeypatch, YEAR_1973)
    with Store(store, create=False) as held:
        (scale,) = held.scales(NAME)
        assert held.units(NAME, scale) and held.sessions(NAME, scale) and held.experiments()
        config_hash, config = held.config_hash(NAME, scale), held.config(NAME, scale)
        writes = (
            lambda: held.begin(NAME, scale, config_hash, config, fresh=True),
            lambda: held.update(NAME, scale, config_hash, config, []),
            lambda: held.start_session(NAME, scale, config_hash, "local", 1, 0),
        )
        for write in writes:
            with pytest.raises(NeurohoverError, match=r"the system clock's time .* is not allowed: .*set the system clock \(nothing was written\)"):
                write()
    assert store.read_bytes() == before
    assert not Path(f"{store}.lock").exists()


def _policy_file() -> Path:
    return Path(neurohover.__file__).parent / "data" / "policies" / "ghh09" / "specialised_0.json"


def _policy_copy(plot: Path) -> None:
    shutil.copyfile(_policy_file(), plot)


def _policy_link(plot: Path) -> None:
    shutil.copyfile(_policy_file(), plot.with_name("p.json"))
    plot.symlink_to("p.json")


@pytest.mark.parametrize(
    ("make", "says"),
    [
        (_policy_copy, r"plot file '.*cumulative\.png' is a policy file: it would be replaced with a PNG image"),
        (lambda plot: plot.mkdir(), r"plot file '.*cumulative\.png' is a directory"),
        (lambda plot: os.mkfifo(plot), r"plot file '.*cumulative\.png' is not a regular file \(a device, pipe or socket\)"),
        (lambda plot: plot.symlink_to("nowhere"), r"plot file '.*cumulative\.png' is a symbolic link to 'nowhere'"),
        (_policy_link, r"plot file .* is a symbolic link to .*p\.json' .*: a plot is PNG"),
    ],
    ids=["policy-file", "directory", "fifo", "dangling-link", "link-to-policy"],
)
def test_compete_refuses_a_plot_file_it_would_not_replace_before_any_run_flies(tmp_path: Path, cli, make, says: str) -> None:
    """T50-A05: the refusal came after every run flew and was stored (with --store and without)."""
    out = tmp_path / "c"
    out.mkdir()
    make(out / "cumulative.png")
    for store in ((), ("--store", str(tmp_path / "s.sqlite"))):
        rc, _, err = cli(*COMPETE, "--out", str(out), *store)
        assert rc == 2, err
        assert re.search(says, err), err
        assert not (out / "results.sqlite").exists() and not (tmp_path / "s.sqlite").exists()
        assert not (out / "episodes.csv").exists() and not (out / "summary.json").exists()
