"""Bit-identity of the steady-state neuroevolution and its operators with a frozen reference.

The reference below is a copy of ``SteadyStateNE`` and of ``operators.mutate`` /
``operators.crossover`` as they were before the fast implementation was folded in (649b0b1): plain NumPy,
written for clarity. It is frozen on purpose; do not speed it up or "fix" it. Every test here runs
the library and the reference on the same seeds and requires the same random draws, populations,
fitness, champions and histories, bit for bit, also through :func:`evolve`.
"""

from __future__ import annotations

import importlib
import json
import math

import numpy as np
import pytest

from neurohover.evolution import (
    GenerationalNE,
    GenerationalSettings,
    SteadyStateNE,
    SteadyStateSettings,
    crossover,
    evolve,
    mutate,
    roulette_weights,
)
from neurohover.evolution.common import rank
from neurohover.tasks import get_task_family

run_module = importlib.import_module("neurohover.evolution.run")
generational_module = importlib.import_module("neurohover.evolution.generational")

GHH08 = get_task_family("ghh08")


# --------------------------------------------------------------------------------- frozen reference


def ref_mutate(genome, rng, s):
    g = np.asarray(genome, dtype=np.float64)
    hit = rng.random(g.shape) < s.mutate_frac
    delta = rng.normal(0.0, s.mutate_std, g.shape)
    replace = rng.random(g.shape) < s.mutate_repl
    return np.where(hit, np.where(replace, delta, g + delta), g)


def ref_crossover(a, b, rng, s):
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    if a.shape != b.shape:
        raise ValueError("crossover parents must have the same shape")
    average = rng.random(a.shape) < s.averaging_prob
    take_a = rng.random(a.shape) < 0.5
    return np.where(average, 0.5 * (a + b), np.where(take_a, a, b))


def ref_roulette_weights(returns):
    r = np.asarray(returns, dtype=np.float64)
    w = np.zeros_like(r)
    ok = np.isfinite(r)
    w[ok] = 1.0 / np.log(np.maximum(-r[ok], 1.0 + 1e-6))
    if not np.any(w > 0):
        w = np.ones_like(r)
    return w


def ref_rank(returns):
    key = np.where(np.isnan(returns), -np.inf, returns)
    return np.argsort(-key, kind="stable")


class FrozenSteadyStateNE:
    """The steady-state algorithm of Appendix A exactly as first implemented (no checkpoints)."""

    def __init__(self, prototype, settings=None, seed=0):
        self.settings = settings if settings is not None else SteadyStateSettings()
        self.prototype = np.array(prototype, dtype=np.float64)
        self.rng = np.random.default_rng(seed)
        self.population = self.fitness = self.pending = None
        self.generation = 0
        self.evaluations = 0
        self.champion_genome = None
        self.champion_return = -math.inf
        self.since = 0
        self.history = []  # (evaluations, champion_return)

    def ask(self):
        s = self.settings
        if self.population is None:
            p = self.prototype
            batch = np.vstack([p] + [ref_mutate(p, self.rng, s) for _ in range(s.pop_size - 1)])
        else:
            batch = self._breed(s.pop_size - s.elite_size)
        self.pending = batch
        return batch.copy()

    def tell(self, fitness, info=None):  # the protocol: tell(fitness, info); the literal plateau rule needs no crash flags
        f = np.array(fitness, dtype=np.float64)
        if self.population is None:
            self.population, self.fitness = self.pending, f
        else:
            keep = ref_rank(self.fitness)[: self.settings.elite_size]
            self.population = np.vstack([self.population[keep], self.pending])
            self.fitness = np.concatenate([self.fitness[keep], f])
        for g, r in zip(self.pending, f):
            self.evaluations += 1
            if r > self.champion_return:
                self.champion_return = float(r)
                self.champion_genome = np.array(g, dtype=np.float64)
                self.since = 0
                self.history.append((self.evaluations, self.champion_return))
            else:
                self.since += 1
        self.pending = None
        self.generation += 1

    def stop(self):
        s = self.settings
        if self.evaluations == 0:
            return False
        if self.since >= s.plateau_threshold:
            return True
        return s.budget is not None and self.evaluations >= s.budget

    def _breed(self, n):
        s, rng, pop = self.settings, self.rng, self.population
        cdf = np.cumsum(ref_roulette_weights(self.fitness))

        def spin():
            i = int(np.searchsorted(cdf, rng.random() * cdf[-1], side="right"))
            return min(i, cdf.size - 1)

        children = []
        for _ in range(n):
            if rng.random() < s.crossover_prob:
                child = ref_crossover(pop[spin()], pop[spin()], rng, s)
                if rng.random() < s.mutate_prob:
                    child = ref_mutate(child, rng, s)
            else:
                child = ref_mutate(pop[spin()], rng, s)
            children.append(child)
        return np.vstack(children)


# --------------------------------------------------------------------------------- helpers


def same_bits(a, b) -> bool:
    a, b = np.asarray(a), np.asarray(b)
    return a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes()


def assert_same_state(opt: SteadyStateNE, ref: FrozenSteadyStateNE) -> None:
    assert same_bits(opt.population, ref.population)
    assert same_bits(opt.fitness, ref.fitness)
    assert opt.champion_return == ref.champion_return
    assert same_bits(opt.champion_genome, ref.champion_genome)
    assert [(h.evaluations, h.champion_return) for h in opt.history] == ref.history
    assert (opt.evaluations, opt.generation, opt.evaluations_since_champion, opt.stop()) == (ref.evaluations, ref.generation, ref.since, ref.stop())
    assert opt.state_dict()["rng"] == ref.rng.bit_generator.state  # the same draws were made


def synthetic_fitness(genomes, gen: int, target, noise) -> np.ndarray:
    """Noisy negative returns with ties, NaN and -inf; the first generations are all non-finite
    (the roulette wheel then gives every genome weight 1)."""
    f = -np.sum((genomes - target) ** 2, axis=1) * 1e3 - 2.0 + noise.normal(0.0, 50.0, len(genomes))
    if gen < 4:
        return np.where(noise.random(len(f)) < 0.5, np.nan, -np.inf)
    if gen % 3 == 0:
        f = np.round(f, -2)  # ties
    if gen % 97 == 5:
        f[0] = -np.inf
    if gen % 89 == 7:
        f[-1] = np.nan
    if gen > 1200 and gen % 100 == 0:
        f[0] = -0.5 - gen * 1e-4  # error below the floor: the largest roulette weight
    return f


def roundtrip(opt: SteadyStateNE) -> SteadyStateNE:
    return SteadyStateNE.from_state_dict(json.loads(json.dumps(opt.state_dict(), allow_nan=False)))


# --------------------------------------------------------------------------------- operators


@pytest.mark.parametrize("shape,order", [((42,), "C"), ((1,), "C"), ((), "C"), ((3, 5), "C"), ((4, 6), "F")])
def test_operators_match_the_reference(shape, order) -> None:
    rng = np.random.default_rng(0)
    settings = [
        SteadyStateSettings(),
        SteadyStateSettings(mutate_frac=1.0, mutate_repl=0.5, averaging_prob=0.0),
        SteadyStateSettings(mutate_frac=0.0, mutate_std=0.0, averaging_prob=1.0),
    ]
    for trial in range(60):
        s = settings[trial % len(settings)]
        a = np.asarray(rng.normal(size=shape), order=order)
        b = np.asarray(rng.normal(size=shape), order=order)
        seed = int(rng.integers(2**32))
        r1, r2 = np.random.default_rng(seed), np.random.default_rng(seed)
        assert same_bits(mutate(a, r1, s), ref_mutate(a, r2, s))
        assert same_bits(crossover(a, b, r1, s), ref_crossover(a, b, r2, s))
        assert r1.bit_generator.state == r2.bit_generator.state
    strided = np.arange(20.0)[::2]
    r1, r2 = np.random.default_rng(1), np.random.default_rng(1)
    assert same_bits(mutate(strided, r1, s), ref_mutate(strided, r2, s))
    assert same_bits(mutate([1, 2, 3], r1, s), ref_mutate([1, 2, 3], r2, s))  # integers become floats
    assert same_bits(crossover(strided, strided[::-1], r1, s), ref_crossover(strided, strided[::-1], r2, s))
    assert np.array_equal(strided, np.arange(20.0)[::2])  # inputs untouched


def test_roulette_weights_match_the_reference() -> None:
    cases = [
        np.array([-1e4, -100.0, -1.0, 5.0, np.nan, -np.inf, 0.0, -0.0, -1.000001]),  # +inf is refused (T58-B06)
        np.array([np.nan, -np.inf]),
        np.array([-3.0]),  # a 0-d or empty array is refused (fifteenth trial, T15-24)
        -np.abs(np.random.default_rng(2).normal(0, 1e3, 50)),
    ]
    for r in cases:
        assert same_bits(roulette_weights(r), ref_roulette_weights(r))


def test_rank_matches_the_reference() -> None:
    rng = np.random.default_rng(8)
    cases = [np.array([0.0, -0.0, np.nan, -np.inf, 1.0, 0.0, np.nan, -np.inf]), np.array([np.nan]), np.zeros(0)]
    for _ in range(300):
        n = int(rng.integers(1, 60))
        r = np.round(rng.normal(0, 3, n))  # many ties
        r[rng.random(n) < 0.1] = np.nan
        r[rng.random(n) < 0.1] = -np.inf
        cases.append(r)
    for r in cases:
        assert np.array_equal(rank(r), ref_rank(r))


def test_generational_breeding_is_unchanged(monkeypatch) -> None:
    """GenerationalNE breeds with the operators; with the reference operators it must do the same."""
    s = GenerationalSettings(pop_size=12, select_size=4, generations=30, crossover_prob=0.7)
    fitness = np.random.default_rng(4)
    returns = [-np.abs(fitness.normal(0, 100, 12)) for _ in range(30)]
    pops = []
    for use_reference in (False, True):
        if use_reference:
            monkeypatch.setattr(generational_module, "mutate", ref_mutate)
            monkeypatch.setattr(generational_module, "crossover", ref_crossover)
        opt = GenerationalNE(np.zeros(9), s, seed=6)
        for f in returns:
            opt.ask()
            opt.tell(f)
        pops.append(opt.population)
    assert same_bits(pops[0], pops[1])


# --------------------------------------------------------------------------------- steady state ask/tell


@pytest.mark.slow
@pytest.mark.parametrize(
    "pop_size,elite_size,crossover_prob,dim",
    [
        (50, 49, 0.5, 42),  # the paper's settings
        (20, 19, 0.5, 12),
        (10, 7, 0.5, 12),  # several offspring per generation
        (6, 0, 1.0, 5),  # no elite; always crossover
        (8, 5, 0.0, 5),  # never crossover
    ],
)
def test_ask_tell_matches_the_reference(pop_size, elite_size, crossover_prob, dim) -> None:
    settings = SteadyStateSettings(pop_size=pop_size, elite_size=elite_size, crossover_prob=crossover_prob, plateau_threshold=400)
    target = np.random.default_rng(3).normal(size=dim)
    opt, ref = SteadyStateNE(np.zeros(dim), settings, seed=5), FrozenSteadyStateNE(np.zeros(dim), settings, seed=5)
    noise = np.random.default_rng(9)
    for gen in range(1500):
        if gen in (1, 700):  # checkpoint round trips right after the initial population and midway
            opt = roundtrip(opt)
        asked = opt.ask()
        assert same_bits(asked, ref.ask())
        if gen in (2, 900):  # ... and between ask and tell
            opt = roundtrip(opt)
        f = synthetic_fitness(asked, gen, target, noise)
        asked[:] = np.nan  # the caller may scribble on what ask() returned
        opt.tell(f)
        ref.tell(f)
        if gen % 50 == 0 or gen < 6:
            assert_same_state(opt, ref)
    assert_same_state(opt, ref)
    assert math.isfinite(opt.champion_return) and len(opt.history) > 5


def test_state_dict_format_is_unchanged() -> None:
    opt = SteadyStateNE(np.zeros(4), SteadyStateSettings(pop_size=5, elite_size=4), seed=1)
    opt.tell(-np.arange(1.0, 6.0) * 10 + 0 * opt.ask()[:, 0])
    opt.ask()
    state = opt.state_dict()
    assert sorted(state) == sorted(
        ["type", "version", "settings", "prototype", "population", "fitness", "pending", "generation", "rng", "tracker", "wall_seconds"]
    )
    assert (state["type"], state["version"], state["generation"]) == ("SteadyStateNE", 1, 1)
    assert state["population"]["shape"] == [5, 4] and state["pending"]["shape"] == [1, 4]
    assert sorted(state["tracker"]) == ["best", "evaluations", "genome", "history", "since"]
    assert json.loads(json.dumps(state, allow_nan=False)) == state


# --------------------------------------------------------------------------------- evolve


def _recording(cls, made: list):
    def make(*args, **kwargs):
        made.append(cls(*args, **kwargs))
        return made[-1]

    return make


def _result_key(result) -> tuple:
    return (
        result.champion.genome.tobytes(),
        result.champion_return,
        result.episodes,
        result.steps,
        result.evaluations,
        result.generations,
        result.stop_reason,
        [(h.generation, h.evaluations, h.episodes, h.generation_episodes, h.champion_return) for h in result.history],
    )


@pytest.mark.parametrize(
    "topology,seed,kwargs",
    [
        ("slp", 0, dict(budget=600)),
        ("mlp", 1, dict(budget=600)),
        ("mlp", 2, dict(budget=600, mdp="train:1")),
        ("slp", 3, dict(budget=1000, resampling="fixed:2", settings={"pop_size": 10, "elite_size": 7})),
        ("mlp", 4, dict(settings={"plateau_threshold": 150, "pop_size": 20, "elite_size": 19})),
    ],
)
def test_evolve_matches_the_reference(monkeypatch, topology, seed, kwargs) -> None:
    mdp = GHH08.mdp(kwargs.pop("mdp", "train:0"))
    runs = []
    for cls in (SteadyStateNE, FrozenSteadyStateNE):
        made: list = []
        monkeypatch.setattr(run_module, "SteadyStateNE", _recording(cls, made))
        result = evolve(mdp, topology=topology, seed=seed, n_steps=200, threads=1, **kwargs)
        (opt,) = made
        runs.append((result, opt))
    (result, opt), (ref_result, ref) = runs
    assert _result_key(result) == _result_key(ref_result)
    assert same_bits(opt.population, ref.population) and same_bits(opt.fitness, ref.fitness)
    assert [(h.evaluations, h.champion_return) for h in opt.history] == ref.history
    assert result.generations > 100
    if "budget" not in kwargs:
        assert result.stop_reason == "plateau"
