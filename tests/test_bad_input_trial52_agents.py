"""Bad-input trial 52, side B (a user's agent spec, as the README's "A new agent" writes one): AgentSpec's own checks
raised bare ValueErrors (T52-B13); its ``build`` was unchecked, so one that is no callable of (policies, options), or
that answered None or a Policy, was a TypeError, an AttributeError or a FrozenInstanceError at make_agent (T52-B14);
and its ``settings`` were unchecked, so a dict, AgentSettings itself or a class that is no dataclass was an
AttributeError or TypeError once settings were given (T52-B15). Each is now a NeurohoverError naming the spec, the
value and what is allowed."""

from __future__ import annotations

import dataclasses
import re
from dataclasses import dataclass

import pytest

from neurohover.agents import registry as R
from neurohover.agents.reference import GenericAgent
from neurohover.agents.spec import AgentOptions, AgentSettings, AgentSpec
from neurohover.errors import NeurohoverError
from neurohover.experiments import units

NEEDS = frozenset({"generic", "specialised"})


def _build(policies, options):
    return GenericAgent(policies.generic)


@dataclass(frozen=True)
class KSettings(AgentSettings):
    k: int = 3


# --------------------------------------------------------------------------- T52-B13: AgentSpec's own checks


@pytest.mark.parametrize(
    ("kwargs", "why"),
    [
        ({"runs_on": "Specialised"}, "agent 'best-of-two': runs_on='Specialised'; allowed ('any', 'specialised', 'generics-by-kind')"),
        ({"runs_on": ["any"]}, "agent 'best-of-two': runs_on=['any']; allowed ('any', 'specialised', 'generics-by-kind')"),
        ({"needs": frozenset({"special"})}, "agent 'best-of-two': unknown policy needs ['special']; allowed ('generic', 'specialised', 'safe')"),
        ({"needs": None}, "agent 'best-of-two': needs=None is not allowed: give a frozenset of ('generic', 'specialised', 'safe')"),
        ({"needs": frozenset({5})}, "agent 'best-of-two': needs=frozenset({5}) is not allowed: give a frozenset of"),
        ({"runs_on": "any"}, "agent 'best-of-two' (runs_on='any') flies a generic policy on families with generics by kind: name its generic_kind"),
        ({"generic_kind": "Race"}, "agent 'best-of-two': generic_kind='Race' is not allowed: give one of ('zero', 'fixed', 'race'), or None"),
        ({"name": None}, "AgentSpec name=None is not allowed: give a non-empty text"),
        ({"name": "a\nb"}, "AgentSpec name='a\\nb' is not allowed: give a non-empty text"),
    ],
)
def test_a_spec_s_own_checks_are_neurohover_errors(kwargs, why):
    args = {"name": "best-of-two", "runs_on": "specialised", "needs": NEEDS, "build": _build} | kwargs
    with pytest.raises(NeurohoverError, match=re.escape(why)):
        AgentSpec(**args)


def test_needs_given_as_a_set_is_held_as_a_frozenset():
    spec = AgentSpec("best-of-two", "specialised", {"generic"}, _build)
    assert spec.needs == frozenset({"generic"}) and isinstance(spec.needs, frozenset)
    hash(spec)


# --------------------------------------------------------------------------- T52-B14: build, and what it answers


@pytest.mark.parametrize(
    ("build", "why"),
    [
        ("BUILD", "agent 'best-of-two': build='BUILD' is not allowed: give a callable; build(policies, options)"),
        (None, "agent 'best-of-two': build=None is not allowed: give a callable"),
        (lambda p: None, "agent 'best-of-two': build of signature '(p)' is not allowed: it is called as build(policies, options)"),
        (lambda: None, "agent 'best-of-two': build of signature '()' is not allowed"),
        (lambda p, o, x: None, "agent 'best-of-two': build of signature '(p, o, x)' is not allowed"),
    ],
)
def test_a_build_that_cannot_be_called_with_policies_and_options_is_refused(build, why):
    with pytest.raises(NeurohoverError, match=re.escape(why)):
        AgentSpec("best-of-two", "specialised", NEEDS, build)


def test_builds_that_take_more_are_taken():
    AgentSpec("best-of-two", "specialised", NEEDS, lambda p, o, extra=1: _build(p, o))
    AgentSpec("best-of-two", "specialised", NEEDS, lambda *args: _build(*args))


@pytest.mark.parametrize(
    ("answer", "shown"),
    [(lambda p: None, "None"), (lambda p: p.generic, "Policy("), (lambda p: GenericAgent, "<class ")],
)
def test_a_build_answering_no_agent_is_refused_by_name(monkeypatch, answer, shown):
    spec = AgentSpec("best-of-two", "specialised", NEEDS, lambda policies, options: answer(policies))
    monkeypatch.setitem(R.AGENTS, "best-of-two", spec)
    why = f"agent 'best-of-two': its build answered {shown}"
    with pytest.raises(NeurohoverError, match=re.escape(why)) as err:
        R.make_agent("best-of-two", "ghh08")
    assert "must answer an Agent (neurohover.agents.protocol.Agent)" in str(err.value)
    with pytest.raises(NeurohoverError, match=re.escape(why)):
        R.check_agent("best-of-two", "ghh08")


def test_an_experiment_unit_s_agent_is_checked_too(monkeypatch, tmp_path):
    from neurohover.experiments.config import load_config
    from neurohover.experiments.plans import plan

    monkeypatch.setitem(R.AGENTS, "nobody", AgentSpec("nobody", "any", frozenset(), lambda policies, options: None))
    config = tmp_path / "c.toml"
    config.write_text(
        'name = "c"\ntitle = "t"\nkind = "test_runs"\n[settings]\ntask = "ghh08"\nseed = 1\nepisodes = 2\npolicies = "shipped"\n'
        '[[settings.groups]]\nagent = "nobody"\nn_mdps = 1\n[scales.quick]\n'
    )
    (unit,) = plan(load_config(str(config), "quick"), {}, {}).units
    with pytest.raises(NeurohoverError, match=re.escape("agent 'nobody': its build answered None, which is not allowed")):
        units.unit_agent(unit.params)


def test_the_readme_s_spec_makes_an_agent(monkeypatch):
    spec = AgentSpec("best-of-two", "specialised", NEEDS, _build, summary="the better of the generic and one specialised policy")
    monkeypatch.setitem(R.AGENTS, "best-of-two", spec)
    agent = R.make_agent("best-of-two", "ghh08")
    assert isinstance(agent, GenericAgent) and agent.made_for[0] == "ghh08"


# --------------------------------------------------------------------------- T52-B15: settings


class NoDataclass(AgentSettings):
    k = 3


@dataclass
class NotFrozen(AgentSettings):
    k: int = 3


@pytest.mark.parametrize(
    ("settings", "shown"),
    [
        (dict, "<class 'dict'>"),
        (AgentSettings, "<class 'neurohover.agents.spec.AgentSettings'>"),
        (NoDataclass, "NoDataclass'>"),
        (NotFrozen, "NotFrozen'>"),
        (KSettings(), "KSettings(k=3)"),
        ("KSettings", "'KSettings'"),
    ],
)
def test_settings_that_are_no_frozen_agent_settings_dataclass_are_refused(settings, shown):
    with pytest.raises(NeurohoverError, match=re.escape(shown) + ".* is not allowed: give a frozen dataclass subclass of neurohover.agents.spec.AgentSettings"):
        AgentSpec("best-of-two", "specialised", NEEDS, _build, settings=settings)


def test_settings_of_a_frozen_agent_settings_dataclass_reach_build(monkeypatch):
    seen = []

    def build(policies, options):
        seen.append(options.settings)
        return GenericAgent(policies.generic)

    monkeypatch.setitem(R.AGENTS, "best-of-two", AgentSpec("best-of-two", "specialised", NEEDS, build, settings=KSettings))
    R.make_agent("best-of-two", "ghh08", options=AgentOptions(settings={"k": 5}))
    assert seen == [KSettings(k=5)]


def test_every_shipped_spec_passes_its_checks():
    for name, spec in R.SHIPPED_SPECS.items():
        assert dataclasses.replace(spec) == spec, name  # replace runs __post_init__ again
