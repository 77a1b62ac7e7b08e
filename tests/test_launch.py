"""neurohover.launch: the one kernel launch (Batch in, Flown out) and its choice of path."""

from __future__ import annotations

import numpy as np
import pytest

from neurohover import baseline_policy, get_task_family
from neurohover.evaluate import PolicyTable
from neurohover.launch import Batch, Flown, launch, use_lanes
from neurohover.sim.lanes import LANES
from neurohover.tasks import Sensor

TABLE = PolicyTable.from_policies([baseline_policy()])


def batch(n: int, rows: np.ndarray, **kw) -> Batch:
    idx = np.arange(n, dtype=np.int64)
    return Batch(rows, TABLE.kinds, TABLE.genomes, np.zeros(n, dtype=np.int64), idx % rows.shape[0], idx, 7, 300, **kw)


def test_batch_is_checked_by_shape_and_dtype() -> None:
    rows = get_task_family("ghh08").mdp("train:0").row()[None, :]
    with pytest.raises(ValueError, match="Batch.rows"):
        batch(2, rows[:, :29])
    with pytest.raises(ValueError, match="Batch.episode_index has shape"):
        Batch(rows, TABLE.kinds, TABLE.genomes, np.zeros(2, dtype=np.int64), np.zeros(2, dtype=np.int64), np.zeros(3, dtype=np.int64), 0, 10)
    with pytest.raises(ValueError, match="Batch.policy_index"):
        Batch(rows, TABLE.kinds, TABLE.genomes, np.zeros(2), np.zeros(2, dtype=np.int64), np.zeros(2, dtype=np.int64), 0, 10)
    with pytest.raises(ValueError, match="obs_out"):
        batch(1, rows, slots=np.zeros(1, dtype=np.int64))


def test_batch_says_whether_any_job_has_a_safeguard_or_records() -> None:
    rows = get_task_family("ghh08").mdp("train:0").row()[None, :]
    minus = np.full(3, -1, dtype=np.int64)
    assert not batch(3, rows).safeguard and not batch(3, rows, fallback=minus, slots=minus).recording
    assert batch(3, rows, fallback=np.array([-1, 0, -1])).safeguard


@pytest.mark.parametrize("sensor", [None, Sensor.at_level(1.0, correlation=0.5, delay=1)])
def test_every_path_of_one_launch_gives_the_same_bits(sensor) -> None:
    family = get_task_family("fghh", sensor=sensor)
    rows = family.sample_rows(np.random.default_rng(1), 4)
    n = 2 * LANES + 3
    plain = batch(n, rows)
    assert use_lanes("cpu", rows, plain.mdp_index)
    lanes, scalar = Flown.empty(n), Flown.empty(n)
    launch(plain, lanes)
    # The safeguard flag with every fallback -1 (no job hands over) forces the scalar kernel on the same jobs.
    launch(batch(n, rows, fallback=np.full(n, -1, dtype=np.int64), safeguard=True), scalar)
    for a, b in zip((lanes.returns, lanes.crashed, lanes.steps), (scalar.returns, scalar.crashed, scalar.steps)):
        assert np.array_equal(a, b)
    assert (lanes.safeguard_step == -1).all() and (scalar.safeguard_step == -1).all()


def test_an_empty_batch_launches() -> None:
    out = Flown.empty(0)
    assert launch(Batch.empty(), out) >= 0.0 and out.returns.shape == (0,)
