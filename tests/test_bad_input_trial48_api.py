"""Trial 48, side B (Python API): plots of readings no flight gives or huge ones (T48-B01, T48-B05, T48-B06), the module
``neurohover.evaluate`` behind the package's function of that name (T48-B02), Sensor correlation's allowed range
(T48-B08) and load_config's overrides message (T48-B09)."""

from __future__ import annotations

import importlib
import json
import warnings
from pathlib import Path

import numpy as np
import pytest

import neurohover as nh
from neurohover.errors import NeurohoverError
from neurohover.experiments.config import load_config, shipped_configs
from neurohover.flightdata import FlightData
from neurohover.plots import attitude_angles, crashed_episode, flight_figure, plot_flight_data


def _flight(tmp_path: Path, sensor: nh.Sensor | None = None, huge: bool = False) -> FlightData:
    """A 5-step recording of the baseline (saved and loaded), its observations 1e300 if ``huge`` (a hand edit that
    FlightData.load accepts where the file records no MDPs to bound its readings by, as evaluate's did before T59-B04)."""
    family = nh.get_task_family("ghh08", sensor=sensor) if sensor else nh.get_task_family("ghh08")
    data = nh.evaluate(nh.baseline_policy(), family.training_mdps()[0], record=True, seed=2, n_steps=5).flight_data
    path = data.save(tmp_path / "f.npz")
    if huge:
        with np.load(path) as z:
            arrays = {k: z[k] for k in z.files}
        arrays["observations"] = arrays["observations"] * 0 + 1e300
        meta = json.loads(str(arrays["metadata"]))
        arrays["metadata"] = np.array(json.dumps({k: v for k, v in meta.items() if k != "mdps"}))  # its MDP would refuse them
        np.savez(path, **arrays)
    return FlightData.load(path)


@pytest.mark.slow
def test_huge_readings_plot_without_numpy_warnings(tmp_path: Path) -> None:
    """T48-B01: 1e300 readings squared in attitude_angles were NumPy's overflow RuntimeWarnings (a traceback under -W error)."""
    data = _flight(tmp_path, huge=True)
    obs, act = np.full((11, 12), 1e300), np.zeros((10, 4))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        angles = attitude_angles(obs)
        flight_figure(obs, act, episode_steps=10)
        paths = plot_flight_data(data, tmp_path / "plots", episodes=[0])
    assert np.all(np.isfinite(angles)) and [p.name for p in paths] == ["flight-episode0.png"]


def test_attitude_angles_refuses_non_finite_readings() -> None:
    """T48-B06: NaN readings gave NaN angles; they are refused, naming the row, the reading and its value."""
    obs = np.zeros((3, 12))
    for value in (np.nan, np.inf, -np.inf):
        obs[2, 10] = value
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            with pytest.raises(NeurohoverError, match=rf"^observations row 2: its qy {value} is not allowed: no flight records a NaN or infinite reading"):
                attitude_angles(obs)


@pytest.mark.slow
def test_attitude_angles_of_readings_past_the_unit_ball(tmp_path: Path) -> None:
    """T48-B06: a vector part of norm sqrt(3) gave angles of no rotation (roll 146, pitch -90). A noisy sensor's
    recording gives such readings (its norm past 1, loaded by FlightData.load), so they are not refused: they are taken
    as the nearest rotation, the vector part scaled to norm 1, and the recording still plots."""
    over = np.hstack([np.zeros((1, 9)), np.ones((1, 3))])
    unit = np.hstack([np.zeros((1, 9)), np.ones((1, 3)) / np.sqrt(3)])
    np.testing.assert_allclose(attitude_angles(over), attitude_angles(unit), atol=1e-12)
    assert attitude_angles(over)[0, 1] == pytest.approx(-np.degrees(np.arcsin(2 / 3)))
    noisy = _flight(tmp_path, sensor=nh.Sensor(attitude=1.0))
    assert np.linalg.norm(noisy.observations[0][:, 9:12], axis=1).max() > 1  # readings no exact sensor gives
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert len(plot_flight_data(noisy, tmp_path / "noisy")) == 1


def test_crashed_episode_refuses_an_episode_of_no_steps() -> None:
    """T48-B05: actions of shape (0, 4) were called a crash; FlightData.load refuses such an episode."""
    with pytest.raises(NeurohoverError, match=r"^actions of shape \(0, 4\) are not an episode: it has 0 steps \(a flown one has at least 1\)"):
        crashed_episode(np.zeros((0, 4)), 10)
    assert crashed_episode(np.zeros((1, 4)), 10) and not crashed_episode(np.zeros((10, 4)), 10)


def test_the_evaluate_module_is_imported_by_its_names() -> None:
    """T48-B02: the package's ``evaluate`` is the function (README, "What is public"); the module's names import with
    ``from neurohover.evaluate import ...`` and importlib gives the module."""
    from neurohover.evaluate import PolicyTable

    module = importlib.import_module("neurohover.evaluate")
    assert module.PolicyTable is PolicyTable and callable(nh.evaluate) and module.evaluate is nh.evaluate
    import neurohover.evolution

    evolve = importlib.import_module("neurohover.evolution.evolve")  # the other module its package's function shadows
    assert evolve.__name__ == "neurohover.evolution.evolve" and neurohover.evolution.evolve is evolve.evolve
    readme = (Path(__file__).resolve().parents[1] / "README.md").read_text(encoding="utf-8")
    assert "from neurohover.evaluate import PolicyTable" in readme and "not `import neurohover.evaluate as ev`" in readme


@pytest.mark.parametrize("value", [-0.5, "2", True, None, np.array(2.0), 1j, [2], np.True_, float("nan"), 1.5])
def test_sensor_correlation_refusals_name_its_range(value) -> None:
    """T48-B08: every refusal of a correlation said "allowed a finite number >= 0" but 1.5's; its range is 0 <= correlation < 1."""
    with pytest.raises(NeurohoverError, match=r"^sensor correlation=.* allowed 0 <= correlation < 1$"):
        nh.Sensor(attitude=0.01, correlation=value)


@pytest.mark.slow
def test_overrides_with_a_key_not_text_name_a_setting_every_config_takes() -> None:
    """T48-B09: {1: 2} was told "give a dict of settings, e.g. {'episodes': 3}", a setting fig2 refuses."""
    with pytest.raises(NeurohoverError) as err:
        load_config("fig2", "quick", {1: 2})
    message = str(err.value)
    assert "keys are setting names (text), e.g. {'seed': 3} (the CLI's --set seed=3)" in message, message
    for name in shipped_configs():  # the example is a setting of every shipped config
        assert load_config(name, "quick", {"seed": 3}).settings["seed"] == 3
