"""What defines an evolution run: target, prototype, method, optimiser settings, resampling, budget.

:meth:`RunConfig.build` checks every argument of :func:`~neurohover.evolution.evolve.evolve` that
fixes the run and :meth:`RunConfig.to_dict` gives the JSON a checkpoint must match to be resumed.
"""

from __future__ import annotations

import dataclasses
import json
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from ..errors import NeurohoverError, brief, check_flag, finite_real, float_of, unknown_keys, whole_in, whole_number
from ..policies import TOPOLOGIES, Policy
from ..policies import prototype as make_prototype
from ..sim.constants import MAX_EPISODE_STEPS
from ..tasks import MDP, TaskFamily, refuse_drift
from .bandits import BANDITS
from .generational import GENERATIONAL_PRESETS, OLD_GENERATIONAL, GenerationalSettings
from .optimisers import NE, OPTIMISERS, optimiser_names, optimiser_spec, population_settings
from .optimisers.cma import CMASettings
from .races import MAX_RESAMPLING, RACE_RULES  # MAX_RESAMPLING: a generation of 50 candidates is then 5,000,000 episodes
from .seeding import check_seed
from .steady_state import SteadyStateSettings

__all__ = [
    "CMA_DEFAULTS",
    "EVOLUTION_METHODS",
    "MAX_BUDGET",
    "RACE_T_LIMIT",
    "Resampling",
    "RunConfig",
    "check_budget",
    "make_settings",
    "optimiser_of",
    "parse_resampling",
    "resolve_prototype",
    "resolve_target",
    "upgrade_saved_config",
]

#: CMA-ES's default settings (:class:`~.optimisers.cma.CMASettings`; override with ``settings={"sigma0": ..., "popsize": ...}``).
CMA_DEFAULTS: dict[str, Any] = dataclasses.asdict(CMASettings())
RACE_T_LIMIT = 10  # docs/model.md, Fitness under noise: t_limit = t_min = t_max = 10
#: What a run's ``method`` may be: the neuroevolution's two, or a population optimiser's name (:mod:`.optimisers`).
EVOLUTION_METHODS = ("steady-state", "generational", *OPTIMISERS)
#: Steady-state settings that checkpoints written before they existed ran with.
_OLD_STEADY_STATE = {"plateau_rule": "literal", "selection": "roulette", "tournament_size": 5, "init_mutate_frac": None, "init_mutate_std": None}

#: Cap on a run's budget (episodes, or a model's evaluations): far above any run of the paper's (10**10 episodes
#: are 77 days at 1,500 episodes/s), below what a run's counters and history can hold.
MAX_BUDGET = 10**10


def check_budget(budget, unit: str = "episodes", alternative: str = "") -> int:
    """``budget`` as an int; NeurohoverError unless an integer in 1..MAX_BUDGET (``alternative``: what else the caller allows)."""
    if not whole_number(budget):  # T24-11: 1.5 or True "is not allowed" (a type; it said out of range); np.timedelta64 (T17-1)
        raise NeurohoverError(f"budget={brief(budget)} is not allowed: allowed an integer in 1..{MAX_BUDGET:,} ({unit}){alternative}")
    if not 1 <= budget <= MAX_BUDGET:
        raise NeurohoverError(f"budget={brief(budget)} is out of range: allowed an integer in 1..{MAX_BUDGET:,} ({unit}){alternative}")
    return int(budget)


@dataclass(frozen=True)
class Resampling:
    """How a candidate's fitness is estimated: ``fixed`` (mean of ``k`` episodes, 1..100,000), ``race`` (selection race
    at confidence level ``delta`` in (0, 1), deciding by ``rule``: :data:`~neurohover.evolution.races.RACE_RULES`; with
    ``auto=True`` delta is set race by race to match fixed:``k``'s cost, ``k`` in 1..10) or a bandit ``lucb`` /
    ``kl-lucb`` (error probability ``delta`` in (0, 1)). The fields are checked as :func:`parse_resampling` checks a
    spec's; a field the kind does not use must keep its default. ``str()`` gives the spec back (the prose rule unnamed,
    as before the rules)."""

    kind: str
    k: int = 1
    delta: float | None = None
    rule: str = "prose"
    auto: bool = False  # race:auto: the delta of each race set so that races cost what fixed:K would (AUTO_*)

    def __post_init__(self) -> None:  # nothing was checked: k=-5 was NumPy's "negative dimensions", kind='nope' a TypeError in str() (T17-2)
        k, delta = _checked_resampling(self.kind, self.k, self.delta, self.rule, self.auto)
        object.__setattr__(self, "k", k)  # NumPy's integers and floats as Python's: str() and the checkpoint's JSON
        object.__setattr__(self, "delta", delta)
        object.__setattr__(self, "auto", bool(self.auto))  # a NumPy bool (checked above) as Python's: its repr and JSON

    def __str__(self) -> str:
        if self.kind == "fixed":
            return f"fixed:{self.k}"
        if self.kind in BANDITS:
            return f"{self.kind}:{_delta_text(self.delta)}"
        if self.auto:
            return "race:auto" + ("" if self.k == AUTO_K else f":{self.k}")
        return f"race:{_delta_text(self.delta)}" + ("" if self.rule == "prose" else f":{self.rule}")

    @property
    def selects(self) -> bool:
        """Whether it selects the parents itself (a race or a bandit), so it needs generational evolution."""
        return self.kind != "fixed"


def _delta_text(delta: float | None) -> str:
    """``delta`` as a label writes it: '%g' where that reads back as the same number (race:0.05, as every label so far),
    else Python's shortest exact text: race:0.1234567891 was recorded as race:0.123457, and a resume given the recorded
    label was refused as a damaged checkpoint (T52-A02)."""
    short = f"{delta:g}" if delta is not None else "None"  # None: a race:auto's, which its label does not write
    return short if delta is None or float(short) == delta else repr(delta)


#: race:auto (the paper leaves delta open: Section 7 asks for an automatic choice). The cost a race should have is
#: fixed:K's, K * lambda episodes a generation (K = AUTO_K, Figure 15's baseline, by default): after each race delta
#: is multiplied by AUTO_STEP when the race spent more (narrower bounds decide sooner) and divided by it when it spent
#: less, within AUTO_RANGE, starting at AUTO_DELTA0. Races and fixed resampling then spend the same episodes, so a
#: race can only win by choosing better parents.
AUTO_K, AUTO_DELTA0, AUTO_STEP, AUTO_RANGE = 5, 0.5, 0.8, (0.02, 0.98)


def next_auto_delta(delta: float, spent: int, target: int) -> float:
    """The delta of the next race of ``race:auto`` after one at ``delta`` spent ``spent`` episodes against ``target``."""
    lo, hi = AUTO_RANGE
    return float(min(hi, max(lo, delta * AUTO_STEP if spent > target else delta / AUTO_STEP)))


#: What each field of a :class:`Resampling` may be, for the messages of :func:`_checked_resampling`.
_KINDS = ("fixed", "race", *BANDITS)
_K_OF = {"fixed": f"fixed resampling's K, an integer in 1..{MAX_RESAMPLING:,} (episodes per candidate)", "auto": "race:auto's K, an integer in 1..10"}


def _checked_resampling(kind: Any, k: Any, delta: Any, rule: Any, auto: Any) -> tuple[int, float | None]:
    """``(k, delta)`` of a :class:`Resampling` as ints and floats, or NeurohoverError naming the field that is not
    allowed: the one check of a resampling, whether built from a spec or by hand."""
    if not isinstance(kind, str) or kind not in _KINDS:
        raise NeurohoverError(f"Resampling kind={brief(kind)} is not allowed: allowed {', '.join(_KINDS)}")
    check_flag(auto, "Resampling auto", "race:auto, a delta matching fixed:K's cost")
    if auto and kind != "race":
        raise NeurohoverError(f"Resampling auto=True is for kind='race' (race:auto), not kind={kind!r}")
    if not isinstance(rule, str) or rule not in RACE_RULES or (rule != "prose" and (kind != "race" or auto)):
        raise NeurohoverError(
            f"Resampling rule={brief(rule)} is not allowed: a race's (not race:auto's) rule is one of {', '.join(RACE_RULES)}; other kinds keep 'prose'"
        )
    top = MAX_RESAMPLING if kind == "fixed" else 10 if auto else 1
    if not whole_number(k) or not 1 <= k <= top:
        wanted = _K_OF["fixed" if kind == "fixed" else "auto"] if top > 1 else f"1 (kind={kind!r} uses no K)"
        raise NeurohoverError(f"Resampling k={brief(k)} is not allowed: give {wanted}")
    if kind == "fixed":
        if delta is not None:
            raise NeurohoverError(f"Resampling delta={brief(delta)} is not allowed: fixed resampling has none (give None)")
        return int(k), None
    if not finite_real(delta) or not 0.0 < float(delta) < 1.0:
        what = "confidence level" if kind == "race" else "error probability"
        raise NeurohoverError(f"Resampling delta={brief(delta)} is not allowed: give a number strictly between 0 and 1 ({kind}'s {what})")
    return int(k), float(delta)


def _resampling_of(spec: Any, reason: str, allowed: str, *fields: Any, **named: Any) -> Resampling:
    """The :class:`Resampling` of ``fields`` read from ``spec``, its check's refusal as ``spec``'s (``reason``, ``allowed``)."""
    try:
        return Resampling(*fields, **named)
    except NeurohoverError:
        raise NeurohoverError(f"bad resampling {brief(spec)}: {reason}; {allowed}") from None


def _number(text: str, read: Any) -> Any:
    """``read(text)``, or None where it is no number (then the check refuses it)."""
    if read is int:  # digits only ('+5', ' 5' and '5_0' are no K); 12 at most: int() of 5,000 digits raised
        return int(text) if text.isdigit() and len(text.lstrip("0")) <= 12 else None
    try:
        return read(text)
    except ValueError:
        return None


def parse_resampling(spec: str | Resampling | None) -> Resampling:
    """``"fixed:K"`` (K >= 1 episodes per candidate), ``"race:DELTA[:RULE]"`` (0 < DELTA < 1; RULE one of
    :data:`~neurohover.evolution.races.RACE_RULES`, default prose), ``"race:auto[:K]"`` (a delta that matches
    fixed:K's cost, :data:`AUTO_K`) or ``"lucb:DELTA"`` / ``"kl-lucb:DELTA"``; None is ``fixed:1``."""
    if spec is None:
        return Resampling("fixed", 1)
    if isinstance(spec, Resampling):
        return spec
    text = str(spec).strip().lower()
    kind, sep, value = text.partition(":")
    allowed = (
        "allowed fixed:K (K >= 1 episodes per candidate), race:DELTA[:RULE] (confidence level 0 < DELTA < 1, rule "
        + ", ".join(RACE_RULES)
        + "), race:auto[:K] (a DELTA that matches fixed:K's cost, K in 1..10), lucb:DELTA or kl-lucb:DELTA (error probability 0 < DELTA < 1)"
    )
    if not text.isascii():  # int() and float() read other scripts' digits ('fixed:\u0661' would be fixed:1)
        raise NeurohoverError(f"resampling {brief(spec)} is not allowed: numbers in ASCII digits; {allowed}")
    if sep and value and "" in value.split(":"):  # 'race:0.5:' and 'race:auto:' were read as race:0.5 and race:auto (twelfth trial, S8)
        raise NeurohoverError(f"resampling {brief(spec)} is not allowed: it has an empty field (a ':' with nothing after it); {allowed}")
    if kind == "fixed" and sep:  # fixed:100000000000 was a MemoryError (third trial)
        return _resampling_of(spec, f"K must be an integer in 1..{MAX_RESAMPLING:,}", allowed, "fixed", _number(value, int))
    if kind in BANDITS and sep:
        return _resampling_of(spec, "DELTA must be an error probability strictly between 0 and 1", allowed, kind, 1, _number(value, float_of))
    if kind == "race" and sep and value.partition(":")[0] == "auto":
        k = value.partition(":")[2] or str(AUTO_K)
        reason = "race:auto[:K] matches fixed:K's cost, K an integer in 1..10 (a race's limit)"
        return _resampling_of(spec, reason, allowed, "race", _number(k, int), AUTO_DELTA0, auto=True)
    if kind == "race" and sep:
        value, _, rule = value.partition(":")
        if rule and rule not in RACE_RULES:
            raise NeurohoverError(f"bad resampling {brief(spec)}: {brief(rule)} is not a race rule: allowed {', '.join(RACE_RULES)}")
        return _resampling_of(spec, "DELTA must be a number strictly between 0 and 1", allowed, "race", 1, _number(value, float_of), rule or "prose")
    raise NeurohoverError(f"unknown resampling {brief(spec)}: {allowed}")


def resolve_prototype(prototype, topology: str) -> Policy:
    """The prototype policy: a :class:`Policy` of ``topology``, or ``"zero"`` / ``"baseline"``."""
    if not isinstance(topology, str) or topology not in TOPOLOGIES:  # text first: an array's `in` was NumPy's "truth value" error (sixteenth trial)
        raise NeurohoverError(f"unknown topology {brief(topology)}: allowed {', '.join(TOPOLOGIES)}")
    if isinstance(prototype, Policy):
        if prototype.topology != topology:
            raise NeurohoverError(f"the prototype is an {prototype.topology} policy but topology={topology!r}")
        return prototype
    if isinstance(prototype, str) and prototype in ("zero", "baseline"):
        return make_prototype(topology, prototype)
    raise NeurohoverError(f"prototype must be a Policy, 'zero' or 'baseline', got {prototype!r}")


def resolve_target(target, caller: str = "evolve") -> tuple[MDP | None, TaskFamily | None, dict]:
    """``(mdp or None, family or None, description dict)`` of an MDP, a learned model or a task family; ``caller``: the
    function a refusal names (validation_return's named evolve, T29-B10)."""
    if isinstance(target, (MDP, TaskFamily)):
        refuse_drift(target, "evolution" if caller == "evolve" else caller)
    if isinstance(target, MDP):
        return target, None, {"kind": "mdp", "mdp": target.to_dict()}
    if isinstance(target, TaskFamily):  # all it is (sensor included): part of the run's checkpoint and results
        return None, target, {"kind": "family", **target.to_dict()}
    if callable(getattr(target, "mdp", None)) and hasattr(target, "method"):  # a LearnedModel
        mdp = target.mdp()
        return mdp, None, {"kind": "mdp", "mdp": mdp.to_dict()}
    raise NeurohoverError(f"{caller} needs an MDP, a learned model or a task family as target, got {type(target).__name__}")


def optimiser_of(table: Mapping[str, Any]) -> tuple[str, dict[str, Any]]:
    """An experiment config's ``optimiser`` table split into the optimiser's name (its ``name``
    key, default ``ne``) and its settings; an unknown name is refused."""
    rest = dict(table)
    name = rest.pop("name", NE)
    if not isinstance(name, str) or name not in optimiser_names():
        raise NeurohoverError(f"unknown optimizer name = {brief(name)}: allowed {', '.join(optimiser_names())}")
    return name, rest


def make_settings(method: str, optimizer: str, settings) -> Any:
    """The optimiser settings of a run: ``settings`` (None, a settings object, a dict of
    overrides, or for the generational method a preset's name; a dict may name its base with
    ``"preset"``, :data:`~.generational.GENERATIONAL_PRESETS`) checked for ``method`` /
    ``optimizer``: a population optimiser's settings dataclass (:mod:`.optimisers`), or the
    neuroevolution's with the budget left None (the run counts the budget in episodes itself). In a dict, the text
    ``"none"`` (any case: the command line's ``--setting KEY=none``) is None for a setting that takes None."""
    if optimizer != NE:  # CMA-ES's popsize=none was refused as "must be None or an integer" (T52-A03)
        return population_settings(optimizer, _none_texts(settings, _settings_class(optimizer)))
    cls = SteadyStateSettings if method == "steady-state" else GenerationalSettings
    if settings is None:
        return cls()
    if isinstance(settings, str):  # a preset's name
        if cls is not GenerationalSettings:  # was "unknown steady-state setting(s) preset" (second trial)
            raise NeurohoverError(
                f"settings={settings!r:.60} is not allowed: a preset's name is for the generational method; "
                f"{method} takes a {cls.__name__} or a dict of its fields"
            )
        settings = {"preset": settings}
    if isinstance(settings, cls):
        return dataclasses.replace(settings, budget=None)
    if isinstance(settings, (SteadyStateSettings, GenerationalSettings)):
        raise NeurohoverError(f"the {method} method takes {cls.__name__}, got {type(settings).__name__}")
    if not isinstance(settings, Mapping):
        raise NeurohoverError(f"settings must be a {cls.__name__} or a dict of its fields, got {type(settings).__name__}")
    fields = {f.name for f in dataclasses.fields(cls)} - {"budget"}
    presets = GENERATIONAL_PRESETS if cls is GenerationalSettings else {}
    unknown = unknown_keys(settings, fields | ({"preset"} if presets else set()))
    if unknown:
        budget = "; the run's budget is its own option (--budget, evolve(budget=...)), counted in episodes" if "budget" in settings else ""
        raise NeurohoverError(f"unknown {method} setting(s) {unknown}: allowed {', '.join(sorted(fields | ({'preset'} if presets else set())))}{budget}")
    values = dict(settings)
    if "preset" in values:
        name = values.pop("preset")
        if name not in presets:
            raise NeurohoverError(f"unknown {method} preset {name!r}: allowed {', '.join(presets)}")
        values = {**dataclasses.asdict(presets[name]), **values}
        values.pop("budget")
    values = _none_texts(values, cls)  # --setting KEY=none (T37-A04)
    try:
        return cls(**values)
    except ValueError as err:
        raise NeurohoverError(f"bad {method} settings: {err}") from None


def _settings_class(optimizer: str) -> type | None:
    """The settings dataclass of population optimiser ``optimizer`` (None for a name the registry refuses: its own check
    says why)."""
    try:
        return optimiser_spec(optimizer).settings
    except NeurohoverError:
        return None


def _none_texts(settings: Any, cls: type | None) -> Any:
    """``settings`` with the text "none" (any case) as None for each field of the dataclass ``cls`` that takes None."""
    if not isinstance(settings, Mapping) or cls is None or not dataclasses.is_dataclass(cls):
        return settings
    optional = {f.name for f in dataclasses.fields(cls) if "None" in str(f.type)}
    return {k: None if k in optional and isinstance(v, str) and v.lower() == "none" else v for k, v in settings.items()}


def upgrade_saved_config(saved: dict) -> dict:
    """A checkpoint's ``config`` as this version writes it (steady-state settings added since
    filled in with the values the old run used)."""
    if saved.get("method") == "steady-state" and "plateau_rule" not in saved.get("settings", {}):
        # Written before these settings existed: it ran Appendix A's literal plateau rule.
        return {**saved, "settings": {**_OLD_STEADY_STATE, **saved["settings"]}}
    if saved.get("method") == "generational" and "fitness" not in saved.get("settings", {}):
        # Written before the fitness scale existed: mean raw returns, elitist, plain initial mutation.
        return {**saved, "settings": {**OLD_GENERATIONAL, **saved["settings"]}}
    return saved


def preset_hint(saved: dict, given: dict) -> str:
    """How to resume a generational checkpoint ``saved`` whose settings are a preset's, or nearer one than those
    ``given`` (an older checkpoint's are ``raw-elitist``'s, which no message named; T37-A04): '' where none is nearer."""
    theirs, mine = saved.get("settings"), given.get("settings")
    if saved.get("method") != "generational" or not isinstance(theirs, dict) or not isinstance(mine, dict):
        return ""

    def differing(values: dict) -> list[str]:
        return [key for key in sorted(theirs, key=str) if key not in values or values[key] != theirs[key]]

    name, rest = min(((n, differing(dataclasses.asdict(p))) for n, p in GENERATIONAL_PRESETS.items()), key=lambda found: len(found[1]))
    if len(rest) >= len(differing(mine)):
        return ""
    cli = "".join(f" --setting {key}={'none' if theirs[key] is None else json.dumps(theirs[key]).strip(chr(34))}" for key in rest)
    python = {"preset": name, **{key: theirs[key] for key in rest}}
    but = " but " + ", ".join(rest) if rest else ""
    return f"; its settings are the {name!r} preset's{but}: evolve --preset {name}{cli} (settings={python!r:.200} in Python)"


@dataclass(frozen=True)
class RunConfig:
    """A checked run definition (build it with :meth:`build`).

    Attributes
    ----------
    mdp, family : MDP or None, TaskFamily or None
        The target: exactly one is set.
    target : dict
        JSON description of the target.
    prototype : Policy
    topology, optimizer : str
    method : str
        ``steady-state`` or ``generational`` (optimizer ``ne``), else the population optimiser's name.
    resampling : Resampling
    budget : int or None
        Episodes (not part of :meth:`to_dict`: a resumed run may raise it).
    seed, n_steps : int
    settings : SteadyStateSettings, GenerationalSettings, or a population optimiser's settings
    """

    mdp: MDP | None
    family: TaskFamily | None
    target: dict
    prototype: Policy
    topology: str
    optimizer: str
    method: str
    resampling: Resampling
    budget: int | None
    seed: int
    n_steps: int
    settings: Any

    @classmethod
    def build(cls, target, *, topology, prototype, optimizer, resampling, budget, settings, seed, n_steps, method) -> RunConfig:
        """Check the arguments of ``evolve`` that define the run (NeurohoverError on bad input)."""
        mdp, family, target_desc = resolve_target(target)
        if topology is None:  # the prototype's, else the authors' choice: SLP generics over a family, MLPs on one MDP
            topology = prototype.topology if isinstance(prototype, Policy) else ("slp" if family is not None else "mlp")
        proto = resolve_prototype(prototype, topology)
        if not isinstance(optimizer, str) or optimizer not in optimiser_names():
            raise NeurohoverError(f"unknown optimizer {brief(optimizer)}: allowed {', '.join(optimiser_names())}")
        spec = None if optimizer == NE else optimiser_spec(optimizer)  # its registry entry checked first (T41-B02..B04)
        resampling = parse_resampling(resampling)
        if budget is not None:
            budget = check_budget(budget)
        if isinstance(settings, (SteadyStateSettings, GenerationalSettings)) and settings.budget is not None:
            if budget is None:
                budget = check_budget(settings.budget)
            elif budget != settings.budget:  # one of the two was dropped without a word (T33-B08)
                raise NeurohoverError(
                    f"budget={brief(budget)} is not allowed beside settings.budget={brief(settings.budget)}: "
                    "give the budget once (evolve(budget=...), in episodes), or both alike"
                )
        seed = check_seed(seed)
        n_steps = whole_in(n_steps, "n_steps", 1, MAX_EPISODE_STEPS)  # T24-11: 1.5 or True "is not allowed", 0 out of range
        chosen = ("steady-state" if mdp is not None else "generational") if method is None else method
        if not isinstance(chosen, str) or chosen not in ("steady-state", "generational"):
            raise NeurohoverError(f"unknown method {brief(method)}: allowed steady-state, generational")
        if chosen == "steady-state" and family is not None:
            raise NeurohoverError("the steady-state method evolves on one MDP; a task family needs the generational method")
        if optimizer != NE:
            chosen = optimizer  # a population optimiser is its own method
        if resampling.selects and chosen != "generational":
            raise NeurohoverError(
                f"resampling {resampling} (a selection race or bandit) needs the generational method (a task family as target, "
                "optimizer 'ne'); use fixed:K here"
            )
        checked = make_settings("steady-state" if chosen == "steady-state" else "generational", optimizer, settings)
        if resampling.kind in BANDITS and getattr(checked, "fitness", None) != "inv-log-error":
            raise NeurohoverError(
                f"resampling {resampling} (a bandit) needs rewards in [0, 1]: the fitness scale inv-log-error (1/ln(error)), "
                f"not {getattr(checked, 'fitness', None)!r}"
            )
        if spec is not None and budget is None and not spec.stops_itself:
            raise NeurohoverError(f"optimizer {optimizer!r} has no stopping rule of its own: give a budget (episodes)")
        if spec is not None and proto.genome.size < spec.min_genes:
            raise NeurohoverError(f"{optimizer} needs a genome of at least {spec.min_genes} genes")
        return cls(
            mdp, family, target_desc, proto, topology, optimizer, chosen, resampling, None if budget is None else int(budget), seed, int(n_steps), checked
        )

    def to_dict(self) -> dict:
        """What a checkpoint records of the run (JSON types, as read back from a file)."""
        config = {
            "target": self.target,
            "method": self.method,
            "optimizer": self.optimizer,
            "resampling": str(self.resampling),
            "topology": self.topology,
            "prototype": self.prototype.genome.tolist(),
            "seed": self.seed,
            "n_steps": self.n_steps,
            "settings": dict(self.settings) if isinstance(self.settings, dict) else dataclasses.asdict(self.settings),
        }
        return json.loads(json.dumps(config))  # as a checkpoint would hold it
