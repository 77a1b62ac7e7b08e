"""A learned model flown in the simulator's ten substeps (``LearnedModel.mdp(substeps=10)``) and the
``model_substeps`` fit setting of model-learning experiments (``lr-substeps-table4``; docs/model.md)."""

from __future__ import annotations

import numpy as np
import pytest

from neurohover import NeurohoverError, baseline_policy, evaluate, get_task_family
from neurohover.experiments import LocalExecutor, Store, load_config, reproduce, write_report
from neurohover.experiments.config import make_config
from neurohover.experiments.plans import plan
from neurohover.models import LearnedModel, learn_lr
from neurohover.models.wind import WindModel


def _flight():
    return evaluate(baseline_policy(), get_task_family("ghh08").training_mdps()[0], seed=5, record=True, n_steps=800).flight_data


@pytest.fixture(scope="module")
def model() -> LearnedModel:
    return learn_lr(_flight())


def test_ten_substeps_fly_the_equivalent_parameters(model) -> None:
    one, ten = model.mdp(), model.mdp(substeps=10)
    assert (one.substeps, one.dt, ten.substeps, ten.dt) == (1, 0.1, 10, 0.01)
    params, noise = model.equivalent()
    assert np.array_equal(ten.params, params) and np.array_equal(ten.noise_std, noise)
    assert ten.d_u == pytest.approx(model.d_u * params[0] / model.params[0], rel=1e-12)  # D_u scales with the u axis
    assert one.d_u == model.d_u and np.array_equal(one.params, model.params)
    # the same model either way: a policy's returns agree closely over a few steps (not exactly: position and
    # rotation now move within the step)
    r1 = evaluate(baseline_policy(), one, episodes=50, seed=3, n_steps=20).returns.mean()
    r10 = evaluate(baseline_policy(), ten, episodes=50, seed=3, n_steps=20).returns.mean()
    assert r10 == pytest.approx(r1, rel=0.2) and r10 != r1


def test_a_windy_model_flies_ten_substeps_in_the_same_wind(model) -> None:
    """The wind enters the drag as a velocity, C (u + wind): it stays as it is while C and the gains scale."""
    wind = WindModel.from_dict({"kind": "constant", "x": {"offset": 1.5}, "y": {"offset": -0.5}})
    windy = LearnedModel(model.params, model.noise_std, "lr", wind=wind)
    one, ten = windy.mdp(), windy.mdp(substeps=10)
    assert ten.substeps == 10 and (ten.wind_kind, tuple(ten.wind)) == (one.wind_kind, tuple(one.wind)) and one.wind_kind != 0
    assert np.array_equal(ten.params, model.mdp(substeps=10).params)
    # near hover the u velocity settles where the wind's drag is balanced either way: -wind - D_u / C_u
    r1 = evaluate(baseline_policy(), one, episodes=50, seed=3, n_steps=20).returns.mean()
    r10 = evaluate(baseline_policy(), ten, episodes=50, seed=3, n_steps=20).returns.mean()
    assert r10 == pytest.approx(r1, rel=0.2) and r10 != r1
    calm = evaluate(baseline_policy(), model.mdp(substeps=10), episodes=50, seed=3, n_steps=20).returns.mean()
    assert calm != r10  # the wind is flown


def test_bad_substeps_are_refused(model) -> None:
    with pytest.raises(NeurohoverError, match=r"substeps=5: allowed 1 or 10"):
        model.mdp(substeps=5)
    p = np.array(model.params)
    p[5] = -20.0  # C_p: 1 + 0.1 C = -1, no ten-substep equivalent
    flipping = LearnedModel(tuple(p), model.noise_std, "lr")
    with pytest.raises(NeurohoverError, match="the model's p axis has no 10-substep equivalent"):
        flipping.mdp(substeps=10)
    # the agents fly such a model as fitted (strong sensor noise fits one), and say so where a unit records it
    assert (flipping.flyable_substeps(10), flipping.flyable_substeps(1), model.flyable_substeps(10)) == (1, 1, 10)
    from neurohover.agents.model_based import learn_model

    assert learn_model(_flight(), substeps=10).substeps == 10
    ml = {"task": "ghh08", "seed": 1, "n_mdps": 1, "generic": "shipped", "methods": ["lr"]}
    with pytest.raises(NeurohoverError, match="model_substeps"):
        make_config("y", "model_learning", "quick", {**ml, "fits": [{"key": "a", "model_substeps": 3}]})


@pytest.mark.slow
def test_the_substeps_fit_evolves_on_ten_substeps_and_reports_the_factor(tmp_path) -> None:
    cfg = load_config("lr-substeps-table4", "quick", {"n_steps": 60})
    units = {u.key: u for u in plan(cfg, {}).units}
    assert "model_substeps" not in units["model/lr@ours/test0"].params  # absent: as every stored unit
    assert units["model/lr@substeps10/test0"].params["model_substeps"] == 10
    with Store(tmp_path / "s.sqlite") as store:
        assert reproduce(cfg, store, LocalExecutor(1), progress=False).status == "finished"
        results = store.results("lr-substeps-table4", "quick")
        (tmp_path / "report").mkdir()
        report = write_report(store, tmp_path / "report").read_text()
    for i in range(3):
        ours, ten = results[f"model/lr@ours/test{i}"], results[f"model/lr@substeps10/test{i}"]
        assert ours["model_params"] == ten["model_params"]  # the same flight data, the same fit
        assert ours["predicted_return"] != ten["predicted_return"]  # evolved and rated on another integration
        assert ours["test_w_sd"] > 0 and ten["test_w_sd"] > 0
    assert "the model's substeps per control step (model_substeps: 1 -> 10)" in report
    assert "| ten substeps | keep | rms | ours | 10 | 3 |" in report


def test_the_fig8_groups_take_ten_substeps_on_figure_8s_seeds() -> None:
    from neurohover.experiments.units import unit_seed

    fig8 = load_config("fig8", "paper")
    units = {u.key: u for u in plan(load_config("lr-substeps-fig8", "paper"), {}).units if u.kind == "test_run"}
    assert len(units) == 5 * 80
    for group, agent, substeps in (
        ("model-free", "model-free", None),
        ("incremental/substeps10", "incremental", 10),
        ("hybrid/substeps10", "hybrid", 10),
        ("incremental/substeps1", "incremental", None),  # absent: one step, as Figure 8's units stored before 2026-12-04
        ("hybrid/substeps1", "hybrid", None),
    ):
        u = units[f"run/{group}/train3/rep2"]
        assert u.params["seed"] == unit_seed(fig8.typed.seed, "fig8", f"run/{agent}/train3/rep2")  # paired with Figure 8's run
        assert u.params.get("model_substeps") == substeps
    base = {"task": "ghh09", "seed": 1, "episodes": 2, "policies": "shipped"}
    with pytest.raises(NeurohoverError, match="model_substeps applies to the agents that learn models"):
        make_config("x", "test_runs", "quick", {**base, "groups": [{"agent": "model-free", "n_mdps": 1, "model_substeps": 10}]})
    with pytest.raises(NeurohoverError, match="model_substeps"):
        make_config("x", "test_runs", "quick", {**base, "groups": [{"agent": "incremental", "n_mdps": 1, "model_substeps": 2}]})


@pytest.mark.slow
def test_compete_takes_the_model_substeps_for_the_agents_that_learn_models(tmp_path, capsys) -> None:
    import json
    import sqlite3

    from neurohover.cli import main

    args = ["compete", "--task", "ghh08", "--runs", "1", "--episodes", "2", "--episode-steps", "60", "--model-substeps", "10"]
    assert main([*args, "--agent", "model-based", "--out", str(tmp_path / "a")]) == 0
    with sqlite3.connect(tmp_path / "a" / "results.sqlite") as conn:
        (params,) = conn.execute("SELECT params FROM units").fetchone()
    assert json.loads(params)["model_substeps"] == 10  # the run's unit flew the ten-substep model
    assert main([*args, "--agent", "model-free", "--out", str(tmp_path / "b")]) == 2
    assert "--model-substeps applies to the agents that learn models" in capsys.readouterr().err


def test_the_default_is_ten_substeps_for_ghh_and_one_for_fghh() -> None:
    from neurohover.agents.model_based import ModelEvolution
    from neurohover.models.model import DEFAULT_MODEL_SUBSTEPS, LEGACY_MODEL_SUBSTEPS, default_model_substeps

    assert (default_model_substeps("ghh08"), default_model_substeps("ghh09"), default_model_substeps("fghh")) == (10, 10, 1)
    assert ModelEvolution().model_substeps == DEFAULT_MODEL_SUBSTEPS == 10 and LEGACY_MODEL_SUBSTEPS == 1
    # Table 4 and Figure 8 take it: written into the resolved config, carried by every LR unit
    assert load_config("table4", "paper").settings["model_substeps"] == 10
    both = make_config("x", "model_learning", "quick", {"task": "ghh08", "seed": 1, "n_mdps": 1, "generic": "shipped", "methods": ["lr", "ec-meno"]})
    units = {u.params["method"]: u for u in plan(both, {}).units}
    assert units["lr"].params["model_substeps"] == 10
    assert "model_substeps" not in units["ec-meno"].params  # an LR fit setting, as the noise estimate
    fig8 = load_config("fig8", "paper")
    groups = {g["label"]: g for g in fig8.settings["groups"]}
    assert groups["incremental"]["model_substeps"] == groups["hybrid"]["model_substeps"] == 10
    assert "model_substeps" not in groups["model-free"]
    # FGHH's agents keep one step (the authors' published FGHH code): Figure 16's groups say so
    assert {g.get("model_substeps") for g in load_config("fig16", "paper").settings["groups"] if g["agent"] != "baseline"} <= {1, None}


def test_a_config_naming_one_substep_hashes_as_an_absent_one_did() -> None:
    """An absent model_substeps meant one step until 2026-12-04: naming 1 keeps a stored config's hash
    (its results resume), leaving it out takes ten and changes the hash (its units run again)."""
    base = {"task": "ghh08", "seed": 1, "n_mdps": 1, "generic": "shipped", "methods": ["lr"]}
    one = make_config("x", "model_learning", "quick", {**base, "model_substeps": 1})
    ten = make_config("x", "model_learning", "quick", base)
    assert ten.settings["model_substeps"] == 10 and one.hash != ten.hash
    import dataclasses

    stored = {k: v for k, v in one.settings.items() if k != "model_substeps"}  # as a config stored before read back
    assert dataclasses.replace(one, settings=stored).hash == one.hash
    assert dataclasses.replace(ten, settings=stored).hash == one.hash != ten.hash
    lr = [u for u in plan(one, {}).units if u.params.get("method") == "lr"]
    assert lr and all("model_substeps" not in u.params for u in lr)  # the params of the units stored before
    with pytest.raises(NeurohoverError, match="model_substeps = 10 applies to the LR methods without fits"):
        make_config("x", "model_learning", "quick", {**base, "model_substeps": 10, "fits": [{"key": "a"}]})
    with pytest.raises(NeurohoverError, match="model_substeps = 10 applies to the LR methods without fits"):
        make_config("x", "model_learning", "quick", {**base, "methods": ["ec-meno"], "model_substeps": 10})
