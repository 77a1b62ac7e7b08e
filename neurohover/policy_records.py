"""The check of a policy file's record of the run that evolved it (:func:`policy_record_problem`), which
:func:`~neurohover.policies.load_policy` applies to every policy file it reads and :func:`~neurohover.policies.save_policy`
to every one it writes (installed into :data:`~neurohover.policies.RECORD_CHECKS` as this module is imported): its
counts, words and settings against the evolution's own ranges and rules and against each other, its place (task, MDP,
target, mdp_params) against the registered task families, and its fields. Moved out of :mod:`neurohover.manifest`
(which re-exports :func:`policy_record_problem`); a policy set's manifest is checked there."""

from __future__ import annotations

import math
import re
from pathlib import Path
from typing import Any

from .errors import NeurohoverError, brief, check_name_text, finite_real, whole_number
from .policies import RECORD_CHECKS
from .sim.constants import CRASH_STEP_PENALTY, MAX_EPISODE_STEPS, MAX_SECONDS, WORST_RETURN, lowest_return, seconds_allowed

#: What a policy file's record of its run says the run was over: a task family (``ghh08/G``, ``fghh/G(sigma=0.3)``), not one MDP.
_FAMILY_TARGET = re.compile(r"[a-z0-9]+/G(\(sigma=[^()]*\))?")


def policy_record_problem(meta: dict) -> str:
    """What in a policy file's record of the run that evolved it contradicts itself ('' when nothing does): the keys
    :meth:`Run.result <neurohover.evolution.run.Run.result>` writes, each checked where present, against the evolution's
    own ranges and words and against each other, as :mod:`neurohover.experiments.result_checks` checks a stored test run.
    A budget of -5, n_steps of 0, more evaluations than episodes, a steady-state run over a family, a return of 5.0, a
    stop reason 'zzz' or a seed of -3 were all accepted after hand edits (T23-11); and the keys ``neurohover evolve``
    adds (:func:`_validation_problem`, :func:`_place_problem`, :func:`_run_settings_problem`): a validation_return of 5.0,
    a task other than its target's, mdp_params other than its label's MDP or settings of pop_size 0 (T24-02)."""
    from .evolution.config import MAX_BUDGET, parse_resampling
    from .evolution.fitness import ERROR_FLOOR
    from .evolution.optimisers import NE, SHIPPED_SPECS, USER_NAME  # shipped names as shipped: not this process's registry (T41-B02/B03)
    from .evolution.restore import STOP_REASONS
    from .sim.rng import MAX_SEED

    counts = {"seed": (0, MAX_SEED, "in 0..2**63-1 (the run's root seed)"), "budget": (1, MAX_BUDGET, f"in 1..{MAX_BUDGET:,} (episodes), or null"),
              "n_steps": (1, MAX_EPISODE_STEPS, f"in 1..{MAX_EPISODE_STEPS:,} (control steps per episode)"),
              "episode_steps": (1, MAX_EPISODE_STEPS, f"in 1..{MAX_EPISODE_STEPS:,} (control steps per episode)"),  # T27-B07
              "episodes": (1, None, ">= 1 (episodes flown)"), "evaluations": (1, None, ">= 1 (candidates evaluated)"),
              "generations": (0, None, ">= 0 (generations bred)")}  # fmt: skip
    for name, (low, high, allowed) in counts.items():
        value = meta.get(name)
        if name not in meta or (value is None and name == "budget") or (whole_number(value) and low <= value <= (high or value)):
            continue
        return f"its {name} {brief(value)} is not allowed: allowed an integer {allowed}"
    for small, large, why in (("evaluations", "episodes", "each evaluation flies at least one episode"),
                              ("generations", "evaluations", "each generation evaluates at least one candidate")):  # fmt: skip
        if meta.get(small) is not None and meta.get(large) is not None and meta[small] > meta[large]:
            return f"its {small} {brief(meta[small])} is not allowed: more than its {large} {brief(meta[large])}, and {why}"
    own_stop = {"steady-state": "plateau", "generational": "generations", **{spec.label: spec.stop_reason for spec in SHIPPED_SPECS.values()}}
    method, optimizer = meta.get("method"), meta.get("optimizer")
    users = [isinstance(v, str) and USER_NAME.fullmatch(v) is not None for v in (method, optimizer)]  # T40-B14
    user = " or user:NAME (an optimiser registered at run time)"
    if method is not None and not users[0] and (not isinstance(method, str) or method not in own_stop):
        return f"its method {brief(method)} is not allowed: allowed {', '.join(own_stop)}{user}"
    names = {NE: ("steady-state", "generational"), **{name: (spec.label,) for name, spec in SHIPPED_SPECS.items()}}
    if optimizer is not None and not users[1] and (not isinstance(optimizer, str) or optimizer not in names):
        return f"its optimizer {brief(optimizer)} is not allowed: allowed {', '.join(names)}{user}"
    if method is not None and optimizer is not None and users[0] != users[1]:
        return f"its method {brief(method)} is not allowed beside its optimizer {brief(optimizer)}: a run of a user:NAME optimizer records both so"
    if users[0] and optimizer is not None and method != optimizer:  # user:openai-es beside user:other-name was written (T41-B04)
        return f"its method {brief(method)} is not allowed beside its optimizer {brief(optimizer)}: a run of optimizer user:NAME records method user:NAME"
    if method is not None and optimizer is not None and not users[1] and method not in names[optimizer]:
        return f"its method {brief(method)} is not allowed: optimizer {optimizer!r} evolves by {' or '.join(names[optimizer])}"
    problem = _run_words_problem(meta, own_stop, STOP_REASONS, parse_resampling, (1 + 1e-9) / math.log(ERROR_FLOOR))
    problem = problem or _validation_problem(meta) or _place_problem(meta) or _run_settings_problem(meta)  # T24-02: what evolve adds
    problem = problem or _counts_problem(meta, parse_resampling) or _generations_problem(meta, parse_resampling)  # T26-B04/B06
    return problem or _fields_problem(meta) or _not_json_problem(meta)  # T25-04/05/06/12/14, T32-B17


def _not_json_problem(meta: dict) -> str:
    """A metadata value that is no strict JSON (a NaN or an Infinity at any depth), named by its key: Python's JSON
    reader takes those literals, so a policy file's note of NaN loaded, and save_policy then refused the policy (T32-B17)."""
    from .jsontext import MAX_NOTE_DEPTH, json_text, nesting_depth

    for key, value in meta.items():
        try:
            json_text({key: value})
        except (TypeError, ValueError, RecursionError):
            return f"its {key} {brief(value)} is not allowed: give strict JSON values, numbers finite (NaN and Infinity are no JSON: save_policy refuses them)"
        if nesting_depth(value) > MAX_NOTE_DEPTH:  # a note 600 deep loaded, then the Policy could not be copied or pickled (T33-B03)
            return f"its {key} {brief(value)} is not allowed: it is nested more than {MAX_NOTE_DEPTH} lists or tables deep"
    return ""


def _run_words_problem(meta: dict, own_stop: dict, stop_reasons: tuple, parse_resampling, best_fitness: float) -> str:
    """:func:`policy_record_problem`'s checks of a record's target, resampling, champion_return and stop_reason against its
    method, budget and episodes ('' when they agree)."""
    method, target = meta.get("method"), meta.get("target")
    if target is not None and not isinstance(target, str):
        return f"its target {brief(target)} is not allowed: give the label of the MDP or task family it was evolved on"
    if method == "steady-state" and target is not None and _FAMILY_TARGET.fullmatch(target):
        why = "steady state evolves on one MDP, a task family needs the generational method"
        return f"its method 'steady-state' is not allowed beside its target {brief(target)}: {why}"
    if meta.get("resampling") is not None:
        try:
            selects = parse_resampling(meta["resampling"]).selects if isinstance(meta["resampling"], str) else None
        except ValueError:  # NeurohoverError among them
            selects = None
        if selects is None:
            return f"its resampling {brief(meta['resampling'])} is not allowed: allowed fixed:K, race:DELTA, lucb:DELTA or kl-lucb:DELTA"
        if selects and method is not None and method != "generational":
            return (
                f"its resampling {brief(meta['resampling'])} is not allowed beside its method {brief(method)}: a race or bandit needs the generational method"
            )
    ret = meta.get("champion_return")
    if ret is not None:
        fitness = method in (None, "generational")  # a generational run's champion is on its fitness scale, 1/ln(error) by default
        if not (finite_real(ret) and (-WORST_RETURN <= ret <= 0 or (fitness and 0 < ret <= best_fitness))):
            allowed = f"a return in [{-WORST_RETURN:.3g}, 0] (every reward is minus a sum of squares)"
            allowed += f", or a fitness 1/ln(error) in (0, {best_fitness:.8g}]" if fitness else f" for a {method} run (on the return scale)"
            return f"its champion_return {brief(ret)} is not allowed: allowed {allowed}"
        problem = _lowest_return_problem(meta, "champion_return", ret)
        if problem:
            return problem
    reason = meta.get("stop_reason")
    if reason is None:
        return ""
    if isinstance(method, str) and method.startswith("user:"):  # a user optimiser's own stop is any name it gives (its spec's stop_reason)
        try:  # 'my-stop' was refused, as save_policy saved the champion of the run that stopped by it
            check_name_text("stop_reason", reason, "why the run stopped: budget, or its optimiser's own stop")
        except NeurohoverError as err:
            return f"its {err}"
    elif not isinstance(reason, str) or reason not in stop_reasons:
        return f"its stop_reason {brief(reason)} is not allowed: allowed {', '.join(stop_reasons)} (why the run stopped)"
    budget, episodes = meta.get("budget"), meta.get("episodes")
    if reason == "budget" and "budget" in meta and (budget is None or (episodes is not None and episodes < budget)):
        has = "it has no budget" if budget is None else f"its {episodes:,} episodes are fewer than its budget {budget:,}"
        return f"its stop_reason 'budget' is not allowed: {has} (a run stops by its budget once it has flown it)"
    if reason != "budget" and method in own_stop and reason != own_stop[method]:  # (a user:NAME method's own stop is its own)
        return f"its stop_reason {brief(reason)} is not allowed beside its method {method!r}: allowed budget or {own_stop[method]}"
    return ""


def _validation_problem(meta: dict) -> str:
    """A record's validation of its champion (evolve flies it on validation_episodes fresh episodes after the run and
    records their mean return and its standard deviation, :func:`~neurohover.evolution.evolve.validation_return`) against
    the ranges of such figures and each other ('' when they agree; T24-02)."""
    from .evaluate import MAX_EPISODES_PER_CALL

    episodes: Any = meta.get("validation_episodes")
    ret: Any = meta.get("validation_return")
    sd: Any = meta.get("validation_sd")
    if "validation_episodes" in meta and not (whole_number(episodes) and 1 <= episodes <= MAX_EPISODES_PER_CALL):
        allowed = f"an integer in 1..{MAX_EPISODES_PER_CALL:,} (episodes the champion was validated on)"
        return f"its validation_episodes {brief(episodes)} is not allowed: allowed {allowed}"
    if "validation_return" in meta and not (finite_real(ret) and -WORST_RETURN <= ret <= 0):
        return f"its validation_return {brief(ret)} is not allowed: allowed a mean return in [{-WORST_RETURN:.3g}, 0] (every reward is minus a sum of squares)"
    if "validation_sd" in meta and not (finite_real(sd) and 0 <= sd <= WORST_RETURN / 2):
        return f"its validation_sd {brief(sd)} is not allowed: allowed a standard deviation of returns in [0, {WORST_RETURN / 2:.3g}]"
    if "validation_return" in meta and (low := _lowest_return_problem(meta, "validation_return", ret)):
        return low
    if episodes == 1 and sd is not None and sd != 0:
        return f"its validation_sd {brief(sd)} is not allowed beside its validation_episodes 1: one return has no spread (0)"
    return seconds_problem(meta)


def _lowest_return_problem(meta: dict, name: str, ret: float) -> str:
    """A record's return ``ret`` (its ``name``) against the lowest return of an episode of its length (n_steps, else
    episode_steps; :func:`~neurohover.sim.constants.lowest_return`), '' when within it or the length is not recorded:
    -1e9 of a 20-step run was taken (T27-B03)."""
    steps = [meta[key] for key in ("n_steps", "episode_steps") if whole_number(meta.get(key))]
    if not steps or ret > 0 or ret >= lowest_return(max(steps)):
        return ""
    key = "n_steps" if whole_number(meta.get("n_steps")) else "episode_steps"
    bound = f"{lowest_return(max(steps)):.10g} (the worst step, {CRASH_STEP_PENALTY:.6g}, for each of its {key} {max(steps):,})"
    return f"its {name} {brief(ret)} is not allowed: allowed a return >= {bound}"


def seconds_problem(record: dict) -> str:
    """A record's ``seconds`` (how long the run or build took) against the bound of checkpoints', stored timings' and
    compete summaries' seconds, :data:`~neurohover.sim.constants.MAX_SECONDS` (100 years), '' when it is within it or
    absent: 1e30 was taken in policy files and policy sets' manifests (T26-B13)."""
    seconds: Any = record.get("seconds")
    if "seconds" in record and not seconds_allowed(seconds):
        return f"its seconds {brief(seconds)} is not allowed: allowed a number of seconds >= 0 and <= {MAX_SECONDS:.6g} (100 years: how long it took)"
    return ""


def _place_problem(meta: dict) -> str:
    """A record's task, mdp (what evolve's --mdp or --wind/--params named), target (the label of the MDP or family the
    run evolved on) and mdp_params (that MDP) against each other ('' when they agree; T24-02). mdp_params is checked
    as every MDP is against its label (:mod:`neurohover.tasks.held`); a run over a family has
    none (a champion no longer copies its seed policy's record, T25-12)."""
    from .tasks import task_names

    task, mdp = meta.get("task"), meta.get("mdp")
    target: Any = meta.get("target")
    names = task_names()  # the registry as it is: a family registered at run time too (T46-B07)
    if "task" in meta and not (isinstance(task, str) and task in names):  # T26-B07: 'ghh10' was taken
        return f"its task {brief(task)} is not allowed: allowed {', '.join(names)} (the registered task families)"
    if "mdp" in meta and not isinstance(mdp, str):
        return f"its mdp {brief(mdp)} is not allowed: give what the run was evolved on as text (G, zero, train:N, ...)"
    named = target.partition("/")[0] if isinstance(target, str) and "/" in target else None
    if isinstance(task, str) and named is not None and named != task:
        return f"its task {brief(task)} is not allowed beside its target {brief(target)}: a run evolves on its task's MDPs, here {named}'s"
    problem = _named_mdp_problem(mdp, target, named) or (_task_mdp_problem(task, mdp) if named is None else "")
    if problem:
        return problem
    over_family = mdp == "G" or (isinstance(target, str) and _FAMILY_TARGET.fullmatch(target) is not None)
    if isinstance(mdp, str) and named is not None:
        spec = target.partition("/")[2]
        over = _FAMILY_TARGET.fullmatch(target) is not None
        # beside a target naming one of the family's MDPs, evolve writes that very spec: 'banana', '' or 'TRAIN:0' were
        # taken beside ghh08/train:0 (T30-B02); beside an MDP of its own label, what --wind or --params wrote, as beside a
        # task alone (_task_mdp_problem): 'banana' was taken beside ghh08/wind=[1.0, 2.0]
        agrees = over if mdp == "G" else (spec == mdp if _SPEC.fullmatch(spec) else mdp.startswith(_OWN_MDP) and not over)
        if not agrees:
            return f"its mdp {brief(mdp)} is not allowed beside its target {brief(target)}: the run was evolved on {target.partition('/')[2]!r}"
    if "mdp_params" not in meta:
        return ""
    if over_family:
        return f"its mdp_params {brief(meta['mdp_params'])} is not allowed beside its target {brief(target)}: a run over a family evolves on no one MDP"
    return _mdp_params_problem(meta["mdp_params"], task, target)


#: How the mdp of a run on an MDP of its own label begins: what evolve's --wind and --params write (``wind=1,2``).
_OWN_MDP = ("wind=", "params=")

#: What ``neurohover evolve --mdp`` names as one of a family's MDPs (:meth:`TaskFamily.mdp`), labelled ``TASK/<it>``.
_SPEC = re.compile(r"zero|sample|(?:seeded-)?(?:train|test):[0-9]+")


def _named_mdp_problem(mdp: object, target: object, named: str | None) -> str:
    """A record's target naming a task family that is registered, and its mdp and target's MDP (``train:12``) one its
    family has, by the family's own parser (:meth:`TaskFamily.mdp`): with mdp_params removed, ghh10/train:0 or
    ghh08/train:12 were taken (T26-B07)."""
    from .tasks import get_task_family, task_names

    if named is None:
        return ""
    spec, names = str(target).partition("/")[2], task_names()  # a family registered at run time too (T46-B07)
    if named not in names and (_SPEC.fullmatch(spec) or _FAMILY_TARGET.fullmatch(str(target))):
        return f"its target {brief(target)} is not allowed: {named!r} is no task family (allowed {', '.join(names)}, the registered ones)"
    for key, given in (("mdp", mdp), ("target", spec)):
        if named in names and isinstance(given, str) and _SPEC.fullmatch(given) and given != "sample":  # sample: drawn, any
            try:
                get_task_family(named).mdp(given)
            except NeurohoverError as err:
                return f"its {key} {brief(mdp if key == 'mdp' else target)} is not allowed: {named} has no such MDP ({err})"
    said = _TARGET_SIGMA.fullmatch(str(target))
    return _target_sigma_problem(str(target), named, said.group(1)) if said is not None and named in names else ""


#: A family target's breadth, as :meth:`Run.result <neurohover.evolution.run.Run.result>` writes it: ``fghh/G(sigma=0.3)``.
_TARGET_SIGMA = re.compile(r"[a-z0-9]+/G\(sigma=([^()]*)\)")


def _target_sigma_problem(target: str, named: str, text: str) -> str:
    """The sigma a family target names, ``G(sigma=...)``, checked as the record's sigma key is (by the family's own
    check, :class:`~neurohover.tasks.fghh.FGHH`) and written as a run writes it ('%g'): ghh08/G(sigma=0.3) and
    fghh/G(sigma=5), -1, nan or abc were taken (T53-B02/B03). Its agreement with the sigma key: :func:`_fields_problem`."""
    from .tasks import get_task_family

    if not get_task_family(named).has_sigma:
        return f"its target {brief(target)} is not allowed: {named}'s MDPs have no breadth (sigma is FGHH's); allowed {named}/G"
    value: Any = text  # refused by the family's check as written where it is no number
    for number in (int, float):  # 5 named as 5, not 5.0
        try:
            value = number(text)
            break
        except ValueError:
            pass
    try:
        get_task_family(named, value)
    except NeurohoverError as err:
        return f"its target {brief(target)} is not allowed: {err}"
    if f"{value:g}" != text:  # ' 0.3', '0.30' or '3e-1': a run writes '%g', which the sigma key is compared with
        return f"its target {brief(target)} is not allowed: its sigma {text!r} is not written as a run writes it; allowed {named}/G(sigma={value:g})"
    return ""


def _task_mdp_problem(task: object, mdp: object) -> str:
    """A record's mdp, with no target naming a family, against its task as a target's is against the target's family
    (:func:`_named_mdp_problem`): one of the task's MDPs by its parser (:meth:`TaskFamily.mdp`), G, sample, or what
    evolve's --wind and --params write; train:99, banana or '' beside ghh08 were taken (T53-B01)."""
    from .tasks import get_task_family, task_names

    if not (isinstance(task, str) and task in task_names() and isinstance(mdp, str)):
        return ""  # a task refused by _place_problem; an mdp that is no text too
    if mdp in ("G", "sample") or mdp.startswith(_OWN_MDP):
        return ""
    try:
        get_task_family(task).mdp(mdp)
    except NeurohoverError as err:
        also = "or G (its family), wind=U,V or params=... (what evolve's --wind and --params write)"
        return f"its mdp {brief(mdp)} is not allowed beside its task {brief(task)}: {task} has no such MDP ({err}); {also}"
    return ""


def _mdp_params_problem(params: object, task: object, target: object) -> str:
    """A record's mdp_params (the MDP a run evolved on, as :meth:`MDP.to_dict` writes it) against its task and target,
    and against its own label as flight data's MDPs are checked (T24-02)."""
    from .tasks import MDP

    try:
        mdp = MDP.from_dict(params) if isinstance(params, dict) else None
    except NeurohoverError as err:
        return f"its mdp_params {brief(params)} is not allowed: {err}"
    if mdp is None:
        return f"its mdp_params {brief(params)} is not allowed: give the MDP the run was evolved on as a table (MDP.to_dict)"
    if isinstance(target, str) and mdp.label != target:
        return f"its mdp_params label {brief(mdp.label)} is not allowed beside its target {brief(target)}: the run was evolved on its target"
    if isinstance(task, str) and mdp.family != task:
        return f"its mdp_params family {brief(mdp.family)} is not allowed beside its task {brief(task)}: a run evolves on its task's MDPs"
    if not mdp.drift.none:  # evolve refuses a drifting target, yet {"walk": 0.01} was taken (T41-B05)
        why = "evolution flies fixed dynamics (drift is flown by test runs), so no run evolved on it"
        return f"its mdp_params drift {brief(params.get('drift') if isinstance(params, dict) else None)} is not allowed: {why}; allowed none (leave drift out)"
    return ""


def _run_settings_problem(meta: dict) -> str:
    """A record's settings (the optimiser's, as the run used them), champion_fitness_scale and episode_steps against its
    method, optimizer, champion_return and n_steps ('' when they agree; T24-02): settings are checked as ``evolve`` checks
    them (:func:`~neurohover.evolution.config.make_settings`)."""
    from .evolution.fitness import FITNESS_SCALES

    method, settings = meta.get("method"), meta.get("settings")
    steps: Any = meta.get("episode_steps")
    n_steps: Any = meta.get("n_steps")
    if "episode_steps" in meta and n_steps is not None and steps != n_steps:
        why = "evolve flies the run's and the validation's episodes at one length"
        return f"its n_steps {brief(n_steps)} is not allowed beside its episode_steps {brief(steps)}: {why}"
    if "settings" in meta and not isinstance(settings, dict):
        return f"its settings {brief(settings)} is not allowed: give the optimiser's settings as a table"
    try:
        _recorded_settings(meta)
    except NeurohoverError as err:
        return f"its settings {brief(settings)} is not allowed: {err}"
    scale = meta.get("champion_fitness_scale")
    ret: Any = meta.get("champion_return")
    if "champion_fitness_scale" not in meta:
        return ""
    if not isinstance(scale, str) or scale not in FITNESS_SCALES:
        return f"its champion_fitness_scale {brief(scale)} is not allowed: allowed {', '.join(FITNESS_SCALES)} (the scale of its champion_return)"
    fitness = settings.get("fitness") if isinstance(settings, dict) and method == "generational" else None
    own = fitness if fitness is not None else ("return" if method not in (None, "generational") else None)
    if own is not None and scale != own:
        return f"its champion_fitness_scale {brief(scale)} is not allowed beside its method {brief(method)}: its run's champions are on the {own} scale"
    if finite_real(ret) and (scale == "return") != (ret <= 0):
        why = "a return is <= 0" if scale == "return" else "a fitness 1/ln(error) is > 0"
        return f"its champion_return {brief(ret)} is not allowed beside its champion_fitness_scale {brief(scale)}: {why}"
    return ""


def _recorded_settings(meta: dict) -> Any:
    """The optimiser settings a record's run used, made of its settings as ``evolve`` makes them
    (:func:`~neurohover.evolution.config.make_settings`: its table over the defaults); None where it records none (or no
    optimiser to read them by), NeurohoverError where they are not allowed."""
    from .evolution.config import make_settings
    from .evolution.optimisers import NE, USER_NAME

    method, settings = meta.get("method"), meta.get("settings")
    optimizer = meta.get("optimizer", NE if method in ("steady-state", "generational") else None)
    if not (isinstance(settings, dict) and optimizer is not None and (optimizer != NE or method is not None)):
        return None
    if isinstance(optimizer, str) and USER_NAME.fullmatch(optimizer):  # a user's optimiser: its settings class may not be here
        return None
    given = {k: v for k, v in settings.items() if not (optimizer == NE and k == "budget" and v is None)}  # NE's: the run counts its budget
    return make_settings("steady-state" if method == "steady-state" else "generational", optimizer, given)


def _generations_problem(meta: dict, parse_resampling) -> str:
    """A neuroevolution record's generations against its evaluations, and its episodes against its budget, by the
    settings it records ('' when they agree, or where it records none). Steady state's generation g is
    :func:`~neurohover.evolution.steady_state.steady_state_evaluations` evaluations (the rule a checkpoint is held to),
    generational NE's g x pop_size: generations 40 beside 50 evaluations of pop_size 50, elite_size 49 were taken
    (T26-B04). A run asks its budget at each generation boundary and stops at the first at or past it (:func:`~neurohover.
    evolution.restore.stop_reason`): with fixed:K, its episodes are at most budget - 1 plus a generation's K x offspring,
    or its first generation's K x pop_size, and a run stopped otherwise had not reached it (any method, settings or
    none); 5,000 episodes of a budget of 10, or 1,000 of a plateau's stop, were taken (T26-B06). A chain set's ancestor
    sums the episodes of its stages (one run each over the training MDPs), each so bounded."""
    from .evolution.steady_state import steady_state_evaluations
    from .tasks.base import N_TRAINING

    method, reason, budget, episodes = meta.get("method"), meta.get("stop_reason"), meta.get("budget"), meta.get("episodes")
    ancestor = meta.get("name") == "ancestor"
    if reason not in (None, "budget") and whole_number(budget) and whole_number(episodes) and episodes >= budget and not ancestor:
        why = "they reached it, and a run asks its budget first at each generation boundary"
        return f"its stop_reason {brief(reason)} is not allowed beside its {episodes:,} episodes and budget {budget:,}: {why}; allowed budget"
    try:
        made = _recorded_settings(meta) if method in ("steady-state", "generational") else None
    except NeurohoverError:
        made = None  # (refused by _run_settings_problem)
    if made is None:
        return ""
    steady, pop = method == "steady-state", made.pop_size
    offspring = pop - made.elite_size if steady else pop
    generations, evaluations = meta.get("generations"), meta.get("evaluations")
    sizes = f"pop_size {pop}" + (f", then {offspring} a generation" if steady else " a generation")
    if whole_number(generations) and whole_number(evaluations):
        made_evaluations = steady_state_evaluations(generations, pop, made.elite_size) if steady else generations * pop
        if made_evaluations != evaluations:
            return (
                f"its generations {brief(generations)} is not allowed beside its evaluations {brief(evaluations)}: generation {generations:,} of "
                f"a {method} run is {made_evaluations:,} evaluations ({sizes}, by its settings)"
            )
    resampling = meta.get("resampling")
    fixed = isinstance(resampling, str) and resampling.strip().lower().startswith("fixed:")
    if not (fixed and whole_number(budget) and whole_number(episodes)):
        return ""
    k = parse_resampling(resampling).k
    most = max(k * pop, budget - 1 + k * offspring)  # the first generation past the budget, or the one that crossed it
    stages = N_TRAINING if ancestor else 1
    if episodes > stages * most:
        each = f"at most {most:,} episodes" + (f" in each of its {stages} stages" if stages > 1 else "")
        return (
            f"its episodes {brief(episodes)} is not allowed beside its budget {budget:,}: a run stops at the first generation boundary at or "
            f"past its budget, here after {each} ({method}, {resampling}, {sizes})"
        )
    return ""


#: Keys no policy file is written with that read as settings a policy file would hold: never read, they misled (T25-12).
_NOT_POLICY_KEYS = {
    "format": "policy files carry no format tag (a model file's or a summary's key?)",
    "obs_noise": "a policy file records the sensor its run saw as 'sensor' (a table of Sensor.to_dict)",
    "obs_delay": "a policy file records the sensor its run saw as 'sensor' (a table of Sensor.to_dict)",
}


def _counts_problem(meta: dict, parse_resampling) -> str:
    """A record's episodes and evaluations against its resampling fixed:K (each evaluation flies K episodes), and a
    steady-state stop by plateau against its plateau_threshold (T25-06): fixed:3 beside 50 episodes of 50 evaluations, or
    a plateau after 50 evaluations at a threshold of 1000, were accepted. A chain set's ancestor (name 'ancestor') records
    the episodes of all its stages and the evaluations of its last: its episodes may be more."""
    episodes, evaluations, resampling = meta.get("episodes"), meta.get("evaluations"), meta.get("resampling")
    if isinstance(resampling, str) and resampling.strip().lower().startswith("fixed:") and whole_number(episodes) and whole_number(evaluations):
        k = parse_resampling(resampling).k
        if episodes != k * evaluations and not (meta.get("name") == "ancestor" and episodes > k * evaluations):
            return (
                f"its episodes {brief(episodes)} is not allowed beside its evaluations {brief(evaluations)} and resampling {brief(resampling)}: "
                f"each evaluation flies {k} episode{'s' if k != 1 else ''}, {k * evaluations:,} in all"
            )
    settings = meta.get("settings")
    threshold = settings.get("plateau_threshold") if isinstance(settings, dict) else None
    if meta.get("stop_reason") == "plateau" and meta.get("method") == "steady-state" and whole_number(threshold) and whole_number(evaluations):
        if evaluations < threshold:
            return (
                f"its stop_reason 'plateau' is not allowed beside its evaluations {brief(evaluations)} and settings' plateau_threshold "
                f"{brief(threshold)}: steady state stops by plateau after plateau_threshold evaluations without a new champion"
            )
    return ""


def _fields_problem(meta: dict) -> str:
    """A record's sensor (read as :meth:`Sensor.from_dict <neurohover.tasks.sensor.Sensor.from_dict>` reads it; T25-04),
    sigma (checked by the FGHH family, against its task and its target's ``G(sigma=...)``; T25-05), prototype as evolve
    writes it (T39-B05) and against its seed_policy (T25-06), seed_policy and history as what evolve writes (T25-14), and keys no policy file holds (T25-12)."""
    from dataclasses import fields

    from .tasks import MDP, get_task_family
    from .tasks.fghh import FGHH
    from .tasks.sensor import Sensor

    bad = next((key for key in _NOT_POLICY_KEYS if key in meta), None)
    if bad is not None:
        return f"its {bad} {brief(meta[bad])} is not allowed: {_NOT_POLICY_KEYS[bad]}"
    if "sensor" in meta:
        try:
            sensor = Sensor.from_dict(meta["sensor"])
        except NeurohoverError as err:
            return f"its sensor {brief(meta['sensor'])} is not allowed: {err}"
        params = meta.get("mdp_params")
        held = MDP.from_dict(params).sensor if isinstance(params, dict) else sensor  # (mdp_params checked by _place_problem)
        if held != sensor:  # T26-B08: a delay of 5 beside mdp_params' 2 was taken
            key = next(f.name for f in fields(Sensor) if getattr(sensor, f.name) != getattr(held, f.name))
            why = "the run's MDP was seen through the run's sensor"
            return f"its sensor's {key} {brief(getattr(sensor, key))} is not allowed beside its mdp_params' sensor's {brief(getattr(held, key))}: {why}"
    task, target = meta.get("task"), meta.get("target")
    if "sigma" in meta:
        sigma = meta["sigma"]
        try:
            FGHH(sigma=sigma)
        except NeurohoverError as err:
            return f"its sigma {brief(sigma)} is not allowed: {err}"
        # no task: its target's family, as the API's evolve writes a target alone ('ghh08/train:0' took a sigma; T42-B06)
        named = task if "task" in meta else target.partition("/")[0] if isinstance(target, str) and "/" in target else None
        try:
            family = get_task_family(named) if isinstance(named, str) else None
        except NeurohoverError:  # no task's name: left to the place checks
            family = None
        if family is not None and not family.has_sigma:  # a seeded champion no longer carries its seed's sigma (T25-12)
            beside = f"task {brief(task)}" if "task" in meta else f"target {brief(target)}"
            return f"its sigma {brief(sigma)} is not allowed beside its {beside}: {named}'s MDPs have no breadth (sigma is FGHH's)"
        said = re.fullmatch(r"[a-z0-9]+/G\(sigma=([^()]*)\)", target) if isinstance(target, str) else None
        if said is not None and f"{float(sigma):g}" != said.group(1):
            return f"its sigma {brief(sigma)} is not allowed beside its target {brief(target)}: the run was evolved over G(sigma={said.group(1)})"
    seed_policy, proto = meta.get("seed_policy"), meta.get("prototype")
    if "seed_policy" in meta and (not isinstance(seed_policy, str) or seed_policy == ""):
        return f"its seed_policy {brief(seed_policy)} is not allowed: give what the run was seeded from as text (zero, baseline or a policy file)"
    if "prototype" in meta and not (isinstance(proto, str) and proto in ("zero", "baseline")):  # 3 and 'zzz' were saved and loaded (T39-B05)
        return (
            f"its prototype {brief(proto)} is not allowed: give where the run's lineage started, zero or baseline "
            "(neurohover.policies.prototype's seeds, which evolve writes and carries on), or leave it out"
        )
    if seed_policy in ("zero", "baseline") and "prototype" in meta and proto != seed_policy:
        return f"its prototype {brief(proto)} is not allowed beside its seed_policy {brief(seed_policy)}: a run seeded from {seed_policy} has its prototype"
    history = meta.get("history")
    if "history" in meta and not (isinstance(history, str) and history.endswith(".history.csv") and Path(history).name == history and "\\" not in history):
        return f"its history {brief(history)} is not allowed: give the name (no folder) of the run's history file beside it, ending .history.csv"
    return ""


RECORD_CHECKS["policy_record_problem"] = policy_record_problem  # every policy file load_policy reads is checked by it (T23-11)
