"""Bad-input trial 52, side B, a user's ask/tell optimiser registered at run time (README, A new optimiser): its
champion_genome of text, a table, a ragged list or complex numbers failed in NumPy or was taken with a warning
(T52-B07); a spec's make of the wrong arity or none, or answering None, failed with a raw TypeError or AttributeError
(T52-B08); its settings no frozen dataclass class, or of a default JSON cannot write, failed in asdict or the JSON
writer (T52-B09); a tell(self, fitness) without info was a TypeError after the first generation (T52-B10); its
stop_reason 'budget', 5, '' or 'a\\nb', stops_itself='no' (a run with no budget never ended) and stop() answering
"yes" or None were taken (T52-B11); a from_state_dict ignoring its state or answering None was called a damaged
checkpoint (T52-B12); a state_dict() with keys that are no text, or tuples, was written as text keys and lists
(T52-B17)."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest
from test_bad_input_trial40_evolution import _Mine as _Trial40Mine

import neurohover as nh
from neurohover.errors import NeurohoverError
from neurohover.evolution import evolve
from neurohover.evolution.optimisers import OPTIMISERS, OptimiserSpec

MDP = nh.get_task_family("ghh08").mdp("train:0")


@dataclasses.dataclass(frozen=True)
class _S:
    popsize: int = 4


class _Mine(_Trial40Mine):
    """A user's optimiser (the trial's): a generation of 4 copies of the prototype, its champion the best told (trial
    40's, answering as it should: each test here changes one of its methods on this subclass)."""


def _register(monkeypatch, **kwargs):
    kwargs = {"settings": _S, "make": _Mine, "stops_itself": False, **kwargs}
    monkeypatch.setitem(OPTIMISERS, "mine", OptimiserSpec("mine", "user", **kwargs))


def _evolve(**kwargs):
    return evolve(MDP, optimizer="mine", topology="slp", n_steps=20, **{"budget": 8, **kwargs})


@pytest.mark.parametrize("genome", ["x", {"a": 1}, [[1, 2], [3]], np.zeros(40, complex), np.zeros(3), np.full(40, np.nan)])
def test_a_champion_genome_of_the_wrong_kind_is_refused_by_name(monkeypatch, genome):  # T52-B07
    _register(monkeypatch)
    monkeypatch.setattr(_Mine, "champion_genome", property(lambda s: None if s.best is None else genome))
    with pytest.raises(NeurohoverError, match=r"optimizer 'mine': its champion_genome .* is not allowed: give None .* shape \(40,\)"):
        _evolve()


def test_a_well_behaved_user_optimiser_runs(monkeypatch):
    _register(monkeypatch)
    assert -1e4 < _evolve().champion_return <= 0


@pytest.mark.parametrize(
    "make, said",
    [
        (lambda prototype: None, r"its make of signature '\(prototype\)' cannot be called as a run calls it"),
        (5, r"its make 5 is no callable"),
    ],
)
def test_a_spec_make_of_the_wrong_kind_is_refused(monkeypatch, make, said):  # T52-B08
    _register(monkeypatch, make=make)
    with pytest.raises(NeurohoverError, match=rf"OPTIMISERS\['mine'\] = .* is not allowed: {said}"):
        _evolve()


def test_a_make_answering_no_optimiser_is_refused(monkeypatch):  # T52-B08
    _register(monkeypatch, make=lambda proto, settings, seed: None)
    with pytest.raises(NeurohoverError, match=r"optimizer 'mine': its make answered NoneType None, which has no ask\(\) and is not allowed"):
        _evolve()


_F32 = dataclasses.make_dataclass("F32", [("lr", float, dataclasses.field(default=np.float32(0.1)))], frozen=True)


@pytest.mark.parametrize(
    "settings, said",
    [
        (type("Plain", (), {"popsize": 4}), r"its settings .*Plain.* is no frozen dataclass class"),
        (_S(), r"its settings .* is no frozen dataclass class"),
        (dataclasses.make_dataclass("Loose", [("popsize", int, 4)]), r"its settings .*Loose.* is no frozen dataclass class"),
        (_F32, r"its settings field 'lr''s default is float32 .*, no plain JSON value"),
        (dataclasses.make_dataclass("Bare", [("popsize", int)], frozen=True), r"its settings field 'popsize' has no default"),
    ],
)
def test_spec_settings_that_are_no_frozen_dataclass_of_json_defaults_are_refused(monkeypatch, settings, said):  # T52-B09
    _register(monkeypatch, settings=settings)
    with pytest.raises(NeurohoverError, match=rf"OPTIMISERS\['mine'\] = .* is not allowed: {said}"):
        _evolve()


def test_a_tell_without_info_is_refused_before_flying(monkeypatch):  # T52-B10
    _register(monkeypatch)
    monkeypatch.setattr(_Mine, "tell", lambda s, f: None)
    with pytest.raises(NeurohoverError, match=r"optimizer 'mine': its tell of signature '\(f\)' is not allowed: a run calls tell\(fitness, info=None\)"):
        _evolve()


@pytest.mark.parametrize(
    "spec, said",
    [
        ({"stop_reason": "budget", "stops_itself": True}, r"its stop_reason 'budget' names no stop of its own"),
        ({"stop_reason": 5}, r"its stop_reason 5 names no stop of its own"),
        ({"stop_reason": ""}, r"its stop_reason '' names no stop of its own"),
        ({"stop_reason": "a\nb"}, r"its stop_reason 'a\\nb' names no stop of its own"),
        ({"stops_itself": "no"}, r"its stops_itself 'no' is no bool"),
    ],
)
def test_a_spec_stop_reason_or_stops_itself_of_the_wrong_kind_is_refused(monkeypatch, spec, said):  # T52-B11
    _register(monkeypatch, **spec)
    with pytest.raises(NeurohoverError, match=rf"OPTIMISERS\['mine'\] = .* is not allowed: {said}"):
        _evolve(budget=None, progress=_halt, progress_every_s=0)  # stops_itself='no' ran for ever here


def _halt(info) -> None:
    if info.generation >= 3:
        raise RuntimeError("the run went on")


@pytest.mark.parametrize("answer", ["yes", None, [], np.array([True])])
def test_a_stop_answer_that_is_no_bool_is_refused(monkeypatch, answer):  # T52-B11
    _register(monkeypatch, stop_reason="mine-stop", stops_itself=True)
    monkeypatch.setattr(_Mine, "stop", lambda s: answer)
    with pytest.raises(NeurohoverError, match=r"optimizer 'mine': its stop\(\) answered .* which is not allowed: answer True or False"):
        _evolve(budget=800)


def test_a_stop_answering_a_numpy_bool_stops_by_its_own_reason(monkeypatch):  # T52-B11
    _register(monkeypatch, stop_reason="mine-stop", stops_itself=True)
    monkeypatch.setattr(_Mine, "stop", lambda s: np.bool_(True))
    result = _evolve(budget=800)
    assert result.stop_reason == "mine-stop"


@pytest.mark.parametrize("answer, said", [("ignore", r"champion_return -inf, where the checkpoint's champion has return -"), ("none", r"NoneType None")])
def test_a_from_state_dict_that_loses_its_state_is_named(monkeypatch, tmp_path, answer, said):  # T52-B12
    _register(monkeypatch)
    ck = tmp_path / "ck.json"
    _evolve(checkpoint=ck, checkpoint_every_s=1e-9)
    if answer == "none":
        monkeypatch.setattr(_Mine, "from_state_dict", classmethod(lambda c, st: None))
    with pytest.raises(NeurohoverError, match=rf"optimizer 'mine': its from_state_dict answered .*{said}") as err:
        _evolve(budget=16, checkpoint=ck, resume=True)
    assert "damaged" not in str(err.value)


@pytest.mark.parametrize(
    "state, at",
    [
        ({1: 2.5, "n": {2: "x"}}, r"\[1\] \(a key that is no text, which JSON writes as text\) is int 1"),
        ({"n": {2: "x"}}, r"\['n'\]\[2\] \(a key that is no text"),
        ({"t": (1, 2)}, r"\['t'\] \(a tuple, which JSON writes as a list\)"),
    ],
)
def test_a_state_dict_that_json_writes_otherwise_is_refused(monkeypatch, tmp_path, state, at):  # T52-B17
    _register(monkeypatch)
    monkeypatch.setattr(_Mine, "state_dict", lambda s: state)
    with pytest.raises(NeurohoverError, match=rf"optimizer 'mine': its state_dict\(\) entry {at}"):
        _evolve(checkpoint=tmp_path / "ck.json")
    assert list(tmp_path.iterdir()) == []


def test_a_plain_state_dict_is_written_as_it_is(monkeypatch, tmp_path):  # T52-B17
    _register(monkeypatch)
    monkeypatch.setattr(_Mine, "state_dict", lambda s: {"n": [1, {"k": "x"}], "x": 2.5})
    ck = tmp_path / "ck.json"
    _evolve(checkpoint=ck, checkpoint_every_s=1e-9)
    assert json.loads(ck.read_text())["optimizer_state"] == {"n": [1, {"k": "x"}], "x": 2.5}
