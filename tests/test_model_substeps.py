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


@pytest.fixture(scope="module")
def model() -> LearnedModel:
    ev = evaluate(baseline_policy(), get_task_family("ghh08").training_mdps()[0], seed=5, record=True, n_steps=800)
    return learn_lr(ev.flight_data)


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


def test_bad_substeps_are_refused(model) -> None:
    with pytest.raises(NeurohoverError, match=r"substeps=5: allowed 1 or 10"):
        model.mdp(substeps=5)
    windy = LearnedModel(model.params, model.noise_std, "lr", wind=WindModel(kind="constant"))
    with pytest.raises(NeurohoverError, match="applies to wind-blind models; this one has a constant wind"):
        windy.mdp(substeps=10)
    p = np.array(model.params)
    p[5] = -20.0  # C_p: 1 + 0.1 C = -1, no ten-substep equivalent
    with pytest.raises(NeurohoverError, match="the model's p axis has no 10-substep equivalent"):
        LearnedModel(tuple(p), model.noise_std, "lr").mdp(substeps=10)
    ml = {"task": "ghh08", "seed": 1, "n_mdps": 1, "generic": "shipped", "methods": ["lr"]}
    with pytest.raises(NeurohoverError, match="model_substeps"):
        make_config("y", "model_learning", "quick", {**ml, "fits": [{"key": "a", "model_substeps": 3}]})


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
    assert len(units) == 3 * 80
    for group, agent in (("model-free", "model-free"), ("incremental/substeps10", "incremental"), ("hybrid/substeps10", "hybrid")):
        u = units[f"run/{group}/train3/rep2"]
        assert u.params["seed"] == unit_seed(fig8.typed.seed, "fig8", f"run/{agent}/train3/rep2")  # paired with Figure 8's run
        assert u.params.get("model_substeps") == (None if agent == "model-free" else 10)
    base = {"task": "ghh09", "seed": 1, "episodes": 2, "policies": "shipped"}
    with pytest.raises(NeurohoverError, match="model_substeps apply to the agents that learn models"):
        make_config("x", "test_runs", "quick", {**base, "groups": [{"agent": "model-free", "n_mdps": 1, "model_substeps": 10}]})
    with pytest.raises(NeurohoverError, match="model_substeps"):
        make_config("x", "test_runs", "quick", {**base, "groups": [{"agent": "incremental", "n_mdps": 1, "model_substeps": 2}]})


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
