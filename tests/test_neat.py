"""Topology evolution with neat-python (neurohover.integrations.neat; issue 35): the compiled forward pass is
neat-python's network, and a run is reproducible from its seed. Skipped where neat-python is not installed."""

from __future__ import annotations

import random
from pathlib import Path

import numpy as np
import pytest

neat = pytest.importorskip("neat", reason="neat-python is not installed (a dependency: pip install neat-python)")

from neurohover import NeurohoverError, baseline_policy, evaluate, get_task_family  # noqa: E402  # noqa: E402
from neurohover.evolution.evolve import validation_return  # noqa: E402
from neurohover.experiments.config import load_config  # noqa: E402
from neurohover.experiments.plans import plan  # noqa: E402
from neurohover.experiments.results import UnitKey  # noqa: E402
from neurohover.experiments.units import run_unit  # noqa: E402
from neurohover.integrations.flying import evaluate_callable  # noqa: E402
from neurohover.integrations.neat import (  # noqa: E402
    INPUT_INDEX,
    NeatSettings,
    evolve_topology,
    forward,
    genome_record,
    neat_config,
    network_of_record,
    pack_networks,
    seed_baseline,
)


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


@pytest.mark.slow
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


def test_a_stored_record_flies_as_the_genome_it_was_made_of() -> None:
    genomes, config = _grown_genomes(8, seed=4)
    obs = np.random.default_rng(1).normal(scale=2.0, size=(8, 12))
    direct = forward(pack_networks(genomes, config), np.arange(8), obs)
    for i, g in enumerate(genomes):
        again = forward(network_of_record(genome_record(g)), np.zeros(1, dtype=np.int64), obs[i : i + 1])
        np.testing.assert_array_equal(again[0], direct[i])
    with pytest.raises(NeurohoverError, match="does not hold"):
        network_of_record([2.0, 0.0, 0.1])


def test_a_run_over_a_task_family_draws_fresh_mdps_and_scores_on_the_fitness_scale() -> None:
    family = get_task_family("fghh", 0.3)
    settings = NeatSettings(pop_size=6, episodes=2, fitness="inv-log-error", start="baseline", activations=("identity", "tanh"))
    a = evolve_topology(family, budget=24, seed=3, settings=settings, n_steps=60)
    b = evolve_topology(family, budget=24, seed=3, settings=settings, n_steps=60)
    assert a.history == b.history and a.generations == 2
    assert all(0.0 < h["best"] < 1.0 for h in a.history)  # 1/ln(error) of errors above e, not raw returns
    with pytest.raises(ValueError, match="fitness="):
        NeatSettings(fitness="median")


def test_a_neat_variant_pairs_with_the_mlp_runs_and_its_ne_variants_are_fig2s_runs() -> None:
    """topology-ghh08: its NE variants are planned with fig2's params and seeds (so they are fig2's runs again) and
    each NEAT run takes the seed of fig2's MLP run on the same MDP, so it meets that champion's validation episodes."""
    mine = {u.key: u.params for u in plan(load_config("topology-ghh08", "quick"), {}).units}
    fig2 = {u.key: u.params for u in plan(load_config("fig2", "quick"), {}).units}
    ne = [k for k in mine if "/neat" not in k]
    assert ne and all(mine[k] == fig2[k] for k in ne)
    for k in (k for k in mine if "/neat" in k):
        key = UnitKey.parse(k)
        assert mine[k]["seed"] == fig2[UnitKey.make("evolve", "mlp-baseline", key.mdp, key.rep)]["seed"]
        assert mine[k]["topology"] == "neat" and mine[k]["optimiser"]["name"] == "neat"


def test_a_neat_unit_validates_on_the_episodes_of_the_champion_it_is_paired_with() -> None:
    """A NEAT unit's champion made the baseline (no generation can beat it: the mutations are zero-sized) flies
    the validation episodes the baseline flies through validation_return with the same seed: the same MDP and gusts."""
    mdp = get_task_family("ghh08").mdp("train:1")
    frozen = {"start": "baseline", "activations": ["identity"], "weight_mutate_rate": 0.0, "bias_mutate_rate_unused": None}
    frozen.pop("bias_mutate_rate_unused")
    params = {
        "target": {"kind": "mdp", "mdp": mdp.to_dict()}, "topology": "neat", "prototype": "baseline", "resampling": "fixed:1", "budget": 8,
        "optimiser": {"name": "neat", "pop_size": 4, "node_add_prob": 0.0, "conn_add_prob": 0.0, "conn_delete_prob": 0.0, "node_delete_prob": 0.0,
                      "bias_mutate_power": 1e-300, "replace_rate": 0.0, "activation_mutate_rate": 0.0, **frozen},
        "n_steps": 80, "validation_episodes": 3, "seed": 17,
    }  # fmt: skip
    result = run_unit({"experiment": "t", "key": "evolve/neat/train1/run0", "kind": "evolve", "params": params}, threads=1)
    expected = validation_return(baseline_policy(), mdp, episodes=3, seed=17, n_steps=80)
    np.testing.assert_allclose([float(x) for x in result["validation"]], expected, rtol=1e-9)
    assert result["champion"]["topology"] == "neat" and result["episodes"] == 8 and result["validation_crashed"] == [False] * 3


@pytest.mark.parametrize(
    ("variant", "message"),
    [
        ('topology = "neat"\nneat = { pop_size = 1 }', "pop_size=1"),
        ('topology = "neat"\nneat = { colour = 1 }', "unknown NEAT setting"),
        ('topology = "mlp"\nneat = { pop_size = 10 }', "neat applies to topology = 'neat'"),
        ('topology = "neat"\nresampling = "fixed:5"', "takes no resampling"),
        ('topology = "neat"\nprototype = "zero"', "prototype = 'zero' does nothing for topology = 'neat'"),  # was ignored (bad-input trial)
    ],
)
def test_bad_neat_variants_are_refused_when_the_config_loads(tmp_path: Path, variant: str, message: str) -> None:
    path = tmp_path / "neat-bad.toml"
    path.write_text(
        'name = "neat-bad"\ntitle = "t"\nkind = "evolution"\n[settings]\ntask = "ghh08"\nseed = 1\ntarget = "train"\n'
        f'[[settings.variants]]\nkey = "x"\nlabel = "x"\n{variant}\n[scales.quick]\nbudget = 600\nruns = 1\n[scales.paper]\nbudget = 600\nruns = 1\n'
    )
    with pytest.raises(NeurohoverError, match=message):
        load_config(str(path), "quick")


def test_a_neat_run_over_the_family_must_be_validated_on_its_test_mdps(tmp_path: Path) -> None:
    path = tmp_path / "neat-family.toml"
    path.write_text(
        'name = "neat-family"\ntitle = "t"\nkind = "evolution"\n[settings]\ntask = "fghh"\nsigma = 0.3\nseed = 1\ntarget = "family"\n'
        '[[settings.variants]]\nkey = "x"\nlabel = "x"\ntopology = "neat"\n[scales.quick]\nbudget = 600\nruns = 1\n[scales.paper]\nbudget = 600\nruns = 1\n'
    )
    with pytest.raises(NeurohoverError, match="validation_mdps = 'test'"):
        load_config(str(path), "quick")


@pytest.mark.slow
def test_the_report_pairs_each_neat_run_with_the_mlp_run_of_its_seed(tmp_path: Path) -> None:
    """A NEAT variant paired with an NE variant of the same experiment: the section's paired block tests the run pairs
    (same MDP, seed and validation episodes) by Wilcoxon, with the p-value scipy gives on the stored returns."""
    from scipy import stats

    from neurohover.experiments.executors import make_executor
    from neurohover.experiments.report import write_report
    from neurohover.experiments.runner import reproduce
    from neurohover.experiments.store import Store

    path = tmp_path / "pair.toml"
    path.write_text(
        'name = "pair"\ntitle = "pair"\nkind = "evolution"\n[settings]\ntask = "ghh08"\nseed = 3\ntarget = "train"\nvalidation_episodes = 2\n'
        'seeds_of = { experiment = "pair", seed = 3 }\n'  # its own runs' seeds: the NEAT run r on MDP i takes the MLP run's
        '[[settings.variants]]\nkey = "mlp"\nlabel = "MLP"\ntopology = "mlp"\n'
        '[[settings.variants]]\nkey = "net"\nlabel = "NEAT"\ntopology = "neat"\npaired_with = "mlp"\n'
        'neat = { pop_size = 4, start = "baseline", activations = ["identity", "tanh"], weight_mutate_power = 0.02 }\n'
        "[scales.quick]\nn_mdps = 2\nruns = 2\nbudget = 8\nn_steps = 40\n[scales.paper]\nruns = 1\nbudget = 8\n"
    )
    with Store(tmp_path / "s.sqlite") as store:
        executor = make_executor("local", jobs=1)
        try:
            reproduce(load_config(str(path), "quick"), store, executor, progress=False)
        finally:
            executor.close()
        results = {u["key"]: u["result"] for u in store.units("pair", "quick")}
        write_report(store, tmp_path / "out", scale="quick", names=["pair"])
    report = (tmp_path / "out" / "report.md").read_text()
    pairs = [(f"train{i}", f"run{r}") for i in range(2) for r in range(2)]
    diff = [np.mean(results[f"evolve/net/{m}/{r}"]["validation"]) - np.mean(results[f"evolve/mlp/{m}/{r}"]["validation"]) for m, r in pairs]
    block = report[report.index("### Paired runs") :]
    row = next(line for line in block.splitlines() if line.startswith("| NEAT | MLP |"))
    cells = [c.strip() for c in row.strip("|").split("|")]
    assert cells[2] == "4" and cells[5] == f"{sum(d > 0 for d in diff)} of 4"
    assert float(cells[7]) == pytest.approx(stats.wilcoxon(diff).pvalue if any(diff) else 1.0, rel=1e-3)


def test_a_neat_variant_whose_budget_is_below_one_generation_is_refused_when_the_config_loads(tmp_path: Path) -> None:
    path = tmp_path / "neat-budget.toml"
    path.write_text(
        'name = "neat-budget"\ntitle = "t"\nkind = "evolution"\n[settings]\ntask = "ghh08"\nseed = 1\ntarget = "train"\n'
        '[[settings.variants]]\nkey = "x"\nlabel = "x"\ntopology = "neat"\nneat = { pop_size = 10, episodes = 2 }\n'
        "[scales.quick]\nbudget = 19\nruns = 1\n[scales.paper]\nbudget = 20\nruns = 1\n"
    )
    with pytest.raises(NeurohoverError, match=r"budget = 19 is below one NEAT generation \(10 genomes x 2 episodes = 20\)"):
        load_config(str(path), "quick")


def test_neat_refuses_what_neat_python_would_fail_on_later() -> None:
    mdp = get_task_family("ghh08").mdp("train:0")
    for bad in ({"node_add_prob": True}, {"weight_mutate_power": 1e308}, {"pop_size": 10**12}, {"activations": ("tanh", "tanh")}):
        with pytest.raises(NeurohoverError):
            NeatSettings.of(bad)
    with pytest.raises(NeurohoverError, match="seed=-1 is out of range"):
        evolve_topology(get_task_family("ghh08"), budget=4, seed=-1, settings={"pop_size": 4}, n_steps=20)
    with pytest.raises(NeurohoverError, match="neat-python stopped the run"):  # more species than the population holds
        evolve_topology(mdp, budget=50, seed=0, settings=NeatSettings(pop_size=10, compatibility_threshold=0.01), n_steps=20)
    assert evolve_topology(mdp, budget=8, seed=0, settings={"pop_size": 4}, n_steps=20).episodes == 8  # a dict of settings
