"""Bad-input trial 23, T23-01: learn-model wrote its model, then refused the flight data's MDP (dt 0.02 x 10 substeps,
no 0.1 s control step): the refused command left m.json behind, and its message named no file."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np


def test_learn_model_refuses_a_recorded_mdp_before_writing_its_model(cli, tmp_path: Path) -> None:
    flown, edited, out = tmp_path / "f.npz", tmp_path / "x.npz", tmp_path / "m.json"
    assert cli("fly", "--task", "ghh08", "--mdp", "train:1", "--episodes", "1", "--record", str(flown))[0] == 0
    arrays = dict(np.load(flown))
    meta = json.loads(str(arrays["metadata"]))
    meta["mdps"][0]["dt"] = 0.02
    arrays["metadata"] = np.array(json.dumps(meta))
    np.savez(edited, **arrays)
    rc, out_text, err = cli("learn-model", "--flight-data", str(edited), "--method", "lr", "--out", str(out))
    assert rc == 2 and not out.exists() and "written" not in out_text, out_text + err
    # refused at load since T23-02 (no ghh08 MDP has dt 0.02), before learn-model's own step check: either names file and dt
    assert f"flight-data file '{edited}'" in err and "dt=0.02" in err and err.count("\n") == 1, err
    assert cli("learn-model", "--flight-data", str(flown), "--method", "lr", "--out", str(out))[0] == 0 and out.exists()
