"""learn-model's notes: nan rows explained, short data, absorbed wind and an unusable model warned of."""

from __future__ import annotations

import numpy as np

from neurohover.cli import main
from neurohover.cli.learning import RELIABLE_TRANSITIONS, model_notes
from neurohover.evaluate import evaluate
from neurohover.models import LearnedModel, one_substep_params, parameter_table
from neurohover.policies import baseline_policy
from neurohover.tasks import get_task_family


def _flown(mdp, episodes: int = 1, n_steps: int = 6000):
    return evaluate(baseline_policy(), [mdp], episodes=episodes, record=True, n_steps=n_steps).flight_data


def _true_model() -> LearnedModel:
    params, noise = one_substep_params()
    return LearnedModel(tuple(params), tuple(noise), "lr")


def test_a_faithful_model_from_enough_calm_data_gets_no_note() -> None:
    zero = get_task_family("ghh08").zero()
    model = _true_model()
    assert model_notes(model, _flown(zero), zero, parameter_table(model, zero)) == []


def test_nan_rows_are_explained() -> None:
    params, noise = one_substep_params()
    params[0] = -15.0  # 1 + 0.1 * C_u < 0: no 10-substep equivalent on the u axis
    model = LearnedModel(tuple(params), tuple(noise), "lr")
    rows = parameter_table(model, None)
    assert np.isnan(rows[0].learned)
    notes = model_notes(model, _flown(get_task_family("ghh08").zero()), None, rows)
    assert any(n.startswith("note: C_u show nan") and "1 + 0.1*C is not positive" in n for n in notes)


def test_short_data_are_warned_of() -> None:
    zero = get_task_family("ghh08").zero()
    model = _true_model()
    data = _flown(zero, n_steps=RELIABLE_TRANSITIONS - 1)
    notes = model_notes(model, data, zero, parameter_table(model, zero))
    assert any(f"only {RELIABLE_TRANSITIONS - 1} transitions" in n for n in notes)


def test_wind_absorbed_into_the_model_is_noted() -> None:
    windy = get_task_family("ghh08").mdp("train:2")
    model = _true_model()
    notes = model_notes(model, _flown(windy), windy, parameter_table(model, windy))
    assert any("flown in wind (ghh08/train:2)" in n for n in notes)


def test_a_model_the_baseline_crashes_on_is_warned_of_through_the_cli(tmp_path, capsys) -> None:
    record = tmp_path / "calm.npz"
    assert main(["fly", "--task", "ghh08", "--episodes", "1", "--record", str(record), "--json"]) == 0
    capsys.readouterr()
    assert main(["learn-model", "--flight-data", str(record), "--method", "lr", "--out", str(tmp_path / "m.json")]) == 0
    err = capsys.readouterr().err
    model = LearnedModel.load(tmp_path / "m.json")
    crashes = evaluate(baseline_policy(), [model.mdp("m")], episodes=3, seed=0).crashed.sum()
    # LR from one closed-loop baseline episode: its w axis is identified only with the baseline's feedback.
    assert crashes > 0
    assert f"crashes on this model in {crashes} of 3 episodes" in err and "never crashes in the true MDP" in err
