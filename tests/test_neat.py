"""Topology evolution with neat-python (neurohover.integrations.neat; issue 35): the compiled forward pass is
neat-python's network, and a run is reproducible from its seed. Skipped where neat-python is not installed."""

from __future__ import annotations

import random

import numpy as np
import pytest

neat = pytest.importorskip("neat", reason="neat-python is not installed (pip install '.[neat]')")

from neurohover import NeurohoverError, baseline_policy, evaluate, get_task_family  # noqa: E402  # noqa: E402
from neurohover.integrations.flying import evaluate_callable  # noqa: E402
from neurohover.integrations.neat import INPUT_INDEX, NeatSettings, evolve_topology, forward, neat_config, pack_networks, seed_baseline  # noqa: E402


def _grown_genomes(n: int, seed: int):
    """Genomes with hidden nodes of every activation: neat-python's own mutations, many times over."""
    settings = NeatSettings(pop_size=n, activations=("tanh", "sigmoid", "identity", "clamped", "relu"), node_add_prob=0.9, conn_add_prob=0.9)
    config = neat_config(settings)
    random.seed(seed)
    genomes = list(neat.Population(config).population.values())  # the population sets up the innovation tracker
    for g in genomes:
        for _ in range(12):
            g.mutate(config.genome_config)
    return genomes, config


def test_the_compiled_forward_pass_is_neat_pythons_network() -> None:
    genomes, config = _grown_genomes(12, seed=3)
    assert any(len(g.nodes) > 4 for g in genomes)  # hidden nodes, not only the outputs
    assert {g.nodes[k].activation for g in genomes for k in g.nodes} >= {"tanh", "sigmoid", "identity"}
    obs = np.random.default_rng(0).normal(scale=2.0, size=(12, 12))
    packed = pack_networks(genomes, config)
    ours = forward(packed, np.arange(12), obs)
    for i, g in enumerate(genomes):
        theirs = neat.nn.FeedForwardNetwork.create(g, config).activate(obs[i, INPUT_INDEX].tolist())
        np.testing.assert_allclose(ours[i], theirs, rtol=1e-12, atol=1e-12)


def test_a_run_is_reproducible_from_its_seed_and_leaves_the_global_random_state_alone() -> None:
    mdp = get_task_family("ghh08").mdp("train:0")
    settings = NeatSettings(pop_size=12, episodes=2)
    random.seed(99)
    before = random.getstate()
    a = evolve_topology(mdp, budget=72, seed=1, settings=settings, n_steps=100)
    assert random.getstate() == before
    b = evolve_topology(mdp, budget=72, seed=1, settings=settings, n_steps=100)
    c = evolve_topology(mdp, budget=72, seed=2, settings=settings, n_steps=100)
    assert a.champion_fitness == b.champion_fitness and a.history == b.history
    assert a.history != c.history
    assert a.generations == 3 and a.episodes == 72 and [h["episodes"] for h in a.history] == [24, 48, 72]
    assert a.act(np.zeros((5, 12))).shape == (5, 4)
    assert a.champion_fitness == max(h["best"] for h in a.history)  # the best genome ever is the champion


def test_bad_settings_are_refused() -> None:
    mdp = get_task_family("ghh08").mdp("train:0")
    with pytest.raises(NeurohoverError, match="budget=10 is out of range"):
        evolve_topology(mdp, budget=10, settings=NeatSettings(pop_size=12))
    with pytest.raises(ValueError, match="activations"):
        NeatSettings(activations=("softplus",))
    with pytest.raises(ValueError, match="pop_size"):
        NeatSettings(pop_size=2)
    with pytest.raises(NeurohoverError, match="mdps must be"):
        evolve_topology([], budget=1000)


def test_a_genome_seeded_with_the_baseline_flies_the_baseline() -> None:
    """The whole path (the network, its inputs, the vector environment's gusts) is the kernel's: a NEAT
    genome made the baseline earns the baseline policy's returns on the same episodes."""
    config = neat_config(NeatSettings(pop_size=4, start="baseline", activations=("identity", "tanh")))
    random.seed(0)
    genome = next(iter(neat.Population(config).population.values()))
    seed_baseline(genome, config)
    packed = pack_networks([genome], config)
    mdps = [get_task_family("ghh09").mdp(f"train:{i}") for i in (0, 3)]
    ours = evaluate_callable(lambda obs: forward(packed, np.zeros(len(obs), dtype=np.int64), obs), mdps, episodes=3, seed=5, obs_dtype="float64")
    theirs = evaluate(baseline_policy(), mdps, episodes=3, seed=5)
    np.testing.assert_allclose(ours.returns, theirs.returns[0], rtol=1e-9)  # (policies, MDPs, episodes)
    assert not ours.crashed.any()
    with pytest.raises(ValueError, match="start='baseline' needs"):
        NeatSettings(start="baseline", activations=("tanh",))
