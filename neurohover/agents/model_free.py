"""The model-free agent that won the 2008 competition (docs/model.md, On-line agents; paper Section 3.3)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..policies import Policy
from ..tasks import TaskFamily
from .protocol import Agent, Choice, EpisodeOutcome, check_agent_policies
from .spec import AgentSpec


class ModelFreeAgent(Agent):
    """Fly each specialised policy once, then keep the one with the best return for the rest.

    Parameters
    ----------
    specialised : sequence of Policy
        One policy evolved off-line per training MDP.
    """

    name = "model-free"

    def __init__(self, specialised: Sequence[Policy]) -> None:
        self.specialised = specialised
        self.check_arguments()
        self.trial_returns = np.full(len(self.specialised), -np.inf)

    def check_arguments(self) -> None:
        check_agent_policies("specialised", self.specialised)
        self.specialised = list(self.specialised)

    def start(self, family: TaskFamily, rng: np.random.Generator) -> None:
        self.trial_returns = np.full(len(self.specialised), -np.inf)

    def choose(self, episode: int) -> Choice:
        if episode < len(self.specialised):
            return Choice(self.specialised[episode], f"specialised:{episode}")
        best = int(np.argmax(self.trial_returns))
        return Choice(self.specialised[best], f"specialised:{best}", final=True)

    def update(self, outcome: EpisodeOutcome) -> None:
        if outcome.episode < len(self.specialised):
            self.trial_returns[outcome.episode] = outcome.ret


AGENT_SPECS = (
    AgentSpec(
        "model-free",
        "specialised",
        frozenset({"specialised"}),
        lambda policies, options: ModelFreeAgent(policies.specialised),
        summary="fly each specialised policy once, keep the best (the 2008 winner)",
    ),
)
