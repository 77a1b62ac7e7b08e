"""Typed experiment settings, one frozen dataclass per experiment kind (what the planner reads).

A config's settings are checked against :data:`neurohover.experiments.schema.SCHEMAS` and kept as
that plain table (``ExperimentConfig.settings``: it is what the config hash and the store hold);
:func:`typed_settings` reads the checked table into these classes (``ExperimentConfig.typed``),
so the planner and the report name their fields instead of string keys. A setting that a config
may leave out is None here when it did.
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from typing import Any

from ..models.lr import DEFAULT_NOISE_ESTIMATE
from ..models.model import LEGACY_MODEL_SUBSTEPS


@dataclass(frozen=True, kw_only=True)
class Variant:
    """One evolution variant (a ``[[settings.variants]]`` table)."""

    key: str
    label: str
    topology: str = "mlp"
    prototype: str = "baseline"
    resampling: str = "fixed:1"
    sigma: float | None = None
    optimizer: dict | None = None  # over the experiment's optimizer table (None: left out)
    neat: dict | None = None  # topology "neat": NEAT's settings (NeatSettings' fields; None: its defaults)
    paired_with: str | None = None  # with the experiment's seeds_of: that experiment's variant whose seeds it takes


@dataclass(frozen=True, kw_only=True)
class Group:
    """One group of test runs (a ``[[settings.groups]]`` table): an agent on some MDPs."""

    agent: str
    label: str
    n_mdps: int
    mdps: str = "test"
    runs_per_mdp: int = 1
    exclude_own: bool = False
    hybrid: dict
    settings: dict | None = None  # the agent's own typed settings, as a table
    estimator: str = "ols"
    wind_model: str = "none"  # the wind of the LR models its agents learn
    d_u: str = "keep"  # how its LR models treat the fitted u constant (the authors': discard)
    noise: str | None = None  # their gust-noise estimate (None: the group's agents learn no models)
    model_policy: str = "ours"  # how policies are evolved on them (the authors': an SLP from the baseline by eonn)
    # the substeps their policies evolve on those models in (10 or 1; the schema writes the task's default in,
    # so this default is what an absent value meant in a config stored before 2026-12-04)
    model_substeps: int = LEGACY_MODEL_SUBSTEPS
    sensor: dict | None = None  # this group's sensors (None: the experiment's)
    drift: dict | None = None  # this group's drifting dynamics (None: the experiment's)
    seeds_of: dict | None = None  # {experiment, seed, group}: its runs take that group's seeds (None: its own)


@dataclass(frozen=True, kw_only=True)
class Condition:
    """One sensor condition of a model-learning experiment (a ``[[settings.conditions]]`` table)."""

    key: str
    label: str
    sensor: dict | None = None  # None: exact sensors
    data_episodes: int = 1


@dataclass(frozen=True, kw_only=True)
class Fit:
    """One way of fitting LR and evolving on it in a model-learning experiment (a ``[[settings.fits]]`` table)."""

    key: str
    label: str
    d_u: str = "keep"
    noise: str = DEFAULT_NOISE_ESTIMATE
    model_policy: str = "ours"
    model_substeps: int = LEGACY_MODEL_SUBSTEPS  # LearnedModel.mdp(substeps=): the policy evolves on the model in 1 or 10 substeps


@dataclass(frozen=True, kw_only=True)
class ExperimentSettings:
    """What every experiment kind has."""

    task: str
    seed: int
    sigma: float | None = None
    n_steps: int = 6000
    sensor: dict | None = None  # every MDP of the experiment seen through these sensors (None: exact)


@dataclass(frozen=True, kw_only=True)
class EvolutionSettings(ExperimentSettings):
    target: str
    runs: int
    n_mdps: int = 10
    budget: int = 0
    optimizer: dict
    validation_episodes: int = 0
    validation_mdps: str | None = None
    champion_reevaluation: int = 0  # 0: the run's champion as it ends
    history_points: int = 300
    robustness_variants: tuple[str, ...] = ()
    robustness_episodes: int = 10
    robustness_policies: str | None = None  # a policy set whose specialised policies Table 3 also flies (None: none)
    seeds_of: dict | None = None  # {experiment, seed}: its runs take that experiment's seeds (None: their own)
    variants: tuple[Variant, ...]


@dataclass(frozen=True, kw_only=True)
class ModelLearningSettings(ExperimentSettings):
    mdps: str = "test"
    n_mdps: int
    methods: tuple[str, ...]
    generic: str = "evolve"
    generic_budget: int = 0
    model_budget: int = 2000
    ec_meno_budget: int = 0
    ec_mer_episodes: int = 1
    policy_budget: int = 0
    policy_prototype: str = "generic"
    test_episodes: int = 5
    conditions: tuple[Condition, ...] = ()  # empty: one condition, the experiment's sensor and one episode of data
    fits: tuple[Fit, ...] = ()  # empty: LR as the methods say (D_u kept, `noise`, our evolution)
    authors_generations: int = 500  # generations of the authors' eonn, where a fit evolves so
    noise: str | None = None  # the LR methods' gust-noise estimate where no fits give it (None: no LR method)
    model_substeps: int = LEGACY_MODEL_SUBSTEPS  # and the substeps their policies evolve on the models in


@dataclass(frozen=True, kw_only=True)
class TestRunsSettings(ExperimentSettings):
    episodes: int
    policies: str = "evolve"
    policy_budget: int = 0
    generic_budget: int = 0
    generic_resampling: dict
    generics_per_agent: int = 1
    generic_topology: str = "mlp"  # of the FGHH generics the experiment evolves itself
    generics_from: dict | None = None
    safety_episodes: int = 3
    model_budget: int = 2000
    predict_episodes: int = 5
    max_learning_episodes: int = 25
    authors_generations: int = 500  # generations of the authors' eonn, where a group's agents evolve so
    drift: dict | None = None  # every test run's MDP drifts so (None: fixed dynamics)
    groups: tuple[Group, ...]


KIND_SETTINGS: dict[str, type[ExperimentSettings]] = {
    "evolution": EvolutionSettings,
    "model_learning": ModelLearningSettings,
    "test_runs": TestRunsSettings,
}
_NESTED: dict[str, type] = {"variants": Variant, "groups": Group, "conditions": Condition, "fits": Fit}


def _build(cls: type, table: dict) -> Any:
    names = {f.name for f in fields(cls)}
    unknown = sorted(set(table) - names)
    if unknown:  # the schemas and these classes must agree: a programming error, not a user's
        raise RuntimeError(f"{cls.__name__} has no field(s) {', '.join(unknown)}: add them beside the schema's")
    values: dict[str, Any] = {}
    for name, value in table.items():
        if name in _NESTED:
            value = tuple(_build(_NESTED[name], item) for item in value)
        elif isinstance(value, list):
            value = tuple(value)
        values[name] = value
    return cls(**values)


def typed_settings(kind: str, table: dict) -> ExperimentSettings:
    """The checked settings ``table`` of an experiment of ``kind`` as its typed settings."""
    return _build(KIND_SETTINGS[kind], table)
