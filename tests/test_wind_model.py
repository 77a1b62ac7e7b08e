"""Wind-aware learned models (neurohover.models.wind): the wind type, its file form, its kernel slots,
the aliasing map, identification on model data and on GHH-09, agents and experiments that use it."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from neurohover import baseline_policy, evaluate, get_task_family
from neurohover.agents.model_based import ModelEvolution
from neurohover.cli import main
from neurohover.errors import NeurohoverError
from neurohover.experiments.config import load_config, make_config
from neurohover.experiments.plans import plan
from neurohover.experiments.units import unit_agent
from neurohover.models import LearnedModel, learn_lr, one_step_error, one_substep_params
from neurohover.models.transitions import Transitions
from neurohover.models.wind import NO_WIND, WindAxis, WindModel, effective_wind, fit_wind, model_times, sinusoid_axes
from neurohover.sim.constants import DEFAULT_NOISE_STD, SUBSTEP_DT, SUBSTEPS, WIND_CONSTANT, WIND_SINUSOID

HELD = one_substep_params()[0]  # the default helicopter in the model's integration: LR holds its C_u, C_v, D_v with a wind
WIND = WindModel("sinusoid", WindAxis(1.5, 3.0, 0.7, 2.0), WindAxis(2.5, 11.0, 4.0, -1.0))


def _model(wind: WindModel) -> LearnedModel:
    return LearnedModel(tuple(HELD), tuple(one_substep_params(noise_std=DEFAULT_NOISE_STD)[1]), "lr", wind=wind)


@pytest.fixture(scope="module")
def ghh09_flights():
    """One baseline episode on GHH-09 training MDP 1 (a 2.6 Hz wind east-west of 3.4 m/s), and a held-out one."""
    mdp = get_task_family("ghh09").training_mdps()[1]
    return mdp, evaluate(baseline_policy(), mdp, record=True, seed=3).flight_data, evaluate(baseline_policy(), mdp, record=True, seed=99).flight_data


def test_wind_values_are_checked_with_one_clear_message() -> None:
    with pytest.raises(NeurohoverError, match="wind model 'gusty' is not allowed"):
        WindModel("gusty")
    with pytest.raises(NeurohoverError, match="omega=-1.0 must be >= 0"):
        WindAxis(omega=-1.0)
    with pytest.raises(NeurohoverError, match="amplitude=nan must be a finite number"):
        WindAxis(amplitude=float("nan"))
    with pytest.raises(NeurohoverError, match="a 'constant' wind has offsets only"):
        WindModel("constant", WindAxis(amplitude=1.0))
    with pytest.raises(NeurohoverError, match="'none' has no offsets"):
        WindModel("none", WindAxis(offset=1.0))
    with pytest.raises(NeurohoverError, match=r"wind.x must hold amplitude, omega, phase and offset"):
        WindModel.from_dict({"kind": "sinusoid", "x": {"amp": 1.0}})


def test_a_model_file_records_its_wind_and_older_files_read_as_wind_blind(tmp_path: Path) -> None:
    model = _model(WIND)
    path = model.save(tmp_path / "m.json")
    data = json.loads(path.read_text())
    assert data["wind"] == {"kind": "sinusoid", "x": {"amplitude": 1.5, "omega": 3.0, "phase": 0.7, "offset": 2.0}, "y": WIND.y.to_dict()}
    assert LearnedModel.load(path) == model and LearnedModel.load(path) != _model(NO_WIND)
    del data["wind"]
    path.write_text(json.dumps(data))
    assert LearnedModel.load(path).wind == NO_WIND
    data["wind"] = {"kind": "sinusoid", "x": {**WIND.x.to_dict(), "omega": -2.0}, "y": WIND.y.to_dict()}  # a file's wind is whole (T37-B05)
    path.write_text(json.dumps(data))
    with pytest.raises(NeurohoverError, match=r"model file .*m\.json.*: wind omega=-2.0 must be >= 0"):
        LearnedModel.load(path)


def test_the_kernel_slots_fly_the_wind_the_model_describes() -> None:
    kind, slots = WIND.mdp_wind()
    assert kind == WIND_SINUSOID
    # The kernel's reading of the slots (SPEC section 2) gives back the wind's own numbers.
    for axis, read in zip((WIND.x, WIND.y), sinusoid_axes(slots), strict=True):
        for name in ("amplitude", "omega", "phase", "offset"):
            assert getattr(read, name) == pytest.approx(getattr(axis, name), rel=1e-12, abs=1e-12)
    assert WindModel("constant", WindAxis(offset=1.0), WindAxis(offset=-2.0)).mdp_wind() == (WIND_CONSTANT, (1.0, -2.0))
    assert _model(NO_WIND).mdp().wind_kind == 0 and _model(WIND).mdp().wind == slots


@pytest.mark.parametrize("omega", [0.9, 7.0, 25.0, 31.0, 40.0, 55.0, 62.0])
def test_effective_wind_is_the_step_average_sampled_at_10_hz(omega: float) -> None:
    axis = WindAxis(2.0, omega, 1.3, 0.5)
    eff = effective_wind(axis)
    assert 0.0 <= eff.omega <= 10 * math.pi + 1e-12
    k = np.arange(200)
    substeps = 0.1 * k[:, None] + SUBSTEP_DT * np.arange(SUBSTEPS)[None, :]
    np.testing.assert_allclose(eff.at(0.1 * k), axis.at(substeps).mean(axis=1), atol=1e-9)


def test_lr_recovers_the_wind_of_data_flown_in_a_windy_model() -> None:
    truth = _model(WIND)
    data = evaluate(baseline_policy(), truth.mdp(), record=True, seed=4).flight_data
    got = learn_lr(data, wind_model="sinusoid")
    assert got.params[:3] == tuple(HELD[:3]) and got.d_u == 0.0
    for axis, want in ((got.wind.x, WIND.x), (got.wind.y, WIND.y)):
        assert axis.omega == pytest.approx(want.omega, rel=1e-3)
        assert axis.amplitude == pytest.approx(want.amplitude, rel=0.05)
        assert axis.offset == pytest.approx(want.offset, abs=0.1)
        assert abs((axis.phase - want.phase + math.pi) % (2 * math.pi) - math.pi) < 0.1
    # A constant wind's model on the same data explains less; the wind-blind one less still on u and v.
    const = learn_lr(data, wind_model="constant")
    assert const.wind.kind == "constant" and const.stats["uv_residual_rms"] > got.stats["uv_residual_rms"]
    assert got.stats["uv_residual_rms"] < 0.5 * got.stats["uv_residual_rms_wind_blind"]


def test_on_ghh09_the_wind_aware_model_finds_the_effective_wind_and_predicts_better(ghh09_flights) -> None:
    mdp, data, held_out = ghh09_flights
    # innovations noise: the authors' rms estimate counts the blind model's unexplained wind as gusts, so it flies softer
    blind, aware = learn_lr(data, noise="innovations"), learn_lr(data, wind_model="sinusoid", noise="innovations")
    true_y = effective_wind(sinusoid_axes(mdp.wind)[1])
    assert aware.wind.y.omega == pytest.approx(true_y.omega, rel=1e-4)
    assert aware.wind.y.amplitude == pytest.approx(true_y.amplitude, rel=0.03)
    assert abs((aware.wind.y.phase - true_y.phase + math.pi) % (2 * math.pi) - math.pi) < 0.05
    assert one_step_error(aware, held_out) < 0.3 * one_step_error(blind, held_out)
    # The baseline's return predicted on each model against the true one (the wind-blind model crashes it).
    true_return = evaluate(baseline_policy(), mdp, seed=5).returns[0]
    predicted = {m.wind.kind: evaluate(baseline_policy(), m.mdp(), seed=5).returns[0] for m in (blind, aware)}
    assert abs(predicted["sinusoid"] - true_return) < 0.5 * abs(true_return) < abs(predicted["none"] - true_return)


def test_fitting_the_drags_too_never_explains_the_data_worse(ghh09_flights) -> None:
    _, data, _ = ghh09_flights
    tr = Transitions(data)
    held = fit_wind(tr, "sinusoid", HELD[0], HELD[1], HELD[2])
    joint = fit_wind(tr, "sinusoid", HELD[0], HELD[1], HELD[2], fit_drags=True, iterations=20)
    assert held[1:3] == (HELD[0], HELD[1]) and held[3]["wind_fit_rounds"] == 1
    assert joint[1:3] != held[1:3] and joint[3]["wind_fit_rounds"] > 1
    # Alternating least squares from the held drags only lowers the joint residual.
    assert joint[3]["uv_residual_rms"] <= held[3]["uv_residual_rms"] + 1e-12


def test_model_times_are_the_kernels_floored_competition_times() -> None:
    steps = np.arange(6000)
    expected = [int((0.1 * k + 0.0) * 100.0) / 100.0 for k in steps.tolist()]
    assert model_times(steps).tolist() == expected


def test_agents_and_experiment_groups_take_the_wind_model() -> None:
    with pytest.raises(NeurohoverError, match="wind_model='gusty' is not allowed"):
        ModelEvolution(wind_model="gusty")
    base = load_config("fig8", "quick", {"policies": "shipped"})  # the shipped policies: its test runs plan at once
    units = plan(base, {}).units
    assert all("wind_model" not in u.params for u in units)  # unchanged plans: no key for the default
    groups = [dict(g) for g in base.settings["groups"]]
    group = groups[1] = dict(groups[1], wind_model="sinusoid")  # the incremental agent
    own = {k: v for k, v in base.settings.items() if k != "policy_budget"}  # a config of its own: --set may not change a shipped group (T29-A02)
    cfg = make_config("windy-fig8", "test_runs", "quick", {**own, "groups": groups})
    windy_units = [u for u in plan(cfg, {}).units if u.params.get("group") == group["label"]]
    assert windy_units and all(u.params["wind_model"] == "sinusoid" for u in windy_units)
    agent = unit_agent(windy_units[0].params)
    assert agent.settings.wind_model == "sinusoid"


def test_learn_model_command_writes_the_wind_and_refuses_it_for_evolved_models(ghh09_flights, tmp_path: Path, capsys) -> None:
    _, data, _ = ghh09_flights
    data = data.__class__(data.observations, data.actions, {**data.metadata})
    path = data.save(tmp_path / "f.npz")
    out = tmp_path / "m.json"
    assert main(["learn-model", "--flight-data", str(path), "--method", "lr", "--wind-model", "sinusoid", "--out", str(out)]) == 0
    assert LearnedModel.load(out).wind == learn_lr(data, wind_model="sinusoid").wind
    assert "identified wind (world frame" in capsys.readouterr().err
    assert main(["learn-model", "--flight-data", str(path), "--method", "ec-meno", "--wind-model", "constant", "--out", str(out)]) == 2
    assert "--wind-model applies to --method lr only" in capsys.readouterr().err


def test_a_competition_hands_the_wind_model_to_its_agent_and_keeps_older_digests() -> None:
    from neurohover.compete import competition_config

    plain = competition_config("ghh09", "hybrid", runs=2, episodes=3)
    windy = competition_config("ghh09", "hybrid", runs=2, episodes=3, wind_model="sinusoid")
    assert "wind_model" not in plain.settings["groups"][0] and plain.scale != windy.scale
    units = plan(windy, {}).units
    assert units and all(unit_agent(u.params).settings.wind_model == "sinusoid" for u in units)


def test_agents_wait_for_flight_data_that_span_a_winds_frequency() -> None:
    from neurohover.agents.model_based import enough_to_learn

    data = evaluate(baseline_policy(), get_task_family("ghh09").training_mdps()[1], episodes=3, seed=3, record=True, n_steps=7).flight_data
    assert data.n_transitions == 21 and enough_to_learn(data) and enough_to_learn(data, "constant")
    assert not enough_to_learn(data, "sinusoid")
    with pytest.raises(NeurohoverError, match="at least 8 control steps, got 7"):
        learn_lr(data, wind_model="sinusoid")
