"""Bad-input trial 47, files and records: T47-B08 (a LearnedModel's wind past every MDP's bound was made, saved and
loaded, and only .mdp() refused it, naming internal values), T47-B09 (a model file's nested params or noise_std loaded
as if flat), T47-B11 (wrappers.crash_aware took a masked array's hidden values), T47-B15 (the name '.json' was refused
with "give a path ending .json") and T47-B16 (a NEAT record's wrong node count blamed its activation ids)."""

from __future__ import annotations

import dataclasses
import json
import math
import re
from pathlib import Path

import numpy as np
import pytest

import neurohover as nh
from neurohover.errors import NeurohoverError
from neurohover.models import LearnedModel
from neurohover.models.wind import WindAxis, WindModel
from neurohover.sim.constants import DEFAULT_NOISE_STD, DEFAULT_PARAMS

WIND = WindModel("sinusoid", WindAxis(1.0, 2.0, 0.5, 0.3), WindAxis(1.0, 2.0, 0.5, 0.3))


def _model(wind: WindModel = WIND) -> LearnedModel:
    return LearnedModel(DEFAULT_PARAMS, DEFAULT_NOISE_STD, "lr", wind=wind)


# T47-B08 ------------------------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("field", "allowed"),
    [
        ("amplitude", "amplitude + offset in [-50000, 50000]"),
        ("omega", "omega in [0, 628318.5] rad/s"),
        ("phase", "phase in [-62831.85, 62831.85] rad"),
        ("offset", "offset in [-50000, 50000]"),
    ],
)
def test_b08_a_models_wind_past_every_mdps_bound_is_refused_when_made_and_loaded(tmp_path: Path, field: str, allowed: str) -> None:
    wind = dataclasses.replace(WIND, x=dataclasses.replace(WIND.x, **{field: 1e308}))
    words = f"model wind x.{field}=1e+308 is out of range: allowed {allowed} (every MDP's bound, 10000, on its wind numbers: no MDP flies it)"
    with pytest.raises(NeurohoverError, match="^" + re.escape(words) + "$"):
        _model(wind)
    path = _model().save(tmp_path / "m.json")
    d = json.loads(path.read_text())
    d["wind"]["x"][field] = 1e308
    path.write_text(json.dumps(d) + "\n")
    with pytest.raises(NeurohoverError, match="^" + re.escape(f"model file {str(path)!r}: {words}")):
        LearnedModel.load(path)


def test_b08_a_wind_at_every_mdps_bound_flies() -> None:
    bound = 10_000.0
    for changed in ({"amplitude": 5 * bound - 0.3}, {"omega": 20 * math.pi * bound}, {"phase": -2 * math.pi * bound}, {"offset": 5 * bound, "amplitude": 0.0}):
        _model(dataclasses.replace(WIND, y=dataclasses.replace(WIND.y, **changed))).mdp()
    _model(WindModel("constant", WindAxis(offset=bound), WindAxis())).mdp()
    with pytest.raises(NeurohoverError, match=r"^model wind x\.offset=10001\.0 is out of range: allowed offset in \[-10000, 10000\]"):
        _model(WindModel("constant", WindAxis(offset=bound + 1), WindAxis()))


# T47-B09 ------------------------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("key", "nest", "length"),
    [("params", lambda v: [[x] for x in v], 11), ("noise_std", lambda v: [v[:3], v[3:]], 6)],
)
def test_b09_a_model_files_nested_params_or_noise_are_refused(tmp_path: Path, key: str, nest, length: int) -> None:
    path = _model().save(tmp_path / "m.json")
    d = json.loads(path.read_text())
    d[key] = nest(d[key])
    path.write_text(json.dumps(d) + "\n")
    with pytest.raises(NeurohoverError, match=rf"^model file .*: its {key} \[\[.* is not allowed: allowed a flat list of {length} numbers"):
        LearnedModel.load(path)


# T47-B11 ------------------------------------------------------------------------------------------------------------


def test_b11_crash_aware_refuses_a_masked_array() -> None:
    from neurohover.wrappers import crash_aware

    with pytest.raises(NeurohoverError, match=r"^reward=masked_array\(.* is not allowed: .*\(not a masked array: its masked entries would be"):
        crash_aware(np.ma.masked_array([-1e9, -2.0], mask=[True, False]))
    assert crash_aware(np.array([-1.0])).tolist() == [-math.log(2.0)]


# T47-B15 ------------------------------------------------------------------------------------------------------------


@pytest.mark.parametrize(("given", "like"), [(".json", "out.json"), ("x/.json", "x/out.json")])
def test_b15_a_name_that_is_only_its_suffix_is_refused_saying_why(tmp_path: Path, monkeypatch, given: str, like: str) -> None:
    monkeypatch.chdir(tmp_path)
    words = f"policy file '{given}' is not allowed: '.json' is a hidden file's name with no stem: give a name before the suffix (e.g. '{like}')"
    with pytest.raises(NeurohoverError, match="^" + re.escape(words) + "$"):
        nh.save_policy(nh.baseline_policy(), given)
    assert list(tmp_path.iterdir()) == []


def test_b15_flight_data_named_only_npz_is_refused_saying_why(tmp_path: Path, monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)
    flight = nh.evaluate(nh.baseline_policy(), nh.get_task_family("ghh08").zero(), episodes=1, n_steps=5, record=True).flight_data
    with pytest.raises(NeurohoverError, match=r"'\.npz' is a hidden file's name with no stem: give a name before the suffix \(e\.g\. 'out\.npz'\)"):
        flight.save(".npz")


# T47-B16 ------------------------------------------------------------------------------------------------------------

OUTS = [v for key in range(4) for v in (key, 0.0, 1.0, 0)]  # the 4 output nodes 0..3: key, bias, response, identity
RECORD = [4.0, *OUTS, -1, 0, 1.0, -2, 1, 1.0]  # 23 numbers: 4 nodes, 2 connections


@pytest.mark.parametrize("count", [99.0, 5.0, 1e6, 1e308])
def test_b16_a_neat_records_wrong_node_count_is_named(count: float) -> None:
    from neurohover.integrations.neat import forward, network_of_record

    words = (
        f"a NEAT record's node count {count!r} is not allowed: a record of 23 numbers (the count, then 4 per node and 3 per connection) "
        f"does not hold {count!r} nodes and whole connections; it holds 4 nodes"
    )
    with pytest.raises(NeurohoverError, match="^" + re.escape(words) + "$"):
        network_of_record([count, *RECORD[1:]])
    assert forward(network_of_record(RECORD), np.zeros(1, np.int64), np.ones((1, 12))).shape == (1, 4)
