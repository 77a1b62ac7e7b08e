"""The agent registry: one spec per agent, read by the CLI, the competitions and the experiments."""

from __future__ import annotations

import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

from neurohover.agents.registry import AGENTS, HYBRID_AGENTS, agent_spec, discover, make_agent
from neurohover.agents.spec import AgentPolicies, AgentSpec
from neurohover.errors import NeurohoverError
from neurohover.experiments.config import load_config
from neurohover.tasks import get_task_family


def test_the_paper_agents_are_registered_with_their_tasks() -> None:
    assert list(AGENTS)[:2] == ["baseline", "generic"]
    assert set(AGENTS) == {
        "baseline",
        "generic",
        "model-free",
        "model-based",
        "incremental",
        "incremental-zero",
        "incremental-fixed",
        "incremental-race",
        "hybrid",
        "hybrid-baseline",
        "authors-zero",
        "authors-fixed",
        "authors-race",
        "continual",
        "model-free-risk",
        "hybrid-risk",
        "hybrid-baseline-risk",
    }
    assert HYBRID_AGENTS == ("hybrid", "hybrid-baseline")
    assert AGENTS["model-free"].tasks == ("ghh08", "ghh09") and AGENTS["incremental-race"].tasks == ("fghh",)
    assert AGENTS["authors-fixed"].tasks == ("fghh",) and AGENTS["authors-fixed"].generic_kind == "fixed"


@pytest.mark.parametrize("name", list(AGENTS))
def test_every_agent_builds_from_the_shipped_policy_set_of_each_of_its_tasks(name: str) -> None:
    spec = AGENTS[name]
    for task in spec.tasks:
        agent = make_agent(name, get_task_family(task))
        assert agent.name == name
    other = {"ghh08", "ghh09", "fghh"} - set(spec.tasks)
    for task in other:
        with pytest.raises(NeurohoverError, match=f"does not apply to task '{task}'"):
            make_agent(name, get_task_family(task))


def test_fghh_agents_fly_the_generic_policy_of_their_kind() -> None:
    from neurohover.policysets import load_policy_set

    ps = load_policy_set("fghh")
    for kind in ("zero", "fixed", "race"):
        flown = make_agent(f"incremental-{kind}", get_task_family("fghh")).generic.genome
        assert np.array_equal(flown, ps.generics[kind].genome)
    assert np.array_equal(make_agent("incremental", get_task_family("fghh")).generic.genome, ps.generics["race"].genome)
    assert not np.array_equal(ps.generics["zero"].genome, ps.generics["race"].genome)


def test_unknown_agents_are_refused_everywhere_with_the_same_list() -> None:
    with pytest.raises(NeurohoverError, match="unknown agent 'sarsa': allowed baseline, generic, model-free"):
        agent_spec("sarsa")
    with pytest.raises(NeurohoverError, match="'sarsa'.*one of 'baseline', 'generic', 'model-free'"):
        load_config("fig7", "quick", {"groups": [{"agent": "sarsa", "n_mdps": 1}]})


def test_a_new_agent_module_is_discovered_without_editing_any_other_file(tmp_path: Path, monkeypatch) -> None:
    package = tmp_path / "myagents"
    package.mkdir()
    (package / "__init__.py").write_text("")
    (package / "always_generic.py").write_text(
        textwrap.dedent("""
        from neurohover.agents.reference import GenericAgent
        from neurohover.agents.spec import AgentSpec

        AGENT_SPECS = (AgentSpec("always-generic", "specialised", frozenset({"generic"}),
                                 lambda policies, options: GenericAgent(policies.generic)),)
    """)
    )
    monkeypatch.syspath_prepend(str(tmp_path))
    specs = discover("myagents")
    assert list(specs) == ["always-generic"] and isinstance(specs["always-generic"], AgentSpec)
    sys.modules.pop("myagents", None)


def test_a_spec_refuses_unknown_policy_needs() -> None:
    with pytest.raises(ValueError, match="unknown policy needs"):
        AgentSpec("x", "specialised", frozenset({"teacher"}), lambda p, o: None)
    with pytest.raises(ValueError, match=r"runs_on=\('ghh08',\); allowed \('any', 'specialised', 'generics-by-kind'\)"):
        AgentSpec("x", ("ghh08",), frozenset({"generic"}), lambda p, o: None)
    with pytest.raises(ValueError, match="name its generic_kind"):
        AgentSpec("x", "any", frozenset({"generic"}), lambda p, o: None)
    assert AgentPolicies().generic is None


def test_a_policy_set_evolved_for_another_sigma_is_refused(tmp_path: Path, capsys) -> None:
    from neurohover.cli import main

    with pytest.raises(NeurohoverError, match="evolved for sigma = 0.3, not 0.2"):
        make_agent("generic", get_task_family("fghh", 0.2))
    assert make_agent("generic", get_task_family("fghh", 0.3)).name == "generic"
    assert make_agent("baseline", get_task_family("fghh", 0.2)).name == "baseline"  # flies no policy set
    rc = main(["compete", "--task", "fghh", "--sigma", "0.2", "--agent", "incremental-race", "--runs", "1", "--episodes", "2", "--out", str(tmp_path / "c")])
    assert rc == 2 and "evolved for sigma = 0.3, not 0.2" in capsys.readouterr().err


def test_the_readmes_example_agent_works_as_one_new_module(tmp_path: Path, monkeypatch) -> None:
    from neurohover.agents.protocol import run_test
    from neurohover.agents.registry import policies_from_set
    from neurohover.agents.spec import AgentOptions
    from neurohover.policysets import load_policy_set

    readme = (Path(__file__).parent.parent / "README.md").read_text()
    block = readme.split("# neurohover/agents/best_of_two.py\n", 1)[1].split("```", 1)[0]
    package = tmp_path / "readme_agents"
    package.mkdir()
    (package / "__init__.py").write_text("")
    (package / "best_of_two.py").write_text(block)
    monkeypatch.syspath_prepend(str(tmp_path))
    spec = discover("readme_agents")["best-of-two"]
    family = get_task_family("ghh08")
    agent = spec.build(policies_from_set(spec, load_policy_set("ghh08")), AgentOptions())
    run = run_test(agent, family, family.test_mdps()[0], episodes=4, n_steps=100)
    assert run.policy[:2] == ["candidate:0", "candidate:1"] and run.policy[2] == run.policy[3]
    # T49-B02: flown again, the same agent scores as a fresh one (its start resets what the first run learned)
    again = run_test(agent, family, family.test_mdps()[1], episodes=4, n_steps=100)
    fresh = run_test(spec.build(policies_from_set(spec, load_policy_set("ghh08")), AgentOptions()), family, family.test_mdps()[1], episodes=4, n_steps=100)
    assert again.policy == fresh.policy and np.array_equal(again.returns, fresh.returns)
    sys.modules.pop("readme_agents", None)
    sys.modules.pop("readme_agents.best_of_two", None)


def test_a_new_family_gets_every_agent_its_policy_set_can_serve() -> None:
    """Agents name a condition on the family, not a list of names: a new family needs no agent edited."""
    from types import SimpleNamespace

    specialised_like = SimpleNamespace(name="heavy", generic_over_distribution=False)  # its sets: generic + specialised
    over_g_like = SimpleNamespace(name="fghh-wide", generic_over_distribution=True)  # its sets: generics by kind
    on_first = {n for n, s in AGENTS.items() if s.applies_to(specialised_like)}
    on_second = {n for n, s in AGENTS.items() if s.applies_to(over_g_like)}
    assert {"baseline", "generic", "model-free", "incremental", "hybrid"} <= on_first and not any(n.startswith("authors-") for n in on_first)
    assert {"baseline", "incremental", "authors-race", "incremental-zero"} <= on_second and "model-free" not in on_second and "hybrid" not in on_second
    with pytest.raises(NeurohoverError, match="agent 'hybrid' does not apply to task 'fghh-wide': it runs on ghh08, ghh09"):
        agent_spec("hybrid", over_g_like)


def test_an_agent_with_settings_of_its_own_takes_them_from_a_config_group(tmp_path, monkeypatch) -> None:
    """An agent's typed settings class is all it takes: configs validate them, units carry them, the agent gets them."""
    from dataclasses import dataclass

    from neurohover.agents import registry
    from neurohover.agents.reference import GenericAgent
    from neurohover.agents.spec import AgentSettings
    from neurohover.experiments.plans import plan
    from neurohover.experiments.units import unit_agent

    @dataclass(frozen=True)
    class PatientSettings(AgentSettings):
        patience: int = 3

        def __post_init__(self) -> None:
            if self.patience < 1:
                raise ValueError(f"patience={self.patience} must be >= 1")

    built = []

    def build(policies, options):
        built.append(options.settings)
        return GenericAgent(policies.generic)

    spec = AgentSpec("patient", "any", frozenset({"generic"}), build, generic_kind="race", settings=PatientSettings)
    monkeypatch.setitem(registry.AGENTS, "patient", spec)
    config = tmp_path / "patient.toml"
    text = """
name = "patienttest"
kind = "test_runs"
[settings]
task = "ghh08"
seed = 3
policies = "shipped"
groups = [{ agent = "patient", n_mdps = 1, settings = { patience = 7 } }, { agent = "generic", n_mdps = 1 }]
[scales.quick]
episodes = 2
n_steps = 50
"""
    config.write_text(text)
    cfg = load_config(config, "quick")
    units = {u.key: u for u in plan(cfg, {}).units}
    assert units["run/patient/test0/rep0"].params["agent_settings"] == {"patience": 7}
    assert "agent_settings" not in units["run/generic/test0/rep0"].params  # others' params (and hashes) as before
    unit_agent(units["run/patient/test0/rep0"].params)
    assert built == [PatientSettings(patience=7)]
    config.write_text(text.replace("patience = 7", "patience = 0"))
    with pytest.raises(NeurohoverError, match="group 'patient': bad PatientSettings: patience=0 must be >= 1"):
        load_config(config, "quick")
    config.write_text(text.replace("patience = 7", "patiense = 7"))
    with pytest.raises(NeurohoverError, match="unknown PatientSettings setting.*patiense.*allowed patience"):
        load_config(config, "quick")
    config.write_text(text.replace('{ agent = "generic", n_mdps = 1 }', '{ agent = "generic", n_mdps = 1, settings = { patience = 2 } }'))
    with pytest.raises(NeurohoverError, match="agent 'generic' takes no settings table"):
        load_config(config, "quick")
