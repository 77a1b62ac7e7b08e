"""Bad-input trial 41, side B, the optimiser registry and evolution's policy records: an entry of ``OPTIMISERS`` that is
no OptimiserSpec (5, None) was an AttributeError in evolve and in every later load_policy (T41-B02); the 'cma' slot
holding OpenAI-ES's spec ran OpenAI-ES as cma and wrote a record its reader refused elsewhere (T41-B03); a run-time
optimiser under a key other than its spec's name, with a shipped label or a key with a space recorded a mismatched
method (T41-B04); a policy record whose mdp_params carry a drift was taken (T41-B05); the API's evolve left the sensor
its run saw out of the champion's record (T41-B08)."""

from __future__ import annotations

import dataclasses
import json

import pytest

import neurohover as nh
from neurohover.errors import NeurohoverError
from neurohover.evolution import evolve
from neurohover.evolution.optimisers import OPTIMISERS

FAMILY = nh.get_task_family("ghh08")
MDP = FAMILY.mdp("train:0")


def _evolve(optimizer: str, target=MDP, **kwargs):
    return evolve(target, optimizer=optimizer, topology="slp", budget=8, seed=0, n_steps=20, **kwargs)


@pytest.fixture(scope="module")
def es_policy(tmp_path_factory):
    path = tmp_path_factory.mktemp("t41") / "es.json"
    champion = _evolve("openai-es").champion
    nh.save_policy(champion, path)
    return path


@pytest.mark.parametrize("bad", [5, None])
def test_a_registry_entry_that_is_no_spec_is_refused_by_name_and_breaks_nothing_else(monkeypatch, es_policy, bad):
    monkeypatch.setitem(OPTIMISERS, "bad", bad)
    assert nh.load_policy(es_policy).metadata["method"] == "openai-es"  # an unrelated file reads as before
    with pytest.raises(NeurohoverError, match=rf"OPTIMISERS\['bad'\] = {bad} is not allowed: register an OptimiserSpec"):
        _evolve("bad")
    assert _evolve("openai-es").champion.metadata["optimizer"] == "openai-es"  # another optimiser still runs


def test_a_replaced_shipped_entry_is_refused_where_used_and_its_records_still_read(monkeypatch, tmp_path):
    path = tmp_path / "cma.json"
    nh.save_policy(_evolve("cma").champion, path, settings={"popsize": 6})  # settings as the command line records them
    monkeypatch.setitem(OPTIMISERS, "cma", OPTIMISERS["openai-es"])
    with pytest.raises(NeurohoverError, match=r"OPTIMISERS\['cma'\] = .* is not allowed: 'cma' is a shipped optimiser's name and holds its shipped spec"):
        _evolve("cma")
    assert nh.load_policy(path).metadata["method"] == "cma-es"  # checked against the shipped spec, not the slot
    monkeypatch.setitem(OPTIMISERS, "cma", None)
    assert nh.load_policy(path).metadata["settings"] == {"popsize": 6}


@pytest.mark.parametrize(
    "key, edit, why",
    [
        ("other-name", {}, r"its spec's name 'openai-es' is not its key"),
        ("my-es", {"name": "my-es"}, r"its label 'openai-es' is not its name; a run-time optimiser records its name as its method \(user:my-es\)"),
        ("my es", {"name": "my es", "label": ""}, r"a run-time optimiser's name is one line of at most 64 letters, digits and \._\+-"),
    ],
)
def test_a_run_time_entry_under_another_name_or_label_is_refused(monkeypatch, key, edit, why):
    monkeypatch.setitem(OPTIMISERS, key, dataclasses.replace(OPTIMISERS["openai-es"], **edit))
    with pytest.raises(NeurohoverError, match=rf"OPTIMISERS\['{key}'\] = .* is not allowed: {why}"):
        _evolve(key)


def test_a_run_time_copy_of_a_shipped_spec_records_its_own_name(monkeypatch, tmp_path):
    monkeypatch.setitem(OPTIMISERS, "my-es", dataclasses.replace(OPTIMISERS["openai-es"], name="my-es", label=""))
    champion = _evolve("my-es").champion
    assert (champion.metadata["method"], champion.metadata["optimizer"]) == ("user:my-es", "user:my-es")
    path = tmp_path / "mine.json"
    nh.save_policy(champion, path)
    path.write_text(json.dumps({**json.loads(path.read_text()), "method": "user:openai-es"}))  # as the label was recorded
    with pytest.raises(NeurohoverError, match=r"its method 'user:openai-es' is not allowed beside its optimizer 'user:my-es'"):
        nh.load_policy(path)


def test_a_drift_in_a_records_mdp_params_is_refused(es_policy, tmp_path):
    record = json.loads(es_policy.read_text())
    params = {**MDP.to_dict(), "drift": {"walk": 0.01}}
    path = tmp_path / "drift.json"
    path.write_text(json.dumps({**record, "task": "ghh08", "mdp": "train:0", "mdp_params": params}))
    with pytest.raises(NeurohoverError, match=r"its mdp_params drift \{'walk': 0.01\} is not allowed: evolution flies fixed dynamics"):
        nh.load_policy(path)
    path.write_text(json.dumps({**record, "task": "ghh08", "mdp": "train:0", "mdp_params": MDP.to_dict()}))
    assert nh.load_policy(path).metadata["mdp_params"] == MDP.to_dict()  # without one, as evolve writes it


@pytest.mark.parametrize("target", [MDP.with_sensor(nh.Sensor(delay=2)), nh.get_task_family("ghh08", sensor=nh.Sensor(delay=2))])
def test_the_apis_champion_records_the_sensor_its_run_saw(target, tmp_path):
    champion = _evolve("openai-es", target=target).champion
    assert champion.metadata["sensor"] == nh.Sensor(delay=2).to_dict()
    path = tmp_path / "sensor.json"
    nh.save_policy(champion, path)
    assert nh.load_policy(path).metadata["sensor"] == nh.Sensor(delay=2).to_dict()
    assert "sensor" not in _evolve("openai-es").champion.metadata  # exact sensors: nothing, as before
