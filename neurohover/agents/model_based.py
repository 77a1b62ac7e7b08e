"""Model-based agents: learn an LR model from flight data, evolve a policy on it (docs/model.md, On-line agents).

The evolution on a learned model starts from the generic policy (the prototype) and uses the
steady-state method with an evaluation budget; every episode flown on the model is simulated, so
this costs computation but no samples of the real MDP.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from ..errors import NeurohoverError, whole_in
from ..evaluate import evaluate
from ..flightdata import FlightData
from ..models.lr import DEFAULT_NOISE_ESTIMATE, lr_determined
from ..models.model import DEFAULT_MODEL_SUBSTEPS, LearnedModel
from ..policies import Policy, baseline_policy
from ..sim.constants import EPISODE_STEPS, MAX_EPISODE_STEPS
from ..tasks import MDP, TaskFamily
from .protocol import Agent, Choice, EpisodeOutcome, check_agent_policy, check_agent_settings
from .spec import FGHH_GENERIC_KINDS, AgentOptions, AgentPolicies, AgentSettings, AgentSpec

#: How a policy is evolved on a learned model: ``"ours"``, steady state from the generic policy with
#: the model budget; ``"authors"``, the authors' GHH-09 agents: an SLP from the baseline by their
#: ``eonn`` (:mod:`neurohover.evolution.eonn`, 50 genomes, 49 kept, one offspring in each of ``authors_generations`` generations).
MODEL_POLICIES = ("ours", "authors")


@dataclass(frozen=True)
class ModelEvolution:
    """How an agent learns a model and evolves a policy on it.

    Parameters
    ----------
    budget : int
        Episodes on the model per evolution (steady state, paper Table 6 otherwise).
    predict_episodes : int
        Model episodes to predict the evolved policy's return.
    n_steps : int
        Control steps of each model episode.
    estimator : {"ols", "gls"}
        The least-squares estimator of the LR model (:func:`learn_model`): ``"ols"`` (default, the paper's) or ``"gls"``.
    device : {"cpu", "cuda"}
        Where the model episodes fly (docs/gpu.md).
    wind_model : {"none", "constant", "sinusoid"}
        The wind of the LR models the agent learns: ``"none"`` (default, the paper's wind-blind model),
        ``"constant"`` or ``"sinusoid"`` (:mod:`neurohover.models.wind`; docs/model.md, Wind-aware models).
    d_u : {"keep", "discard"}
        Keep the fitted u constant as the model's D_u (default) or discard it, as the authors' code did
        (:func:`neurohover.models.learn_lr`).
    noise : {"rms", "innovations"}
        The model's gust noise from the authors' rms one-step error / 0.05 (default) or from the
        residuals' innovations / 0.4 (ours until 2026-12-04).
    model_policy : {"ours", "authors"}
        Evolve on the model from the generic policy (``"ours"``, default: steady state, ``budget``
        episodes) or an SLP from the baseline by the authors' eonn (``"authors"``: 50 genomes, then
        ``authors_generations`` generations of one offspring each; :data:`MODEL_POLICIES`).
    authors_generations : int
        Generations of the authors' eonn when ``model_policy`` is ``"authors"``.
    model_substeps : {10, 1}
        Policies evolve on the learned model in the simulator's 10 substeps of its equivalent
        parameters (the paper's model equations run at simulator timesteps; GHH's default) or in one
        0.1 s step per control step (FGHH's default: the authors' published FGHH code; the default
        everywhere until 2026-12-04) (:meth:`neurohover.models.LearnedModel.mdp`, measured in
        ``lr-substeps-table4``, docs/model.md).
    """

    budget: int = 2000
    predict_episodes: int = 5
    n_steps: int = EPISODE_STEPS
    estimator: str = "ols"
    device: str = "cpu"
    wind_model: str = "none"
    d_u: str = "keep"
    noise: str = DEFAULT_NOISE_ESTIMATE
    model_policy: str = "ours"
    authors_generations: int = 500
    model_substeps: int = DEFAULT_MODEL_SUBSTEPS

    def __post_init__(self) -> None:
        from ..evaluate import check_device
        from ..evolution.common import MAX_EPISODES
        from ..evolution.config import MAX_BUDGET
        from ..models import D_U_CHOICES, ESTIMATORS, NOISE_ESTIMATES
        from ..models.model import check_model_substeps
        from ..models.wind import WIND_MODELS

        for name, allowed in (
            ("estimator", ESTIMATORS),
            ("wind_model", WIND_MODELS),
            ("d_u", D_U_CHOICES),
            ("noise", NOISE_ESTIMATES),
            ("model_policy", MODEL_POLICIES),
        ):
            value = getattr(self, name)
            if value not in allowed:
                raise NeurohoverError(f"{name}={value!r} is not allowed: choose one of {', '.join(map(str, allowed))}")
        check_model_substeps(self.model_substeps, "model_substeps")  # True was taken as 1 (True in (1, 10))
        object.__setattr__(self, "model_substeps", int(self.model_substeps))  # np.int64(1) stored as a JSON number
        # budget, predict_episodes and n_steps went unchecked ('x' was taken, then refused mid-run by evolve; T33-B12):
        # the experiments' caps (model_budget, predict_episodes), the kernel's episode length
        for name, high, text in (
            ("budget", MAX_BUDGET, f"{MAX_BUDGET:,} (model evaluations)"),
            ("predict_episodes", MAX_EPISODES, f"{MAX_EPISODES:,}"),
            ("n_steps", MAX_EPISODE_STEPS, f"{MAX_EPISODE_STEPS:,} (control steps)"),
        ):
            object.__setattr__(self, name, whole_in(getattr(self, name), name, 1, high, text))
        # T24-11: 1.5 or True "is not allowed" (a type), 0 "is out of range" (both said out of range); no bound but int64's
        # stored as the Python int whole_in returns (the settings are stored as JSON); np.int64 was refused (T33-B12)
        object.__setattr__(self, "authors_generations", whole_in(self.authors_generations, "authors_generations", 1, 2**63 - 1, "2**63-1"))
        check_device(self.device)

    def fit(self, flight_data: FlightData) -> LearnedModel:
        """The LR model of ``flight_data`` under these settings, as fitted (one 0.1 s step: its one-step errors)."""
        from ..models import learn_lr

        return learn_lr(flight_data, estimator=self.estimator, wind_model=self.wind_model, d_u=self.d_u, noise=self.noise)

    def learn(self, flight_data: FlightData) -> MDP:
        """The LR model of ``flight_data`` under these settings, as the MDP its policies evolve on: in
        ``model_substeps`` where the model has that equivalent, else as fitted (``LearnedModel.flyable_substeps``)."""
        return learn_model(flight_data, self.estimator, self.wind_model, d_u=self.d_u, noise=self.noise, substeps=self.model_substeps)


def learn_model(
    flight_data: FlightData,
    estimator: str = "ols",
    wind_model: str = "none",
    *,
    d_u: str = "keep",
    noise: str = DEFAULT_NOISE_ESTIMATE,
    substeps: int = DEFAULT_MODEL_SUBSTEPS,
) -> MDP:
    """The LR model (the paper's best method) of the flight data, as an MDP.

    ``estimator="ols"`` (default): ordinary least squares, as the paper and the authors' code;
    ``"gls"``: the AR(1) quasi-differencing option (:func:`neurohover.models.learn_lr`). Intercepts
    are LR's default, ``"uv"`` (D_v, and the model's D_u unless ``d_u="discard"``, as the authors).
    ``wind_model``: ``"none"`` (default, the paper's), ``"constant"`` or ``"sinusoid"``, a
    world-frame wind identified from the data. ``noise``: the authors' ``"rms"`` (default) or
    ``"innovations"``. ``substeps``: 10 (default, the simulator's substeps) or 1 (one 0.1 s step); a model with an axis that
    has no ten-substep equivalent is flown as fitted (:meth:`neurohover.models.LearnedModel.flyable_substeps`).
    """
    from ..models import learn_lr

    return learn_lr(flight_data, estimator=estimator, wind_model=wind_model, d_u=d_u, noise=noise).flown_mdp(substeps)


def enough_to_learn(flight_data: FlightData, wind_model: str = "none") -> bool:
    """Whether ``flight_data`` determine an LR model (``MIN_TRANSITIONS`` transitions, regressors of
    full rank; :func:`neurohover.models.lr.lr_determined`): an agent whose flights crash within a
    few steps flies again to gather more before it learns. (Twenty one-step crashes give twenty
    transitions that all start from rest: u never varies.) With ``wind_model="sinusoid"`` an
    episode must also span the control steps a wind frequency needs."""
    return lr_determined(flight_data, wind_model=wind_model)  # it counts the transitions first


def evolve_on_model(model: MDP, prototype: Policy, settings: ModelEvolution, seed: int) -> tuple[Policy, float]:
    """Evolve a policy on ``model`` (from ``prototype``, or as ``settings.model_policy`` says); return it
    and its predicted return (mean over model episodes)."""
    from ..evolution.eonn import EonnSettings, eonn_evolve
    from ..evolution.evolve import evolve

    if settings.model_policy == "authors":  # their GHH-09 agents: an SLP from the baseline, whatever the generic
        policy = eonn_evolve(
            model,
            baseline_policy(),
            settings=EonnSettings(generations=settings.authors_generations),
            seed=seed,
            n_steps=settings.n_steps,
            threads=1,
            device=settings.device,
        ).champion
    else:
        result = evolve(
            model,
            topology=prototype.topology,
            prototype=prototype,
            budget=settings.budget,
            seed=seed,
            n_steps=settings.n_steps,
            threads=1,
            device=settings.device,
        )
        policy = result.champion
    predicted = evaluate(
        policy, model, episodes=settings.predict_episodes, seed=seed, first_episode=10**9, n_steps=settings.n_steps, threads=1, device=settings.device
    ).returns.mean()
    return policy, float(predicted)


def check_max_learning_episodes(value: object) -> int:
    """The incremental agents' ``max_learning_episodes`` as an int, refused unless a whole number in 1..2**63-1."""
    return whole_in(value, "max_learning_episodes", 1, 2**63 - 1, "2**63-1")


class ModelBasedAgent(Agent):
    """Fly the generic policy once, learn an LR model, evolve a policy on it, keep it for the run."""

    name = "model-based"

    def __init__(self, generic: Policy, settings: ModelEvolution = ModelEvolution()) -> None:
        self.generic = generic
        self.settings = settings
        self.check_arguments()
        self.policy: Policy | None = None
        self.flight_data: FlightData | None = None
        self._rng = np.random.default_rng(0)

    def check_arguments(self) -> None:
        check_agent_policy("generic", self.generic)
        check_agent_settings("settings", self.settings, ModelEvolution)

    def start(self, family: TaskFamily, rng: np.random.Generator) -> None:
        self.policy = None
        self.flight_data = None
        self._rng = rng

    def choose(self, episode: int) -> Choice:
        if self.policy is None:
            return Choice(self.generic, "generic", record=True)
        return Choice(self.policy, "model:1", final=True)

    def update(self, outcome: EpisodeOutcome) -> None:
        if self.policy is None and outcome.flight_data is not None:
            self.flight_data = outcome.flight_data if self.flight_data is None else self.flight_data + outcome.flight_data
            if enough_to_learn(self.flight_data, self.settings.wind_model):  # a generic that crashed at once flies again first
                model = self.settings.learn(self.flight_data)
                self.policy, _ = evolve_on_model(model, self.generic, self.settings, int(self._rng.integers(2**62)))


class IncrementalModelBasedAgent(Agent):
    """After every episode re-learn the model from all flight data of the run and evolve a new
    policy; stop once a policy does at least as well in the MDP as the model predicted, and keep it.

    If no policy meets its prediction within ``max_learning_episodes`` episodes, the agent keeps the
    policy with the best return flown so far (a choice the paper leaves open; the paper's runs stopped
    within a few episodes). ``max_learning_episodes``: a whole number from 1 (keep the generic policy after
    its first episode) to 2**63-1 (in effect, learn until a policy meets its prediction), as
    :class:`IncrementalSettings` takes it.
    """

    name = "incremental"

    def __init__(self, generic: Policy, settings: ModelEvolution = ModelEvolution(), max_learning_episodes: int = 25) -> None:
        self.generic = generic
        self.settings = settings
        self.max_learning_episodes = max_learning_episodes
        self.check_arguments()
        self._reset(np.random.default_rng(0))

    def check_arguments(self) -> None:
        check_agent_policy("generic", self.generic)
        check_agent_settings("settings", self.settings, ModelEvolution)
        # -1, 0, 2.5 and True were taken: the agent stopped learning after its first episode without a word (T39-B03)
        self.max_learning_episodes = check_max_learning_episodes(self.max_learning_episodes)

    def _reset(self, rng: np.random.Generator) -> None:
        self._rng = rng
        self.flight_data: FlightData | None = None
        self.current: Policy = self.generic
        self.current_label = "generic"
        self.predicted: float | None = None
        self.kept: tuple[Policy, str] | None = None
        self.best: tuple[float, Policy, str] = (-np.inf, self.generic, "generic")
        self.models_learned = 0
        self.stopped_at: int | None = None

    def start(self, family: TaskFamily, rng: np.random.Generator) -> None:
        self._reset(rng)

    def choose(self, episode: int) -> Choice:
        if self.kept is not None:
            return Choice(self.kept[0], self.kept[1], final=True)
        return Choice(self.current, self.current_label, record=True)

    def update(self, outcome: EpisodeOutcome) -> None:
        if self.kept is not None:
            return
        if outcome.ret > self.best[0]:
            self.best = (outcome.ret, self.current, self.current_label)
        # Stop rule: the policy did at least as well in the MDP as the model predicted.
        if self.predicted is not None and not outcome.crashed and outcome.ret >= self.predicted:
            self.kept = (self.current, self.current_label)
            self.stopped_at = outcome.episode
            return
        if outcome.episode + 1 >= self.max_learning_episodes:
            self.kept = (self.best[1], self.best[2])
            self.stopped_at = outcome.episode
            return
        if outcome.flight_data is not None:
            self.flight_data = outcome.flight_data if self.flight_data is None else self.flight_data + outcome.flight_data
        assert self.flight_data is not None  # the first episode is always recorded
        if not enough_to_learn(self.flight_data, self.settings.wind_model):  # the policy crashed at once: fly it again first
            return
        model = self.settings.learn(self.flight_data)
        self.models_learned += 1
        self.current, self.predicted = evolve_on_model(model, self.generic, self.settings, int(self._rng.integers(2**62)))
        self.current_label = f"model:{self.models_learned}"


@dataclass(frozen=True)
class IncrementalSettings(AgentSettings):
    """The incremental agents' own settings.

    Attributes
    ----------
    max_learning_episodes : int
        The episode by which it stops learning at the latest (a test-run unit's ``max_learning_episodes``,
        a setting of the whole experiment).
    """

    UNIT_KEY: ClassVar[str] = "max_learning_episodes"

    max_learning_episodes: int = 25

    def __post_init__(self) -> None:
        # T24-11: 1.5 or True "is not allowed" (a type), 0 "is out of range" (both said out of range); no bound but int64's
        # stored as the Python int whole_in returns (the settings are stored as JSON); np.int64 was refused (T33-B12)
        object.__setattr__(self, "max_learning_episodes", check_max_learning_episodes(self.max_learning_episodes))

    @classmethod
    def from_unit(cls, params: dict) -> IncrementalSettings:
        return cls(max_learning_episodes=params["max_learning_episodes"])


def _model_based(policies: AgentPolicies, options: AgentOptions) -> Agent:
    generic = check_agent_policy("generic", policies.generic)  # not an assert: a bare AssertionError (T47-B01)
    return ModelBasedAgent(generic, options.evolution or ModelEvolution())


def _incremental(name: str):
    def build(policies: AgentPolicies, options: AgentOptions) -> Agent:
        generic = check_agent_policy("generic", policies.generic)  # not an assert: a bare AssertionError (T47-B01)
        settings = options.settings or IncrementalSettings()
        agent = IncrementalModelBasedAgent(generic, options.evolution or ModelEvolution(), max_learning_episodes=settings.max_learning_episodes)
        agent.name = name
        return agent

    return build


AGENT_SPECS = (
    AgentSpec(
        "model-based",
        "any",
        frozenset({"generic"}),
        _model_based,
        generic_kind="race",
        learns_models=True,
        summary="fly the generic policy once, learn a model, evolve a policy on it, keep it",
    ),
    AgentSpec(
        "incremental",
        "any",
        frozenset({"generic"}),
        _incremental("incremental"),
        generic_kind="race",
        settings=IncrementalSettings,
        learns_models=True,
        summary="re-learn the model and re-evolve after every episode until a policy meets its prediction",
    ),
    *(
        AgentSpec(
            f"incremental-{kind}",
            "generics-by-kind",
            frozenset({"generic"}),
            _incremental(f"incremental-{kind}"),
            generic_kind=kind,
            settings=IncrementalSettings,
            learns_models=True,
            summary=f"incremental, from the FGHH generic policy evolved {what}",
        )
        for kind, what in FGHH_GENERIC_KINDS
    ),
)
