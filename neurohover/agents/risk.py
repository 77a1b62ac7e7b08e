"""Risk-sensitive variants of the model-free and hybrid agents (issue 22; paper Section 4.3: "competition
agents should also be risk sensitive").

A single crash (about -1e7) decides a competition, so the candidate best in expectation need not be
the one to fly for a whole run. These agents choose among their candidate policies by a
risk-sensitive score of each candidate's episodes instead of its mean:

=========  =====================================================================================
criterion  score of a candidate's episode values v_1..v_n
=========  =====================================================================================
mean       their mean (the paper's agents)
lcb        a lower confidence bound, ``mean - level * sd / sqrt(n)`` (sample sd; 0 for one episode)
worst      the worst of them
=========  =====================================================================================

``model-free-risk`` flies each specialised policy ``trials`` times (round robin) and keeps the best
by the score. ``hybrid-risk`` and ``hybrid-baseline-risk`` are the hybrid agents (authors'
re-ranking, generic or baseline fallback, their other settings at the defaults) ranking candidates
by the score; an episode in which the safeguard fired counts as the authors' -1e6, a near-crash.
Settings: a test-runs group's ``settings`` table (``criterion``, ``level``, ``trials``).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..errors import NeurohoverError, brief, finite_real, real_number, whole_in
from ..policies import Policy, baseline_policy
from .hybrid import HybridAgent
from .model_based import ModelEvolution
from .model_free import ModelFreeAgent
from .protocol import Agent, Choice, EpisodeOutcome, check_agent_policy, check_agent_settings
from .spec import AgentOptions, AgentPolicies, AgentSettings, AgentSpec

#: The most trials of each specialised policy: a run's episodes (1,000,000 at most) cannot hold more (10**13 was accepted).
MAX_TRIALS = 1_000_000

CRITERIA = ("mean", "lcb", "worst")


@dataclass(frozen=True)
class RiskSettings(AgentSettings):
    """How a risk-sensitive agent scores its candidates (the module docstring's table).

    Attributes
    ----------
    criterion : {"mean", "lcb", "worst"}
        A candidate's score from its episode values.
    level : float
        lcb's standard errors below the mean (>= 0).
    trials : int
        model-free-risk only: episodes per specialised policy before it settles (the hybrids ignore it).
    """

    criterion: str = "lcb"
    level: float = 1.0
    trials: int = 2

    def __post_init__(self) -> None:
        if self.criterion not in CRITERIA:
            raise NeurohoverError(f"risk criterion {brief(self.criterion)} is not allowed: choose one of {', '.join(CRITERIA)}")
        if not real_number(self.level):  # 'abc' was called "out of range" (eighth trial)
            raise NeurohoverError(f"risk level={brief(self.level)} is not a number: allowed a finite number >= 0 (standard errors below the mean)")
        if not finite_real(self.level) or self.level < 0:
            raise NeurohoverError(f"risk level={brief(self.level)} is out of range: allowed a finite number >= 0 (standard errors below the mean)")
        # T24-11: 1.5 or True "is not allowed"; stored as the Python int whole_in returns, np.int64 taken (T33-B12)
        object.__setattr__(self, "trials", whole_in(self.trials, "risk trials", 1, MAX_TRIALS, f"{MAX_TRIALS:,}"))

    def check_episodes(self, agent: str, episodes: int) -> None:
        """model-free-risk's trials of its specialised policies that fill the whole run: it would never settle, and its
        criterion and level would have no effect (trials=1000000 in 25 episodes ran as trials=3, T32-A07)."""
        if agent != "model-free-risk":
            return
        from ..tasks.base import N_TRAINING  # the specialised policies of a GHH policy set, one per training MDP

        trying = N_TRAINING * self.trials
        if trying < episodes:
            return
        fits = (episodes - 1) // N_TRAINING
        allowed = f"give trials at most {fits}, or more than {trying:,} episodes" if fits >= 1 else f"give more than {trying:,} episodes"
        raise NeurohoverError(
            f"risk trials={self.trials:,} cannot fit in a run of {episodes:,} episodes: model-free-risk flies each of its {N_TRAINING} "
            f"specialised policies trials times ({trying:,} episodes) before it settles on the best by its risk score, so it would "
            f"never settle and its criterion would have no effect; {allowed}"
        )

    @classmethod
    def unused(cls, agent: str, given: dict) -> str | None:
        """``trials`` beside a hybrid, ``level`` beside another criterion than lcb: each would be ignored (fifth trial)."""
        given = {k: v for k, v in given.items() if v != getattr(cls, k, None)}  # at its default: said nothing
        if "trials" in given and agent != "model-free-risk":
            return f"trials applies to model-free-risk only, not to {agent} (it scores its candidates from the model)"
        criterion = given.get("criterion", cls.criterion)
        if "level" in given and criterion != "lcb":
            return f"level applies to criterion lcb only, not to criterion {criterion!r}"
        return None

    def score(self, values: Sequence[float]) -> float:
        """The candidate's score from its episode values (higher is better)."""
        v = np.asarray(values, dtype=float)
        if v.size == 0:
            raise NeurohoverError("a candidate with no episode has no score")
        if self.criterion == "worst":
            return float(v.min())
        mean = float(v.mean())
        if self.criterion == "mean" or v.size == 1:
            return mean
        return mean - self.level * float(v.std(ddof=1)) / math.sqrt(v.size)


class RiskModelFreeAgent(ModelFreeAgent):
    """The model-free agent flying each specialised policy ``trials`` times, keeping the best by a risk score."""

    name = "model-free-risk"

    def __init__(self, specialised: Sequence[Policy], risk: RiskSettings = RiskSettings()) -> None:
        self.risk = risk  # before the constructor's check_arguments
        super().__init__(specialised)
        self.trials: list[list[float]] = [[] for _ in self.specialised]

    def check_arguments(self) -> None:
        super().check_arguments()
        check_agent_settings("risk", self.risk, RiskSettings)

    def start(self, family, rng: np.random.Generator) -> None:
        super().start(family, rng)
        self.trials = [[] for _ in self.specialised]

    def _trying(self, episode: int) -> bool:
        return episode < len(self.specialised) * self.risk.trials

    def choose(self, episode: int) -> Choice:
        n = len(self.specialised)
        if self._trying(episode):
            return Choice(self.specialised[episode % n], f"specialised:{episode % n}")
        best = int(np.argmax([self.risk.score(t) for t in self.trials]))  # ties: the earliest
        return Choice(self.specialised[best], f"specialised:{best}", final=True)

    def update(self, outcome: EpisodeOutcome) -> None:
        if self._trying(outcome.episode):
            self.trials[outcome.episode % len(self.specialised)].append(outcome.ret)


class RiskHybridAgent(HybridAgent):
    """The hybrid agent (authors' re-ranking) ranking its candidates by a risk score instead of the mean."""

    def __init__(self, safe, generic, fallback, settings: ModelEvolution = ModelEvolution(), name: str = "hybrid-risk", risk: RiskSettings = RiskSettings()):
        self.risk = risk  # before the constructor's check_arguments
        super().__init__(safe, generic, fallback, settings, name=name)

    def check_arguments(self) -> None:
        super().check_arguments()
        check_agent_settings("risk", self.risk, RiskSettings)

    @property
    def scores(self) -> list[float]:
        return [self.risk.score(v) for v in self.values]


def _hybrid_risk(name: str, fallback: str):
    def build(policies: AgentPolicies, options: AgentOptions) -> Agent:
        generic = check_agent_policy("generic", policies.generic)  # not an assert: a bare AssertionError (T47-B01)
        backup = generic if fallback == "generic" else baseline_policy()
        risk = options.settings or RiskSettings()
        return RiskHybridAgent(policies.safe, generic, backup, options.evolution or ModelEvolution(), name=name, risk=risk)

    return build


AGENT_SPECS = (
    AgentSpec(
        "model-free-risk",
        "specialised",
        frozenset({"specialised"}),
        lambda policies, options: RiskModelFreeAgent(policies.specialised, options.settings or RiskSettings()),
        settings=RiskSettings,
        summary="model-free, each specialised policy flown `trials` times, the best kept by a risk score (lcb or worst)",
    ),
    *(
        AgentSpec(
            name,
            "specialised",
            frozenset({"generic", "safe"}),
            _hybrid_risk(name, fallback),
            settings=RiskSettings,
            learns_models=True,
            summary=f"the hybrid agent ranking its candidates by a risk score ({fallback} fallback)",
        )
        for name, fallback in (("hybrid-risk", "generic"), ("hybrid-baseline-risk", "baseline"))
    ),
)
