"""The twenty-first bad-input trial's findings in ``neurohover plot`` (neurohover.plots): flight data no flight gives and
compete summaries that contradict their episodes are refused with one message naming the bad value, status 2 on the
command line."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from neurohover.errors import NeurohoverError
from neurohover.flightdata import FlightData
from neurohover.plots import flight_figure, plot_flight_data

NOT_FLOWN = "no flight records a NaN or infinite observation, a crash's last one included; give flight data as flown"


def _flight(steps: int = 5, episodes: int = 1) -> FlightData:
    """Small flight data of full (uncrashed) episodes of ``steps`` steps."""
    obs = tuple(np.full((steps + 1, 12), 0.01) for _ in range(episodes))
    act = tuple(np.zeros((steps, 4)) for _ in range(episodes))
    return FlightData(obs, act, {"episode_steps": steps, "crashed": [False] * episodes})


def test_plot_refuses_a_flight_data_file_of_nan_observations_as_learn_model_does(tmp_path: Path, cli) -> None:
    """T21-04: a recording whose observations were all set to NaN (loaded, changed and saved back with numpy) drew empty
    panels and exited 0, while learn-model refused the same file."""
    path = _flight(episodes=2).save(tmp_path / "f.npz")
    arrays = dict(np.load(path))
    arrays["observations"][:] = np.nan
    np.savez(path, **arrays)
    rc, out, err = cli("plot", str(path), "--out", str(tmp_path / "plots"))
    assert rc == 2 and "Traceback" not in err, err
    assert f"flight data, episode 0: step 0 reads u = nan (71 more of the episode's observation readings are NaN or infinite): {NOT_FLOWN}" in err, err
    assert out == "" and not list(tmp_path.glob("**/*.png"))


def test_plot_flight_data_refuses_an_infinite_observation_of_any_episode_before_writing(tmp_path: Path) -> None:
    """T21-04: one infinite reading in the second episode; nothing is drawn, the first episode's file neither."""
    data = _flight(episodes=2)
    data.observations[1][2, 5] = -np.inf
    with pytest.raises(NeurohoverError, match=re.escape(f"flight data, episode 1: step 2 reads z = -inf: {NOT_FLOWN}")):
        plot_flight_data(data, tmp_path / "plots")
    assert not (tmp_path / "plots").exists()


def test_flight_figure_refuses_a_nan_action_but_a_crashed_episodes_last(tmp_path: Path) -> None:
    """T21-04: a NaN action mid-episode is no flight; a crash's last action may be NaN (the kernel records the policy's
    NaN action and crashes there) and its last observation out of bounds: that episode is drawn."""
    obs, act = np.full((6, 12), 0.01), np.zeros((5, 4))
    act[1, 3] = np.nan
    with pytest.raises(
        NeurohoverError, match=re.escape("flight_figure: step 1 reads collective = nan: no flight records a NaN or infinite action, but as a crashed")
    ):
        flight_figure(obs, act, crashed=False)
    act[1, 3], act[-1, :] = 0.0, np.nan
    obs[-1, 3] = 100.0  # 100 m off the spot: a crash's last observation
    with pytest.raises(NeurohoverError, match="step 4 reads aileron = nan"):
        flight_figure(obs, act, crashed=False)
    assert flight_figure(obs, act, crashed=True) is not None
