"""The genetic operators of neuroevolution (neurohover.evolution.operators): mutation, crossover, roulette weights."""

from __future__ import annotations

import math

import numpy as np
import pytest

from neurohover.evolution import (
    SteadyStateSettings,
    crossover,
    mutate,
    roulette_weights,
)

# --------------------------------------------------------------------------- operators


def test_mutation_statistics() -> None:
    s = SteadyStateSettings()  # frac 0.1, std 0.8, repl 0.25
    g = np.full(400_000, 100.0)
    out = mutate(g, np.random.default_rng(0), s)
    assert np.all(g == 100.0)  # input untouched
    changed = out != 100.0
    assert changed.mean() == pytest.approx(0.1, abs=0.003)
    replaced = changed & (np.abs(out) < 50.0)  # replaced genes are N(0, .8), shifted ones ~100
    assert replaced.sum() / changed.sum() == pytest.approx(0.25, abs=0.01)
    shifted = changed & ~replaced
    assert np.std(out[shifted] - 100.0) == pytest.approx(0.8, rel=0.02)
    assert np.std(out[replaced]) == pytest.approx(0.8, rel=0.03)
    assert abs(np.mean(out[shifted] - 100.0)) < 0.02


def test_mutation_extremes() -> None:
    g = np.arange(50, dtype=float)
    none = SteadyStateSettings(mutate_frac=0.0)
    assert np.array_equal(mutate(g, np.random.default_rng(0), none), g)
    allrepl = SteadyStateSettings(mutate_frac=1.0, mutate_repl=1.0, mutate_std=0.01)
    assert np.all(np.abs(mutate(g, np.random.default_rng(0), allrepl)) < 0.1)


def test_crossover_statistics() -> None:
    s = SteadyStateSettings(averaging_prob=0.3)
    a, b = np.zeros(300_000), np.ones(300_000)
    child = crossover(a, b, np.random.default_rng(0), s)
    assert set(np.unique(child)) == {0.0, 0.5, 1.0}
    assert np.mean(child == 0.5) == pytest.approx(0.3, abs=0.004)
    copies = child != 0.5
    assert np.mean(child[copies] == 0.0) == pytest.approx(0.5, abs=0.005)
    with pytest.raises(ValueError, match="same shape"):
        crossover(np.zeros(3), np.zeros(4), np.random.default_rng(0), s)


def test_roulette_weights() -> None:
    w = roulette_weights(np.array([-1e4, -100.0, -1.0, 5.0, np.nan, -np.inf]))
    assert np.all(np.isfinite(w)) and np.all(w[:4] > 0)
    assert w[0] < w[1] < w[2]  # smaller error, larger weight
    assert w[2] == w[3]  # error <= 1 clamped to the same floor
    assert w[1] == pytest.approx(1.0 / math.log(100.0))
    assert w[4] == 0.0 and w[5] == 0.0
    assert np.array_equal(roulette_weights(np.array([np.nan, np.nan])), [1.0, 1.0])
