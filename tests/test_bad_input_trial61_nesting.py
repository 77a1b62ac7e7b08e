"""Bad-input trial 61, side B: settings values nested too deep, or holding themselves.

T61-B01: a run-time agent's or optimiser's settings value for a field typed ``Any`` (or ``dict``, ``list``) nested about
500 lists deep, or a list or table that holds itself, was a raw RecursionError from the settings check, given to
``compete``/``evolve`` (as a table or as an object) and as a class's default at registration. Depth 300 was accepted and
stored. Such a value is now refused by name before the check goes in, at the limit policy notes already have (100 lists or
tables, T33-B03): so 101 levels is refused too, and 100 taken.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np
import pytest

from neurohover.agents import registry as R
from neurohover.agents.protocol import Agent, Choice
from neurohover.agents.spec import AgentSettings, AgentSpec
from neurohover.compete import compete
from neurohover.errors import NeurohoverError
from neurohover.evolution import evolve
from neurohover.evolution.optimisers import OPTIMISERS, SHIPPED_SPECS, OptimiserSpec
from neurohover.jsontext import MAX_NOTE_DEPTH
from neurohover.settings_checks import checked_settings, settings_defaults_problem, settings_from_dict
from neurohover.tasks import get_task_family

AGENT = "t61nesting1"
OPTIMISER = "t61-nesting-opt"
DEEP = f"nested more than {MAX_NOTE_DEPTH} lists or tables deep"
ITSELF = "it holds itself"


def deep(n: int) -> Any:
    """A list nested ``n`` levels deep around 1."""
    value: Any = 1
    for _ in range(n):
        value = [value]
    return value


def looped_list() -> list:
    x: list = []
    x.append(x)
    return x


def looped_table() -> dict:
    t: dict = {"b": [1]}
    t["a"] = [{"c": t}]
    return t


@dataclasses.dataclass(frozen=True)
class NestSettings(AgentSettings):
    """An Any field, a dict field and a bare list field."""

    anyv: Any = None
    table: dict = dataclasses.field(default_factory=dict)
    xs: list = dataclasses.field(default_factory=list)


class PlainAgent(Agent):
    """Flies its generic policy."""

    name = AGENT

    def __init__(self, generic) -> None:
        self.generic = generic

    def choose(self, episode):
        return Choice(self.generic, "generic", final=True)

    def update(self, outcome) -> None:
        pass


@pytest.mark.parametrize(
    ("given", "said"),
    [
        ({"anyv": deep(500)}, DEEP),
        ({"anyv": deep(MAX_NOTE_DEPTH + 1)}, DEEP),  # 300 was accepted and stored
        ({"table": {"k": deep(600)}}, DEEP),
        ({"xs": deep(500)}, DEEP),  # a list field's own items
        ({"xs": [[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[np.zeros((1,) * 60)]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]}, DEEP),  # an array: its lists
        ({"anyv": looped_list()}, ITSELF),
        ({"anyv": looped_table()}, ITSELF),
        ({"xs": looped_list()}, ITSELF),
    ],
)
def test_a_deep_or_looped_setting_is_refused_by_name(given, said) -> None:
    (key,) = given
    with pytest.raises(NeurohoverError, match="bad NS") as info:
        settings_from_dict(NestSettings, given, unknown_what="NS", bad_what="NS")
    assert said in str(info.value) and f"{key}=" in str(info.value)
    with pytest.raises(NeurohoverError, match=said):  # as an object of the class, too
        checked_settings(NestSettings(**given), bad_what="NS")


def test_the_limit_itself_is_taken_and_shared_values_are_no_loop() -> None:
    shared = [1, 2]
    settings = settings_from_dict(NestSettings, {"anyv": deep(MAX_NOTE_DEPTH), "table": {"a": shared, "b": shared}}, unknown_what="NS", bad_what="NS")
    assert settings.anyv == deep(MAX_NOTE_DEPTH) and settings.table == {"a": [1, 2], "b": [1, 2]}
    with pytest.raises(NeurohoverError, match=DEEP):
        settings_from_dict(NestSettings, {"anyv": [shared, deep(MAX_NOTE_DEPTH)]}, unknown_what="NS", bad_what="NS")


@pytest.mark.parametrize(("made", "said"), [(lambda: deep(600), DEEP), (looped_list, ITSELF), (lambda: {"t": deep(200)}, DEEP)])
def test_a_deep_or_looped_default_is_refused_at_registration(made, said) -> None:
    @dataclasses.dataclass(frozen=True)
    class DeepDefault(AgentSettings):
        anyv: Any = dataclasses.field(default_factory=made)

    problem = settings_defaults_problem(DeepDefault)
    assert said in problem and "anyv=" in problem
    with pytest.raises(NeurohoverError, match=said):
        AgentSpec(AGENT, "specialised", frozenset({"generic"}), lambda p, o: PlainAgent(p.generic), settings=DeepDefault)
    assert AGENT not in R.AGENTS


@pytest.fixture
def agent():
    R.AGENTS[AGENT] = AgentSpec(AGENT, "specialised", frozenset({"generic"}), lambda p, o: PlainAgent(p.generic), settings=NestSettings)
    yield AGENT
    R.AGENTS.pop(AGENT, None)


@pytest.mark.parametrize("value", [deep(500), looped_list()])
def test_compete_refuses_a_deep_or_looped_agent_setting(agent, tmp_path, value) -> None:
    with pytest.raises(NeurohoverError, match=f"anyv=.*({DEEP}|{ITSELF})"):
        compete("ghh08", agent, runs=1, episodes=2, n_steps=20, out=tmp_path / "o", store=tmp_path / "s.sqlite", agent_settings={"anyv": value})
    assert not (tmp_path / "s.sqlite").exists()


@dataclasses.dataclass(frozen=True)
class NestOptSettings:
    popsize: int = 4
    anyv: Any = None


def _make(prototype, settings, seed):
    from neurohover.evolution.optimisers.openai_es import OpenAIESSettings

    return SHIPPED_SPECS["openai-es"].make(prototype, OpenAIESSettings(popsize=settings.popsize), seed)


@pytest.fixture
def optimiser():
    OPTIMISERS[OPTIMISER] = OptimiserSpec(OPTIMISER, "user", NestOptSettings, _make, stops_itself=False)
    yield OPTIMISER
    OPTIMISERS.pop(OPTIMISER, None)


@pytest.mark.parametrize("value", [deep(500), looped_table()])
def test_evolve_refuses_a_deep_or_looped_optimiser_setting(optimiser, value) -> None:
    mdp = get_task_family("ghh08").mdp("zero")
    with pytest.raises(NeurohoverError, match=f"anyv=.*({DEEP}|{ITSELF})"):
        evolve(mdp, topology="slp", optimizer=optimiser, budget=8, n_steps=10, seed=0, settings={"anyv": value})
