"""Bad-input trial 57, side B (a run-time agent's and optimiser's settings): a user settings class's values were kept as
given, NumPy scalars (np.float32(0.1), np.float64(0.5), np.int64(3), np.bool_), Fractions and -0.0, whether given as a
dict or as an object of the class, so the agent computed with float32's 0.10000000149, its recorded settings held
values JSON cannot write (compete's config was json's TypeError) and -0.0 hashed as another run than 0.0; a class's
own defaults of those kinds flew unconverted (T57-B02). Each setting is now its plain Python value (a real number as
``setting_float`` reads it, a Fraction too, as every float setting takes one; a Decimal, no numbers.Real, stays
refused), and a default that is not one is refused by name.

T57-B03 (a model file with a wind whose ``stats`` were deleted loads with stats {}) is no bug: stats are informational,
read by nothing that flies or reports a model, and {} is what ``LearnedModel(..., wind=w).save`` itself writes."""

from __future__ import annotations

import dataclasses
import json
import math
import re
from decimal import Decimal
from fractions import Fraction

import numpy as np
import pytest

from neurohover.agents import registry as R
from neurohover.agents.protocol import Agent, Choice
from neurohover.agents.spec import AgentOptions, AgentSettings, AgentSpec
from neurohover.errors import NeurohoverError
from neurohover.evolution.optimisers import OPTIMISERS, OptimiserSpec, entry_problem, population_settings

NAME = "t57-settings-agent-1"
NEEDS = frozenset({"generic"})


@dataclasses.dataclass(frozen=True)
class T57Settings(AgentSettings):
    """Plain fields, no ``__post_init__`` of their own."""

    k: int = 2
    rate: float = 0.5
    flag: bool = False
    cap: float | None = None


class HoldingAgent(Agent):
    """Flies its generic policy and holds the settings it is given."""

    name = NAME

    def __init__(self, generic, settings) -> None:
        self.generic, self.settings = generic, settings

    def choose(self, episode):
        return Choice(self.generic, "generic", final=True)

    def update(self, outcome) -> None:
        pass


@pytest.fixture
def agent():
    R.AGENTS[NAME] = AgentSpec(NAME, "specialised", NEEDS, lambda p, o: HoldingAgent(p.generic, o.settings), settings=T57Settings)
    yield NAME
    R.AGENTS.pop(NAME, None)


def _plain(value: object, expected: object) -> bool:
    """Whether ``value`` is ``expected`` of its very type and sign (-0.0 is no 0.0)."""
    if type(value) is not type(expected) or value != expected:
        return False
    return not isinstance(value, float) or math.copysign(1.0, value) == math.copysign(1.0, expected)  # type: ignore[arg-type]


GIVEN = [
    ({"rate": np.float32(0.1)}, "rate", 0.1),
    ({"rate": np.float16(0.1)}, "rate", 0.1),
    ({"rate": np.float64(0.5)}, "rate", 0.5),
    ({"rate": Fraction(1, 3)}, "rate", 1 / 3),
    ({"rate": -0.0}, "rate", 0.0),
    ({"rate": 1}, "rate", 1.0),
    ({"cap": np.float32(0.25)}, "cap", 0.25),
    ({"k": np.int64(3)}, "k", 3),
    ({"k": np.uint64(2**64 - 1)}, "k", 2**64 - 1),
    ({"flag": np.bool_(True)}, "flag", True),
]


@pytest.mark.parametrize(("given", "key", "expected"), GIVEN)
def test_an_agent_gets_its_settings_given_as_a_dict_as_plain_values(agent, given, key, expected):
    settings = R.make_agent(agent, "ghh08", options=AgentOptions(settings=given)).settings
    assert _plain(getattr(settings, key), expected)
    json.dumps(settings.to_dict(), allow_nan=False)  # what a run records


@pytest.mark.parametrize(("given", "key", "expected"), GIVEN)
def test_an_agent_gets_its_settings_given_as_an_object_as_plain_values(agent, given, key, expected):
    settings = R.make_agent(agent, "ghh08", options=AgentOptions(settings=T57Settings(**given))).settings
    assert _plain(getattr(settings, key), expected)
    json.dumps(settings.to_dict(), allow_nan=False)


def test_a_decimal_stays_refused_and_a_fraction_is_no_integer(agent):
    settings = R.make_agent(agent, "ghh08", options=AgentOptions(settings={"rate": Fraction(3, 4)})).settings
    assert _plain(settings.rate, 0.75)  # a Fraction is a real number, read as its float ...
    why = "bad T57Settings: rate=Decimal('0.5') is not allowed: give a finite number (its field T57Settings.rate is of type float)"
    with pytest.raises(NeurohoverError, match=re.escape(why)):  # ... a Decimal is none, as in every float setting
        R.make_agent(agent, "ghh08", options=AgentOptions(settings={"rate": Decimal("0.5")}))
    with pytest.raises(NeurohoverError, match=re.escape("bad T57Settings: k=Fraction(3, 1) is not allowed: give an integer")):
        R.make_agent(agent, "ghh08", options=AgentOptions(settings={"k": Fraction(3, 1)}))


def test_compete_s_config_holds_the_plain_settings(agent):
    from neurohover.compete import check_agent_settings, competition_config

    given = {"rate": np.float32(0.1), "k": np.int64(3)}
    assert check_agent_settings(agent, given) == {"k": 3, "rate": 0.1, "flag": False, "cap": None}
    config = competition_config("ghh08", agent, runs=1, episodes=2, agent_settings=given)  # was json's TypeError (int64)
    own = config.settings["groups"][0]["settings"]
    assert own == {"k": 3, "rate": 0.1, "flag": False, "cap": None} and (type(own["k"]), type(own["rate"])) == (int, float)
    assert config == competition_config("ghh08", agent, runs=1, episodes=2, agent_settings={"rate": 0.1, "k": 3})


@pytest.mark.parametrize(
    ("default", "why"),
    [
        (np.float32(0.1), "field 'rate''s default is float32 np.float32(0.1), no plain JSON value: give 0.1"),
        (np.float64(0.5), "field 'rate''s default is float64 np.float64(0.5), no plain JSON value: give 0.5"),
        (Fraction(1, 2), "field 'rate''s default is Fraction Fraction(1, 2), no plain JSON value: give 0.5"),
        (-0.0, "field 'rate''s default is float -0.0, which settings given are read as 0.0: give 0.0"),
    ],
)
def test_an_agent_spec_refuses_a_default_that_is_no_plain_value(default, why):
    cls = dataclasses.make_dataclass("S", [("rate", float, dataclasses.field(default=default))], bases=(AgentSettings,), frozen=True)
    with pytest.raises(NeurohoverError, match=re.escape(f"agent {NAME!r}: its settings class S's {why} (the defaults are used as written)")):
        AgentSpec(NAME, "specialised", NEEDS, lambda p, o: HoldingAgent(p.generic, o.settings), settings=cls)
    ints = dataclasses.make_dataclass("S", [("rate", float, dataclasses.field(default=1))], bases=(AgentSettings,), frozen=True)
    AgentSpec(NAME, "specialised", NEEDS, lambda p, o: HoldingAgent(p.generic, o.settings), settings=ints)  # 1 for 1.0 is Python's


@dataclasses.dataclass(frozen=True)
class T57OptSettings:
    popsize: int = 4
    sigma: float = 0.1


def test_a_run_time_optimiser_gets_its_settings_as_plain_values():
    OPTIMISERS["t57-settings-opt-1"] = OptimiserSpec("t57-settings-opt-1", "user", settings=T57OptSettings, make=lambda p, s, seed: None, stops_itself=False)
    try:
        for given in ({"popsize": np.int64(6), "sigma": np.float32(0.3)}, T57OptSettings(np.int64(6), np.float32(0.3))):
            settings = population_settings("t57-settings-opt-1", given)
            assert _plain(settings.popsize, 6) and _plain(settings.sigma, 0.3)
        assert _plain(population_settings("t57-settings-opt-1", {"sigma": -0.0}).sigma, 0.0)
    finally:
        OPTIMISERS.pop("t57-settings-opt-1", None)


def test_a_run_time_optimiser_s_minus_zero_default_is_refused():
    cls = dataclasses.make_dataclass("OS", [("sigma", float, dataclasses.field(default=-0.0))], frozen=True)
    problem = entry_problem("t57-settings-opt-2", OptimiserSpec("t57-settings-opt-2", "user", cls, lambda p, s, seed: None, stops_itself=False))
    assert "its settings field 'sigma''s default is float -0.0, which settings given are read as 0.0: give 0.0" in problem
