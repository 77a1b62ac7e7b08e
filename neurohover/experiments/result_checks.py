"""Checks of stored results (:mod:`~neurohover.experiments.results`): a stored value against its field's annotation,
and a test run's parts against each other."""

from __future__ import annotations

import dataclasses
import math
from typing import TYPE_CHECKING, Any

from ..errors import brief, finite_real, whole_number
from ..sim.constants import WORST_RETURN

if TYPE_CHECKING:
    from .results import TestRunResult


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
    if run.crash_steps is not None and len(run.crash_steps) != len(run.crash_episodes):
        return f"{len(run.crash_steps)} crash steps for {len(run.crash_episodes)} crash episodes"
    for i, step in enumerate(run.crash_steps or ()):
        if step < 1:  # the kernel counts the crashing control step from 1 (its unit's params bound it: params_problem)
            return f"crash_steps[{i}] = {step!r} is not allowed: a crash ends its episode at control step 1 or later"
    return _after_learning_problem(run)


def _changes_problem(changes: Any, n: int) -> str:
    """'' when ``changes`` are a run of ``n`` episodes' policy changes: (episode, policy) pairs of episodes in 0..n-1, in
    order, each once, and a policy's name; else what is wrong ([[50, 'x'], [-1, '']] of a 3-episode run was taken; T22-09)."""
    last = -1
    for i, change in enumerate(changes):
        episode, policy = change if isinstance(change, tuple) and len(change) == 2 else (None, None)
        if not (whole_number(episode) and last < episode < n and isinstance(policy, str) and policy):
            shown = brief(list(change) if isinstance(change, tuple) else change)
            return f"policy_changes[{i}] = {shown} is not allowed: give [episode, policy name], its episodes among 0..{n - 1}, in order, each once"
        last = episode
    return ""


def seconds_problem(timing: Any) -> str:
    """'' when every field of the record ``timing`` is a finite number of seconds >= 0, else which is not (T22-09)."""
    for f in dataclasses.fields(timing):
        value = getattr(timing, f.name)
        if not (finite_real(value) and value >= 0):
            return f"timing.{f.name} = {brief(value)} is not allowed: give a finite number of seconds >= 0"
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


def params_problem(result: Any, params: Any) -> str:
    """What in a stored unit's ``result`` contradicts the unit's own ``params`` ('' when nothing does; params of another
    shape are the plan check's to name): a test run's agent or MDP, or a model's method or MDP, other than its params
    say (a run of model-free on ghh08/test:0 holding agent 'baseline' and mdp 'ghh09/test:7' was exported; T22-08), or a
    crash at a step past its episodes' ``n_steps`` (999999 of 20 was reported; T22-07)."""
    from .results import ModelResult, TestRunResult

    if not (isinstance(result, (TestRunResult, ModelResult)) and isinstance(params, dict)):
        return ""
    for name in ("agent", "mdp") if isinstance(result, TestRunResult) else ("method", "mdp"):
        says = _params_says(params, name)
        if isinstance(says, str) and getattr(result, name) != says:
            where = "params.mdp.label" if name == "mdp" else f"params.{name}"
            return f"{name} = {brief(getattr(result, name))} is not allowed: its unit's {where} is {brief(says)}, and a result must be its unit's"
    n_steps = params.get("n_steps")
    if isinstance(result, TestRunResult) and whole_number(n_steps):
        for i, step in enumerate(result.crash_steps or ()):
            if not 1 <= step <= n_steps:
                return f"crash_steps[{i}] = {step!r} is not allowed: its unit's episodes are {n_steps} control steps long: allowed 1..{n_steps}"
    return ""
