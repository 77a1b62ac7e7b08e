"""Reference agents that do not learn: the competition's baseline policy and the task's generic policy."""

from __future__ import annotations

from ..policies import Policy, baseline_policy
from .protocol import Agent, Choice, EpisodeOutcome, check_agent_policy
from .spec import AgentOptions, AgentPolicies, AgentSpec


class BaselineAgent(Agent):
    """Flies the competition's baseline policy every episode (a reference, not a learner)."""

    name = "baseline"

    def choose(self, episode: int) -> Choice:
        return Choice(baseline_policy(), "baseline", final=True)

    def update(self, outcome: EpisodeOutcome) -> None:
        pass


class GenericAgent(Agent):
    """Flies the task's generic policy every episode (no on-line learning)."""

    name = "generic"

    def __init__(self, generic: Policy) -> None:
        self.generic = generic
        self.check_arguments()

    def check_arguments(self) -> None:
        check_agent_policy("generic", self.generic)

    def choose(self, episode: int) -> Choice:
        return Choice(self.generic, "generic", final=True)

    def update(self, outcome: EpisodeOutcome) -> None:
        pass


def _generic(policies: AgentPolicies, options: AgentOptions) -> Agent:
    generic = check_agent_policy("generic", policies.generic)  # not an assert: a bare AssertionError (T47-B01)
    return GenericAgent(generic)


AGENT_SPECS = (
    AgentSpec(
        "baseline",
        "any",
        frozenset(),
        lambda policies, options: BaselineAgent(),
        summary="the competition's baseline policy, every episode",
    ),
    AgentSpec(
        "generic",
        "any",
        frozenset({"generic"}),
        _generic,
        generic_kind="race",
        summary="the task's generic policy, every episode",
    ),
)
