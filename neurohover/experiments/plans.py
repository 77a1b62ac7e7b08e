"""From a resolved config to units of work, stage by stage.

``plan(config, results)`` returns every unit that can be defined given the results finished so
far (a later stage's units need earlier results: e.g. Table 3 tests the best champion of each
MDP's evolution runs; test runs fly policies evolved by the experiment's own policy units) and the
total number of units the experiment will have. The runner calls it until every planned unit is
done. Planning is deterministic: the same config and results give the same units, keys, params.

Unit keys (unique within an experiment)::

    evolve/<variant>/train<i>/run<r>     evolution run r of a variant on training MDP i
    evolve/<variant>/run<r>              ... on the zero setting or on G
    robust/<variant>/train<i>            Table 3: best champion of MDP i flown on every MDP
    policy/generic, policy/specialised<i>, policy/safety, policy/generic-<zero|fixed|race><j>
    model/<method>/<mdps><i>             Table 4: one model-learning trial
    run/<group>/<mdps><i>/rep<r>         one test run of a group's agent
"""

from __future__ import annotations

import functools
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from ..agents.hybrid import HybridSettings
from ..agents.registry import HYBRID_AGENTS, agent_spec
from ..errors import NeurohoverError, brief
from ..integrations.neat import NEAT_TOPOLOGY
from ..models.lr import LEGACY_NOISE_ESTIMATE
from ..models.model import LEGACY_MODEL_SUBSTEPS
from ..policies import baseline_policy
from ..policysets import policy_set_roles
from ..tasks import EXACT, N_TEST, N_TRAINING, Sensor
from ..tasks.drift import Drift
from .config import ExperimentConfig, load_config
from .external import dir_champions, load_external, policy_needs
from .keys import UnitKey
from .schema import DIR_SOURCE, POLICY_SET_GROUP, variant_optimizer
from .settings import EvolutionSettings, ExperimentSettings, Group, ModelLearningSettings, TestRunsSettings
from .stored_agents import StoredAgent, UnregisteredAgentError
from .units import Unit, family_of, policy_dict, unit_seed

_SAMPLE_TAG = 0x5A3


@dataclass(frozen=True)
class Plan:
    units: list[Unit]
    total: int
    waiting: tuple[str, ...] = ()  # why some units cannot be planned yet (unfinished sources)


def _family_target(s: ExperimentSettings, sigma: float | None) -> dict:
    """An evolution unit's target "over the family": :meth:`TaskFamily.to_dict`'s table as the stored units spell it
    (``task`` for ``family``, a ``sigma`` always; :func:`~neurohover.tasks.family_from_dict` reads both)."""
    return {"kind": "family", "task": s.task, "sigma": sigma, **({"sensor": s.sensor} if s.sensor is not None else {})}


def _mdps(family, which: str, n: int, seed: int):
    if which == "train":
        return family.training_mdps()[:n]
    if which == "test":
        return family.test_mdps()[:n]
    return [family.sample(np.random.default_rng(np.random.SeedSequence([seed, _SAMPLE_TAG, i])), label=f"{family.name}/sample:{i}") for i in range(n)]


def _unit(cfg: ExperimentConfig, key: str, kind: str, params: dict, seed_key: str | None = None, seed: int | None = None) -> Unit:
    params = {**params, "seed": unit_seed(cfg.typed.seed, cfg.name, seed_key or key) if seed is None else seed}
    return Unit(cfg.name, key, kind, params)


# --------------------------------------------------------------------------------- evolution


def _plan_evolution(cfg: ExperimentConfig, results: dict) -> Plan:
    s = cfg.typed
    assert isinstance(s, EvolutionSettings)
    family = family_of(s.task, s.sigma, s.sensor)
    units: list[Unit] = []
    base = {
        "budget": s.budget,
        "optimiser": s.optimizer,  # the unit's param keeps its first spelling: the stored plans' params
        "n_steps": s.n_steps,
        "validation_episodes": s.validation_episodes,
        "history_points": s.history_points,
    }
    root, name = (s.seed, cfg.name) if s.seeds_of is None else (s.seeds_of["seed"], s.seeds_of["experiment"])

    def paired_seed(v, mdp: str | None, r: int) -> int | None:
        """With seeds_of: the seed of run r of the other experiment's variant ``v`` pairs with (None: the unit's own)."""
        return unit_seed(root, name, UnitKey.make("evolve", v.paired_with or v.key, mdp, r)) if s.seeds_of else None

    if s.validation_mdps == "test":  # one seed for every run's validation: the same MDPs and gusts
        base.update(validation_mdps="test", validation_seed=unit_seed(root, name, "validation"))
    if s.champion_reevaluation:  # absent otherwise: stored units keep their params
        base["champion_reevaluation"] = s.champion_reevaluation
    train = family.training_mdps()[: s.n_mdps]
    for v in s.variants:
        common = {**base, "topology": v.topology, "prototype": v.prototype, "resampling": v.resampling}
        if v.optimizer is not None:
            common["optimiser"] = variant_optimizer(s.optimizer, v.optimizer)
        if v.topology == NEAT_TOPOLOGY:  # NEAT's settings travel as the run's optimiser
            common["optimiser"] = {"name": NEAT_TOPOLOGY, **(v.neat or {})}
        if s.target == "train":
            for i, mdp in enumerate(train):
                for r in range(s.runs):
                    key = UnitKey.make("evolve", v.key, f"train{i}", r)
                    units.append(_unit(cfg, key, "evolve", {**common, "target": {"kind": "mdp", "mdp": mdp.to_dict()}}, seed=paired_seed(v, f"train{i}", r)))
        else:
            sigma = v.sigma if v.sigma is not None else s.sigma
            if s.target == "zero":
                target = {"kind": "mdp", "mdp": family_of(s.task, sigma, s.sensor).zero().to_dict()}
            else:
                target = _family_target(s, sigma)
            for r in range(s.runs):
                units.append(_unit(cfg, UnitKey.make("evolve", v.key, rep=r), "evolve", {**common, "target": target}, seed=paired_seed(v, None, r)))
    total = len(units) + len(s.robustness_variants) * len(train)
    for vkey in s.robustness_variants:
        for i in range(len(train)):
            keys = [UnitKey.make("evolve", vkey, f"train{i}", r) for r in range(s.runs)]
            if not all(k in results for k in keys):
                continue
            best = max(keys, key=lambda k: float(results[k]["champion_return"]))
            units.append(
                _unit(
                    cfg,
                    UnitKey.make("robust", vkey, f"train{i}"),
                    "robustness",
                    {
                        "policy": results[best]["champion"],
                        "source": best,
                        "own": i,
                        "mdps": [m.to_dict() for m in train],
                        "episodes": s.robustness_episodes,
                        "n_steps": s.n_steps,
                    },
                )
            )
    if s.robustness_policies is not None:
        units += _policy_set_robustness(cfg, train)
        total += len(train)
    return Plan(units, total)


def robust_sources(cfg: ExperimentConfig) -> dict[str, list[str]]:
    """Every robustness unit's key of an evolution experiment that flies a champion of its own evolve units, each with
    the keys of those units (planned once they are all stored): ``reproduce --only`` makes them first and is checked
    against these keys (T48-A01, T48-A02); empty for the other kinds."""
    s = cfg.typed
    if not isinstance(s, EvolutionSettings):
        return {}
    n_train = len(family_of(s.task, s.sigma, s.sensor).training_mdps()[: s.n_mdps]) if s.robustness_variants else 0
    return {
        UnitKey.make("robust", vkey, f"train{i}"): [UnitKey.make("evolve", vkey, f"train{i}", r) for r in range(s.runs)]
        for vkey in s.robustness_variants
        for i in range(n_train)
    }


def _policy_set_robustness(cfg: ExperimentConfig, train: list) -> list[Unit]:
    """Table 3 for a policy set: specialised policy i flown on every training MDP, as MDP i's best champion is."""
    s = cfg.typed
    assert isinstance(s, EvolutionSettings) and s.robustness_policies is not None
    ps = load_external(s.task, s.robustness_policies, "robustness_policies")
    params = {"mdps": [m.to_dict() for m in train], "episodes": s.robustness_episodes, "n_steps": s.n_steps}
    return [
        _unit(
            cfg,
            UnitKey.make("robust", POLICY_SET_GROUP, f"train{i}"),
            "robustness",
            {"policy": policy_dict(ps.specialised[i]), "source": f"{s.robustness_policies}:specialised_{i}", "own": i, **params},
        )
        for i in range(len(train))
    ]


# --------------------------------------------------------------------------------- policies of a test


def _policy_evolution_unit(cfg: ExperimentConfig, key: str, target: dict, budget: int, resampling: str = "fixed:1", topology: str = "mlp") -> Unit:
    return _unit(
        cfg,
        key,
        "evolve",
        {
            "target": target,
            "topology": topology,
            "prototype": "baseline",
            "resampling": resampling,
            "budget": budget,
            "optimiser": {},
            "n_steps": cfg.typed.n_steps,
            "validation_episodes": 0,
            "history_points": 50,
        },
    )


def source_experiments(cfg: ExperimentConfig) -> list[str]:
    """The experiments whose results a config's units need (``generics_from``), in the order named."""
    s = cfg.typed
    sources = (s.generics_from or {}).values() if isinstance(s, TestRunsSettings) else ()
    names = [str(src).partition("/")[0] for src in sources if not str(src).startswith(DIR_SOURCE)]
    return list(dict.fromkeys(names))


def source_results(cfg: ExperimentConfig, store) -> dict[str, dict]:
    """name -> the stored results of each of :func:`source_experiments` at the config's scale (none yet: empty), what
    :func:`plan` takes as its sources."""
    return {name: store.results(name, cfg.scale, missing_ok=True) for name in source_experiments(cfg)}


def _source_champions(source: str, scale: str, results: dict) -> tuple[list[tuple[str, dict]] | None, str]:
    """The final champions ``[(key, policy)]`` of ``source`` (``EXPERIMENT/VARIANT`` or
    ``EXPERIMENT/best-race``: the race variant whose final champions' fitness estimates have the
    highest mean, so that no test MDP chooses it), or None and why while its runs are unfinished."""

    if source.startswith(DIR_SOURCE):
        return dir_champions(source), ""
    name, _, want = source.partition("/")
    src = load_config(name, scale).typed
    if not isinstance(src, EvolutionSettings):
        raise NeurohoverError(f"generics_from {source!r}: {name} is not an evolution experiment")
    variants = [v for v in src.variants if v.resampling.startswith("race")] if want == "best-race" else [v for v in src.variants if v.key == want]
    if not variants:
        keys = ", ".join(v.key for v in src.variants)
        raise NeurohoverError(f"generics_from {source!r}: {name} has no variant {want!r} (its variants: {keys}; or best-race)")
    runs = {v.key: [UnitKey.make("evolve", v.key, rep=r) for r in range(src.runs)] for v in variants}
    missing = sum(k not in results for keys in runs.values() for k in keys)
    if missing:
        return None, f"{missing} of {sum(map(len, runs.values()))} evolution runs of {name} ({', '.join(runs)}) are not in the store yet"
    best = max(runs, key=lambda v: float(np.mean([float(results[k]["champion_return"]) for k in runs[v]])))
    return [(f"{name}/{k}", results[k]["champion"]) for k in runs[best]], ""


class _Policies:
    """The policies a test-runs experiment's agents fly: evolved by its own units, read from a
    policy set directory, or drawn from another experiment's champions (``generics_from``).
    ``get`` returns None while the units they come from are unfinished."""

    def __init__(
        self, cfg: ExperimentConfig, results: dict, sources: dict[str, dict] | None = None, unregistered: Mapping[str, StoredAgent] | None = None
    ) -> None:
        self.cfg, self.results, self.unregistered = cfg, results, unregistered or {}
        s = cfg.typed
        assert isinstance(s, TestRunsSettings)
        self.settings = s
        self.task = s.task
        self.family = family_of(s.task, s.sigma, s.sensor)
        self.needs = needs = policy_needs(self.family, [g.agent for g in s.groups], self.unregistered)
        self.units: list[Unit] = []
        self.total = 0
        self.external = None if s.policies == "evolve" else load_external(self.task, s.policies)
        if self.external is not None:
            if self.family.generic_over_distribution and s.generics_per_agent != 1:
                raise NeurohoverError(
                    f"config {cfg.name!r}: a policy set holds one generic policy per method; "
                    f'generics_per_agent = {s.generics_per_agent} needs policies = "evolve"'
                )
            return
        hidden = [a for a in self.unregistered.values() if not a.shown]
        if hidden:  # the policy units planned below depend on what it flies (T60-B04)
            raise UnregisteredAgentError(hidden[0].unplannable())
        budget = s.policy_budget
        roles = policy_set_roles(self.family)  # the policies of the task's set, as build-policies evolves them
        if not self.family.generic_over_distribution:
            train = self.family.training_mdps()
            for role in roles:
                if role.kind == "generic" and "generic" in needs:
                    self._add(UnitKey.make("policy", "generic"), {"kind": "mdp", "mdp": self.family.zero().to_dict()}, budget)
                if role.kind == "specialised" and needs & {"specialised", "safe"}:
                    self._add(UnitKey.make("policy", f"specialised{role.index}"), {"kind": "mdp", "mdp": train[role.index].to_dict()}, budget)
            if "safe" in needs:
                self.total += 1
                found = [self.results.get(UnitKey.make("policy", f"specialised{i}")) for i in range(10)]
                if all(found):
                    self.units.append(
                        _unit(
                            cfg,
                            UnitKey.make("policy", "safety"),
                            "safety",
                            {
                                "policies": [r["champion"] for r in found if r is not None],
                                "mdps": [m.to_dict() for m in self.family.training_mdps()],
                                "episodes": s.safety_episodes,
                                "n_steps": s.n_steps,
                            },
                        )
                    )
        else:
            self.drawn: dict[str, list[tuple[str, dict]] | None] = {}
            self.waiting: list[str] = []
            for kind, source in (s.generics_from or {}).items():
                if kind in needs:
                    self.drawn[kind], why = _source_champions(source, cfg.scale, (sources or {}).get(source.partition("/")[0], {}))
                    if why:
                        self.waiting.append(f"the {kind} generics come from {source}: {why}")
            for role in roles:
                kind = role.kind
                if kind not in needs or kind in self.drawn:
                    continue
                for j in range(s.generics_per_agent):
                    if role.target == "zero":
                        self._add(UnitKey.make("policy", f"generic-zero{j}"), {"kind": "mdp", "mdp": self.family.zero().to_dict()}, budget)
                    else:
                        resampling = s.generic_resampling.get(kind, role.resampling)
                        self._add(UnitKey.make("policy", f"generic-{kind}{j}"), _family_target(s, s.sigma), s.generic_budget, resampling)

    def _add(self, key: str, target: dict, budget: int, resampling: str = "fixed:1") -> None:
        topology = self.settings.generic_topology if key.startswith("policy/generic-") else "mlp"
        self.units.append(_policy_evolution_unit(self.cfg, key, target, budget, resampling, topology))
        self.total += 1

    @functools.cached_property
    def _ext_dicts(self) -> dict:
        """The external set's policies as params hold them, made once (per run, they were a fifth of planning)."""
        ext = self.external
        assert ext is not None
        return {
            "generic": policy_dict(ext.generic),
            "specialised": [policy_dict(p) for p in ext.specialised],
            "generics": {k: policy_dict(v) for k, v in ext.generics.items()},
        }

    def _evolved(self, key: str) -> dict | None:
        r = self.results.get(key)
        return None if r is None else r["champion"]

    def for_agent(self, agent: str, mdp_index: int | None, run_counter: int, exclude_own: bool, key: str = "") -> dict | None:
        """The policies of one run of ``agent``, unit ``key`` (None: not ready yet)."""
        spec = self.unregistered.get(agent) or agent_spec(agent)
        need = spec.needs
        out: dict = {}
        ext = self.external
        if self.family.generic_over_distribution:
            kind = spec.generic_kind
            if kind is not None:
                if kind in getattr(self, "drawn", {}):
                    champions = self.drawn[kind]
                    if champions is None:
                        return None
                    # Each run draws one of the source's champions, as the authors' agent picks one of its files.
                    rng = np.random.default_rng(unit_seed(self.settings.seed, self.cfg.name, f"{key}/generic"))
                    source, out["generic"] = champions[int(rng.integers(len(champions)))]
                    out["generic_source"] = source
                elif ext is not None:
                    out["generic"] = dict(self._ext_dicts["generics"][kind])
                else:
                    j = run_counter % self.settings.generics_per_agent
                    out["generic"] = self._evolved(UnitKey.make("policy", f"generic-{kind}{j}"))
                    out["generic_source"] = UnitKey.make("policy", f"generic-{kind}{j}")
            return None if any(v is None for v in out.values()) else out
        if "generic" in need:
            out["generic"] = dict(self._ext_dicts["generic"]) if ext is not None else self._evolved(UnitKey.make("policy", "generic"))
        if need & {"specialised", "safe"}:
            specialised: list[dict | None]
            if ext is not None:
                specialised = [dict(d) for d in self._ext_dicts["specialised"]]
            else:
                specialised = [self._evolved(UnitKey.make("policy", f"specialised{i}")) for i in range(10)]
            if any(p is None for p in specialised):
                return None
            if "safe" in need:
                if ext is not None:
                    safe = list(ext.safe)
                else:
                    sr = self.results.get(UnitKey.make("policy", "safety"))
                    if sr is None:
                        return None
                    safe = sr["safe"]
                out["safe"] = [specialised[i] for i in safe]
                out["safe_indices"] = safe
            if "specialised" in need:
                keep = [i for i in range(len(specialised)) if not (exclude_own and i == mdp_index)]
                out["specialised"] = [specialised[i] for i in keep]
                out["specialised_indices"] = keep
        return None if any(v is None for v in out.values()) else out


def _lr_fit(d_u: str, noise: str | None, model_policy: str, authors_generations: int, model_substeps: int) -> dict:
    """A unit's LR-fit params where they differ from ours before these settings (absent then: stored units keep their params)."""
    out: dict = {}
    if d_u != "keep":
        out["d_u"] = d_u
    if noise is not None and noise != LEGACY_NOISE_ESTIMATE:
        out["noise"] = noise
    if model_policy != "ours":
        out["model_policy"] = model_policy
        out["authors_generations"] = authors_generations
    if model_substeps != LEGACY_MODEL_SUBSTEPS:
        out["model_substeps"] = model_substeps
    return out


def group_hybrid_settings(group: Group) -> dict | None:
    """The full hybrid settings of a group's units (None: the group's agent is not a hybrid agent)."""

    return HybridSettings.from_dict(group.hybrid).to_dict() if group.agent in HYBRID_AGENTS else None


def _plan_test_runs(
    cfg: ExperimentConfig, results: dict, sources: dict[str, dict] | None = None, unregistered: Mapping[str, StoredAgent] | None = None
) -> Plan:
    pol = _Policies(cfg, results, sources, unregistered)
    s = pol.settings
    units = list(pol.units)
    total = pol.total
    settings = {
        "task": s.task, "sigma": s.sigma, "episodes": s.episodes, "n_steps": s.n_steps, "model_budget": s.model_budget,
        "predict_episodes": s.predict_episodes, "max_learning_episodes": s.max_learning_episodes,
    }  # fmt: skip
    for g in s.groups:
        mdps = _mdps(pol.family, g.mdps, g.n_mdps, s.seed)
        if g.sensor is not None:  # this group's agents fly the same MDPs through sensors of its own
            group_sensor = Sensor.from_dict(g.sensor)
            mdps = [m.with_sensor(group_sensor) for m in mdps]
        drift = g.drift if g.drift is not None else s.drift
        if drift is not None:  # the test runs' MDPs drift (the harness flies the drift, neurohover.tasks.drift)
            run_drift = Drift.from_dict(drift)
            mdps = [m.with_drift(run_drift) for m in mdps]
        sensor = g.sensor if g.sensor is not None else s.sensor
        hybrid = group_hybrid_settings(g)
        counter = 0
        for i, mdp in enumerate(mdps):
            for rep in range(g.runs_per_mdp):
                total += 1
                key = UnitKey.make("run", g.label, f"{g.mdps}{i}", rep)
                seed = None
                if g.seeds_of is not None:  # the seed of the same run of another experiment's group
                    of = g.seeds_of
                    seed = unit_seed(of["seed"], of["experiment"], UnitKey.make("run", of["group"], f"{g.mdps}{i}", rep))
                policies = pol.for_agent(g.agent, i if g.mdps == "train" else None, counter, g.exclude_own and g.mdps == "train", key)
                counter += 1
                if policies is None:
                    continue
                units.append(
                    _unit(
                        cfg,
                        key,
                        "test_run",
                        {
                            **settings,
                            "agent": g.agent,
                            "group": g.label,
                            "mdp": mdp.to_dict(),
                            "policies": policies,
                            "estimator": g.estimator,
                            **({"wind_model": g.wind_model} if g.wind_model != "none" else {}),  # absent: unit keys as before winds
                            **_lr_fit(g.d_u, g.noise, g.model_policy, s.authors_generations, g.model_substeps),  # absent: ours, as before
                            **({"sensor": sensor} if sensor is not None else {}),
                            **({"hybrid": hybrid} if hybrid else {}),
                            **({"agent_settings": g.settings} if g.settings is not None else {}),
                        },
                        seed=seed,
                    )
                )
    return Plan(units, total, tuple(getattr(pol, "waiting", ())))


# --------------------------------------------------------------------------------- model learning


def run_keys(cfg: ExperimentConfig) -> list[str]:
    """Every run unit's key of a test-runs experiment, without planning it: the keys follow from its groups, not from
    the policies they fly, which a staged plan waits for (``reproduce --only`` is checked against them); empty for
    the other kinds."""
    s = cfg.typed
    if not isinstance(s, TestRunsSettings):
        return []
    available = {"train": N_TRAINING, "test": N_TEST}  # _mdps' slices; "sample" draws n
    return [
        UnitKey.make("run", g.label, f"{g.mdps}{i}", rep)
        for g in s.groups
        for i in range(min(g.n_mdps, available.get(g.mdps, g.n_mdps)))
        for rep in range(g.runs_per_mdp)
    ]


def _plan_model_learning(cfg: ExperimentConfig, results: dict) -> Plan:
    s = cfg.typed
    assert isinstance(s, ModelLearningSettings)
    family = family_of(s.task, s.sigma, s.sensor)
    units: list[Unit] = []
    total = len(s.methods) * s.n_mdps * max(1, len(s.conditions), len(s.fits))
    if s.generic == "evolve":
        total += 1
        units.append(_policy_evolution_unit(cfg, UnitKey.make("policy", "generic"), {"kind": "mdp", "mdp": family.zero().to_dict()}, s.generic_budget))
        generic = results.get(UnitKey.make("policy", "generic"), {}).get("champion")
    elif s.generic == "baseline":
        generic = policy_dict(baseline_policy())
    else:
        generic = policy_dict(load_external(s.task, s.generic, "generic").generic)
    if generic is None:
        return Plan(units, total)
    for i, mdp in enumerate(_mdps(family, s.mdps, s.n_mdps, s.seed)):
        for method in s.methods:
            # The seed depends on the MDP only: every method (and sensor condition) learns from the same
            # gusts' flight data and its policy meets the same gusts (a paired comparison).
            common = {
                "method": method,
                "generic": generic,
                "n_steps": s.n_steps,
                "model_budget": s.model_budget,
                "ec_meno_budget": s.ec_meno_budget,
                "ec_mer_episodes": s.ec_mer_episodes,
                "policy_budget": s.policy_budget,
                "prototype": s.policy_prototype,
                "test_episodes": s.test_episodes,
            }
            seed_key = f"model/{s.mdps}{i}"
            if method in ("lr", "lr-gls"):  # the experiment's noise estimate (fits give their own)
                common.update(_lr_fit("keep", s.noise, "ours", s.authors_generations, s.model_substeps))
            if not s.conditions and not s.fits:
                units.append(_unit(cfg, UnitKey.make("model", method, f"{s.mdps}{i}"), "model", {**common, "mdp": mdp.to_dict()}, seed_key=seed_key))
            for f in s.fits:  # every fit learns from the same flight data and its policy meets the same gusts
                params = {**common, "mdp": mdp.to_dict(), **_lr_fit(f.d_u, f.noise, f.model_policy, s.authors_generations, f.model_substeps)}
                units.append(_unit(cfg, UnitKey.make("model", f"{method}@{f.key}", f"{s.mdps}{i}"), "model", params, seed_key=seed_key))
            for c in s.conditions:
                seen = mdp.with_sensor(EXACT if c.sensor is None else Sensor.from_dict(c.sensor))
                params = {**common, "mdp": seen.to_dict(), "data_episodes": c.data_episodes, "exact_checks": True}
                units.append(_unit(cfg, UnitKey.make("model", f"{method}@{c.key}", f"{s.mdps}{i}"), "model", params, seed_key=seed_key))
    return Plan(units, total)


_PLANNERS = {"evolution": _plan_evolution, "test_runs": _plan_test_runs, "model_learning": _plan_model_learning}


def _results_table(value) -> bool:
    """Whether ``value`` is key -> result (text -> dict), as the store's results are."""
    return isinstance(value, dict) and all(isinstance(k, str) and isinstance(v, dict) for k, v in value.items())


def _check_plan_arguments(cfg, results, sources, unregistered) -> None:
    """:func:`plan`'s arguments of the right kinds (None, [] or a config of None were AttributeErrors; fourteenth trial, T14-23)."""
    if not isinstance(cfg, ExperimentConfig):
        raise NeurohoverError(f"plan: cfg = {brief(cfg)} is not allowed: give an experiment's config, load_config(NAME, SCALE)")
    if not _results_table(results):
        raise NeurohoverError(f"plan: results = {brief(results)} is not allowed: give a dict of unit key -> result dict ({{}}: none finished)")
    if sources is not None and not (isinstance(sources, dict) and all(isinstance(k, str) and _results_table(v) for k, v in sources.items())):
        raise NeurohoverError(
            f"plan: sources = {brief(sources)} is not allowed: give None or a dict of experiment name -> its results (unit key -> result dict)"
        )
    if unregistered is not None and not (isinstance(unregistered, Mapping) and all(isinstance(a, StoredAgent) for a in unregistered.values())):
        raise NeurohoverError(f"plan: unregistered = {brief(unregistered)} is not allowed: give None or a dict of agent name -> StoredAgent (stored_agents)")


def plan(
    cfg: ExperimentConfig,
    results: dict[str, dict],
    sources: dict[str, dict[str, dict]] | None = None,
    unregistered: Mapping[str, StoredAgent] | None = None,
) -> Plan:
    """Every unit that can be defined given ``results`` (key -> result) and the results of the
    experiments it draws from (``sources``: name -> results, :func:`source_experiments`), and the
    final unit count. ``unregistered``: the agents of a stored config that this process has not
    registered, as the store shows them (:func:`~.stored_agents.stored_agents`; T60-B04); an agent
    neither registered nor among them is refused by name."""
    _check_plan_arguments(cfg, results, sources, unregistered)
    if cfg.kind == "test_runs":
        return _plan_test_runs(cfg, results, sources, unregistered)
    return _PLANNERS[cfg.kind](cfg, results)
