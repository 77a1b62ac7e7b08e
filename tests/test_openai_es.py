"""OpenAI-ES: the optimiser on its own, and through the registry in evolve, the CLI and experiment configs."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import neurohover as nh
from neurohover.evolution.evolve import EvolutionInterrupted, evolve
from neurohover.evolution.optimisers import OPTIMISERS, optimiser_names
from neurohover.evolution.optimisers.openai_es import OpenAIES, OpenAIESSettings, centred_ranks

GHH08 = nh.get_task_family("ghh08")
FGHH = nh.get_task_family("fghh")


def test_centred_ranks_keep_only_the_order_and_put_nan_last() -> None:
    shaped = centred_ranks(np.array([-5.0, np.nan, -1.0, -1e9, -np.inf]))
    np.testing.assert_allclose(shaped, [0.25, -0.25, 0.5, 0.0, -0.5])  # NaN ties -inf at the bottom, in order


def test_ask_gives_antithetic_pairs_around_the_mean() -> None:
    opt = OpenAIES(np.arange(5.0), OpenAIESSettings(popsize=6, sigma=0.1), seed=1)
    genomes = opt.ask()
    assert genomes.shape == (6, 5)
    np.testing.assert_allclose((genomes[:3] + genomes[3:]) / 2, np.tile(np.arange(5.0), (3, 1)))
    np.testing.assert_array_equal(opt.ask(), genomes)  # asked again before tell: the same generation


def test_it_climbs_a_quadratic_and_the_champion_is_the_best_return_told() -> None:
    target = np.array([1.0, -2.0, 0.5, 3.0])
    opt = OpenAIES(np.zeros(4), OpenAIESSettings(popsize=20, sigma=0.1, learning_rate=0.05, l2=0.0), seed=3)
    told = []
    for _ in range(300):
        genomes = opt.ask()
        returns = -((genomes - target) ** 2).sum(axis=1)
        told.append(returns.max())
        opt.tell(returns)
    assert np.linalg.norm(opt.mean - target) < 0.05 * np.linalg.norm(target)
    assert opt.champion_return == max(told) and opt.evaluations == 300 * 20
    assert -((opt.champion_genome - target) ** 2).sum() == opt.champion_return


def test_state_dict_between_ask_and_tell_continues_bit_for_bit() -> None:
    def run(opt: OpenAIES, generations: int) -> list[np.ndarray]:
        out = []
        for _ in range(generations):
            g = opt.ask()
            opt.tell(-np.abs(g).sum(axis=1))
            out.append(opt.mean.copy())
        return out

    a = OpenAIES(np.ones(6), seed=9)
    run(a, 3)
    a.ask()
    b = OpenAIES.from_state_dict(json.loads(json.dumps(a.state_dict())))
    for x, y in zip(run(a, 4), run(b, 4)):
        np.testing.assert_array_equal(x, y)
    assert a.champion_return == b.champion_return


@pytest.mark.parametrize(
    ("settings", "message"),
    [({"popsize": 5}, "must be even"), ({"sigma": 0}, "sigma=0.0 must be a finite number >= 1e-100"), ({"beta1": 1.0}, r"beta1=1.0 must be in \[0, 1\)")],
)
def test_bad_settings_are_refused_naming_the_value(settings: dict, message: str) -> None:
    with pytest.raises(nh.NeurohoverError, match=message):
        evolve(GHH08.mdp("train:0"), optimizer="openai-es", settings=settings, budget=10)


def test_the_registry_finds_it_and_evolve_needs_a_budget_for_it() -> None:
    assert optimiser_names() == ("ne", "cma", "openai-es", "uh-cma") and not OPTIMISERS["openai-es"].stops_itself
    with pytest.raises(nh.NeurohoverError, match="'openai-es' has no stopping rule of its own: give a budget"):
        evolve(GHH08.mdp("train:0"), optimizer="openai-es")
    with pytest.raises(nh.NeurohoverError, match="unknown openai-es setting.*sigma0.*allowed popsize"):
        evolve(GHH08.mdp("train:0"), optimizer="openai-es", settings={"sigma0": 0.1}, budget=10)


@pytest.mark.parametrize("target", [GHH08.mdp("train:1"), FGHH], ids=["mdp", "family"])
def test_evolve_improves_on_the_baseline_and_resumes_bit_for_bit(tmp_path: Path, target) -> None:
    common = dict(topology="slp", optimizer="openai-es", seed=3, n_steps=300, resampling="fixed:2" if target is FGHH else None)
    full = evolve(target, budget=600, **common)
    assert full.stop_reason == "budget" and 600 <= full.episodes < 600 + 20 * 2
    assert full.champion.metadata["method"] == "openai-es" and full.settings["method"] == "openai-es"
    if target is not FGHH:
        base = nh.evaluate(nh.prototype("slp", "baseline"), target, episodes=10, seed=5, n_steps=300).returns.mean()
        assert nh.evaluate(full.champion, target, episodes=10, seed=5, n_steps=300).returns.mean() > 0.5 * base
    ckpt = tmp_path / "run.checkpoint.json"

    def stop_midway(info) -> None:
        if info.episodes >= 250 and not info.done:
            raise KeyboardInterrupt

    with pytest.raises(EvolutionInterrupted):
        evolve(target, budget=600, checkpoint=ckpt, progress=stop_midway, progress_every_s=0, **common)
    resumed = evolve(target, budget=600, checkpoint=ckpt, resume=True, **common)
    np.testing.assert_array_equal(resumed.champion.genome, full.champion.genome)
    assert resumed.champion_return == full.champion_return and resumed.episodes == full.episodes


def test_the_cli_takes_it_under_either_spelling(tmp_path: Path, capsys) -> None:
    from neurohover.cli import main

    out = tmp_path / "p.json"
    args = ["evolve", "--task", "ghh08", "--mdp", "train:0", "--budget", "100", "--seed", "1", "--out", str(out), "--json"]
    assert main([*args, "--optimizer", "openai-es", "--setting", "popsize=10"]) == 0
    summary = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert summary["stop_reason"] == "budget" and nh.load_policy(out).metadata["method"] == "openai-es"
    assert main([*args, "--optimizer", "openai-es", "--setting", "popsize=7"]) == 2
    assert "popsize=7 must be even" in capsys.readouterr().err


def test_an_experiment_config_chooses_it_per_variant(tmp_path: Path) -> None:
    from neurohover.experiments import Store, load_config, make_executor, reproduce

    config = tmp_path / "es.toml"
    config.write_text(
        """
name = "estest"
kind = "evolution"
[settings]
task = "ghh08"
target = "train"
n_mdps = 1
runs = 1
budget = 60
n_steps = 100
seed = 4
optimizer = { mutate_std = 0.5 }
variants = [
  { key = "ne", label = "steady-state NE", topology = "slp" },
  { key = "es", label = "OpenAI-ES", topology = "slp", optimizer = { name = "openai-es", popsize = 10 } },
]
[scales.quick]
"""
    )
    cfg = load_config(config, "quick")
    with Store(tmp_path / "s.sqlite") as store:
        reproduce(cfg, store, make_executor("local", jobs=1))
        results = store.results("estest", "quick")
    es, ne = results["evolve/es/train0/run0"], results["evolve/ne/train0/run0"]
    assert es["champion"]["genome"] != ne["champion"]["genome"] and es["episodes"] == 60
    bad = config.read_text().replace('name = "openai-es", popsize = 10', 'name = "openai-es", popsize = 11')
    config.write_text(bad)
    with pytest.raises(nh.NeurohoverError, match="variant 'es'.*popsize=11 must be even"):
        load_config(config, "quick")


def test_build_policies_takes_it_for_every_run_but_fghhs_race(tmp_path: Path) -> None:
    from neurohover.policysets import build_policy_set

    ps = build_policy_set("fghh", tmp_path, budget=40, fghh_budget=40, n_steps=50, optimizer="openai-es")
    assert ps.manifest["optimizer"] == "openai-es"
    assert {k: p.metadata["method"] for k, p in ps.generics.items()} == {"zero": "openai-es", "fixed": "openai-es", "race": "generational"}
    with pytest.raises(nh.NeurohoverError, match="unknown optimizer 'adam'"):
        build_policy_set("ghh08", tmp_path, budget=10, optimizer="adam")
