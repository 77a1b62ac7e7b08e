"""evaluate.KernelFlyer, the evolution's route to the kernel: the same episodes as evaluate_jobs."""

from __future__ import annotations

import numpy as np
import pytest

from neurohover import NeurohoverError, get_task_family, prototype
from neurohover.evaluate import KernelFlyer, PolicyTable, evaluate_jobs, num_threads


def test_the_flyer_flies_what_evaluate_jobs_flies_with_consecutive_episode_indices() -> None:
    rows = get_task_family("fghh", 0.3).sample_rows(np.random.default_rng(1), 5)
    genomes = np.stack([prototype("slp", "baseline").genome * (1 + 0.05 * i) for i in range(3)])
    flyer = KernelFlyer("slp", 123, 150)
    flyer.trace = []
    with num_threads(None):
        flyer.start()
        first = flyer.fly(genomes, rows, "range", None, 3).copy()  # genome j on MDP 0
        second = flyer.fly(genomes, rows, np.array([0, 1, 2, 0, 1]), "range", 5).copy()
        one = flyer.fly(genomes[2:], rows, None, None, 1).copy()
    ev = evaluate_jobs(
        PolicyTable.from_genomes(genomes, "slp"), rows, [0, 1, 2, 0, 1, 2, 0, 1, 2], [0, 0, 0, 0, 1, 2, 3, 4, 0], np.arange(9), seed=123, n_steps=150
    )
    np.testing.assert_array_equal(np.concatenate([first, second, one]), ev.returns)
    assert (flyer.episodes, flyer.steps) == (9, int(ev.steps.sum()))
    assert np.array_equal(flyer.crashed, ev.crashed[-1:])
    assert [t[4].tolist() for t in flyer.trace] == [[0, 1, 2], [3, 4, 5, 6, 7], [8]]


@pytest.mark.parametrize(
    "args,words",
    [
        (("tlp", 0, 10), "unknown policy topology"),
        (("mlp", -1, 10), "seed=-1 is out of range"),
        (("mlp", 0, 0), "n_steps=0 is out of range"),
    ],
)
def test_bad_flyer_arguments_are_clear_errors(args, words) -> None:
    with pytest.raises(NeurohoverError, match=words):
        KernelFlyer(*args)
