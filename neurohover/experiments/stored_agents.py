"""The agents of a stored test-runs experiment that this process has not registered: a run-time agent
(``AGENTS[name] = AgentSpec(...)`` in the script that ran it) whose store ``neurohover results`` or ``report`` reads,
as every process reads it, registered or not. What its plan needs of the agent's spec is the policies it flies (``needs``
and, on a family of generics by kind, ``generic_kind``); they are read from what the store records, its units' params,
so that such a store's units are checked against its config, and counted, as a registered agent's are (its "unknown
agent" was taken for a policy directory gone: an edited seed or an unplanned unit was exported, and its report said
"1 of None units"; T60-B04, T60-B05)."""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass

from ..agents.registry import AGENTS
from ..agents.spec import POLICY_NEEDS
from ..errors import NeurohoverError
from .config import ExperimentConfig
from .settings import TestRunsSettings


class UnregisteredAgentError(NeurohoverError):
    """A stored experiment's plan needs an agent this process has not registered, and its store does not show what
    the plan needs of it (:meth:`StoredAgent.unplannable`): the store is not damaged, so its readers say so without
    calling it damaged."""


@dataclass(frozen=True)
class StoredAgent:
    """An agent this process has not registered, as its stored units show it: what :func:`~.plans.plan` reads of its
    :class:`~neurohover.agents.spec.AgentSpec`.

    Attributes
    ----------
    name : str
        The agent's name, as the config's group gives it.
    needs : frozenset of str
        The policies (of :data:`~neurohover.agents.spec.POLICY_NEEDS`) its stored runs fly: those most of them fly, so
        that a run edited to fly others is the one the plan check names.
    generic_kind : str or None
        Its generic policy's kind on a family of generics by kind (FGHH); None where it flies no generic, and until
        :func:`~.export.stored_plan` finds the kind whose plan gives its stored runs' generic.
    shown : bool
        Whether the store holds a run of it; False: what it flies is unknown (planned as nothing, which only a config
        that evolves its own policies cannot do: :meth:`unplannable`).
    """

    name: str
    needs: frozenset[str] = frozenset()
    generic_kind: str | None = None
    shown: bool = True

    def unplannable(self) -> str:
        """The refusal of a plan that needs what this agent flies where the store shows none of it."""
        return (
            f"agent {self.name!r} is not registered in this process, and the store holds no run of it that shows which policies it "
            "flies, on which the policy units its config evolves depend: read the store in a Python process that registers the "
            f"agent first (AGENTS[{self.name!r}] = AgentSpec(...), as the script that ran it did)"
        )


def agent_runs(units: list[dict], agent: str) -> list[dict]:
    """The stored test runs of ``agent`` (:meth:`~.store.Store.units`' dicts) whose params hold a policies table."""
    return [
        u
        for u in units
        if u["kind"] == "test_run" and isinstance(u["params"], dict) and u["params"].get("agent") == agent and isinstance(u["params"].get("policies"), dict)
    ]


def stored_agents(config: ExperimentConfig, units: list[dict]) -> dict[str, StoredAgent]:
    """Name -> :class:`StoredAgent` of each agent of ``config``'s groups that this process has not registered, read
    from its stored ``units`` (:meth:`~.store.Store.units`' dicts); empty for the other kinds of experiment. A name in
    the registry is read there, so a bad entry is refused by name where the plan reads it."""
    s = config.typed
    if not isinstance(s, TestRunsSettings):
        return {}
    out: dict[str, StoredAgent] = {}
    for agent in dict.fromkeys(g.agent for g in s.groups):
        if agent in AGENTS:
            continue
        flown = Counter(frozenset(u["params"]["policies"]).intersection(POLICY_NEEDS) for u in agent_runs(units, agent))
        out[agent] = StoredAgent(agent, flown.most_common(1)[0][0]) if flown else StoredAgent(agent, shown=False)
    return out
