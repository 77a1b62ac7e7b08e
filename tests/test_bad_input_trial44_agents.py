"""Bad-input trial 44, side B (the agents' registry): discover imported every module of a package, ``__main__`` included
(discover('neurohover') ran the CLI, a user's package's __main__.py ended the interpreter), and bad package names leaked
ValueError, ModuleNotFoundError, AttributeError or TypeError (T44-B06); check_agent took no task name, which make_agent
and agent_spec take (T44-B07); agent_spec's task and policies_from_set's spec and policy set were unchecked (T44-B08);
an edited registry entry that is no AgentSpec was an AttributeError in make_agent and compete (T44-B14), and an alias
key or a shipped slot holding a user's spec were used without a word (T44-B15). A test run on a learned model's MDP
stays refused, and the README and glossary no longer say the model's MDP flies anywhere an MDP does (T44-B16)."""

from __future__ import annotations

import copy
import re
import sys
import textwrap
from pathlib import Path

import pytest

import neurohover as nh
from neurohover.agents import registry as R
from neurohover.agents import run_test
from neurohover.agents.spec import AgentSpec
from neurohover.compete import agents_with_settings, compete, competition_config
from neurohover.errors import NeurohoverError
from neurohover.experiments.config import make_config
from neurohover.models import LearnedModel
from neurohover.policysets import load_policy_set

USER_SPEC = AgentSpec("best-of-two", "specialised", frozenset({"generic", "specialised"}), lambda policies, options: None, summary="a user's")


# --------------------------------------------------------------------------- T44-B06: discover


def test_discover_skips_main_and_private_modules(tmp_path, monkeypatch):
    pkg = tmp_path / "t44_agents"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    (pkg / "__main__.py").write_text("import sys\nsys.exit(3)\n")
    (pkg / "_helpers.py").write_text("raise RuntimeError('a private module is not imported')\n")
    (pkg / "registry.py").write_text(
        textwrap.dedent("""
        from neurohover.agents.spec import AgentSpec
        AGENT_SPECS = (AgentSpec("mine", "any", frozenset(), lambda policies, options: None),)
        """)
    )
    monkeypatch.syspath_prepend(str(tmp_path))
    try:
        assert list(R.discover("t44_agents")) == ["mine"]  # a user's module named registry is one of its agent modules
    finally:
        for name in [m for m in sys.modules if m == "t44_agents" or m.startswith("t44_agents.")]:
            del sys.modules[name]
    assert R.discover("neurohover") == {}  # neurohover.__main__ ran the CLI: SystemExit 2
    assert list(R.discover("neurohover.agents")) == list(R.SHIPPED_SPECS) == list(R.AGENTS)  # every shipped agent found


@pytest.mark.parametrize(
    ("package", "why"),
    [
        ("", "package='' is not allowed: give an importable package's dotted name"),
        (".agents", "package='.agents' is not allowed: give"),
        (None, "package=None is not allowed: give"),
        (5, "package=5 is not allowed: give"),
        (["neurohover.agents"], "package=['neurohover.agents'] is not allowed: give"),
        ("t44_no_such_package", "package='t44_no_such_package' is not allowed: no module named 't44_no_such_package' is importable"),
        ("neurohover.no_such", "package='neurohover.no_such' is not allowed: no module named 'neurohover.no_such'"),
        ("os", "package='os' is not allowed: it is a module, not a package"),
        ("neurohover.agents.registry", "package='neurohover.agents.registry' is not allowed: it is a module, not a package"),
    ],
)
def test_discover_refuses_bad_package(package, why):
    with pytest.raises(NeurohoverError, match=re.escape(why)):
        R.discover(package)


def test_discover_refuses_bad_agent_specs(tmp_path, monkeypatch):
    pkg = tmp_path / "t44_bad_specs"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    (pkg / "one.py").write_text("AGENT_SPECS = 5\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    try:
        with pytest.raises(NeurohoverError, match=re.escape("module t44_bad_specs.one's AGENT_SPECS=5 is not allowed: declare a tuple of AgentSpecs")):
            R.discover("t44_bad_specs")
    finally:
        for name in [m for m in sys.modules if m == "t44_bad_specs" or m.startswith("t44_bad_specs.")]:
            del sys.modules[name]


# --------------------------------------------------------------------------- T44-B07, T44-B08: the task, spec and set


def test_check_agent_takes_a_task_name():
    assert R.check_agent("incremental", "ghh08") is None  # as make_agent and agent_spec take it
    assert R.check_agent("baseline", nh.get_task_family("ghh09")) is None
    for bad in (None, 5, ["ghh08"]):
        with pytest.raises(NeurohoverError, match=re.escape(f"family={bad!r} is not allowed: give a task family")):
            R.check_agent("incremental", bad)
    with pytest.raises(NeurohoverError, match="unknown task 'no-such'"):
        R.check_agent("incremental", "no-such")


@pytest.mark.parametrize("task", [5, ["ghh08"], 1.5])
def test_agent_spec_refuses_bad_task(task):
    with pytest.raises(NeurohoverError, match=re.escape(f"task={task!r} is not allowed: give a task family")):
        R.agent_spec("incremental", task)


def test_policies_from_set_checks_spec_and_set():
    ps = load_policy_set("ghh08")
    by_name, by_spec = R.policies_from_set("model-free", ps), R.policies_from_set(R.agent_spec("model-free"), ps)
    assert by_name == by_spec and by_name.specialised
    for spec in (R.agent_spec("model-free"), "model-free"):
        with pytest.raises(NeurohoverError, match=re.escape("ps=None is not allowed: give a PolicySet")):
            R.policies_from_set(spec, None)
    for spec in (None, 5):
        with pytest.raises(NeurohoverError, match=re.escape(f"spec={spec!r} is not allowed: give an AgentSpec or an agent's name")):
            R.policies_from_set(spec, ps)
    with pytest.raises(NeurohoverError, match="unknown agent 'no-such'"):
        R.policies_from_set("no-such", ps)


# --------------------------------------------------------------------------- T44-B14, T44-B15: the registry edited


def _still_usable() -> None:
    """The registry's other entries work beside a bad one."""
    assert type(R.make_agent("model-free", "ghh08")).__name__ == "ModelFreeAgent"
    assert "incremental" in agents_with_settings()
    from neurohover.cli.app import build_parser

    assert build_parser() is not None  # compete --agent's help lists the usable agents


def test_registry_entry_that_is_no_spec(monkeypatch, tmp_path):
    monkeypatch.setitem(R.AGENTS, "junk", "not a spec")
    why = re.escape("AGENTS['junk'] = 'not a spec' is not allowed: register an AgentSpec under its name")
    with pytest.raises(NeurohoverError, match=why):
        R.make_agent("junk", nh.get_task_family("ghh08"))
    with pytest.raises(NeurohoverError, match=why):
        compete("ghh08", "junk", runs=1, episodes=2, out=tmp_path / "out")
    assert not (tmp_path / "out").exists()
    with pytest.raises(NeurohoverError, match=r"unknown agent 'zz': allowed baseline, [^:]*-risk$") as err:
        R.agent_spec("zz")
    assert "junk" not in str(err.value)
    assert "junk" not in R.usable_agents()
    _still_usable()


def test_registry_bad_entry_in_experiment_configs(monkeypatch):
    monkeypatch.setitem(R.AGENTS, "junk", "not a spec")
    monkeypatch.setitem(R.AGENTS, 5, R.SHIPPED_SPECS["baseline"])  # a key that is no text: 'int' has no attribute 'lower'
    config = competition_config("ghh08", "baseline", runs=1, episodes=2)  # the other agents' configs are made
    settings = copy.deepcopy(dict(config.settings))
    settings["groups"] = [{**settings["groups"][0], "agent": "junk"}]
    with pytest.raises(NeurohoverError, match=r"agent.*'junk'.*not allowed.*'baseline'"):
        make_config("t44-junk", "test_runs", "quick", settings)


def test_registry_alias_and_replaced_shipped_slot(monkeypatch):
    monkeypatch.setitem(R.AGENTS, "alias", USER_SPEC)
    with pytest.raises(NeurohoverError, match=re.escape("its spec's name 'best-of-two' is not its key; register a spec under its own name")):
        R.make_agent("alias", "ghh08")
    monkeypatch.setitem(R.AGENTS, "baseline", USER_SPEC)
    with pytest.raises(NeurohoverError, match=re.escape("'baseline' is a shipped agent's name and holds its shipped spec")):
        R.make_agent("baseline", "ghh08")
    monkeypatch.setitem(R.AGENTS, "best-of-two", USER_SPEC)  # a run-time agent under its own name is taken
    assert R.agent_spec("best-of-two", "ghh08") is USER_SPEC
    monkeypatch.setitem(R.AGENTS, "baseline", R.SHIPPED_SPECS["baseline"])  # its shipped spec back: taken again
    assert R.agent_spec("baseline") is R.SHIPPED_SPECS["baseline"]
    _still_usable()


# --------------------------------------------------------------------------- T44-B16: a test run on a model's MDP


def test_test_run_on_a_model_mdp_is_refused_and_documented():
    family = nh.get_task_family("ghh09")
    model = LearnedModel(tuple(nh.get_task_family("fghh").zero().params), (0.1,) * 6, "lr")
    mdp = model.mdp()
    assert nh.evaluate(nh.baseline_policy(), mdp, n_steps=5).returns.shape == (1, 1, 1)  # it flies where an MDP does
    with pytest.raises(NeurohoverError, match=re.escape("is a model MDP, but the run's family is ghh09: an agent's test run flies an MDP of its family")):
        run_test(R.make_agent("baseline", family), family, mdp, episodes=1, n_steps=5)
    root = Path(__file__).resolve().parents[1]
    readme, glossary = (root / "README.md").read_text(), (root / "docs" / "glossary.md").read_text()
    assert "flies anywhere an MDP does\n" not in readme and "not run_test" in readme
    assert "but in an\nagent's test run (`run_test`)" in glossary
