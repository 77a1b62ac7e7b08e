"""Uncertainty-handling CMA-ES (pycma's NoiseHandler) as an ask/tell optimiser, and through the registry."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import neurohover as nh
from neurohover.evolution.evolve import EvolutionInterrupted, evolve
from neurohover.evolution.optimisers import OPTIMISERS
from neurohover.evolution.optimisers.uh_cma import UHCMAES, UHCMASettings

GHH08 = nh.get_task_family("ghh08")


def sphere_run(noise: float, generations: int, seed: int = 3) -> tuple[UHCMAES, list[int]]:
    """Maximise -|x|^2 plus Gaussian noise of sd ``noise``; the sizes of the batches asked."""
    rng = np.random.default_rng(0)
    opt = UHCMAES(np.ones(6), UHCMASettings(sigma0=0.3, max_evaluations=8), seed=seed)
    sizes = []
    for _ in range(2 * generations):  # a generation and its re-evaluations
        x = opt.ask()
        sizes.append(len(x))
        opt.tell(-np.sum(x**2, axis=1) + rng.normal(0.0, noise, len(x)))
    return opt, sizes


def test_noise_raises_the_evaluations_and_a_clean_objective_keeps_one() -> None:
    clean, sizes = sphere_run(0.0, 30)
    assert clean.evaluations_per_solution == 1 and clean.noise_measure <= 0
    assert sizes[0] == clean.popsize and 1 <= sizes[1] < clean.popsize  # the generation, then a few re-evaluated solutions
    assert np.linalg.norm(clean.mean) < 0.5 * np.linalg.norm(np.ones(6))  # it still climbs
    noisy, sizes = sphere_run(50.0, 30)  # ranks are all noise at this scale
    assert noisy.evaluations_per_solution > 1 and noisy.noise_measure > 0
    assert max(sizes) > noisy.popsize  # each solution flown several times
    assert noisy._tracker.evaluations == sum(sizes)  # the budget counts every row, re-evaluations included


def test_runs_are_reproducible_and_leave_numpys_global_generator_alone() -> None:
    np.random.seed(123)
    before = np.random.get_state()[1].copy()
    a, _ = sphere_run(5.0, 10)
    assert np.array_equal(np.random.get_state()[1], before)
    b, _ = sphere_run(5.0, 10)
    np.testing.assert_array_equal(a.mean, b.mean)
    assert a.sigma == b.sigma and a.champion_return == b.champion_return


def test_state_dict_between_the_two_rounds_continues_bit_for_bit() -> None:
    rng = np.random.default_rng(1)
    opt = UHCMAES(np.ones(4), UHCMASettings(sigma0=0.3), seed=2)
    x = opt.ask()
    opt.tell(-np.sum(x**2, axis=1) + rng.normal(0, 1, len(x)))  # a generation told: its re-evaluations wait
    copy = UHCMAES.from_state_dict(opt.state_dict())
    for o in (opt, copy):
        r = np.random.default_rng(9)
        for _ in range(5):
            y = o.ask()
            o.tell(-np.sum(y**2, axis=1) + r.normal(0, 1, len(y)))
    np.testing.assert_array_equal(opt.mean, copy.mean)
    assert opt.sigma == copy.sigma


@pytest.mark.parametrize(
    ("settings", "message"),
    [
        ({"max_evaluations": 0}, "min_evaluations=1 and max_evaluations=0 must be integers with 1 <= min <= max"),
        ({"min_evaluations": 3, "max_evaluations": 2}, "1 <= min <= max"),
        ({"epsilon": -1.0}, "epsilon=-1.0 must be a finite number >= 0"),
        ({"reevaluations": 0}, "reevaluations=0 must be None or an integer >= 1"),
    ],
)
def test_bad_settings_are_refused_naming_the_value(settings: dict, message: str) -> None:
    with pytest.raises(nh.NeurohoverError, match=message):
        evolve(GHH08.mdp("train:0"), optimizer="uh-cma", settings=settings, budget=10)


def test_its_settings_extend_cma_es_but_are_not_taken_for_them() -> None:
    with pytest.raises(ValueError, match="CMA-ES sigma0=0.0 must be a finite number >= 1e-100"):  # CMA-ES's own check
        UHCMASettings(sigma0=0.0)
    with pytest.raises(nh.NeurohoverError, match="settings for optimizer 'cma' must be a CMASettings"):
        evolve(GHH08.mdp("train:0"), optimizer="cma", settings=UHCMASettings(), budget=10)


@pytest.mark.slow
def test_evolve_runs_it_and_resumes_bit_for_bit(tmp_path: Path) -> None:
    assert OPTIMISERS["uh-cma"].stops_itself
    common = dict(topology="slp", optimizer="uh-cma", seed=4, n_steps=200, settings={"max_evaluations": 4})
    full = evolve(GHH08.mdp("train:1"), budget=300, **common)
    assert full.stop_reason == "budget" and full.champion.metadata["method"] == "uh-cma-es"
    ckpt = tmp_path / "run.checkpoint.json"

    def stop_midway(info) -> None:
        if info.episodes >= 120 and not info.done:
            raise KeyboardInterrupt

    with pytest.raises(EvolutionInterrupted):
        evolve(GHH08.mdp("train:1"), budget=300, checkpoint=ckpt, progress=stop_midway, progress_every_s=0, **common)
    resumed = evolve(GHH08.mdp("train:1"), budget=300, checkpoint=ckpt, resume=True, **common)
    np.testing.assert_array_equal(resumed.champion.genome, full.champion.genome)
    assert resumed.champion_return == full.champion_return and resumed.episodes == full.episodes
