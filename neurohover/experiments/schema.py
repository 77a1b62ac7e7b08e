"""The schema of experiment configs: each kind's settings, their defaults and checks (:mod:`.config`).

``SCHEMAS[kind]`` maps each setting to ``(default, check)``: the default is ``REQUIRED`` (the config
must give it), ``OMIT`` (a setting added later, absent from the resolved config unless given, so that
older configs keep their hash) or a value; the check returns ``(ok, what is allowed)``; a
``("list", SUB_SCHEMA)`` pair is a list of sub-tables (``[[variants]]``, ``[[groups]]``).
:func:`validate_table` applies a schema, :func:`check_kind` the checks across settings.
"""

from __future__ import annotations

import json
import re
from dataclasses import fields
from typing import Any

from ..agents.hybrid import HybridSettings
from ..agents.model_based import MODEL_POLICIES
from ..agents.registry import AGENTS, HYBRID_AGENTS
from ..errors import NeurohoverError
from ..evolution.config import make_settings, optimiser_of
from ..evolution.evolve import parse_resampling
from ..evolution.optimisers import OPTIMISERS
from ..evolution.races import RACE_RULES
from ..integrations.neat import NEAT_TOPOLOGY
from ..models.lr import D_U_CHOICES, DEFAULT_NOISE_ESTIMATE, NOISE_ESTIMATES
from ..models.model import MODEL_SUBSTEPS, default_model_substeps
from ..policysets import FGHH_GENERIC_RESAMPLING
from ..tasks import TASK_FAMILIES, TASK_NAMES, Drift, Sensor

#: A ``generics_from`` source that names a directory of policy files (``.net`` or ``.json``) instead of an experiment.
DIR_SOURCE = "dir:"

REQUIRED = object()
#: The group of the robustness units that fly a policy set's specialised policies (``robustness_policies``).
POLICY_SET_GROUP = "policy-set"
OMIT = object()  # default of a setting added later: absent from the resolved config unless given (older configs keep their hash)


def _int(minimum: int):
    def check(v):
        return isinstance(v, int) and not isinstance(v, bool) and v >= minimum, f"an integer >= {minimum}"

    return check


def _float(lo: float, hi: float):
    def check(v):
        return isinstance(v, (int, float)) and not isinstance(v, bool) and lo <= v <= hi, f"a number in [{lo:g}, {hi:g}]"

    return check


def _choice(*allowed: str):
    def check(v):
        return v in allowed, "one of " + ", ".join(repr(a) for a in allowed)

    return check


def _agent():
    def check(v):
        return v in AGENTS, "one of " + ", ".join(repr(a) for a in AGENTS)

    return check


def _str():
    def check(v):
        return isinstance(v, str) and v != "", "a non-empty string"

    return check


def _bool():
    def check(v):
        return isinstance(v, bool), "true or false"

    return check


def _table():
    def check(v):
        return isinstance(v, dict), "a table"

    return check


def _str_list(*allowed: str):
    def check(v):
        ok = isinstance(v, list) and len(v) > 0 and all(isinstance(x, str) for x in v)
        if ok and allowed:
            ok = all(x in allowed for x in v)
        return ok, "a non-empty list of " + ("strings" if not allowed else "names from " + ", ".join(allowed))

    return check


def _resampling():
    def check(v):
        if not isinstance(v, str):
            return False, "a string fixed:K or race:DELTA"

        try:
            parse_resampling(v)
        except NeurohoverError:
            return False, "fixed:K (K >= 1) or race:DELTA[:RULE] (0 < DELTA < 1, RULE " + ", ".join(RACE_RULES) + ")"
        return True, ""

    return check


def _settings_table(cls, keys: str):
    """A table that ``cls.from_dict`` reads (a Sensor's or a Drift's), checked by it; ``keys`` names its settings."""

    def check(v):
        if not isinstance(v, dict):
            return False, f"a table of {cls.__name__.lower()} settings ({keys})"
        try:
            cls.from_dict(v)
        except NeurohoverError as exc:
            return False, f"a valid {cls.__name__.lower()} ({exc})"
        return True, ""

    return check


def _sensor_table():
    return _settings_table(Sensor, ", ".join(["level", *(f.name for f in fields(Sensor))]))


def _drift_table():
    return _settings_table(Drift, ", ".join(f.name for f in fields(Drift) if f.init))


def _seeds_of(names: tuple[str, ...] = ("experiment", "group")):
    def check(v):
        ok = (
            isinstance(v, dict)
            and set(v) == {*names, "seed"}
            and all(isinstance(v[k], str) and v[k] != "" for k in names)
            and isinstance(v["seed"], int)
            and not isinstance(v["seed"], bool)
            and 0 <= v["seed"] <= 2**63 - 1
        )
        fields = ", ".join(["experiment = NAME", "seed = ITS ROOT SEED", *(["group = ITS GROUP'S LABEL"] if "group" in names else [])])
        return ok, "a table {" + fields + "}"

    return check


def _substeps():
    return lambda v: (v in MODEL_SUBSTEPS and not isinstance(v, bool), " or ".join(map(str, MODEL_SUBSTEPS)))


def _policy_source():
    def check(v):
        return isinstance(v, str) and v != "", "'evolve', 'shipped' or a directory holding <task>/ policy sets"

    return check


# key -> (default or REQUIRED, check)
_COMMON: dict[str, tuple[Any, Any]] = {
    "task": (REQUIRED, _choice(*TASK_NAMES)),
    "sigma": (None, _float(0.0, 1.0)),
    "seed": (REQUIRED, lambda v: (isinstance(v, int) and not isinstance(v, bool) and 0 <= v <= 2**63 - 1, "an integer in 0..2**63-1")),
    "n_steps": (6000, _int(1)),
    "sensor": (OMIT, _sensor_table()),  # every MDP of the experiment seen through these sensors (docs/benchmarks.md)
}

_VARIANT = {
    "key": (REQUIRED, _str()),
    "label": (REQUIRED, _str()),
    "topology": ("mlp", _choice("slp", "mlp", NEAT_TOPOLOGY)),
    "prototype": ("baseline", _choice("zero", "baseline")),
    # topology "neat": NEAT's settings (neurohover.integrations.neat.NeatSettings' fields; its start replaces the prototype)
    "neat": (OMIT, _table()),
    "resampling": ("fixed:1", _resampling()),
    "sigma": (None, _float(0.0, 1.0)),
    "optimizer": (OMIT, _table()),  # this variant's optimizer settings, over the experiment's `optimizer`
    # with the experiment's seeds_of: the variant of that experiment whose runs' seeds this one's take (absent: its own key)
    "paired_with": (OMIT, _str()),
}

_GROUP = {
    "agent": (REQUIRED, _agent()),
    "label": (None, _str()),
    "mdps": ("test", _choice("train", "test", "sample")),
    "n_mdps": (REQUIRED, _int(1)),
    "runs_per_mdp": (1, _int(1)),
    "exclude_own": (False, _bool()),
    # an agent's own typed settings (its spec's settings class); a hybrid agent's (replacement, model_from, rule,
    # box, tilt: HybridSettings) are resolved under `hybrid`, their older name (either spelling is read)
    "settings": (OMIT, _table()),
    "hybrid": ({}, _table()),
    "estimator": ("ols", _choice("ols", "gls")),  # least squares of the LR models an agent learns
    "wind_model": (OMIT, _choice("none", "constant", "sinusoid")),  # and their wind (neurohover.models.wind; absent: none)
    # LR as the authors fitted it, each choice apart (absent: ours; neurohover.agents.model_based.ModelEvolution);
    # noise is written into the resolved config of every group whose agents learn models (check_kind)
    "d_u": (OMIT, _choice(*D_U_CHOICES)),
    "noise": (OMIT, _choice(*NOISE_ESTIMATES)),
    "model_policy": (OMIT, _choice(*MODEL_POLICIES)),
    "model_substeps": (OMIT, _substeps()),  # written in by check_kind for the agents that learn models (the task's default)
    "sensor": (OMIT, _sensor_table()),  # this group's agents fly the group's MDPs through these sensors
    "drift": (OMIT, _drift_table()),  # and with these drifting dynamics (neurohover.tasks.drift)
    # run i of MDP m takes the seed of that run of another experiment's group: the same gusts and draws (paired)
    "seeds_of": (OMIT, _seeds_of()),
}

# One sensor condition of a model-learning experiment: its models learn from flight data seen through
# these sensors, and are checked against exact ones (docs/benchmarks.md, learned models under sensor noise).
_CONDITION = {
    "key": (REQUIRED, _str()),
    "label": (None, _str()),
    "sensor": (OMIT, _sensor_table()),  # absent: exact sensors
    "data_episodes": (1, _int(1)),  # episodes of the generic policy's flight data each model learns from
}

# One way of fitting LR and evolving a policy on the model (the LR methods' units of each fit; docs/model.md)
_FIT = {
    "key": (REQUIRED, _str()),
    "label": (None, _str()),
    "d_u": ("keep", _choice(*D_U_CHOICES)),
    "noise": (DEFAULT_NOISE_ESTIMATE, _choice(*NOISE_ESTIMATES)),
    "model_policy": ("ours", _choice(*MODEL_POLICIES)),
    # written in by check_kind: the task's default (ten for GHH; an absent one in a stored config was 1)
    "model_substeps": (OMIT, _substeps()),
}

SCHEMAS: dict[str, dict[str, tuple[Any, Any]]] = {
    "evolution": {
        **_COMMON,
        "target": (REQUIRED, _choice("train", "zero", "family")),
        "n_mdps": (10, _int(1)),
        "runs": (REQUIRED, _int(1)),
        "budget": (0, _int(0)),
        "optimizer": ({}, _table()),
        "validation_episodes": (0, _int(0)),
        # "fresh": each champion on fresh draws (of its MDP, or from G) of its own seed; "test": every
        # champion on the family's test MDPs with the same noise (paired comparisons)
        "validation_mdps": (OMIT, _choice("fresh", "test")),
        # the champion chosen again: the last generation's parents each flown this many fresh episodes (generational runs)
        "champion_reevaluation": (OMIT, _int(1)),
        "history_points": (300, _int(2)),
        "robustness_variants": ([], lambda v: (isinstance(v, list) and all(isinstance(x, str) for x in v), "a list of variant keys")),
        "robustness_episodes": (10, _int(1)),
        # Table 3 also for a policy set's specialised policies ("shipped" or a directory of <task>/ sets): the ones
        # Table 4 and Figures 7, 8 and 11 fly, flown as the best champions are
        "robustness_policies": (OMIT, _policy_source()),
        # run r of each variant takes the seed of run r of another experiment's variant (paired_with), and the
        # champions are validated on that experiment's test episodes: paired comparisons across experiments
        "seeds_of": (OMIT, _seeds_of(("experiment",))),
        "variants": (REQUIRED, ("list", _VARIANT)),
    },
    "model_learning": {
        **_COMMON,
        "mdps": ("test", _choice("train", "test", "sample")),
        "n_mdps": (REQUIRED, _int(1)),
        "methods": (["ec-mer", "ec-meno", "lr"], _str_list("ec-mer", "ec-meno", "lr", "lr-gls")),
        "generic": ("evolve", _policy_source()),
        "generic_budget": (0, _int(0)),
        "model_budget": (2000, _int(1)),  # EC-MER evaluations
        "ec_meno_budget": (0, _int(0)),  # EC-MENO evaluations; 0: the plateau stop
        "ec_mer_episodes": (1, _int(1)),
        "policy_budget": (0, _int(0)),
        "policy_prototype": ("generic", _choice("generic", "baseline")),
        "test_episodes": (5, _int(1)),
        "conditions": (OMIT, ("list", _CONDITION)),  # sensor conditions, each its own models of every MDP
        "fits": (OMIT, ("list", _FIT)),  # LR fits, each its own LR models of every MDP (paired with the others)
        "authors_generations": (OMIT, _int(1)),  # the authors' eonn generations (absent: 500, theirs)
        # the LR methods' gust-noise estimate, where no fits give it (written in by check_kind when they learn LR)
        "noise": (OMIT, _choice(*NOISE_ESTIMATES)),
        # and the substeps their policies evolve on the models in (written in likewise: the task's default)
        "model_substeps": (OMIT, _substeps()),
    },
    "test_runs": {
        **_COMMON,
        "episodes": (REQUIRED, _int(1)),
        "policies": ("evolve", _policy_source()),
        "policy_budget": (0, _int(0)),
        "generic_budget": (0, _int(0)),
        "generic_resampling": (dict(FGHH_GENERIC_RESAMPLING), _table()),
        "generics_per_agent": (1, _int(1)),
        # the topology of the FGHH generics the experiment evolves itself (absent: MLP; the authors' were SLPs)
        "generic_topology": (OMIT, _choice("slp", "mlp")),
        # kind -> "EXPERIMENT/VARIANT" (or "EXPERIMENT/best-race"): each run's generic drawn from the
        # final champions of another experiment's evolution runs, in the same store and scale
        "generics_from": (OMIT, _table()),
        "safety_episodes": (3, _int(1)),
        "model_budget": (2000, _int(1)),
        "predict_episodes": (5, _int(1)),
        "max_learning_episodes": (25, _int(1)),
        "authors_generations": (OMIT, _int(1)),  # the authors' eonn generations on a model (absent: 500, theirs)
        "drift": (OMIT, _drift_table()),  # every test run's MDP drifts so (neurohover.tasks.drift)
        "groups": (REQUIRED, ("list", _GROUP)),
    },
}


def validate_table(values: dict, schema: dict, where: str) -> dict:
    unknown = sorted(set(values) - set(schema))
    if unknown:
        hint = " (the optimizer table is spelled `optimizer`, as on the command line)" if "optimiser" in unknown else ""
        raise NeurohoverError(f"{where}: unknown setting(s) {', '.join(unknown)}; allowed: {', '.join(sorted(schema))}{hint}")
    out: dict[str, Any] = {}
    for key, (default, check) in schema.items():
        if key not in values:
            if default is REQUIRED:
                raise NeurohoverError(f"{where}: missing required setting {key!r}")
            if default is OMIT:
                continue
            out[key] = json.loads(json.dumps(default))
            continue
        value = values[key]
        if isinstance(check, tuple):  # a list of sub-tables
            if not isinstance(value, list) or not value or not all(isinstance(x, dict) for x in value):
                raise NeurohoverError(f"{where}: {key!r} must be a non-empty list of tables ([[{key}]] in TOML)")
            out[key] = [validate_table(item, check[1], f"{where}, {key}[{i}]") for i, item in enumerate(value)]
            continue
        if value is None and default is None:
            out[key] = None
            continue
        ok, allowed = check(value)
        if not ok:
            raise NeurohoverError(f"{where}: {key} = {value!r} is not allowed: expected {allowed}")
        out[key] = value
    return out


def check_kind(settings: dict, kind: str, where: str) -> None:
    """Cross-field checks (and the defaults they write in), by the experiment's kind."""
    task, sigma = settings["task"], settings.get("sigma")

    if sigma is not None and not TASK_FAMILIES[task].has_sigma:
        with_sigma = ", ".join(repr(n) for n, c in TASK_FAMILIES.items() if c.has_sigma)
        raise NeurohoverError(f"{where}: sigma applies to task {with_sigma} only, not {task!r}")
    if kind == "evolution":
        _check_evolution(settings, task, where)
    if kind == "model_learning":
        _check_model_learning(settings, task, where)
    if kind in ("model_learning", "test_runs"):
        _check_mdp_counts(settings, where)
    if kind == "test_runs":
        _check_test_runs(settings, task, where)


def _check_neat_variant(settings: dict, v: dict, where: str) -> None:
    """A NEAT variant: its ``neat`` table checked now (NeatSettings), neat-python installed, one episode per
    candidate's resampling (NEAT's own ``episodes`` setting counts them), and validation episodes NEAT can fly."""
    if v["topology"] != NEAT_TOPOLOGY:
        if "neat" in v:
            raise NeurohoverError(f"{where}: variant {v['key']!r} sets neat but its topology is {v['topology']!r} (neat applies to topology = 'neat')")
        return
    from ..integrations.neat import NeatSettings

    try:
        import neat  # noqa: F401  # the optional extra the variant needs, refused now rather than when a unit runs
    except ImportError:
        raise NeurohoverError(f"{where}: variant {v['key']!r} evolves with NEAT: neat-python is missing (pip install neat-python)") from None
    try:
        NeatSettings.of(v.get("neat", {}))
    except (TypeError, ValueError) as err:
        raise NeurohoverError(f"{where}: variant {v['key']!r}: neat: {err}") from None
    if v["resampling"] != "fixed:1" or "optimizer" in v:
        raise NeurohoverError(f"{where}: variant {v['key']!r}: a NEAT variant takes no resampling or optimizer (its neat table's episodes and settings)")
    if settings["target"] == "family" and settings.get("validation_mdps") != "test":
        raise NeurohoverError(f"{where}: variant {v['key']!r}: a NEAT run over the family is validated on its test MDPs: set validation_mdps = 'test'")


def _check_evolution(settings: dict, task: str, where: str) -> None:
    """Variants, their optimisers (checked now, not when a unit first runs), robustness and validation targets."""
    keys = [v["key"] for v in settings["variants"]]
    if len(set(keys)) != len(keys):
        raise NeurohoverError(f"{where}: variant keys must be unique, got {keys}")
    for v in settings["variants"]:
        if v["sigma"] is not None and not TASK_FAMILIES[task].has_sigma:
            raise NeurohoverError(f"{where}: variant {v['key']!r} sets sigma but the task is {task!r}")
        if settings["target"] != "family" and parse_resampling(v["resampling"]).selects:
            raise NeurohoverError(f"{where}: variant {v['key']!r}: selection races and bandits need target = 'family'")

    for v in settings["variants"]:
        _check_neat_variant(settings, v, where)
    method = "generational" if settings["target"] == "family" else "steady-state"
    for v in [None, *(v for v in settings["variants"] if v["topology"] != NEAT_TOPOLOGY)]:
        table = settings["optimizer"] if v is None else variant_optimizer(settings["optimizer"], v.get("optimizer"))
        try:  # the optimizer settings are checked here, not when a unit first runs
            name, rest = optimiser_of(table)
            if name != "ne" and settings["budget"] == 0 and not OPTIMISERS[name].stops_itself:
                raise NeurohoverError(f"optimizer {name!r} has no stopping rule of its own: give the experiment a budget")
            make_settings(method, name, rest)
        except NeurohoverError as err:
            whose = "" if v is None else f" of variant {v['key']!r}"
            raise NeurohoverError(f"{where}: optimizer{whose}: {err}") from None
    unpaired = [v["key"] for v in settings["variants"] if "paired_with" in v]
    if unpaired and "seeds_of" not in settings:
        raise NeurohoverError(f"{where}: variant(s) {', '.join(unpaired)} set paired_with: give the experiment's seeds_of too")
    bad = [k for k in settings["robustness_variants"] if k not in keys or next(v for v in settings["variants"] if v["key"] == k)["topology"] == NEAT_TOPOLOGY]
    if bad:
        raise NeurohoverError(f"{where}: robustness_variants {bad} are not keys of SLP or MLP variants ({', '.join(keys)})")
    if settings["robustness_variants"] and settings["target"] != "train":
        raise NeurohoverError(f"{where}: robustness_variants need target = 'train'")
    if "robustness_policies" in settings:
        if settings["target"] != "train" or TASK_FAMILIES[task].generic_over_distribution:
            raise NeurohoverError(
                f"{where}: robustness_policies flies a set's specialised policies on the training MDPs: it needs target = 'train' and a GHH task"
            )
        if settings["robustness_policies"] == "evolve" or POLICY_SET_GROUP in keys:
            raise NeurohoverError(
                f"{where}: robustness_policies = {settings['robustness_policies']!r} is not allowed: give 'shipped' or a directory holding <task>/ "
                f"policy sets (and no variant named {POLICY_SET_GROUP!r})"
            )
    if "champion_reevaluation" in settings and settings["target"] != "family":
        raise NeurohoverError(f"{where}: champion_reevaluation chooses among a generational run's parents: it needs target = 'family'")
    if settings.get("validation_mdps") == "test" and settings["target"] != "family":
        raise NeurohoverError(f"{where}: validation_mdps = 'test' flies champions evolved over G on the family's test MDPs: it needs target = 'family'")
    if settings["target"] == "train" and settings["n_mdps"] > 10:
        raise NeurohoverError(f"{where}: n_mdps = {settings['n_mdps']} is out of range: there are 10 training MDPs")


def _check_model_learning(settings: dict, task: str, where: str) -> None:
    """Conditions or fits, and the LR methods' noise estimate and substeps (written in: part of the hash)."""
    if "conditions" in settings:
        _keyed(settings["conditions"], "condition", where)
        if "sensor" in settings:
            raise NeurohoverError(f"{where}: sensor is set by each of the conditions here: leave [settings] sensor out")
    lr_methods = set(settings["methods"]) & {"lr", "lr-gls"}
    for key in ("noise", "model_substeps"):
        if key in settings and (not lr_methods or "fits" in settings):
            why = "each of the fits gives its own" if lr_methods else f"methods {settings['methods']} learn no LR model"
            raise NeurohoverError(f"{where}: {key} = {settings[key]!r} applies to the LR methods without fits, not here: {why}")
    if lr_methods and "fits" not in settings:  # the estimate and the substeps are part of the config (and its hash)
        settings["noise"] = settings.get("noise", DEFAULT_NOISE_ESTIMATE)
        settings["model_substeps"] = settings.get("model_substeps", default_model_substeps(task))
    for f in settings.get("fits", []):
        f["model_substeps"] = f.get("model_substeps", default_model_substeps(task))
    if "fits" in settings:
        _keyed(settings["fits"], "fit", where)
        if "conditions" in settings:
            raise NeurohoverError(f"{where}: fits and conditions cannot be combined: give one of them")
        if not set(settings["methods"]) <= {"lr", "lr-gls"}:
            raise NeurohoverError(f"{where}: fits apply to the LR methods only (lr, lr-gls), not to {sorted(set(settings['methods']) - {'lr', 'lr-gls'})}")


def _check_mdp_counts(settings: dict, where: str) -> None:
    """A group's (or the experiment's) MDP count within the family's training or test set."""
    groups = settings.get("groups", [{"mdps": settings.get("mdps"), "n_mdps": settings.get("n_mdps")}])
    for g in groups:
        limit = {"train": 10, "test": 100}.get(g["mdps"])
        if limit is not None and g["n_mdps"] > limit:
            raise NeurohoverError(f"{where}: n_mdps = {g['n_mdps']} is out of range for mdps = {g['mdps']!r} (at most {limit})")


def _check_test_runs(settings: dict, task: str, where: str) -> None:
    """Groups (agents for the task, their LR and own settings, written in where defaulted) and the generics' sources."""
    labels = [g["label"] or g["agent"] for g in settings["groups"]]
    if len(set(labels)) != len(labels):
        raise NeurohoverError(f"{where}: group labels must be unique (set label = ... on repeated agents), got {labels}")
    for g in settings["groups"]:
        if task not in AGENTS[g["agent"]].tasks:
            raise NeurohoverError(f"{where}: agent {g['agent']!r} does not apply to task {task!r}")
        g["label"] = g["label"] or g["agent"]
        lr_keys = [k for k in ("d_u", "noise", "model_policy", "model_substeps") if k in g]
        if lr_keys and not AGENTS[g["agent"]].learns_models:
            learners = ", ".join(name for name, spec in AGENTS.items() if spec.learns_models)
            raise NeurohoverError(
                f"{where}: group {g['label']!r}: {', '.join(lr_keys)} apply to the agents that learn models ({learners}), not to {g['agent']!r}"
            )
        if AGENTS[g["agent"]].learns_models:  # the estimate and the substeps are part of the config (and its hash)
            g["noise"] = g.get("noise", DEFAULT_NOISE_ESTIMATE)
            g["model_substeps"] = g.get("model_substeps", default_model_substeps(task))
        if "settings" in g and g["agent"] in HYBRID_AGENTS:  # one spelling for every agent's own settings
            if g["hybrid"]:
                raise NeurohoverError(f"{where}: group {g['label']!r}: give the hybrid settings once, as settings (hybrid is its older name), not both")
            g["hybrid"] = g.pop("settings")  # kept under `hybrid`: configs written before keep their hash
        if g["hybrid"]:
            if g["agent"] not in HYBRID_AGENTS:
                raise NeurohoverError(
                    f"{where}: group {g['label']!r}: hybrid settings apply to the agents {', '.join(HYBRID_AGENTS)} only, not to {g['agent']!r}"
                )
            try:
                g["hybrid"] = HybridSettings.from_dict(g["hybrid"]).to_dict()
            except NeurohoverError as e:
                raise NeurohoverError(f"{where}: group {g['label']!r}: {e}") from None
        if "settings" in g:  # checked here, not when a unit first runs
            own = AGENTS[g["agent"]].settings
            if own is None or own.UNIT_KEY != "agent_settings":
                raise NeurohoverError(f"{where}: group {g['label']!r}: agent {g['agent']!r} takes no settings table")
            try:
                g["settings"] = own.from_dict(g["settings"]).to_dict()
            except NeurohoverError as e:
                raise NeurohoverError(f"{where}: group {g['label']!r}: {e}") from None
    for kind, source in settings.get("generics_from", {}).items():
        name, _, variant = str(source).partition("/")
        if str(source).startswith(DIR_SOURCE) and len(str(source)) > len(DIR_SOURCE):
            name = variant = "dir"  # a directory of policy files (checked when the config's digest reads them)
        if kind not in ("fixed", "race") or not isinstance(source, str) or not name or not variant:
            raise NeurohoverError(
                f"{where}: generics_from = {{ {kind} = {source!r} }} is not allowed: expected keys fixed and/or race holding "
                "'EXPERIMENT/VARIANT', 'EXPERIMENT/best-race' (e.g. fixed = 'fig13/k5') or 'dir:PATH' (a directory of policy files)"
            )
    if "generic_topology" in settings and (settings["policies"] != "evolve" or not TASK_FAMILIES[task].generic_over_distribution):
        raise NeurohoverError(f"{where}: generic_topology applies to the FGHH generics an experiment evolves itself (policies = 'evolve', task fghh)")
    gr = settings["generic_resampling"]
    if set(gr) - {"fixed", "race"} or not all(_resampling()(v)[0] for v in gr.values()):
        raise NeurohoverError(f"{where}: generic_resampling must be a table with keys fixed and/or race holding fixed:K / race:DELTA")


def _keyed(items: list[dict], what: str, where: str) -> None:
    """Check that sub-tables' keys are unique unit-key words; a label defaults to the key."""
    keys = [item["key"] for item in items]
    bad = [k for k in keys if not re.fullmatch(r"[a-z0-9][a-z0-9.-]*", k)]
    if bad or len(set(keys)) != len(keys):
        raise NeurohoverError(f"{where}: {what} keys must be unique and of lower-case letters, digits, '.' and '-', got {keys}")
    for item in items:
        item["label"] = item["label"] or item["key"]


def variant_optimizer(experiment: dict, own: dict | None) -> dict:
    """The ``optimizer`` table a variant runs: its own keys (``own``, None: none) over the experiment's,
    or its own alone when it names another optimiser (``name``), whose settings are not the experiment's."""
    own = own or {}
    if own.get("name", "ne") != experiment.get("name", "ne"):
        return dict(own)
    return {**experiment, **own}
