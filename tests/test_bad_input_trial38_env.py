"""The thirty-eighth bad-input trial's findings in the environment (T38-A01, T38-A02): a SOURCE_DATE_EPOCH that NumPy's
f2py cannot read is refused by name before anything runs (set but empty: unset), and so is an address-space limit
(``ulimit -v``) below what the thread pools reserve as they start, where SciPy's OpenBLAS hung for ever."""

from __future__ import annotations

import os
import resource
import subprocess
import sys

import pytest

import neurohover
from neurohover.errors import NeurohoverError


def _command(env: dict[str, str], *args: str, address_space: int | None = None, timeout: float = 120) -> subprocess.CompletedProcess:
    """``neurohover ARGS`` with ``env`` added to the environment (``address_space``: its RLIMIT_AS, in bytes)."""

    def limit() -> None:
        if address_space is not None:
            resource.setrlimit(resource.RLIMIT_AS, (address_space, address_space))

    argv = [sys.executable, "-m", "neurohover", *args]
    return subprocess.run(argv, env={**os.environ, **env}, capture_output=True, text=True, timeout=timeout, preexec_fn=limit)


@pytest.mark.parametrize("value", ["abc", "1.5", " ", "1e9", "99999999999999999999"])
def test_a_source_date_epoch_f2py_cannot_read_is_named(monkeypatch, value: str) -> None:
    """T38-A01: SOURCE_DATE_EPOCH=abc (or 1.5) was f2py's ValueError traceback from fly, evolve and report as NumPy or
    SciPy imported f2py lazily (OverflowError past time_t), and compete's failed units named no variable."""
    monkeypatch.setenv("SOURCE_DATE_EPOCH", value)
    with pytest.raises(NeurohoverError, match=r"^environment variable SOURCE_DATE_EPOCH=.* is not allowed: give a whole number of seconds"):
        neurohover._check_source_date_epoch()


@pytest.mark.parametrize("value", ["1700000000", " 12 ", "-5", "+7", "1_000"])
def test_a_source_date_epoch_f2py_reads_is_taken(monkeypatch, value: str) -> None:
    """T38-A01: exactly what f2py itself reads (``int()``, then ``time.gmtime``) is taken, and left as it is."""
    monkeypatch.setenv("SOURCE_DATE_EPOCH", value)
    neurohover._check_source_date_epoch()
    assert os.environ["SOURCE_DATE_EPOCH"] == value


def test_an_empty_source_date_epoch_is_unset(monkeypatch) -> None:
    """T38-A01: set but empty (a build shell's ``SOURCE_DATE_EPOCH=``) is unset, as the reproducible-builds specification
    has it: f2py, which read it as an integer, no longer sees it."""
    monkeypatch.setenv("SOURCE_DATE_EPOCH", "")
    neurohover._check_source_date_epoch()
    assert "SOURCE_DATE_EPOCH" not in os.environ
    from numpy.f2py import rules  # noqa: F401  (imports here, where it raised ValueError on '')


def test_the_command_refuses_a_bad_source_date_epoch_in_one_line() -> None:
    """T38-A01: the command's exit 2 and one line, before anything runs (fly flew into f2py's traceback)."""
    proc = _command({"SOURCE_DATE_EPOCH": "abc"}, "fly", "--task", "ghh08", "--episodes", "2")
    assert proc.returncode == 2 and proc.stdout == "" and len(proc.stderr.splitlines()) == 1, proc.stderr
    assert proc.stderr.startswith("neurohover: error: environment variable SOURCE_DATE_EPOCH='abc' is not allowed: ")
    assert proc.stderr.endswith(", or unset it\n")


def test_an_address_space_limit_the_pools_cannot_start_in_is_named() -> None:
    """T38-A02: under ``ulimit -v 400000`` fly printed nothing and slept for ever, SIGTERM unheard: SciPy's OpenBLAS,
    loaded by numba's first compilation, retried its buffer's mmap in a loop with the interpreter's lock held."""
    proc = _command(
        {"NUMBA_NUM_THREADS": "2", "OPENBLAS_NUM_THREADS": "2"}, "fly", "--task", "ghh08", "--episodes", "2", address_space=400_000 * 1024, timeout=30
    )
    assert proc.returncode == 2 and proc.stdout == "" and len(proc.stderr.splitlines()) == 1, proc.stderr
    assert proc.stderr.startswith(
        "neurohover: error: the address-space limit (ulimit -v) 400000 KiB is not allowed: neurohover needs 496640 KiB with 2 OpenBLAS and 2 numba threads"
    )
    assert proc.stderr.endswith("or unset it (ulimit -v unlimited)\n")


@pytest.mark.parametrize(
    ("env", "threads"),
    [
        ({"NUMBA_NUM_THREADS": "3", "OPENBLAS_NUM_THREADS": "1"}, (1, 3)),
        ({"NUMBA_NUM_THREADS": "1", "OMP_NUM_THREADS": "5"}, (5, 1)),
        ({"NUMBA_NUM_THREADS": "7", "OPENBLAS_NUM_THREADS": "500"}, (64, 7)),
    ],
)
def test_the_address_space_needed_follows_the_thread_pools(monkeypatch, env: dict[str, str], threads: tuple[int, int]) -> None:
    """T38-A02: the room asked for grows with OpenBLAS's threads (which stop at 64) and numba's."""
    for name in ("OPENBLAS_NUM_THREADS", "GOTO_NUM_THREADS", "OMP_NUM_THREADS"):
        monkeypatch.delenv(name, raising=False)
    for name, value in env.items():
        monkeypatch.setenv(name, value)
    assert neurohover._pool_threads() == threads
