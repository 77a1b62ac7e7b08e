"""Bad-input trial 41, side B (the Python API and hand-edited files): evaluate_callable's on_step of the wrong arity was a
bare TypeError after the first step (T41-B01), and its n_steps was refused as "episode_steps", a parameter it has not
(T41-B10); evaluate_jobs' index arrays holding an integer past int64 were "must hold integers, got dtype object", naming
neither value nor range (T41-B09); flight_figure and crashed_episode took an episode_steps shorter than the episode drawn
(T41-B07); a strict policy set took a file whose prototype was edited to 'zero' or deleted (T41-B06); a Policy whose
frozen topology or genome was overwritten (object.__setattr__) was a KeyError or flown by evaluate, evaluate_jobs and
run_test, while save_policy checked it (T41-B11: checked again where every flight's policy table is made)."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest

import neurohover as nh
from neurohover.agents import Agent, Choice, run_test
from neurohover.errors import NeurohoverError
from neurohover.integrations.flying import evaluate_callable
from neurohover.plots import crashed_episode, flight_figure
from neurohover.policysets import SHIPPED, load_policy_set

FAM = nh.get_task_family("ghh08")
MDP = FAM.training_mdps()[0]


def _act(obs):
    return np.zeros((len(obs), 4))


@pytest.mark.parametrize("on_step", [lambda x: None, lambda x, y: None])
def test_evaluate_callables_on_step_of_the_wrong_arity_is_refused_before_the_flight(on_step) -> None:
    """T41-B01: `act` was arity-checked, `on_step` was not (a TypeError from inside flying.py)."""
    with pytest.raises(NeurohoverError, match=r"^on_step of signature '\(x.*\)' is not allowed: the flight calls on_step\(\) after each step"):
        evaluate_callable(_act, MDP, n_steps=5, on_step=on_step)
    calls = []
    evaluate_callable(_act, MDP, n_steps=5, on_step=lambda *args: calls.append(args))  # any no-argument call is taken
    assert calls == [()] * 5


@pytest.mark.parametrize("n_steps", [0, 10**8])
def test_evaluate_callables_n_steps_is_refused_under_its_own_name(n_steps: int) -> None:
    """T41-B10: it said "episode_steps=0 is out of range", as evaluate says n_steps."""
    with pytest.raises(NeurohoverError, match=rf"^n_steps={n_steps} is out of range: allowed an integer in 1\.\.10000000"):
        evaluate_callable(_act, MDP, n_steps=n_steps)


@pytest.mark.parametrize(
    ("where", "value", "shown"),
    [
        ("episode_index", 10**30, r"1000000000\.\.\.\(31 digits\)"),
        ("episode_index", -(10**30), r"-1000000000\.\.\.\(31 digits\)"),
        ("policy_index", 2**70, "1180591620717411303424"),
        ("policy_index", 2**64, "18446744073709551616"),
    ],
)
def test_evaluate_jobs_names_an_index_past_int64_and_the_range(where: str, value: int, shown: str) -> None:
    """T41-B09: an integer past int64 makes an array of objects; it was "must hold integers, got dtype object"."""
    indices = {"policy_index": [0], "episode_index": [0], where: [value]}
    with pytest.raises(NeurohoverError, match=rf"^{where} holds {shown}, out of range: allowed 0\.\.2\*\*63-1$"):
        nh.evaluate_jobs([nh.baseline_policy()], [MDP], indices["policy_index"], [0], indices["episode_index"], n_steps=5)
    with pytest.raises(NeurohoverError, match=r"^episode_index must hold integers, got dtype object$"):  # not integers: as before
        nh.evaluate_jobs([nh.baseline_policy()], [MDP], [0], [0], np.array(["x"], dtype=object), n_steps=5)


def test_flight_figure_refuses_an_episode_steps_shorter_than_its_episode() -> None:
    """T41-B07: 10 for a 6000-step episode was drawn ("no crash"), a contradiction the FlightData constructor refuses."""
    obs, act = np.zeros((6, 12)), np.zeros((5, 4))
    words = r"^the episode has 5 steps, more than episode_steps=3 \(every episode ends at that budget\): .* an integer in 5\.\.10,000,000$"
    with pytest.raises(NeurohoverError, match=words):
        flight_figure(obs, act, episode_steps=3)
    with pytest.raises(NeurohoverError, match=words):
        crashed_episode(act, 3)
    assert crashed_episode(act, 5) is False and crashed_episode(act, 6) is True  # at and above the length: as before


def _edited_set(tmp_path: Path, edit) -> Path:
    shutil.copytree(SHIPPED / "ghh08", tmp_path / "ghh08")
    path = tmp_path / "ghh08" / "specialised_3.json"
    record = json.loads(path.read_text())
    edit(record)
    path.write_text(json.dumps(record))
    return tmp_path


@pytest.mark.parametrize(
    ("edit", "words"),
    [
        (lambda r: r.update(prototype="zero"), r"specialised_3\.json \(specialised policy 3\) records prototype 'zero', not 'baseline'"),
        (lambda r: r.pop("prototype"), r"specialised_3\.json records no prototype, which its build wrote \(allowed 'baseline'"),
    ],
)
def test_a_policy_sets_file_whose_prototype_was_edited_is_refused(tmp_path: Path, edit, words: str) -> None:
    """T41-B06: name, target, seed, budget, n_steps, topology and genome were cross-checked, the prototype not."""
    with pytest.raises(NeurohoverError, match=words):
        load_policy_set("ghh08", _edited_set(tmp_path, edit))
    assert load_policy_set("ghh08", _edited_set(tmp_path / "as-built", lambda r: None)).specialised[3].metadata["prototype"] == "baseline"


def _overwritten(field: str, value) -> nh.Policy:
    policy = nh.prototype("slp", "baseline")
    object.__setattr__(policy, field, value)  # past the frozen dataclass
    return policy


class _Chooser(Agent):
    name = "chooser"

    def __init__(self, policy: nh.Policy) -> None:
        self.policy = policy

    def choose(self, episode):
        return Choice(self.policy, "p", final=True)

    def update(self, outcome):
        pass


@pytest.mark.parametrize(
    ("field", "value", "words"),
    [
        ("topology", "rnn", r"^unknown policy topology 'rnn': allowed slp, mlp$"),
        ("topology", "mlp", r"^a mlp genome has 42 genes, got shape \(40,\)$"),
        ("genome", np.zeros(3), r"^a slp genome has 40 genes, got shape \(3,\)$"),
    ],
)
def test_a_policy_whose_frozen_fields_were_overwritten_is_checked_again_before_it_flies(field: str, value, words: str) -> None:
    """T41-B11: KeyError 'rnn' from evaluate; a 3-gene genome or an SLP genome relabelled 'mlp' was flown without a word."""
    fallback = nh.Safeguard(nh.prototype("slp", "baseline"))
    object.__setattr__(fallback.fallback, field, value)
    policy = _overwritten(field, value)
    with pytest.raises(NeurohoverError, match=words):
        nh.save_policy(policy, "never-written.json")  # what save_policy already said
    for fly in (
        lambda: nh.evaluate(policy, MDP, n_steps=5),
        lambda: nh.evaluate_jobs([policy], [MDP], [0], [0], [0], n_steps=5),
        lambda: nh.evaluate(nh.baseline_policy(), MDP, n_steps=5, safeguard=fallback),
        lambda: run_test(_Chooser(policy), FAM, MDP, episodes=1, n_steps=5),
    ):
        with pytest.raises(NeurohoverError, match=words):
            fly()
