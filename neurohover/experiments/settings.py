"""Typed experiment settings, one frozen dataclass per experiment kind: the one source of the config schema.

Each field is declared with :func:`~neurohover.experiments.checks.setting`: its default in the class, what a
config that leaves it out resolves to (a value, required, or omitted: a setting added later, so that older
configs keep their hash) and its check. :mod:`neurohover.experiments.schema` builds each kind's schema from
these classes (:func:`~neurohover.experiments.checks.schema_of`) and adds the checks across settings. A
config's checked settings are kept as that plain table (``ExperimentConfig.settings``: it is what the config
hash and the store hold); :func:`typed_settings` reads the table into these classes (``ExperimentConfig.typed``),
so the planner and the report name their fields instead of string keys. A setting that a config may leave out
is the field's default here when it did.
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from typing import Any

from ..agents.model_based import MODEL_POLICIES
from ..evolution.config import MAX_BUDGET
from ..integrations.neat import NEAT_TOPOLOGY
from ..models.lr import D_U_CHOICES, DEFAULT_NOISE_ESTIMATE, NOISE_ESTIMATES
from ..models.model import LEGACY_MODEL_SUBSTEPS
from ..policysets import FGHH_GENERIC_RESAMPLING
from .checks import (
    MAX_EPISODES,
    MAX_RUNS,
    MAX_STEPS,
    OMIT,
    agent,
    boolean,
    choice,
    drift_table,
    integer,
    keys_list,
    number,
    policy_source,
    resampling,
    seed,
    seeds_of,
    sensor_table,
    setting,
    substeps,
    table,
    task_family,
    text,
    text_list,
)


@dataclass(frozen=True, kw_only=True)
class Variant:
    """One evolution variant (a ``[[settings.variants]]`` table)."""

    key: str = setting(text())
    label: str = setting(text())
    topology: str = setting(choice("slp", "mlp", NEAT_TOPOLOGY), "mlp")
    prototype: str = setting(choice("zero", "baseline"), "baseline")
    # topology "neat": NEAT's settings (neurohover.integrations.neat.NeatSettings' fields; its start replaces the prototype)
    neat: dict | None = setting(table(), None, absent=OMIT)
    resampling: str = setting(resampling(), "fixed:1")
    sigma: float | None = setting(number(0.0, 1.0), None)
    optimizer: dict | None = setting(table(), None, absent=OMIT)  # this variant's optimizer settings, over the experiment's `optimizer`
    # with the experiment's seeds_of: the variant of that experiment whose runs' seeds this one's take (absent: its own key)
    paired_with: str | None = setting(text(), None, absent=OMIT)


@dataclass(frozen=True, kw_only=True)
class Group:
    """One group of test runs (a ``[[settings.groups]]`` table): an agent on some MDPs."""

    agent: str = setting(agent())
    label: str = setting(text(), absent=None)  # absent: the agent's name (check_kind writes it in)
    mdps: str = setting(choice("train", "test", "sample"), "test")
    n_mdps: int = setting(integer(1))
    runs_per_mdp: int = setting(integer(1, MAX_RUNS), 1)
    exclude_own: bool = setting(boolean(), False)
    # an agent's own typed settings (its spec's settings class); a hybrid agent's (replacement, model_from, rule,
    # box, tilt: HybridSettings) are resolved under `hybrid`, their older name (either spelling is read)
    settings: dict | None = setting(table(), None, absent=OMIT)
    hybrid: dict = setting(table(), absent={})
    estimator: str = setting(choice("ols", "gls"), "ols")  # least squares of the LR models an agent learns
    wind_model: str = setting(choice("none", "constant", "sinusoid"), "none", absent=OMIT)  # their wind (neurohover.models.wind)
    # LR as the authors fitted it, each choice apart (absent: ours; neurohover.agents.model_based.ModelEvolution);
    # noise is written into the resolved config of every group whose agents learn models (check_kind)
    d_u: str = setting(choice(*D_U_CHOICES), "keep", absent=OMIT)  # how its LR models treat the fitted u constant
    noise: str | None = setting(choice(*NOISE_ESTIMATES), None, absent=OMIT)  # their gust-noise estimate (None: no models)
    model_policy: str = setting(choice(*MODEL_POLICIES), "ours", absent=OMIT)  # how policies are evolved on them
    # the substeps their policies evolve on those models in (10 or 1; check_kind writes the task's default in for the
    # agents that learn models, so this default is what an absent value meant in a config stored before 2026-12-04)
    model_substeps: int = setting(substeps(), LEGACY_MODEL_SUBSTEPS, absent=OMIT)
    sensor: dict | None = setting(sensor_table(), None, absent=OMIT)  # this group's sensors (None: the experiment's)
    drift: dict | None = setting(drift_table(), None, absent=OMIT)  # this group's drifting dynamics (None: the experiment's)
    # run i of MDP m takes the seed of that run of another experiment's group: the same gusts and draws (paired). The
    # seed is derived from (experiment, seed, group), so group may be any name several groups share (bench-drift's
    # conditions), not only a group that experiment runs; the experiment must be shipped or this one (load_config checks)
    seeds_of: dict | None = setting(seeds_of(), None, absent=OMIT)


@dataclass(frozen=True, kw_only=True)
class Condition:
    """One sensor condition of a model-learning experiment (a ``[[settings.conditions]]`` table): its models learn
    from flight data seen through these sensors, and are checked against exact ones (docs/benchmarks.md)."""

    key: str = setting(text())
    label: str = setting(text(), absent=None)  # absent: the key (check_kind writes it in)
    sensor: dict | None = setting(sensor_table(), None, absent=OMIT)  # None: exact sensors
    data_episodes: int = setting(integer(1, MAX_EPISODES), 1)  # episodes of the generic policy's flight data each model learns from


@dataclass(frozen=True, kw_only=True)
class Fit:
    """One way of fitting LR and evolving on it in a model-learning experiment (a ``[[settings.fits]]`` table;
    the LR methods' units of each fit, docs/model.md)."""

    key: str = setting(text())
    label: str = setting(text(), absent=None)  # absent: the key (check_kind writes it in)
    d_u: str = setting(choice(*D_U_CHOICES), "keep")
    noise: str = setting(choice(*NOISE_ESTIMATES), DEFAULT_NOISE_ESTIMATE)
    model_policy: str = setting(choice(*MODEL_POLICIES), "ours")
    # LearnedModel.mdp(substeps=): the policy evolves on the model in 1 or 10 substeps (written in by check_kind:
    # the task's default; an absent one in a stored config was 1)
    model_substeps: int = setting(substeps(), LEGACY_MODEL_SUBSTEPS, absent=OMIT)


@dataclass(frozen=True, kw_only=True)
class ExperimentSettings:
    """What every experiment kind has."""

    task: str = setting(task_family())
    sigma: float | None = setting(number(0.0, 1.0), None)
    seed: int = setting(seed())
    n_steps: int = setting(integer(1, MAX_STEPS), 6000)
    # every MDP of the experiment seen through these sensors (None: exact; docs/benchmarks.md)
    sensor: dict | None = setting(sensor_table(), None, absent=OMIT)


@dataclass(frozen=True, kw_only=True)
class EvolutionSettings(ExperimentSettings):
    target: str = setting(choice("train", "zero", "family"))
    n_mdps: int = setting(integer(1), 10)
    runs: int = setting(integer(1, MAX_RUNS))
    budget: int = setting(integer(0, MAX_BUDGET), 0)
    optimizer: dict = setting(table(), absent={})
    validation_episodes: int = setting(integer(0, MAX_EPISODES), 0)
    # "fresh": each champion on fresh draws (of its MDP, or from G) of its own seed; "test": every champion on the
    # family's test MDPs with the same noise (paired comparisons)
    validation_mdps: str | None = setting(choice("fresh", "test"), None, absent=OMIT)
    # the champion chosen again: the last generation's parents each flown this many fresh episodes (0: the run's own)
    champion_reevaluation: int = setting(integer(1, MAX_EPISODES), 0, absent=OMIT)
    history_points: int = setting(integer(2), 300)
    robustness_variants: tuple[str, ...] = setting(keys_list(), (), absent=[])
    robustness_episodes: int = setting(integer(1, MAX_EPISODES), 10)
    # Table 3 also for a policy set's specialised policies ("shipped" or a directory of <task>/ sets): the ones Table 4
    # and Figures 7, 8 and 11 fly, flown as the best champions are (None: none)
    robustness_policies: str | None = setting(policy_source(), None, absent=OMIT)
    # run r of each variant takes the seed of run r of another experiment's variant (paired_with), and the champions
    # are validated on that experiment's test episodes: paired comparisons across experiments (None: their own)
    seeds_of: dict | None = setting(seeds_of(("experiment",)), None, absent=OMIT)
    variants: tuple[Variant, ...] = setting(table=Variant)


@dataclass(frozen=True, kw_only=True)
class ModelLearningSettings(ExperimentSettings):
    mdps: str = setting(choice("train", "test", "sample"), "test")
    n_mdps: int = setting(integer(1))
    methods: tuple[str, ...] = setting(text_list("ec-mer", "ec-meno", "lr", "lr-gls"), absent=["ec-mer", "ec-meno", "lr"])
    generic: str = setting(policy_source(), "evolve")
    generic_budget: int = setting(integer(0, MAX_BUDGET), 0)
    model_budget: int = setting(integer(1, MAX_BUDGET), 2000)  # EC-MER evaluations
    ec_meno_budget: int = setting(integer(0, MAX_BUDGET), 0)  # EC-MENO evaluations; 0: the plateau stop
    ec_mer_episodes: int = setting(integer(1), 1)
    policy_budget: int = setting(integer(0, MAX_BUDGET), 0)
    policy_prototype: str = setting(choice("generic", "baseline"), "generic")
    test_episodes: int = setting(integer(1, MAX_EPISODES), 5)
    # sensor conditions, each its own models of every MDP (empty: one, the experiment's sensor, one episode of data)
    conditions: tuple[Condition, ...] = setting(default=(), absent=OMIT, table=Condition)
    # LR fits, each its own LR models of every MDP, paired with the others (empty: LR as the methods say)
    fits: tuple[Fit, ...] = setting(default=(), absent=OMIT, table=Fit)
    authors_generations: int = setting(integer(1), 500, absent=OMIT)  # generations of the authors' eonn, where a fit evolves so
    # the LR methods' gust-noise estimate where no fits give it (written in by check_kind when they learn LR; None: no LR)
    noise: str | None = setting(choice(*NOISE_ESTIMATES), None, absent=OMIT)
    # and the substeps their policies evolve on the models in (written in likewise: the task's default)
    model_substeps: int = setting(substeps(), LEGACY_MODEL_SUBSTEPS, absent=OMIT)


@dataclass(frozen=True, kw_only=True)
class TestRunsSettings(ExperimentSettings):
    episodes: int = setting(integer(1, MAX_EPISODES))
    policies: str = setting(policy_source(), "evolve")
    policy_budget: int = setting(integer(0, MAX_BUDGET), 0)
    generic_budget: int = setting(integer(0, MAX_BUDGET), 0)
    generic_resampling: dict = setting(table(), absent=dict(FGHH_GENERIC_RESAMPLING))
    generics_per_agent: int = setting(integer(1), 1)
    # the topology of the FGHH generics the experiment evolves itself (the authors' were SLPs)
    generic_topology: str = setting(choice("slp", "mlp"), "mlp", absent=OMIT)
    # kind -> "EXPERIMENT/VARIANT" (or "EXPERIMENT/best-race"): each run's generic drawn from the final champions of
    # another experiment's evolution runs, in the same store and scale (None: evolved or shipped)
    generics_from: dict | None = setting(table(), None, absent=OMIT)
    safety_episodes: int = setting(integer(1, MAX_EPISODES), 3)
    model_budget: int = setting(integer(1, MAX_BUDGET), 2000)
    predict_episodes: int = setting(integer(1, MAX_EPISODES), 5)
    max_learning_episodes: int = setting(integer(1), 25)
    authors_generations: int = setting(integer(1), 500, absent=OMIT)  # the authors' eonn generations on a model
    drift: dict | None = setting(drift_table(), None, absent=OMIT)  # every test run's MDP drifts so (None: fixed dynamics)
    groups: tuple[Group, ...] = setting(table=Group)


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
