"""Trial 42, side A: an own config's mistake named by the table that holds it (T42-A01), and learn-model's refusal of
flight data read through a noisy attitude sensor naming that sensor (T42-A05)."""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import tiny_test_runs

from neurohover.errors import NeurohoverError


def _config(tmp_path, text: str, paper: bool = True):
    """``text`` (a tiny test-runs config, quick scale) with a paper scale table too."""
    path = tmp_path / "mine.toml"
    path.write_text(text + ("[scales.paper]\nepisodes = 3\nn_steps = 20\n" if paper else ""))
    return str(path)


@pytest.mark.parametrize("paper", [True, False])
def test_a_mistake_in_settings_is_named_by_settings_not_a_scale(tmp_path, paper) -> None:
    from neurohover.experiments import load_config

    base = tiny_test_runs("model-free", "baseline", name="mine")
    seeded = _config(tmp_path, base.replace("seed = 1", 'seed = "7"'), paper)
    with pytest.raises(NeurohoverError, match=r"mine\.toml', \[settings\]: seed = '7' is not allowed: expected an integer in 0\.\.2\*\*63-1$"):
        load_config(seeded, "quick")
    groups = _config(tmp_path, base.replace("n_mdps = 1", "n_mdps = 0", 1), paper)
    with pytest.raises(NeurohoverError, match=r"mine\.toml', \[settings\], groups\[0\]: n_mdps = 0 is not allowed: expected an integer >= 1$"):
        load_config(groups, "quick")
    unknown = _config(tmp_path, base.replace("seed = 1", "seed = 1\nsed = 2"), paper)
    with pytest.raises(NeurohoverError, match=r"mine\.toml', \[settings\]: unknown setting\(s\) 'sed'; allowed: "):
        load_config(unknown, "quick")


def test_a_mistake_of_one_scale_names_that_scale_and_the_run_scale_comes_first(tmp_path) -> None:
    from neurohover.experiments import load_config

    base = tiny_test_runs("model-free", name="mine")
    in_paper = _config(tmp_path, base + "[scales.paper]\nepisodes = 2.0\nn_steps = 20\n", paper=False)
    with pytest.raises(NeurohoverError, match=r"mine\.toml' at scale 'paper': episodes = 2\.0 is not allowed"):
        load_config(in_paper, "quick")
    # [settings]' bad seed only reaches the paper scale (the quick one gives its own): still named where it is written
    overridden = _config(tmp_path, base.replace("seed = 1", 'seed = "7"').replace("episodes = 2\n", "episodes = 2\nseed = 1\n"))
    with pytest.raises(NeurohoverError, match=r"mine\.toml', \[settings\]: seed = '7' is not allowed"):
        load_config(overridden, "quick")
    # ... and a bad [settings] value that every scale table replaces is used nowhere, accepted as before
    everywhere = _config(tmp_path, Path(overridden).read_text().replace("[scales.paper]\n", "[scales.paper]\nseed = 2\n"), paper=False)
    assert load_config(everywhere, "paper").settings["seed"] == 2
    # a bad seed in every scale table, none in [settings]: named by the scale run
    both = _config(tmp_path, base.replace("seed = 1\n", "").replace("episodes = 2\n", 'episodes = 2\nseed = "7"\n'), paper=False)
    Path(both).write_text(Path(both).read_text() + '[scales.paper]\nepisodes = 3\nn_steps = 20\nseed = "7"\n')
    for scale in ("quick", "paper"):
        with pytest.raises(NeurohoverError, match=rf"mine\.toml' at scale '{scale}': seed = '7' is not allowed"):
            load_config(both, scale)
    # a check across settings (sigma on a GHH task) needs the merged table: it names the scale run
    sigma = _config(tmp_path, base.replace("seed = 1", "seed = 1\nsigma = 0.1"))
    with pytest.raises(NeurohoverError, match=r"mine\.toml' at scale 'quick': sigma applies to task 'fghh' only, not 'ghh08'"):
        load_config(sigma, "quick")
    # --set on the run's scale replaces a bad [settings] value that no other scale uses
    only_quick = _config(tmp_path, base.replace("seed = 1", 'seed = "7"'), paper=False)
    assert load_config(only_quick, "quick", {"seed": 7}).settings["seed"] == 7


def test_flight_data_through_a_noisy_attitude_sensor_is_refused_naming_that_sensor(tmp_path, cli, monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)
    # seed 0: attitude noise 0.4 reads a quaternion vector part of length 1.16 before the baseline crashes (about 95 steps)
    rc, _, err = cli("fly", "--task", "ghh08", "--episodes", "1", "--obs-noise", "attitude=0.4", "--record", "f.npz")
    assert rc == 0, err
    for method in ("lr", "ec-mer"):
        rc, _, err = cli("learn-model", "--flight-data", "f.npz", "--method", method, "--out", "m.json")
        assert rc == 2 and not (tmp_path / "m.json").exists()
        assert (
            "flight data: quaternion vector parts (qx, qy, qz) longer than 1 (max 1.16494 in episode 0), read through the attitude sensor "
            "noise 0.4 its metadata records for that episode: a model is fitted from unit quaternions (qw = sqrt(1 - |q vector|^2)), so "
            "record the flight with less attitude noise (e.g. --obs-noise attitude=0.05) or exact sensors" in err
        ), err


def test_flight_data_longer_than_a_unit_quaternion_without_recorded_attitude_noise_is_refused_as_before() -> None:
    import neurohover as nh
    from neurohover.models import learn_lr

    flights = nh.evaluate(nh.baseline_policy(), nh.get_task_family("ghh08").zero(), episodes=1, record=True, n_steps=40).flight_data
    obs = flights.observations[0].copy()
    obs[5, 9:12] = 0.7
    meta = {k: v for k, v in flights.metadata.items() if k != "mdps"}  # as recorded before T59-B04: else the tilt is refused as no flight's
    edited = nh.FlightData([obs], list(flights.actions), meta)
    with pytest.raises(
        NeurohoverError, match=r"^flight data: quaternion vector parts \(qx, qy, qz\) longer than 1 \(max 1\.21244\); not helicopter observations$"
    ):
        learn_lr(edited)
