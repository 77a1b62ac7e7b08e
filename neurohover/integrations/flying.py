"""Fly a Python policy (a batch of observations -> a batch of actions) as ``neurohover.evaluate`` flies a policy file.

A learned network (SB3, CleanRL, torch, JAX) is no :class:`~neurohover.policies.Policy`, so the
compiled kernel cannot run it inside its loop. :func:`evaluate_callable` steps all its episodes
in lockstep in one native vector environment, one network call per control step for the whole
batch, and gives episode ``e`` on MDP ``m`` the gust stream ``(seed, first_episode + m * episodes
+ e)``: the very gusts :func:`neurohover.evaluate` gives any policy file, so a learned policy and
the paper's policies are compared on the same episodes::

    import neurohover as nh
    from neurohover.integrations.flying import evaluate_callable

    ghh08 = nh.get_task_family("ghh08")
    mdps = [ghh08.mdp(f"train:{i}") for i in range(10)]
    learned = evaluate_callable(lambda obs: model.predict(obs, deterministic=True)[0], mdps, episodes=20)
    baseline = nh.evaluate(nh.baseline_policy(), mdps, episodes=20)   # the same gusts
"""

from __future__ import annotations

import functools
import time
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from ..envs.arguments import check_episode_steps, check_obs_dtype, real_values
from ..envs.vector import HoverVectorEnv
from ..errors import NeurohoverError, brief, check_arity, float64_of, masked_note, refused_signature, whole_in
from ..evaluate import Evaluation, check_first_episode
from ..policies import Policy
from ..sim.constants import ACTION_DIM, EPISODE_STEPS
from ..tasks import MDP, TaskFamily, get_task_family, refuse_unordered_mdps
from ..tasks.base import LEARNED_MODEL

__all__ = ["AgentRow", "checked_obs_statistics", "compare_agent", "evaluate_callable"]

MAX_EPISODES = 1 << 16  # helicopters in one lockstep batch: the vector environment's arrays stay small


def _checked_mdps(mdps: Any) -> tuple[list[MDP], str | None]:
    """``mdps`` (one MDP or a sequence of them, of one task family) as a list, with their family: the one check of
    :func:`evaluate_callable` and :func:`compare_agent` (a Policy flew MDPs of mixed families; twelfth trial S5). A
    learned model's MDP is of no family and flies beside any, as an environment's explicit ``mdp`` does
    (:func:`~neurohover.envs.arguments.resolve_mdp`; it was refused as not "of one task family", T36-B06); the family
    is None where all are models'."""
    refuse_unordered_mdps(mdps)  # a set flew in hash order (T32-B02)
    given = mdps
    if isinstance(mdps, MDP):
        mdps = [mdps]
    elif isinstance(mdps, Iterable) and not isinstance(mdps, (str, bytes, np.ndarray)):
        # an array is refused as evaluate and evolve_neat refuse it: a 0-d one was a TypeError "iteration over a 0-d
        # array", a 1-D object array of MDPs flew here though evaluate refuses it (T42-B02)
        mdps = list(mdps)
    if not isinstance(mdps, list) or not mdps or not all(isinstance(m, MDP) for m in mdps):
        raise NeurohoverError(
            f"mdps={brief(given)} is not allowed: mdps must be one MDP or a non-empty sequence of MDPs"
            " (a list or tuple, not an array; e.g. get_task_family('ghh08').mdp('train:3'))"
        )
    families = sorted({m.family for m in mdps} - {LEARNED_MODEL})
    if len(families) > 1:
        raise NeurohoverError(f"mdps must all be MDPs of one task family (got {', '.join(families)}): a learned model's MDP flies beside any")
    return mdps, families[0] if families else None


def _check_on_step(on_step: Any) -> None:
    """Refuse an ``on_step`` that cannot be called before anything flies (5 was a TypeError after the first step; twelfth trial T5)."""
    if on_step is not None and not callable(on_step):
        raise NeurohoverError(f"on_step={brief(on_step)} is not allowed: give a function of no arguments (called after each step) or None")
    # lambda x: None was a bare TypeError after the first step (T41-B01)
    check_arity("on_step", on_step, 0, "the flight calls on_step() after each step", "a function of no arguments, or None")


def evaluate_callable(
    act: Callable[..., Any],
    mdps: MDP | Sequence[MDP],
    *,
    episodes: int = 1,
    seed: int = 0,
    first_episode: int = 0,
    n_steps: int = EPISODE_STEPS,
    obs_dtype: str = "float32",
    indexed: bool = False,
    on_step: Callable[[], None] | None = None,
) -> Evaluation:
    """Fly ``act`` for ``episodes`` episodes on every MDP; arrays are shaped (M, E).

    Parameters
    ----------
    act : callable
        Maps observations, shape (B, 12) of ``obs_dtype``, to actions, shape (B, 4) (clipped to
        [-1, 1] by the environment, as for every policy). B is the number of episodes still flying.
    mdps : MDP or sequence of MDP
        MDPs of one task family; a learned model's MDP (``LearnedModel.mdp()``) flies beside any, or alone.
    episodes, seed, first_episode, n_steps
        As :func:`neurohover.evaluate`: episode e on MDP m meets gust stream
        ``(seed, first_episode + m * episodes + e)``.
    obs_dtype : {"float32", "float64"}
        What ``act`` receives (float32 for networks trained on the ``-Short-v0`` ids).
    indexed : bool
        Call ``act(observations, episodes)`` with the indices ``k = m * episodes + e`` of the episodes
        still flying, for a batch of several policies (one per episode, as a NEAT generation flies).
    on_step : callable, optional
        Called after each control step of the flight (a progress bar's update).
    """
    if not callable(act):  # None was a TypeError at the first step (sixth trial)
        raise NeurohoverError(f"act={act!r:.60} is not allowed: give a function of a batch of observations (B, 12) -> actions (B, 4)")
    if not isinstance(indexed, (bool, np.bool_)):  # 'yes' was taken as true
        raise NeurohoverError(f"indexed={indexed!r:.40} is not allowed: give True (act takes the episodes' indices too) or False")
    mdps, family = _checked_mdps(mdps)
    _check_on_step(on_step)
    unchecked = not _check_arity(act, bool(indexed))  # no signature to read: a TypeError of its first call says so
    n_steps = check_episode_steps(n_steps, "n_steps")  # refused as "episode_steps=0", a parameter it has not (T41-B10)
    first_episode = check_first_episode(first_episode)  # text was a TypeError from first_episode + k, True taken as 1 (twelfth trial T5)
    if len(mdps) > MAX_EPISODES:
        raise NeurohoverError(f"mdps: {len(mdps):,} MDPs is out of range: at most {MAX_EPISODES} (episodes x MDPs <= {MAX_EPISODES})")
    # T24-11: 1.5 or True "is not allowed" (a type), 0 "is out of range" (both said out of range)
    top = MAX_EPISODES // len(mdps)
    episodes = whole_in(episodes, "episodes", 1, top, f"{top} (episodes x MDPs <= {MAX_EPISODES})")
    n = len(mdps) * episodes
    sigma = getattr(mdps[0], "sigma", None)
    env = HoverVectorEnv(n, task=family or "ghh08", sigma=sigma, mdp=[m for m in mdps for _ in range(episodes)], episode_steps=n_steps, obs_dtype=obs_dtype)
    streams = [(seed, int(first_episode) + k) for k in range(n)]  # k = m * episodes + e, as evaluate numbers them
    start = time.perf_counter()
    obs, _ = env.reset(seed=seed, options={"noise": streams})
    returns, steps = np.zeros(n), np.zeros(n, dtype=np.int64)
    crashed, alive = np.zeros(n, dtype=np.bool_), np.ones(n, dtype=np.bool_)
    actions = np.zeros((n, ACTION_DIM))
    while alive.any():
        live = np.flatnonzero(alive)
        try:
            raw = act(obs[live], live) if indexed else act(obs[live])
        except TypeError as err:  # act(obs, k) without indexed=True was a bare TypeError (T37-B11)
            if unchecked:
                raise NeurohoverError(f"{_arity_problem(act, bool(indexed))} (its first call raised TypeError: {str(err)[:80]})") from err
            raise
        unchecked = False
        # complex, text, None and bool were read as numbers, as the environments do not (ninth trial)
        out = real_values(  # the message is built only when refused: str(raw) at every step was half a step's time
            raw,
            functools.partial(_bad_actions, raw, live.size),
        )
        if out.shape != (live.size, ACTION_DIM):
            raise NeurohoverError(f"act returned actions of shape {out.shape} for {live.size} observations: expected ({live.size}, {ACTION_DIM})")
        actions[live] = out
        obs, reward, terminated, truncated, _ = env.step(actions)  # finished episodes autoreset; they no longer count
        returns[live] += reward[live]
        steps[live] += 1
        crashed[live] |= terminated[live]
        alive[live] = ~(terminated[live] | truncated[live])
        if on_step is not None:
            on_step()
    env.close()
    shape = (len(mdps), int(episodes))
    return Evaluation(
        returns.reshape(shape), crashed.reshape(shape), steps.reshape(shape), np.full(shape, -1, dtype=np.int64), None, time.perf_counter() - start
    )


def checked_obs_statistics(mean: Any, var: Any, n_obs: int, what: str) -> tuple[np.ndarray, np.ndarray]:
    """The observation statistics ``(mean, var)`` an agent's observations are normalised with, as float64 arrays of
    ``n_obs``, or one NeurohoverError naming ``what`` (the file): NaN, inf and negative variances were flown and
    reported as the agent crashing, other shapes were tracebacks (ninth trial)."""
    checked = []
    for name, value in (("mean", mean), ("var", var)):
        if isinstance(value, np.ma.MaskedArray):  # np.asarray drops the mask: the hidden values were taken (T55-B12)
            raise NeurohoverError(f"{what} holds a {name} that is not an array of {n_obs} real numbers{masked_note(value)}")
        try:
            a = np.asarray(value)
        except (TypeError, ValueError):  # a ragged nesting
            a = np.asarray(None)
        if a.dtype.kind not in "iuf" or a.shape != (n_obs,):
            shown = f"shape {a.shape} of {a.dtype}" if a.dtype.kind != "O" else f"{str(value)[:40]!r}"
            raise NeurohoverError(f"{what} holds a {name} of {shown}, not an array of {n_obs} real numbers")
        a = float64_of(a)  # a longdouble past float64's range: inf, refused below (T37-B10)
        bad = np.flatnonzero(~np.isfinite(a) | ((a < 0) if name == "var" else False))
        if bad.size:
            raise NeurohoverError(
                f"{what} holds a {name} of {a[bad[0]]} at observation {bad[0]}: "
                f"expected finite numbers{', variances >= 0' if name == 'var' else ''} ({bad.size} of {n_obs} are not)"
            )
        checked.append(a)
    return checked[0], checked[1]


@dataclass(frozen=True)
class AgentRow:
    """One policy's paper measures over the same episodes: the mean return per episode (the paper's), the
    median over MDPs of the mean return on each, the crashed episodes and how many flew."""

    name: str
    return_per_episode: float
    median_over_mdps: float
    crashes: int
    episodes: int

    @classmethod
    def of(cls, name: str, ev: Evaluation) -> AgentRow:
        returns = np.asarray(ev.returns, dtype=np.float64).reshape(-1, np.asarray(ev.returns).shape[-1])
        crashed = np.asarray(ev.crashed).reshape(returns.shape)
        return cls(name, float(returns.mean()), float(np.median(returns.mean(axis=1))), int(crashed.sum()), int(returns.size))


def compare_agent(
    act: Callable[[np.ndarray], Any] | Policy,
    mdps: MDP | Sequence[MDP],
    *,
    episodes: int = 1,
    seed: int = 0,
    n_steps: int = EPISODE_STEPS,
    obs_dtype: str | None = None,
    on_step: Callable[[], None] | None = None,
    generic: Policy | None = None,
) -> list[AgentRow]:
    """``act`` flown on ``mdps`` beside the competition's baseline and the shipped generic policy of the MDPs' task,
    all on the same gusts (:func:`evaluate_callable` and :func:`neurohover.evaluate` number them alike): a learned
    policy measured as the paper measured its agents (full episodes of ``n_steps``; the return per episode and
    the crashes). ``mdps``: one MDP or a sequence of MDPs of one task family, as for :func:`evaluate_callable`.
    ``obs_dtype`` (default ``"float32"``) and ``on_step`` as there for a callable; a
    :class:`~neurohover.policies.Policy` flies in the compiled kernel, as the other two do, in one call (``on_step``
    is not called) on float64 observations, so ``obs_dtype`` beside it is refused, as the CLI refuses ``--obs-dtype``
    beside ``--policy``. ``generic``: the generic row's policy (default: the shipped generic of the MDPs' task, refused,
    as make_agent refuses the set, for FGHH MDPs not drawn at the sigma it was evolved for; T35-B07; learned models' MDPs
    alone are of no task, so give it). Returns rows for
    ``agent``, ``baseline`` and ``generic``, in that order."""
    from ..evaluate import evaluate
    from ..policies import baseline_policy
    from ..policysets import load_policy_set

    mdps, family = _checked_mdps(mdps)  # one MDP was "'MDP' object is not iterable" (twelfth trial T5)
    _check_on_step(on_step)
    if generic is not None and not isinstance(generic, Policy):
        raise NeurohoverError(f"generic={brief(generic)} is not allowed: give a Policy for the generic row, or None (the shipped generic)")
    if generic is None and family is None:  # a shipped generic is a task family's (T36-B06)
        raise NeurohoverError(
            f"generic=None is not allowed beside mdps of learned models only ({brief([m.label for m in mdps])}): they are of no task family, so "
            "no shipped generic is theirs; give generic= a policy for the generic row (e.g. load_policy_set('ghh08').generic for a model of GHH-08 flights)"
        )
    if obs_dtype is not None:  # checked for a Policy too, which ignored obs_dtype='x' (twelfth trial S5)
        check_obs_dtype(obs_dtype)
    if isinstance(act, Policy):
        if obs_dtype is not None:
            raise NeurohoverError(
                f"obs_dtype={obs_dtype!r} applies to a callable that receives observations, not to a Policy (it flies in the compiled kernel on float64)"
            )
        agent = evaluate(act, mdps, episodes=episodes, seed=seed, n_steps=n_steps)
    else:
        indexed = bool(getattr(act, "indexed", False))  # a recurrent policy keeps a state per episode
        agent = evaluate_callable(
            act, mdps, episodes=episodes, seed=seed, n_steps=n_steps, obs_dtype="float32" if obs_dtype is None else obs_dtype, indexed=indexed, on_step=on_step
        )
    if generic is None:
        assert family is not None  # refused above for models' MDPs alone
        ps = load_policy_set(family)
        _refuse_other_sigma(mdps, get_task_family(family), ps.manifest.get("sigma"))
        generic = ps.generic
    rows = [AgentRow.of("agent", agent)]
    for name, policy in (("baseline", baseline_policy()), ("generic", generic)):
        rows.append(AgentRow.of(name, evaluate(policy, mdps, episodes=episodes, seed=seed, n_steps=n_steps)))
    return rows


def generic_sigma_problem(family: TaskFamily, built: object) -> float | None:
    """``built``, the sigma a policy set's generics were evolved for (its manifest's), where ``family`` flies another
    breadth sigma over which a generic is evolved; None where they fit or either is unknown. The one decision of
    make_agent and compare_agent (they refuse the set) and evaluate-agent (a note; T35-B07)."""
    if family.sigma is None or not family.generic_over_distribution or built is None or float(built) == family.sigma:  # type: ignore[arg-type]
        return None
    return float(built)  # type: ignore[arg-type]


def _refuse_other_sigma(mdps: list[MDP], family: TaskFamily, built: object) -> None:
    """Refuse the shipped generic for ``mdps`` not drawn at the sigma it was evolved for. MDPs carry no sigma: they are
    taken to be of ``family`` (at its build sigma) where it names each by its label with the same dynamics (T35-B07)."""
    if not family.generic_over_distribution or built is None:
        return
    other_sigma = generic_sigma_problem(family, built) is not None  # the family's own sigma is another: every MDP refused
    for m in mdps:
        try:
            named = family.mdp(m.label.split("/", 1)[-1])
        except NeurohoverError:
            named = None
        if other_sigma or named is None or replace(m, sensor=named.sensor, drift=named.drift) != named:
            raise NeurohoverError(
                f"mdps {m.label or brief(m)!r} is not allowed with the shipped {family.name} generic: it is no {family.name} MDP of sigma = {built}, "
                f"the sigma that generic was evolved for (make_agent refuses the set at another sigma too): give MDPs of "
                f"get_task_family({family.name!r}), or generic= a policy of your own for the generic row"
            )


def _bad_actions(raw: Any, n: int) -> str:
    """What ``act`` returned, when it is no array of ``n`` actions (built only then)."""
    return (
        f"act returned {type(raw).__name__} {str(raw)[:60]!r}: expected numbers (real ones: not text, booleans, complex or None), an array ({n}, {ACTION_DIM})"
    )


def _arity_problem(act: Any, indexed: bool, signature: str = "") -> str:
    """The refusal of an ``act`` that cannot be called as ``indexed`` calls it (its arity is another)."""
    name = getattr(act, "__qualname__", None) or type(act).__name__
    calls = "act(observations, indices)" if indexed else "act(observations)"
    return (
        f"act {brief(name)}{f' of signature {brief(signature)}' if signature else ''} is not allowed: indexed={indexed} calls it as {calls}; "
        "give a function of (observations) with indexed=False, or of (observations, indices) with indexed=True"
    )


def _check_arity(act: Any, indexed: bool) -> bool:
    """Refuse ``act`` where its signature cannot take the arguments ``indexed`` passes (T37-B11); whether it was checked
    (False: no signature to read, e.g. a builtin's)."""
    refused = refused_signature(act, 2 if indexed else 1)
    if refused:
        raise NeurohoverError(_arity_problem(act, indexed, refused))
    return refused is not None
