"""Trial 28 (28a), output files and standard output: T28-A01 (a closed standard output; a broken pipe), T28-A04 (report
--out replaced a user's report.md or figure name, and wrote through a symbolic link), T28-A05 (PNG outputs replaced files
of another kind), T28-A08 (a FIFO read beside the outputs hung for ever), T28-A12 (a relative path from a deleted
working directory)."""

from __future__ import annotations

import os
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest
from conftest import ROOT, tiny_test_runs


@pytest.fixture(scope="module")
def tiny_store(tmp_path_factory) -> Path:
    """A results store holding the tiny test-runs experiment tr1 (baseline, one MDP, two episodes of 20 steps)."""
    from neurohover.cli import main

    where = tmp_path_factory.mktemp("t28out")
    (where / "t.toml").write_text(tiny_test_runs("baseline"))
    assert main(["reproduce", str(where / "t.toml"), "--store", str(where / "t.sqlite"), "--no-progress"]) == 0
    return where / "t.sqlite"


# T28-A01: a closed standard output; a broken pipe


@pytest.mark.parametrize("argv", [("settings", "hybrid"), ("results", "tr1", "--store", "{store}")])
def test_a_command_that_prints_refuses_a_closed_standard_output(cli, tiny_store, monkeypatch, argv) -> None:
    monkeypatch.setattr(sys, "stdout", None)  # what Python makes of `1>&-`
    rc, _, err = cli(*(a.format(store=tiny_store) for a in argv))
    assert rc == 2 and "error: standard output is closed: this command prints its results there" in err, err


def test_a_command_writing_a_file_runs_with_a_closed_standard_output(cli, tiny_store, tmp_path, monkeypatch) -> None:
    monkeypatch.setattr(sys, "stdout", None)
    rc, _, err = cli("results", "tr1", "--store", str(tiny_store), "--out", str(tmp_path / "x.csv"))
    assert rc == 0 and (tmp_path / "x.csv").stat().st_size > 0, err
    assert sys.stdout is None


@pytest.mark.slow
def test_a_reader_gone_away_ends_the_command_quietly_with_status_1() -> None:
    """Python's recommended handling of a broken pipe (its docs' "Note on SIGPIPE"): status 1 and no line on stderr."""
    proc = subprocess.Popen([sys.executable, "-m", "neurohover", "settings", "hybrid"], cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    assert proc.stdout is not None and proc.stderr is not None
    proc.stdout.close()  # the reader is gone before the command writes
    err = proc.stderr.read()
    assert proc.wait(timeout=60) == 1 and err == b"", err


# T28-A04: report --out replaces only its own report.md and figures, and writes through no symbolic link


@pytest.mark.slow
def test_report_replaces_its_own_report_and_figure(cli, tiny_store, tmp_path) -> None:
    out = tmp_path / "rep"
    assert cli("report", "--store", str(tiny_store), "--out", str(out))[0] == 0
    rc, _, err = cli("report", "--store", str(tiny_store), "--out", str(out))
    assert rc == 0 and (out / "tr1-quick.png").read_bytes().startswith(b"\x89PNG"), err


def test_report_refuses_a_report_md_it_did_not_write(cli, tiny_store, tmp_path) -> None:
    (tmp_path / "report.md").write_text("my notes, precious\n")
    rc, _, err = cli("report", "--store", str(tiny_store), "--out", str(tmp_path))
    assert rc == 2 and "report.md' is a file neurohover did not write: it would be replaced with a reproduction report" in err, err
    assert (tmp_path / "report.md").read_text() == "my notes, precious\n" and not (tmp_path / "tr1-quick.png").exists()


def test_report_refuses_a_symbolic_link_at_report_md(cli, tiny_store, tmp_path) -> None:
    (tmp_path / "target.md").write_text("target\n")
    (tmp_path / "out").mkdir()
    (tmp_path / "out" / "report.md").symlink_to(tmp_path / "target.md")
    rc, _, err = cli("report", "--store", str(tiny_store), "--out", str(tmp_path / "out"))
    assert rc == 2 and "report.md' is a symbolic link (to" in err and "is not written through one" in err, err
    assert (tmp_path / "target.md").read_text() == "target\n"


def test_report_refuses_a_file_of_another_kind_at_a_figure_name(cli, tiny_store, tmp_path) -> None:
    (tmp_path / "tr1-quick.png").write_text("not png\n")
    rc, _, err = cli("report", "--store", str(tiny_store), "--out", str(tmp_path))
    assert rc == 2 and "tr1-quick.png' is a file neurohover did not write: it would be replaced with a PNG image" in err, err
    assert (tmp_path / "tr1-quick.png").read_text() == "not png\n" and not (tmp_path / "report.md").exists()


# T28-A05: every PNG writer replaces only a PNG


def test_write_png_replaces_a_png_or_an_empty_file_and_refuses_another_file(tmp_path) -> None:
    from matplotlib.figure import Figure

    from neurohover.errors import NeurohoverError
    from neurohover.paths import write_png

    fig = Figure()
    for name in ("new.png", "empty.png"):
        (tmp_path / "empty.png").write_bytes(b"")
        write_png(fig, tmp_path / name, "plot file")
        write_png(fig, tmp_path / name, "plot file")  # a PNG: replaced
        assert (tmp_path / name).read_bytes().startswith(b"\x89PNG\r\n\x1a\n")
    (tmp_path / "notes.png").write_text("my pic\n")
    with pytest.raises(NeurohoverError, match=r"plot file '.*notes.png' is a file neurohover did not write: it would be replaced with a PNG image"):
        write_png(fig, tmp_path / "notes.png", "plot file")
    assert (tmp_path / "notes.png").read_text() == "my pic\n"


@pytest.mark.slow
def test_plot_of_flight_data_refuses_a_text_file_at_an_episode_png(cli, tmp_path) -> None:
    assert cli("fly", "--task", "ghh08", "--episodes", "1", "--record", str(tmp_path / "f.npz"))[0] == 0
    (tmp_path / "f-episode0.png").write_text("notes\n")
    rc, _, err = cli("plot", str(tmp_path / "f.npz"))
    assert rc == 2 and "f-episode0.png' is a file neurohover did not write" in err, err
    assert (tmp_path / "f-episode0.png").read_text() == "notes\n"


def test_compete_refuses_a_text_file_at_cumulative_png(cli, tmp_path) -> None:
    (tmp_path / "cumulative.png").write_text("my pic\n")
    argv = ("compete", "--task", "ghh08", "--agent", "baseline", "--episodes", "2", "--episode-steps", "20", "--runs", "1", "--out", str(tmp_path))
    rc, _, err = cli(*argv)
    assert rc == 2 and "cumulative.png' is a file neurohover did not write" in err, err
    assert (tmp_path / "cumulative.png").read_text() == "my pic\n"


# T28-A08: a FIFO beside the outputs is refused, not read


def _unblocked(fifo: Path) -> threading.Event:
    """An event set if anything opens ``fifo`` for reading within 10 s; the opener then gets end of file (no hang)."""
    opened = threading.Event()

    def watch() -> None:
        deadline = time.monotonic() + 10
        while time.monotonic() < deadline:
            try:
                fd = os.open(fifo, os.O_WRONLY | os.O_NONBLOCK)  # succeeds only once a reader has it open
            except OSError:
                time.sleep(0.05)
                continue
            opened.set()
            os.close(fd)
            return

    threading.Thread(target=watch, daemon=True).start()
    return opened


@pytest.mark.slow
def test_report_refuses_a_fifo_discussion(cli, tiny_store, tmp_path) -> None:
    (tmp_path / "discussion").mkdir()
    os.mkfifo(tmp_path / "discussion" / "tr1-quick.md")
    opened = _unblocked(tmp_path / "discussion" / "tr1-quick.md")
    rc, _, err = cli("report", "--store", str(tiny_store), "--out", str(tmp_path))
    assert not opened.is_set() and rc == 2 and "tr1-quick.md' is not a regular file (a device, pipe or socket)" in err, err


def test_compete_refuses_a_fifo_summary_in_its_output_folder(cli, tmp_path) -> None:
    os.mkfifo(tmp_path / "summary.json")
    opened = _unblocked(tmp_path / "summary.json")
    argv = ("compete", "--task", "ghh08", "--agent", "baseline", "--episodes", "2", "--episode-steps", "20", "--runs", "1", "--out", str(tmp_path))
    rc, _, err = cli(*argv)
    assert not opened.is_set() and rc == 2 and "summary.json' is not a regular file (a device, pipe or socket)" in err, err


@pytest.mark.parametrize("name", ["summary.json", "episodes.csv"])
def test_plot_compete_refuses_a_fifo_in_the_folder(cli, tmp_path, name) -> None:
    (tmp_path / "c").mkdir()
    (tmp_path / "c" / "episodes.csv").write_text("run,episode,return\n0,0,-1.0\n")
    (tmp_path / "c" / name).unlink(missing_ok=True)
    os.mkfifo(tmp_path / "c" / name)
    opened = _unblocked(tmp_path / "c" / name)
    rc, _, err = cli("plot", "--compete", str(tmp_path / "c"), "--out", str(tmp_path))
    assert not opened.is_set() and rc == 2 and f"--compete '{tmp_path}/c/{name}' is not a regular file (a device, pipe or socket)" in err, err


# T28-A12: a relative path from a deleted working directory


@pytest.mark.parametrize(
    ("argv", "named"),
    [
        (("reproduce", "{config}", "--store", "rel.sqlite"), "--store 'rel.sqlite'"),
        (("results", "tr1", "--store", "{store}", "--out", "x.csv"), "--out 'x.csv'"),
        (("evolve", "--task", "ghh08", "--budget", "10", "--episode-steps", "20", "--out", "p.json"), "--out 'p.json'"),
        (("fly", "--task", "ghh08", "--episodes", "1", "--record", "f.npz"), "--record 'f.npz'"),
    ],
)
def test_a_relative_output_from_a_deleted_directory_is_named(cli, tiny_store, tmp_path, monkeypatch, argv, named) -> None:
    gone = tmp_path / "gone"
    gone.mkdir()
    monkeypatch.chdir(gone)
    gone.rmdir()
    rc, _, err = cli(*(a.format(store=tiny_store, config=tiny_store.parent / "t.toml") for a in argv))
    assert rc == 2 and f"error: {named}: the current directory no longer exists: give an absolute path" in err, err
