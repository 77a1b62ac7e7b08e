"""Flight-data metadata checked against itself and against the episodes it describes (docs/model.md, Learned models).

:func:`neurohover.flightdata.check_metadata` checks each field's kind; this module checks what the fields say, the way
:mod:`neurohover.experiments.result_checks` checks a stored test run against itself (each MDP is one its task family
holds and the MDP its label names as every MDP is built: :mod:`neurohover.tasks.held`), the seed is a seed (T23-05), no return is above 0 and each is
what the episode's observations give (T23-03), and no episode is flagged crashed whose last reading shows none
(T23-19). The policy ``policy_flown`` records must be a policy (T24-06, :func:`recorded_policy_problem`) and, where the
readings are exact, give the recorded actions (:func:`check_policy_actions`). What the readings cannot prove (an MDP not
recorded, a sensor model between the state and the readings) is left unchecked: a file ``fly --record`` wrote is never
refused.
"""

from __future__ import annotations

from dataclasses import fields
from typing import Any, TypeVar

import numpy as np

from .errors import NeurohoverError, brief, finite_real, whole_in
from .policies import MAX_OBSERVATION, Policy, policy_from_dict
from .sim.constants import CRASH_STEP_PENALTY, MAX_POSITION, MAX_RATE, MAX_VELOCITY, MIN_QW, WORST_RETURN
from .sim.rng import MAX_SEED

#: Recorded steps a recorded policy is flown on again to see that it gave their actions, and how near they must be
#: (float32 files round the observations: actions move by ~1e-6; a policy one gene away moved them by ~0.5; T22-17).
CHECKED_STEPS, ACTION_TOLERANCE = 200, 1e-4
#: Readings within the crash bounds by this fraction of each bound: float32 files round them (about 6e-8 relative).
_CRASH_MARGIN = 1e-5
#: How far a return may lie from what the observations give, relative to the sums it is made of: a float32 file
#: rounds each reading (its square by about 1.2e-7 relative), the kernel sums in its own order (about 1e-12).
_RETURN_RTOL = 1e-6


def check_meaning(metadata: dict, mdps: list, episodes: tuple[tuple, tuple, list[bool]] | None, where: str) -> None:
    """Refuse metadata that contradicts itself or the episodes, naming ``where``, the field, its value and what it
    contradicts. ``mdps`` are the MDPs of the metadata's ``mdps`` tables (None for an entry ``{}``), as flightdata
    checked them; ``episodes`` the observations, actions and crash flags (flightdata.crash_flags) of each episode, or
    None where only their lengths are known."""
    seed = metadata.get("seed")
    if seed is not None:  # 'abc' and -5 were taken (T23-05); every seed's range is sim.rng's
        whole_in(seed, f"{where}: its metadata seed", 0, MAX_SEED, "2**63-1")
    returns = metadata.get("returns")
    returns = returns if isinstance(returns, list) else []
    for i, value in enumerate(returns):  # [5.0, 3.0] was taken (T23-03): every reward is minus a sum of squares
        if finite_real(value) and not -WORST_RETURN <= value <= 0:
            raise NeurohoverError(
                f"{where}: its metadata returns={brief(returns)} is not allowed: episode {i}'s return {value!r} is not in "
                f"-{WORST_RETURN:.4g}..0 (every reward is minus a sum of squares, a crash's charge at worst)"
            )
    if episodes is None:
        return
    observations, actions, flags = episodes
    steps = metadata.get("episode_steps")
    for i, mdp in enumerate(mdps):  # the readings are the state only where the sensors are exact and the MDP recorded
        if mdp is None or not mdp.sensor.exact or not np.isfinite(observations[i]).all():
            continue  # non-finite readings: flightdata.check_flown names them
        if flags[i] and "crashed" in metadata:  # not a length taken for a crash (files before crashed was recorded)
            _check_crash(metadata["crashed"], observations[i], actions[i], i, where)
        _check_in_bounds(metadata, observations[i], i, flags[i], where)
        if i < len(returns) and finite_real(returns[i]):
            _check_return(returns, i, observations[i], flags[i], steps if type(steps) is int else None, where)


def _check_crash(flags: list, obs: np.ndarray, act: np.ndarray, i: int, where: str) -> None:
    """Refuse a crashed flag that the episode's last reading and action disprove (T23-19): the kernel tests the crash on
    the state after every step and ends the episode there, so a crash leaves its last reading out of the bounds (body
    frame: a norm bounds each world component) or follows a non-finite action, whose reading is the one before."""
    last = obs[-1]
    if not np.isfinite(act[-1]).all():
        return
    within = 1.0 - _CRASH_MARGIN
    calm = (
        np.linalg.norm(last[0:3]) <= MAX_VELOCITY * within
        and np.linalg.norm(last[3:6]) <= MAX_POSITION * within
        and np.abs(last[6:9]).max() <= MAX_RATE * within
        and float(last[9:12] @ last[9:12]) <= (1.0 - MIN_QW**2) * within
    )
    if calm:
        raise NeurohoverError(
            f"{where}: its metadata crashed={brief(flags)} is not allowed: episode {i} is flagged crashed, yet after its last "
            f"step ({act.shape[0]:,}) it flies within every crash bound (speed {np.linalg.norm(last[0:3]):.3g} m/s, distance "
            f"{np.linalg.norm(last[3:6]):.3g} m, rates under {MAX_RATE:.3g} rad/s, tilt under 15 degrees) after a finite action: "
            "a crash leaves the helicopter out of bounds; its flags and observations contradict"
        )


#: The crash bounds as readings show them (sim.constants; sim.kernel.crashed tests the world-frame state): a body-frame
#: velocity or position of world components each within its bound has a norm within sqrt(3) of it; the rates are the
#: state's; a unit quaternion's |qw| >= MIN_QW holds its vector part's squares within 1 - MIN_QW**2.
_READING_BOUNDS = (
    ("speed", slice(0, 3), 3 * MAX_VELOCITY**2, f"{3**0.5 * MAX_VELOCITY:.4g} m/s (each world component within {MAX_VELOCITY:g})"),
    ("distance", slice(3, 6), 3 * MAX_POSITION**2, f"{3**0.5 * MAX_POSITION:.4g} m (each world component within {MAX_POSITION:g})"),
    ("rate", None, MAX_RATE, f"{MAX_RATE:.4g} rad/s"),
    ("tilt", slice(9, 12), 1.0 - MIN_QW**2, "30 degrees (|qw| at least cos 15 degrees)"),
)


def _check_in_bounds(metadata: dict, obs: np.ndarray, i: int, crashed: bool, where: str) -> None:
    """Refuse an exact episode's reading past a crash bound where the simulator flew on (T26-B11: a position 50 m off in an
    episode flagged uncrashed was learned from): it tests the crash after every step and ends the episode at the first
    past a bound, so every reading but the last is within them, and the last too of an episode flagged uncrashed (where
    the flag is recorded: a file before crashed was recorded counts a full-length episode uncrashed, a crash on its last
    step too). The converse of :func:`_check_crash`; one pass over the readings."""
    flagged = not crashed and "crashed" in metadata
    rows = obs if flagged else obs[:-1]
    if rows.shape[0] == 0:
        return
    with np.errstate(over="ignore"):  # a reading of 1e300 squares to inf: past every bound
        ratios = np.stack(
            [
                (np.abs(rows[:, 6:9]).max(axis=1) if part is None else np.einsum("ij,ij->i", rows[:, part], rows[:, part])) / bound
                for _, part, bound, _ in _READING_BOUNDS
            ]
        )
    past_bound = ratios.max(axis=0) > 1.0 + _CRASH_MARGIN
    if not past_bound.any():
        return
    k = int(np.argmax(past_bound))  # the first reading past a bound
    j = int(np.argmax(ratios[:, k]))
    name, part, bound, allowed = _READING_BOUNDS[j]
    shown = float(ratios[j, k] * bound) if part is None else float(np.hypot.reduce(rows[k, part]))  # (hypot: no overflow)
    if name == "tilt":  # the vector part of a unit quaternion is sin(angle / 2)
        shown = float(np.degrees(2 * np.arcsin(min(shown, 1.0))))
    past = f"after step {k:,} its {name} is {shown:.4g}, past the crash bound {allowed}"
    ends = "the simulator tests the crash after every step and ends the episode at the first past a bound"
    if flagged:
        raise NeurohoverError(
            f"{where}: its metadata crashed={brief(metadata['crashed'])} is not allowed: episode {i} is flagged uncrashed, yet {past}: "
            f"{ends}; its flags and observations contradict"
        )
    raise NeurohoverError(
        f"{where}: episode {i}'s observations are not allowed: {past}, yet it flies on to step {obs.shape[0] - 1:,}: {ends}; its observations were changed"
    )


def _check_return(returns: list, i: int, obs: np.ndarray, crashed: bool, steps: int | None, where: str) -> None:
    """Refuse a return that is not minus the sum of the episode's rewards as its observations give them (T23-03): each
    step's reward is minus the sum of squares of the 12 readings after it (sim.kernel.reward_of); a crash's step is
    charged CRASH_STEP_PENALTY for each step left of the budget instead (0 of them for a crash on the last step)."""
    value, flown = float(returns[i]), obs.shape[0] - 1
    squares = np.einsum("ij,ij->i", obs[1:], obs[1:])
    earned = -float(squares[: flown - 1].sum() if crashed else squares.sum())
    tolerance = _RETURN_RTOL * abs(earned) + 1e-12 * abs(value) + 1e-9  # a crash's charge is no reading: exact to float64
    if not crashed:
        if abs(value - earned) <= tolerance:
            return
        gives = f"{earned!r}, minus the sum of squares of its 12 readings over its {flown:,} steps"
    else:
        left = (earned - value) / CRASH_STEP_PENALTY  # the steps charged: 0..steps - flown
        most = np.inf if steps is None else steps - flown
        if abs(left - round(left)) * CRASH_STEP_PENALTY <= tolerance and -0.5 < left < most + 0.5:
            return
        budget = "the steps left of its budget" if steps is None else f"each of the {most:,} steps left of its budget"
        gives = f"{earned!r} (its first {flown - 1:,} steps' rewards) less {CRASH_STEP_PENALTY:.6g} for {budget} (a crash's charge)"
    raise NeurohoverError(
        f"{where}: its metadata returns={brief(returns)} is not allowed: episode {i}'s return {value!r} is not what its "
        f"observations give: {gives}; its returns and observations contradict"
    )


def flown_policy(metadata: dict, where: str) -> Policy | None:
    """The policy metadata ``policy_flown`` records (``fly --record`` keeps the one that flew every episode), or None where
    none is: no entry, or null (joined recordings of several). One that is no policy is refused, as a policy file is
    read (:func:`neurohover.policies.policy_from_dict`): 'x' or a genome of 3 genes was taken until EC-MER (T24-06)."""
    flown = metadata.get("policy_flown")
    if flown is None:
        return None
    try:
        return policy_from_dict(flown, "it is no policy")
    except NeurohoverError as err:
        raise NeurohoverError(
            f"{where}: its metadata policy_flown={brief(flown)} is not allowed: {err}; give the policy that flew the episodes "
            "({'topology': 'slp' or 'mlp', 'genome': [...]}, as fly --record writes it), or null"
        ) from None


def action_mismatch(policy: Policy, observations: np.ndarray, actions: np.ndarray) -> tuple[int, int, float, float] | None:
    """The first of an episode's first :data:`CHECKED_STEPS` steps where ``policy`` does not give the recorded action
    (clipped to [-1, 1] as the kernel flies it, within :data:`ACTION_TOLERANCE`), as (step, action index, the policy's,
    the recorded), or None. Steps of a non-finite action, or of a reading Policy.act refuses (non-finite or past
    MAX_OBSERVATION, T31-B05), are passed over (a crash's NaN action is recorded as given). Recordings hold what the
    policy saw (a sensor's readings) and ``fly --record`` flies no safeguard, so every recorded action is the policy's
    own: the one test of it, at load and by EC-MER (models.ec.check_policy_flew)."""
    for k in range(min(CHECKED_STEPS, actions.shape[0])):
        # Policy.act's bound (T31-B05), in float64: float32 readings cast 1e60 to inf, with NumPy's overflow warning (T34-B16)
        if not np.all(np.isfinite(actions[k])) or not np.all(np.abs(observations[k].astype(np.float64)) <= MAX_OBSERVATION):
            continue
        flown = np.clip(policy.act(observations[k]), -1.0, 1.0)
        i = int(np.argmax(np.abs(flown - actions[k])))
        if abs(flown[i] - actions[k, i]) > ACTION_TOLERANCE:
            return k, i, float(flown[i]), float(actions[k, i])
    return None


def check_policy_actions(metadata: dict, observations: tuple, actions: tuple, where: str) -> None:
    """Refuse a ``policy_flown`` that does not give the first episode's recorded actions (:func:`action_mismatch`): one
    edited by a gene was plotted and learned from by LR, and named 'baseline' by EC-MER's refusal (T24-06). Its cost is
    fixed (:data:`CHECKED_STEPS` steps, some milliseconds), whatever the file's size. For exact readings only (a float64
    file): float32 rounds the readings, and a policy's actions move by its gain times that rounding, which no fixed
    tolerance tells from another policy's for every genome; EC-MER checks those files against its policy as before."""
    policy = flown_policy(metadata, where)
    miss = None if policy is None or not actions else action_mismatch(policy, observations[0], actions[0])
    if miss is not None:
        k, i, flown, recorded = miss
        raise NeurohoverError(
            f"{where}: its metadata policy_flown={brief(metadata['policy_flown'])} is not allowed: it did not fly the episodes: at "
            f"step {k} of episode 0 it gives action {i} = {flown:.6g} where they record {recorded:.6g} (fly --record keeps the "
            "policy that flew them); give that policy, or null"
        )


_D = TypeVar("_D", bound=type)


def compared_by_value(cls: _D) -> _D:
    """Dataclass ``cls`` (made with eq=False) given the ``==`` of :func:`neurohover.flightdata.same_values` over its
    compared fields (not those of compare=False: arrays whole, NaN equal to NaN), and no hash, as a list has none: the
    generated ``==`` of one holding arrays was NumPy's "truth value is ambiguous" (RunResult, RaceResult,
    ResamplingResult, CompeteResult; T46-B08)."""
    from .flightdata import same_values  # flightdata imports this module

    names = tuple(f.name for f in fields(cls) if f.compare)

    def __eq__(self: Any, other: object) -> bool:
        if other.__class__ is not self.__class__:
            return NotImplemented
        return same_values(tuple(getattr(self, n) for n in names), tuple(getattr(other, n) for n in names))

    setattr(cls, "__eq__", __eq__)  # noqa: B010
    setattr(cls, "__hash__", None)  # noqa: B010
    return cls
