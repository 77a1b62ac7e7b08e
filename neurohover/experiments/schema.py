"""The schema of experiment configs: each kind's settings, their defaults and checks (:mod:`.config`).

``SCHEMAS[kind]`` maps each setting to ``(absent, check)``, read from the kind's typed settings class
(:mod:`.settings`; :func:`~.checks.setting` declares each field): ``absent`` is ``REQUIRED`` (the config
must give it), ``OMIT`` (a setting added later, absent from the resolved config unless given, so that
older configs keep their hash) or a value; the check returns ``(ok, what is allowed)`` (and the value as read, where a
setting has one spelling of several, as a task's name); a
``("list", SUB_SCHEMA)`` pair is a list of sub-tables (``[[variants]]``, ``[[groups]]``).
:func:`validate_table` applies a schema, :func:`check_kind` the checks across settings.
"""

from __future__ import annotations

import json
import re
from collections.abc import Collection
from typing import Any

from ..agents.hybrid import HybridSettings
from ..agents.registry import AGENTS, HYBRID_AGENTS, usable_agents
from ..agents.spec import unused_reason
from ..errors import NeurohoverError, brief, unknown_keys
from ..evolution.config import make_settings, optimiser_of
from ..evolution.evolve import parse_resampling
from ..evolution.optimisers import optimiser_spec
from ..integrations.neat import NEAT_TOPOLOGY
from ..models.lr import DEFAULT_NOISE_ESTIMATE
from ..models.model import default_model_substeps
from ..tasks import Drift, family_class, task_names
from .checks import OMIT, REQUIRED, schema_of
from .readonly import plain
from .settings import KIND_SETTINGS

#: A ``generics_from`` source that names a directory of policy files (``.net`` or ``.json``) instead of an experiment.
DIR_SOURCE = "dir:"

#: The group of the robustness units that fly a policy set's specialised policies (``robustness_policies``).
POLICY_SET_GROUP = "policy-set"

#: Each kind's schema, ``{setting: (absent, check)}``, built from its typed settings class (:mod:`.settings`, the one
#: place a setting is declared).
SCHEMAS: dict[str, dict[str, tuple[Any, Any]]] = {kind: schema_of(cls) for kind, cls in KIND_SETTINGS.items()}


#: A group's options of the LR models its agents learn, each with the value that leaves a group's units as they are
#: (given on a group whose agents learn no models: refused; OMIT, any value given). The estimator is written into every
#: group (absent: "ols"); a baseline group's "gls" was stored without a word while the others were refused (T26-A03).
MODEL_OPTIONS: dict[str, Any] = {"d_u": OMIT, "noise": OMIT, "model_policy": OMIT, "model_substeps": OMIT, "wind_model": "none", "estimator": "ols"}


#: What 0 means for the budget settings that take it: no cap, the run stopped by its own rule (the units pass 0 on as no
#: budget, ``budget or None``): told where one is refused, for a -1 or "unlimited" meant as no cap (T21-14).
ZERO_MEANS = dict.fromkeys(
    ("budget", "policy_budget", "generic_budget"),
    " (0: no cap, each evolution run stops by its optimizer's own rule: the plateau stop, or the generations setting)",
) | {"ec_meno_budget": " (0: no cap, EC-MENO stops at its plateau)"}


def validate_table(values: dict, schema: dict, where: str, *, given_only: bool = False) -> dict:
    """``values`` checked against ``schema``, with the defaults written in. ``given_only``: check the settings given and
    nothing else (no required setting missed, no defaults): a config's [settings] table, whose scale tables add the rest."""
    unknown = unknown_keys(values, schema)  # each key quoted: the key '' read "unknown setting(s) ; allowed" (T58-B03)
    if unknown:
        hint = " (the optimizer table is spelled `optimizer`, as on the command line)" if "optimiser" in values and "optimiser" not in schema else ""
        raise NeurohoverError(f"{where}: unknown setting(s) {unknown}; allowed: {', '.join(sorted(schema))}{hint}")
    out: dict[str, Any] = {}
    for key, (default, check) in schema.items():
        if key not in values:
            if given_only:
                continue
            if default is REQUIRED:
                raise NeurohoverError(f"{where}: missing required setting {key!r}")
            if default is OMIT:
                continue
            out[key] = json.loads(json.dumps(default))
            continue
        value = plain(values[key])  # np.int64(3) as 3: the config is stored as JSON (a seed of np.arange was refused; T43-B11)
        if isinstance(check, tuple):  # a list of sub-tables
            if not isinstance(value, list) or not value or not all(isinstance(x, dict) for x in value):
                raise NeurohoverError(f"{where}: {key!r} must be a non-empty list of tables ([[{key}]] in TOML)")
            out[key] = [validate_table(item, check[1], f"{where}, {key}[{i}]") for i, item in enumerate(value)]
            continue
        if value is None and default is None:
            out[key] = None
            continue
        ok, allowed, *read = check(value)
        if not ok:
            no_cap = ZERO_MEANS.get(key, "") if check(0)[0] else ""  # -1 for "unlimited" was refused without the way to say it (T21-14)
            raise NeurohoverError(f"{where}: {key} = {brief(value)} is not allowed: expected {allowed}{no_cap}")
        out[key] = read[0] if read else value  # the setting's one spelling, where its check reads one ('GHH08': ghh08; T58-A01)
    return out


def check_kind(settings: dict, kind: str, where: str) -> None:
    """Cross-field checks (and the defaults they write in), by the experiment's kind."""
    task, sigma = settings["task"], settings.get("sigma")

    if sigma is not None and not family_class(task).has_sigma:  # the registry's checked entries: a has_sigma 'no' was listed (T54-B11)
        with_sigma = ", ".join(repr(n) for n in task_names() if family_class(n).has_sigma)
        raise NeurohoverError(f"{where}: sigma applies to task {with_sigma} only, not {task!r}")
    if kind == "evolution":
        _check_evolution(settings, task, where)
    if kind == "model_learning":
        _check_model_learning(settings, task, where)
    if kind in ("model_learning", "test_runs"):
        _check_mdp_counts(settings, where)
    if kind == "test_runs":
        _check_test_runs(settings, task, where)


def check_given(settings: dict, where: str) -> None:
    """Refuse a setting given where it does nothing (``settings`` as written, before defaults fill them in):
    a NEAT variant's ``prototype`` (NEAT starts from its own genomes: its neat table's ``start``), a group's
    ``exclude_own`` on MDPs other than the training MDPs (only those have a specialised policy of their own).

    The experiment-wide settings no unit uses are refused by :func:`check_used` (the policy-evolution settings a config
    file gives stay accepted where ``--set policies=shipped`` switched its source: one config serves both sources)."""
    for i, g in enumerate(settings.get("groups") or []):
        if isinstance(g, dict) and g.get("exclude_own") is True and g.get("mdps", "test") != "train":  # accepted without a word (ninth trial)
            raise NeurohoverError(
                f"{where}, groups[{i}]: exclude_own = true does nothing on mdps = {g.get('mdps', 'test')!r}: only the training MDPs have "
                "specialised policies of their own to leave out (give mdps = 'train', or leave exclude_own out)"
            )
    for i, v in enumerate(settings.get("variants") or []):
        if isinstance(v, dict) and v.get("topology") == NEAT_TOPOLOGY and "prototype" in v:
            raise NeurohoverError(
                f"{where}, variants[{i}]: prototype = {v['prototype']!r} does nothing for topology = 'neat': NEAT starts from its own "
                "genomes; give neat = { start = 'baseline' } for the baseline-equivalent start, or leave prototype out"
            )


def _given(written: dict, schema: dict, key: str) -> bool:
    """Whether ``written`` (settings as written) gives ``key`` a value that changes the resolved config and its hash: any
    value of a setting left out when absent (OMIT), another than the default of one written in when absent."""
    return key in written and (schema[key][0] is OMIT or written[key] != schema[key][0])


def _idle(written: dict, schema: dict, keys: tuple[str, ...], applies: bool, whom: str, where: str) -> None:
    """Refuse the ``keys`` given (:func:`_given`) when they apply to ``whom`` only and this config runs none (not ``applies``)."""
    given = [k for k in keys if _given(written, schema, k)]
    if given and not applies:
        named = ", ".join(f"{k} = {brief(written[k])}" for k in given)
        raise NeurohoverError(f"{where}: {named} {'applies' if len(given) == 1 else 'apply'} to {whom}; this config has none: leave it out")


#: The test-runs settings of the policies an experiment evolves itself (policies = "evolve"): a --set policies=... on the
#: command line leaves the config file's own standing (one config serves both sources, :func:`check_used`).
POLICY_EVOLUTION_SETTINGS = ("policy_budget", "generic_budget", "generic_resampling", "generics_per_agent", "safety_episodes")

#: A model-learning experiment's settings read by one of its methods only (:func:`~.units.run_model`; T60-A02).
METHOD_SETTINGS = {"ec-mer": ("model_budget", "ec_mer_episodes"), "ec-meno": ("ec_meno_budget",)}

#: The settings a source switched by --set leaves a config file's own standing (one config serves each source, as
#: ``--set 'generic="shipped"'`` does table4's: :func:`switched_settings`): the test-runs policies' evolution settings, a
#: model-learning experiment's generic_budget and its methods' own settings.
SWITCHED_BY: dict[str, tuple[str, ...]] = {
    "policies": POLICY_EVOLUTION_SETTINGS,
    "generic": ("generic_budget",),
    "methods": tuple(k for keys in METHOD_SETTINGS.values() for k in keys),
}


def switched_settings(own: Collection[str], overrides: dict) -> frozenset[str]:
    """The settings of ``own`` (those a config file gives) whose source (:data:`SWITCHED_BY`) the ``overrides`` (--set)
    switch and do not give themselves: :func:`check_used` accepts them where no unit uses them."""
    return frozenset(k for source, keys in SWITCHED_BY.items() if source in overrides for k in keys if k in own and k not in overrides)


def check_used(written: dict, settings: dict, kind: str, where: str, switched: frozenset[str] = frozenset()) -> None:
    """Refuse an experiment-wide setting given (``written``: as written; ``settings``: resolved) that no unit of the
    config uses, as a group's model options on agents that learn none are (T26-A02, T26-A04): it changed the config's hash
    for nothing, so a store made without it refused the command, and --update ran every unit again. ``switched``: the
    settings the config file gives where --set switched the source they apply to (:func:`switched_settings`; accepted)."""
    schema = SCHEMAS[kind]
    switchable = {k for keys in SWITCHED_BY.values() for k in keys}
    written = {k: v for k, v in written.items() if k not in switched or k not in switchable}
    if kind == "evolution":
        robust = bool(settings["robustness_variants"]) or "robustness_policies" in settings
        _idle(written, schema, ("robustness_episodes",), robust, "Table 3's robustness units (robustness_variants, or robustness_policies)", where)
    if kind == "model_learning":  # read only by the fits with model_policy = 'authors', yet part of the hash (T54-A01)
        authors = any(f["model_policy"] == "authors" for f in settings.get("fits", ()))
        _idle(written, schema, ("authors_generations",), authors, "the fits with model_policy = 'authors'", where)
        methods = settings["methods"]  # each budget is read by its own method only, yet part of the hash (T60-A02)
        for method, keys in METHOD_SETTINGS.items():
            _idle(written, schema, keys, method in methods, f"the method {method!r} (methods = {brief(methods)})", where)
        generic = f"the generic policy an experiment evolves itself (generic = 'evolve', and this config's generic is {brief(settings['generic'])})"
        _idle(written, schema, ("generic_budget",), settings["generic"] == "evolve", generic, where)
    if kind != "test_runs":
        return
    groups, task = settings["groups"], settings["task"]
    learners = ", ".join(name for name, spec in usable_agents().items() if spec.learns_models)
    learning = [g for g in groups if AGENTS[g["agent"]].learns_models]
    _idle(written, schema, ("model_budget", "predict_episodes", "max_learning_episodes"), bool(learning), f"the agents that learn models ({learners})", where)
    authors = any(g.get("model_policy") == "authors" for g in learning)
    _idle(written, schema, ("authors_generations",), authors, "the groups of agents that learn models with model_policy = 'authors'", where)
    fghh = family_class(task).generic_over_distribution
    needs = {n for g in groups for n in AGENTS[g["agent"]].needs} | {AGENTS[g["agent"]].generic_kind for g in groups if fghh}
    evolved = (needs - set(settings.get("generics_from") or {})) if settings["policies"] == "evolve" else set()
    source = "policies = 'evolve'" + (f", and this config's policies are {brief(settings['policies'])}" if settings["policies"] != "evolve" else "")
    generics = "the FGHH generics an experiment evolves itself"
    safe = "the safe pair an experiment chooses among the specialised policies it evolves"
    rules: tuple[tuple[tuple[str, ...], bool, str], ...]
    if fghh:
        rules = (
            (("policy_budget",), "zero" in evolved, f"the zero-setting generics an experiment evolves itself ({source}; task fghh)"),
            (
                ("generic_budget", "generic_resampling"),
                bool(evolved & {"fixed", "race"}),
                f"{generics} over G ({source}; agents flying them)",
            ),
            (("generics_per_agent",), bool(evolved & {"zero", "fixed", "race"}), f"{generics} ({source})"),
            (("safety_episodes",), False, f"{safe} (a GHH task, not {task!r})"),
        )
    else:
        safe_agents = ", ".join(name for name, spec in usable_agents().items() if "safe" in spec.needs)
        rules = (
            (
                ("policy_budget",),
                bool(evolved & {"generic", "specialised", "safe"}),
                f"the policies an experiment evolves itself ({source}; agents flying them)",
            ),
            (("safety_episodes",), "safe" in evolved, f"{safe} ({source}; agents {safe_agents})"),
            (("generic_budget", "generic_resampling", "generics_per_agent"), False, f"{generics} (task fghh, not {task!r})"),
        )
    for keys, applies, whom in rules:
        _idle(written, schema, keys, applies, whom, where)


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
        neat = NeatSettings.of(v.get("neat", {}))
    except (TypeError, ValueError) as err:
        raise NeurohoverError(f"{where}: variant {v['key']!r}: neat: {err}") from None
    generation = neat.pop_size * neat.episodes
    if settings["budget"] < generation:  # refused now, not by every unit when it runs
        raise NeurohoverError(
            f"{where}: variant {v['key']!r}: budget = {settings['budget']} is below one NEAT generation ({neat.pop_size} genomes x "
            f"{neat.episodes} episodes = {generation}): give the experiment a budget >= {generation}"
        )
    if v["resampling"] != "fixed:1" or "optimizer" in v:
        raise NeurohoverError(f"{where}: variant {v['key']!r}: a NEAT variant takes no resampling or optimizer (its neat table's episodes and settings)")
    if settings["target"] == "family" and settings.get("validation_mdps") != "test":
        raise NeurohoverError(f"{where}: variant {v['key']!r}: a NEAT run over the family is validated on its test MDPs: set validation_mdps = 'test'")


#: One word of a unit key that a config names (a variant's key, a part of a group's label): nothing that reads as a path.
_KEY_WORD = r"[A-Za-z0-9][A-Za-z0-9._+=-]*"
MAX_LABEL = 100  # characters of a group label, as of an experiment's name (config.check_name)
_KEY_WORD_ALLOWED = "letters, digits, '.', '_', '+', '=' or '-', starting with a letter or digit"


def _check_evolution(settings: dict, task: str, where: str) -> None:
    """Variants, their optimisers (checked now, not when a unit first runs), robustness and validation targets."""
    keys = [v["key"] for v in settings["variants"]]
    if len(set(keys)) != len(keys):
        raise NeurohoverError(f"{where}: variant keys must be unique, got {keys}")
    for key in keys:  # a key is one part of its units' keys (evolve/KEY/...): "../x" was taken (eighth trial)
        if not re.fullmatch(_KEY_WORD, key):
            raise NeurohoverError(f"{where}: variant key {key!r:.60} is not allowed: give {_KEY_WORD_ALLOWED}")
    _unique_labels(settings["variants"], "variant", where)
    for v in settings["variants"]:
        if v["sigma"] is not None and not family_class(task).has_sigma:
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
            if name != "ne" and not optimiser_spec(name).stops_itself and settings["budget"] == 0:  # its entry checked (T41-B02)
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
        if settings["target"] != "train" or family_class(task).generic_over_distribution:
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
    for label in labels:  # a group's label is part of its units' keys, whose parts '/' separates (seventh trial: "../x")
        if len(label) > MAX_LABEL:  # 5,000 characters were taken, where names have 100 (trial 27, borderline)
            raise NeurohoverError(f"{where}: group label {brief(label)} is not allowed: give at most {MAX_LABEL} characters")
        if not re.fullmatch(f"{_KEY_WORD}(/{_KEY_WORD})*", label):
            raise NeurohoverError(
                f"{where}: group label {label!r:.60} is not allowed: give words of {_KEY_WORD_ALLOWED}, joined by '/' (it names the group's "
                "units, run/LABEL/MDP/REP)"
            )
    if len(set(labels)) != len(labels):
        raise NeurohoverError(f"{where}: group labels must be unique (set label = ... on repeated agents), got {labels}")
    agents = {name.lower(): name for name in usable_agents()}  # a bad registry entry breaks only its own use (T44-B14)
    for g, label in zip(settings["groups"], labels, strict=True):  # wins, the report and the paper's claims read a group by its label (T28-A03)
        other = agents.get(label.lower())
        if other is not None and other != g["agent"]:
            raise NeurohoverError(
                f"{where}: group label {label!r} is not allowed for agent {g['agent']!r}: it is the name of the agent {other!r}, and its results "
                "would pass for that agent's; give a label of its own"
            )
    for g in settings["groups"]:
        if task not in AGENTS[g["agent"]].tasks:
            raise NeurohoverError(f"{where}: agent {g['agent']!r} does not apply to task {task!r}")
        g["label"] = g["label"] or g["agent"]
        own = g.get("drift")
        drift = own or settings.get("drift")
        if drift:  # a table checked by Drift (drift_table()); its change must come within the runs, named where it is given (T27-A08)
            at = f"{where}: group {g['label']!r}" if own else f"{where}: the experiment's drift (every group's)"
            Drift.from_dict(drift).check_run(settings["episodes"], at, at_given="change_at" in drift, config=True)
        lr_keys = [k for k, idle in MODEL_OPTIONS.items() if k in g and g[k] != idle]
        if lr_keys and not AGENTS[g["agent"]].learns_models:
            learners = ", ".join(name for name, spec in usable_agents().items() if spec.learns_models)
            raise NeurohoverError(
                f"{where}: group {g['label']!r}: {', '.join(lr_keys)} {'applies' if len(lr_keys) == 1 else 'apply'} to the agents that learn models "
                f"({learners}), not to {g['agent']!r}"
            )
        idle = [k for k in MODEL_OPTIONS if k in g and k in AGENTS[g["agent"]].idle_model_options]
        if idle:  # model_policy for the authors' FGHH agents: taken, ignored, and a hash of its own (T40-A03)
            raise NeurohoverError(
                f"{where}: group {g['label']!r}: {', '.join(idle)} {'is' if len(idle) == 1 else 'are'} not allowed for agent {g['agent']!r}, "
                "which would ignore it (its evolution on the model is always its own): leave it out"
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
                given = g["settings"]
                checked = own.from_dict(given)
                checked.check_episode_steps(settings["n_steps"])  # refused before any run, not in one (twelfth trial, S3)
                g["settings"] = checked.to_dict()
            except NeurohoverError as e:
                raise NeurohoverError(f"{where}: group {g['label']!r}: {e}") from None
            why = unused_reason(own, g["agent"], given)  # its answer checked (T60-B06)
            if why is not None:  # a setting the agent would ignore (fifth trial)
                raise NeurohoverError(f"{where}: group {g['label']!r}: {why}")
    for kind, source in settings.get("generics_from", {}).items():
        name, _, variant = str(source).partition("/")
        if str(source).startswith(DIR_SOURCE) and len(str(source)) > len(DIR_SOURCE):
            name = variant = "dir"  # a directory of policy files (checked when the config's digest reads them)
        if kind not in ("fixed", "race") or not isinstance(source, str) or not name or not variant:
            raise NeurohoverError(
                f"{where}: generics_from = {{ {kind} = {source!r} }} is not allowed: expected keys fixed and/or race holding "
                "'EXPERIMENT/VARIANT', 'EXPERIMENT/best-race' (e.g. fixed = 'fig13/k5') or 'dir:PATH' (a directory of policy files)"
            )
    if "generic_topology" in settings and (settings["policies"] != "evolve" or not family_class(task).generic_over_distribution):
        raise NeurohoverError(f"{where}: generic_topology applies to the FGHH generics an experiment evolves itself (policies = 'evolve', task fghh)")
    _check_generic_resampling(settings["generic_resampling"], where)


def _check_generic_resampling(table: dict, where: str) -> None:
    """Each ``generic_resampling`` key a kind of FGHH generic and its value a resampling, naming the bad key or value
    (the message named neither, and ``{}`` was taken; twenty-second trial, T22-15)."""
    head = f"{where}: generic_resampling"
    if not table:
        raise NeurohoverError(
            f"{head} = {{}} is not allowed: give keys fixed and/or race, each holding a resampling (e.g. "
            "{ fixed = 'fixed:5', race = 'race:0.2' }), or leave the setting out (the recipe's own resampling)"
        )
    for key, value in table.items():
        if key not in ("fixed", "race"):
            raise NeurohoverError(f"{head} has the key {brief(key)}: allowed keys fixed and race (the kinds of generic policy)")
        if not isinstance(value, str):
            raise NeurohoverError(f"{head}.{key} = {brief(value)} is not allowed: give a text such as 'fixed:5' or 'race:0.2'")
        try:
            parse_resampling(value)
        except NeurohoverError as e:
            raise NeurohoverError(f"{head}.{key}: {e}") from None


def _keyed(items: list[dict], what: str, where: str) -> None:
    """Check that sub-tables' keys are unique unit-key words; a label defaults to the key."""
    keys = [item["key"] for item in items]
    bad = [k for k in keys if not re.fullmatch(r"[a-z0-9][a-z0-9.-]*", k)]
    if bad or len(set(keys)) != len(keys):
        raise NeurohoverError(f"{where}: {what} keys must be unique and of lower-case letters, digits, '.' and '-', got {keys}")
    for item in items:
        item["label"] = item["label"] or item["key"]
    _unique_labels(items, what, where)


def _unique_labels(items: list[dict], what: str, where: str) -> None:
    """Refuse two of ``items`` (variants, conditions, fits: keyed sub-tables, their labels written in) under one label,
    spaces aside: it names each one's row in the report's tables, its figures' legends and its ranking, which could not
    tell them apart (two variants' "SLP, baseline seed" rows; T45-A03), as repeated group labels are refused."""
    seen: dict[str, str] = {}
    for item in items:
        label, key = item["label"], item["key"]
        other = seen.setdefault(" ".join(label.split()), key)
        if other != key:
            raise NeurohoverError(
                f"{where}: {what} label {brief(label)} is not allowed on {what} {key!r}: {what} {other!r} has it; give each {what} a label "
                "of its own (it names its rows in the report's tables and figures)"
            )


def variant_optimizer(experiment: dict, own: dict | None) -> dict:
    """The ``optimizer`` table a variant runs: its own keys (``own``, None: none) over the experiment's,
    or its own alone when it names another optimiser (``name``), whose settings are not the experiment's."""
    own = own or {}
    if own.get("name", "ne") != experiment.get("name", "ne"):
        return dict(own)
    return {**experiment, **own}
