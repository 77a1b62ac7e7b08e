"""An agent that keeps learning: refits its model as flight data arrive, and re-evolves when the model stops predicting.

The paper's incremental agent learns until one policy meets its model's prediction and then keeps
it for the rest of the run, which is right when the MDP stays fixed. Under drifting dynamics
(:mod:`neurohover.tasks.drift`) the kept policy's model goes stale. This agent records every
episode and keeps a sliding window of the most recent episodes' flight data, which its LR model
is refitted on whenever it learns (lazily: the model a refit after every episode would give at that
moment). It watches the one-step prediction error of the model its policy was evolved on, on
each new episode. When that error exceeds ``threshold`` times the error the model had on its own
data, for ``patience`` episodes in a row, or the helicopter crashes, it learns again as the
incremental agent does: it evolves on the newest model and flies the result, until a policy meets
its prediction or ``max_learning_episodes`` episodes pass. It flies with the generic policy as
the safeguard's fallback (``safeguard``).

The settings, their defaults and meaning: :class:`ContinualSettings` (``neurohover settings continual``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import NeurohoverError, brief, finite_real, real_number, whole_in
from ..evaluate import DangerousState
from ..flightdata import FlightData
from ..models.model import LearnedModel
from ..models.transitions import one_step_error
from ..policies import Policy
from ..tasks import TaskFamily
from .model_based import ModelEvolution, enough_to_learn, evolve_on_model
from .protocol import Agent, Choice, EpisodeOutcome, check_agent_policy, check_agent_settings
from .spec import AgentOptions, AgentPolicies, AgentSettings, AgentSpec


@dataclass(frozen=True)
class ContinualSettings(AgentSettings):
    """The continual agent's settings (a test-runs group's ``settings`` table).

    Attributes
    ----------
    window : int
        The most recent episodes a model is fitted on.
    threshold : float
        Re-learn once an episode's one-step error exceeds this times the model's own (> 1).
    patience : int
        ... in this many consecutive episodes (a crash re-learns at once).
    max_learning_episodes : int
        Episodes of one learning phase, then the phase's best policy is kept.
    safeguard : bool
        Fly with the generic policy as the safeguard's fallback.
    cooldown : int
        After a phase, changes (and crashes) do not start another for this many episodes, doubled after
        each phase in a row that ended without meeting its prediction (0: re-learn at once; it bounds the
        model evolutions of a run where every policy crashes).
    safeguard_after : int
        Control steps at the start of each episode before the safeguard's test applies (0: from the
        first, the authors' test; a learned policy's start-up correction can trip it in episodes it flies well).
    """

    window: int = 5
    threshold: float = 2.0
    patience: int = 2
    max_learning_episodes: int = 10
    safeguard: bool = True
    cooldown: int = 0
    safeguard_after: int = 0

    def __post_init__(self) -> None:
        # T24-11: 1.5 or True "is not allowed" (a type), 0 "is out of range" (both said out of range); no bound but int64's
        for name, low, high, text in (
            ("window", 1, 2**63 - 1, "2**63-1"),
            ("patience", 1, 2**63 - 1, "2**63-1"),
            ("max_learning_episodes", 1, 2**63 - 1, "2**63-1"),
            ("cooldown", 0, 10**6, "1000000 (episodes)"),
            ("safeguard_after", 0, 10**6, "1000000 (control steps)"),
        ):
            # stored as the Python int whole_in returns: the settings are stored as JSON (a NumPy integer is no JSON
            # number), and np.int64(10), which every other integer argument takes, was refused (T33-B12)
            object.__setattr__(self, name, whole_in(getattr(self, name), f"continual {name}", low, high, text))
        t = self.threshold
        if not real_number(t) or not finite_real(t) or t <= 1:
            raise NeurohoverError(f"continual threshold={brief(t)} is out of range: allowed a number > 1 (a ratio of one-step errors)")
        if not isinstance(self.safeguard, bool):
            raise NeurohoverError(f"continual safeguard={brief(self.safeguard)} is not allowed: true or false")

    def check_episode_steps(self, n_steps: int) -> None:
        """``safeguard_after`` at or past the episode length: the safeguard would never test (twelfth trial, S3)."""
        if self.safeguard and self.safeguard_after >= n_steps:
            raise NeurohoverError(
                f"continual safeguard_after={self.safeguard_after} is not below the episode's {n_steps} control steps (--episode-steps, "
                f"n_steps): the safeguard would never test; give safeguard_after below {n_steps}, or safeguard=false"
            )

    @classmethod
    def unused(cls, agent: str, given: dict) -> str | None:
        """``safeguard_after`` beside ``safeguard = false``: it would be ignored (seventh trial)."""
        if given.get("safeguard", cls.safeguard) is False and given.get("safeguard_after", cls.safeguard_after) != cls.safeguard_after:
            return "safeguard_after applies with safeguard = true only (without the safeguard there is no test to delay)"
        return None

    def to_dict(self) -> dict:
        d = super().to_dict()
        if d["safeguard_after"] == 0:  # added later: left out at its default, so configs written before keep their hash
            del d["safeguard_after"]
        return d


class ContinualAgent(Agent):
    """Learn as the incremental agent, then keep refitting and watching the model; re-learn when it stops predicting."""

    name = "continual"

    def __init__(self, generic: Policy, evolution: ModelEvolution = ModelEvolution(), settings: ContinualSettings = ContinualSettings()) -> None:
        self.generic, self.evolution, self.settings = generic, evolution, settings
        self.check_arguments()
        self._reset(np.random.default_rng(0))

    def check_arguments(self) -> None:
        check_agent_policy("generic", self.generic)
        check_agent_settings("evolution", self.evolution, ModelEvolution)
        check_agent_settings("settings", self.settings, ContinualSettings)

    def _reset(self, rng: np.random.Generator) -> None:
        self._rng = rng
        self._dangerous = DangerousState(arm_after=self.settings.safeguard_after)  # of the settings at the run's start
        self.window: list[tuple[np.ndarray, np.ndarray]] = []  # (observations, actions) of the recent episodes
        self.policy, self.label = self.generic, "generic"
        self.learning = True  # in a learning phase (else flying a kept policy and watching its model)
        self.phase_start = 0
        self.predicted: float | None = None
        self.policy_model: LearnedModel | None = None  # the model the flying policy was evolved on, as fitted (None: the generic)
        self.reference_error: float | None = None  # that model's one-step error on its own data
        self.phase_best = self._candidate(-np.inf)
        self.strikes = 0
        self.models = 0
        self.relearned_at: list[int] = []  # episodes after which a change was detected
        self.quiet_until = -1  # no new phase before this episode (the cooldown)
        self.failed_phases = 0  # phases in a row that ended without meeting their prediction

    def start(self, family: TaskFamily, rng: np.random.Generator) -> None:
        self._reset(rng)

    def choose(self, episode: int) -> Choice:
        fallback = self.generic if self.settings.safeguard and self.policy is not self.generic else None
        dangerous = self._dangerous if fallback is not None else DangerousState()  # a rule without a fallback is refused (T34-B07)
        return Choice(self.policy, self.label, fallback=fallback, dangerous=dangerous, record=True)

    def _candidate(self, ret: float) -> tuple:
        """The flying policy with its return, label, model and the model's own error (a phase's best so far)."""
        return (ret, self.policy, self.label, self.policy_model, self.reference_error)

    def _data(self) -> FlightData:
        return FlightData(tuple(o for o, _ in self.window), tuple(a for _, a in self.window))

    def _evolve(self) -> None:
        """Refit on the window and evolve a policy on the model (the next episode flies it)."""
        data = self._data()
        if not enough_to_learn(data, self.evolution.wind_model):
            return
        fitted = self.evolution.fit(data)  # watched by its one-step errors, flown in the evolution's substeps
        self.models += 1
        self.policy_model = fitted
        self.reference_error = float(one_step_error(fitted, data))
        model = fitted.flown_mdp(self.evolution.model_substeps)
        self.policy, self.predicted = evolve_on_model(model, self.generic, self.evolution, int(self._rng.integers(2**62)))
        self.label = f"model:{self.models}"

    def update(self, outcome: EpisodeOutcome) -> None:
        fd = outcome.flight_data
        if fd is not None:
            self.window.append((fd.observations[-1], fd.actions[-1]))
            del self.window[: -self.settings.window]
        if self.learning:
            self._learn(outcome)
        else:
            self._watch(outcome)

    def _learn(self, outcome: EpisodeOutcome) -> None:
        if outcome.ret > self.phase_best[0]:
            self.phase_best = self._candidate(outcome.ret)
        met = self.predicted is not None and not outcome.crashed and outcome.ret >= self.predicted
        if met or outcome.episode + 1 - self.phase_start >= self.settings.max_learning_episodes:
            if not met:  # the phase's best policy, watched against the model it was evolved on
                _, self.policy, self.label, self.policy_model, self.reference_error = self.phase_best
            self.learning, self.strikes = False, 0
            self.failed_phases = 0 if met else self.failed_phases + 1
            self.quiet_until = outcome.episode + self.settings.cooldown * 2**self.failed_phases
            return
        self._evolve()

    def _watch(self, outcome: EpisodeOutcome) -> None:
        stale = outcome.crashed
        if not stale and self.policy_model is not None and self.reference_error and outcome.flight_data is not None:
            latest = FlightData((outcome.flight_data.observations[-1],), (outcome.flight_data.actions[-1],))
            if enough_to_learn(latest, self.evolution.wind_model):
                error = float(one_step_error(self.policy_model, latest))
                self.strikes = self.strikes + 1 if error > self.settings.threshold * self.reference_error else 0
                stale = self.strikes >= self.settings.patience
        if stale and outcome.episode < self.quiet_until:  # cooling down: fly on (the safeguard still acts)
            stale, self.strikes = False, 0
        if stale:  # the dynamics moved away from the model: learn again from the recent episodes
            self.relearned_at.append(outcome.episode)
            self.learning, self.phase_start, self.strikes = True, outcome.episode + 1, 0
            self.phase_best, self.predicted = self._candidate(-np.inf), None
            self.window = self.window[-self.settings.patience :]  # keep the episodes that showed the change
            self._evolve()


def _continual(policies: AgentPolicies, options: AgentOptions) -> Agent:
    generic = check_agent_policy("generic", policies.generic)  # not an assert: a bare AssertionError (T47-B01)
    return ContinualAgent(generic, options.evolution or ModelEvolution(), options.settings or ContinualSettings())


AGENT_SPECS = (
    AgentSpec(
        "continual",
        "any",
        frozenset({"generic"}),
        _continual,
        generic_kind="race",
        settings=ContinualSettings,
        learns_models=True,
        summary="learn as incremental, then refit the model on every episode and re-learn when its one-step error grows",
    ),
)
