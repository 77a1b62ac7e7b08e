"""The hybrid agent of GHH-09 with its safeguard (paper Sections 4.1-4.3; docs/model.md, On-line agents).

Where the paper's text and the authors' code differ, the code is the default (it produced the
paper's figures) and the text is an option:

| setting | default (authors' code) | option (paper's text) |
|---|---|---|
| dangerous state | tilted (qw < 0.99) and outside the 0.5 box | outside the box |
| a policy that needed the safeguard | charged an error of 1e6; the best remaining policy flies on (``"rerank"``) | replaced by a policy newly evolved on the model (``"evolve"``) |
| flight data of the model | the first trial episode that needed no safeguard (``"first-safe"``) | both trial episodes (``"both"``) |
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from ..errors import NeurohoverError, brief, unknown_keys
from ..evaluate import DangerousState
from ..flightdata import FlightData
from ..policies import Policy, baseline_policy
from ..tasks import MDP, TaskFamily
from .model_based import ModelEvolution, enough_to_learn, evolve_on_model
from .protocol import Agent, Choice, EpisodeOutcome, check_agent_policies, check_agent_policy, check_agent_settings, check_name_text
from .spec import AgentOptions, AgentPolicies, AgentSettings, AgentSpec

N_EVOLVED = 3
DISCARD_RETURN = -1e6  # the authors' code charges a policy that needed the safeguard an error of 1e6
REPLACEMENTS = ("rerank", "evolve")
MODEL_DATA = ("first-safe", "both")


@dataclass(frozen=True)
class HybridSettings(AgentSettings):
    """How the hybrid agent treats dangerous states (the hybrid agents' own settings; a test-run
    unit holds them as its ``hybrid`` table, from the config group's ``hybrid``).

    Parameters
    ----------
    replacement : {"rerank", "evolve"}
        What happens to a policy that needed the safeguard (or crashed under it). ``"rerank"`` (the
        authors' code): every candidate is scored by the mean over the episodes it started, each
        counting its return, or -1e6 when the safeguard fired (that episode's return goes to the
        fallback, which is never a candidate); after every episode the best-scoring candidate flies
        the next, ties to the earliest. So one firing after many good episodes barely moves a
        policy, a policy that fired in its only episode is ranked below every policy that has not,
        and nothing is re-evolved. ``"evolve"`` (the paper's text): the policy is discarded and a
        policy newly evolved on the model replaces it.
    model_from : {"first-safe", "both"}
        Which trial episodes the LR model learns from: the first of the two safe specialised
        policies' episodes in which the safeguard did not fire (both when it fired in each), as the
        authors' code did; or both episodes, as the paper's text says.
    dangerous : DangerousState
        The safeguard's dangerous-state test (default: the authors').
    """

    UNIT_KEY: ClassVar[str] = "hybrid"

    replacement: str = "rerank"
    model_from: str = "first-safe"
    dangerous: DangerousState = DangerousState()

    def __post_init__(self) -> None:
        if self.replacement not in REPLACEMENTS:
            raise NeurohoverError(f"unknown hybrid replacement {brief(self.replacement)}: allowed {', '.join(REPLACEMENTS)}")
        if self.model_from not in MODEL_DATA:
            raise NeurohoverError(f"unknown hybrid model_from {brief(self.model_from)}: allowed {', '.join(MODEL_DATA)}")
        if not isinstance(self.dangerous, DangerousState):  # anything was taken, then an AttributeError mid-run (eleventh trial)
            raise NeurohoverError(f"dangerous={brief(self.dangerous)} is not allowed: give a DangerousState (neurohover.evaluate.DangerousState)")

    def to_dict(self) -> dict:
        """Plain settings: replacement, model_from, rule, box, tilt (as experiment configs write them)."""
        d = self.dangerous
        return {"replacement": self.replacement, "model_from": self.model_from, "rule": d.rule, "box": d.box, "tilt": d.tilt}

    @classmethod
    def from_dict(cls, values: dict) -> HybridSettings:
        """Settings from a (partial) dict of :meth:`to_dict`'s keys; unknown keys are refused."""
        known = set(cls().to_dict())
        unknown = unknown_keys(values, known)
        if unknown:
            raise NeurohoverError(f"unknown hybrid setting(s) {unknown}: allowed {', '.join(sorted(known))}")
        v = {**cls().to_dict(), **values}
        return cls(v["replacement"], v["model_from"], DangerousState(v["rule"], v["box"], v["tilt"]))


class HybridAgent(Agent):
    """Fly two safe specialised policies, learn an LR model from their flight data, evolve three
    policies on it and fly each once; keep the best of the five for the rest of the run.

    Every episode flies under the safeguard: on a dangerous state the ``fallback`` policy (the
    generic policy, or the baseline, which the paper found safer) takes over for the rest of the
    episode. What then happens to the policy that needed it is ``hybrid.replacement``.
    """

    name = "hybrid"

    def __init__(
        self,
        safe: Sequence[Policy],
        generic: Policy,
        fallback: Policy,
        settings: ModelEvolution = ModelEvolution(),
        name: str = "hybrid",
        hybrid: HybridSettings = HybridSettings(),
    ) -> None:
        self.safe = safe
        self.generic = generic
        self.fallback = fallback
        self.settings = settings
        self.hybrid = hybrid
        self.name = name
        self.check_arguments()
        self._reset(np.random.default_rng(0))

    def check_arguments(self) -> None:
        check_agent_policies("safe", self.safe, exactly=2)
        self.safe = list(self.safe)
        check_agent_policy("generic", self.generic)
        check_agent_policy("fallback", self.fallback)  # None after construction flew without a safeguard (T39-B03)
        check_agent_settings("settings", self.settings, ModelEvolution)
        check_agent_settings("hybrid", self.hybrid, HybridSettings)
        check_name_text("name", self.name, "the agent in the run's records")  # None, 5 and '' were taken (T39-B04)

    def _reset(self, rng: np.random.Generator) -> None:
        self._rng = rng
        self.model: MDP | None = None
        self.candidates: list[tuple[Policy, str]] = [(p, f"safe:{i}") for i, p in enumerate(self.safe)]
        self.trial_returns: list[float] = []
        self.trial_fired: list[bool] = []  # the safeguard fired (or the helicopter crashed) in that trial
        self.trial_data: list[tuple[FlightData, bool]] = []  # (flight data, safeguard fired)
        self.trial_values: list[float] = []  # each trial's return, or DISCARD_RETURN if the safeguard fired
        self.values: list[list[float]] = []  # "rerank": per candidate, the values of the episodes it started
        self.fallback_returns: list[float] = []  # "rerank": returns of the episodes the fallback finished
        self.current: tuple[Policy, str] | None = None
        self.replacements = 0  # "evolve": policies evolved to replace one that needed the safeguard
        self.discarded = 0  # "rerank": policies charged DISCARD_RETURN

    def start(self, family: TaskFamily, rng: np.random.Generator) -> None:
        self._reset(rng)

    def _evolve(self, label: str) -> tuple[Policy, str]:
        assert self.model is not None
        policy, _ = evolve_on_model(self.model, self.generic, self.settings, int(self._rng.integers(2**62)))
        return policy, label

    def choose(self, episode: int) -> Choice:
        d = self.hybrid.dangerous
        if self.current is None:
            policy, label = self.candidates[len(self.trial_returns)]
            return Choice(policy, label, fallback=self.fallback, dangerous=d, record=len(self.trial_returns) < 2)
        # Re-ranking after every episode may change the choice after any episode: fly one at a time.
        repeat = self.hybrid.replacement != "rerank"
        return Choice(self.current[0], self.current[1], fallback=self.fallback, dangerous=d, repeat=repeat)

    def _model_data(self) -> FlightData:
        if self.hybrid.model_from == "first-safe":
            for data, fired in self.trial_data:
                if not fired:
                    return data
        data = self.trial_data[0][0]
        for more, _ in self.trial_data[1:]:
            data = data + more
        return data

    @property
    def scores(self) -> list[float]:
        """``"rerank"``: each candidate's score, the mean value of the episodes it started."""
        return [float(np.mean(v)) for v in self.values]

    def _rank(self) -> None:
        self.current = self.candidates[int(np.argmax(self.scores))]  # ties: the earliest, as Python's min

    def update(self, outcome: EpisodeOutcome) -> None:
        fired = outcome.safeguard_step >= 0
        dangerous = fired or outcome.crashed
        value = DISCARD_RETURN if fired else outcome.ret  # the authors' error of 1e6 for a firing
        rerank = self.hybrid.replacement == "rerank"
        if rerank and fired:
            self.fallback_returns.append(outcome.ret)
            self.discarded += 1
        if self.current is None:
            self.trial_returns.append(outcome.ret)
            self.trial_fired.append(dangerous)
            self.trial_values.append(value)
            if outcome.flight_data is not None:
                self.trial_data.append((outcome.flight_data, dangerous))
            if len(self.trial_returns) == 2:
                data = self._model_data()
                # Trials that crash within a few steps may not determine a model: then the two safe policies are all there is.
                if enough_to_learn(data, self.settings.wind_model):
                    self.model = self.settings.learn(data)
                    self.candidates += [self._evolve(f"model:{i}") for i in range(N_EVOLVED)]
            if len(self.trial_returns) < len(self.candidates):
                return
            if rerank:
                self.values = [[v] for v in self.trial_values]
                self._rank()
                return
            # "evolve": a policy that needed the safeguard is discarded
            finite = [-np.inf if f else r for f, r in zip(self.trial_fired, self.trial_returns)]
            best = int(np.argmax(finite))
            if np.isfinite(finite[best]) or self.model is None:
                self.current = self.candidates[best]
            else:  # every trial needed the safeguard: start with a fresh policy from the model
                self.replacements += 1
                self.current = self._evolve(f"replacement:{self.replacements}")
            return
        if rerank:
            self.values[[label for _, label in self.candidates].index(self.current[1])].append(value)
            self._rank()
            return
        if dangerous and self.model is not None:
            self.replacements += 1
            self.current = self._evolve(f"replacement:{self.replacements}")


def _hybrid(name: str, fallback: str):
    def build(policies: AgentPolicies, options: AgentOptions) -> Agent:
        generic = check_agent_policy("generic", policies.generic)  # not an assert: a bare AssertionError (T47-B01)
        backup = generic if fallback == "generic" else baseline_policy()
        return HybridAgent(policies.safe, generic, backup, options.evolution or ModelEvolution(), name=name, hybrid=options.settings or HybridSettings())

    return build


AGENT_SPECS = (
    AgentSpec(
        "hybrid",
        "specialised",
        frozenset({"generic", "safe"}),
        _hybrid("hybrid", "generic"),
        settings=HybridSettings,
        learns_models=True,
        summary="the safe specialised pair, then policies evolved on a model, under a safeguard (generic fallback)",
    ),
    AgentSpec(
        "hybrid-baseline",
        "specialised",
        frozenset({"generic", "safe"}),
        _hybrid("hybrid-baseline", "baseline"),
        settings=HybridSettings,
        learns_models=True,
        summary="the hybrid agent with the baseline policy as the safeguard's fallback",
    ),
)
