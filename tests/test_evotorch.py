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


def test_the_snes_example_runs_and_is_reproducible() -> None:
    import subprocess
    import sys
    from pathlib import Path

    script = Path(__file__).resolve().parents[1] / "examples" / "evotorch_snes.py"
    runs = []
    for _ in range(2):
        cmd = [sys.executable, str(script), "--generations", "3", "--popsize", "8", "--n-steps", "200"]
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
        assert proc.returncode == 0, proc.stderr[-2000:]
        runs.append({line.split()[0]: float(line.split("mean return")[1].split()[0]) for line in proc.stdout.splitlines() if "mean return" in line})
    assert set(runs[0]) == {"baseline", "SNES"} and all(np.isfinite(list(runs[0].values())))
    assert runs[0] == runs[1]  # the seed fixes SNES's samples and the gusts
