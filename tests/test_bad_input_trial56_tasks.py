"""Bad-input trial 56, side B (tasks and models): a NumPy float32 or float16 setting (FGHH's sigma, a sensor's and a
drift's fields, a noise level, a wind) was kept as its float32 value, so ``sigma=np.float32(0.3)`` flew FGHH's seeded
sets (T56-B03): it is read as the decimal it prints as. -0.0 in a sensor's or drift's field was recorded as -0.0, an
equal sensor hashed as another competition (T56-B04): it is 0.0. A model file without its d_u entry, though its stats
say d_u 'keep' or it has a wind entry, loaded with D_u 0.0 (T56-B05): refused, naming what is missing. A task family
object where a task's name goes was an "unknown task" (T56-B06): the message names the name to give."""

from __future__ import annotations

import json

import gymnasium as gym
import numpy as np
import pytest

import neurohover as nh
from neurohover import Drift, NeurohoverError, Sensor
from neurohover.models import LearnedModel, learn_lr


@pytest.mark.parametrize("kind", [np.float32, np.float16])
def test_b03_a_narrow_float_sigma_is_read_as_printed(kind) -> None:
    """T56-B03: np.float32(0.3) was FGHH(sigma=0.30000001192092896), whose train:0 was the seeded set's."""
    family = nh.get_task_family("fghh", sigma=kind(0.3))
    assert family.sigma == 0.3 and family.has_competition_sets
    assert family.mdp("train:0").label == "fghh/train:0"
    assert nh.get_task_family("fghh", sigma=np.float32(0.25)).sigma == 0.25  # exact in float32 (trial 26)


def test_b03_narrow_float_sensor_drift_and_wind_settings_are_read_as_printed() -> None:
    """T56-B03: a float32 level, sensor std, dropout, drift walk and factor, and wind were kept as float32 values."""
    assert Sensor.at_level(np.float32(0.1)) == Sensor.at_level(0.1)
    assert Sensor(velocity=np.float16(0.1), dropout=np.float32(0.1)) == Sensor(velocity=0.1, dropout=0.1)
    assert Sensor(position=0.2, correlation=np.float32(0.9)).correlation == 0.9
    assert Drift(np.float32(0.01), (("D_w", np.float32(0.8)),)).to_dict() == {"walk": 0.01, "change": {"D_w": 0.8}, "change_at": [200, 800]}
    ghh08 = nh.get_task_family("ghh08")
    assert ghh08.make([np.float32(0.3), np.float32(-0.1)]).wind == (0.3, -0.1)
    assert ghh08.make(np.array([0.3, 0.1], dtype=np.float32)).wind == (0.3, 0.1)


def test_b04_minus_zero_sensor_and_drift_fields_are_zero() -> None:
    """T56-B04: correlation=-0.0 compared equal but to_dict wrote -0.0, another settings hash: a second competition."""
    for sensor in (Sensor.at_level(1, correlation=-0.0), Sensor(velocity=-0.0, dropout=-0.0), Sensor.at_level(-0.0)):
        assert all(np.copysign(1.0, v) == 1.0 for v in sensor.to_dict().values())
    assert Sensor.at_level(1, correlation=-0.0).to_dict() == Sensor.at_level(1).to_dict()
    assert np.copysign(1.0, Drift(-0.0, (("D_w", 0.8),)).to_dict()["walk"]) == 1.0


@pytest.fixture(scope="module")
def model_file(tmp_path_factory) -> dict:
    """An LR model's file (d_u 'keep', no wind) as a dict: the baseline's 100 steps on GHH-08's train:0."""
    flown = nh.evaluate(nh.baseline_policy(), nh.get_task_family("ghh08").mdp("train:0"), record=True, n_steps=100).flight_data
    path = learn_lr(flown).save(tmp_path_factory.mktemp("m") / "model.json")
    return json.loads(path.read_text())


def test_b05_a_model_file_without_its_d_u_is_refused(model_file, tmp_path) -> None:
    """T56-B05: the file loaded with D_u 0.0, flown without its u acceleration, though its stats say d_u 'keep'."""
    assert model_file["stats"]["d_u"] == "keep" and "wind" in model_file
    d = {k: v for k, v in model_file.items() if k != "d_u"}
    with pytest.raises(NeurohoverError, match=r"it has no d_u entry, but its stats say d_u 'keep' and it has a wind entry, .*: give d_u, a finite number"):
        LearnedModel.from_dict(d, "m.json")
    d.pop("wind")
    with pytest.raises(NeurohoverError, match=r"no d_u entry, but its stats say d_u 'keep', which"):
        LearnedModel.from_dict(d, "m.json")


def test_b05_a_file_from_before_d_u_still_loads(model_file) -> None:
    """T56-B05: a file without wind, d_u and stats.d_u (as written before D_u) loads, with D_u 0.0."""
    d = {k: v for k, v in model_file.items() if k not in ("d_u", "wind")}
    d["stats"] = {k: v for k, v in d["stats"].items() if k not in ("d_u", "wind_model")}
    d["stats"].pop("intercepts", None)
    assert LearnedModel.from_dict(d, "m.json").d_u == 0.0


def test_b06_a_family_object_as_the_task_names_its_name() -> None:
    """T56-B06: FGHH(sigma=0.2) as the task was "unknown task FGHH(sigma=0.2)"; None and 5 stay unknown tasks (trial 11)."""
    with pytest.raises(NeurohoverError, match=r"^task=FGHH\(sigma=0\.2\) is not allowed: give the task's name, 'fghh' \(and sigma=0\.2\)$"):
        nh.get_task_family(nh.get_task_family("fghh", sigma=0.2))
    with pytest.raises(NeurohoverError, match=r"^task=GHH08\(\) is not allowed: give the task's name, 'ghh08'$"):
        nh.envs.HoverEnv(nh.get_task_family("ghh08"))
    with pytest.raises(NeurohoverError, match=r"^task=GHH08\(\) is not allowed: give the task's name, 'ghh08'$"):
        gym.make("neurohover/GHH08-v0", task=nh.get_task_family("ghh08"))
    with pytest.raises(NeurohoverError, match=r"^unknown task None: allowed ghh08"):
        nh.get_task_family(None)  # type: ignore[arg-type]
