"""Bad-input trial 60, side B (a run-time agent's or optimiser's settings class).

T60-B01: a settings field typed ``dict`` or ``Any`` (any type but a plain one, a list or a tuple) was left to the class:
NumPy scalars, a set or an object in it passed the check, and compete and evolve were json's TypeError before flying.

T60-B02: such a field's default went unchecked at registration too: an ``Any`` field's frozenset or ``{"a": np.int64(1)}``
was accepted by AgentSpec and OptimiserSpec, then the run was json's TypeError (the README promises plain JSON defaults).

T60-B03: a NumPy array given for such a field was NumPy's "truth value of an array is ambiguous" ValueError, from the
check's own comparison.

One rule now: every settings value, whatever its field's annotation, is a plain JSON value once made plain (NumPy's
scalars and arrays read as theirs), given or default; anything else is refused by name. A field annotated as a dataclass
also takes an object of it, whose own fields are held to the rule. The optimiser registry's own check of defaults (which
refused a tuple default an agent's spec took) is gone: the shared check is the one.

T60-B06: whatever a settings class's ``unused()`` answered other than None became the whole refusal: '', blanks, True,
5 or a list gave "agent 'u60': " and no reason. Its answer is now checked: None, or a non-empty one-line text.
"""

from __future__ import annotations

import dataclasses
import json
import re
from typing import Any

import numpy as np
import pytest

from neurohover.agents import registry as R
from neurohover.agents.protocol import Agent, Choice
from neurohover.agents.spec import AgentOptions, AgentSettings, AgentSpec
from neurohover.compete import compete
from neurohover.errors import NeurohoverError
from neurohover.evolution import evolve
from neurohover.evolution.optimisers import OPTIMISERS, SHIPPED_SPECS, OptimiserSpec, entry_problem, population_settings
from neurohover.experiments import load_config
from neurohover.settings_checks import checked_settings, settings_defaults_problem
from neurohover.tasks import get_task_family

ZERO = get_task_family("ghh08").zero()
RUN = dict(topology="slp", prototype="zero", seed=3, n_steps=20)
AGENT = "t60settings1"
OPTIMISER = "t60-opt-1"
NEEDS = frozenset({"generic"})
JSON_VALUE = "give a plain JSON value (a number, a text, true or false, None, or a list, tuple or text-keyed table of them)"


class HoldingAgent(Agent):
    """Flies its generic policy and holds the settings it is given."""

    name = AGENT

    def __init__(self, generic, settings) -> None:
        self.generic, self.settings = generic, settings

    def choose(self, episode):
        return Choice(self.generic, "generic", final=True)

    def update(self, outcome) -> None:
        pass


@dataclasses.dataclass(frozen=True)
class Inner:
    """A nested settings dataclass."""

    rate: float = 1.0
    extra: Any = None


@dataclasses.dataclass(frozen=True)
class T60Settings(AgentSettings):
    """A dict field, an Any field and a nested dataclass field."""

    table: dict = dataclasses.field(default_factory=dict)
    anyv: Any = None
    inner: Inner = Inner()


@dataclasses.dataclass(frozen=True)
class T60OptSettings:
    popsize: int = 4
    table: dict = dataclasses.field(default_factory=dict)
    anyv: Any = None
    xs: list = dataclasses.field(default_factory=list)


def _build(p, o):
    return HoldingAgent(p.generic, o.settings)


@pytest.fixture
def agent():
    R.AGENTS[AGENT] = AgentSpec(AGENT, "specialised", NEEDS, _build, settings=T60Settings)
    yield AGENT
    R.AGENTS.pop(AGENT, None)


def _make(prototype, settings, seed):
    from neurohover.evolution.optimisers.openai_es import OpenAIESSettings

    return SHIPPED_SPECS["openai-es"].make(prototype, OpenAIESSettings(popsize=settings.popsize), seed)


@pytest.fixture
def optimiser():
    OPTIMISERS[OPTIMISER] = OptimiserSpec(OPTIMISER, "user", T60OptSettings, _make, stops_itself=False)
    yield OPTIMISER
    OPTIMISERS.pop(OPTIMISER, None)


def _types(value) -> Any:
    """``value``'s types, item by item."""
    if isinstance(value, dict):
        return {k: _types(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_types(v) for v in value]
    return type(value)


# --- T60-B01, B03: a dict or Any field's value made plain, or refused by name ----------------------------------------


@pytest.mark.parametrize(
    ("given", "expected"),
    [
        ({"table": {"a": np.int64(2)}}, {"table": {"a": 2}}),
        ({"table": {"a": np.float32(0.1), "b": [np.bool_(True), -0.0]}}, {"table": {"a": 0.1, "b": [True, 0.0]}}),
        ({"anyv": np.arange(3)}, {"anyv": [0, 1, 2]}),  # T60-B03: NumPy's "truth value ... is ambiguous"
        ({"anyv": np.float64(2.5)}, {"anyv": 2.5}),
        ({"table": {"a": np.array([0.5, 1.0], dtype=np.float32)}}, {"table": {"a": [0.5, 1.0]}}),
    ],
)
def test_an_optimiser_s_dict_or_any_setting_holds_plain_values(optimiser, given, expected) -> None:
    settings = population_settings(optimiser, given)
    for key, value in expected.items():
        held = getattr(settings, key)
        assert held == value and _types(held) == _types(value)
    json.dumps(dataclasses.asdict(settings), allow_nan=False)  # what a run records


def test_evolve_with_numpy_values_in_a_dict_setting_records_them(optimiser, tmp_path) -> None:
    """T60-B01: "TypeError: Object of type int64 is not JSON serializable" from the run's config."""
    evolve(ZERO, budget=8, optimizer=optimiser, settings={"table": {"a": np.int64(2)}, "anyv": np.arange(2)}, checkpoint=tmp_path / "c.json", **RUN)
    settings = json.loads((tmp_path / "c.json").read_text())["config"]["settings"]
    assert (settings["table"], settings["anyv"]) == ({"a": 2}, [0, 1])


@pytest.mark.parametrize(
    ("given", "why"),
    [
        ({"table": {"a": {1}}}, f"table={{'a': {{1}}}} is not allowed: it holds {{1}}: {JSON_VALUE} (its field T60OptSettings.table is of type dict"),
        ({"anyv": object()}, f"is not allowed: {JSON_VALUE} (its field T60OptSettings.anyv is of type Any; settings are recorded as JSON)"),
        ({"anyv": frozenset({1})}, f"anyv=frozenset({{1}}) is not allowed: {JSON_VALUE}"),
        ({"table": {1: 2}}, f"table={{1: 2}} is not allowed: {JSON_VALUE}"),
        ({"anyv": [1, {"k": np.array(1.0)}]}, f"is not allowed: it holds array(1.): {JSON_VALUE}"),
    ],
)
def test_an_optimiser_s_dict_or_any_setting_json_cannot_write_is_refused(optimiser, given, why) -> None:
    """T60-B01: a set or an object was json's TypeError once the run began."""
    with pytest.raises(NeurohoverError, match=re.escape(f"bad {OPTIMISER} settings: ") + ".*" + re.escape(why)):
        population_settings(optimiser, given)
    with pytest.raises(NeurohoverError, match=re.escape(why)):
        evolve(ZERO, budget=8, optimizer=optimiser, settings=given, **RUN)


def test_an_optimiser_s_settings_object_is_checked_alike(optimiser) -> None:
    """T60-B01: an object of the settings class went through checked_settings unchecked in the same fields."""
    settings = population_settings(optimiser, T60OptSettings(table={"a": np.int64(3)}, anyv=np.arange(2)))
    assert (settings.table, settings.anyv, _types(settings.table)) == ({"a": 3}, [0, 1], {"a": int})
    with pytest.raises(NeurohoverError, match=re.escape(f"anyv={{1}} is not allowed: {JSON_VALUE}")):
        population_settings(optimiser, T60OptSettings(anyv={1}))


def test_an_agent_gets_its_dict_and_any_settings_as_plain_values(agent) -> None:
    """T60-B01, B03: make_agent handed NumPy values on, or failed with NumPy's ValueError for an array."""
    given = {"table": {"a": np.int64(2), "b": np.float32(0.1)}, "anyv": np.arange(2), "inner": Inner(np.float32(0.5), np.bool_(True))}
    for settings_given in (given, T60Settings(**given)):
        settings = R.make_agent(agent, "ghh08", options=AgentOptions(settings=settings_given)).settings
        assert (settings.table, settings.anyv, settings.inner) == ({"a": 2, "b": 0.1}, [0, 1], Inner(0.5, True))
        assert (_types(settings.table), _types(settings.anyv), type(settings.inner.extra)) == ({"a": int, "b": float}, [int, int], bool)
        json.dumps(settings.to_dict(), allow_nan=False)  # what a run records


@pytest.mark.parametrize(
    ("given", "why"),
    [
        ({"table": {"a": np.float32(0.1), "s": {1}}}, f"table={{'a': np.float32(0.1), 's': {{1}}}} is not allowed: it holds {{1}}: {JSON_VALUE}"),
        ({"anyv": object()}, f"is not allowed: {JSON_VALUE} (its field T60Settings.anyv is of type Any"),
        (
            {"inner": Inner(extra={1})},
            f"inner=Inner(rate=1.0, extra={{1}}) is not allowed: its extra={{1}} is not allowed: {JSON_VALUE} (its field Inner.extra",
        ),
        ({"inner": Inner(rate=float("nan"))}, "inner=Inner(rate=nan, extra=None) is not allowed: its rate=nan is out of range: allowed a finite number"),
    ],
)
def test_an_agent_s_dict_any_or_nested_setting_json_cannot_write_is_refused(agent, given, why) -> None:
    with pytest.raises(NeurohoverError, match=re.escape("bad T60Settings: ") + ".*" + re.escape(why)):
        R.make_agent(agent, "ghh08", options=AgentOptions(settings=given))


def test_compete_with_numpy_values_in_a_dict_setting_records_them(agent, tmp_path) -> None:
    """T60-B01: compete was json's TypeError (its settings' digest) before flying."""
    out = tmp_path / "out"
    compete("ghh08", agent, runs=1, episodes=2, n_steps=20, out=out, store=tmp_path / "s.sqlite", agent_settings={"table": {"a": np.int64(2)}})
    assert json.loads((out / "summary.json").read_text())  # the run finished and wrote its summary
    with pytest.raises(NeurohoverError, match=re.escape(f"bad T60Settings: anyv={{1}} is not allowed: {JSON_VALUE}")):
        compete("ghh08", agent, runs=1, episodes=2, n_steps=20, out=tmp_path / "o2", store=tmp_path / "s2.sqlite", agent_settings={"anyv": {1}})
    assert not (tmp_path / "o2").exists()


# --- T60-B02: a default of any field's type checked at registration --------------------------------------------------


def _settings(default, *, annotation: Any = Any, bases: tuple[type, ...] = ()) -> type:
    field = dataclasses.field(default_factory=lambda: default)
    return dataclasses.make_dataclass("S", [("x", annotation, field)], bases=bases, frozen=True)


BAD_DEFAULTS = [
    (frozenset({1}), Any, f"default (made by its default_factory) x=frozenset({{1}}) is not allowed: {JSON_VALUE} (its field S.x is of type Any"),
    ({"a": np.int64(1)}, dict, "field 'x''s default is dict {'a': np.int64(1)}, no plain JSON value: give {'a': 1}"),
    ({"a": {1, 2}}, dict, f"default (made by its default_factory) x={{'a': {{1, 2}}}} is not allowed: it holds {{1, 2}}: {JSON_VALUE}"),
    (object(), object, f"is not allowed: {JSON_VALUE} (its field S.x is of type object"),
    (np.arange(2), Any, "field 'x''s default is ndarray array([0, 1]), no plain JSON value: give [0, 1]"),
    (Inner(extra={1}), Inner, f"x=Inner(rate=1.0, extra={{1}}) is not allowed: its extra={{1}} is not allowed: {JSON_VALUE}"),
]


@pytest.mark.parametrize(("default", "annotation", "why"), BAD_DEFAULTS)
def test_an_agent_spec_refuses_a_default_json_cannot_write(default, annotation, why) -> None:
    """T60-B02: AgentSpec took them; a compete given any agent_settings was json's TypeError."""
    cls = _settings(default, annotation=annotation, bases=(AgentSettings,))
    with pytest.raises(NeurohoverError, match=re.escape(f"agent {AGENT!r}: its settings class S's ") + ".*" + re.escape(why)):
        AgentSpec(AGENT, "specialised", NEEDS, _build, settings=cls)


@pytest.mark.parametrize(("default", "annotation", "why"), BAD_DEFAULTS)
def test_a_run_time_optimiser_s_default_json_cannot_write_is_refused(default, annotation, why) -> None:
    """T60-B02: OptimiserSpec took them; evolve was json's TypeError."""
    spec = OptimiserSpec("t60-opt-2", "user", _settings(default, annotation=annotation), _make, stops_itself=False)
    assert why in entry_problem("t60-opt-2", spec)
    OPTIMISERS["t60-opt-2"] = spec
    try:
        with pytest.raises(NeurohoverError, match=re.escape("OPTIMISERS['t60-opt-2'] = ") + ".*" + re.escape(why)):
            evolve(ZERO, budget=8, optimizer="t60-opt-2", **RUN)
    finally:
        OPTIMISERS.pop("t60-opt-2", None)


def test_a_tuple_default_is_one_rule_for_agents_and_optimisers() -> None:
    """The optimiser registry's own check refused a tuple default that an agent's spec took: one check now takes it."""
    cls = dataclasses.make_dataclass("S", [("xs", tuple[int, ...], (1, 2)), ("any", Any, (1, "a"))], frozen=True)
    assert settings_defaults_problem(cls) == ""
    assert entry_problem("t60-opt-3", OptimiserSpec("t60-opt-3", "user", cls, _make, stops_itself=False)) == ""


def test_a_nested_dataclass_default_made_plain_is_named() -> None:
    """T60-B02: a nested dataclass's NumPy default reached the run (json writes its asdict)."""
    cls = _settings(Inner(np.float32(0.5)), annotation=Inner)
    shown = "Inner(rate=np.float32(0.5), extra=None)"
    assert (
        settings_defaults_problem(cls)
        == f"field 'x''s default is Inner {shown}, no plain JSON value: give Inner(rate=0.5, extra=None) (the defaults are used as written)"
    )
    assert checked_settings(cls(x=Inner(np.float32(0.5), [np.int64(1)])), bad_what="S").x == Inner(0.5, [1])


# --- T60-B06: a settings class's unused() answer checked -------------------------------------------------------------


ANSWER: dict[str, Any] = {}


@dataclasses.dataclass(frozen=True)
class Unused(AgentSettings):
    k: int = 2

    @classmethod
    def unused(cls, agent: str, given: dict) -> str | None:
        return ANSWER["why"]


@pytest.fixture
def unused_agent():
    R.AGENTS["t60settings2"] = AgentSpec("t60settings2", "specialised", NEEDS, _build, settings=Unused)
    yield "t60settings2"
    R.AGENTS.pop("t60settings2", None)
    ANSWER.clear()


@pytest.mark.parametrize("why", ["", "  ", "two\nlines", True, 5, ["x"], b"why"])
def test_compete_refuses_a_bad_unused_answer(unused_agent, tmp_path, why) -> None:
    """T60-B06: "agent 'u60': " (no reason), "agent 'u60': True"."""
    ANSWER["why"] = why
    with pytest.raises(
        NeurohoverError,
        match=re.escape(f"agent 't60settings2': its settings class Unused's unused() answered {type(why).__name__} {why!r}, which is not"),
    ):
        compete("ghh08", unused_agent, runs=1, episodes=2, n_steps=20, out=tmp_path / "o", store=tmp_path / "s.sqlite", agent_settings={"k": 3})
    assert not (tmp_path / "o").exists()


CONFIG = (
    'name = "t60-settings"\ntitle = "t60"\nkind = "test_runs"\n[settings]\ntask = "ghh08"\nseed = 1\npolicies = "shipped"\n'
    '[[settings.groups]]\nagent = "t60settings2"\nlabel = "u"\nmdps = "train"\nn_mdps = 1\nsettings = { k = 3 }\n'
    "[scales.quick]\nepisodes = 2\nn_steps = 20\n"
)


def test_an_experiment_group_refuses_a_bad_unused_answer(unused_agent, tmp_path) -> None:
    """T60-B06: a config group's refusal was "group 'u': " with no reason."""
    path = tmp_path / "u.toml"
    path.write_text(CONFIG)
    ANSWER["why"] = "   "
    with pytest.raises(NeurohoverError, match=re.escape("its settings class Unused's unused() answered str '   ', which is not allowed")):
        load_config(str(path), "quick")


def test_a_fraction_past_a_float_s_range_in_a_list_setting_is_named(optimiser) -> None:
    """Seen beside T60-B01: float() of it, made plain, was a raw OverflowError in a list field."""
    from fractions import Fraction

    with pytest.raises(NeurohoverError, match=re.escape("xs=[Fraction(") + ".*" + re.escape("is out of range: allowed finite numbers")):
        population_settings(optimiser, {"xs": [Fraction(10**400)]})
