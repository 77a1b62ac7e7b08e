"""Trial 44, side A (the command line), stores and signals: a results store whose full path is over SQLite's limit was
refused with SQLite's bare "unable to open database file" (T44-A05): it is refused up front, naming the path's length
and the limit. A SIGPIPE sent with ``kill`` is ignored, as Python sets it, where the README said every signal whose
default ends a process without a core dump stops a command (T44-A02): the README now names the exception, and the
behaviour is pinned. ``wins --draws``'s help gives its default as the option takes it (10000, not 10,000)."""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from conftest import tiny_test_runs
from store_edits import competed_store, error

from neurohover.errors import NeurohoverError
from neurohover.experiments.store_checks import SQLITE_MAX_PATH

LINUX = sys.platform.startswith("linux")


def deep_file(tmp_path: Path, size: int) -> Path:
    """A file ``s.sqlite`` under ``tmp_path`` whose full path (links resolved) is ``size`` bytes, in folders of names
    under 255 bytes (made)."""
    folder = Path(os.path.realpath(tmp_path))
    need = size - len(os.fsencode(str(folder / "s.sqlite")))  # each folder: its name and a "/"
    while need > 0:
        name = min(200, need - 1) if need - 201 != 1 else 150
        folder, need = folder / ("d" * name), need - name - 1
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / "s.sqlite"
    assert len(os.fsencode(str(path))) == size
    return path


def test_the_store_refuses_a_full_path_over_sqlites_limit(tmp_path: Path) -> None:
    """T44-A05: 504 bytes open (SQLite's 512 less the 8 of "-journal"), written and read; 505 were SQLite's bare
    "unable to open database file"."""
    from neurohover.experiments import Store

    fits = deep_file(tmp_path, SQLITE_MAX_PATH)
    Store(fits).close()
    Store(fits, create=False).close()
    over = deep_file(tmp_path, SQLITE_MAX_PATH + 1)
    line = rf"is too long for SQLite: its full path \(.*\) is 505 bytes, and SQLite opens at most {SQLITE_MAX_PATH} "
    with pytest.raises(NeurohoverError, match=line):
        Store(over)
    assert not over.exists()
    shutil.copyfile(fits, over)  # a store moved where SQLite cannot open it
    with pytest.raises(NeurohoverError, match=line):
        Store(over, create=False)


@pytest.mark.slow
def test_reproduce_and_results_refuse_a_store_in_a_deep_folder(cli, tmp_path: Path, monkeypatch) -> None:
    """T44-A05: --store in a deep folder, or a short --store from a deep working directory."""
    config = tmp_path / "mini.toml"
    config.write_text(tiny_test_runs("baseline", name="mini"))
    deep = deep_file(tmp_path / "deep", 637)
    rc, _, err = cli("reproduce", str(config), "--store", str(deep), "--no-progress")
    assert rc == 2 and "its full path (the working directory and links resolved) is 637 bytes" in error(err, "reproduce"), err
    assert not deep.exists()
    shutil.copyfile(competed_store(tmp_path), deep)
    monkeypatch.chdir(deep.parent)
    rc, _, err = cli("results", "mini", "--store", deep.name)
    assert rc == 2 and error(err, "results").startswith("results store 's.sqlite' is too long for SQLite: its full path"), err


@pytest.mark.slow
@pytest.mark.skipif(not LINUX, reason="signal handlers read from /proc")
def test_a_sent_sigpipe_leaves_a_command_running_to_its_end(tmp_path: Path) -> None:
    """T44-A02: SIGPIPE stays ignored, as Python sets it (a reader gone away is a BrokenPipeError, the quiet status 1
    test_cli_fuzz pins); one sent once neurohover's handlers are in place changes nothing, as the README says."""
    argv = [sys.executable, "-m", "neurohover", "fly", "--task", "ghh08", "--mdp", "train:0", "--episodes", "600", "--threads", "1"]
    fly = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, cwd=tmp_path)
    status = Path(f"/proc/{fly.pid}/status")
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline and fly.poll() is None:  # until SIGTERM is caught: neurohover's handlers are set
        caught = next((ln.split()[1] for ln in status.read_text().splitlines() if ln.startswith("SigCgt:")), "0")
        if int(caught, 16) >> (signal.SIGTERM - 1) & 1:
            fly.send_signal(signal.SIGPIPE)
            break
        time.sleep(0.002)
    else:
        pytest.fail("fly ended before its handlers could be seen")
    out, err = fly.communicate(timeout=120)
    assert fly.returncode == 0 and "terminated" not in err.decode() and b"episodes_per_second" in out, err


def test_wins_draws_help_gives_its_default_as_the_option_takes_it(cli, capsys) -> None:
    """Trial 44: the help said "default 10,000", which --draws refuses (no integer option takes a comma)."""
    with pytest.raises(SystemExit):
        cli("wins", "--help")
    assert "(default 10000)" in " ".join(capsys.readouterr().out.split())
