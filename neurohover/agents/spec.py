"""What an agent is to the rest of neurohover: a name, the tasks it runs on, the policies it flies
and how to build it. Every agent module declares its agents in ``AGENT_SPECS``; the registry
(:mod:`neurohover.agents.registry`) collects them, and the CLI, the competitions and the
experiments read them from there.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

from ..policies import Policy

if TYPE_CHECKING:
    from ..tasks import TaskFamily
    from .hybrid import HybridSettings
    from .model_based import ModelEvolution
    from .protocol import Agent

#: The policies an agent can need: the generic policy, the specialised policies (one per training
#: MDP), and the safe pair of specialised policies (the paper's rule, :mod:`neurohover.policysets`).
POLICY_NEEDS = ("generic", "specialised", "safe")
#: FGHH's generic policies, by kind: how each was evolved (agents named ``<agent>-<kind>`` fly one).
FGHH_GENERIC_KINDS = (("zero", "on the zero setting"), ("fixed", "over G with fixed resampling"), ("race", "over G with selection races"))
#: Which task families an agent runs on, by what the families' policy sets hold: every family;
#: the families with specialised policies (one per training MDP: GHH-08, GHH-09, and any family
#: whose generic is not evolved over G); or the families whose generics are evolved over G, by kind (FGHH).
FAMILY_CONDITIONS = ("any", "specialised", "generics-by-kind")


@dataclass(frozen=True)
class AgentPolicies:
    """The policies one agent flies (those its spec ``needs``; the rest stay empty)."""

    generic: Policy | None = None
    specialised: tuple[Policy, ...] = ()
    safe: tuple[Policy, ...] = ()


@dataclass(frozen=True)
class AgentOptions:
    """Settings of the learning agents; None: the agent's own default.

    ``evolution``: how policies are evolved on learned models (``ModelEvolution``); ``hybrid``:
    the hybrid agents' safeguard and replacement rule (``HybridSettings``); ``max_learning_episodes``:
    when the incremental agent stops learning at the latest.
    """

    evolution: ModelEvolution | None = None
    hybrid: HybridSettings | None = None
    max_learning_episodes: int | None = None


@dataclass(frozen=True)
class AgentSpec:
    """One agent, as everything else sees it.

    Attributes
    ----------
    name : str
        What ``--agent`` and experiment configs call it.
    runs_on : {"any", "specialised", "generics-by-kind"}
        The task families it runs on (:data:`FAMILY_CONDITIONS`), a condition on the family rather
        than a list of names, so a new family gets every agent its policy set can serve.
    needs : frozenset of str
        Which of :data:`POLICY_NEEDS` it flies.
    build : callable
        ``build(policies, options) -> Agent``: a fresh agent from an :class:`AgentPolicies` and
        :class:`AgentOptions`.
    generic_kind : str or None
        On a family with generic policies by kind (FGHH: ``"zero"``, ``"fixed"``, ``"race"``),
        which one is this agent's generic policy.
    takes_hybrid : bool
        Whether it accepts hybrid settings (``AgentOptions.hybrid``).
    summary : str
        One line for help texts.
    """

    name: str
    runs_on: str
    needs: frozenset[str]
    build: Callable[[AgentPolicies, AgentOptions], Agent]
    generic_kind: str | None = None
    takes_hybrid: bool = False
    summary: str = ""

    def __post_init__(self) -> None:
        unknown = set(self.needs) - set(POLICY_NEEDS)
        if unknown:
            raise ValueError(f"agent {self.name!r}: unknown policy needs {sorted(unknown)}; allowed {POLICY_NEEDS}")
        if self.runs_on not in FAMILY_CONDITIONS:
            raise ValueError(f"agent {self.name!r}: runs_on={self.runs_on!r}; allowed {FAMILY_CONDITIONS}")
        if self.runs_on != "specialised" and "generic" in self.needs and self.generic_kind is None:
            raise ValueError(f"agent {self.name!r} flies a generic policy on families with generics by kind: name its generic_kind")

    def applies_to(self, family: TaskFamily) -> bool:
        """Whether the agent runs on ``family`` (its :attr:`runs_on` condition)."""
        by_kind = family.generic_over_distribution
        return self.runs_on == "any" or (self.runs_on == "generics-by-kind") == by_kind

    @property
    def tasks(self) -> tuple[str, ...]:
        """The registered task families it runs on, by name (for help texts)."""
        from ..tasks import TASK_NAMES, get_task_family

        return tuple(name for name in TASK_NAMES if self.applies_to(get_task_family(name)))
