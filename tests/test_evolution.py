"""Tests of the optimiser layer (neurohover.evolution): operators, NE, CMA-ES, races."""

from __future__ import annotations

import dataclasses
import json
import math
import warnings

import numpy as np
import pytest
from scipy import stats

from neurohover.evolution import (
    CMAES,
    GenerationalNE,
    GenerationalSettings,
    SteadyStateNE,
    SteadyStateSettings,
    bayes_mean_bounds,
    crossover,
    fixed_resampling,
    mutate,
    roulette_weights,
    selection_race,
)
from neurohover.evolution.common import TellInfo

D = 10
TARGET = np.random.default_rng(1234).normal(size=D)


def sphere_return(genomes: np.ndarray) -> np.ndarray:
    """Synthetic return to maximise: -||g - target||^2 - 1 (optimum -1, prototype ~ -6.6)."""
    return -np.sum((np.atleast_2d(genomes) - TARGET) ** 2, axis=1) - 1.0


PROTO_RETURN = float(sphere_return(np.zeros(D))[0])


def run_to_stop(opt, fitness=sphere_return) -> None:
    while not opt.stop():
        opt.tell(fitness(opt.ask()))


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


# --------------------------------------------------------------------------- settings


@pytest.mark.parametrize(
    ("cls", "kwargs", "message"),
    [
        (SteadyStateSettings, {"elite_size": 60}, r"elite_size=60 must be smaller than pop_size=50"),
        (SteadyStateSettings, {"pop_size": 10}, r"elite_size=49 must be smaller than pop_size=10"),
        (SteadyStateSettings, {"pop_size": 1, "elite_size": 0}, r"pop_size=1 must be an integer >= 2"),
        (SteadyStateSettings, {"crossover_prob": 1.5}, r"crossover_prob=1.5 must be a probability in \[0, 1\]"),
        (SteadyStateSettings, {"mutate_frac": -0.1}, r"mutate_frac=-0.1 must be a probability"),
        (SteadyStateSettings, {"mutate_repl": float("nan")}, r"mutate_repl=nan must be a probability"),
        (SteadyStateSettings, {"mutate_std": -1.0}, r"mutate_std=-1.0 must be a finite number >= 0"),
        (SteadyStateSettings, {"mutate_std": math.inf}, r"mutate_std=inf must be a finite number"),
        (SteadyStateSettings, {"plateau_threshold": 0}, r"plateau_threshold=0 must be an integer >= 1"),
        (SteadyStateSettings, {"budget": 0}, r"budget=0 must be an integer >= 1"),
        (SteadyStateSettings, {"elite_size": 2.5}, r"elite_size=2.5 must be an integer"),
        (GenerationalSettings, {"select_size": 0}, r"select_size=0 must be an integer >= 1"),
        (GenerationalSettings, {"select_size": 51}, r"select_size=51 must be in \[1, pop_size=50\]"),
        (GenerationalSettings, {"generations": 0}, r"generations=0 must be an integer >= 1"),
        (GenerationalSettings, {"averaging_prob": 2}, r"averaging_prob=2 must be a probability"),
    ],
)
def test_settings_validation(cls, kwargs, message) -> None:
    with pytest.raises(ValueError, match=message):
        cls(**kwargs)


def test_settings_defaults_are_paper_tables() -> None:
    s = SteadyStateSettings()
    assert (s.pop_size, s.elite_size, s.crossover_prob, s.averaging_prob) == (50, 49, 0.5, 0.5)
    assert (s.mutate_prob, s.mutate_frac, s.mutate_std, s.mutate_repl) == (0.75, 0.1, 0.8, 0.25)
    assert (s.plateau_threshold, s.budget) == (1000, None)
    g = GenerationalSettings()
    assert (g.pop_size, g.select_size, g.generations, g.crossover_prob) == (50, 20, 4000, 1.0)
    assert (g.averaging_prob, g.mutate_prob, g.mutate_frac, g.mutate_std, g.mutate_repl) == (
        0.5,
        0.75,
        0.1,
        0.8,
        0.25,
    )
    assert isinstance(SteadyStateSettings(pop_size=np.int64(60)).pop_size, int)


# --------------------------------------------------------------------------- steady state


def test_steady_state_ask_tell_shapes_and_budget() -> None:
    opt = SteadyStateNE(np.zeros(D), SteadyStateSettings(budget=120), seed=0)
    first = opt.ask()
    assert first.shape == (50, D)
    assert np.array_equal(first[0], np.zeros(D))  # the prototype itself
    assert np.any(first[1:] != 0.0)  # mutated copies
    with pytest.raises(RuntimeError):
        opt.ask()
    with pytest.raises(ValueError, match="shape"):
        opt.tell(np.zeros(49))
    opt.tell(sphere_return(first))
    assert opt.ask().shape == (1, D)
    with pytest.raises(ValueError, match=r"\+inf"):
        opt.tell(np.array([np.inf]))
    opt.tell(np.array([-5.0]))
    run_to_stop(opt)
    assert opt.evaluations == 120
    assert opt.population.shape == (50, D)


def test_steady_state_improves() -> None:
    opt = SteadyStateNE(np.zeros(D), SteadyStateSettings(budget=3000), seed=3)
    run_to_stop(opt)
    assert opt.evaluations == 3000
    assert opt.champion_return > -1.2  # prototype is ~ -6.6, optimum -1
    assert opt.champion_return == pytest.approx(float(sphere_return(opt.champion_genome)[0]))
    returns = [h.champion_return for h in opt.history]
    evals = [h.evaluations for h in opt.history]
    assert np.all(np.diff(returns) > 0) and np.all(np.diff(evals) > 0)
    assert returns[-1] == opt.champion_return
    # Elitism: the population's best is the champion.
    assert np.nanmax(opt.fitness) == opt.champion_return


def test_steady_state_plateau_stop() -> None:
    # budget only guards against a hang if the plateau rule were broken
    opt = SteadyStateNE(np.zeros(D), SteadyStateSettings(plateau_threshold=70, budget=500), seed=0)
    run_to_stop(opt, lambda g: np.full(len(g), -10.0))  # nothing ever beats the first genome
    assert opt.evaluations == 71
    assert opt.evaluations_since_champion == 70
    assert len(opt.history) == 1 and opt.history[0].evaluations == 1


def test_steady_state_nonfinite_returns_rank_worst() -> None:
    opt = SteadyStateNE(np.zeros(D), SteadyStateSettings(budget=1500), seed=0)
    crash = np.random.default_rng(5)

    def fitness(g):
        r = sphere_return(g)
        u = crash.random(r.size)
        r[u < 0.2] = np.nan
        r[u > 0.9] = -np.inf
        return r

    n_finite = []
    while not opt.stop():
        opt.tell(fitness(opt.ask()))
        n_finite.append(int(np.isfinite(opt.fitness).sum()))
        finite_fit = np.where(np.isinf(opt.fitness), np.nan, opt.fitness)
        assert np.nanmax(finite_fit) == opt.champion_return
    # Elitism never drops a finite genome in favour of a NaN / -inf one.
    assert n_finite[0] < 50
    assert all(b >= min(a, 49) for a, b in zip(n_finite, n_finite[1:]))
    assert math.isfinite(opt.champion_return)
    assert opt.champion_return > PROTO_RETURN + 5.0


def test_steady_state_determinism() -> None:
    runs = []
    for seed in (7, 7, 8):
        opt = SteadyStateNE(np.zeros(D), SteadyStateSettings(budget=400), seed=seed)
        run_to_stop(opt)
        runs.append(opt)
    assert np.array_equal(runs[0].population, runs[1].population)
    assert runs[0].champion_return == runs[1].champion_return
    assert not np.array_equal(runs[0].population, runs[2].population)


@pytest.mark.parametrize("between_ask_and_tell", [False, True])
def test_steady_state_checkpoint_resume(between_ask_and_tell: bool) -> None:
    settings = SteadyStateSettings(budget=500)
    ref = SteadyStateNE(np.zeros(D), settings, seed=11)
    run_to_stop(ref)

    opt = SteadyStateNE(np.zeros(D), settings, seed=11)
    for _ in range(40):
        opt.tell(sphere_return(opt.ask()))
    pending = opt.ask() if between_ask_and_tell else None
    text = json.dumps(opt.state_dict(), allow_nan=False)
    resumed = SteadyStateNE.from_state_dict(json.loads(text))
    if pending is not None:
        resumed.tell(sphere_return(pending))
    run_to_stop(resumed)

    assert resumed.evaluations == ref.evaluations == 500
    assert np.array_equal(resumed.population, ref.population)
    assert np.array_equal(resumed.fitness, ref.fitness)
    assert np.array_equal(resumed.champion_genome, ref.champion_genome)
    assert [(h.evaluations, h.champion_return) for h in resumed.history] == [(h.evaluations, h.champion_return) for h in ref.history]
    assert resumed.history[-1].wall_seconds >= resumed.history[0].wall_seconds


# --------------------------------------------------------------------------- generational


def test_generational_improves_and_records() -> None:
    opt = GenerationalNE(np.zeros(D), GenerationalSettings(generations=60), seed=5)
    first = opt.ask()
    assert first.shape == (50, D) and np.array_equal(first[0], np.zeros(D))
    opt.tell(sphere_return(first))
    run_to_stop(opt)
    assert opt.generation == 60 and opt.evaluations == 3000
    hist = opt.history
    assert [h.generation for h in hist] == list(range(1, 61))
    assert all(h.episodes == 50 for h in hist) and hist[-1].evaluations == 3000
    assert hist[0].champion_return < -3.0 < -1.3 < hist[-1].champion_return
    assert opt.champion_return == hist[-1].champion_return
    assert opt.champion_return == pytest.approx(float(sphere_return(opt.champion_genome)[0]))


def test_generational_breeds_only_from_selected() -> None:
    # With no mutation, children are per-gene averages/copies of parents, so
    # they stay inside the selected parents' per-gene range.
    s = GenerationalSettings(pop_size=20, select_size=4, generations=2, mutate_prob=0.0)
    opt = GenerationalNE(np.zeros(3), s, seed=0)
    pop = opt.ask()
    chosen = np.array([3, 7, 11, 19])
    opt.tell(np.zeros(20), selected=chosen, episodes=123)
    children = opt.ask()
    lo, hi = pop[chosen].min(axis=0), pop[chosen].max(axis=0)
    assert np.all(children >= lo - 1e-12) and np.all(children <= hi + 1e-12)
    assert opt.history[0].episodes == 123 and opt.evaluations == 123
    with pytest.raises(ValueError, match="distinct integer indices"):
        opt.tell(np.zeros(20), selected=np.array([1, 1, 2, 3]))


@pytest.mark.parametrize("elitist", [True, False])
def test_generational_survivors(elitist: bool) -> None:
    # Every gene mutates, so no two genomes coincide by chance.
    s = GenerationalSettings(pop_size=10, select_size=3, generations=3, elitist=elitist, mutate_frac=1.0, mutate_prob=1.0)
    opt = GenerationalNE(np.zeros(4), s, seed=1)
    pop = opt.ask()
    chosen = np.array([8, 2, 5])
    opt.tell(np.arange(10.0), selected=chosen)
    nxt = opt.ask()
    survived = [any(np.array_equal(p, q) for q in nxt) for p in pop[chosen]]
    # Elitist: the selected parents are the first rows of the next population; otherwise all
    # rows are new (mutated) offspring.
    assert all(survived) if elitist else not any(survived)
    if elitist:
        np.testing.assert_array_equal(nxt[:3], pop[chosen])


def test_generational_with_selection_race_on_noisy_fitness() -> None:
    noise_rng = np.random.default_rng(99)
    s = GenerationalSettings(pop_size=20, select_size=6, generations=25)
    opt = GenerationalNE(np.zeros(D), s, seed=2)
    while not opt.stop():
        pop = opt.ask()
        true = sphere_return(pop)
        race = selection_race(lambda idx, true=true: true[idx] + noise_rng.normal(0.0, 0.3, idx.size), 20, 6, 0.9, t_limit=5)
        opt.tell(race.means, TellInfo(selected=race.selected, episodes=race.episodes_spent))
        assert opt.history[-1].episodes == race.episodes_spent
    assert opt.evaluations == sum(h.episodes for h in opt.history) < 25 * 20 * 5
    assert float(sphere_return(opt.champion_genome)[0]) > PROTO_RETURN + 3.0


@pytest.mark.parametrize("between_ask_and_tell", [False, True])
def test_generational_checkpoint_resume(between_ask_and_tell: bool) -> None:
    s = GenerationalSettings(pop_size=12, select_size=4, generations=30)
    ref = GenerationalNE(np.zeros(D), s, seed=4)
    run_to_stop(ref)
    opt = GenerationalNE(np.zeros(D), s, seed=4)
    for _ in range(13):
        opt.tell(sphere_return(opt.ask()))
    pending = opt.ask() if between_ask_and_tell else None
    text = json.dumps(opt.state_dict(), allow_nan=False)
    resumed = GenerationalNE.from_state_dict(json.loads(text))
    if pending is not None:
        resumed.tell(sphere_return(pending))
    run_to_stop(resumed)
    assert np.array_equal(resumed.population, ref.population)
    assert np.array_equal(resumed.champion_genome, ref.champion_genome)
    assert [h.champion_return for h in resumed.history] == [h.champion_return for h in ref.history]


def test_generational_determinism() -> None:
    settings = GenerationalSettings(generations=5)
    a, b, c = (GenerationalNE(np.zeros(D), settings, seed=s) for s in (1, 1, 2))
    for opt in (a, b, c):
        run_to_stop(opt)
    assert np.array_equal(a.population, b.population)
    assert not np.array_equal(a.population, c.population)


# --------------------------------------------------------------------------- CMA-ES


def test_cmaes_improves_is_deterministic_and_leaves_global_rng_alone() -> None:
    before = np.random.get_state()[1].copy()
    opts = [CMAES(np.zeros(D), sigma0=0.5, seed=s, budget=1500) for s in (3, 3, 4)]
    for opt in opts:
        run_to_stop(opt)
    assert np.array_equal(np.random.get_state()[1], before)
    a, b, c = opts
    assert a.champion_return > -1.01
    assert a.champion_return == b.champion_return and np.array_equal(a.mean, b.mean)
    assert a.champion_return != c.champion_return
    assert np.all(np.diff([h.champion_return for h in a.history]) > 0)
    assert a.evaluations <= 1500 + a.popsize


def test_cmaes_nonfinite_and_popsize() -> None:
    opt = CMAES(np.zeros(D), seed=0, popsize=8, budget=400)
    while not opt.stop():
        x = opt.ask()
        assert x.shape == (8, D)
        r = sphere_return(x)
        r[0], r[1] = np.nan, -np.inf
        opt.tell(r)
    assert math.isfinite(opt.champion_return) and opt.champion_return > PROTO_RETURN
    with pytest.raises(ValueError, match="sigma0"):
        CMAES(np.zeros(D), sigma0=0.0)


# --------------------------------------------------------------------------- races


def noisy_sampler(means: np.ndarray, sd: float, seed: int):
    rng = np.random.default_rng(seed)
    calls = []

    def sample(idx: np.ndarray) -> np.ndarray:
        calls.append(idx.size)
        return means[idx] + rng.normal(0.0, sd, idx.size)

    return sample, calls


def test_bayes_mean_bounds_edge_cases() -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert bayes_mean_bounds(np.array([3.0]), 0.9) == (-math.inf, math.inf)
        assert bayes_mean_bounds(np.array([2.0, 2.0, 2.0]), 0.9) == (2.0, 2.0)
        assert bayes_mean_bounds(np.array([-np.inf, 1.0]), 0.9) == (-math.inf, -math.inf)
        lo, hi = bayes_mean_bounds(np.array([1.0, 2.0]), 0.9)
        assert math.isfinite(lo) and lo < 1.5 < hi
        x = np.random.default_rng(0).normal(5.0, 2.0, 7)
        expected = stats.t.interval(0.8, 6, loc=x.mean(), scale=stats.sem(x))
        assert bayes_mean_bounds(x, 0.8) == pytest.approx(expected)
        assert bayes_mean_bounds(x, 0.95)[0] < bayes_mean_bounds(x, 0.5)[0]


@pytest.mark.parametrize("n", [2, 3, 5, 10, 37, 1000, 1001, 1500])
@pytest.mark.parametrize("delta", [0.1, 0.5, 0.9, 0.99])
def test_bayes_mean_bounds_match_scipy_bayes_mvs(n: int, delta: float) -> None:
    x = np.random.default_rng(n).normal(-3e4, 5e3, n)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # n=2: infinite statistic
        expected = stats.bayes_mvs(x, alpha=delta)[0].minmax
    assert bayes_mean_bounds(x, delta) == pytest.approx(expected, rel=1e-12, abs=1e-9)


def test_race_selects_top_mu_and_saves_episodes() -> None:
    means = -10.0 * np.arange(20)[::-1]  # candidate 19 best
    sample, calls = noisy_sampler(means, 1.0, seed=0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        race = selection_race(sample, 20, 5, delta=0.9, t_limit=10)
    assert sorted(race.selected.tolist()) == [15, 16, 17, 18, 19]
    assert race.n_raced == 5
    fixed = fixed_resampling(noisy_sampler(means, 1.0, seed=0)[0], 20, k=10)
    assert fixed.episodes_spent == 200 and fixed.samples.shape == (20, 10)
    assert race.episodes_spent < fixed.episodes_spent / 2
    assert race.episodes_spent == race.n_samples.sum() == sum(calls)
    assert race.rounds == len(calls) + 1 and race.n_samples.max() <= 10  # rounds 1 and 2 fly in one call
    assert calls[0] == 40  # every candidate twice
    assert np.all(race.lower <= race.means) and np.all(race.means <= race.upper)
    assert np.all(np.abs(race.means - means) < 4.0)


def test_race_decision_rule_thresholds() -> None:
    # Scripted returns, delta=0.5 (t quantile 1.0 at 1 dof). After round 2:
    # c0 = [10, 12] -> bounds [10, 12]; c1 = [11.5, 11.5] -> point 11.5, inside
    # c0's bounds; c2, c3 = [0, 0] -> point 0. With lambda=4, mu=1 nobody beats
    # lambda-mu=3 others yet, while c2 and c3 lie below >= mu=1 others: discarded.
    # Round 3: c0 = [10, 12, 11] -> 11 +- 0.47, so c1 (11.5) now beats all 3
    # and c0 lies below c1.
    script = {0: [10.0, 12.0, 11.0], 1: [11.5, 11.5, 11.5], 2: [0.0, 0.0, 0.0], 3: [0.0, 0.0, 0.0]}
    calls = {i: 0 for i in script}

    def sample(idx):
        out = []
        for i in idx:
            out.append(script[int(i)][calls[int(i)]])
            calls[int(i)] += 1
        return np.array(out)

    race = selection_race(sample, 4, 1, delta=0.5, t_limit=10)
    assert race.rounds == 3 and race.n_raced == 1
    assert race.selected.tolist() == [1]
    assert race.discarded.tolist() == [2, 3, 0]  # c0 (upper 11.47 < 11.5) goes in round 3
    assert race.n_samples.tolist() == [3, 3, 2, 2]
    assert race.lower[0] == pytest.approx(11.0 - stats.t.ppf(0.75, 2) * math.sqrt(1 / 3))


def test_race_indistinguishable_candidates_run_to_limit() -> None:
    sample, _ = noisy_sampler(np.zeros(12), 1.0, seed=1)
    race = selection_race(sample, 12, 4, delta=0.99, t_limit=6)
    assert len(set(race.selected.tolist())) == 4
    assert race.rounds == 6 and race.episodes_spent <= 12 * 6
    # The fill step takes the best means among the undecided ones.
    undecided = race.n_samples == 6
    filled = race.selected[race.n_raced :]
    assert np.all(undecided[filled])
    others = np.setdiff1d(np.flatnonzero(undecided), race.selected)
    assert race.means[filled].min() >= race.means[others].max()


def test_race_single_sample_and_zero_variance() -> None:
    means = np.arange(8, dtype=float)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        one = selection_race(lambda i: means[i], 8, 3, delta=0.9, t_limit=1)
        assert one.rounds == 1 and one.episodes_spent == 8 and one.n_raced == 0
        assert sorted(one.selected.tolist()) == [5, 6, 7]
        exact = selection_race(lambda i: means[i], 8, 3, delta=0.9, t_limit=10)
        assert exact.rounds == 2 and exact.episodes_spent == 16 and exact.n_raced == 3
        assert sorted(exact.selected.tolist()) == [5, 6, 7]
        ties = selection_race(lambda i: np.full(i.size, -4.0), 8, 3, delta=0.9, t_limit=4)
        assert ties.rounds == 4 and ties.n_raced == 0 and len(set(ties.selected.tolist())) == 3


def test_race_nan_returns_are_worst() -> None:
    means = np.arange(10, dtype=float)

    def sample(idx):
        out = means[idx] + np.random.default_rng(int(idx.sum())).normal(0, 0.1, idx.size)
        out[idx == 9] = np.nan  # the nominally best candidate crashes the simulator
        return out

    race = selection_race(sample, 10, 3, delta=0.9)
    assert 9 not in race.selected and sorted(race.selected.tolist()) == [6, 7, 8]
    assert race.means[9] == -math.inf


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"delta": 0.0}, r"delta=0.0 must be a confidence level strictly between 0 and 1"),
        ({"delta": 1.0}, r"delta=1.0 must be"),
        ({"mu": 0}, r"mu=0 must be an integer >= 1"),
        ({"mu": 6}, r"mu=6 must be smaller than n_candidates=6"),
        ({"t_limit": 0}, r"t_limit=0 must be an integer >= 1"),
        ({"n_candidates": 1, "mu": 1}, r"n_candidates=1 must be an integer >= 2"),
    ],
)
def test_race_validation(kwargs, message) -> None:
    args = {"n_candidates": 6, "mu": 2, "delta": 0.9, "t_limit": 3} | kwargs
    with pytest.raises(ValueError, match=message):
        selection_race(lambda i: np.zeros(i.size), **args)


def test_resampling_validation_and_shape_check() -> None:
    with pytest.raises(ValueError, match=r"k=0 must be an integer >= 1"):
        fixed_resampling(lambda i: np.zeros(i.size), 5, 0)
    with pytest.raises(ValueError, match="sample_fn returned shape"):
        fixed_resampling(lambda i: np.zeros(3), 5, 2)
    res = fixed_resampling(lambda i: i.astype(float), 4, 3)
    assert np.array_equal(res.means, [0.0, 1.0, 2.0, 3.0]) and res.episodes_spent == 12


# ------------------------------------------------- selection_race regression (reference copy)
# A frozen copy of the original per-candidate implementation of ``selection_race``
# (one ``bayes_mean_bounds`` and one mean per candidate per round). The vectorised
# implementation in neurohover.evolution.races must reproduce it exactly: same
# selection (and order), same calls to ``sample_fn``, same means / bounds / counts.


def _ref_draw(sample_fn, indices: np.ndarray) -> np.ndarray:
    out = np.asarray(sample_fn(indices.copy()), dtype=np.float64)
    if out.shape != indices.shape:
        raise ValueError(f"sample_fn returned shape {out.shape} for {indices.size} candidates; expected {indices.shape}")
    if np.any(out == np.inf):
        raise ValueError("sample_fn returned +inf; returns must be finite, NaN or -inf")
    return np.where(np.isnan(out), -np.inf, out)


def _ref_mean(samples: np.ndarray) -> float:
    return -math.inf if np.any(np.isneginf(samples)) else float(np.mean(samples))


def _ref_bounds(samples: np.ndarray, delta: float) -> tuple[float, float]:
    x = np.asarray(samples, dtype=np.float64).ravel()
    n = x.size
    if np.any(np.isneginf(x)):
        return -math.inf, -math.inf
    if n == 1:
        return -math.inf, math.inf
    if np.all(x == x[0]):
        m = float(x[0])
        return m, m
    xbar = float(x.mean())
    var = float(x.var())
    scale = math.sqrt(var / n) if n > 1000 else math.sqrt(var / (n - 1))
    q_lo, q_hi = (1.0 - delta) / 2.0, (1.0 + delta) / 2.0
    if n > 1000:
        q_lo, q_hi = float(stats.norm.ppf(q_lo)), float(stats.norm.ppf(q_hi))
    else:
        q_lo, q_hi = float(stats.t.ppf(q_lo, n - 1)), float(stats.t.ppf(q_hi, n - 1))
    return q_lo * scale + xbar, q_hi * scale + xbar


def _ref_best_first(means: np.ndarray, idx: np.ndarray) -> np.ndarray:
    return np.argsort(-means[idx], kind="stable")


def _reference_selection_race(sample_fn, n: int, mu: int, delta: float, t_limit: int = 10) -> dict:
    samples: list[list[float]] = [[] for _ in range(n)]
    lower = np.full(n, -np.inf)
    upper = np.full(n, np.inf)
    means = np.full(n, np.nan)
    undecided = np.ones(n, dtype=bool)
    discarded = np.zeros(n, dtype=bool)
    selected: list[int] = []
    discard_order: list[int] = []
    rounds = 0
    while True:
        active = np.flatnonzero(undecided)
        for i, r in zip(active, _ref_draw(sample_fn, active)):
            samples[i].append(float(r))
            arr = np.asarray(samples[i])
            means[i] = _ref_mean(arr)
            lower[i], upper[i] = _ref_bounds(arr, delta)
        rounds += 1
        n_beaten = (upper[None, :] < lower[active, None]).sum(axis=1)
        n_beating = (lower[None, :] > upper[active, None]).sum(axis=1)
        newly_sel = active[n_beaten >= n - mu]
        newly_dis = active[n_beating >= mu]
        room = mu - len(selected)
        if newly_sel.size > room:
            newly_sel = newly_sel[_ref_best_first(means, newly_sel)][:room]
        selected.extend(int(i) for i in newly_sel[_ref_best_first(means, newly_sel)])
        undecided[newly_sel] = False
        undecided[newly_dis] = False
        discarded[newly_dis] = True
        discard_order.extend(int(i) for i in newly_dis)
        if len(selected) >= mu or not undecided.any():
            break
        if len(selected) + int(undecided.sum()) <= mu:
            break
        if rounds >= t_limit:
            break
    n_raced = len(selected)
    for pool in (np.flatnonzero(undecided), np.flatnonzero(discarded)):
        need = mu - len(selected)
        if need <= 0:
            break
        selected.extend(int(i) for i in pool[_ref_best_first(means, pool)][:need])
    n_samples = np.array([len(s) for s in samples], dtype=np.int64)
    return {
        "selected": np.asarray(selected, dtype=np.int64),
        "means": means,
        "n_samples": n_samples,
        "lower": lower,
        "upper": upper,
        "discarded": np.asarray([i for i in discard_order if i not in selected], dtype=np.int64),
        "n_raced": n_raced,
        "episodes_spent": int(n_samples.sum()),
        "rounds": rounds,
    }


def _race_case(seed: int):
    """A random race problem: (n, mu, delta, t_limit, table of returns per candidate and sample)."""
    rng = np.random.default_rng(seed)
    n = int(rng.integers(5, 61))
    mu = int(rng.integers(1, n))
    delta = float(rng.uniform(0.05, 0.95))
    t_limit = int(rng.integers(2, 11)) if seed % 11 else int(rng.integers(1, 4))
    kind = seed % 7
    scale = float(10.0 ** rng.uniform(-2, 4))
    true = rng.normal(0.0, scale, n) - (3e4 if seed % 2 else 0.0)
    noise = float(10.0 ** rng.uniform(-3, 0.5)) * scale
    table = true[:, None] + rng.normal(0.0, noise, (n, t_limit))
    if kind == 1:  # heavy ties: few distinct values
        table = rng.integers(0, 3, (n, t_limit)).astype(float) + rng.integers(0, 2, (n, 1))
    elif kind == 2:  # some constant candidates
        const = rng.random(n) < 0.5
        table[const] = true[const, None]
    elif kind == 3:  # NaN and -inf returns
        table[rng.random((n, t_limit)) < 0.05] = np.nan
        table[rng.random((n, t_limit)) < 0.03] = -np.inf
    elif kind == 4:  # all identical
        table[:] = -4.0
    elif kind == 5:  # rounded returns (ties between candidates and samples), some crashes
        table = np.round(table / noise)
        table[rng.random((n, t_limit)) < 0.02] = np.nan
    elif kind == 6:  # huge dynamic range, sums where order matters
        table = rng.choice([1e16, 1.0, -1e16, 0.1, 3.0, -2.5e-3], (n, t_limit)) + true[:, None] * 1e-3
    return n, mu, delta, t_limit, table


def _table_sampler(table: np.ndarray):
    count = np.zeros(table.shape[0], dtype=np.int64)
    calls: list[np.ndarray] = []

    def sample(idx: np.ndarray) -> np.ndarray:
        calls.append(idx.copy())
        out = np.empty(idx.size)
        for q, i in enumerate(idx):  # a candidate listed twice flies its next two samples, in list order
            out[q] = table[i, count[i]]
            count[i] += 1
        idx[:] = -1  # a sample_fn scribbling on its argument must not matter
        return out

    return sample, calls


def _assert_race_equal(new, ref: dict) -> None:
    for key in ("selected", "n_samples", "discarded"):
        got = getattr(new, key)
        assert got.dtype == ref[key].dtype and np.array_equal(got, ref[key]), key
    for key in ("n_raced", "episodes_spent", "rounds"):
        assert getattr(new, key) == ref[key], key
    for key in ("means", "lower", "upper"):
        np.testing.assert_allclose(getattr(new, key), ref[key], rtol=1e-12, atol=0, err_msg=key)


@pytest.mark.parametrize("seed", range(400))
def test_selection_race_matches_reference_implementation(seed: int) -> None:
    n, mu, delta, t_limit, table = _race_case(seed)
    ref_sample, ref_calls = _table_sampler(table)
    with warnings.catch_warnings(record=True) as ref_warnings:
        warnings.simplefilter("always")
        ref = _reference_selection_race(ref_sample, n, mu, delta, t_limit)
    new_sample, new_calls = _table_sampler(table)
    with warnings.catch_warnings(record=True) as new_warnings:
        warnings.simplefilter("always")
        new = selection_race(new_sample, n, mu, delta, t_limit)
    _assert_race_equal(new, ref)
    if t_limit >= 2:  # rounds 1 and 2 in one call: the reference's first two calls, one after the other
        ref_calls = [np.concatenate(ref_calls[:2]), *ref_calls[2:]]
    assert len(new_calls) == len(ref_calls)
    for a, b in zip(new_calls, ref_calls):
        assert a.dtype == b.dtype and np.array_equal(a, b)
    if not ref_warnings:
        assert not new_warnings


@pytest.mark.parametrize("seed", range(40))
def test_selection_race_matches_reference_with_stream_sampler(seed: int) -> None:
    """Returns drawn from one RNG stream in call order (as the evolve loop does)."""
    rng = np.random.default_rng(seed)
    n = int(rng.integers(5, 61))
    mu, delta, t_limit = int(rng.integers(1, n)), float(rng.uniform(0.05, 0.95)), int(rng.integers(2, 11))
    true = rng.normal(0.0, 1.0, n)

    def make():
        stream = np.random.default_rng(seed + 1000)
        return lambda idx: true[idx] + stream.normal(0.0, 2.0, idx.size)

    ref = _reference_selection_race(make(), n, mu, delta, t_limit)
    _assert_race_equal(selection_race(make(), n, mu, delta, t_limit), ref)


def test_selection_race_matches_reference_beyond_1000_samples() -> None:
    """Indistinguishable candidates raced past n = 1000 (normal-approximation bounds)."""
    rng = np.random.default_rng(5)
    table = rng.normal(0.0, 1.0, (3, 1003))
    ref = _reference_selection_race(_table_sampler(table)[0], 3, 1, 0.999999, 1003)
    new = selection_race(_table_sampler(table)[0], 3, 1, 0.999999, 1003)
    assert ref["rounds"] > 1000
    _assert_race_equal(new, ref)


def test_selection_race_bad_returns_raise_like_reference() -> None:
    for bad in (lambda i: np.zeros(i.size + 1), lambda i: np.where(i == 3, np.inf, 0.0)):
        for impl in (_reference_selection_race, selection_race):
            with pytest.raises(ValueError, match="sample_fn returned"):
                impl(bad, 6, 2, 0.9, 3)


@pytest.mark.parametrize("seed", range(0, 400, 7))
def test_a_races_look_ahead_changes_no_result(seed: int) -> None:
    """With every candidate's t-th sample fixed (the table), look-ahead batches fly more samples
    per call but the race uses exactly the samples it used without them."""
    n, mu, delta, t_limit, table = _race_case(seed)
    plain_sample, plain_calls = _table_sampler(table)
    plain = selection_race(plain_sample, n, mu, delta, t_limit)
    for batch in (7, 64, 10_000):
        sample, calls = _table_sampler(table)
        ahead = selection_race(sample, n, mu, delta, t_limit, batch=batch)
        _assert_race_equal(ahead, dataclasses.asdict(plain))
        assert len(calls) <= len(plain_calls)
        if batch == 10_000:  # every sample up to t_limit in the first call
            assert len(calls) == 1
        assert ahead.episodes_flown == sum(c.size for c in calls) >= ahead.episodes_spent
    assert plain.episodes_flown == plain.episodes_spent
