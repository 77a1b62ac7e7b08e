"""Bad-input trial 59, side B (run-time registries): a user's task family whose make() ignores its params was refused
only where kernel rows are built (rows(), the vector environment), while training_mdps, test_mdps, mdp('test:3'),
sample(), make() itself and HoverEnv flew every MDP at the default dynamics without a word (T59-B02); and ``report`` on
a store holding a compete run of an agent registered at run time, from a process without it registered, was a
KeyError traceback (the command line left an empty output directory), where ``results`` exports the same store
(T59-B03)."""

from __future__ import annotations

import subprocess
import sys
from dataclasses import dataclass

import numpy as np
import pytest

import neurohover.tasks.base as base
from neurohover.agents import registry as R
from neurohover.agents.protocol import Agent, Choice
from neurohover.agents.spec import AgentSpec
from neurohover.compete import compete
from neurohover.envs import HoverEnv
from neurohover.errors import NeurohoverError
from neurohover.experiments import Store, write_report
from neurohover.sim.constants import DEFAULT_PARAMS, ROW_PARAMS
from neurohover.tasks import MDP, TASK_FAMILIES, TaskFamily, get_task_family

_NAMES = ("C_u", "C_v", "D_v", "C_w", "D_w", "C_p", "D_p", "C_q", "D_q", "C_r", "D_r")
FAMILY = "t59_reg_family_1"
AGENT = "t59agent1"


def _draws(self, rng, n):
    """A heavier helicopter's draws: D_w scaled by a factor in [0.5, 1], one per MDP."""
    out = np.repeat(DEFAULT_PARAMS[None, :], n, axis=0)
    out[:, 4] *= rng.uniform(0.5, 1.0, n)
    return out


def _family(name: str, make) -> type[TaskFamily]:
    """A user's family of the 11 GHH parameters (README's Extending neurohover) with the given make."""
    attributes = {"__module__": __name__, "name": name, "n_params": 11, "param_names": _NAMES, "row_slice": ROW_PARAMS, "set_code": 159}
    attributes |= {"make": make, "zero": lambda self: MDP(name, label=f"{name}/zero"), "sample_params": _draws}
    return dataclass(frozen=True)(type("Heavy59", (TaskFamily,), attributes))


@pytest.fixture
def register(monkeypatch):
    """Register a family for this test only, with private fixed sets and row templates."""
    monkeypatch.setattr(base, "_FIXED_SETS", {})
    monkeypatch.setattr(base, "_ROW_LAYOUTS", {})

    def put(name: str, make) -> TaskFamily:
        monkeypatch.setitem(TASK_FAMILIES, name, _family(name, make))
        return get_task_family(name)

    return put


# --------------------------------------------------------------------------- T59-B02: a make() that ignores its params

IGNORED = rf"^{FAMILY} make\(\)'s kernel row is not allowed: it does not put the parameters .* they sit nowhere in its row"


def _ignoring(self, params, label=""):
    return MDP(FAMILY, label=label)  # the bug: params ignored


@pytest.mark.parametrize(
    "use",
    [
        lambda f: f.training_mdps(),
        lambda f: f.test_mdps(),
        lambda f: f.mdp("test:3"),
        lambda f: f.mdp("seeded-train:0"),
        lambda f: f.sample(0),
        lambda f: f.make(DEFAULT_PARAMS * 0.9),
        lambda f: HoverEnv(task=FAMILY).reset(seed=0),
    ],
    ids=["training_mdps", "test_mdps", "mdp-test:3", "mdp-seeded-train:0", "sample", "make", "HoverEnv"],
)
def test_a_make_that_ignores_its_params_is_refused_on_every_path(register, use):
    """T59-B02: each gave MDPs of the default D_w (-42.15), the sampled values lost; rows() alone refused the family."""
    family = register(FAMILY, _ignoring)
    with pytest.raises(NeurohoverError, match=IGNORED):
        use(family)
    with pytest.raises(NeurohoverError, match=IGNORED):  # refused again, not taken from a cache the first try filled
        use(family)


# --------------------------------------------------------------------------- T59-B03: report of a run-time agent's store


class Flies59(Agent):
    """Flies its generic policy every episode."""

    name = AGENT

    def __init__(self, generic) -> None:
        self.generic = generic

    def choose(self, episode):
        return Choice(self.generic, "generic", final=True)

    def update(self, outcome) -> None:
        pass


@pytest.fixture(scope="module")
def store(tmp_path_factory):
    """A store holding a compete run of the agent, registered only while it ran (as in the script that ran compete)."""
    where = tmp_path_factory.mktemp("t59reg")
    with pytest.MonkeyPatch.context() as mp:
        mp.setitem(R.AGENTS, AGENT, AgentSpec(AGENT, "specialised", frozenset({"generic"}), lambda p, o: Flies59(p.generic)))
        compete("ghh08", AGENT, runs=1, episodes=2, n_steps=20, out=where / "out", store=where / "s.sqlite")
    assert AGENT not in R.AGENTS
    return where / "s.sqlite"


@pytest.mark.slow
def test_write_report_of_an_unregistered_agents_store(store, tmp_path):
    """T59-B03: KeyError 't59agent1' at report_factorial.varies."""
    written = write_report(Store(store), tmp_path / "rep")
    assert f"compete-ghh08-{AGENT}" in (tmp_path / "rep" / "report.md").read_text(encoding="utf-8")
    assert written is not None


@pytest.mark.slow
def test_report_command_of_an_unregistered_agents_store(store, tmp_path):
    """T59-B03: a traceback, exit status 1, and an empty rep/ left behind."""
    out = tmp_path / "rep"
    done = subprocess.run([sys.executable, "-m", "neurohover", "report", "--store", str(store), "--out", str(out)], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert "Traceback" not in done.stderr
    assert f"compete-ghh08-{AGENT}" in (out / "report.md").read_text(encoding="utf-8")
