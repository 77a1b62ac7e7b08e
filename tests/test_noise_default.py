"""The authors' noise estimate as the default (issue 31), and `reproduce --update`, which takes a changed
config and keeps the stored units it plans unchanged, on a real SQLite store."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from neurohover.agents.model_based import ModelEvolution
from neurohover.errors import NeurohoverError
from neurohover.evaluate import evaluate
from neurohover.experiments import Store, reproduce
from neurohover.experiments.config import load_config, make_config
from neurohover.experiments.executors import make_executor
from neurohover.experiments.plans import plan
from neurohover.experiments.runner import unchanged_units
from neurohover.models import DEFAULT_NOISE_ESTIMATE, learn_lr
from neurohover.policies import baseline_policy
from neurohover.tasks import get_task_family

TEST_RUNS = {"task": "ghh08", "seed": 7, "episodes": 2, "n_steps": 30, "policies": "shipped", "model_budget": 20, "predict_episodes": 1}


def _groups(noise: str | None = None) -> list[dict]:
    learner = {"agent": "model-based", "n_mdps": 2}
    if noise is not None:
        learner["noise"] = noise
    return [{"agent": "model-free", "n_mdps": 2}, learner]


def test_the_default_noise_estimate_is_the_authors() -> None:
    flight = evaluate(baseline_policy(), get_task_family("ghh08").training_mdps()[0], seed=3, record=True, n_steps=200).flight_data
    assert DEFAULT_NOISE_ESTIMATE == "rms" and ModelEvolution().noise == "rms"
    model = learn_lr(flight)
    assert model.stats["noise"] == "rms" and list(model.noise_std) == model.stats["noise_std_rms"]


def test_groups_that_learn_models_take_the_default_into_their_config_and_units() -> None:
    cfg = make_config("x", "test_runs", "quick", {**TEST_RUNS, "groups": _groups()})
    free, learner = cfg.settings["groups"]
    assert "noise" not in free and learner["noise"] == "rms"
    units = {u.key: u.params for u in plan(cfg, {}).units if u.kind == "test_run"}
    assert units["run/model-based/test0/rep0"]["noise"] == "rms"
    assert "noise" not in units["run/model-free/test0/rep0"]


def test_a_config_naming_innovations_hashes_and_plans_as_one_written_before_the_default_changed() -> None:
    """Before the change an absent estimate meant innovations: such a config's stored units resume."""
    named = make_config("x", "test_runs", "quick", {**TEST_RUNS, "groups": _groups("innovations")})
    default = make_config("x", "test_runs", "quick", {**TEST_RUNS, "groups": _groups()})
    rms = make_config("x", "test_runs", "quick", {**TEST_RUNS, "groups": _groups("rms")})
    assert default.hash == rms.hash != named.hash
    legacy = dict(named.settings, groups=[{k: v for k, v in g.items() if k != "noise"} for g in named.settings["groups"]])
    assert named.hash == type(named)(**{**named.__dict__, "settings": legacy}).hash
    params = [u.params for u in plan(named, {}).units if u.kind == "test_run"]
    assert params and all("noise" not in p for p in params)


def test_model_learning_takes_the_default_for_its_lr_methods_only() -> None:
    base = {"task": "ghh08", "seed": 1, "n_mdps": 1, "generic": "shipped"}
    cfg = make_config("y", "model_learning", "quick", {**base, "methods": ["ec-mer", "lr"]})
    assert cfg.settings["noise"] == "rms"
    units = {u.key: u.params for u in plan(cfg, {}).units}
    assert units["model/lr/test0"]["noise"] == "rms" and "noise" not in units["model/ec-mer/test0"]
    assert "noise" not in make_config("y", "model_learning", "quick", {**base, "methods": ["ec-mer"]}).settings
    with pytest.raises(NeurohoverError, match="noise = 'rms' applies to the LR methods without fits, not here: methods"):
        make_config("y", "model_learning", "quick", {**base, "methods": ["ec-mer"], "noise": "rms"})
    with pytest.raises(NeurohoverError, match="each of the fits gives its own"):
        make_config("y", "model_learning", "quick", {**base, "methods": ["lr"], "noise": "rms", "fits": [{"key": "a"}]})


def test_the_noise_factorials_name_our_old_estimate_so_their_stored_units_resume() -> None:
    for name in ("lr-noise-fig7", "lr-noise-fig11"):
        groups = {g.label: g.noise for g in load_config(name, "paper").typed.groups}
        assert groups.pop("model-free") is None
        assert groups and all(noise == ("rms" if label.endswith("/noise") else "innovations") for label, noise in groups.items())


def _run(cfg, store: Store, **kw) -> None:
    executor = make_executor("local", jobs=1)
    try:
        reproduce(cfg, store, executor, progress=False, **kw)
    finally:
        executor.close()


def test_update_keeps_the_unchanged_units_and_runs_the_changed_ones(tmp_path: Path) -> None:
    old = make_config("upd", "test_runs", "quick", {**TEST_RUNS, "groups": _groups("innovations")})
    new = make_config("upd", "test_runs", "quick", {**TEST_RUNS, "groups": _groups()})
    with Store(tmp_path / "s.sqlite") as store:
        _run(old, store)
        before = {u["key"]: u for u in store.units("upd", "quick")}
        with pytest.raises(NeurohoverError, match="--update to keep the stored units"):
            _run(new, store)
        assert unchanged_units(new, store) == {k for k in before if k.startswith("run/model-free/")}
        with pytest.raises(NeurohoverError, match="give one of them"):
            _run(new, store, fresh=True, update=True)
        _run(new, store, update=True)
        after = {u["key"]: u for u in store.units("upd", "quick")}
        assert store.config_hash("upd", "quick") == new.hash and set(after) == set(before)
        for key, unit in after.items():
            if key.startswith("run/model-free/"):  # kept, not flown again
                assert unit["result"] == before[key]["result"] and unit["finished"] == before[key]["finished"]
            else:  # flown again with the new estimate
                assert unit["params"]["noise"] == "rms" and "noise" not in before[key]["params"]
                assert unit["finished"] > before[key]["finished"]
        assert all(s["status"] == "finished" for s in store.sessions("upd", "quick"))


def test_update_refuses_units_of_another_version(tmp_path: Path) -> None:
    old = make_config("upd", "test_runs", "quick", {**TEST_RUNS, "groups": _groups("innovations")})
    new = make_config("upd", "test_runs", "quick", {**TEST_RUNS, "groups": _groups()})
    with Store(tmp_path / "s.sqlite") as store:
        _run(old, store, only=("run/model-free/test0/*",))
        stored = store.config("upd", "quick")
        stored["settings"]["seed"] = 8  # as if another version of the units had hashed it
        store.conn.execute("UPDATE experiments SET config = ? WHERE name = 'upd'", (json.dumps(stored),))
        store.conn.commit()
        with pytest.raises(NeurohoverError, match="rerun with --fresh instead of --update"):
            _run(new, store, update=True)
        assert len(store.units("upd", "quick")) == 1  # nothing lost


def test_update_and_fresh_together_are_refused_on_the_command_line(cli, tmp_path: Path) -> None:
    rc, _, err = cli("reproduce", "table4", "--scale", "quick", "--store", str(tmp_path / "s.sqlite"), "--fresh", "--update")
    assert rc == 2 and "give one of them" in err and "Traceback" not in err
