"""Trial 45, side A (CLI): T45-A01 (a low open-files limit ended ``compete --jobs 2`` with a bare "Too many open
files" and left its new folder behind) and T45-A02 (``--executor ray --address auto`` with RAY_ADDRESS naming a dead
cluster retried it without end; ``--address auto`` reads RAY_ADDRESS, which was not checked)."""

from __future__ import annotations

import errno
import os
import resource
import subprocess
import sys
from pathlib import Path

import pytest

ENV = dict(os.environ)  # with this checkout on PYTHONPATH (conftest)


def _cores() -> int:
    try:
        return len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        return os.cpu_count() or 1


def _soft_limit(soft: int):
    def lower() -> None:  # in the child, before it starts Python
        resource.setrlimit(resource.RLIMIT_NOFILE, (soft, resource.getrlimit(resource.RLIMIT_NOFILE)[1]))

    return lower


needs_two_cores = pytest.mark.skipif(_cores() < 2 or not os.path.isdir("/proc/self/fd"), reason="--jobs 2 needs 2 cores; Linux's /proc")


@pytest.mark.slow
@needs_two_cores
def test_compete_with_workers_under_a_low_open_files_limit_is_refused_up_front(tmp_path: Path) -> None:
    """T45-A01: refused before anything is written, naming the limit, --jobs and what to do (no folder left)."""
    argv = ["compete", "--task", "ghh08", "--agent", "baseline", "--runs", "2", "--episodes", "2", "--episode-steps", "20"]
    proc = subprocess.run(
        [sys.executable, "-m", "neurohover", *argv, "--jobs", "2", "--out", "c"],
        cwd=tmp_path, env=ENV, capture_output=True, text=True, timeout=120, preexec_fn=_soft_limit(16),
    )  # fmt: skip
    assert proc.returncode == 2, proc.stderr[-2000:]
    line = proc.stderr.strip()
    assert line.startswith("neurohover compete: error: --jobs 2 is not allowed here: starting 2 worker processes needs"), line
    assert "`ulimit -n`, the open-files limit, is 16" in line and "give fewer --jobs" in line and "Traceback" not in line
    assert not (tmp_path / "c").exists()


@pytest.mark.slow
@needs_two_cores
def test_a_worker_pool_under_a_low_open_files_limit_is_refused_by_name(tmp_path: Path) -> None:
    """T45-A01, the API: worker_pool(2) measures what starting the workers takes, not EMFILE from inside multiprocessing."""
    code = (
        "import resource\nfrom neurohover.procs import worker_pool\n"
        "resource.setrlimit(resource.RLIMIT_NOFILE, (12, resource.getrlimit(resource.RLIMIT_NOFILE)[1]))\n"
        "try:\n    worker_pool(2)\nexcept Exception as err:\n    print(type(err).__name__, err)\n"
    )
    proc = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, env=ENV, capture_output=True, text=True, timeout=120)
    assert proc.stdout.startswith("NeurohoverError jobs 2 is not allowed here: starting 2 worker processes needs 15"), proc.stdout + proc.stderr
    assert "is 12" in proc.stdout


@pytest.mark.parametrize("code, words", [(errno.EMFILE, "raise the limit (`ulimit -n 1024` or more) or give fewer --jobs"), (errno.ENFILE, "on this system")])
def test_too_many_open_files_anywhere_is_one_line_naming_the_limit(cli, monkeypatch, tmp_path: Path, code: int, words: str) -> None:
    """T45-A01: an EMFILE/ENFILE no check foresaw names the limit and the remedies, not a bare 'Too many open files'."""
    import neurohover.compete

    def fail(*args, **kwargs):
        raise OSError(code, os.strerror(code), "results.sqlite")

    monkeypatch.setattr(neurohover.compete, "compete", fail)
    rc, _, err = cli("compete", "--task", "ghh08", "--agent", "baseline", "--runs", "1", "--episodes", "1", "--out", str(tmp_path / "c"))
    assert rc == 2
    assert err.startswith("neurohover compete: error: too many open files"), err
    assert words in err and "opening 'results.sqlite'" in err
    if code == errno.EMFILE:
        assert f"the open-files limit, is {resource.getrlimit(resource.RLIMIT_NOFILE)[0]}" in err


@pytest.mark.slow
@pytest.mark.parametrize("env_address", ["127.0.0.1:1", "ray://127.0.0.1:1"])
def test_ray_address_auto_checks_the_ray_address_it_reads(tmp_path: Path, env_address: str) -> None:
    """T45-A02: --address auto joins RAY_ADDRESS; a dead one is refused before ray.init (it retried without end). The
    timeout is only a safety net: the assertion is on the line and the status."""
    pytest.importorskip("ray")
    proc = subprocess.run(
        [sys.executable, "-m", "neurohover", "reproduce", "fig2", "--executor", "ray", "--address", "auto", "--store", "s.sqlite", "--no-progress"],
        cwd=tmp_path, env={**ENV, "RAY_ADDRESS": env_address}, capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert proc.returncode == 2, proc.stderr[-2000:]
    line = proc.stderr.strip()
    assert line.splitlines() == [line]
    assert line.startswith(f"neurohover reproduce: error: RAY_ADDRESS '{env_address}': no Ray cluster is listening at 127.0.0.1:1"), line
    assert "unset RAY_ADDRESS" in line
    assert not (tmp_path / "s.sqlite").exists()


def test_make_executor_ray_auto_checks_the_ray_address_it_reads(monkeypatch) -> None:
    """T45-A02, the API: make_executor('ray', address='auto') refuses a dead RAY_ADDRESS before ray.init."""
    ray = pytest.importorskip("ray")
    from neurohover.errors import NeurohoverError
    from neurohover.experiments import make_executor

    if ray.is_initialized():
        pytest.skip("Ray already started in this process")
    monkeypatch.setenv("RAY_ADDRESS", "127.0.0.1:1")
    monkeypatch.setattr(ray, "init", lambda *a, **k: pytest.fail("ray.init was called"))
    with pytest.raises(NeurohoverError, match=r"^RAY_ADDRESS '127.0.0.1:1': no Ray cluster is listening at 127.0.0.1:1"):
        make_executor("ray", address="auto")


def test_a_store_sqlite_cannot_open_a_file_for_is_not_called_damaged(cli, monkeypatch, tmp_path: Path) -> None:
    """T45-A01's close: under `ulimit -n 7` SQLite could not open the store's journal (SQLITE_CANTOPEN), and a healthy
    store was called "damaged or no results store"; it now names the open-files limit or the folder instead."""
    import sqlite3

    import neurohover.compete

    def fail(*args, **kwargs):
        err = sqlite3.OperationalError("unable to open database file")
        err.sqlite_errorcode = sqlite3.SQLITE_CANTOPEN  # as SQLite's own error carries it
        raise err

    monkeypatch.setattr(neurohover.compete, "compete", fail)
    monkeypatch.setattr(resource, "getrlimit", lambda which: (64, 64))  # a low limit, as the trial's
    rc, _, err = cli("compete", "--task", "ghh08", "--agent", "baseline", "--runs", "1", "--episodes", "1", "--out", str(tmp_path / "c"))
    assert rc == 2 and "damaged or is no results store" not in err, err
    assert "could not open a file it needs (SQLite says: unable to open database file): too few open files allowed" in err, err
    assert "the open-files limit, is 64" in err and "the store itself is not damaged" in err
