"""The twenty-first bad-input trial's findings in ``neurohover plot`` (neurohover.plots): flight data no flight gives and
compete summaries that contradict their episodes are refused with one message naming the bad value, status 2 on the
command line."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest

from neurohover.compete_files import read_compete_dir
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
    said = f"flight-data file '{path}', episode 0: step 0 reads u = nan (71 more of the episode's observation readings are NaN or infinite)"
    assert f"{said}: {NOT_FLOWN}" in err, err
    assert out == "" and not list(tmp_path.glob("**/*.png"))


def test_plot_flight_data_refuses_an_infinite_observation_of_any_episode_before_writing(tmp_path: Path) -> None:
    """T21-04: one infinite reading in the second episode; nothing is drawn, the first episode's file neither."""
    clean = _flight(episodes=2)
    observations = [o.copy() for o in clean.observations]  # flight data's arrays are read-only (T45-B07): new ones made
    observations[1][2, 5] = -np.inf
    data = FlightData(tuple(observations), clean.actions, clean.metadata)
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


#: A competition as ``neurohover compete --out`` writes it: 2 runs of 2 episodes of 20 steps, one crash at step 7.
EPISODES = """run,mdp,episode,return,crashed,steps,policy,safeguard_fired
0,ghh08/test:0,0,-10.0,0,20,baseline,0
0,ghh08/test:0,1,-12.5,0,20,baseline,0
1,ghh08/test:1,0,-30.0,0,20,baseline,0
1,ghh08/test:1,1,-25000.0,1,7,baseline,0
"""
TOTALS = np.array([-22.5, -25030.0])  # the crash charged its 13 steps left (T26-B09)
SUMMARY = {
    "task": "ghh08", "agent": "baseline", "mdps": "test", "seed": 0, "store": "results.sqlite", "episode_steps": 20, "sigma": None,
    "sensor": None, "drift": None, "experiment": "compete-ghh08-baseline", "scale": "settings-4a8d2c2c96", "runs": 2, "episodes": 2,
    "mean_cumulative_return": float(TOTALS.mean()), "sd_cumulative_return": float(TOTALS.std(ddof=1)), "crash_rate_runs": 0.5,
    "crashes_per_episode": 0.25, "mean_return_after_learning": -6263.125, "mean_seconds_per_run": 0.1, "mean_offline_seconds_per_run": 0.0,
}  # fmt: skip


def _competition(folder: Path, **edits: object) -> Path:
    folder.mkdir()
    (folder / "episodes.csv").write_text(EPISODES)
    (folder / "summary.json").write_text(json.dumps(SUMMARY | edits, indent=1))
    return folder


def test_plot_refuses_a_compete_summary_whose_task_its_rows_contradict(tmp_path: Path, cli) -> None:
    """T21-07: a summary's task edited from ghh08 to ghh09 over ghh08's rows was plotted as ghh09's, without a word;
    the summary as written is plotted."""
    rc, out, err = cli("plot", "--compete", str(_competition(tmp_path / "a")), "--out", str(tmp_path / "p"))
    assert rc == 0 and out.strip().endswith("compete.png"), err
    rc, out, err = cli("plot", "--compete", str(_competition(tmp_path / "b", task="ghh09")), "--out", str(tmp_path / "q"))
    assert rc == 2 and "Traceback" not in err and out == "", err
    assert "summary.json' says task 'ghh09' where its episodes.csv holds ghh08 MDPs (line 2: mdp 'ghh08/test:0'): the two are of different" in err


@pytest.mark.parametrize(
    ("edits", "message"),
    [
        ({"agent": "model-free"}, "says agent 'model-free' where its experiment is 'compete-ghh08-baseline' (compete-TASK-AGENT)"),
        ({"experiment": "compete-ghh09-baseline"}, "says task 'ghh08' where its experiment is 'compete-ghh09-baseline'"),
        ({"mdps": "train"}, "says mdps 'train' where its episodes.csv holds test MDPs (line 2: mdp 'ghh08/test:0')"),
        ({"runs": 3}, "says runs 3 where its episodes.csv holds 2"),
        ({"episode_steps": 6000}, "says episode_steps 6000 where its episodes.csv holds an uncrashed episode of 20 steps (line 2)"),
        ({"episode_steps": 5}, "says episode_steps 5 where its episodes.csv holds an uncrashed episode of 20 steps (line 2)"),
        ({"episode_steps": "20"}, "says episode_steps '20', not a number of steps (an integer in 1..10,000,000): it is no compete summary"),
        ({"crashes_per_episode": 0.0}, "says crashes_per_episode 0.0 where its episodes.csv holds 1 crash in 4 episodes"),
        ({"crash_rate_runs": 1.0}, "says crash_rate_runs 1.0 where its episodes.csv holds 1 of 2 runs with a crash"),
        ({"mean_cumulative_return": -12526.0}, "says mean_cumulative_return -12526.0 where its episodes.csv's runs return -12526.25 in all on average"),
        ({"sd_cumulative_return": "x"}, "says sd_cumulative_return 'x' where its episodes.csv's runs' cumulative returns have an sd of 17682.97"),
    ],
)
def test_read_compete_dir_refuses_a_summary_whose_parts_contradict(tmp_path: Path, edits: dict, message: str) -> None:
    """T21-07: every field of a summary the rows or its own experiment name contradict is refused, naming both values."""
    with pytest.raises(NeurohoverError, match=re.escape(message)):
        read_compete_dir(_competition(tmp_path / "c", **edits))
