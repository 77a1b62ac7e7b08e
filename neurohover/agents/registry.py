"""Agents by name, built from a task family's policy set (what ``neurohover compete --agent`` takes)."""

from __future__ import annotations

from collections.abc import Callable

from ..errors import NeurohoverError
from ..policies import baseline_policy
from ..policysets import PolicySet, load_policy_set
from ..tasks import TaskFamily
from .hybrid import HYBRID_AGENTS, HybridAgent, HybridSettings
from .model_based import IncrementalModelBasedAgent, ModelBasedAgent
from .model_free import ModelFreeAgent
from .protocol import Agent, Choice, EpisodeOutcome


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

    def __init__(self, policies: PolicySet) -> None:
        self.generic = policies.generic

    def choose(self, episode: int) -> Choice:
        return Choice(self.generic, "generic", final=True)

    def update(self, outcome: EpisodeOutcome) -> None:
        pass


def _incremental(generic_name: str | None) -> Callable[[PolicySet], Agent]:
    def make(ps: PolicySet) -> Agent:
        generic = ps.generic if generic_name is None else ps.generics[generic_name]
        agent = IncrementalModelBasedAgent(generic)
        agent.name = "incremental" if generic_name is None else f"incremental-{generic_name}"
        return agent
    return make


def _hybrid(fallback: str) -> Callable[..., Agent]:
    def make(ps: PolicySet, hybrid: HybridSettings = HybridSettings()) -> Agent:
        safe = [ps.specialised[i] for i in ps.safe]
        fb = ps.generic if fallback == "generic" else baseline_policy()
        return HybridAgent(safe, ps.generic, fb, name="hybrid" if fallback == "generic" else "hybrid-baseline",
                           hybrid=hybrid)
    return make


# name -> (tasks it applies to, factory from the policy set; None: needs no policy set)
AGENTS: dict[str, tuple[tuple[str, ...], Callable[..., Agent] | None]] = {
    "baseline": (("ghh08", "ghh09", "fghh"), None),
    "generic": (("ghh08", "ghh09", "fghh"), GenericAgent),
    "model-free": (("ghh08", "ghh09"), lambda ps: ModelFreeAgent(ps.specialised)),
    "model-based": (("ghh08", "ghh09", "fghh"), lambda ps: ModelBasedAgent(ps.generic)),
    "incremental": (("ghh08", "ghh09", "fghh"), _incremental(None)),
    "hybrid": (("ghh08", "ghh09"), _hybrid("generic")),
    "hybrid-baseline": (("ghh08", "ghh09"), _hybrid("baseline")),
    "incremental-zero": (("fghh",), _incremental("zero")),
    "incremental-fixed": (("fghh",), _incremental("fixed")),
    "incremental-race": (("fghh",), _incremental("race")),
}


def check_agent(name: str, task: str, policy_dir: str | None = None) -> None:
    """Refuse unknown agents, agents for another task, and missing policy sets, with clear messages."""
    if name not in AGENTS:
        raise NeurohoverError(f"unknown agent {name!r}: allowed {', '.join(AGENTS)}")
    tasks, factory = AGENTS[name]
    if task not in tasks:
        raise NeurohoverError(f"agent {name!r} does not apply to task {task!r}: it runs on {', '.join(tasks)}")
    if factory is not None:
        factory(load_policy_set(task, policy_dir))


def make_agent(name: str, family: TaskFamily, *, policy_dir: str | None = None,
               hybrid: HybridSettings = HybridSettings()) -> Agent:
    """A fresh agent called ``name`` for ``family`` (``hybrid``: the hybrid agents' safeguard settings)."""
    if name not in AGENTS:
        raise NeurohoverError(f"unknown agent {name!r}: allowed {', '.join(AGENTS)}")
    _, factory = AGENTS[name]
    if factory is None:
        return BaselineAgent()
    if name in HYBRID_AGENTS:
        return factory(load_policy_set(family.name, policy_dir), hybrid)
    return factory(load_policy_set(family.name, policy_dir))
