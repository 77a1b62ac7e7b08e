"""Issue 37, trial 49 (T49-B02): an agent whose class defines no start kept its first run's state into the next.

The README's example agent kept the returns of its first two episodes in ``__init__``: flown a second time, it chose
its final policy from the first run's returns, and the second run scored another total than a fresh agent's, without
a word. Now such an agent is refused a second run when its attributes changed in the first, naming the attribute; one
that keeps nothing (the protocol docstring's AlwaysBaseline, the shipped baseline and generic agents) flies any number.
"""

from __future__ import annotations

import numpy as np
import pytest

from neurohover import NeurohoverError, get_task_family
from neurohover.agents.protocol import Agent, Choice, run_test
from neurohover.agents.registry import make_agent
from neurohover.policies import baseline_policy
from neurohover.policysets import load_policy_set

FAMILY = get_task_family("ghh08")


class KeepsReturns(Agent):
    """The README's example agent before the fix: per-run state set in __init__, no start."""

    name = "keeps-returns"

    def __init__(self, generic, other) -> None:
        self.candidates, self.returns = [generic, other], []

    def choose(self, episode):
        if episode < 2:
            return Choice(self.candidates[episode], f"candidate:{episode}")
        return Choice(self.candidates[max(range(2), key=self.returns.__getitem__)], "best", final=True)

    def update(self, outcome) -> None:
        if outcome.episode < 2:
            self.returns.append(outcome.ret)


class AlwaysBaseline(Agent):
    """The protocol docstring's agent: keeps nothing, defines no start."""

    name = "always-baseline"

    def choose(self, episode):
        return Choice(baseline_policy(), "baseline", final=True)

    def update(self, outcome) -> None:
        pass


def _run(agent, mdp: int = 0):
    return run_test(agent, FAMILY, FAMILY.test_mdps()[mdp], episodes=4, n_steps=50)


def test_b02_an_agent_without_start_that_kept_state_is_refused_a_second_run() -> None:
    policies = load_policy_set("ghh08")
    agent = KeepsReturns(policies.generic, policies.specialised[0])
    _run(agent)
    refused = r"agent 'keeps-returns' has flown a test run, and its attribute 'returns' changed in it, .* defines no start\(self, family, rng\)"
    with pytest.raises(NeurohoverError, match=refused):
        _run(agent, 1)
    assert len(agent.returns) == 2  # refused before the agent was called again


def test_b02_agents_that_keep_nothing_fly_again_as_fresh_ones() -> None:
    first, second = _run(AlwaysBaseline()), _run(reused := AlwaysBaseline())
    assert np.array_equal(first.returns, second.returns) and np.array_equal(_run(reused).returns, first.returns)
    for name in ("baseline", "generic"):  # the shipped reference agents define no start either
        agent = make_agent(name, FAMILY)
        assert np.array_equal(_run(agent, 1).returns, _run(agent, 1).returns)


def test_b02_an_agent_that_resets_in_start_flies_again() -> None:
    class ResetsInStart(KeepsReturns):
        def start(self, family, rng) -> None:
            self.returns = []

    policies = load_policy_set("ghh08")
    agent = ResetsInStart(policies.generic, policies.specialised[0])
    _run(agent)
    again = _run(agent, 1)
    assert np.array_equal(again.returns, _run(ResetsInStart(policies.generic, policies.specialised[0]), 1).returns)
