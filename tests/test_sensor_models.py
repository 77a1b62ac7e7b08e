"""bench-sensor-models: LR models learned through sensor conditions (config, plan, units, report section)."""

from __future__ import annotations

from pathlib import Path

import pytest

from neurohover import NeurohoverError
from neurohover.experiments.config import load_config
from neurohover.experiments.executors import LocalExecutor
from neurohover.experiments.plans import plan
from neurohover.experiments.report import write_report
from neurohover.experiments.results import ModelResult
from neurohover.experiments.runner import reproduce
from neurohover.experiments.store import Store
from neurohover.experiments.units import run_unit

NAME = "bench-sensor-models"


def _conditions(*tables: dict) -> dict:
    return {"conditions": list(tables)}


def test_conditions_are_checked_when_the_config_loads() -> None:
    with pytest.raises(NeurohoverError, match="condition keys must be unique and of lower-case letters"):
        load_config(NAME, "quick", _conditions({"key": "White 1", "sensor": {"level": 1.0}}))
    with pytest.raises(NeurohoverError, match="condition keys must be unique"):
        load_config(NAME, "quick", _conditions({"key": "a"}, {"key": "a"}))
    with pytest.raises(NeurohoverError, match=r"conditions\[0\]: data_episodes = 0 is not allowed"):
        load_config(NAME, "quick", _conditions({"key": "a", "data_episodes": 0}))
    with pytest.raises(NeurohoverError, match="sensor is set by each of the conditions here"):
        load_config(NAME, "quick", {"sensor": {"level": 1.0}})


def test_a_model_learning_config_without_conditions_plans_its_units_as_before() -> None:
    # table4's params have no condition keys (tests/test_stored_plans.py checks them against the store)
    units = plan(load_config("table4", "quick", {"generic": "baseline"}), {}).units
    models = [u for u in units if u.kind == "model"]
    assert models and all("exact_checks" not in u.params and "data_episodes" not in u.params for u in models)


def test_every_condition_of_an_mdp_takes_its_seed_and_its_own_sensors() -> None:
    cfg = load_config(NAME, "quick")
    units = [u for u in plan(cfg, {}).units if u.kind == "model"]
    assert len(units) == len(cfg.typed.conditions) * cfg.typed.n_mdps
    by_mdp: dict[str, set] = {}
    for u in units:
        by_mdp.setdefault(u.key.rsplit("/", 1)[1], set()).add(u.params["seed"])
    assert all(len(seeds) == 1 for seeds in by_mdp.values()) and len(by_mdp) == cfg.typed.n_mdps
    white4 = next(u for u in units if u.key == "model/lr@white4-5ep/test0")
    assert white4.params["data_episodes"] == 5 and white4.params["mdp"]["sensor"]["velocity"] == pytest.approx(0.4)
    exact = next(u for u in units if u.key == "model/lr@exact/test0")
    assert "sensor" not in exact.params["mdp"] or exact.params["mdp"]["sensor"]["velocity"] == 0.0


def test_noisy_readings_bias_the_model_and_exact_sensors_fly_the_same_gusts() -> None:
    units = {u.key: u for u in plan(load_config(NAME, "quick"), {}).units}
    exact = ModelResult.from_dict(run_unit(units["model/lr@exact/test0"], threads=1))
    noisy = ModelResult.from_dict(run_unit(units["model/lr@white4/test0"], threads=1))
    more = ModelResult.from_dict(run_unit(units["model/lr@white4-5ep/test0"], threads=1))
    # With exact sensors the policy's test through "the sensors" is the exact test, gust for gust.
    assert exact.test_returns == exact.exact_test_returns and exact.test_crashes == exact.exact_test_crashes
    assert len(exact.param_relative_errors) == 11
    # Noisy regressors: the model predicts exact flight data worse, and five times the data does not cure it.
    assert noisy.exact_one_step_error > 10 * exact.exact_one_step_error
    assert more.exact_one_step_error > 10 * exact.exact_one_step_error
    # Its own (noisy) data it fits worse still: the readings' noise is in its targets too.
    assert noisy.own_one_step_error > noisy.exact_one_step_error


@pytest.mark.slow
def test_the_report_tabulates_every_condition(tmp_path: Path) -> None:
    cfg = load_config(NAME, "quick", {"n_mdps": 1, "conditions": [{"key": "exact"}, {"key": "white2", "sensor": {"level": 2.0}}]})
    with Store(tmp_path / "s.sqlite") as store:
        reproduce(cfg, store, LocalExecutor(1), progress=False)
        text = write_report(store, tmp_path / "out").read_text()
    assert "### LR models learned through the sensors" in text
    rows = [line for line in text.splitlines() if line.startswith("| exact |") or line.startswith("| white2 |")]
    assert [r.split("|")[2].strip() for r in rows] == ["exact", "level 2.0"]
    assert (tmp_path / "out" / f"{NAME}-quick.png").stat().st_size > 10_000
