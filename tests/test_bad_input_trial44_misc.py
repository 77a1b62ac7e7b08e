"""Trial 44, side B (Python API and files): win_probabilities with one agent's runs on an MDP given as a number or a
one-shot iterator (T44-B01); sb3_model_file given a str path (T44-B05); run_unit of an evolve unit whose params were
edited by hand (T44-B11, T44-B12); LearnedModel given an array as its method (T44-B13); settings_rows of a user's class
annotated with real types (T44-B18); default_model_substeps of no task family (T44-B20); the plumbing modules' boundary
and sole_writer given a str path (T44-B17, T44-B19)."""

from __future__ import annotations

import copy
import dataclasses
import re

import numpy as np
import pytest

import neurohover as nh
from neurohover.errors import NeurohoverError


@pytest.mark.parametrize("scores", [1.5, np.float64(1.5), np.array(1.5), None, (x for x in [1.0, 2.0]), map(float, [1.0]), reversed([1.0])])
def test_win_probabilities_refuses_runs_given_as_a_number_or_an_iterator(scores) -> None:
    """T44-B01: a number or a one-shot iterator as one agent's runs on an MDP was a TypeError "has no len()"."""
    from neurohover.experiments.wins import win_probabilities

    with pytest.raises(NeurohoverError, match=r"agent 'a' has runs on MDP 'g' given as .*: give a list of the cumulative rewards"):
        win_probabilities({"a": {"g": scores}, "b": {"g": [0.0, 3.0]}}, 2, draws=10)


def test_win_probabilities_takes_lists_arrays_and_deques() -> None:
    import collections

    from neurohover.experiments.wins import win_probabilities

    odds = win_probabilities({"a": {"g": collections.deque([1.0])}, "b": {"g": np.array([0.0, 3.0])}, "c": {"g": (2.0,)}}, 2, draws=10)
    assert sum(odds.values()) == pytest.approx(1.0)


def test_sb3_model_file_takes_a_str_path(tmp_path, monkeypatch) -> None:
    """T44-B05: a str path was an AttributeError 'is_file'."""
    from neurohover.integrations.sb3_files import sb3_model_file

    monkeypatch.chdir(tmp_path)
    (tmp_path / "model.zip").write_bytes(b"PK\x05\x06" + b"\0" * 18)
    assert sb3_model_file("model.zip").name == "model.zip"
    with pytest.raises(NeurohoverError, match="is not a Stable-Baselines3 model file"):
        sb3_model_file(str(tmp_path / "none.zip"))
    with pytest.raises(NeurohoverError, match="path=None is not allowed"):
        sb3_model_file(None)  # type: ignore[arg-type]


@pytest.mark.parametrize("method", [np.array(["lr", "lr"]), np.array("lr"), ["lr"], None])
def test_learned_model_refuses_a_method_that_is_no_text(method) -> None:
    """T44-B13: an array of two texts was NumPy's ambiguous truth value; a 0-d array was kept as an ndarray."""
    from neurohover.models import LearnedModel

    params = tuple(nh.get_task_family("fghh").zero().params)
    with pytest.raises(NeurohoverError, match="unknown model-learning method .*: allowed lr, ec-meno, ec-mer"):
        LearnedModel(params, (0.1,) * 6, method)
    assert type(LearnedModel(params, (0.1,) * 6, np.str_("lr")).method) is str


def test_settings_rows_name_real_type_annotations() -> None:
    """T44-B18: a user's settings class annotated with real types read "<class 'float'>"."""
    from neurohover.settingsdoc import settings_rows

    Mine = dataclasses.make_dataclass("Mine", [("b", float, dataclasses.field(default=2.0)), ("c", list[int] | None, dataclasses.field(default=None))])
    assert [(r.name, r.type) for r in settings_rows(Mine)] == [("b", "float"), ("c", "list[int] | None")]


def test_default_model_substeps_refuses_what_is_no_task_family() -> None:
    """T44-B20: any unknown task, None or a number was answered 10; an array was NumPy's ambiguous truth value."""
    from neurohover.models.model import DEFAULT_MODEL_SUBSTEPS, default_model_substeps

    assert default_model_substeps("fghh") == default_model_substeps(nh.get_task_family("fghh")) == 1
    assert default_model_substeps("GHH-08") == default_model_substeps(nh.get_task_family("ghh09")) == DEFAULT_MODEL_SUBSTEPS
    with pytest.raises(NeurohoverError, match="unknown task 'no-such-task': allowed ghh08, ghh09, fghh"):
        default_model_substeps("no-such-task")
    for task in (None, 5, np.array(["fghh", "ghh08"])):
        with pytest.raises(NeurohoverError, match=r"task=.* is not allowed: give a task family's name \(ghh08, ghh09, fghh\) or a TaskFamily"):
            default_model_substeps(task)  # type: ignore[arg-type]


@pytest.fixture(scope="module")
def evolve_unit():
    import neurohover.experiments as E

    u = E.plan(E.load_config("fig7", "quick"), {}).units[0]
    assert u.kind == "evolve"
    return u


@pytest.mark.parametrize(
    ("edit", "allowed"),
    [
        ({"target": None}, 'a table {"kind": "mdp"'),
        ({"target": {"kind": "mdp"}}, 'a table {"kind": "mdp"'),
        ({"target": {"kind": "bogus", "task": "ghh09"}}, 'a table {"kind": "mdp"'),
        ({"optimiser": None}, "a table (dict)"),
        ({"history_points": -1}, "an integer >= 2"),
        ({"budget": -1}, "an integer in 0..10000000000"),
        ({"seed": None}, "an integer in 0..2**63-1"),
        ({"topology": 5}, "text"),
        ({"resampling": "x"}, "fixed:K"),
        ({"validation_mdps": "train"}, "one of None, 'test'"),
    ],
)
def test_run_unit_refuses_evolve_params_edited_by_hand(evolve_unit, edit: dict, allowed: str) -> None:
    """T44-B11, T44-B12: target None was a TypeError, {'kind': 'mdp'} a KeyError, kind 'bogus' flew as a family run,
    optimiser None a TypeError, history_points -1 NumPy's error: each is refused naming the unit and the param."""
    import neurohover.experiments as E

    name = next(iter(edit))
    params = {**copy.deepcopy(evolve_unit.params), "budget": 10, "n_steps": 20, **edit}
    message = f"unit {evolve_unit.key!r}: its param {name} = "
    with pytest.raises(NeurohoverError, match=re.escape(message) + ".* is not allowed: give " + re.escape(allowed)):
        E.run_unit(E.Unit(evolve_unit.experiment, evolve_unit.key, evolve_unit.kind, params))


def test_an_evolve_units_budget_0_is_the_plateau_stop(evolve_unit) -> None:
    """T44-B12, not a bug: a unit's budget 0 is the plateau stop, as the configs' policy_budget and generic_budget 0
    plan it (evolve's own budget=None); a planned unit holds it, and run_unit takes it."""
    import neurohover.experiments as E
    from neurohover.experiments.params import EvolveParams, checked_unit_params

    unit = E.plan(E.load_config("fig7", "quick", {"policy_budget": 0}), {}).units[0]
    assert (unit.key, unit.params["budget"]) == (evolve_unit.key, 0)
    assert checked_unit_params("evolve", unit.params, unit.key).budget == 0
    assert "budget`` 0: no budget, the plateau stop" in (EvolveParams.__doc__ or "")


def test_every_planned_unit_passes_the_checks_of_run_unit() -> None:
    """The checks run_unit adds refuse no unit the planner writes (a structure check with None everywhere is
    unit_params' own, tests/test_experiment_settings.py)."""
    from neurohover.experiments import load_config, plan
    from neurohover.experiments.params import PARAMS, checked_unit_params

    kinds = set()
    for name in ("fig7", "fig11", "table4", "fig13", "ablation-fghh"):
        cfg = load_config(name, "quick")
        for unit in plan(load_config(name, "quick", {"policies": "shipped"}) if cfg.kind == "test_runs" else cfg, {}, {}).units:
            if unit.kind in PARAMS:
                checked_unit_params(unit.kind, unit.params, unit.key)
                kinds.add(unit.kind)
    assert kinds >= {"evolve", "test_run"}


PLUMBING = ("paths", "filekinds", "jsontext", "locks", "compete_labels", "evolution.state_codec", "experiments.keys", "models.model_checks")
INTERNAL_HELPERS = (
    ("experiments.results", "num"),
    ("models.model", "check_stats"),
    ("integrations.neat", "pack_networks"),
)


def test_the_plumbing_says_it_is_internal_as_the_readme_says() -> None:
    """T44-B17, T44-B19, not bugs: these helpers are neurohover's plumbing, called with checked values (None, NaN and
    the like reach them from no public call). README's Python API section says where the public boundary is, and each
    plumbing module and helper says "Internal:"."""
    import importlib
    from pathlib import Path

    readme = " ".join((Path(__file__).parents[1] / "README.md").read_text(encoding="utf-8").split())
    section = readme[readme.index("**What is public.**") :].split("## ")[0]
    for name in PLUMBING:
        assert "Internal:" in (importlib.import_module(f"neurohover.{name}").__doc__ or ""), name
        assert f"`.{name}`" in section or f"`neurohover.{name}`" in section, name
    for module, helper in INTERNAL_HELPERS:
        assert "Internal:" in (getattr(importlib.import_module(f"neurohover.{module}"), helper).__doc__ or ""), helper
        assert f"`{module}.{helper}`" in section, helper


def test_sole_writer_takes_a_str_path(tmp_path, monkeypatch) -> None:
    """T44-B19: locks.sole_writer given a str path was an AttributeError 'with_name' (every path-taking function takes
    a str or a path object)."""
    from neurohover.locks import sole_writer

    monkeypatch.chdir(tmp_path)
    with sole_writer("out.json", "--out"):
        assert (tmp_path / ".out.json.lock").exists()
        with pytest.raises(NeurohoverError, match="--out '.*out.json' is being written by another run"):
            with sole_writer(str(tmp_path / "out.json"), "--out"):
                pass
