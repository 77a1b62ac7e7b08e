"""Top-mu selection by LUCB1 and KL-LUCB (issue 35): known answers of the bounds, the selection on tables of
samples, and the resampling kinds `lucb:DELTA` / `kl-lucb:DELTA` in generational evolution."""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import table_sampler

from neurohover.errors import NeurohoverError
from neurohover.evolution.bandits import kl_bounds, lucb_radius, top_mu_bandit
from neurohover.evolution.config import parse_resampling
from neurohover.evolution.evolve import evolve
from neurohover.experiments.units import family_of


def test_lucb_radius_is_the_papers_formula() -> None:
    # Kalyanakrishnan et al. 2012, LUCB1: beta(u, t) = sqrt(ln(5 n t^4 / (4 delta)) / (2 u))
    expected = math.sqrt(math.log(5 * 50 * 100**4 / (4 * 0.1)) / (2 * 4))
    assert lucb_radius(np.array([4]), 100, 50, 0.1)[0] == pytest.approx(expected, rel=1e-12)
    assert lucb_radius(np.array([16]), 100, 50, 0.1)[0] == pytest.approx(expected / 2, rel=1e-12)


def test_kl_bounds_solve_the_divergence_equation() -> None:
    lower, upper = kl_bounds(np.array([0.5, 0.0, 1.0, 0.2]), np.array([10, 10, 10, 40]), 2.0)
    for p, u, q in ((0.5, 10, upper[0]), (0.5, 10, lower[0]), (0.2, 40, upper[3]), (0.2, 40, lower[3])):
        kl = p * math.log(p / q) + (1 - p) * math.log((1 - p) / (1 - q))
        assert u * kl == pytest.approx(2.0, rel=1e-9)
    assert lower[0] < 0.5 < upper[0] and upper[0] == pytest.approx(1 - lower[0], rel=1e-9)  # symmetric about 1/2
    assert lower[1] == 0.0 and upper[2] == 1.0 and upper[3] - lower[3] < upper[0] - lower[0]  # more samples: tighter


def _one_bound(p: float, u: int, level: float, upper: bool) -> float:
    """One candidate's bound, bisected alone as the stored paper units computed it (before the bisections were stacked)."""
    eps = 1e-15
    pa = np.clip(np.array([p]), eps, 1 - eps)
    lo, hi = (np.array([p]), np.ones(1)) if upper else (np.zeros(1), np.array([p]))
    for _ in range(60):
        mid = (lo + hi) / 2
        q = np.clip(mid, eps, 1 - eps)
        inside = pa * np.log(pa / q) + (1 - pa) * np.log((1 - pa) / (1 - q)) <= level / u
        rises = inside if upper else ~inside
        lo, hi = np.where(rises, mid, lo), np.where(rises, hi, mid)
    return float(lo[0] if upper else hi[0])


def test_kl_bounds_bisected_together_are_each_candidates_bounds_bit_for_bit() -> None:
    """The stacked bisection (2.4x faster) keeps every stored KL-LUCB unit's bits: each bound as if bisected alone."""
    rng = np.random.default_rng(3)
    means = np.concatenate([rng.uniform(0, 1, 40), [0.0, 1.0, 1e-16]])
    samples = rng.integers(1, 11, means.size)
    lower, upper = kl_bounds(means, samples, 4.7)
    for i, (p, u) in enumerate(zip(means, samples)):
        assert lower[i] == _one_bound(p, u, 4.7, False) and upper[i] == _one_bound(p, u, 4.7, True), i


@pytest.mark.parametrize("rule", ["lucb", "kl-lucb"])
def test_separated_candidates_are_told_apart_before_the_limit(rule: str) -> None:
    table = np.repeat(np.array([[0.9], [0.1], [0.85], [0.15]]), 500, axis=1)  # no noise: the bounds alone decide
    result = top_mu_bandit(table_sampler(table), 4, 2, 0.1, rule=rule, t_limit=500)
    assert sorted(result.selected.tolist()) == [0, 2] and result.n_raced == 2
    assert result.episodes_spent < 4 * 500 and result.episodes_spent == result.n_samples.sum()


@pytest.mark.slow
@pytest.mark.parametrize("rule", ["lucb", "kl-lucb"])
def test_at_a_races_limit_fifty_candidates_are_never_told_apart(rule: str) -> None:
    """Distribution-free bounds need more than 10 episodes a candidate: the rule runs to the limit (n_raced 0),
    sampling the contested candidates more, and the selection is by mean."""
    rng = np.random.default_rng(1)
    means = rng.uniform(0.05, 0.25, 50)
    table = np.clip(means[:, None] + rng.normal(0.0, 0.02, (50, 10)), 0, 1)
    result = top_mu_bandit(table_sampler(table), 50, 20, 0.1, rule=rule, t_limit=10)
    assert result.n_raced == 0 and result.n_samples.max() == 10 and result.n_samples.min() >= 1
    assert len(set(result.selected.tolist()) & set(np.argsort(-means)[:20].tolist())) >= 17


def test_bad_bandit_settings_are_refused() -> None:
    table = np.zeros((4, 10))
    for kwargs, message in (({"delta": 1.0}, "delta=1.0 must be an error probability"), ({"rule": "ucb"}, "rule='ucb' is not a bandit rule")):
        with pytest.raises(ValueError, match=message):
            top_mu_bandit(table_sampler(table), 4, 2, **{"delta": 0.1, **kwargs})
    assert str(parse_resampling("kl-lucb:0.05")) == "kl-lucb:0.05" and parse_resampling("lucb:0.1").selects
    with pytest.raises(NeurohoverError, match="DELTA must be an error probability strictly between 0 and 1"):
        parse_resampling("lucb:1.5")


@pytest.mark.slow
def test_generational_evolution_selects_by_lucb_and_refuses_raw_returns() -> None:
    family = family_of("fghh", 0.3, None)
    run = evolve(family, topology="slp", prototype="baseline", resampling="lucb:0.1", budget=700, seed=2, n_steps=40)
    again = evolve(family, topology="slp", prototype="baseline", resampling="lucb:0.1", budget=700, seed=2, n_steps=40, threads=1)
    assert run.settings["resampling"] == "lucb:0.1" and run.generations >= 1 and run.episodes >= 700
    assert np.array_equal(run.champion.genome, again.champion.genome)  # the same run whatever the threads
    with pytest.raises(NeurohoverError, match="needs rewards in \\[0, 1\\]: the fitness scale inv-log-error"):
        evolve(family, topology="slp", prototype="baseline", resampling="lucb:0.1", budget=100, seed=2, n_steps=40, settings={"fitness": "return"})
