"""neurohover.tasks: a task family is one value that round-trips through one dict shape (issue 34)."""

from __future__ import annotations

import json

import pytest

from neurohover.errors import NeurohoverError
from neurohover.evolution.config import resolve_target
from neurohover.tasks import TASK_NAMES, Drift, Sensor, family_from_dict, get_task_family

NOISY = Sensor.parse("level=1.0")
DRIFT = Drift.from_dict({"walk": 0.01})


@pytest.mark.parametrize("name", TASK_NAMES)
@pytest.mark.parametrize("sensor", [None, NOISY])
@pytest.mark.parametrize("drift", [None, DRIFT])
def test_a_family_round_trips_through_its_dict(name: str, sensor, drift) -> None:
    sigma = 0.2 if get_task_family(name).has_sigma else None
    family = get_task_family(name, sigma, sensor, drift)
    d = family.to_dict()
    assert json.loads(json.dumps(d)) == d  # JSON-ready
    back = family_from_dict(d)
    assert back == family and back.sensor == family.sensor and back.drift == family.drift and back.sigma == family.sigma
    assert ("sensor" in d) == (sensor is not None) and ("drift" in d) == (drift is not None)


def test_the_experiments_spelling_reads_as_the_same_family() -> None:
    assert family_from_dict({"task": "fghh", "sigma": 0.3, "sensor": NOISY.to_dict()}) == get_task_family("fghh", 0.3, NOISY)


def test_an_evolution_target_records_what_the_family_is() -> None:
    """The checkpoint's target of a noisy-sensor family differs from the exact one's (a resume cannot mix them)."""
    exact, noisy = get_task_family("fghh", 0.3), get_task_family("fghh", 0.3, NOISY)
    assert resolve_target(exact)[2] == {"kind": "family", "family": "fghh", "sigma": 0.3}  # as checkpoints always recorded it
    assert resolve_target(noisy)[2] == {"kind": "family", **noisy.to_dict()} != resolve_target(exact)[2]


@pytest.mark.parametrize(
    "bad, message",
    [
        ({"family": "ghh08", "sigmaa": 0.3}, "unknown key(s) 'sigmaa'"),
        ({"sigma": 0.3}, "no family name"),
        ({"family": "ghh99"}, "unknown task 'ghh99'"),
        ({"family": "ghh08", "sigma": 0.3}, "sigma applies to the fghh task only"),
        ({"family": "fghh", "sensor": {"levle": 1}}, "unknown sensor setting(s) 'levle'"),
        ("ghh08", "must be a table"),
    ],
)
def test_a_bad_family_table_is_refused_by_name(bad, message) -> None:
    with pytest.raises(NeurohoverError) as err:
        family_from_dict(bad)
    assert message in str(err.value)


def test_a_bad_sensor_names_constructors_that_work() -> None:
    """The message's examples build a sensor (it once suggested Sensor.parse('obs_noise=...'), which is refused)."""
    with pytest.raises(NeurohoverError) as err:
        get_task_family("ghh08", sensor="x")
    assert "Sensor.of(obs_noise=1.0)" in str(err.value) and "Sensor.parse('level=1.0')" in str(err.value)
    assert Sensor.of(obs_noise=1.0) == Sensor.parse("level=1.0") != Sensor()
