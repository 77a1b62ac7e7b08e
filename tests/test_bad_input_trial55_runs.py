"""Bad-input trial 55, side B (runs): a user's optimiser registered at run time whose from_state_dict forgot part of its
state (its generator, its champion) resumed without a word, over a task family unchecked at all (T55-B04); an agent
that flew two policies under one Choice label was recorded as flying one, its learning episodes counted as the final
policy's (T55-B06); a checkpoint of an evolution over a run-time task family resumed after the family was redefined
under its name with another distribution, two distributions flown as one run (T55-B10)."""

from __future__ import annotations

import dataclasses
import json
from dataclasses import dataclass

import numpy as np
import pytest

import neurohover as nh
import neurohover.tasks.base as base
from neurohover.agents.protocol import Agent, Choice, run_test
from neurohover.evolution import evolve
from neurohover.evolution.optimisers import OPTIMISERS, OptimiserSpec
from neurohover.policies import GENOME_LENGTH
from neurohover.sim.constants import DEFAULT_PARAMS, ROW_PARAMS
from neurohover.tasks import MDP, TASK_FAMILIES, TaskFamily, finite_vector

GHH08 = nh.get_task_family("ghh08")
RUN = {"optimizer": "forget", "topology": "slp", "n_steps": 20, "seed": 3}

# --------------------------------------------------------------------------- T55-B04: an optimiser's state read back whole


@dataclasses.dataclass(frozen=True)
class _S:
    popsize: int = 4


class _Forgetful:
    """A user's optimiser: 4 noisy copies of its mean a generation, its champion the best told; its from_state_dict
    restores what ``keeps`` names of its state ("champion", "rng"), the rest started afresh."""

    keeps: tuple[str, ...] = ("champion", "rng")

    def __init__(self, proto, settings, seed):
        self.p, self.best, self.r, self.n = np.asarray(proto, float), None, -np.inf, settings.popsize
        self.rng = np.random.default_rng(seed)

    def ask(self):
        self.last = self.p + self.rng.normal(0, 0.01, (self.n, self.p.size))
        return self.last

    def tell(self, fitness, info=None):
        i = int(np.argmax(fitness))
        if fitness[i] > self.r:
            self.best, self.r = self.last[i].copy(), float(fitness[i])

    def stop(self):
        return False

    @property
    def champion_genome(self):
        return self.best

    @property
    def champion_return(self):
        return self.r

    def state_dict(self):
        best = None if self.best is None else self.best.tolist()
        return {"r": self.r if np.isfinite(self.r) else None, "best": best, "p": self.p.tolist(), "n": self.n, "rng": self.rng.bit_generator.state}

    @classmethod
    def from_state_dict(cls, state):
        opt = cls(np.asarray(state["p"]), _S(state["n"]), 0)
        if "champion" in cls.keeps:
            opt.r = -np.inf if state["r"] is None else state["r"]
            opt.best = None if state["best"] is None else np.asarray(state["best"])
        if "rng" in cls.keeps:
            opt.rng.bit_generator.state = state["rng"]
        state.clear()  # (what it read is its own to change: the run compares with the state as read)
        return opt


@pytest.fixture
def forgetful(monkeypatch):
    monkeypatch.setitem(OPTIMISERS, "forget", OptimiserSpec("forget", "user", settings=_S, make=_Forgetful, stops_itself=False))
    return lambda keeps: monkeypatch.setattr(_Forgetful, "keeps", keeps)


@pytest.mark.parametrize(
    ("target", "keeps", "entry"),
    [(GHH08.mdp("train:0"), ("champion",), r"\['rng'\]\['state'\]\['state'\] is \d+.*, where the checkpoint's state has \d+"), (GHH08, (), r"\['r'\] is None")],
    ids=["mdp-rng-forgotten", "family-all-forgotten"],
)
def test_a_from_state_dict_forgetting_its_state_is_refused_by_entry(forgetful, tmp_path, target, keeps, entry):
    evolve(target, budget=12, checkpoint=tmp_path / "ck.json", **RUN)
    forgetful(keeps)
    with pytest.raises(
        nh.NeurohoverError,
        match=rf"optimizer 'forget': its from_state_dict answered an optimiser whose state_dict\(\) entry {entry}.*, which is not allowed: "
        r"from_state_dict\(state\) gives back the optimiser whose state_dict\(\) wrote state, all of it",
    ):
        evolve(target, budget=24, checkpoint=tmp_path / "ck.json", resume=True, **RUN)


@pytest.mark.parametrize("target", [GHH08.mdp("train:0"), GHH08], ids=["mdp", "family"])
def test_a_from_state_dict_restoring_its_whole_state_resumes_as_one_run(forgetful, tmp_path, target):
    straight = evolve(target, budget=24, **RUN)
    evolve(target, budget=12, checkpoint=tmp_path / "ck.json", **RUN)
    assert evolve(target, budget=24, checkpoint=tmp_path / "ck.json", resume=True, **RUN).champion_return == straight.champion_return


def test_a_shipped_optimiser_under_a_run_time_name_resumes(monkeypatch, tmp_path):  # its state's wall clock runs on
    spec = OPTIMISERS["openai-es"]
    monkeypatch.setitem(OPTIMISERS, "my-es", OptimiserSpec("my-es", "mine", spec.settings, spec.make, stops_itself=False))
    run = {**RUN, "optimizer": "my-es", "checkpoint": tmp_path / "ck.json"}
    evolve(GHH08, budget=20, **run)
    assert evolve(GHH08, budget=40, resume=True, **run).evaluations > 0


# --------------------------------------------------------------------------- T55-B06: one label, one policy


class _Labelled(Agent):
    """Flies ``first`` for two episodes, then ``then`` to the end, both under the label 'p'."""

    name = "same-label"

    def __init__(self, first, then):
        self.first, self.then = first, then

    def start(self, family, rng):
        pass

    def choose(self, episode):
        return Choice(self.first, "p") if episode < 2 else Choice(self.then, "p", final=True)

    def update(self, outcome):
        pass


def _flown(first, then):
    return run_test(_Labelled(first, then), GHH08, GHH08.mdp("test:0"), episodes=4, n_steps=20)


@pytest.mark.parametrize(("first", "other"), [(nh.Policy("slp", np.zeros(40)), "genome"), (nh.Policy("mlp", np.zeros(GENOME_LENGTH["mlp"])), "topology")])
def test_a_label_chosen_again_with_another_policy_is_refused(first, other):
    with pytest.raises(
        nh.NeurohoverError,
        match=rf"agent 'same-label' chose label 'p' for episode 2 with a policy of another {other} than it flew under that label from episode 0, "
        r"which is not allowed: give each policy a label of its own",
    ):
        _flown(first, nh.baseline_policy())


def test_a_label_chosen_again_with_the_same_policy_is_flown():
    again = nh.Policy("slp", nh.baseline_policy().genome.copy())  # another object, the same policy
    assert _flown(nh.baseline_policy(), again).policy == ["p"] * 4


# --------------------------------------------------------------------------- T55-B10: a run-time family's G in its checkpoints


def _light(self, rng, n):
    out = np.repeat(DEFAULT_PARAMS[None, :], n, axis=0)
    out[:, 4] *= rng.uniform(0.5, 1.0, n)
    return out


def _heavy(self, rng, n):
    out = np.repeat(DEFAULT_PARAMS[None, :], n, axis=0)
    out[:, 4] *= rng.uniform(2.0, 3.0, n)
    return out


def _family(sample) -> type[TaskFamily]:
    """A user's family 'heavy55' of the 11 GHH parameters drawing by ``sample``."""

    def made(self, params, label=""):
        return MDP("heavy55", params=tuple(finite_vector(params, 11, "p").tolist()), label=label)

    names = ("C_u", "C_v", "D_v", "C_w", "D_w", "C_p", "D_p", "C_q", "D_q", "C_r", "D_r")
    attributes = {"__module__": __name__, "name": "heavy55", "n_params": 11, "param_names": names, "row_slice": ROW_PARAMS, "set_code": 155}
    attributes |= {"make": made, "zero": lambda self: MDP("heavy55", label="heavy55/zero"), "sample_params": sample}
    return dataclass(frozen=True)(type("Heavy55", (TaskFamily,), attributes))


@pytest.fixture
def define(monkeypatch):
    """(Re)define the family 'heavy55' for this test only, with private fixed sets and row templates."""
    monkeypatch.setattr(base, "_FIXED_SETS", {})
    monkeypatch.setattr(base, "_ROW_LAYOUTS", {})

    def put(sample):
        monkeypatch.setitem(TASK_FAMILIES, "heavy55", _family(sample))
        return nh.get_task_family("heavy55")

    return put


FAMILY_RUN = {"topology": "slp", "n_steps": 10, "seed": 0, "resampling": "fixed:1"}


def test_a_family_redefined_since_its_checkpoint_is_refused(define, tmp_path):
    ck = tmp_path / "hk.json"
    evolve(define(_light), budget=50, checkpoint=ck, **FAMILY_RUN)
    assert len(json.loads(ck.read_text())["family_draws"]) == 16
    evolve(define(_light), budget=100, checkpoint=ck, resume=True, **FAMILY_RUN)  # defined alike: resumed
    with pytest.raises(
        nh.NeurohoverError,
        match=r"hk.json' was written by a run over another task family 'heavy55' \(its sample_params' seeded draws have digest [0-9a-f]{16}, the "
        r"family's now [0-9a-f]{16}: it was redefined under its name since\), which is not allowed: resume with the family defined as when the run began",
    ):
        evolve(define(_heavy), budget=150, checkpoint=ck, resume=True, **FAMILY_RUN)


def test_a_checkpoint_without_family_draws_resumes_and_a_shipped_familys_has_none(define, tmp_path):
    ck = tmp_path / "hk.json"
    evolve(define(_light), budget=50, checkpoint=ck, **FAMILY_RUN)
    older = json.loads(ck.read_text())
    del older["family_draws"]
    ck.write_text(json.dumps(older))
    evolve(define(_heavy), budget=100, checkpoint=ck, resume=True, **FAMILY_RUN)  # written before the digest: as before
    evolve(GHH08, budget=50, checkpoint=tmp_path / "g.json", **FAMILY_RUN)
    assert "family_draws" not in json.loads((tmp_path / "g.json").read_text())
