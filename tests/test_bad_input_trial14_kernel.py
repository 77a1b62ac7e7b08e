"""Fourteenth session: the kernel's output and parking arguments, which the thirteenth trial's checks of a Batch did not
reach. A Flown shorter than the batch was written past its end (the process aborted: 'free(): invalid next size'); a
parking slot outside the Parking, a wrong-sized parked state, a short safeguard limits array and recording buffers of
another dtype are refused with a NeurohoverError before the kernel runs."""

from __future__ import annotations

import numpy as np
import pytest

from neurohover import get_task_family, launch
from neurohover.errors import NeurohoverError
from neurohover.evaluate import mdp_rows
from neurohover.policies import baseline_policy
from neurohover.sim.kernel import GENOME_WIDTH

ROWS = mdp_rows([get_task_family("ghh08").zero()])


def batch(n_jobs: int = 3, **changed) -> launch.Batch:
    genomes = np.zeros((1, GENOME_WIDTH))
    genomes[0, : baseline_policy().genome.shape[0]] = baseline_policy().genome
    zeros = np.zeros(n_jobs, dtype=np.int64)
    given = dict(
        rows=ROWS, kinds=np.zeros(1, dtype=np.int64), genomes=genomes, policy_index=zeros, mdp_index=zeros, episode_index=np.arange(n_jobs), seed=0, n_steps=20
    )
    return launch.Batch(**{**given, **changed})


@pytest.mark.parametrize(
    ("out", "message"),
    [
        (launch.Flown.empty(0), r"Flown.returns=a 1-d float64 array of shape \(0,\) is not allowed: give a writeable 1-d float64 array of at least 3 entries"),
        (launch.Flown.empty(2), r"Flown.returns=.* of shape \(2,\) .* at least 3 entries"),
        (
            launch.Flown(np.zeros(3), np.zeros(3, dtype=np.int64), np.zeros(3, dtype=np.int64), np.zeros(3, dtype=np.int64)),
            "Flown.crashed=.* give a writeable 1-d bool array",
        ),
        (launch.Flown(np.zeros(3), np.zeros(3, dtype=bool), np.zeros(3), np.zeros(3, dtype=np.int64)), "Flown.steps=.* give a writeable 1-d int64 array"),
        (launch.Flown(np.zeros(3), np.zeros(3, dtype=bool), np.zeros(3, dtype=np.int64), [0, 0, 0]), r"Flown.safeguard_step=\[0, 0, 0\] is not allowed"),
        ((np.zeros(3),) * 4, r"out=\(array.* is not allowed: give a Flown of four 1-d arrays"),
    ],
)
def test_launch_refuses_an_out_that_cannot_hold_the_batch(out, message: str) -> None:
    with pytest.raises(NeurohoverError, match=message):
        launch.launch(batch(), out)


def test_launch_refuses_a_read_only_out_and_still_flies_a_good_one() -> None:
    out = launch.Flown.empty(3)
    out.returns.flags.writeable = False
    with pytest.raises(NeurohoverError, match="Flown.returns=a read-only 1-d float64 array"):
        launch.launch(batch(), out)
    good = launch.Flown.empty(4)  # longer than the batch is allowed: the flyers keep one buffer for many calls
    launch.launch(batch(), good)
    assert (good.steps[:3] == 20).all() and np.isfinite(good.returns[:3]).all()


@pytest.mark.parametrize(
    ("slots", "n_required", "parking", "message"),
    [
        (np.array([0, 1, 5]), 3, launch.Parking.empty(3), "slots holds 5, out of range: allowed 0..2"),
        (np.array([0, -1, 2]), 3, launch.Parking.empty(3), r"slots holds negative values \(min -1\); allowed >= 0"),
        (np.array([0, 1]), 3, launch.Parking.empty(3), r"slots=.* give a 1-d int64 numpy array, one parking slot per job \(3\)"),
        (np.array([0, 1, 2]), 4, launch.Parking.empty(3), r"n_required=4 is out of range: allowed an integer in 0..3"),
        (np.array([0, 1, 2]), True, launch.Parking.empty(3), r"n_required=True is not allowed"),
        (
            np.array([0, 1, 2]),
            3,
            launch.Parking(np.zeros((3, 2)), launch.Parking.empty(3).streams, np.zeros(3, dtype=np.int64)),
            r"Parking.floats=a float64 array of shape \(3, 2\)",
        ),
        (np.array([0, 1, 2]), 3, launch.Parking.empty(3).floats, r"parking=.* give a Parking"),
    ],
)
def test_launch_parked_refuses_slots_outside_the_parking(slots, n_required, parking, message: str) -> None:
    with pytest.raises(NeurohoverError, match=message):
        launch.launch_parked(batch(), launch.Flown.empty(3), slots, n_required, parking)


def test_batch_refuses_short_safeguard_limits_and_recording_buffers_of_another_dtype() -> None:
    fallback = np.zeros(3, dtype=np.int64)
    with pytest.raises(NeurohoverError, match=r"Batch.limits of shape \(2,\) is not allowed: give \d+ limits"):
        batch(fallback=fallback, limits=np.ones(2))
    slots = np.array([0, -1, -1])
    with pytest.raises(NeurohoverError, match="Batch.obs_out=a 3-d float32 array .* give a 3-d float64 numpy array"):
        batch(slots=slots, obs_out=np.zeros((1, 21, 12), dtype=np.float32), act_out=np.zeros((1, 20, 4)))
