"""Bad-input trial 53, side A (the command line): fly --record (and FlightData.save) replaced a .npz that neurohover did
not write, a user's own NumPy archive or a text file, without a word (T53-A04): refused now, naming it, as the other
writers refuse files they did not write; flight data neurohover wrote is still replaced."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import neurohover as nh
from neurohover import NeurohoverError


@pytest.mark.parametrize("made", ["archive", "text"])
def test_a04_a_npz_neurohover_did_not_write_is_not_replaced(tmp_path: Path, cli, made: str) -> None:
    path = tmp_path / "u3.npz"
    if made == "archive":
        np.savez(path, weights=np.ones(5))
    else:
        path.write_text("my notes\n")
    before = path.read_bytes()
    rc, _, err = cli("fly", "--task", "ghh08", "--episodes", "1", "--record", str(path))
    assert rc == 2 and "is a file neurohover did not write: give another path (writing flight data (a NumPy archive) would destroy it)" in err, err
    fd = nh.evaluate(nh.baseline_policy(), nh.get_task_family("ghh08").zero(), n_steps=10, record=True).flight_data
    with pytest.raises(NeurohoverError, match="is a file neurohover did not write"):
        fd.save(path)
    assert path.read_bytes() == before


def test_a04_flight_data_neurohover_wrote_is_replaced(tmp_path: Path, cli) -> None:
    path = tmp_path / "own.npz"
    for episodes in ("1", "2"):
        rc, _, err = cli("fly", "--task", "ghh08", "--episodes", episodes, "--record", str(path))
        assert rc == 0, err
    assert nh.FlightData.load(path).n_episodes == 2
