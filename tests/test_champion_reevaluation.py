"""The champion chosen again (issue 32): the last generation's parents flown the same fresh episodes, the best mean
kept; kept in checkpoints; stored beside the run's own champion by an experiment's evolve units."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

from neurohover.errors import NeurohoverError
from neurohover.evolution.evolve import evolve, reevaluated_champion
from neurohover.evolution.fitness import episode_fitness
from neurohover.evolution.generational import GenerationalNE, GenerationalSettings
from neurohover.experiments.config import load_config, make_config
from neurohover.experiments.plans import plan
from neurohover.experiments.results import EvolveResult
from neurohover.experiments.units import family_of, run_evolve
from neurohover.policies import prototype
from neurohover.tasks import get_task_family

FAMILY = family_of("fghh", 0.3, None)


@pytest.fixture(scope="module")
def race_run():
    return evolve(FAMILY, topology="slp", prototype="baseline", resampling="race:0.5", budget=1200, seed=3, n_steps=80)


def test_the_champion_chosen_again_is_the_parent_of_best_mean_on_shared_fresh_episodes(race_run) -> None:
    assert race_run.parents is not None and race_run.parents.shape == (20, race_run.champion.genome.size)
    assert any(np.array_equal(p, race_run.champion.genome) for p in race_run.parents)  # the run's champion is a parent
    policy, means = reevaluated_champion(race_run, FAMILY, episodes=6, n_steps=80)
    best = int(np.argmax(means))
    assert policy.metadata["reevaluated_from"] == best and np.array_equal(policy.genome, race_run.parents[best])
    one_thread, means_one = reevaluated_champion(race_run, FAMILY, episodes=6, n_steps=80, threads=1)
    assert np.array_equal(one_thread.genome, policy.genome) and np.array_equal(means_one, means)
    assert np.all(np.isfinite(means)) and np.all(means > 0)  # the run's 1/ln(error) scale
    # every parent flew the same MDPs and gusts: two identical parents get the same mean
    twins = dataclasses.replace(race_run, parents=np.vstack([race_run.parents[:1], race_run.parents[:1]]))
    twin_means = reevaluated_champion(twins, FAMILY, episodes=6, n_steps=80)[1]
    assert twin_means[0] == twin_means[1] == means[0]
    # among the run's best generation champions: its own champion's estimate is the best of them, first
    hall = race_run.hall_of_fame
    assert hall is not None and 1 <= len(hall) <= 20 and any(np.array_equal(h, race_run.champion.genome) for h in hall)
    best_ever, hall_means = reevaluated_champion(race_run, FAMILY, episodes=6, n_steps=80, among="best-ever")
    assert len(hall_means) == len(hall) and np.array_equal(best_ever.genome, hall[int(np.argmax(hall_means))])
    with pytest.raises(NeurohoverError, match="among='worst' is not allowed: choose one of last, best-ever"):
        reevaluated_champion(race_run, FAMILY, episodes=6, among="worst")


def test_a_steady_state_run_has_no_parents_to_choose_from() -> None:
    mdp = get_task_family("ghh08").training_mdps()[0]
    run = evolve(mdp, topology="slp", prototype="baseline", budget=60, seed=1, n_steps=50)
    assert run.parents is None
    with pytest.raises(NeurohoverError, match="no selected parents to choose from again"):
        reevaluated_champion(run, mdp, episodes=3)


def test_bad_episode_counts_are_refused(race_run) -> None:
    for bad, problem in ((0, "is out of range"), (-1, "is out of range"), (2.5, "is not allowed"), (True, "is not allowed")):  # a type is no range (T24-11)
        with pytest.raises(NeurohoverError, match=f"episodes=.* {problem}: allowed an integer in 1..100,000,000"):
            reevaluated_champion(race_run, FAMILY, episodes=bad)


def test_the_parents_survive_a_checkpoint_and_older_checkpoints_load() -> None:
    opt = GenerationalNE(prototype("slp", "baseline").genome, GenerationalSettings(pop_size=25, select_size=20))
    population = opt.ask()
    opt.tell(np.arange(population.shape[0], dtype=float))  # the 20 best estimates: the last 20 candidates
    assert np.array_equal(opt.parents, population[np.arange(24, 4, -1)])
    state = json.loads(json.dumps(opt.state_dict()))
    restored = GenerationalNE.from_state_dict(state)
    assert np.array_equal(restored.parents, opt.parents) and np.array_equal(restored.hall_of_fame, opt.hall_of_fame)
    assert np.array_equal(opt.hall_of_fame, [population[24]])  # the generation's champion: the best estimate
    state.pop("parents")  # a checkpoint written before the parents were kept
    state.pop("hall_of_fame")
    assert GenerationalNE.from_state_dict(state).parents is None and GenerationalNE.from_state_dict(state).hall_of_fame is None


def test_fig15_champion_is_figure_15s_runs_again_with_the_champion_chosen_again() -> None:
    mine = {u.key: u.params for u in plan(load_config("fig15-champion", "paper"), {}).units}
    fig15 = {u.key: u.params for u in plan(load_config("fig15", "paper"), {}).units}
    assert len(mine) == 48
    for key, params in mine.items():
        assert {k: v for k, v in params.items() if k != "champion_reevaluation"} == fig15[key] and params["champion_reevaluation"] == 50
    base = {"task": "ghh08", "seed": 1, "target": "train", "runs": 1, "champion_reevaluation": 5, "variants": [{"key": "a", "label": "a"}]}
    with pytest.raises(NeurohoverError, match="champion_reevaluation chooses among a generational run's parents: it needs target = 'family'"):
        make_config("x", "evolution", "quick", base)


def test_an_evolve_unit_stores_the_champion_chosen_again_validated_as_its_own() -> None:
    cfg = load_config("fig15-champion", "quick", {"budget": 300, "n_steps": 40, "validation_episodes": 4, "champion_reevaluation": 3})
    unit = next(u for u in plan(cfg, {}).units if u.key == "evolve/race0.5/run0")
    stored = run_evolve(unit.params, threads=1)
    result = EvolveResult.from_dict(json.loads(json.dumps(stored)))
    again, best_ever = result.reevaluated, result.reevaluated_best_ever
    assert again is not None and again.episodes == 3 and 0 <= again.parent < 20
    assert best_ever is not None and best_ever.episodes == 3 and 0 <= best_ever.parent < 20
    assert len(again.validation) == len(best_ever.validation) == len(result.validation) == 4 and len(again.validation_crashed) == 4
    # its validation is the stored policy flown on the run's validation episodes, as the run's own champion was
    fitness = episode_fitness(np.array([float(x) for x in again.validation]), "inv-log-error")
    assert np.all(np.isfinite(fitness))
    older = {k: v for k, v in stored.items() if not k.startswith("reevaluated")}  # a store written before the setting
    assert EvolveResult.from_dict(older).reevaluated is None and EvolveResult.from_dict(older).to_dict() == older
