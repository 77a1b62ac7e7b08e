"""Fixtures the test modules share: the repository's root, the committed results store, the command line in-process."""

from __future__ import annotations

import gzip
import shutil
from collections.abc import Callable
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
STORE_GZ = ROOT / "docs" / "reproduction" / "results.sqlite.gz"

#: What the ``cli`` fixture returns for one command: exit status, standard output, standard error.
CliRun = Callable[..., tuple[int, str, str]]


@pytest.fixture(scope="session")
def repo_root() -> Path:
    """The checkout the tests run from (README, docs, examples, configs)."""
    return ROOT


@pytest.fixture(scope="session")
def committed_store(tmp_path_factory) -> Path:
    """A private copy of the committed paper-scale results store (skipped where the checkout lacks it)."""
    if not STORE_GZ.is_file():
        pytest.skip("the committed results store is not in this checkout")
    path = tmp_path_factory.mktemp("committed") / "results.sqlite"
    with gzip.open(STORE_GZ) as src, open(path, "wb") as dst:
        shutil.copyfileobj(src, dst)
    return path


@pytest.fixture
def cli(capsys) -> CliRun:
    """``neurohover ARGS...`` run in this process: returns (exit status, stdout, stderr)."""
    from neurohover.cli import main

    def run(*argv: str) -> tuple[int, str, str]:
        rc = main(list(argv))
        out = capsys.readouterr()
        return rc, out.out, out.err

    return run
