"""Bad-input trial 23, the checks' wiring: a plain ``import neurohover`` checks a policy file's record in load_policy
(T23-11; the check lives in manifest, above policies, and is installed when the package imports), and a plot checks
flight data's returns against their readings when the metadata were changed after the flight data were made (T23-03)."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from neurohover.errors import NeurohoverError
from neurohover.flightdata import FlightData
from neurohover.plots import plot_flight_data


@pytest.mark.slow
def test_a_plain_import_checks_a_policy_files_record(tmp_path: Path) -> None:
    path = tmp_path / "p.json"
    shipped = Path(__file__).parents[1] / "neurohover" / "data" / "policies" / "ghh08" / "generic.json"
    record = json.loads(shipped.read_text())
    record["stop_reason"] = "zzz"
    path.write_text(json.dumps(record))
    script = f"import neurohover\ntry:\n    neurohover.load_policy({str(path)!r})\nexcept ValueError as e:\n    print('refused:', e)\n"
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120, check=True).stdout
    assert out.startswith(f"refused: policy file {str(path)!r}: its stop_reason 'zzz' is not allowed"), out


def test_a_plot_checks_returns_changed_after_making(cli, tmp_path: Path) -> None:
    flown = tmp_path / "f.npz"
    assert cli("fly", "--task", "ghh08", "--mdp", "train:3", "--episodes", "1", "--record", str(flown))[0] == 0
    data = FlightData.load(flown)
    assert data.metadata["returns"][0] < -1.0  # so that -1.0 is no return these readings give
    data.metadata["returns"] = [-1.0]
    with pytest.raises(NeurohoverError, match=r"^flight data: its metadata returns=\[-1\.0\] is not allowed"):
        plot_flight_data(data, tmp_path / "plots")
    assert not (tmp_path / "plots").exists()
