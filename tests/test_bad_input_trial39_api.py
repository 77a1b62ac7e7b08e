"""Bad-input trial 39 (the Python API): an Agent subclass's staticmethod or classmethod choose was called raw by
neurohover's check and failed, a keyword-only one was Python's bare TypeError (T39-B01); agent constructors stored their
settings unchecked, and an agent's arguments changed after construction failed deep in run_test (T39-B02);
IncrementalModelBasedAgent took max_learning_episodes -1, 0, 2.5 and True, and a hybrid agent with its fallback set to
None flew without its safeguard (T39-B03); HybridAgent took None, 5, '' and 'x\\ny' as its name (T39-B04); an evolved
policy file's prototype was never checked (T39-B05)."""

from __future__ import annotations

import json

import pytest

import neurohover as nh
from neurohover.agents import Agent, Choice, run_test
from neurohover.agents.continual import ContinualAgent, ContinualSettings
from neurohover.agents.fghh_code import CodeFGHHAgent
from neurohover.agents.hybrid import HybridAgent, HybridSettings
from neurohover.agents.model_based import IncrementalModelBasedAgent, ModelBasedAgent
from neurohover.agents.model_free import ModelFreeAgent
from neurohover.agents.risk import RiskHybridAgent, RiskModelFreeAgent
from neurohover.errors import NeurohoverError

P = nh.baseline_policy()
FAM = nh.get_task_family("ghh08")


def _run(agent, episodes=2):
    return run_test(agent, FAM, FAM.zero(), episodes=episodes, n_steps=20)


class _Static(Agent):
    @staticmethod
    def choose(episode):
        return Choice(P, f"s:{episode}")

    @staticmethod
    def update(outcome):
        pass


class _Class(Agent):
    @classmethod
    def choose(cls, episode):
        return Choice(P, f"c:{episode}")

    def update(self, outcome):
        pass


class _Property(Agent):
    @property
    def choose(self):
        return lambda episode: Choice(P, f"p:{episode}")

    def update(self, outcome):
        pass


class _KeywordOnly(Agent):
    def choose(self, *, episode):
        return Choice(P, "k")

    def update(self, outcome):
        pass


def test_an_agents_choose_is_called_as_plain_python_calls_it():
    """T39-B01: a staticmethod, classmethod or property choose (and a staticmethod update) fly; a choose run_test cannot
    call (a keyword-only episode) is refused by name before any episode, as is a start set to None."""
    for cls, tag in ((_Static, "s"), (_Class, "c"), (_Property, "p")):
        assert _run(cls()).policy == [f"{tag}:0", f"{tag}:1"]
    keyword_only = r"^agent class _KeywordOnly's choose of signature '\(\*, episode\)' is not allowed: run_test calls agent.choose\(episode\); "
    with pytest.raises(NeurohoverError, match=keyword_only + r"give a method choose\(self, episode\)"):
        _run(_KeywordOnly())
    agent = _Static()
    agent.start = None
    with pytest.raises(NeurohoverError, match=r"^agent 'agent''s start=None is not allowed: run_test calls agent.start\(family, rng\)"):
        _run(agent)


def _agents():
    return {
        "model-based": (ModelBasedAgent, (P,), "settings", "ModelEvolution"),
        "incremental": (IncrementalModelBasedAgent, (P,), "settings", "ModelEvolution"),
        "hybrid": (HybridAgent, ([P, P], P, P), "settings", "ModelEvolution"),
        "hybrid-settings": (HybridAgent, ([P, P], P, P), "hybrid", "HybridSettings"),
        "continual-evolution": (ContinualAgent, (P,), "evolution", "ModelEvolution"),
        "continual": (ContinualAgent, (P,), "settings", "ContinualSettings"),
        "model-free-risk": (RiskModelFreeAgent, ([P],), "risk", "RiskSettings"),
        "hybrid-risk": (RiskHybridAgent, ([P, P], P, P), "risk", "RiskSettings"),
        "authors": (CodeFGHHAgent, (P,), "settings", "CodeAgentSettings"),
    }


@pytest.mark.parametrize("case", list(_agents()))
def test_agent_settings_of_another_class_are_refused(case):
    """T39-B02: None, 'x', 5 or another class's settings were stored, then an AttributeError at the first episode that read
    them (RiskHybridAgent's after 40 episodes); refused by the constructor, and by run_test when set after it."""
    cls, args, name, kind = _agents()[case]
    for bad in (None, "x", 5, HybridSettings() if kind != "HybridSettings" else ContinualSettings()):
        with pytest.raises(NeurohoverError, match=rf"^{name}=.* is not allowed: give a {kind} \({kind}\(\) for its defaults\)$"):
            cls(*args, **{name: bad})
    agent = cls(*args)
    setattr(agent, name, None)
    with pytest.raises(NeurohoverError, match=rf"^agent '.*': {name}=None is not allowed: give a {kind}"):
        _run(agent)


def test_agent_arguments_changed_after_construction_are_refused_as_the_constructor_refuses_them():
    """T39-B02: specialised = [], safe = [], generic = None, update = None and made_for = [] were a ValueError,
    IndexError, AttributeError or TypeError in the run; each is the constructor's refusal, before any episode."""
    cases = (
        (ModelFreeAgent([P]), "specialised", [], r"specialised has 0 policies, which is not allowed: give at least one"),
        (ModelFreeAgent([P]), "specialised", None, r"specialised=None is not allowed: give a list of at least one Policy"),
        (HybridAgent([P, P], P, P), "safe", [], r"safe has 0 policies, which is not allowed: give exactly 2"),
        (HybridAgent([P, P], P, P), "generic", None, r"generic=None is not allowed: give a Policy"),
        (ModelBasedAgent(P), "settings", None, r"settings=None is not allowed: give a ModelEvolution"),
    )
    for agent, name, value, message in cases:
        setattr(agent, name, value)
        with pytest.raises(NeurohoverError, match=rf"^agent '[a-z-]+': {message}"):
            _run(agent)
    agent = ModelFreeAgent([P])
    agent.update = None
    with pytest.raises(NeurohoverError, match=r"^agent 'model-free''s update=None is not allowed: run_test calls agent.update\(outcome\)"):
        _run(agent)
    agent = ModelFreeAgent([P])
    agent.made_for = []
    with pytest.raises(NeurohoverError, match=r"^agent 'model-free''s made_for=\[\] is not allowed: give None .* or the \(family name, sigma\)"):
        _run(agent)


def test_incremental_max_learning_episodes_is_a_whole_number_of_at_least_one():
    """T39-B03: -1, 0, 2.5, True and 10**30 were taken (the agent stopped learning after its first episode); refused as
    IncrementalSettings refuses them, by the constructor and when set after it; a hybrid's fallback set to None after
    construction flew without its safeguard, now refused."""
    out, wrong = "is out of range", "is not allowed"
    for bad, how in ((-1, out), (0, out), (10**30, out), (2.5, wrong), (True, wrong), (None, wrong)):
        with pytest.raises(NeurohoverError, match=rf"^max_learning_episodes=.* {how}: allowed an integer in 1..2\*\*63-1$"):
            IncrementalModelBasedAgent(P, max_learning_episodes=bad)
    assert IncrementalModelBasedAgent(P, max_learning_episodes=1).max_learning_episodes == 1
    agent = IncrementalModelBasedAgent(P)
    agent.max_learning_episodes = -1
    with pytest.raises(NeurohoverError, match=r"^agent 'incremental': max_learning_episodes=-1 is out of range"):
        _run(agent)
    hybrid = HybridAgent([P, P], P, P)
    hybrid.fallback = None
    with pytest.raises(NeurohoverError, match=r"^agent 'hybrid': fallback=None is not allowed: give a Policy"):
        _run(hybrid)


def test_an_agents_name_is_checked_as_a_choices_label():
    """T39-B04: HybridAgent(name=None / 5 / '' / '  ' / 'x\\ny') ran and wrote it into RunResult.agent; refused as a
    Choice's label is, and a name set after construction by run_test."""
    for bad in (None, 5, "", "  ", "x\ny"):
        with pytest.raises(NeurohoverError, match=r"^name=.* is not allowed: give a non-empty text \(one line, printable\) naming the agent"):
            HybridAgent([P, P], P, P, name=bad)
        with pytest.raises(NeurohoverError, match=r"^name=.* is not allowed"):
            RiskHybridAgent([P, P], P, P, name=bad)
    with pytest.raises(NeurohoverError, match=r"^Choice label='x\\ny' is not allowed: give a non-empty text \(one line, printable\)"):
        Choice(P, "x\ny")
    agent = ModelFreeAgent([P])
    agent.name = 5
    with pytest.raises(NeurohoverError, match=r"^agent name=5 is not allowed: give a non-empty text"):
        _run(agent)


def test_an_evolved_records_prototype_is_zero_or_baseline(tmp_path):
    """T39-B05: an evolved policy file's prototype 3 or 'zzz' was saved and loaded; evolve writes zero or baseline (its
    lineage's start), which load."""
    from neurohover.evolution import evolve

    champion = evolve(FAM.training_mdps()[0], topology="slp", budget=10, seed=0, n_steps=10).champion
    assert champion.metadata["prototype"] == "baseline"
    saved = nh.save_policy(champion, tmp_path / "ev.json")
    assert nh.load_policy(saved).metadata["prototype"] == "baseline"
    record = {k: v for k, v in json.loads(saved.read_text()).items() if k not in ("topology", "genome")}
    for bad in (3, "zzz", None, ""):
        with pytest.raises(NeurohoverError, match=rf"its prototype {bad!r} is not allowed: give where the run's lineage started, zero or baseline"):
            nh.save_policy(champion, tmp_path / "sp.json", **{**record, "prototype": bad})
        (tmp_path / "edited.json").write_text(json.dumps({**json.loads(saved.read_text()), "prototype": bad}))
        with pytest.raises(NeurohoverError, match="its prototype .* is not allowed"):
            nh.load_policy(tmp_path / "edited.json")
    assert nh.load_policy(nh.save_policy(nh.prototype("mlp", "zero"), tmp_path / "z.json")).metadata == {"prototype": "zero"}
