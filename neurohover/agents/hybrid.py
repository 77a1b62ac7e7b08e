"""The hybrid agent of GHH-09 with its safeguard (paper Sections 4.1-4.3; docs/model.md, On-line agents and Safeguard)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..errors import NeurohoverError
from ..flightdata import FlightData
from ..policies import Policy
from ..tasks import MDP, TaskFamily
from .model_based import ModelEvolution, evolve_on_model, learn_model
from .protocol import Agent, Choice, EpisodeOutcome

N_EVOLVED = 3


class HybridAgent(Agent):
    """Fly two safe specialised policies, learn an LR model from their flight data, evolve three
    policies on it and fly each once; keep the best of the five for the rest of the run.

    Every episode flies under the safeguard: on a dangerous state the ``fallback`` policy (the
    generic policy, or the baseline, which the paper found safer) takes over for the rest of the
    episode. A policy that induced a dangerous state is discarded: during the five trials it can no
    longer be chosen, and afterwards it is replaced by a policy newly evolved on the model.
    """

    name = "hybrid"

    def __init__(self, safe: Sequence[Policy], generic: Policy, fallback: Policy,
                 settings: ModelEvolution = ModelEvolution(), name: str = "hybrid") -> None:
        if len(safe) != 2:
            raise NeurohoverError(f"the hybrid agent needs exactly 2 safe specialised policies, got {len(safe)}")
        self.safe = list(safe)
        self.generic = generic
        self.fallback = fallback
        self.settings = settings
        self.name = name
        self._reset(np.random.default_rng(0))

    def _reset(self, rng: np.random.Generator) -> None:
        self._rng = rng
        self.flight_data: FlightData | None = None
        self.model: MDP | None = None
        self.candidates: list[tuple[Policy, str]] = [(p, f"safe:{i}") for i, p in enumerate(self.safe)]
        self.trial_returns: list[float] = []
        self.current: tuple[Policy, str] | None = None
        self.replacements = 0

    def start(self, family: TaskFamily, rng: np.random.Generator) -> None:
        self._reset(rng)

    def _evolve(self, label: str) -> tuple[Policy, str]:
        policy, _ = evolve_on_model(self.model, self.generic, self.settings, int(self._rng.integers(2**62)))
        return policy, label

    def choose(self, episode: int) -> Choice:
        if self.current is None:
            policy, label = self.candidates[len(self.trial_returns)]
            return Choice(policy, label, fallback=self.fallback, record=len(self.trial_returns) < 2)
        return Choice(self.current[0], self.current[1], fallback=self.fallback, repeat=True)

    def update(self, outcome: EpisodeOutcome) -> None:
        dangerous = outcome.safeguard_step >= 0 or outcome.crashed
        if self.current is None:
            # Trials: a policy that needed the safeguard is discarded.
            self.trial_returns.append(-np.inf if dangerous else outcome.ret)
            if outcome.flight_data is not None:
                self.flight_data = outcome.flight_data if self.flight_data is None else self.flight_data + outcome.flight_data
            if len(self.trial_returns) == 2:
                self.model = learn_model(self.flight_data)
                self.candidates += [self._evolve(f"model:{i}") for i in range(N_EVOLVED)]
            if len(self.trial_returns) == len(self.candidates):
                best = int(np.argmax(self.trial_returns))
                if np.isfinite(self.trial_returns[best]):
                    self.current = self.candidates[best]
                else:  # every trial needed the safeguard: start with a fresh policy from the model
                    self.replacements += 1
                    self.current = self._evolve(f"replacement:{self.replacements}")
            return
        if dangerous:
            self.replacements += 1
            self.current = self._evolve(f"replacement:{self.replacements}")
