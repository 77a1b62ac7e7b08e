"""The FGHH agent of the authors' code (docs/model.md, On-line agents; their FGHH ``mb_agent``).

It is not the paper's incremental loop. In the run's first episode it flies its generic policy
(no safeguard) and records it; an LR model is learned from that episode alone. After episodes
1, 2 and 3 it evolves a policy on the model and flies it in the next episode under the
``ratio-sum`` safeguard (:class:`~neurohover.evaluate.DangerousState`: the signed sum of the
observation's ratios to their limits above 0.15 hands the rest of the episode to the baseline
policy and charges the offending policy an error of 100,000). From episode 5 on it flies, every
episode and under the same safeguard, the policy with the lowest mean error so far among the
generic and the three evolved ones.

==========================  ===============================================================
the authors' code            here
==========================  ===============================================================
evolution on the model       ``eonn`` with 49 of 50 kept, 2,500 generations of one offspring,
                             tournaments of 5, from their ``model.net`` MLP: steady state with
                             the same settings (:data:`MODEL_EVOLUTION`), 2,550 model
                             episodes, from the baseline-equivalent MLP (their ``model.net``
                             is not ours to ship)
a candidate's error          their ``end()`` appends the episode's last reward only (an
                             oversight); here the episode's error, ``-return``
a safeguard firing           the offending policy's entry for that episode is 100,000 (the
                             episode's own error goes to the fallback, which is never a
                             candidate)
a generic that crashes       their LR then fits on a few steps; here the generic flies again
within 20 steps              (recorded) until the flight data hold 20 transitions
==========================  ===============================================================
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import NeurohoverError, brief, finite_real, whole_in
from ..evaluate import DangerousState
from ..evolution.steady_state import SteadyStateSettings
from ..flightdata import FlightData
from ..models.lr import D_U_CHOICES, DEFAULT_NOISE_ESTIMATE, ESTIMATORS, NOISE_ESTIMATES
from ..models.model import check_model_substeps
from ..models.wind import WIND_MODELS
from ..policies import Policy, baseline_policy, prototype
from ..sim.constants import EPISODE_STEPS
from ..tasks import MDP, TaskFamily
from .model_based import enough_to_learn, learn_model
from .protocol import Agent, Choice, EpisodeOutcome, check_agent_policy, check_agent_settings
from .spec import FGHH_GENERIC_KINDS, AgentOptions, AgentPolicies, AgentSpec

#: The authors' ``eonn`` settings on the model (their FGHH agent): 49 of 50 kept, one offspring a
#: generation by crossover of two tournament winners (then mutation with probability 0.75), the
#: initial copies mutated with frac 0.5 and std 0.5; no plateau stop (a fixed number of generations).
MODEL_EVOLUTION = SteadyStateSettings(
    pop_size=50,
    elite_size=49,
    crossover_prob=1.0,
    selection="tournament",
    tournament_size=5,
    init_mutate_frac=0.5,
    init_mutate_std=0.5,
    plateau_threshold=10**9,
)


@dataclass(frozen=True)
class CodeAgentSettings:
    """Settings of :class:`CodeFGHHAgent` (defaults: the authors' code).

    Attributes
    ----------
    evolutions : int
        Policies evolved on the model, one after each of the first ``evolutions`` episodes (3).
    model_budget : int
        Model episodes per evolution (2,550: 50 initial candidates and 2,500 generations).
    fired_error : float
        The error charged to a policy for an episode in which the safeguard fired (100,000).
    dangerous : DangerousState
        The safeguard's test (the ``ratio-sum`` rule at 0.15).
    n_steps : int
        Control steps of a model episode.
    estimator : {"ols", "gls"}
        The LR model's least squares (OLS, as the authors).
    wind_model : {"none", "constant", "sinusoid"}
        The LR model's wind (none, as the authors; FGHH has no wind).
    d_u, noise : str
        The LR model's u constant and noise estimate (:func:`neurohover.models.learn_lr`; ours by
        default, ``"discard"`` and ``"rms"`` as the authors' code). Its evolution on the model is
        always the authors' (:data:`MODEL_EVOLUTION`), whatever a run's ``model_policy`` says.
    model_substeps : {1, 10}
        The model's substeps per control step (1: the authors' published FGHH code flies its model as
        ``Helicopter(params, noise_std, 0.1)``, one 0.1 s step; the GHH agents' default is ten,
        :data:`neurohover.models.model.DEFAULT_MODEL_SUBSTEPS`; :meth:`neurohover.models.LearnedModel.mdp`).
    """

    evolutions: int = 3
    model_budget: int = 2550
    fired_error: float = 1e5
    dangerous: DangerousState = DangerousState("ratio-sum")
    n_steps: int = EPISODE_STEPS
    estimator: str = "ols"
    wind_model: str = "none"
    d_u: str = "keep"
    noise: str = DEFAULT_NOISE_ESTIMATE
    model_substeps: int = 1

    def __post_init__(self) -> None:
        check_model_substeps(self.model_substeps, "model_substeps")  # True == 1 was taken as 1 (eleventh trial)
        for name, low in (("evolutions", 1), ("model_budget", 50), ("n_steps", 1)):
            # T24-11: 1.5 or True "is not allowed"; stored as the Python int whole_in returns, np.int64 taken (T33-B12)
            object.__setattr__(self, name, whole_in(getattr(self, name), name, low, 2**63 - 1, "2**63-1"))
        if not (finite_real(self.fired_error) and self.fired_error >= 0):  # finite_real: NumPy's isfinite raised TypeError on 10**400
            raise NeurohoverError(f"fired_error={brief(self.fired_error)} is out of range: allowed a finite number >= 0")
        if not isinstance(self.dangerous, DangerousState):  # anything was taken, then an AttributeError after an episode (eleventh trial)
            raise NeurohoverError(f"dangerous={brief(self.dangerous)} is not allowed: give a DangerousState (neurohover.evaluate.DangerousState)")
        for name, allowed in (("estimator", ESTIMATORS), ("wind_model", WIND_MODELS), ("d_u", D_U_CHOICES), ("noise", NOISE_ESTIMATES)):
            value = getattr(self, name)
            if not isinstance(value, str) or value not in allowed:  # checked here, not first in the run's model learning
                raise NeurohoverError(f"{name}={brief(value)} is not allowed: choose one of {', '.join(allowed)}")


class CodeFGHHAgent(Agent):
    """The authors' FGHH agent (module docstring): the generic, three model policies, then the best."""

    name = "authors"

    def __init__(self, generic: Policy, settings: CodeAgentSettings = CodeAgentSettings()) -> None:
        self.generic = generic
        self.settings = settings
        self.fallback = baseline_policy()
        self.check_arguments()
        self._reset(np.random.default_rng(0))

    def check_arguments(self) -> None:
        check_agent_policy("generic", self.generic)
        check_agent_settings("settings", self.settings, CodeAgentSettings)
        check_agent_policy("fallback", self.fallback)

    def _reset(self, rng: np.random.Generator) -> None:
        self._rng = rng
        self.flight_data: FlightData | None = None
        self.model: MDP | None = None
        self.candidates: list[tuple[Policy, str]] = [(self.generic, "generic")]
        self.errors: dict[str, list[float]] = {"generic": []}
        self.next_trial = 1  # the evolved candidate flown next (1-based), until all are flown
        self.flying = "generic"

    def start(self, family: TaskFamily, rng: np.random.Generator) -> None:
        self._reset(rng)

    def _mean_error(self, label: str) -> float:
        e = self.errors[label]
        return float(np.mean(e)) if e else np.inf

    def best(self) -> tuple[Policy, str]:
        """The candidate with the lowest mean error so far (the first of equals)."""
        return min(self.candidates, key=lambda c: self._mean_error(c[1]))

    def choose(self, episode: int) -> Choice:
        s = self.settings
        if self.model is None:  # the generic gathers the flight data, without a safeguard
            self.flying = "generic"
            return Choice(self.generic, "generic", record=True)
        if self.next_trial <= len(self.candidates) - 1:
            policy, label = self.candidates[self.next_trial]
        else:
            policy, label = self.best()
        self.flying = label
        return Choice(policy, label, fallback=self.fallback, dangerous=s.dangerous)

    def update(self, outcome: EpisodeOutcome) -> None:
        s = self.settings
        fired = outcome.safeguard_step >= 0
        self.errors[self.flying].append(s.fired_error if fired else -outcome.ret)
        if self.model is None:
            assert outcome.flight_data is not None  # the generic's episodes are recorded
            self.flight_data = outcome.flight_data if self.flight_data is None else self.flight_data + outcome.flight_data
            if not enough_to_learn(self.flight_data, s.wind_model):
                return
            self.model = learn_model(self.flight_data, s.estimator, s.wind_model, d_u=s.d_u, noise=s.noise, substeps=s.model_substeps)
        elif self.flying != "generic" and self.next_trial <= len(self.candidates) - 1:
            self.next_trial += 1
        if len(self.candidates) - 1 < s.evolutions and self.next_trial == len(self.candidates):
            self._evolve()

    def _evolve(self) -> None:
        from ..evolution.evolve import evolve

        s = self.settings
        result = evolve(
            self.model,
            topology="mlp",
            prototype=prototype("mlp", "baseline"),
            budget=s.model_budget,
            settings=MODEL_EVOLUTION,
            seed=int(self._rng.integers(2**62)),
            n_steps=s.n_steps,
            threads=1,
        )
        label = f"model:{len(self.candidates)}"
        self.candidates.append((result.champion, label))
        self.errors[label] = []


def _build(name: str):
    def build(policies: AgentPolicies, options: AgentOptions) -> Agent:
        generic = check_agent_policy("generic", policies.generic)  # not an assert: a bare AssertionError (T47-B01)
        evo = options.evolution
        if evo is not None and evo.model_policy != "ours":  # ignored without a word: it evolves as the authors' code (T40-A03)
            raise NeurohoverError(
                f"model_policy={brief(evo.model_policy)} is not allowed for agent {name!r}: it evolves on the model as the authors' code "
                "does (MODEL_EVOLUTION), whatever model_policy says; leave model_policy out"
            )
        # A run's model budget (the configs' model_budget) applies here too: 2,550 is the authors'.
        settings = (
            CodeAgentSettings()
            if evo is None
            else CodeAgentSettings(
                model_budget=max(50, evo.budget),
                n_steps=evo.n_steps,
                estimator=evo.estimator,
                wind_model=evo.wind_model,
                d_u=evo.d_u,
                noise=evo.noise,
                model_substeps=evo.model_substeps,
            )
        )
        agent = CodeFGHHAgent(generic, settings)
        agent.name = name
        return agent

    return build


AGENT_SPECS = tuple(
    AgentSpec(
        f"authors-{kind}",
        "generics-by-kind",
        frozenset({"generic"}),
        _build(f"authors-{kind}"),
        generic_kind=kind,
        learns_models=True,
        idle_model_options=frozenset({"model_policy"}),  # its evolution on the model is always the authors' (T40-A03)
        summary=f"the authors' FGHH agent (generic, one-episode model, three model policies, the best) from the generic evolved {what}",
    )
    for kind, what in FGHH_GENERIC_KINDS
)
