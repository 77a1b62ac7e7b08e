"""The experimental per-gene mutation scale (SteadyStateSettings.mutation_floor)."""

from __future__ import annotations

import numpy as np
import pytest

from neurohover.errors import NeurohoverError
from neurohover.evolution import SteadyStateNE, SteadyStateSettings, evolve
from neurohover.evolution.operators import mutate
from neurohover.policies import prototype
from neurohover.tasks import get_task_family


def test_scale_multiplies_each_genes_perturbation_from_the_same_draws() -> None:
    s = SteadyStateSettings(mutate_frac=0.5)
    scale = np.linspace(0.01, 2.0, 42)
    zeros = np.zeros(42)  # shifted or replaced, a zero gene becomes its delta
    plain = mutate(zeros, np.random.default_rng(3), s)
    scaled = mutate(zeros, np.random.default_rng(3), s, scale)
    assert (plain != 0).sum() > 5
    np.testing.assert_allclose(scaled, plain * scale)
    np.testing.assert_array_equal(mutate(zeros, np.random.default_rng(3), s, np.ones(42)), plain)


def test_without_a_floor_the_optimiser_is_unchanged_and_with_one_it_scales_by_the_prototype() -> None:
    proto = prototype("mlp", "baseline").genome
    base = SteadyStateNE(proto, SteadyStateSettings(), seed=5).ask()
    again = SteadyStateNE(proto, SteadyStateSettings(mutation_floor=None), seed=5).ask()
    np.testing.assert_array_equal(base, again)
    # From an all-zero prototype every mutated gene is its delta, so the floor scales the whole batch.
    zero = np.zeros(42)
    plain = SteadyStateNE(zero, SteadyStateSettings(), seed=5).ask()
    scaled = SteadyStateNE(zero, SteadyStateSettings(mutation_floor=0.3), seed=5).ask()
    assert (plain != 0).sum() > 100
    np.testing.assert_allclose(scaled, plain * 0.3, atol=1e-15)
    # From the baseline seed, genes of size 0.02 move by about their own size, not by 0.8.
    moves = np.abs(SteadyStateNE(proto, SteadyStateSettings(mutation_floor=0.02), seed=5).ask() - proto)
    small = np.abs(proto) < 0.05
    assert moves[:, small].max() < 0.5 < np.abs(base - proto)[:, small].max()


def test_the_floor_survives_a_checkpoint() -> None:
    proto = prototype("mlp", "baseline").genome
    opt = SteadyStateNE(proto, SteadyStateSettings(mutation_floor=0.05), seed=2)
    opt.tell(-np.arange(len(opt.ask()), dtype=float) - 100)
    resumed = SteadyStateNE.from_state_dict(opt.state_dict())
    np.testing.assert_array_equal(opt.ask(), resumed.ask())


def test_evolve_takes_the_floor_as_a_setting() -> None:
    mdp = get_task_family("ghh08").training_mdps()[3]
    a = evolve(mdp, topology="mlp", prototype="baseline", budget=120, seed=1, n_steps=200, threads=1, settings={"mutation_floor": 0.02})
    b = evolve(mdp, topology="mlp", prototype="baseline", budget=120, seed=1, n_steps=200, threads=1)
    assert a.settings["settings"]["mutation_floor"] == 0.02
    assert not np.array_equal(a.champion.genome, b.champion.genome)


@pytest.mark.parametrize("floor", [0, -0.1, float("nan"), float("inf"), True, "0.02"])
def test_bad_floors_are_refused(floor) -> None:
    with pytest.raises(NeurohoverError, match="mutation_floor="):
        SteadyStateSettings(mutation_floor=floor)
