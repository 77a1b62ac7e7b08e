"""The test-run protocol and the on-line agents behave as the paper describes."""

from __future__ import annotations

import numpy as np
import pytest

from neurohover import NeurohoverError, Policy, baseline_policy, evaluate_jobs, get_task_family, prototype
from neurohover.agents import Agent, Choice, EpisodeOutcome, ModelFreeAgent, run_test

STEPS = 400


def _weak_policy() -> Policy:
    g = prototype("slp", "baseline").genome.copy()
    g[36] += 0.05  # a trimmed aileron bias: flies, but drifts
    return Policy("slp", g)


def test_model_free_tries_each_policy_once_then_keeps_the_best() -> None:
    family = get_task_family("ghh08")
    mdp = family.training_mdps()[0]
    policies = [_weak_policy(), baseline_policy(), prototype("slp", "zero")]
    result = run_test(ModelFreeAgent(policies), family, mdp, episodes=12, seed=3, n_steps=STEPS)
    assert result.policy[:3] == ["specialised:0", "specialised:1", "specialised:2"]
    assert result.crashed[2] and not result.crashed[:2].any()
    best = int(np.argmax(result.returns[:3]))
    assert set(result.policy[3:]) == {f"specialised:{best}"}
    # Batched flying of the final choice gives exactly what flying episode by episode gives.
    for e in (3, 11):
        ev = evaluate_jobs([policies[best]], mdp, [0], [0], [e], seed=3, n_steps=STEPS)
        assert ev.returns[0] == result.returns[e]
    assert result.score == pytest.approx(result.returns.sum())


class _Recorder(Agent):
    name = "recorder"

    def __init__(self) -> None:
        self.outcomes: list[EpisodeOutcome] = []

    def choose(self, episode: int) -> Choice:
        return Choice(baseline_policy(), "baseline", record=episode == 1)

    def update(self, outcome: EpisodeOutcome) -> None:
        self.outcomes.append(outcome)


def test_agent_sees_outcomes_and_requested_flight_data() -> None:
    family = get_task_family("ghh09")
    agent = _Recorder()
    result = run_test(agent, family, family.test_mdps()[0], episodes=3, seed=1, n_steps=STEPS)
    assert [o.episode for o in agent.outcomes] == [0, 1, 2]
    assert agent.outcomes[0].flight_data is None and agent.outcomes[2].flight_data is None
    fd = agent.outcomes[1].flight_data
    assert fd.n_transitions == STEPS and fd.observations[0].shape == (STEPS + 1, 12)
    assert [o.ret for o in agent.outcomes] == result.returns.tolist()
    assert (result.offline_seconds >= 0).all() and len(result.rows()) == 3


def test_run_rejects_bad_episode_counts() -> None:
    family = get_task_family("ghh08")
    with pytest.raises(NeurohoverError, match="episodes=0"):
        run_test(ModelFreeAgent([baseline_policy()]), family, family.zero(), episodes=0)
    with pytest.raises(NeurohoverError, match="at least one specialised policy"):
        ModelFreeAgent([])
