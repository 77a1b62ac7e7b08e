"""Trial 53's files (T53-B04, T53-B06): a learned model with a wind and a non-zero d_u, and the no-drift table the
library writes that did not read back. T53-B05 (a policy file's seconds past its manifest's) is not a bug: a build
resumed after an interruption keeps its finished runs with their own seconds and times only itself, so its manifest
holds fewer seconds than its files (T45-B08, pinned in tests/test_bad_input_trial45_evolution.py); refusing it refused
sets neurohover wrote."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

import neurohover as nh
from neurohover.errors import NeurohoverError
from neurohover.models import LearnedModel, WindModel

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


def test_the_no_drift_table_the_library_writes_reads_back_as_no_drift() -> None:
    """T53-B06: Drift.from_dict(Drift().to_dict()) refused 'walk=0.0 changes nothing', while Drift() and {} are taken."""
    assert nh.Drift.from_dict(nh.Drift().to_dict()) == nh.Drift()
    assert nh.Drift.from_dict({}) == nh.Drift()
    for table in ({"walk": 0.0}, {"walk": 0.0, "change": {}}):  # a hand-written walk 0 alone: still a likely slip (documented)
        with pytest.raises(NeurohoverError, match=r"drift walk=0\.0 changes nothing"):
            nh.Drift.from_dict(table)
