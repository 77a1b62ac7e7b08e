"""Helpers of the tests that hand-edit a flight-data file's metadata and read what each reader said of it (trials 23, 24)."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from neurohover.errors import NeurohoverError
from neurohover.flightdata import FlightData


def recorded(where: Path, episodes: int) -> Path:
    """A recording as ``neurohover fly --record`` writes it under ``where`` (ghh08 train:1, ``episodes`` episodes)."""
    from neurohover.cli import main

    path = where / "f.npz"
    argv = ["fly", "--task", "ghh08", "--mdp", "train:1", "--episodes", str(episodes), "--threads", "1", "--json", "--record", str(path)]
    assert main(argv) == 0
    return path


def edited_copy(flight: Path, out: Path, edit: Callable[[dict], None]) -> Path:
    """``flight`` written again to ``out`` with its metadata changed by ``edit``, its arrays as they were: a hand edit."""
    with np.load(flight) as z:
        arrays = {k: z[k] for k in z.files}
    metadata = json.loads(str(arrays["metadata"]))
    edit(metadata)
    np.savez_compressed(out, **{**arrays, "metadata": np.array(json.dumps(metadata))})
    return out


def refused_everywhere(path: Path, message: str, cli, tmp_path: Path) -> None:
    """``path`` is refused by FlightData.load, plot and learn-model --method lr with ``message`` (a plain text), each
    command in one line naming the file, writing nothing."""
    with pytest.raises(NeurohoverError) as err:
        FlightData.load(path)
    assert str(err.value).startswith(f"flight-data file '{path}': its metadata ") and message in str(err.value), str(err.value)
    for argv in (
        ["plot", str(path), "--episodes", "0", "--out", str(tmp_path / "p")],
        ["learn-model", "--flight-data", str(path), "--method", "lr", "--out", str(tmp_path / "m.json")],
    ):
        rc, _, stderr = cli(*argv)
        assert rc == 2 and "Traceback" not in stderr and message in stderr and str(path) in stderr, stderr
        assert len(stderr.strip().splitlines()) == 1, stderr
        assert not list(tmp_path.glob("p/*.png")) and not (tmp_path / "m.json").exists()
