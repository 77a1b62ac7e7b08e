"""Bad input, trial 27: model files' entries of the wrong kind and parameter_table's true noise (T27-B01, T27-B02, T27-B11,
T27-B12).

LearnedModel.load of a file whose param_names was None, 5 or true was Python's TypeError ('NoneType' object is not
iterable); a stats, d_u or seconds of the wrong kind (true, 'x', null) was "malformed model (...)" in Python's words,
naming no key; a d_u or seconds given as text ('0.0443', ' 0.0443 ', '0.01') or as true loaded as floats, and stats given
as a list of pairs as a dict. Each is now refused by name with what is allowed (seconds as policy files refuse them).
parameter_table took a true noise std of -1 (negative standard deviations are refused wherever model noise is read)."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from neurohover import baseline_policy, evaluate, get_task_family
from neurohover.errors import NeurohoverError
from neurohover.models import LearnedModel, learn_lr
from neurohover.models.model import parameter_table
from neurohover.sim.constants import PARAM_NAMES
from neurohover.tasks import MDP


@pytest.fixture(scope="module")
def model_file(tmp_path_factory) -> dict:
    """An LR model of a recorded baseline episode (200 steps, GHH-08's zero MDP), as its file's dict."""
    flight = evaluate(baseline_policy(), get_task_family("ghh08").zero(), record=True, seed=1, n_steps=200).flight_data
    path = learn_lr(flight).save(tmp_path_factory.mktemp("models27") / "m.json")
    return json.loads(path.read_text())


def _load(d: dict, tmp_path: Path, **changes) -> LearnedModel:
    path = tmp_path / "x.json"
    path.write_text(json.dumps({**d, **changes}))
    return LearnedModel.load(path)


def _refused(d: dict, tmp_path: Path, fragment: str, **changes) -> str:
    with pytest.raises(NeurohoverError) as err:
        _load(d, tmp_path, **changes)
    message = str(err.value)
    assert message.startswith(f"model file {str(tmp_path / 'x.json')!r}: {fragment}"), message
    assert "malformed" not in message and "\n" not in message, message
    return message


def test_what_the_code_writes_still_loads(model_file: dict, tmp_path: Path) -> None:
    """The checks take a written file, and one of whole-number d_u and seconds or without the optional entries."""
    model = _load(model_file, tmp_path)
    assert isinstance(model.d_u, float) and isinstance(model.seconds, float)
    assert _load(model_file, tmp_path, seconds=3) == model
    bare = {k: v for k, v in model_file.items() if k not in ("param_names", "d_u", "seconds", "stats", "wind", "noise_names")}
    assert _load(bare, tmp_path).d_u == 0.0
    assert _load({**model_file, "stats": {}}, tmp_path, d_u=0).d_u == 0.0


@pytest.mark.parametrize("names", [None, 5, True, "C_u", {"C_u": 1}, list(reversed(PARAM_NAMES)), list(PARAM_NAMES)[:10]])
def test_param_names_not_the_list_are_refused(model_file: dict, tmp_path: Path, names) -> None:
    """T27-B01: None, 5 and true were a TypeError; a list in another order was refused, now in the same words."""
    message = _refused(model_file, tmp_path, "its param_names ", param_names=names)
    assert f"is not allowed: allowed the list {list(PARAM_NAMES)}" in message


@pytest.mark.parametrize(
    ("key", "value", "allowed"),
    [
        ("stats", True, "allowed a JSON object"),
        ("stats", "x", "allowed a JSON object"),
        ("stats", None, "allowed a JSON object"),
        ("d_u", "x", "allowed a finite number (D_u"),
        ("d_u", None, "allowed a finite number (D_u"),
        ("seconds", "x", "allowed a number of seconds >= 0 and <= 3.15576e+09"),
        ("seconds", None, "allowed a number of seconds >= 0 and <= 3.15576e+09"),
    ],
)
def test_wrong_kinds_name_the_key(model_file: dict, tmp_path: Path, key: str, value, allowed: str) -> None:
    """T27-B02: Python's message inside "malformed model (...)", naming neither the key nor what is allowed."""
    message = _refused(model_file, tmp_path, f"its {key} ", **{key: value})
    assert f"is not allowed: {allowed}" in message


@pytest.mark.parametrize(
    ("key", "value"),
    [("d_u", "0.0443"), ("d_u", " 0.0443 "), ("d_u", True), ("d_u", False), ("seconds", "0.01"), ("seconds", True), ("stats", [["n_transitions", 199]])],
)
def test_converted_values_are_refused(model_file: dict, tmp_path: Path, key: str, value) -> None:
    """T27-B11: text and bools loaded as floats (float(...)) and a list of pairs as stats (dict(...))."""
    _refused(model_file, tmp_path, f"its {key} {value!r} is not allowed: allowed ", **{key: value})


def test_parameter_table_refuses_negative_true_noise(model_file: dict, tmp_path: Path) -> None:
    """T27-B12: a true noise std of -1 gave 17 rows; refused as model noise is elsewhere, with or without a true MDP."""
    model = _load(model_file, tmp_path)
    for truth in (None, MDP("fghh"), list(MDP("fghh").params)):
        with pytest.raises(NeurohoverError, match=re.escape("true noise std must be >= 0, got [-1.0, -1.0")):
            parameter_table(model, truth, true_noise_std=[-1.0] * 6)
        assert len(parameter_table(model, truth, true_noise_std=[0.0] * 6)) == 17
