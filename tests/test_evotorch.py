"""EvoTorch over the batched kernel (skipped where EvoTorch is not installed)."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("evotorch", reason="evotorch is not installed (pip install evotorch)")

import neurohover as nh  # noqa: E402
from neurohover.evaluate import PolicyTable, evaluate_jobs  # noqa: E402
from neurohover.integrations.evotorch import HoverProblem  # noqa: E402


def test_a_population_flies_in_one_call_with_fresh_episodes_each_evaluation() -> None:
    problem = HoverProblem("ghh08", mdps="train:3", topology="slp", episodes=2, n_steps=200, seed=4)
    batch = problem.generate_batch(5)
    problem.evaluate(batch)
    genomes = batch.values.detach().numpy()
    mdp = nh.get_task_family("ghh08").mdp("train:3")
    jobs = np.arange(10)
    ev = evaluate_jobs(PolicyTable.from_genomes(genomes, "slp"), mdp, jobs // 2, np.zeros(10, dtype=np.int64), jobs, seed=4, n_steps=200)
    np.testing.assert_allclose(batch.evals.detach().numpy().ravel(), ev.returns.reshape(5, 2).mean(axis=1), rtol=1e-12)
    again = problem.generate_batch(5)
    again.set_values(batch.values.clone())
    problem.evaluate(again)  # the same genomes meet the next episodes' gusts
    assert not np.array_equal(again.evals.detach().numpy(), batch.evals.detach().numpy())


def test_snes_from_the_baseline_improves_over_the_family() -> None:
    from evotorch.algorithms import SNES

    problem = HoverProblem("fghh", sigma=0.3, mdps="sample", topology="slp", episodes=1, n_steps=300, seed=1)
    searcher = SNES(problem, stdev_init=0.005, center_init=problem.baseline_center(), popsize=16)
    searcher.run(5)
    assert problem.steps_flown > 0 and np.isfinite(float(searcher.status["best"].evals[0]))


def test_bad_settings_are_refused() -> None:
    with pytest.raises(nh.NeurohoverError, match="topology='rnn' is not allowed"):
        HoverProblem(topology="rnn")
    with pytest.raises(nh.NeurohoverError, match="MDP index 99 in .train:99. is out of range"):
        HoverProblem(mdps="train:99")
