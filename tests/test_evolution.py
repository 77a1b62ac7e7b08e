"""The optimisers (neurohover.evolution): their settings, steady-state and generational NE, CMA-ES (operators: test_operators.py; races: test_races.py)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from neurohover.evolution import (
    CMAES,
    GenerationalNE,
    GenerationalSettings,
    SteadyStateNE,
    SteadyStateSettings,
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


# --------------------------------------------------------------------------- settings


@pytest.mark.parametrize(
    ("cls", "kwargs", "message"),
    [
        (SteadyStateSettings, {"elite_size": 60}, r"elite_size=60 must be smaller than pop_size=50"),
        (SteadyStateSettings, {"pop_size": 10}, r"elite_size=49 \(its default\) must be smaller than pop_size=10: give elite_size below it too"),
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


@pytest.mark.slow
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


@pytest.mark.slow
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
