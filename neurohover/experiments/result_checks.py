"""Checks of stored results (:mod:`~neurohover.experiments.results`): a stored value against its field's annotation,
a test run's, an evolution run's and a robustness unit's parts against each other, and a result against its unit's
params."""

from __future__ import annotations

import dataclasses
import math
from typing import TYPE_CHECKING, Any

from ..compete_labels import NO_OFFLINE, NO_SAFEGUARD, policy_label_problem
from ..errors import NeurohoverError, brief, finite_real, whole_number
from ..integrations.neat import NEAT_TOPOLOGY
from ..sim.constants import CRASH_STEP_PENALTY, MAX_SECONDS, WORST_RETURN, crash_charge, crash_return_ceiling, lowest_return, seconds_allowed

if TYPE_CHECKING:
    from .results import EvolveResult, ModelResult, RobustnessResult, TestRunResult


def _num(v) -> bool:
    """A stored number: an int or float, or a non-finite one as :func:`enc_float`-style text."""
    return (isinstance(v, (int, float)) and not isinstance(v, bool)) or v in ("nan", "inf", "-inf")


def _int(v) -> bool:
    return isinstance(v, int) and not isinstance(v, bool)


#: Checks of a stored value by its field's annotation (the simple ones; others are read as they are).
KIND_CHECKS: dict[str, Any] = {
    "str": lambda v: isinstance(v, str),
    "int": _int,
    "Num": _num,
    "tuple[Num, ...]": lambda v: isinstance(v, list) and all(map(_num, v)),
    "tuple[int, ...]": lambda v: isinstance(v, list) and all(map(_int, v)),
    "tuple[int, ...] | None": lambda v: v is None or (isinstance(v, list) and all(map(_int, v))),
}


def run_inconsistency(run: TestRunResult) -> str:
    """What in test run ``run`` does not fit together ('' when all does): the score is the sum of the returns, the episodes
    named are among them, one crash step per crash; each return is an episode's (finite, at most 0: returns [5, 7, 1] were
    reported as a mean; T22-05)."""
    n = len(run.returns)
    if n == 0:
        return "it holds no episode's return"
    try:
        total = math.fsum(float(r) for r in run.returns)
    except OverflowError:  # returns of 1e308 (eighth trial)
        return "its returns sum past a float's range"
    if not math.isclose(float(run.score), total, rel_tol=1e-9, abs_tol=1e-6):
        return f"its score {run.score!r:.20} is not the sum of its {n} returns"
    for i, r in enumerate(run.returns):
        if not (math.isfinite(float(r)) and -WORST_RETURN <= float(r) <= 0):
            allowed = f"allowed a finite number in [{-WORST_RETURN:.3g}, 0] (every reward is minus a sum of squares)"
            return f"returns[{i}] = {brief(r)} is no episode's return: {allowed}"
    for name in ("crash_episodes", "safeguard_episodes"):
        episodes = getattr(run, name)
        outside = [e for e in episodes if not 0 <= e < n]
        if outside:
            return f"{name} names episode {outside[0]!r}, outside 0..{n - 1}"
        if list(episodes) != sorted(set(episodes)):  # [1, 1] was counted as two crashes (T22-07)
            return f"{name} = {brief(list(episodes))} is not allowed: each episode of 0..{n - 1} at most once, in order"
    problem = _changes_problem(run.policy_changes, n)
    if problem:
        return problem
    for i, (_, policy) in enumerate(run.policy_changes):  # T25-09: 'specialised:3' of authors-zero, 'model:0' of generic were taken
        problem = policy_label_problem(run.agent, policy)
        if problem:
            return f"policy_changes[{i}]: {problem}"
    if run.crash_steps is not None and len(run.crash_steps) != len(run.crash_episodes):
        return f"{len(run.crash_steps)} crash steps for {len(run.crash_episodes)} crash episodes"
    for i, step in enumerate(run.crash_steps or ()):
        if step < 1:  # the kernel counts the crashing control step from 1 (its unit's params bound it: params_problem)
            return f"crash_steps[{i}] = {step!r} is not allowed: a crash ends its episode at control step 1 or later"
    if run.agent in NO_SAFEGUARD and run.safeguard_episodes:  # the baseline's run was stored with safeguard episodes (T23-14)
        return f"safeguard_episodes = {brief(list(run.safeguard_episodes))} is not allowed: agent {run.agent} flies under no safeguard: allowed []"
    seconds, offline = float(run.timing.seconds), float(run.timing.offline_seconds)
    if offline > seconds * (1 + 1e-9) + 1e-6:  # the agent's work between episodes is part of the run's time (T23-14)
        return (
            f"timing.offline_seconds = {brief(run.timing.offline_seconds)} is not allowed: it is "
            f"part of the run's timing.seconds {brief(run.timing.seconds)}: allowed at most that"
        )
    return _after_learning_problem(run)


def _changes_problem(changes: Any, n: int) -> str:
    """'' when ``changes`` are a run of ``n`` episodes' policy changes: (episode, policy) pairs of episodes in 0..n-1, in
    order, each once, and a policy's name, the first at episode 0; else what is wrong ([[50, 'x'], [-1, '']] of a 3-episode
    run was taken; T22-09)."""
    last = -1
    for i, change in enumerate(changes):
        episode, policy = change if isinstance(change, tuple) and len(change) == 2 else (None, None)
        if not (whole_number(episode) and last < episode < n and isinstance(policy, str) and policy):
            shown = brief(list(change) if isinstance(change, tuple) else change)
            return f"policy_changes[{i}] = {shown} is not allowed: give [episode, policy name], its episodes among 0..{n - 1}, in order, each once"
        last = episode
    if not changes or changes[0][0] != 0:  # T27-B09: [] and [[2, 'specialised:2']] of a 3-episode run were taken
        which = f"policy_changes[0] = {brief(list(changes[0]))}" if changes else "policy_changes = []"
        return f"{which} is not allowed: every episode flies a policy, so the changes start at episode 0: give [0, policy name] first"
    return ""


def seconds_problem(timing: Any) -> str:
    """'' when every field of the record ``timing`` is a finite number of seconds >= 0 (T22-09) and at most MAX_SECONDS
    (100 years, as a checkpoint's: 1e300 was taken, T24-07), else which is not."""
    for f in dataclasses.fields(timing):
        value = getattr(timing, f.name)
        if seconds_allowed(value):
            continue
        if not (finite_real(value) and value >= 0):
            return f"timing.{f.name} = {brief(value)} is not allowed: give a finite number of seconds >= 0"
        return f"timing.{f.name} = {brief(value)} is not allowed: at most {MAX_SECONDS:.6g} seconds (100 years: no run lasts longer)"
    return ""


def _after_learning_problem(run: TestRunResult) -> str:
    """'' when the run's learning episodes are among its episodes (the episode from which its policy no longer changed)
    and its mean return after learning is the mean of its returns from there; else what contradicts them (a NaN or -1e9
    mean was exported, printed as bare NaN in JSON; T22-06)."""
    n, start = len(run.returns), run.learning_episodes
    if not 0 <= start < n:
        return f"learning_episodes = {start!r} is outside 0..{n - 1} (the episode from which its policy no longer changed)"
    mean = math.fsum(float(r) for r in run.returns[start:]) / (n - start)
    if not math.isclose(float(run.mean_return_after_learning), mean, rel_tol=1e-9, abs_tol=1e-6):
        return (
            f"mean_return_after_learning = {brief(run.mean_return_after_learning)} is not the mean of its returns after its "
            f"{start} learning episode(s): allowed {mean!r}"
        )
    return ""


def _params_says(params: dict, name: str) -> Any:
    """What a unit's params say its result's ``name`` is (the MDP: its table's label; None where they do not say)."""
    if name == "mdp":
        mdp = params.get("mdp")
        return mdp.get("label") if isinstance(mdp, dict) else None
    return params.get(name)


def identity_problem(kind: Any, result: Any, params: Any) -> str:
    """What names another run than the unit's ``params`` in its ``result`` of ``kind`` (as stored, a dict, or read): a
    test run's agent or MDP, a model's method or MDP ('' when none does, or for another kind). Compared before the
    result's own consistency: a test run whose agent was edited was blamed on its sound policy_changes (T55-A04)."""
    names = {"test_run": ("agent", "mdp"), "model": ("method", "mdp")}.get(kind, ()) if isinstance(params, dict) else ()
    for name in names:
        says = _params_says(params, name)
        held = result.get(name) if isinstance(result, dict) else getattr(result, name, None)
        if isinstance(says, str) and isinstance(held, str) and held != says:
            where = "params.mdp.label" if name == "mdp" else f"params.{name}"
            return f"{name} = {brief(held)} is not allowed: its unit's {where} is {brief(says)}, and a result must be its unit's"
    return ""


def params_problem(result: Any, params: Any) -> str:
    """What in a stored unit's ``result`` contradicts the unit's own ``params`` ('' when nothing does; params of another
    shape are the plan check's to name): a test run's agent or MDP, or a model's method or MDP, other than its params
    say (a run of model-free on ghh08/test:0 holding agent 'baseline' and mdp 'ghh09/test:7' was exported; T22-08), offline
    seconds of an agent that does none (:data:`~neurohover.compete_labels.NO_OFFLINE`; T24-07), or a crash at a step past
    its episodes' ``n_steps`` (999999 of 20 was reported; T22-07); an evolution run's or a
    robustness unit's figures that contradict its params (T23-08: :func:`evolve_params_problem`,
    :func:`robustness_params_problem`)."""
    from .results import EvolveResult, ModelResult, RobustnessResult, TestRunResult

    if isinstance(result, EvolveResult) and isinstance(params, dict):
        return evolve_params_problem(result, params)
    if isinstance(result, RobustnessResult) and isinstance(params, dict):
        return robustness_params_problem(result, params)
    if not (isinstance(result, (TestRunResult, ModelResult)) and isinstance(params, dict)):
        return ""
    problem = identity_problem("test_run" if isinstance(result, TestRunResult) else "model", result, params)
    if problem:
        return problem
    if isinstance(result, TestRunResult) and result.agent in NO_OFFLINE and float(result.timing.offline_seconds) != 0:
        return (  # its update is never called (T24-07: as plot --compete reads a summary); after its agent against its params
            f"timing.offline_seconds = {brief(result.timing.offline_seconds)} is not allowed: agent {result.agent} does no work between "
            "episodes (its first choice holds for the whole run): allowed 0"
        )
    n_steps = params.get("n_steps")
    if isinstance(result, TestRunResult) and whole_number(n_steps):
        lowest = lowest_return(n_steps)  # T27-B03: -1e9 of a 20-step run was reported
        for i, r in enumerate(result.returns):
            if float(r) < lowest:
                bound = f"{lowest:.10g} (the worst step, {CRASH_STEP_PENALTY:.6g}, for each of its {n_steps} steps)"
                return f"returns[{i}] = {brief(r)} is not allowed: its unit's episodes are {n_steps} control steps long: allowed at least {bound}"
        for i, step in enumerate(result.crash_steps or ()):
            if not 1 <= step <= n_steps:
                return f"crash_steps[{i}] = {step!r} is not allowed: its unit's episodes are {n_steps} control steps long: allowed 1..{n_steps}"
            e = result.crash_episodes[i]
            if float(result.returns[e]) > crash_return_ceiling(n_steps, step):  # sim.kernel.crash_charge: none for a crash on the last step (T26-B09)
                return (
                    f"returns[{e}] = {brief(result.returns[e])} is not allowed: episode {e} crashed at step {step} of its {n_steps}, and a crash is "
                    f"charged {CRASH_STEP_PENALTY:.6g} for each step left: allowed at most {crash_charge(n_steps, step):.10g}"
                )
    return ""


def _lists(value: Any) -> Any:
    """Tuples (nested) as lists, to show a stored value as the store holds it."""
    return [_lists(v) for v in value] if isinstance(value, tuple) else value


def _close(a: float, b: float) -> bool:
    """Whether two stored figures are one (floats round; infinities of one sign are equal, NaNs are not)."""
    return a == b or math.isclose(a, b, rel_tol=1e-9, abs_tol=1e-6)


def _returns_problem(name: str, returns: Any) -> str:
    """'' when ``returns`` are episodes' returns (each a number in [-WORST_RETURN, 0], or NaN: a numerical blow-up, which
    stored validations keep as 'nan'), else which is not."""
    for i, r in enumerate(returns):
        if not (_num(r) and (math.isnan(float(r)) or -WORST_RETURN <= float(r) <= 0)):
            allowed = f"allowed a number in [{-WORST_RETURN:.3g}, 0] or nan (every reward is minus a sum of squares)"
            return f"{name}[{i}] = {brief(r)} is no episode's return: {allowed}"
    return ""


def _validation_problem(where: str, validation: Any, crashed: Any) -> str:
    """'' when ``validation`` (None: none asked for) are episodes' returns and ``crashed`` (None: not recorded) one flag
    each of them, else what is not."""
    if validation is None:
        return "" if crashed is None else f"{where}validation_crashed = {brief(_lists(crashed))} is not allowed: it holds no validation: allowed null"
    problem = _returns_problem(f"{where}validation", validation)
    if problem or crashed is None:
        return problem
    if not (isinstance(crashed, tuple) and len(crashed) == len(validation) and all(isinstance(c, bool) for c in crashed)):
        return (
            f"{where}validation_crashed = {brief(_lists(crashed))} is not allowed: give one true or false for each of its {len(validation)} validation episodes"
        )
    return ""


def _fitness_problem(name: str, value: Any, scale: Any) -> str:
    """'' when ``value`` is a fitness on ``scale`` (the result's ``fitness``; None: raw returns), else why not: on
    inv-log-error ``1/ln(error)`` is in (0, 1/ln(ERROR_FLOOR)], on returns every value is at most 0; -inf (a NaN episode's
    fitness) and NaN are not refused."""
    from ..evolution.fitness import ERROR_FLOOR

    v = float(value)
    if scale == "inv-log-error":
        top = 1.0 / math.log(ERROR_FLOOR)
        if v == -math.inf or 0 < v <= top * (1 + 1e-9) or math.isnan(v):
            return ""
        return (
            f"{name} = {brief(value)} is not allowed: on its fitness scale inv-log-error a fitness is 1/ln(error): allowed a number in (0, {top:.7g}] or -inf"
        )
    if v > 0 or -WORST_RETURN > v > -math.inf:
        what = "its fitness scale return" if scale == "return" else "raw returns (no fitness scale)"
        return f"{name} = {brief(value)} is not allowed: on {what} it is a mean return: allowed a number in [{-WORST_RETURN:.3g}, 0] or -inf"
    return ""


def _history_problem(run: EvolveResult) -> str:
    """'' when the run's history is its (episodes, champion fitness) records, their episodes increasing within
    1..its episodes and the last at its episodes (its last generation), else what is not."""
    episodes, last = run.episodes, 0
    if not run.history:
        return "its history is empty: a run records its last generation at least"
    for i, entry in enumerate(run.history):
        if not (isinstance(entry, tuple) and len(entry) == 2 and _int(entry[0]) and last < entry[0] <= episodes and _num(entry[1])):
            shown = brief(list(entry) if isinstance(entry, tuple) else entry)
            return (
                f"history[{i}] = {shown} is not allowed: give [episodes, champion fitness], its episodes increasing within 1..{episodes} (the run's episodes)"
            )
        problem = _fitness_problem(f"history[{i}]'s champion fitness", entry[1], run.fitness)
        if problem:
            return problem
        last = entry[0]
    if last != episodes:
        return (
            f"history[{len(run.history) - 1}] = {brief(list(run.history[-1]))} is not allowed: "
            f"a run's history ends at its last generation, at its {episodes} episodes"
        )
    return ""


def evolve_inconsistency(run: EvolveResult) -> str:
    """What in evolution run ``run`` does not fit together ('' when all does; T23-08: a hand-edited run was exported and
    reported): a stop reason the evolution gives (:data:`~neurohover.evolution.restore.STOP_REASONS`), a fitness scale
    it knows, one generation at least, evaluating a candidate at least each and flying an episode at least per
    evaluation; a history of increasing episodes ending at the run's; a champion fitness on its scale that is its
    history's last (NEAT's: the best genome ever, at least its history's best generation); kernel seconds within its
    seconds; validation returns that are episodes' returns, with one crash flag each."""
    from ..evolution.fitness import FITNESS_SCALES
    from ..evolution.restore import STOP_REASONS

    if run.stop_reason not in STOP_REASONS:
        return f"stop_reason = {brief(run.stop_reason)} is not allowed: allowed one of {', '.join(STOP_REASONS)} (why the evolution stops)"
    if run.fitness is not None and run.fitness not in FITNESS_SCALES:
        return f"fitness = {brief(run.fitness)} is not allowed: allowed one of {', '.join(FITNESS_SCALES)}, or none (raw returns)"
    if run.champion_crashed is not None and not isinstance(run.champion_crashed, bool):
        return f"champion_crashed = {brief(run.champion_crashed)} is not allowed: allowed true, false or none (not recorded)"
    g, ev, e = run.generations, run.evaluations, run.episodes
    if not 1 <= g <= e:
        return (
            f"generations = {g!r} is not allowed: a run stops at a generation boundary, after one generation "
            f"at least, each flying an episode at least, and it flew {e} episodes: allowed 1..{e}"
        )
    if not g <= ev <= e:
        return (
            f"evaluations = {ev!r} is not allowed: each of its {g} generations evaluates a candidate at "
            f"least, each evaluation flies an episode at least, and it flew {e} episodes: allowed {g}..{e}"
        )
    problem = _fitness_problem("champion_return", run.champion_return, run.fitness) or _history_problem(run)
    if problem:
        return problem
    champion, returns = float(run.champion_return), [float(r) for _, r in run.history]
    if run.champion.topology == "neat":  # NEAT's champion is the best genome ever; its history each generation's best
        if champion < max(returns) and not _close(champion, max(returns)):
            return (
                f"champion_return = {brief(run.champion_return)} is not allowed: its history's best generation "
                f"reached {max(returns)!r}, and a NEAT champion is the best genome ever: allowed at least that"
            )
    elif not (_close(champion, returns[-1]) or (math.isnan(champion) and math.isnan(returns[-1]))):
        return (
            f"champion_return = {brief(run.champion_return)} is not allowed: its history "
            f"ends at {run.history[-1][1]!r}, the champion's fitness at its last generation"
        )
    seconds, kernel = float(run.timing.seconds), float(run.timing.kernel_seconds)
    if kernel > seconds * (1 + 1e-9) + 1e-6:  # each kernel call is timed within the run (T24-09; a checkpoint's too, T21-03)
        return (
            f"timing.kernel_seconds = {brief(run.timing.kernel_seconds)} is not allowed: it is part of the run's "
            f"timing.seconds {brief(run.timing.seconds)}: allowed at most that"
        )
    problem = _validation_problem("", run.validation, run.validation_crashed)
    for name in ("reevaluated", "reevaluated_best_ever"):
        again = getattr(run, name)
        if again is not None and not problem:
            problem = _validation_problem(f"{name}.", again.validation, again.validation_crashed)
    return problem


def _policies(run: EvolveResult) -> list[tuple[str, Any]]:
    """The run's stored policies by name: its champion, and the champions chosen again."""
    found = [("champion", run.champion)]
    for name in ("reevaluated", "reevaluated_best_ever"):
        again = getattr(run, name)
        if again is not None:
            found.append((f"{name}.champion", again.champion))
    return found


def _budget_problem(run: EvolveResult, params: dict) -> str:
    """'' when the run's episodes fit its unit's budget, resampling and stop reason, else what contradicts them: a run
    stops at the first generation boundary at or past its budget (by 'budget'), or before it by its optimiser; its last
    generation flew at most its resampling's episodes (fixed:K: K; a race or bandit: RACE_T_LIMIT) for each of its
    evaluations that its earlier generations (one at least each) did not have. NEAT flies whole generations within it."""
    from ..evolution.config import RACE_T_LIMIT, parse_resampling

    budget, e, ev, g = params.get("budget"), run.episodes, run.evaluations, run.generations
    try:
        resampling = parse_resampling(params.get("resampling"))
    except (NeurohoverError, TypeError):  # params of another shape are the plan check's to name
        return ""
    if resampling.kind == "fixed" and e != resampling.k * ev:
        return (
            f"episodes = {e!r} is not allowed: its unit's resampling is {resampling}, {resampling.k} "
            f"episode(s) an evaluation, and it made {ev} evaluations: allowed {resampling.k * ev}"
        )
    if not (whole_number(budget) and budget >= 0):
        return ""
    if run.champion.topology == "neat":
        if budget and e > budget:
            return (
                f"episodes = {e!r} is not allowed: its unit's budget is {budget} episodes, and NEAT flies whole generations within it: allowed at most {budget}"
            )
        return ""
    if not budget:
        return f"stop_reason = 'budget' is not allowed: its unit has no budget (params.budget {budget!r})" if run.stop_reason == "budget" else ""
    if run.stop_reason != "budget":
        if e >= budget:
            return (
                f"episodes = {e!r} is not allowed: it stopped by {run.stop_reason!r} before its unit's budget "
                f"of {budget} episodes (a run at or past it stops by 'budget'): allowed fewer than {budget}"
            )
        return ""
    top = budget - 1 + (RACE_T_LIMIT if resampling.selects else resampling.k) * (ev - g + 1)
    if not budget <= e <= top:
        return (
            f"episodes = {e!r} is not allowed: it stopped by its unit's budget of {budget} episodes, at the first generation boundary at or past it, "
            f"its last generation flying at most {top - budget + 1} ({resampling}, {ev} evaluations in {g} generations): allowed {budget}..{top}"
        )
    return ""


def evolve_params_problem(run: EvolveResult, params: dict) -> str:
    """What in evolution run ``run`` contradicts its unit's ``params`` ('' when nothing does; T23-08): a champion of
    another topology, or a genome not of its topology's length; validations of other counts than its validation
    episodes, or champions chosen again over other episodes than its ``champion_reevaluation``; a champion's fitness
    that falls where it cannot (:func:`_history_fall_problem`); episodes that do not fit its budget and resampling
    (:func:`_budget_problem`)."""
    from ..policies import GENOME_LENGTH

    topology = params.get("topology")
    for name, policy in _policies(run):
        if isinstance(topology, str) and policy.topology != topology:
            return (
                f"{name}.topology = {brief(policy.topology)} is not allowed: its unit's params.topology is {brief(topology)}, and a result must be its unit's"
            )
        n = GENOME_LENGTH.get(policy.topology)
        genome = policy.genome
        if n is not None and not (isinstance(genome, tuple) and len(genome) == n and all(finite_real(x) for x in genome)):
            return f"{name}.genome = {brief(genome)} is not allowed: a {policy.topology} genome is {n} finite numbers"
    episodes, again = params.get("validation_episodes"), params.get("champion_reevaluation")
    for where, held in [("", run), *((f"{n}.", getattr(run, n)) for n in ("reevaluated", "reevaluated_best_ever"))]:
        if held is None:
            continue
        if held.validation is not None and whole_number(episodes) and len(held.validation) != episodes:
            return (
                f"{where}validation = {brief(list(held.validation))} is not allowed: its "
                f"unit's params.validation_episodes is {episodes}: allowed {episodes} returns"
            )
        if where and whole_number(again) and held.episodes != again:
            return f"{where}episodes = {brief(held.episodes)} is not allowed: its unit's params.champion_reevaluation is {again}: allowed {again}"
    return _own_length_problem(run, params) or _history_fall_problem(run, params) or _budget_problem(run, params) or _generations_problem(run, params)


def _own_length_problem(run: EvolveResult, params: dict) -> str:
    """'' unless a figure of evolution run ``run`` is one no episode of its unit's ``params.n_steps`` can give ('' where
    it gives none: the plan check's to name): its champion's fitness and its history's, each a mean of its episodes'
    fitness on its scale (:func:`~neurohover.evolution.fitness.fitness_range`; never a sum), or a validation return below
    :func:`~neurohover.sim.constants.lowest_return`. -inf and NaN are :func:`_fitness_problem`'s to judge. -1e9 of a
    20-step run was reported, bounded only by WORST_RETURN's 10**7 steps (T27-B03)."""
    from ..evolution.fitness import fitness_range, in_fitness_range

    n_steps = params.get("n_steps")
    if not (whole_number(n_steps) and n_steps >= 1):
        return ""
    scale = run.fitness if run.fitness in ("return", "inv-log-error") else "return"
    low, high, allowed = fitness_range(n_steps, scale)
    named = [("champion_return", run.champion_return), *((f"history[{i}]'s champion fitness", entry[1]) for i, entry in enumerate(run.history))]
    for name, value in named:
        v = float(value)
        if math.isfinite(v) and not in_fitness_range(v, low, high):
            return f"{name} = {brief(value)} is not allowed: its unit's episodes are {n_steps:,} control steps long: allowed {allowed} or -inf"
    lowest = lowest_return(n_steps)
    for where, held in [("", run), *((f"{n}.", getattr(run, n)) for n in ("reevaluated", "reevaluated_best_ever"))]:
        for i, r in enumerate(() if held is None or held.validation is None else held.validation):
            if float(r) < lowest:  # (NaN is no number below it: a blown-up episode, kept as 'nan')
                bound = f"{lowest:.10g} (the worst step, {CRASH_STEP_PENALTY:.6g}, for each of its {n_steps:,} steps)"
                return f"{where}validation[{i}] = {brief(r)} is not allowed: its unit's episodes are {n_steps:,} control steps long: allowed at least {bound}"
    return ""


def _generations_problem(run: EvolveResult, params: dict) -> str:
    """'' unless a steady-state run's generations and evaluations contradict its unit's optimiser settings ('' where its
    params are of another shape: the plan check's to name): a unit of the neuroevolution (optimiser name ne) on one MDP
    (params.target.kind 'mdp'), not NEAT, evolves by steady state, whose generations make its evaluations
    (:func:`~neurohover.evolution.steady_state.steady_state_evaluations`, the checkpoint's rule): generations 40 beside
    50 evaluations of pop_size 50, elite 49 were reported (T26-B04)."""
    from ..evolution.config import NE, make_settings, optimiser_of
    from ..evolution.steady_state import steady_state_evaluations

    target, table = params.get("target"), params.get("optimiser", {})
    on_mdp = isinstance(target, dict) and target.get("kind") == "mdp" and isinstance(table, dict)
    if not on_mdp or NEAT_TOPOLOGY in (params.get("topology"), run.champion.topology):
        return ""
    try:
        name, rest = optimiser_of(table)
        settings = make_settings("steady-state", NE, rest) if name == NE else None
    except (NeurohoverError, TypeError):
        return ""
    if settings is None:
        return ""
    pop, elite, g, ev = settings.pop_size, settings.elite_size, run.generations, run.evaluations
    if ev == steady_state_evaluations(g, pop, elite):
        return ""
    each = f"its first generation evaluates {pop} candidates, each later one {pop - elite}"
    rule = f"its unit evolves by steady state (pop_size {pop}, elite_size {elite}: {each})"
    if ev >= pop and (ev - pop) % (pop - elite) == 0:
        fits = 1 + (ev - pop) // (pop - elite)
        return f"generations = {g!r} is not allowed: {rule}, and its {ev} evaluations are generation {fits}: allowed {fits}"
    made = steady_state_evaluations(g, pop, elite)
    return f"evaluations = {ev!r} is not allowed: {rule}, and its {g} generations are {made} evaluations: allowed {made}"


def _history_fall_problem(run: EvolveResult, params: dict) -> str:
    """'' unless the champion's fitness falls in the history of a run whose champion is the best single fitness ever
    told (T24-09: [[50, -327086], [66, -1.0], [92, -311685]] was reported): a unit on one MDP (params.target.kind 'mdp':
    steady state, or a population optimiser on an MDP; evolution.run's best-ever generation), NEAT's aside. A run on a
    family (generational NE, races, CMA-ES, OpenAI-ES, uh-cma: each generation's best estimate) and NEAT's (each
    generation's best) may fall; every such unit of the committed store rises or stays."""
    target = params.get("target")
    if not (isinstance(target, dict) and target.get("kind") == "mdp") or NEAT_TOPOLOGY in (params.get("topology"), run.champion.topology):
        return ""
    best = -math.inf
    for i, (episodes, value) in enumerate(run.history):
        v = float(value)
        if v < best and not _close(v, best):
            return (
                f"history[{i}] = {brief([episodes, value])} is not allowed: its unit evolves on one MDP (params.target.kind 'mdp'), "
                f"where the champion is the best fitness ever told, and an earlier record reached {best!r}: allowed at least that"
            )
        best = max(best, v)
    return ""


#: A learned model's parameters and noise standard deviations (learning.LearnedModel's 11 dynamics parameters and 6
#: noise sds: every model unit of the committed store holds as many).
MODEL_PARAMS, MODEL_NOISE_STDS = 11, 6


def model_inconsistency(result: ModelResult) -> str:
    """What in model result ``result`` does not fit together ('' when all does; T25-10: model_params of 3 numbers, a
    generic_return of 5.0 and noise sds of -1.0 were reported): 11 model parameters, 6 noise standard deviations, each a
    finite number >= 0, and a generic return that is an episode's."""
    for name, count in (("model_params", MODEL_PARAMS), ("model_noise_std", MODEL_NOISE_STDS)):
        values = getattr(result, name)
        if len(values) != count:
            return f"{name} = {brief(list(values))} is not allowed: a learned model has {count} of them: allowed {count} numbers"
    for i, sd in enumerate(result.model_noise_std):
        if not (finite_real(sd) and float(sd) >= 0):
            return f"model_noise_std[{i}] = {brief(sd)} is not allowed: a standard deviation: allowed a finite number >= 0"
    return _returns_problem("generic_return", [result.generic_return]).replace("generic_return[0]", "generic_return")


def robustness_inconsistency(result: RobustnessResult) -> str:
    """What in robustness result ``result`` does not fit together ('' when all does; T23-08): a row of returns per MDP,
    each an episode's return (a positive one was reported), a crash count per row within its episodes, its own MDP
    among them."""
    rows = result.returns
    if not rows or not all(isinstance(row, tuple) and row for row in rows):
        return f"returns = {brief(_lists(rows))} is not allowed: give a non-empty row of episode returns for each MDP"
    for i, row in enumerate(rows):
        problem = _returns_problem(f"returns[{i}]", row)
        if problem:
            return problem
    if len(result.crashes) != len(rows):
        return f"crashes = {brief(list(result.crashes))} is not allowed: give one crash count for each of its {len(rows)} MDPs' rows of returns"
    for i, (count, row) in enumerate(zip(result.crashes, rows, strict=True)):
        if not 0 <= count <= len(row):
            return f"crashes[{i}] = {count!r} is not allowed: its MDP's row holds {len(row)} episodes: allowed 0..{len(row)}"
    if not 0 <= result.own < len(rows):
        return f"own = {result.own!r} is not allowed: it holds {len(rows)} MDPs' rows: allowed 0..{len(rows) - 1}"
    return ""


def robustness_params_problem(result: RobustnessResult, params: dict) -> str:
    """What in robustness result ``result`` contradicts its unit's ``params`` ('' when nothing does; T23-08): a row per
    MDP of its ``mdps``, ``episodes`` returns each, its ``own`` MDP."""
    mdps, episodes, own = params.get("mdps"), params.get("episodes"), params.get("own")
    if isinstance(mdps, list) and len(result.returns) != len(mdps):
        return f"returns = {brief(_lists(result.returns))} is not allowed: its unit flies {len(mdps)} MDPs (params.mdps): allowed a row of returns each"
    for i, row in enumerate(result.returns):
        if whole_number(episodes) and len(row) != episodes:
            return f"returns[{i}] = {brief(list(row))} is not allowed: its unit's params.episodes is {episodes}: allowed {episodes} returns"
    if whole_number(own) and result.own != own:
        return f"own = {result.own!r} is not allowed: its unit's params.own is {own}, and a result must be its unit's"
    return ""
