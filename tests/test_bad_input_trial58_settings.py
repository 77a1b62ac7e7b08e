"""Bad-input trial 58, side B (settings tables and a run-time agent's or optimiser's settings class).

T58-B01..B03: ``unknown_keys`` named the unknown keys as text, which for the key '' is '' and its callers read as "no
unknown key": ``evolve(settings={"": 1})`` was SteadyStateSettings' TypeError (a config's ``optimizer = { "" = 1 }`` a
traceback through ``reproduce``), ``hybrid={"": 1}`` was taken and ignored, a unit's params {"": 1} reached the class's
TypeError, and keys were named unquoted ("pop_size " hid its space; cma's, openai-es's and an agent's {"": 1} were
Python's "unexpected keyword argument ''"). Every key is now named as its repr.

T58-B04: a settings field typed as a list or tuple took items JSON cannot write (NumPy ints, np.float32, a set, an
ndarray): evolve and compete were json's TypeError, make_agent handed the NumPy values on. Its items are now made plain
as a plain field's value is (an ndarray's items too), and a value that is no list, tuple or array is refused by name.

T58-B05: a default_factory's default went unchecked at registration: ``[nan]`` flew a whole run, and its checkpoint was
JSON's ValueError, the run lost. It is now made once and checked as a plain default is."""

from __future__ import annotations

import dataclasses
import json
import re

import numpy as np
import pytest

from neurohover.agents import registry as R
from neurohover.agents.hybrid import HybridSettings
from neurohover.agents.protocol import Agent, Choice
from neurohover.agents.spec import AgentOptions, AgentSettings, AgentSpec
from neurohover.errors import NeurohoverError, unknown_keys
from neurohover.evolution import evolve
from neurohover.evolution.optimisers import OPTIMISERS, SHIPPED_SPECS, OptimiserSpec, entry_problem, population_settings
from neurohover.experiments import load_config, params
from neurohover.experiments.params import unit_params
from neurohover.tasks import get_task_family

ZERO = get_task_family("ghh08").zero()
RUN = dict(topology="slp", prototype="zero", seed=3, n_steps=20)
AGENT = "t58-settings-agent-1"
NEEDS = frozenset({"generic"})


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
class T58Settings(AgentSettings):
    """A list field of any JSON values, a tuple field of floats, an optional list of ints."""

    xs: list = dataclasses.field(default_factory=lambda: [1.0])
    ys: tuple[float, ...] = (1.0,)
    ks: list[int] | None = None


@pytest.fixture
def agent():
    R.AGENTS[AGENT] = AgentSpec(AGENT, "specialised", NEEDS, lambda p, o: HoldingAgent(p.generic, o.settings), settings=T58Settings)
    yield AGENT
    R.AGENTS.pop(AGENT, None)


@dataclasses.dataclass(frozen=True)
class T58OptSettings:
    popsize: int = 4
    extra: list = dataclasses.field(default_factory=lambda: [1.0])


@pytest.fixture
def optimiser():
    from neurohover.evolution.optimisers.openai_es import OpenAIESSettings

    name, make = "t58-settings-opt-1", SHIPPED_SPECS["openai-es"].make
    OPTIMISERS[name] = OptimiserSpec(name, "user", T58OptSettings, lambda p, s, seed: make(p, OpenAIESSettings(popsize=s.popsize), seed), stops_itself=False)
    yield name
    OPTIMISERS.pop(name, None)


def _types(values) -> list[type]:
    return [type(v) for v in values]


# --- T58-B01..B03: unknown keys named as their repr -----------------------------------------------------------------


def test_unknown_keys_names_the_empty_key() -> None:
    assert unknown_keys({"": 1, "a": 2}, ["a"]) == "''"
    assert unknown_keys({"pop_size ": 1, 1: 2, b"x": 3}, []) == "1, b'x', 'pop_size '"
    assert unknown_keys({"a": 1}, ["a"]) == ""


@pytest.mark.parametrize(("optimizer", "what"), [("ne", "steady-state"), ("cma", "cma"), ("openai-es", "openai-es")])
def test_evolve_refuses_the_settings_key_empty_text(optimizer, what) -> None:
    """T58-B01/B03: ne's was SteadyStateSettings' TypeError; cma's and openai-es's were Python's own message."""
    with pytest.raises(NeurohoverError, match=re.escape(f"unknown {what} setting(s) '': allowed ")):
        evolve(ZERO, budget=5, optimizer=optimizer, settings={"": 1}, **RUN)


def test_evolve_names_a_key_with_a_trailing_space_quoted() -> None:
    """T58-B03: "unknown steady-state setting(s) pop_size : allowed" hid the space."""
    with pytest.raises(NeurohoverError, match=re.escape("unknown steady-state setting(s) 'pop_size ': allowed ")):
        evolve(ZERO, budget=5, settings={"pop_size ": 3}, **RUN)


CONFIG = """
name = "t58-settings"
title = "t58"
kind = "evolution"
[settings]
task = "ghh08"
seed = 1
target = "train"
validation_episodes = 2
optimizer = { "" = 1 }
[[settings.variants]]
key = "slp-zero"
label = "SLP"
topology = "slp"
prototype = "zero"
[scales.quick]
n_mdps = 1
runs = 1
budget = 40
n_steps = 20
"""


def test_reproduce_refuses_an_optimizer_table_key_empty_text(tmp_path, cli) -> None:
    """T58-B01: a traceback ending in SteadyStateSettings' TypeError, exit status 1."""
    path = tmp_path / "t58.toml"
    path.write_text(CONFIG)
    rc, out, err = cli("reproduce", str(path), "--scale", "quick", "--store", str(tmp_path / "s.sqlite"))
    assert (rc, out) == (2, "") and "optimizer: unknown steady-state setting(s) '': allowed " in err, err


def test_hybrid_settings_refuse_the_key_empty_text(tmp_path) -> None:
    """T58-B02: hybrid={"": 1} was taken and ignored, where {" rule": ...} is refused."""
    with pytest.raises(NeurohoverError, match=re.escape("unknown hybrid setting(s) '': allowed box, model_from")):
        HybridSettings.from_dict({"": 1})
    with pytest.raises(NeurohoverError, match=re.escape("unknown hybrid setting(s) ''")):
        R.make_agent("hybrid", "ghh09", options=AgentOptions(settings={"": 1}))
    path = tmp_path / "h.toml"
    path.write_text(
        'name = "h"\ntitle = "h"\nkind = "test_runs"\n[settings]\ntask = "ghh09"\nseed = 1\npolicies = "shipped"\n'
        '[[settings.groups]]\nagent = "hybrid"\nlabel = "hybrid-x"\nmdps = "train"\nn_mdps = 1\nhybrid = { "" = 1 }\n'
        "[scales.quick]\nepisodes = 2\nn_steps = 20\nmodel_budget = 10\nmax_learning_episodes = 1\n"
    )
    with pytest.raises(NeurohoverError, match=re.escape("group 'hybrid-x': unknown hybrid setting(s) '': allowed ")):
        load_config(str(path), "quick")


def test_an_agent_s_settings_refuse_the_key_empty_text() -> None:
    """T58-B03: "bad IncrementalSettings: IncrementalSettings.__init__() got an unexpected keyword argument ''"."""
    with pytest.raises(NeurohoverError, match=re.escape("unknown IncrementalSettings setting(s) '': allowed max_learning_episodes")):
        R.make_agent("incremental", "ghh08", options=AgentOptions(settings={"": 1}))


def test_load_config_names_an_unknown_override_quoted() -> None:
    """T58-B03: "unknown setting(s) ; allowed: budget, ..."."""
    with pytest.raises(NeurohoverError, match=re.escape("unknown setting(s) ''; allowed: budget")):
        load_config("fig2", "quick", {"": 1})


def test_unit_params_name_the_key_empty_text() -> None:
    """T58-B01's cause in a unit's params: {"": 1} beside every field was TestRunParams' TypeError."""
    fields = {f.name: None for f in dataclasses.fields(params.TestRunParams) if f.default is dataclasses.MISSING}
    with pytest.raises(NeurohoverError, match=re.escape("params hold '', which TestRunParams does not declare")):
        unit_params("test_run", {**fields, "": 1})


# --- T58-B04: a list or tuple field's items made plain, no list refused ---------------------------------------------


@pytest.mark.parametrize(
    ("given", "expected"),
    [
        (list(np.arange(3)), [0, 1, 2]),
        ([np.float32(0.1), np.float64(-0.0)], [0.1, 0.0]),
        (np.array([1.0, 2.5]), [1.0, 2.5]),
        ((np.int8(1), "a", None, np.bool_(True)), [1, "a", None, True]),
        ([{"a": np.int64(2)}, [np.float32(0.5)]], [{"a": 2}, [0.5]]),
    ],
)
def test_an_optimiser_s_list_setting_holds_plain_values(optimiser, given, expected) -> None:
    """T58-B04: NumPy values in a list field were json's TypeError when the run began."""
    settings = population_settings(optimiser, {"extra": given})
    assert settings.extra == expected and type(settings.extra) is list
    assert json.dumps(settings.extra) == json.dumps(expected)  # each item of its plain type (0.1, not 0.10000000149)
    assert _types(settings.extra) == _types(expected)


def test_evolve_with_numpy_items_in_a_list_setting_records_them(optimiser, tmp_path) -> None:
    """T58-B04: "TypeError: Object of type int64 is not JSON serializable" from the run's config."""
    evolve(ZERO, budget=8, optimizer=optimiser, settings={"extra": list(np.arange(3))}, checkpoint=tmp_path / "c.json", **RUN)
    assert json.loads((tmp_path / "c.json").read_text())["config"]["settings"]["extra"] == [0, 1, 2]


@pytest.mark.parametrize("given", [{1.0}, frozenset({1.0}), "abc", 1.0, {"a": 1}, np.float64(1.0), np.array(1.0), np.ma.masked_array([1.0])])
def test_an_optimiser_s_list_setting_that_is_no_list_is_refused(optimiser, given) -> None:
    """T58-B04: a set was json's TypeError; the message names the field and the value."""
    with pytest.raises(
        NeurohoverError, match=r"bad t58-settings-opt-1 settings: extra=.* is not allowed: give a list \(or a tuple\) of plain JSON values"
    ) as err:
        population_settings(optimiser, {"extra": given})
    assert "(its field T58OptSettings.extra is of type list)" in str(err.value)


@pytest.mark.parametrize(("item", "shown"), [(object(), "<object object"), ({1: 2}, "{1: 2}"), (1 + 2j, "(1+2j)"), (b"x", "b'x'")])
def test_an_optimiser_s_list_setting_with_an_item_json_cannot_write_is_refused(optimiser, item, shown) -> None:
    with pytest.raises(NeurohoverError, match=re.escape(f"is not allowed: it holds {shown}")):
        population_settings(optimiser, {"extra": [1.0, item]})


def test_a_non_finite_item_of_an_array_is_refused(optimiser) -> None:
    with pytest.raises(NeurohoverError, match=re.escape("extra=array([ 1., inf]) is out of range: allowed finite numbers")):
        population_settings(optimiser, {"extra": np.array([1.0, np.inf])})


def test_an_agent_gets_its_list_and_tuple_settings_as_plain_values(agent) -> None:
    """T58-B04: make_agent handed the NumPy values on."""
    given = {"xs": list(np.arange(2)), "ys": np.array([0.1, 2], dtype=np.float32), "ks": (np.int64(3),)}
    for settings_given in (given, T58Settings(**given)):
        settings = R.make_agent(agent, "ghh08", options=AgentOptions(settings=settings_given)).settings
        assert (settings.xs, settings.ys, settings.ks) == ([0, 1], (0.1, 2.0), [3])
        assert (_types(settings.xs), _types(settings.ys), _types(settings.ks)) == ([int, int], [float, float], [int])
        json.dumps(settings.to_dict(), allow_nan=False)  # what a run records
    assert R.make_agent(agent, "ghh08", options=AgentOptions(settings={"ks": None})).settings.ks is None
    cls = dataclasses.make_dataclass("S", [("xs", list[float], dataclasses.field(default_factory=lambda: [1, 2.5]))], bases=(AgentSettings,), frozen=True)
    AgentSpec(AGENT, "specialised", NEEDS, lambda p, o: HoldingAgent(p.generic, o.settings), settings=cls)  # a plain factory's (1 for 1.0: Python's)


@pytest.mark.parametrize(
    ("given", "why"),
    [
        ({"ys": [1.0, "a"]}, "ys=[1.0, 'a'] is not allowed: it holds 'a': give a tuple (or a list) whose items are each a finite number"),
        ({"ys": {1.0}}, "ys={1.0} is not allowed: give a tuple (or a list) whose items are each a finite number (its field T58Settings.ys is"),
        ({"ks": [1.5]}, "ks=[1.5] is not allowed: it holds 1.5: give a list (or a tuple) whose items are each an integer, or None"),
        ({"ks": [True]}, "ks=[True] is not allowed: it holds True: give a list (or a tuple) whose items are each an integer"),
        ({"xs": None}, "xs=None is not allowed: give a list (or a tuple) of plain JSON values"),
    ],
)
def test_an_agent_s_list_setting_of_wrong_items_is_refused(agent, given, why) -> None:
    with pytest.raises(NeurohoverError, match=re.escape(f"bad T58Settings: {why}")):
        R.make_agent(agent, "ghh08", options=AgentOptions(settings=given))


# --- T58-B05: a default_factory's default checked at registration ---------------------------------------------------


def _optimiser_settings(default_factory) -> type:
    return dataclasses.make_dataclass("OS", [("extra", list, dataclasses.field(default_factory=default_factory))], frozen=True)


def test_a_run_time_optimiser_s_nan_default_factory_is_refused_at_registration() -> None:
    """T58-B05: a whole run flew, then its checkpoint was JSON's ValueError and the run lost."""
    spec = OptimiserSpec("t58-settings-opt-2", "user", _optimiser_settings(lambda: [float("nan")]), lambda p, s, seed: None, stops_itself=False)
    problem = entry_problem("t58-settings-opt-2", spec)
    assert "its settings default (made by its default_factory) extra=[nan] is out of range: allowed finite numbers" in problem
    OPTIMISERS["t58-settings-opt-2"] = spec
    try:
        with pytest.raises(NeurohoverError, match=re.escape("extra=[nan] is out of range")):
            evolve(ZERO, budget=8, optimizer="t58-settings-opt-2", **RUN)
    finally:
        OPTIMISERS.pop("t58-settings-opt-2", None)


@pytest.mark.parametrize(
    ("default_factory", "why"),
    [
        (lambda: [float("nan")], "default (made by its default_factory) xs=[nan] is out of range: allowed finite numbers"),
        (lambda: [np.float32(0.1)], "field 'xs''s default is list [np.float32(0.1)], no plain JSON value: give [0.1]"),
        (lambda: [-0.0], "field 'xs''s default is list [-0.0], which settings given are read as 0.0: give [0.0]"),
        (lambda: {1.0}, "default (made by its default_factory) xs={1.0} is not allowed: give a list (or a tuple) of plain JSON values"),
        (lambda: [][0], "field 'xs''s default_factory raised IndexError 'list index out of range': give one that makes the default"),
    ],
)
def test_an_agent_spec_refuses_a_default_factory_s_bad_default(default_factory, why) -> None:
    """T58-B05: S(xs=[nan]) was registered and handed to the agent; compete then blamed a value the user never gave."""
    cls = dataclasses.make_dataclass("S", [("xs", list, dataclasses.field(default_factory=default_factory))], bases=(AgentSettings,), frozen=True)
    with pytest.raises(NeurohoverError, match=re.escape(f"agent {AGENT!r}: its settings class S's {why}")):
        AgentSpec(AGENT, "specialised", NEEDS, lambda p, o: HoldingAgent(p.generic, o.settings), settings=cls)
