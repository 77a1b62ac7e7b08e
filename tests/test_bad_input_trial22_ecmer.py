"""Bad-input trial 22, EC-MER's policy (T22-17): a recorded policy_flown edited by one gene, or an older file's metadata
naming a policy that never flew the data, was fitted without a word; the policy must give the recorded actions."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from neurohover.errors import NeurohoverError
from neurohover.flightdata import FlightData
from neurohover.models import ec_mer_policy


def _recorded(cli, tmp_path: Path, *extra: str) -> Path:
    path = tmp_path / "f.npz"
    assert cli("fly", "--task", "ghh08", "--mdp", "train:1", "--episodes", "2", "--record", str(path), *extra)[0] == 0
    return path


def _edited(path: Path, edit) -> Path:
    arrays = dict(np.load(path))
    meta = json.loads(str(arrays["metadata"]))
    edit(meta)
    arrays["metadata"] = np.array(json.dumps(meta))
    out = path.with_name("edited.npz")
    np.savez(out, **arrays)
    return out


def test_ec_mer_refuses_a_recorded_policy_that_did_not_fly_the_data(cli, tmp_path: Path) -> None:
    # float32: a float64 file's policy_flown is checked at load (T24-06), and its refusal names policy_flown, not 'baseline'
    edited = _edited(_recorded(cli, tmp_path, "--record-dtype", "float32"), lambda m: m["policy_flown"]["genome"].__setitem__(1, 0.5))
    out = tmp_path / "m.json"
    rc, _, err = cli("learn-model", "--flight-data", str(edited), "--method", "ec-mer", "--budget", "2", "--out", str(out))
    assert rc == 2 and not out.exists(), err
    named = "the policy their metadata policy_flown records (an slp network, genome [0.0, 0.5, "
    assert f"flight data '{edited}': {named}" in err and ") did not fly them" in err and "at step " in err, err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err


def test_an_older_files_named_policy_must_have_flown_the_data(cli, tmp_path: Path) -> None:
    """Without policy_flown the metadata's policy name is used (older files): a file of another policy is refused."""
    other = tmp_path / "other.json"
    other.write_text(json.dumps({"topology": "slp", "genome": [0.01] * 40}))
    edited = _edited(_recorded(cli, tmp_path), lambda m: (m.pop("policy_flown"), m.update(policy=str(other))))
    with pytest.raises(NeurohoverError, match=r"the recorded policy \('/.*other\.json'.*\) did not fly them .*: at step 0 of episode 0"):
        ec_mer_policy(None, FlightData.load(edited), str(edited))


def test_the_policy_that_flew_the_data_is_taken_through_a_noisy_sensor_and_float32(cli, tmp_path: Path) -> None:
    path = _recorded(cli, tmp_path, "--obs-noise", "0.5", "--record-dtype", "float32")
    data = FlightData.load(path)
    assert ec_mer_policy(None, data, str(path)) == ec_mer_policy("baseline", data, str(path))
