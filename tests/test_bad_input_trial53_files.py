"""Trial 53's files (T53-B04, T53-B05, T53-B06): a learned model with a wind and a non-zero d_u, a policy file whose
seconds exceed its whole build's, and the no-drift table the library writes that did not read back."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

import neurohover as nh
from neurohover.errors import NeurohoverError
from neurohover.models import LearnedModel, WindModel
from neurohover.policysets import build_policy_set, load_policy_set, policy_dir

_PARAMS = (-0.17, -0.44, -1.85, 2.75, -42.3, -3.87, 9.98, -1.92, -7.97, -1.42, 15.1)
_NOISE = (0.26, 0.35, 0.69, 0.096, 0.14, 0.04)
_STILL = {"amplitude": 0.0, "omega": 0.0, "phase": 0.0}


def _constant_wind() -> WindModel:
    return WindModel.from_dict({"kind": "constant", "x": {**_STILL, "offset": 1.0}, "y": {**_STILL, "offset": 0.0}})


def test_a_model_with_a_wind_and_a_d_u_is_refused_by_its_constructor_and_in_its_file(tmp_path: Path) -> None:
    """T53-B04: LearnedModel(..., d_u=0.86, wind=<constant>) was built, saved, loaded and flown; d_u is 0 with a wind."""
    with pytest.raises(NeurohoverError, match=r"its d_u 0\.86 is not allowed with a 'constant' wind: allowed 0\.0"):
        LearnedModel(_PARAMS, _NOISE, "lr", d_u=0.86, wind=_constant_wind())
    ok = LearnedModel(_PARAMS, _NOISE, "lr", d_u=0.0, wind=_constant_wind())  # no D_u beside the wind: as LR's wind fit
    assert LearnedModel(_PARAMS, _NOISE, "lr", d_u=0.86).d_u == 0.86  # D_u without a wind: as LR's "uv" fit
    path = tmp_path / "b04.json"
    ok.save(path)
    d = json.loads(path.read_text())
    d["d_u"] = 0.86  # no stats: nothing else says the file's wind keeps no u constant
    d.pop("stats", None)
    path.write_text(json.dumps(d))
    with pytest.raises(NeurohoverError, match=r"b04\.json': its d_u 0\.86 is not allowed with a 'constant' wind"):
        LearnedModel.load(path)


def test_a_policy_file_whose_seconds_exceed_the_manifest_s_is_refused(tmp_path: Path) -> None:
    """T53-B05: specialised_3.json's seconds 1e6 beside a manifest's 604.4 loaded; each run is part of the build."""
    for task in ("ghh08", "fghh"):  # the shipped sets load (fghh's files sum past its manifest's: each is within it)
        load_policy_set(task)
    shutil.copytree(policy_dir("ghh08"), tmp_path / "ghh08")
    manifest = json.loads((tmp_path / "ghh08" / "manifest.json").read_text())["seconds"]
    f = tmp_path / "ghh08" / "specialised_3.json"
    d = json.loads(f.read_text())
    d["seconds"] = round(manifest + 0.05, 2)  # within the rounding: the file's to 0.01 s, the manifest's to 0.1 s
    f.write_text(json.dumps(d, indent=1))
    load_policy_set("ghh08", tmp_path)
    d["seconds"] = 1e6
    f.write_text(json.dumps(d, indent=1))
    with pytest.raises(NeurohoverError, match=rf"specialised_3\.json's seconds 1000000\.0 is not allowed beside the manifest's seconds {manifest}"):
        load_policy_set("ghh08", tmp_path)


def test_a_resumed_build_counts_its_kept_runs_seconds(tmp_path: Path) -> None:
    """T53-B05: a build resumed counted only its own time, so a run kept from before could exceed the manifest's seconds."""
    said: list[str] = []

    def stop_after_three(message: str) -> None:
        said.append(message)
        if len(said) == 3:
            raise KeyboardInterrupt

    args = {"budget": 20, "n_steps": 30, "safety_episodes": 1}
    with pytest.raises(KeyboardInterrupt):
        build_policy_set("ghh08", tmp_path, progress=stop_after_three, **args)
    stages = [p for p in tmp_path.rglob("*.json") if "seconds" in json.loads(p.read_text())]
    assert stages
    for p in stages:  # runs that took long before the build was stopped
        d = json.loads(p.read_text())
        p.write_text(json.dumps({**d, "seconds": 300.0}, indent=1))
    resumed = build_policy_set("ghh08", tmp_path, **args)
    assert resumed.manifest["seconds"] >= 300.0 * len(stages)
    load_policy_set("ghh08", tmp_path)


def test_the_no_drift_table_the_library_writes_reads_back_as_no_drift() -> None:
    """T53-B06: Drift.from_dict(Drift().to_dict()) refused 'walk=0.0 changes nothing', while Drift() and {} are taken."""
    assert nh.Drift.from_dict(nh.Drift().to_dict()) == nh.Drift()
    assert nh.Drift.from_dict({}) == nh.Drift()
    for table in ({"walk": 0.0}, {"walk": 0.0, "change": {}}):  # a hand-written walk 0 alone: still a likely slip (documented)
        with pytest.raises(NeurohoverError, match=r"drift walk=0\.0 changes nothing"):
            nh.Drift.from_dict(table)
