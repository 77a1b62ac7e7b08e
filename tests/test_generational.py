"""FGHH generic evolution as the authors' code ran it (docs/model.md, FGHH generics): SLPs from the
baseline, 1/ln(error) fitness averaged over a candidate's episodes, no survivors, named presets."""

from __future__ import annotations

import math

import numpy as np
import pytest

from neurohover import NeurohoverError, get_task_family
from neurohover.evaluate import PolicyTable, evaluate_jobs
from neurohover.evolution import GenerationalNE, GenerationalSettings
from neurohover.evolution.config import make_settings, upgrade_saved_config
from neurohover.evolution.evolve import evolve
from neurohover.evolution.fitness import ERROR_FLOOR, episode_fitness, error_of_fitness
from neurohover.evolution.generational import GENERATIONAL_PRESETS
from neurohover.evolution.seeding import mdp_rng, noise_seed, optimiser_seed
from neurohover.policies import prototype

FGHH = get_task_family("fghh", 0.3)


def test_one_episodes_fitness_is_one_over_the_log_of_its_error() -> None:
    r = np.array([-1e7, -1000.0, -150.0, np.nan, -0.5])
    f = episode_fitness(r, "inv-log-error")
    np.testing.assert_allclose(f[:3], [1 / math.log(1e7), 1 / math.log(1000), 1 / math.log(150)], rtol=1e-15)
    assert f[3] == -np.inf  # a numerical blow-up ranks worst
    assert f[4] == 1 / math.log(ERROR_FLOOR)  # an error below 1 is clamped (only very short episodes)
    np.testing.assert_allclose(error_of_fitness(f[:3], "inv-log-error"), [1e7, 1000, 150], rtol=1e-12)
    np.testing.assert_array_equal(episode_fitness(r[:3], "return"), r[:3])
    with pytest.raises(ValueError, match="unknown fitness scale 'log'"):
        episode_fitness(r, "log")


def test_the_defaults_are_table_7_with_the_authors_fitness_breeding_and_initial_population() -> None:
    s = GenerationalSettings()
    assert (s.pop_size, s.select_size, s.mutate_frac, s.mutate_std) == (50, 20, 0.1, 0.8)
    assert (s.fitness, s.elitist, s.init_mutate_frac, s.init_mutate_std, s.crossover_prob) == ("inv-log-error", False, 0.5, 0.5, 1.0)
    script = GENERATIONAL_PRESETS["authors-script"]
    assert (script.pop_size, script.select_size, script.mutate_frac, script.mutate_std, script.fitness) == (30, 10, 0.2, 1.0, "inv-log-error")
    old = GENERATIONAL_PRESETS["raw-elitist"]
    assert (old.fitness, old.elitist, old.init_mutate_frac) == ("return", True, None)


def test_a_preset_is_a_setting_and_its_fields_can_be_overridden() -> None:
    assert make_settings("generational", "ne", "authors-script") == GENERATIONAL_PRESETS["authors-script"]
    s = make_settings("generational", "ne", {"preset": "authors-script", "fitness": "return", "elitist": True})
    assert (s.pop_size, s.fitness, s.elitist) == (30, "return", True)
    with pytest.raises(NeurohoverError, match="unknown generational preset 'table8': allowed table7, authors-script, raw-elitist"):
        make_settings("generational", "ne", "table8")
    with pytest.raises(NeurohoverError, match="fitness='log' is not a fitness scale: allowed inv-log-error, return"):
        make_settings("generational", "ne", {"fitness": "log"})
    with pytest.raises(NeurohoverError, match="unknown steady-state setting"):
        make_settings("steady-state", "ne", {"preset": "table7"})


def test_the_initial_copies_are_mutated_with_the_initial_mutation() -> None:
    proto = prototype("slp", "baseline").genome
    wide = GenerationalNE(proto, GenerationalSettings(init_mutate_frac=1.0, init_mutate_std=0.5), seed=1).ask()
    narrow = GenerationalNE(proto, GenerationalSettings(init_mutate_frac=None, init_mutate_std=None), seed=1).ask()
    np.testing.assert_array_equal(wide[0], proto)
    assert (wide[1:] != proto).all()  # frac 1: every gene of every copy moved
    changed = (narrow[1:] != proto).mean()
    assert 0.03 < changed < 0.2  # frac 0.1 of the genes


def test_no_parent_survives_and_the_champion_is_the_best_selected_parent() -> None:
    opt = GenerationalNE(np.zeros(5), GenerationalSettings(pop_size=6, select_size=2, mutate_prob=1.0, mutate_frac=1.0), seed=0)
    pop = opt.ask()
    f = np.array([0.1, 0.9, 0.2, 0.3, 0.4, 0.5])
    opt.tell(f, selected=np.array([4, 3]))  # a race may select below the best mean
    np.testing.assert_array_equal(opt.champion_genome, pop[4])
    assert opt.champion_return == 0.4
    nxt = opt.ask()
    assert not any((nxt == row).all(axis=1).any() for row in pop)


def _flown(seed: int, k: int, settings) -> tuple[np.ndarray, np.ndarray, object]:
    """One generation over G, and every candidate's k returns flown again on its own MDPs and gusts."""
    s = dict(settings, generations=1)
    result = evolve(FGHH, resampling=f"fixed:{k}", seed=seed, n_steps=300, settings=s)
    population = GenerationalNE(prototype("slp", "baseline").genome, make_settings("generational", "ne", s), seed=optimiser_seed(seed)).ask()
    n = population.shape[0]
    rows = FGHH.sample_rows(mdp_rng(seed), n * k)  # episodes numbered column by column: candidate i flies i, n + i, ...
    jobs = np.arange(n * k)
    ev = evaluate_jobs(PolicyTable.from_genomes(population, "slp"), rows, jobs % n, jobs, jobs, seed=noise_seed(seed), n_steps=300)
    return population, ev.returns.reshape(k, n), result


@pytest.mark.parametrize("scale", ["inv-log-error", "return"])
def test_fixed_resampling_ranks_by_the_mean_episode_fitness(scale: str) -> None:
    population, returns, result = _flown(4, 3, {"fitness": scale})
    estimates = episode_fitness(returns, scale).mean(axis=0)
    best = int(np.argmax(estimates))
    assert result.champion.topology == "slp"  # the default over a family
    np.testing.assert_array_equal(result.champion.genome, population[best])
    assert result.champion_return == pytest.approx(estimates[best], rel=1e-12)
    # The two scales weigh crashes differently: they need not agree on the best candidate.
    other = episode_fitness(returns, "return" if scale != "return" else "inv-log-error").mean(axis=0)
    assert result.champion_return != pytest.approx(other[best])


def test_races_put_their_bounds_on_the_fitness_scale() -> None:
    result = evolve(FGHH, resampling="race:0.5", seed=3, n_steps=300, budget=300)
    assert 0 < result.champion_return < 1  # a mean of 1/ln(error) values, not of returns
    assert all(0 < h.champion_return < 1 for h in result.history)
    raw = evolve(FGHH, resampling="race:0.5", seed=3, n_steps=300, budget=300, settings={"fitness": "return"})
    assert raw.champion_return < 0


def test_the_topology_defaults_to_slp_over_a_family_and_mlp_on_one_mdp() -> None:
    assert evolve(FGHH, budget=50, n_steps=20, settings={"generations": 1}).champion.topology == "slp"
    assert evolve(FGHH.zero(), budget=60, n_steps=20).champion.topology == "mlp"
    assert evolve(FGHH, topology="mlp", budget=50, n_steps=20, settings={"generations": 1}).champion.topology == "mlp"


def test_a_checkpoint_written_before_the_fitness_scale_resumes_as_it_ran() -> None:
    saved = {"method": "generational", "settings": {"pop_size": 50, "select_size": 20}}
    up = upgrade_saved_config(saved)["settings"]
    assert (up["fitness"], up["elitist"], up["init_mutate_frac"]) == ("return", True, None)
    opt = GenerationalNE(np.zeros(3), GenerationalSettings(pop_size=4, select_size=2), seed=0)
    state = opt.state_dict()
    for key in ("fitness", "init_mutate_frac", "init_mutate_std", "elitist"):
        del state["settings"][key]
    old = GenerationalNE.from_state_dict(state)
    assert (old.settings.fitness, old.settings.elitist, old.settings.init_mutate_std) == ("return", True, None)


@pytest.mark.slow
def test_evolve_on_the_command_line_takes_a_preset_and_settings(tmp_path, capsys) -> None:
    import json

    from neurohover.cli import main

    out = tmp_path / "generic.json"
    args = ["evolve", "--task", "fghh", "--budget", "60", "--episode-steps", "30", "--out", str(out)]
    assert main([*args, "--preset", "authors-script", "--setting", "fitness=return", "--setting", "elitist=true"]) == 0
    saved = json.loads(out.read_text())
    assert saved["topology"] == "slp"
    settings = saved["settings"]
    assert (settings["pop_size"], settings["fitness"], settings["elitist"]) == (30, "return", True)
    assert saved["champion_fitness_scale"] == "return" and saved["champion_return"] < 0
    assert main([*args]) == 0  # the default over a family: 1/ln(error)
    saved = json.loads(out.read_text())
    assert saved["champion_fitness_scale"] == "inv-log-error" and 0 < saved["champion_return"] < 1
    capsys.readouterr()
    assert main([*args, "--setting", "fitness=log"]) == 2
    assert "fitness='log' is not a fitness scale: allowed inv-log-error, return" in capsys.readouterr().err
    assert main([*args, "--mdp", "zero", "--preset", "table7"]) == 2
    assert "applies to evolution over a family" in capsys.readouterr().err


@pytest.mark.parametrize("threads", [1, 2])
def test_how_a_race_keeps_the_lanes_busy_changes_no_result(monkeypatch, threads: int) -> None:
    """Parking (the CPU's way) and the look-ahead (elsewhere, any size) fly different episodes, and more
    than the race uses, but the race uses the same ones."""
    import neurohover.evolution.run as run_module
    from neurohover.flyer import KernelFlyer

    flown: dict = {}
    runs = [evolve(FGHH, resampling="race:0.5", seed=6, n_steps=200, budget=400, threads=threads, _flown=flown)]
    assert flown["steps"] > runs[0].steps  # the idle lanes flew later samples, some never used
    monkeypatch.setattr(KernelFlyer, "can_park", lambda self, rows: False)
    for per_thread in (1, 400):
        monkeypatch.setattr(run_module, "RACE_BATCH_PER_THREAD", per_thread)
        runs.append(evolve(FGHH, resampling="race:0.5", seed=6, n_steps=200, budget=400, threads=threads))
    a = runs[0]
    for b in runs[1:]:
        np.testing.assert_array_equal(a.champion.genome, b.champion.genome)
        assert (a.champion_return, a.episodes, a.steps, a.generations) == (b.champion_return, b.episodes, b.steps, b.generations)
        assert [h.champion_return for h in a.history] == [h.champion_return for h in b.history]


def test_configs_take_the_settings_and_refuse_bad_ones_when_loaded() -> None:
    from neurohover.experiments import load_config
    from neurohover.experiments.plans import plan

    cfg = load_config("ablation-fghh", "quick")
    by_variant = {u.key.split("/")[1]: u.params["optimiser"] for u in plan(cfg, {}).units}
    assert by_variant["raw-returns"] == {"fitness": "return"} and by_variant["script-sizes"] == {"preset": "authors-script"}
    assert {u.params["topology"] for u in plan(load_config("fig13", "paper"), {}).units} == {"slp"}
    with pytest.raises(NeurohoverError, match="optimizer: bad generational settings: fitness='bogus' is not a fitness scale"):
        load_config("fig13", "quick", {"optimizer": {"fitness": "bogus"}})
    with pytest.raises(NeurohoverError, match="unknown steady-state setting"):
        load_config("ablation-plateau", "quick", {"optimizer": {"preset": "table7"}})


def test_the_optimizer_table_has_one_spelling() -> None:
    from neurohover.experiments.config import load_config

    with pytest.raises(NeurohoverError, match="unknown setting.*optimiser.*spelled `optimizer`, as on the command line"):
        load_config("ablation-fghh", "quick", {"optimiser": {"fitness": "return"}})
    # Its settings hold the one spelling; their hash reads the table under its former name, so the
    # stores written before resume (tests/test_stored_plans.py checks every stored experiment's hash).
    cfg = load_config("ablation-fghh", "paper")
    assert "optimizer" in cfg.settings and all("optimiser" not in v for v in cfg.settings["variants"])


def _contested_numpy(fitness: np.ndarray, asked: np.ndarray, candidates: np.ndarray, n: int, t_limit: int, mu: int) -> np.ndarray:
    """The race sampler's candidate order as NumPy computed it before it was compiled."""
    mask = np.arange(t_limit)[:, None] < asked[None, :]
    fit = np.where(mask, fitness.reshape(t_limit, n), 0.0)
    count = np.maximum(asked, 1)
    with np.errstate(invalid="ignore", divide="ignore"):
        means = fit.sum(axis=0) / count
        boundary = np.sort(means)[::-1][mu - 1 : mu + 1].mean()
        var = (np.where(mask, fit - means, 0.0) ** 2).sum(axis=0) / np.maximum(count - 1, 1)
        z = np.abs(means[candidates] - boundary) / np.sqrt(var[candidates] / count[candidates])
    return candidates[np.argsort(np.nan_to_num(z, nan=np.inf), kind="stable")]


@pytest.mark.parametrize("seed", range(6))
def test_the_race_samplers_compiled_order_is_the_numpy_one(seed: int) -> None:
    """Which later samples fill idle lanes first (nearest the selection boundary first): the compiled
    order equals the NumPy form, with crashes (-inf), zero spreads and equal distances among the data."""
    from neurohover.evolution.race_sampler import _contested_order

    rng = np.random.default_rng(seed)
    n, t_limit, mu = 50, 10, 20
    fitness = np.round(rng.normal(0.12, 0.03, n * t_limit), 2)  # rounded: ties and zero spreads
    fitness[rng.random(n * t_limit) < 0.03] = -np.inf
    fitness[: 3 * n : n] = fitness[n]  # candidate 0's first samples all equal
    asked = rng.integers(2, t_limit + 1, n)
    candidates = np.flatnonzero(rng.random(n) < 0.6).astype(np.int64)
    got = _contested_order(fitness, asked, candidates, n, mu)
    np.testing.assert_array_equal(got, _contested_numpy(fitness, asked, candidates, n, t_limit, mu))
