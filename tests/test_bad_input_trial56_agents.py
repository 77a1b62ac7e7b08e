"""Bad-input trial 56, side B (agents and a run-time optimiser's answers): a user agent's settings were type-checked
only when given as a dict, so a spec's settings class with a NaN or wrong-type default (``n: int = 'x'``) or a field
without a default was taken, and an instance ``AgentOptions(settings=S(k='x', rate=inf))`` flew unchecked (T56-B01);
and a run-time optimiser's ask() answering a masked array flew its masked genes, NaN too, at their hidden values
(T56-B02). Each is now one NeurohoverError naming the value and what is allowed."""

from __future__ import annotations

import dataclasses
import re
from types import SimpleNamespace

import numpy as np
import pytest

from neurohover.agents import registry as R
from neurohover.agents.protocol import Agent, Choice
from neurohover.agents.spec import AgentOptions, AgentSettings, AgentSpec
from neurohover.errors import NeurohoverError
from neurohover.evolution.answers import asked_genomes, checked_champion_genome
from neurohover.evolution.optimisers import SHIPPED_SPECS, OptimiserSpec, entry_problem
from neurohover.settings_checks import settings_defaults_problem

NEEDS = frozenset({"generic"})


@dataclasses.dataclass(frozen=True)
class KSettings(AgentSettings):
    """The trial's settings: plain fields, no ``__post_init__`` of their own."""

    k: int = 2
    rate: float = 0.5


class HoldingAgent(Agent):
    """Flies its generic policy and holds the settings it is given."""

    name = "holding56"

    def __init__(self, generic, settings) -> None:
        self.generic, self.settings = generic, settings

    def choose(self, episode):
        return Choice(self.generic, "generic", final=True)

    def update(self, outcome) -> None:
        pass


def _settings(*fields) -> type:
    return dataclasses.make_dataclass("S", fields, bases=(AgentSettings,), frozen=True)


def _spec(settings: type) -> AgentSpec:
    return AgentSpec("holding56", "specialised", NEEDS, lambda p, o: HoldingAgent(p.generic, o.settings or settings()), settings=settings)


# --------------------------------------------------------------------------- T56-B01: an agent's settings


@pytest.mark.parametrize(
    ("fields", "why"),
    [
        (
            [("k", int, dataclasses.field(default=2)), ("rate", float, dataclasses.field(default=float("nan")))],
            "default rate=nan is out of range: allowed a finite number (its field S.rate is of type float)",
        ),
        ([("n", int, dataclasses.field(default="x"))], "default n='x' is not allowed: give an integer (its field S.n is of type int)"),
        ([("flag", bool, dataclasses.field(default=1))], "default flag=1 is not allowed: give true or false (its field S.flag is of type bool)"),
        ([("n", int), ("k", int, dataclasses.field(default=2))], "field 'n' has no default: give every field a default (settings left out are the defaults)"),
    ],
)
def test_an_agent_spec_refuses_settings_defaults_by_name(fields, why):
    with pytest.raises(NeurohoverError, match=re.escape(f"agent 'holding56': its settings class S's {why}")):
        _spec(_settings(*fields))


def test_the_shipped_settings_classes_pass_the_defaults_check():
    """Their nested dataclass defaults (HybridSettings.dangerous) are left to the class."""
    classes = {spec.settings for spec in R.SHIPPED_SPECS.values() if spec.settings is not None}
    classes |= {spec.settings for spec in SHIPPED_SPECS.values()}
    assert any(c.__name__ == "HybridSettings" for c in classes)
    assert {c.__name__: settings_defaults_problem(c) for c in classes} == {c.__name__: "" for c in classes}


@pytest.fixture
def holding():
    R.AGENTS["holding56"] = _spec(KSettings)
    yield "holding56"
    R.AGENTS.pop("holding56", None)


@pytest.mark.parametrize(
    ("given", "why"),
    [
        (KSettings(k="x", rate=float("inf")), "k='x' is not allowed: give an integer (its field KSettings.k is of type int)"),
        (KSettings(rate=float("nan")), "rate=nan is out of range: allowed a finite number (its field KSettings.rate is of type float)"),
        (KSettings(k=True), "k=True is not allowed: give an integer"),
    ],
)
def test_an_agent_s_settings_instance_is_checked_as_a_dict_is(holding, given, why):
    with pytest.raises(NeurohoverError, match=re.escape(f"bad KSettings: {why}")):
        R.make_agent(holding, "ghh08", options=AgentOptions(settings=given))
    with pytest.raises(NeurohoverError, match=re.escape(f"bad KSettings: {why}")):
        R.check_agent(holding, "ghh08", settings=given)


def test_an_agent_s_settings_instance_of_its_types_is_taken(holding):
    given = KSettings(k=np.int64(3), rate=1)
    taken = R.make_agent(holding, "ghh08", options=AgentOptions(settings=given)).settings
    assert taken == given and (type(taken.k), type(taken.rate)) == (int, float)  # as plain Python values (T57-B02)
    plain = KSettings(k=3, rate=0.25)
    assert R.make_agent(holding, "ghh08", options=AgentOptions(settings=plain)).settings is plain


class _Opt:
    def __init__(self, proto, settings, seed) -> None:
        pass


def test_a_run_time_optimiser_s_nan_default_is_refused_too():
    cls = dataclasses.make_dataclass("OS", [("lr", float, dataclasses.field(default=float("nan")))], frozen=True)
    problem = entry_problem("mine56", OptimiserSpec("mine56", "user", cls, _Opt, stops_itself=False))
    assert "its settings default lr=nan is out of range: allowed a finite number (its field OS.lr is of type float)" in problem


# --------------------------------------------------------------------------- T56-B02: a masked ask() or champion

CFG = SimpleNamespace(prototype=SimpleNamespace(genome=np.zeros(3)), optimizer="mine", topology="slp")


def _masked(hidden: float, shape: tuple[int, ...]) -> np.ma.MaskedArray:
    values = np.ma.masked_array(np.zeros(shape), mask=False)
    values.data.flat[0] = hidden
    values.mask.flat[0] = True
    return values


@pytest.mark.parametrize("hidden", [float("nan"), 0.5])
def test_a_masked_ask_is_refused(hidden):
    opt = SimpleNamespace(ask=lambda: _masked(hidden, (4, 3)))
    why = "optimizer 'mine': its ask() gave a masked array of shape (4, 3), which is not allowed: give a NumPy array of real numbers of shape (n, 3)"
    with pytest.raises(NeurohoverError, match=re.escape(why) + r".*\(a masked array: give its values, e\.g\. \.filled\(\)\)$"):
        asked_genomes(opt, CFG)
    assert asked_genomes(SimpleNamespace(ask=lambda: np.zeros((4, 3))), CFG).shape == (4, 3)


def test_a_masked_champion_genome_is_refused():
    opt = SimpleNamespace(champion_genome=_masked(0.5, (3,)))
    with pytest.raises(NeurohoverError, match=r"its champion_genome MaskedArray .* is not allowed: .*\(a masked array: give its values"):
        checked_champion_genome(opt, CFG)


def test_a_run_time_optimisers_settings_object_is_checked_as_a_dict_is() -> None:  # T56-B01's rest: population_settings
    import dataclasses as dc

    from neurohover.evolution.optimisers import OPTIMISERS, OptimiserSpec, population_settings

    @dc.dataclass(frozen=True)
    class Plain:
        popsize: int = 4
        sigma: float = 0.1

    OPTIMISERS["plain56"] = OptimiserSpec("plain56", "user", settings=Plain, make=lambda p, s, seed: None, stops_itself=False)
    try:
        with pytest.raises(NeurohoverError, match=r"bad plain56 settings: sigma='x' is not allowed: give a finite number"):
            population_settings("plain56", Plain(sigma="x"))  # type: ignore[arg-type]
        assert population_settings("plain56", Plain(sigma=0.5)) == Plain(sigma=0.5)
    finally:
        OPTIMISERS.pop("plain56", None)
