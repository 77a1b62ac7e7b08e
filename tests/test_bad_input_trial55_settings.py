"""Bad-input trial 55, side B (settings of a user's agent and of a run-time optimiser): an agent's settings of the
wrong type (``k='x'`` for ``k: int = 2``, 2.5, True; text for a float, 5 for a text) were stored and handed to the
agent from --agent-setting, AgentOptions(settings={...}) and a config group's settings table (T55-B01); a run-time
optimiser's were handed to its make, and failed in NumPy inside the user's ask() or flew True as 1.0 (T55-B02); a
float setting given NaN or an infinity was refused only by the results store, naming the whole config, after the
run's folder and store were made (T55-B03); a spec whose build dropped ``options.settings`` flew an agent with
settings None while the run recorded those given (T55-B07); and a run-time optimiser named 'generational' or
'steady-state' was an AttributeError or an AssertionError inside the run (T55-B08). Each is now one NeurohoverError
naming the setting, the value and what is allowed (the spec, or the registry entry), before anything is written."""

from __future__ import annotations

import dataclasses
import re

import numpy as np
import pytest

import neurohover as nh
from neurohover.agents import registry as R
from neurohover.agents.protocol import Agent, Choice
from neurohover.agents.spec import AgentOptions, AgentSettings, AgentSpec
from neurohover.compete import check_agent_settings
from neurohover.errors import NeurohoverError
from neurohover.evolution import evolve
from neurohover.evolution.optimisers import OPTIMISERS, OptimiserSpec, population_settings

NEEDS = frozenset({"generic"})


@dataclasses.dataclass(frozen=True)
class BSettings(AgentSettings):
    """The trial's settings: plain fields, no ``__post_init__`` of their own."""

    k: int = 2
    rate: float = 0.5
    mode: str = "a"
    flag: bool = False
    cap: int | None = None


class HoldingAgent(Agent):
    """Flies its generic policy; holds the settings it is given as ``settings`` (or drops them, ``keep=False``)."""

    name = "holding"

    def __init__(self, generic, settings=None) -> None:
        self.generic, self.settings = generic, settings

    def start(self, family, rng) -> None:
        pass

    def choose(self, episode):
        return Choice(self.generic, "generic", final=True)

    def update(self, outcome) -> None:
        pass


class NoSettingsAttribute(HoldingAgent):
    """Holds what it needs of its settings elsewhere: nothing to compare."""

    def __init__(self, generic, settings=None) -> None:
        self.generic, self.k = generic, settings.k if settings is not None else 2


@pytest.fixture
def agents():
    """The trial's agents, registered at run time (and taken out again)."""
    specs = {
        "holding": AgentSpec("holding", "specialised", NEEDS, lambda p, o: HoldingAgent(p.generic, o.settings), settings=BSettings),
        "dropping": AgentSpec("dropping", "specialised", NEEDS, lambda p, o: HoldingAgent(p.generic), settings=BSettings),
        "elsewhere": AgentSpec("elsewhere", "specialised", NEEDS, lambda p, o: NoSettingsAttribute(p.generic, o.settings), settings=BSettings),
    }
    R.AGENTS.update(specs)
    yield specs
    for name in specs:
        R.AGENTS.pop(name, None)


# --------------------------------------------------------------------------- T55-B01, B03: an agent's settings


@pytest.mark.parametrize(
    ("given", "why"),
    [
        ({"k": "x"}, "k='x' is not allowed: give an integer (its field BSettings.k is of type int)"),
        ({"k": 2.5}, "k=2.5 is not allowed: give an integer"),
        ({"k": True}, "k=True is not allowed: give an integer"),
        ({"rate": "nan"}, "rate='nan' is not allowed: give a finite number (its field BSettings.rate is of type float)"),
        ({"rate": True}, "rate=True is not allowed: give a finite number"),
        ({"rate": float("nan")}, "rate=nan is out of range: allowed a finite number (its field BSettings.rate is of type float)"),
        ({"rate": -np.inf}, "rate=-inf is out of range: allowed a finite number"),
        ({"mode": 5}, "mode=5 is not allowed: give a text (its field BSettings.mode is of type str)"),
        ({"flag": 1}, "flag=1 is not allowed: give true or false (its field BSettings.flag is of type bool)"),
        ({"cap": 1.5}, "cap=1.5 is not allowed: give an integer, or None (its field BSettings.cap is of type int | None)"),
    ],
)
def test_an_agent_s_settings_of_another_type_are_refused_by_name(agents, given, why):
    with pytest.raises(NeurohoverError, match=re.escape(f"bad BSettings: {why}")):
        R.make_agent("holding", "ghh08", options=AgentOptions(settings=given))


def test_an_agent_s_settings_of_their_types_are_taken(agents):
    given = {"k": np.int64(3), "rate": 1, "mode": "b", "flag": np.bool_(True), "cap": None}
    assert R.make_agent("holding", "ghh08", options=AgentOptions(settings=given)).settings == BSettings(3, 1, "b", True, None)
    assert R.make_agent("holding", "ghh08", options=AgentOptions(settings={"cap": 7})).settings.cap == 7


def test_compete_s_agent_settings_are_checked_by_type_and_finiteness(agents):
    with pytest.raises(NeurohoverError, match=re.escape("bad BSettings: k='x' is not allowed: give an integer")):
        check_agent_settings("holding", {"k": "x"}, 20)
    with pytest.raises(NeurohoverError, match=re.escape("bad BSettings: rate=inf is out of range: allowed a finite number")):
        check_agent_settings("holding", {"rate": float("inf")}, 20)


def test_agent_setting_nan_is_refused_before_the_out_folder_is_made(agents, tmp_path, capsys):  # T55-B03
    from neurohover.cli import main

    out = tmp_path / "c"
    args = ["compete", "--task", "ghh08", "--agent", "holding", "--runs", "1", "--episodes", "2", "--episode-steps", "20", "--out", str(out)]
    assert main([*args, "--agent-setting", "rate=nan"]) == 2
    err = capsys.readouterr().err
    assert "bad BSettings: rate=nan is out of range: allowed a finite number" in err and "created directory" not in err
    assert not out.exists()


def test_a_config_group_s_settings_table_is_checked_when_loaded(agents, tmp_path):
    from neurohover.experiments.config import load_config

    config = tmp_path / "c.toml"
    config.write_text(
        'name = "c"\ntitle = "t"\nkind = "test_runs"\n[settings]\ntask = "ghh08"\nseed = 1\nepisodes = 2\npolicies = "shipped"\n'
        '[[settings.groups]]\nagent = "holding"\nn_mdps = 1\nsettings = { k = "x" }\n[scales.quick]\n'
    )
    with pytest.raises(NeurohoverError, match=re.escape("k='x' is not allowed: give an integer (its field BSettings.k is of type int)")):
        load_config(str(config), "quick")


def test_an_annotation_that_does_not_resolve_is_read_from_the_default():
    class Local:
        pass

    @dataclasses.dataclass(frozen=True)
    class LocalSettings(AgentSettings):
        n: int = 1
        other: Local | None = None  # a name get_type_hints cannot resolve: each field's default says its type

    with pytest.raises(NeurohoverError, match=re.escape("bad LocalSettings: n='2' is not allowed: give an integer (its field LocalSettings.n is of type int)")):
        LocalSettings.from_dict({"n": "2"})
    assert LocalSettings.from_dict({"n": 2, "other": "anything"}).other == "anything"  # no plain type: the class's own to check


# --------------------------------------------------------------------------- T55-B02: a run-time optimiser's settings


@dataclasses.dataclass(frozen=True)
class S2:
    popsize: int = 4
    sigma: float = 0.01


class M2:
    """The trial's ask/tell optimiser: its ``sigma`` goes straight to NumPy."""

    def __init__(self, prototype, settings, seed) -> None:
        self.p, self.n, self.sigma = np.asarray(prototype, float), settings.popsize, settings.sigma
        self.rng, self.best, self.ret = np.random.default_rng(seed), None, -np.inf

    def ask(self):
        self.last = self.p + self.rng.normal(0, self.sigma, (self.n, self.p.size))
        return self.last

    def tell(self, fitness, info=None) -> None:
        i = int(np.argmax(fitness))
        if fitness[i] > self.ret:
            self.best, self.ret = self.last[i].copy(), float(fitness[i])

    def stop(self) -> bool:
        return False

    @property
    def champion_genome(self):
        return self.best

    @property
    def champion_return(self) -> float:
        return self.ret

    def state_dict(self) -> dict:
        return {}

    @classmethod
    def from_state_dict(cls, state):
        raise NotImplementedError


@pytest.fixture
def m2():
    OPTIMISERS["m2"] = OptimiserSpec("m2", "user", settings=S2, make=M2, stops_itself=False)
    yield "m2"
    OPTIMISERS.pop("m2", None)


@pytest.mark.parametrize(
    ("given", "why"),
    [
        ({"sigma": "x"}, "sigma='x' is not allowed: give a finite number (its field S2.sigma is of type float)"),
        ({"sigma": True}, "sigma=True is not allowed: give a finite number"),
        ({"sigma": float("nan")}, "sigma=nan is out of range: allowed a finite number"),
        ({"popsize": 4.0}, "popsize=4.0 is not allowed: give an integer (its field S2.popsize is of type int)"),
        ({"popsize": "4"}, "popsize='4' is not allowed: give an integer"),
        ({"popsize": True}, "popsize=True is not allowed: give an integer"),
    ],
)
def test_a_run_time_optimiser_s_settings_of_another_type_are_refused_by_name(m2, given, why):
    with pytest.raises(NeurohoverError, match=re.escape(f"bad m2 settings: {why}")):
        population_settings("m2", given)


def test_evolve_refuses_them_before_the_optimiser_asks(m2):
    with pytest.raises(NeurohoverError, match=re.escape("bad m2 settings: sigma='x' is not allowed: give a finite number")):
        evolve(nh.get_task_family("ghh08").mdp("train:0"), optimizer="m2", topology="slp", n_steps=10, budget=8, settings={"sigma": "x"})


def test_an_int_for_a_float_setting_is_taken(m2):
    assert population_settings("m2", {"sigma": 1, "popsize": np.int64(6)}) == S2(popsize=6, sigma=1)


def test_a_shipped_optimiser_s_own_check_names_its_range():
    with pytest.raises(NeurohoverError, match=re.escape("bad openai-es settings: popsize=3 must be even")):
        population_settings("openai-es", {"popsize": 3})


# --------------------------------------------------------------------------- T55-B07: a build that drops the settings


def test_a_build_that_drops_the_settings_it_was_given_is_refused(agents):
    why = "agent 'dropping': its build made an agent whose settings are None, not the BSettings it was given (BSettings(k=7,"
    with pytest.raises(NeurohoverError, match=re.escape(why) + ".*hand options.settings on to the agent"):
        R.make_agent("dropping", "ghh08", options=AgentOptions(settings={"k": 7}))
    assert R.make_agent("dropping", "ghh08").settings is None  # none given: the defaults, as the agent takes them


def test_an_agent_holding_its_settings_elsewhere_is_not_compared(agents):
    assert R.make_agent("elsewhere", "ghh08", options=AgentOptions(settings={"k": 7})).k == 7
    assert R.make_agent("holding", "ghh08", options=AgentOptions(settings={"k": 7})).settings == BSettings(k=7)


# --------------------------------------------------------------------------- T55-B08: the paper's method names


@pytest.mark.parametrize("name", ["generational", "steady-state"])
def test_a_run_time_optimiser_named_as_a_method_of_ne_is_refused(name):
    OPTIMISERS[name] = OptimiserSpec(name, "user", settings=S2, make=M2, stops_itself=False)
    try:
        why = f"OPTIMISERS[{name!r}] = OptimiserSpec(name={name!r}"
        with pytest.raises(NeurohoverError, match=re.escape(why) + r".* is not allowed: .*\(not 'ne', 'steady-state', 'generational'\)"):
            evolve(nh.get_task_family("ghh08"), optimizer=name, topology="slp", n_steps=10, budget=8)
    finally:
        OPTIMISERS.pop(name, None)


@pytest.mark.slow
def test_compete_refuses_a_build_that_drops_its_settings_before_writing(agents, tmp_path, capsys):  # T55-B07
    from neurohover.cli import main

    out = tmp_path / "c"
    args = ["compete", "--task", "ghh08", "--runs", "1", "--episodes", "2", "--episode-steps", "20", "--out", str(out), "--agent-setting", "k=7"]
    assert main([*args, "--agent", "dropping"]) == 2
    err = capsys.readouterr().err
    assert "agent 'dropping': its build made an agent whose settings are None, not the BSettings it was given" in err, err
    assert not out.exists()
    assert main([*args, "--agent", "holding"]) == 0, capsys.readouterr().err  # one that hands them on flies
