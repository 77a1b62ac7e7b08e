"""Trial 44, side B (Python API and files): win_probabilities with one agent's runs on an MDP given as a number or a
one-shot iterator (T44-B01); sb3_model_file given a str path (T44-B05); run_unit of an evolve unit whose params were
edited by hand (T44-B11, T44-B12); LearnedModel given an array as its method (T44-B13); settings_rows of a user's class
annotated with real types (T44-B18); default_model_substeps of no task family (T44-B20); the plumbing modules' boundary
and sole_writer given a str path (T44-B17, T44-B19)."""

from __future__ import annotations

import dataclasses

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
