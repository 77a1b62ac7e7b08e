"""Trial 59, side B (Python API, files): a sensor dropout too small to lose a reading (T59-B01: Sensor(dropout=1e-320),
5e-324, 1e-300 and 1e-17 were taken, dropped nothing, yet drew a 13th normal each step and so changed every return;
the stds, Drift(walk=), FGHH sigma and CrashAwareReward(scale=) refuse values below 2**-52), and flight data recorded by
evaluate(record=True), whose metadata held no ``mdps`` (T59-B04: their crashed flag edited to True while the episode
ends calm loaded and changed observed_return; the same edit of a ``fly --record`` file is refused)."""

from __future__ import annotations

import json
import re
from dataclasses import dataclass, replace

import numpy as np
import pytest

import neurohover as nh
from neurohover import Sensor
from neurohover.errors import NeurohoverError, brief
from neurohover.flightdata import FlightData
from neurohover.sim.constants import DEFAULT_PARAMS, ROW_PARAMS
from neurohover.tasks import MDP, TASK_FAMILIES, TaskFamily

TOO_SMALL = (
    r"sensor dropout={} is out of range, too small to lose a reading in practice \(below 2\*\*-52\): "
    r"allowed 0 \(none\) or a probability 2\.23e-16 <= dropout < 1$"
)
CALM_CRASH = r"crashed=\[True\] is not allowed: episode 0 is flagged crashed, yet after its last step \(300\) it flies within every crash bound"


@pytest.mark.parametrize("dropout", [1e-320, 5e-324, 1e-300, 1e-17, 2.2e-16, np.float32(1e-20)])
def test_a_dropout_too_small_to_lose_a_reading_is_refused(dropout) -> None:
    """T59-B01: it was taken, lost no reading, and shifted the sensor noise of every later step."""
    with pytest.raises(NeurohoverError, match="^" + TOO_SMALL.format(re.escape(brief(dropout)))):
        Sensor(velocity=0.1, dropout=dropout)


def test_every_path_to_a_sensor_refuses_it_and_the_bounds_stay_allowed() -> None:
    """T59-B01: the check is Sensor's own, so text, tables, MDP rows and replace() meet it; 0 and 2**-52 stay allowed."""
    for make in (
        lambda: Sensor.parse("velocity=0.1,dropout=1e-320"),
        lambda: Sensor.of({"level": 1, "dropout": 1e-17}),
        lambda: Sensor.from_row_values((0.1, 0, 0, 0, 0, 0, 1e-300)),
        lambda: replace(Sensor(velocity=0.1), dropout=5e-324),
    ):
        with pytest.raises(NeurohoverError, match="too small to lose a reading"):
            make()
    row = nh.get_task_family("ghh08").zero().with_sensor(Sensor(velocity=0.1)).row()
    row[-1] = 1e-320  # the sensor's dropout slot (sim.constants.ROW_SENSOR)
    with pytest.raises(NeurohoverError, match=r"^MDP row 0 has an invalid sensor model .*too small to lose a reading"):
        nh.evaluate(nh.baseline_policy(), row[None, :], n_steps=5)
    assert Sensor(dropout=0).dropout == 0.0 and Sensor(dropout=2.0**-52).dropout == 2.0**-52


def test_the_command_line_refuses_it_alike(cli) -> None:
    """T59-B01: ``--obs-noise velocity=0.1,dropout=1e-320`` exited 0 with another mean than velocity=0.1 alone."""
    rc, out, err = cli("fly", "--task", "ghh08", "--obs-noise", "velocity=0.1,dropout=1e-320", "--episodes", "1", "--json")
    assert rc == 2 and not out and re.search(TOO_SMALL.format("1e-320"), err.strip()) and len(err.strip().splitlines()) == 1, err


def _edited(path, tmp_path, **changes) -> str:
    """A copy of the flight-data file ``path`` with its metadata entries changed (None: removed), as a user edits one."""
    members = dict(np.load(path))
    meta = json.loads(str(members["metadata"]))
    meta = {k: v for k, v in (meta | changes).items() if v is not None}
    members["metadata"] = np.array(json.dumps(meta))
    out = tmp_path / f"edited{len(list(tmp_path.iterdir()))}.npz"
    np.savez(out, **members)
    return str(out)


def test_a_calm_episode_flagged_crashed_is_refused_in_evaluate_recordings(tmp_path) -> None:
    """T59-B04: the edited flag loaded (observed_return changed), as the same edit of fly --record's file did not: the
    check needs each episode's MDP (are the readings the true state?), which evaluate(record=True) did not record. A file
    without mdps (written before) still loads: its readings may be a sensor's."""
    mdp = nh.get_task_family("ghh08").test_mdps()[0]
    fd = nh.evaluate(nh.baseline_policy(), mdp, record=True, seed=2, n_steps=300).flight_data
    assert fd.metadata["crashed"] == [False]
    path = tmp_path / "fd.npz"
    fd.save(path)
    with pytest.raises(NeurohoverError, match=CALM_CRASH):
        FlightData.load(_edited(path, tmp_path, crashed=[True]))
    fd.metadata["crashed"] = [True]  # edited in memory: every reader checks again
    with pytest.raises(NeurohoverError, match=CALM_CRASH):
        fd.check_again()
    older = FlightData.load(_edited(path, tmp_path, crashed=[True], mdps=None))
    assert "mdps" not in older.metadata and older.metadata["crashed"] == [True]


@dataclass(frozen=True)
class Heavier(TaskFamily):
    """A family registered at run time: D_w scaled by a factor in [0.5, 1]."""

    name = "t59heavier"
    n_params = 11
    param_names = ("C_u", "C_v", "D_v", "C_w", "D_w", "C_p", "D_p", "C_q", "D_q", "C_r", "D_r")
    row_slice = ROW_PARAMS
    set_code = 97

    def make(self, params, label=""):
        return MDP("t59heavier", params=tuple(float(p) for p in params), label=label)

    def zero(self):
        return MDP("t59heavier", label="t59heavier/zero")

    def sample_params(self, rng, n):
        out = np.repeat(DEFAULT_PARAMS[None, :], n, axis=0)
        out[:, 4] *= rng.uniform(0.5, 1.0, n)
        return out


def test_evaluate_records_each_episodes_mdp_in_job_order(monkeypatch) -> None:
    """T59-B04: one table per episode, as fly --record writes them (policies, then MDPs, then episodes); none for MDP rows
    (no family, no label) and none where a family registered at run time flew (unreadable where it is not registered)."""
    fam = nh.get_task_family("ghh09")
    mdps = [fam.test_mdps()[3], fam.zero().with_sensor(Sensor(velocity=0.2, dropout=0.1))]
    ev = nh.evaluate([nh.baseline_policy()] * 2, mdps, episodes=2, record=True, n_steps=20)
    assert ev.flight_data.metadata["mdps"] == [m.to_dict() for _ in range(2) for m in mdps for _ in range(2)]
    rows = nh.evaluate(nh.baseline_policy(), np.stack([m.row() for m in mdps]), record=True, n_steps=20).flight_data
    assert "mdps" not in rows.metadata
    monkeypatch.setitem(TASK_FAMILIES, Heavier.name, Heavier)
    mine = nh.evaluate(nh.baseline_policy(), nh.get_task_family(Heavier.name).zero(), record=True, n_steps=20).flight_data
    assert "mdps" not in mine.metadata
