"""Trial 47 (47a), the command line: T47-A02 (two reports of different stores into one --out at once both said "report
written", the folder left with one's report.md and the other's figures, no note) and T47-A03 (two flights named alike
plotted into one --out at once mixed their episodes' figures, no note): each holds a lock file in its output folder
while it writes, as compete does (trial 31), a second run refused naming the first's pid."""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from flight_edits import recorded
from store_edits import COMPETE, competed_store

from neurohover.errors import NeurohoverError, brief
from neurohover.paths import WriterLock

#: A pid no process has (past the largest pid_max Linux allows, 2**22): the pid a killed run's lock file names.
DEAD = 2**22 + 1


def _held(path: Path) -> WriterLock:
    """A first writer holding the lock file ``path`` (the lock is the OS's: another process's alike)."""
    lock = WriterLock(path)
    assert lock.acquire(lambda who: who)
    return lock


# T47-A02: one report at a time in one --out


@pytest.mark.slow
def test_a02_a_report_into_a_folder_another_report_is_writing_is_refused(cli, tmp_path: Path) -> None:
    from neurohover.experiments import Store, write_report

    store = competed_store(tmp_path)
    out = tmp_path / "r"
    out.mkdir()
    lock = _held(out / ".report.lock")
    try:
        rc, stdout, err = cli("report", "--store", str(store), "--out", str(out))
        said = f"error: report directory {brief(str(out))} is in use: another report run (pid {os.getpid()} on host "
        assert rc == 2 and said in err and "give another output directory" in err and "report written" not in stdout, err
        with pytest.raises(NeurohoverError, match="is in use: another report run"):  # the API alike
            write_report(Store(store), out)
        assert sorted(p.name for p in out.iterdir()) == [".report.lock"]  # nothing written
    finally:
        lock.release()
    rc, stdout, err = cli("report", "--store", str(store), "--out", str(out))
    assert rc == 0 and (out / "report.md").is_file() and not (out / ".report.lock").exists(), err


@pytest.mark.slow
def test_a02_a_killed_reports_lock_file_does_not_block_the_next(cli, tmp_path: Path) -> None:
    store = competed_store(tmp_path)
    out = tmp_path / "r"
    out.mkdir()
    (out / ".report.lock").write_text(f"{DEAD} h\n")  # left by a killed run: no process holds it
    rc, _, err = cli("report", "--store", str(store), "--out", str(out))
    assert rc == 0 and (out / "report.md").is_file() and not (out / ".report.lock").exists(), err


# T47-A03: one plot at a time in one --out


@pytest.mark.slow
def test_a03_a_plot_into_a_folder_another_plot_is_writing_is_refused(cli, tmp_path: Path) -> None:
    from neurohover.flightdata import FlightData
    from neurohover.plots import plot_flight_data

    flight = recorded(tmp_path, 1)
    out = tmp_path / "p"
    out.mkdir()
    lock = _held(out / ".plot.lock")
    try:
        rc, stdout, err = cli("plot", str(flight), "--out", str(out))
        said = f"error: --out {brief(str(out))} is in use: another plot run (pid {os.getpid()} on host "
        assert rc == 2 and said in err and "give another output directory" in err and ".png" not in stdout, err
        with pytest.raises(NeurohoverError, match=r"^out_dir .* is in use: another plot run"):  # the API alike
            plot_flight_data(FlightData.load(flight), out, stem="f")
        assert sorted(p.name for p in out.iterdir()) == [".plot.lock"]  # nothing written
    finally:
        lock.release()
    rc, stdout, err = cli("plot", str(flight), "--out", str(out))
    assert rc == 0 and stdout.splitlines()[-1] == str(out / "f-episode0.png"), (stdout, err)
    assert sorted(p.name for p in out.iterdir()) == ["f-episode0.png"]  # no lock file left


@pytest.mark.slow
def test_a03_plot_compete_into_a_folder_another_plot_is_writing_is_refused(cli, tmp_path: Path) -> None:
    assert cli(*COMPETE, "--out", str(tmp_path / "c"))[0] == 0
    out = tmp_path / "p"
    out.mkdir()
    lock = _held(out / ".plot.lock")
    try:
        rc, _, err = cli("plot", "--compete", str(tmp_path / "c"), "--out", str(out))
        assert rc == 2 and f"error: --out {brief(str(out))} is in use: another plot run (pid {os.getpid()} on host " in err, err
        assert sorted(p.name for p in out.iterdir()) == [".plot.lock"]
    finally:
        lock.release()
    rc, _, err = cli("plot", "--compete", str(tmp_path / "c"), "--out", str(out))
    assert rc == 0 and sorted(p.name for p in out.iterdir()) == ["compete.png"], err


@pytest.mark.slow
def test_a03_a_killed_plots_lock_file_does_not_block_the_next(cli, tmp_path: Path) -> None:
    flight = recorded(tmp_path, 1)
    out = tmp_path / "p"
    out.mkdir()
    (out / ".plot.lock").write_text(f"{DEAD} h\n")  # left by a killed run: no process holds it
    rc, _, err = cli("plot", str(flight), "--out", str(out))
    assert rc == 0 and sorted(p.name for p in out.iterdir()) == ["f-episode0.png"], err
