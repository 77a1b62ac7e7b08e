"""Bad-input trial 48, side B: T48-B03 (a model file's stats.n_transitions past its n_episodes x MAX_EPISODE_STEPS,
10**30 and 2**63 included, was loaded and saved back), T48-B04 (CMAES and the other optimisers that take a prototype
evolved one whose genes were past a Policy's MAX_GENE, 1e300 genomes refused only when the champion became a Policy) and
T48-B07 (evaluate_jobs blamed episode_index=[0, 2**63] on its dtype float64, NumPy's, where [2**63] named the value)."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest

import neurohover as nh
from neurohover.errors import NeurohoverError, brief
from neurohover.evolution import CMAES, GenerationalNE, SteadyStateNE
from neurohover.evolution.optimisers.openai_es import OpenAIES
from neurohover.evolution.optimisers.uh_cma import UHCMAES
from neurohover.models import LearnedModel, learn_lr
from neurohover.sim.constants import MAX_EPISODE_STEPS


@pytest.fixture(scope="module")
def lr_file(tmp_path_factory) -> dict:
    """An LR model's file, as a dict to edit: learned from 3 baseline episodes of 200 steps on GHH-08's zero MDP."""
    zero = nh.get_task_family("ghh08").zero()
    flight = nh.evaluate(nh.baseline_policy(), [zero] * 3, record=True, seed=1, n_steps=200).flight_data
    path = learn_lr(flight).save(tmp_path_factory.mktemp("models") / "lr.json")
    return json.loads(path.read_text())


def _load(d: dict, tmp_path: Path) -> LearnedModel:
    path = tmp_path / "m.json"
    path.write_text(json.dumps(d))
    return LearnedModel.load(path)


@pytest.mark.parametrize("n", [3 * MAX_EPISODE_STEPS + 1, 10**8, 10**30, 2**63])
def test_more_transitions_than_the_episodes_hold_are_refused(lr_file: dict, tmp_path: Path, n: int) -> None:
    """T48-B03: n_transitions past n_episodes x MAX_EPISODE_STEPS is refused, naming both."""
    assert lr_file["stats"]["n_episodes"] == 3
    d = json.loads(json.dumps(lr_file))
    d["stats"]["n_transitions"] = n
    with pytest.raises(NeurohoverError, match=re.escape(f"its stats.n_transitions {brief(n)} is not allowed: ") + r".*\.\.30,000,000 \(its 3 episodes"):
        _load(d, tmp_path)


def test_transitions_up_to_the_episodes_bound_load(lr_file: dict, tmp_path: Path) -> None:
    d = json.loads(json.dumps(lr_file))
    d["stats"]["n_transitions"] = 3 * MAX_EPISODE_STEPS
    assert _load(d, tmp_path).stats["n_transitions"] == 3 * MAX_EPISODE_STEPS
    assert _load(lr_file, tmp_path).stats == lr_file["stats"]


@pytest.mark.parametrize("make", [lambda p: CMAES(p, popsize=4), lambda p: UHCMAES(p, None), OpenAIES, GenerationalNE, SteadyStateNE])
@pytest.mark.parametrize("gene", [1e300, -1.5e120])
def test_a_prototype_no_policy_holds_is_refused(make, gene: float) -> None:
    """T48-B04: a prototype gene past MAX_GENE (1e120) is refused by every optimiser that takes a prototype."""
    prototype = np.zeros(40)
    prototype[7] = gene
    fragment = f"prototype holds a gene that is out of range: gene 7 is {gene:g}; allowed numbers in [-1e+120, 1e+120]"
    with pytest.raises(NeurohoverError, match=re.escape(fragment)):
        make(prototype)


def test_a_prototype_at_the_bound_is_taken() -> None:
    c = CMAES(np.full(40, 1e120), popsize=4)
    assert c.ask().shape[0] == 4


@pytest.mark.parametrize(("episodes", "named"), [([0, 2**63], 2**63), ((0, 2**63), 2**63), ([-1, 2**63], 2**63), ([0, 2**64], 2**64), ([2**63], 2**63)])
def test_an_index_list_numpy_makes_float_names_its_wide_integer(episodes, named: int) -> None:
    """T48-B07: [0, 2**63] became float64 in NumPy and was blamed on its dtype; the value is named as for [2**63]."""
    ms = nh.get_task_family("ghh08").training_mdps()[:1]
    n = len(episodes)
    with pytest.raises(NeurohoverError, match=re.escape(f"episode_index holds {named}, out of range: allowed 0..2**63-1")):
        nh.evaluate_jobs([nh.baseline_policy()], ms, [0] * n, [0] * n, episodes, n_steps=5)


def test_a_float_index_list_is_still_blamed_on_its_dtype() -> None:
    ms = nh.get_task_family("ghh08").training_mdps()[:1]
    with pytest.raises(NeurohoverError, match="episode_index must hold integers, got dtype float64"):
        nh.evaluate_jobs([nh.baseline_policy()], ms, [0, 0], [0, 0], [0.0, 1e19], n_steps=5)
