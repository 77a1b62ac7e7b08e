"""The on-line test-run protocol (docs/model.md, On-line agents) and the interface every agent implements.

A test run flies N episodes on one MDP the agent does not know; its score is the cumulative
return of the whole run, so every crash counts. Before each episode the agent chooses the policy
(and optionally a safeguard fallback); after it, the agent sees the outcome (with flight data if it
asked for it) and may compute off-line, which is timed and recorded.

Writing an agent
----------------
Subclass :class:`Agent` and implement ``choose`` and ``update``::

    class AlwaysBaseline(Agent):
        name = "always-baseline"
        def choose(self, episode):
            return Choice(baseline_policy(), "baseline", final=True)
        def update(self, outcome):
            pass

``final=True`` promises the agent will choose the same policy for every remaining episode, which
lets the harness fly the rest of the run in one parallel batch (same results, far faster).
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from ..errors import NeurohoverError
from ..evaluate import DangerousState, PolicyTable, check_episode_count, evaluate_jobs
from ..evolution.seeding import check_seed
from ..flightdata import FlightData
from ..policies import Policy
from ..sim.constants import EPISODE_STEPS
from ..tasks import MDP, TaskFamily
from .spec import AgentSettings

REPEAT_CHUNK = 64  # most episodes per kernel call for a repeated choice


@dataclass(frozen=True)
class Choice:
    """What the agent flies next.

    Attributes
    ----------
    policy : Policy
    label : str
        Name of the policy in the run's records (e.g. ``"specialised:3"``, ``"model:2"``).
    fallback : Policy or None
        Safeguard fallback: on a dangerous state it flies the rest of the episode.
    dangerous : DangerousState
        What counts as a dangerous state (default: the authors' test, docs/model.md, Safeguard).
    record : bool
        Whether the agent wants this episode's flight data.
    final : bool
        The agent keeps this choice for the rest of the run.
    repeat : bool
        The agent keeps this choice until an episode in which the safeguard fires or the
        helicopter crashes. The harness then flies several episodes per kernel call and reports
        them to ``update`` in order, up to and including that episode (same results, faster).
    """

    policy: Policy
    label: str
    fallback: Policy | None = None
    dangerous: DangerousState = DangerousState()
    record: bool = False
    final: bool = False
    repeat: bool = False


@dataclass(frozen=True)
class EpisodeOutcome:
    """What the agent learns after an episode."""

    episode: int
    ret: float
    crashed: bool
    steps: int
    safeguard_step: int  # control step at which the fallback took over, or -1
    flight_data: FlightData | None


class Agent:
    """Base class of on-line agents. ``start`` is called once per test run, before episode 0."""

    name: str = "agent"
    #: The task family (name, sigma) :func:`~neurohover.agents.registry.make_agent` made it for, its policies that
    #: family's; :func:`run_test` refuses another (None: an agent built by hand, run on any family).
    made_for: tuple[str, float | None] | None = None

    def start(self, family: TaskFamily, rng: np.random.Generator) -> None:
        """Prepare for a new run on an unknown MDP of ``family`` (reset any per-run state)."""

    def choose(self, episode: int) -> Choice:  # pragma: no cover - abstract
        raise NotImplementedError

    def update(self, outcome: EpisodeOutcome) -> None:  # pragma: no cover - abstract
        raise NotImplementedError


@dataclass
class RunResult:
    """Per-episode records of one test run; ``score`` is the cumulative return."""

    agent: str
    mdp: MDP
    returns: np.ndarray
    crashed: np.ndarray
    steps: np.ndarray
    policy: list[str]
    safeguard_fired: np.ndarray
    offline_seconds: np.ndarray = field(compare=False)  # wall-clock, like seconds: not part of ==
    seconds: float = field(default=0.0, compare=False)
    extra: dict = field(default_factory=dict)

    @property
    def score(self) -> float:
        return float(self.returns.sum())

    @property
    def cumulative(self) -> np.ndarray:
        return np.cumsum(self.returns)

    def rows(self) -> list[dict]:
        """One dict per episode (for CSV / JSON export)."""
        return [
            {
                "episode": e,
                "return": float(self.returns[e]),
                "crashed": bool(self.crashed[e]),
                "steps": int(self.steps[e]),
                "policy": self.policy[e],
                "safeguard_fired": bool(self.safeguard_fired[e]),
                "offline_seconds": float(self.offline_seconds[e]),
            }
            for e in range(self.returns.size)
        ]


def after_learning_start(policy_labels: Sequence[str]) -> int:
    """First episode from which the policy no longer changes (a run's ``policy`` labels)."""
    start = len(policy_labels) - 1
    while start > 0 and policy_labels[start - 1] == policy_labels[-1]:
        start -= 1
    return start


def _family_label(name: str, sigma: float | None) -> str:
    return name if sigma is None else f"{name} (sigma {sigma:g})"


def _check_run(agent, family, mdp, episodes, seed) -> int:
    """:func:`run_test`'s arguments checked (NeurohoverError naming the bad one); returns the seed."""
    if not isinstance(agent, Agent):
        raise NeurohoverError(f"agent={agent!r:.80} is not allowed: give an Agent (neurohover.agents.registry.make_agent(name, family))")
    if not isinstance(family, TaskFamily):
        raise NeurohoverError(f"family={family!r:.80} is not allowed: give a TaskFamily (neurohover.get_task_family(name))")
    if not isinstance(mdp, MDP):
        raise NeurohoverError(f"mdp={mdp!r:.80} is not allowed: give an MDP (family.mdp('test:3'), for example)")
    made = agent.made_for
    if made is not None and made != (family.name, family.sigma):  # GHH-08's policies flew FGHH without a word (tenth trial)
        raise NeurohoverError(
            f"agent {agent.name!r} was made for {_family_label(*made)}, but the run's family is {_family_label(family.name, family.sigma)}: "
            f"make the agent for it (make_agent(name, family))"
        )
    if mdp.family != family.name:  # the agent prepares for its family (its policies, safe pairs): another family's MDP is a mix-up
        raise NeurohoverError(f"mdp {mdp.label!r} is a {mdp.family} MDP, but the run's family is {family.name}: give an MDP of {family.name}")
    if isinstance(episodes, bool) or not isinstance(episodes, (int, np.integer)) or episodes < 1:  # True was one episode
        raise NeurohoverError(f"episodes={episodes!r} is out of range: allowed an integer >= 1")
    check_episode_count(int(episodes), f"episodes={episodes}")
    mdp.drift.check_run(int(episodes))
    return check_seed(seed)


def run_test(
    agent: Agent,
    family: TaskFamily,
    mdp: MDP,
    *,
    episodes: int = 1000,
    seed: int = 0,
    n_steps: int = EPISODE_STEPS,
    threads: int | None = None,
    device: str = "cpu",
) -> RunResult:
    """Fly one test run of ``episodes`` episodes of ``agent`` on ``mdp``.

    Episode e's gusts come from stream (seed, e), so two agents run with the same seed meet the
    same noise. The agent's own randomness derives from ``seed`` as well, and so does the drift of
    an MDP with drifting dynamics (``mdp.drift``: episode e flies its row e, the agent unaware). ``device``: where the
    episodes in the MDP fly (the agent's own evolutions on models follow its ``ModelEvolution``).
    """
    seed = _check_run(agent, family, mdp, episodes, seed)
    settings = getattr(agent, "settings", None)
    if isinstance(settings, AgentSettings) and isinstance(n_steps, (int, np.integer)) and not isinstance(n_steps, bool):
        settings.check_episode_steps(int(n_steps))  # settings that cannot act in episodes this long (twelfth trial, S3)
    start_time = time.perf_counter()
    agent.start(family, np.random.default_rng(np.random.SeedSequence([seed, 0xA6E27])))
    returns = np.zeros(episodes)
    crashed = np.zeros(episodes, dtype=bool)
    steps = np.zeros(episodes, dtype=np.int64)
    fired = np.zeros(episodes, dtype=bool)
    offline = np.zeros(episodes)
    labels: list[str] = [""] * episodes
    # Drifting dynamics (neurohover.tasks.drift): episode e flies drifted row e; else every episode flies the MDP.
    drifted = None if mdp.drift.none else mdp.drift.rows(mdp.row(), episodes, seed)

    def mdps_of(first: int, n: int):
        """The MDP rows and per-job row indices of episodes first..first+n-1."""
        if drifted is None:
            return mdp, np.zeros(n, dtype=np.int64)
        return drifted[first : first + n], np.arange(n, dtype=np.int64)

    e = 0
    chunk = 1
    while e < episodes:
        choice = agent.choose(e)
        if choice.final:
            # The choice holds for the rest of the run: fly it in one parallel batch.
            rest = np.arange(e, episodes)
            zeros = np.zeros(rest.size, dtype=np.int64)
            table = PolicyTable.from_policies([choice.policy] + ([choice.fallback] if choice.fallback else []))
            rows, index = mdps_of(e, rest.size)
            ev = evaluate_jobs(
                table,
                rows,
                zeros,
                index,
                rest,
                seed=seed,
                n_steps=n_steps,
                threads=threads,
                device=device,
                fallback_index=np.full(rest.size, 1 if choice.fallback else -1),
                safeguard_limits=choice.dangerous.limits(),
            )
            returns[e:], crashed[e:], steps[e:] = ev.returns, ev.crashed, ev.steps
            fired[e:] = ev.safeguard_step >= 0
            labels[e:] = [choice.label] * rest.size
            break
        # A repeated choice flies ahead speculatively; the chunk doubles while no event cuts it short
        # and restarts at 1 after one, so frequent safeguard firings waste at most half the work.
        n = min(chunk, episodes - e) if choice.repeat and not choice.record else 1
        table = PolicyTable.from_policies([choice.policy] + ([choice.fallback] if choice.fallback else []))
        zeros = np.zeros(n, dtype=np.int64)
        rows, index = mdps_of(e, n)
        ev = evaluate_jobs(
            table,
            rows,
            zeros,
            index,
            np.arange(e, e + n),
            seed=seed,
            n_steps=n_steps,
            threads=threads,
            device=device,
            fallback_index=np.full(n, 1 if choice.fallback else -1),
            record=np.full(n, choice.record),
            safeguard_limits=choice.dangerous.limits(),
        )
        events = np.flatnonzero((ev.safeguard_step >= 0) | ev.crashed)
        n = int(events[0]) + 1 if events.size else n  # later episodes would have flown another choice
        chunk = 1 if events.size else min(2 * chunk, REPEAT_CHUNK)
        for i in range(n):
            returns[e], crashed[e], steps[e] = ev.returns[i], ev.crashed[i], ev.steps[i]
            fired[e] = ev.safeguard_step[i] >= 0
            labels[e] = choice.label
            t0 = time.perf_counter()
            agent.update(EpisodeOutcome(e, float(ev.returns[i]), bool(ev.crashed[i]), int(ev.steps[i]), int(ev.safeguard_step[i]), ev.flight_data))
            offline[e] = time.perf_counter() - t0
            e += 1
    return RunResult(agent.name, mdp, returns, crashed, steps, labels, fired, offline, time.perf_counter() - start_time)
