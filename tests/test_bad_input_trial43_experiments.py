"""Bad-input trial 43, side B (the Python API): experiment configs and their helpers. load_config(overrides=...) refused
NumPy integers for every integer setting (``seed = np.int64(3)``), where evaluate, evolve and the agents take them
(T43-B11: taken, stored as Python numbers); unit_seed with a lone surrogate was encode()'s UnicodeEncodeError (T43-B12:
refused as the store refuses one); ExperimentConfig.settings could be edited after load_config, runs=-1 was max()'s
ValueError in plan and runs=1 was honoured or ignored as the cached typed view had been read or not (T43-B13: the settings
are read-only, an edit refused by name); compete's and manifest's helpers took None or mismatched tables (T43-B15:
table3_summary, genome_digest and check_agent_settings check them; summarise and episode_rows are compete's internals)."""

from __future__ import annotations

import copy
import json
import pickle
import re
from dataclasses import replace

import numpy as np
import pytest

import neurohover.compete as C
import neurohover.experiments as X
from neurohover.errors import NeurohoverError
from neurohover.experiments.config import ExperimentConfig, make_config
from neurohover.manifest import genome_digest, table3_summary

INTEGERS = {"seed": 3, "n_steps": 150, "n_mdps": 2, "runs": 1, "budget": 400, "validation_episodes": 2, "history_points": 5, "robustness_episodes": 2}


# ----------------------------------------------------------------------------------------------- T43-B11


@pytest.mark.parametrize("key", sorted(INTEGERS))
def test_load_config_takes_numpy_integers_as_python_ints(key: str) -> None:
    """T43-B11: each integer setting given as a NumPy integer is the config of the Python int, stored as one (JSON)."""
    given = X.load_config("fig2", "quick", overrides={key: np.int64(INTEGERS[key])})
    assert type(given.settings[key]) is int and given.settings[key] == INTEGERS[key]
    assert given.hash == X.load_config("fig2", "quick", overrides={key: INTEGERS[key]}).hash
    json.dumps(given.to_dict())


def test_numpy_scalars_of_every_width_and_in_tables() -> None:
    """T43-B11: np.int32 and np.uint16 too, a NumPy float where a number is wanted, and NumPy integers in a group's table."""
    cfg = X.load_config("fig2", "quick", overrides={"seed": np.uint16(3), "runs": np.int32(1)})
    assert (cfg.settings["seed"], cfg.settings["runs"]) == (3, 1) and X.plan(cfg, {}).total == 14
    fig13 = X.load_config("fig13", "quick")
    own = copy.deepcopy(fig13.settings)
    own["variants"][0]["sigma"] = np.float32(0.25)
    mine = make_config("my-fig13", "evolution", "quick", own)
    assert type(mine.settings["variants"][0]["sigma"]) is float and mine.settings["variants"][0]["sigma"] == 0.25
    fig7 = copy.deepcopy(X.load_config("fig7", "quick").settings)
    fig7["groups"][0]["n_mdps"] = np.int64(2)
    assert type(make_config("my-fig7", "test_runs", "quick", fig7).settings["groups"][0]["n_mdps"]) is int


@pytest.mark.parametrize("value", [np.bool_(True), True, np.float64(3.0), np.timedelta64(3), "3"])
def test_numpy_bools_and_non_integers_stay_refused(value: object) -> None:
    """T43-B11: a bool (NumPy's too), a float and a time span are still no integer setting."""
    with pytest.raises(NeurohoverError, match=r"seed = .* is not allowed: expected an integer in 0\.\.2\*\*63-1"):
        X.load_config("fig2", "quick", overrides={"seed": value})


def test_numpy_integer_out_of_range_is_refused() -> None:
    with pytest.raises(NeurohoverError, match=r"runs = -1 is not allowed"):
        X.load_config("fig2", "quick", overrides={"runs": np.int64(-1)})


# ----------------------------------------------------------------------------------------------- T43-B12


@pytest.mark.parametrize(("experiment", "key", "name"), [("fig2", "k\udc80", "key"), ("f\ud800", "k", "experiment")])
def test_unit_seed_refuses_lone_surrogates(experiment: str, key: str, name: str) -> None:
    """T43-B12: a lone surrogate was encode()'s UnicodeEncodeError; refused by the store's check of its text fields."""
    with pytest.raises(NeurohoverError, match=rf"unit_seed: {name} = .* is not allowed: .*lone surrogate"):
        X.unit_seed(0, experiment, key)


def test_unit_seed_of_text_is_unchanged() -> None:
    assert X.unit_seed(0, "fig2", "k") == 5781549759280602795
    assert X.unit_seed(0, "fig2", "") == 8733363878722306095


# ----------------------------------------------------------------------------------------------- T43-B13


def _edits() -> list:
    return [
        lambda s: s.__setitem__("runs", -1),
        lambda s: s.__setitem__("runs", "three"),
        lambda s: s.__setitem__("runs", 1),
        lambda s: s.__setitem__("bogus", 1),
        lambda s: s.__delitem__("seed"),
        lambda s: s.update(n_steps=10**9),
        lambda s: s.setdefault("task", "ghh09"),
        lambda s: s.pop("task"),
        lambda s: s.clear(),
        lambda s: s["variants"].append({"key": "x"}),
        lambda s: s["variants"].pop(),
        lambda s: s["variants"][0].__setitem__("topology", "slp"),
        lambda s: s["robustness_variants"].clear(),
    ]


@pytest.mark.parametrize("edit", range(len(_edits())))
def test_config_settings_are_read_only(edit: int) -> None:
    """T43-B13: every edit of a config's settings (a table or a list in them too) is refused, before or after a plan, and
    the config plans as loaded (runs=-1 was max()'s ValueError, runs=1 honoured or ignored as typed had been read)."""
    cfg = X.load_config("fig2", "quick")
    before = (json.dumps(cfg.settings, sort_keys=True), cfg.hash, X.plan(cfg, {}).total)
    with pytest.raises(NeurohoverError, match=r"ExperimentConfig\.settings: the edit .* is not allowed: .*overrides="):
        _edits()[edit](cfg.settings)
    assert (json.dumps(cfg.settings, sort_keys=True), cfg.hash, X.plan(cfg, {}).total) == before


def test_an_edit_names_itself() -> None:
    cfg = X.load_config("fig2", "quick")
    with pytest.raises(NeurohoverError, match=r"the edit \['runs'\] = -1 is not allowed"):
        cfg.settings["runs"] = -1
    with pytest.raises(NeurohoverError, match=r"the edit del \['seed'\] is not allowed"):
        del cfg.settings["seed"]


def test_read_only_settings_read_copy_and_store_as_before() -> None:
    """T43-B13: read-only settings compare, serialise, pickle and copy as the plain ones; a deep copy (or dict() of them)
    is one's own to edit and make a config of, checked; replace() and from_dict() give read-only ones too."""
    cfg = X.load_config("fig2", "quick")
    plain = json.loads(json.dumps(cfg.settings))
    assert cfg.settings == plain and isinstance(cfg.settings, dict) and isinstance(cfg.settings["variants"], list)
    again = pickle.loads(pickle.dumps(cfg))
    assert again == cfg and again.hash == cfg.hash
    with pytest.raises(NeurohoverError):
        again.settings["runs"] = 1
    own = copy.deepcopy(cfg.settings)
    own["runs"] = 1
    own["variants"][0]["label"] = "mine"
    assert type(own) is dict and type(own["variants"]) is list
    assert X.plan(make_config("my-fig2", "evolution", "quick", own), {}).total == 14
    with pytest.raises(NeurohoverError, match="runs = -1 is not allowed"):
        make_config("my-fig2", "evolution", "quick", {**own, "runs": -1})
    assert copy.deepcopy(cfg) == cfg and type(copy.deepcopy(cfg).settings) is type(cfg.settings)
    for other in (replace(cfg, paper={}), ExperimentConfig.from_dict(cfg.to_dict())):
        with pytest.raises(NeurohoverError):
            other.settings["variants"][0]["topology"] = "slp"
    mine = {"task": "ghh08"}
    built = ExperimentConfig("x", "x", "evolution", "quick", mine)
    mine["task"] = "ghh09"  # the caller's dict is no alias of the config's
    assert built.settings["task"] == "ghh08"


# ----------------------------------------------------------------------------------------------- T43-B15


@pytest.mark.parametrize(
    ("crashes", "returns", "match"),
    [
        (np.zeros((5, 3), int), -np.ones((5, 2)), r"crashes of shape \(5, 3\) is not allowed"),
        (np.zeros((3, 3), int), -np.ones((2, 2)), r"returns of shape \(2, 2\) is not allowed beside crashes of shape \(3, 3\)"),
        (np.zeros((0, 0)), np.zeros((0, 0)), r"crashes of shape \(0, 0\) is not allowed"),
        (None, -np.ones((2, 2)), r"crashes of shape \(\) is not allowed"),
    ],
)
def test_table3_summary_refuses_mismatched_tables(crashes: object, returns: object, match: str) -> None:
    """T43-B15: tables of shapes that do not match were summarised without a word, empty ones as NaN with warnings."""
    with pytest.raises(NeurohoverError, match=match):
        table3_summary(crashes, returns)  # type: ignore[arg-type]


def test_table3_summary_of_one_policy() -> None:
    assert table3_summary(np.array([[1]]), np.array([[-5.0]])) == {"r": -5.0, "r_G": -5.0, "crashed_episodes": 1}


def test_genome_digest_refuses_no_policy() -> None:
    with pytest.raises(NeurohoverError, match=r"policy=None is not allowed: give a Policy"):
        genome_digest(None)  # type: ignore[arg-type]


@pytest.mark.parametrize("values", [None, 5, ["level"]])
def test_check_agent_settings_refuses_no_table(values: object) -> None:
    agent = C.agents_with_settings()[0]
    with pytest.raises(NeurohoverError, match=rf"agent_settings={re.escape(repr(values))} is not allowed: give a dict"):
        C.check_agent_settings(agent, values)  # type: ignore[arg-type]
    if values is None:  # competition_config's own default: no settings of the agent's own
        return
    with pytest.raises(NeurohoverError, match=r"agent_settings=.* is not allowed: give a dict"):
        C.competition_config("ghh08", agent, runs=1, episodes=1, agent_settings=values)  # type: ignore[arg-type]


def test_compete_names_its_entry_points() -> None:
    """T43-B15: summarise and episode_rows are compete's helpers over its own store's results, not entry points."""
    assert "compete" in C.__all__ and "competition_config" in C.__all__
    assert "summarise" not in C.__all__ and "episode_rows" not in C.__all__
    assert all(hasattr(C, name) for name in C.__all__)
