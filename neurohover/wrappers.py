"""Reward transforms for learning on the hovering environments (docs/deep-rl.md).

A crash ends an episode with one reward of ``-CRASH_STEP_PENALTY`` (1748.8, the worst possible
step) times the steps left: about -1.05e7 at the start of a 6000-step episode, where an ordinary
step is about -0.2. Value functions then see losses of 1e13, and ``NormalizeReward`` scales every
ordinary step to nothing. A plain ``sign(r) log(1 + |r|)`` squash makes a crash cost about as much
as two bad steps, and agents learn to crash at once. :func:`crash_aware` squashes an ordinary step
to ``-log(1 + |r|)`` and charges a crash that squashed worst step for every step left, discounted,
so a crash stays worse than any way of flying on::

    import gymnasium as gym, neurohover
    from neurohover.wrappers import CrashAwareReward

    env = CrashAwareReward(gym.make("neurohover/GHH08-Short-v0"))   # a crash at step 1: about -750

On a vector environment use ``gymnasium.wrappers.vector.TransformReward(envs, crash_aware)``, over a plain id only:
an ``-RL-v0`` id's rewards are crash-aware already, and the bare function, which has no environment to check, squashes
them again (a crash of about -75 became an ordinary step's -4.3; forty-second trial).
Report the unwrapped environment's returns (``RecordEpisodeStatistics`` inside this wrapper).
A crash is found by the size of the environment's own reward, so reward transforms (``ClipReward``,
``TransformReward``, ``NormalizeReward``, a second ``CrashAwareReward``) go outside this wrapper, never
inside, where they squashed a crash into an ordinary step: :class:`CrashAwareReward` refuses them, and an
``-RL-v0`` id, whose rewards are crash-aware already (T34-B05). A wrapper of your own that changes the
rewards in ``step`` is not seen: keep it outside too.
"""

from __future__ import annotations

import math
import sys

import gymnasium as gym
import numpy as np

from .errors import NeurohoverError, brief, finite_real, real_number
from .sim.constants import CRASH_STEP_PENALTY, MAX_EPISODE_STEPS

__all__ = ["CrashAwareReward", "crash_aware"]

WORST_STEP = math.log1p(CRASH_STEP_PENALTY)  # the squashed worst step, about 7.47
#: The largest ``scale``: a crash charged for every step of the longest episode (MAX_EPISODE_STEPS), squashed and
#: scaled, stays finite (1e308 made crash rewards -inf with an overflow warning; T35-B08).
MAX_SCALE = 1e300
assert MAX_SCALE * WORST_STEP * MAX_EPISODE_STEPS < sys.float_info.max
#: The smallest ``scale``: a step squashed to 1e-7 or more (|r| of 1e-7: hovering all but still), scaled, stays a normal
#: float, its 53 bits of precision kept (5e-324 made every reward a denormal, one step's the next's; T40-B16).
MIN_SCALE = 1e-300
assert MIN_SCALE * 1e-7 >= sys.float_info.min


def check_discount_and_scale(gamma, scale) -> None:
    """Refuse a discount outside (0, 1] or a scale outside MIN_SCALE..MAX_SCALE, by name: any real type (NumPy
    scalars, Fraction) is taken; np.float32(0.9) was "out of range" (twelfth trial U1), so a wrong type says so."""
    scales = (
        f"a finite number > 0 and <= {MAX_SCALE:g} (a larger one makes a crash's reward infinite) and >= {MIN_SCALE:g} (a smaller one makes "
        "rewards denormal floats, which lose the differences between steps)"
    )
    for name, value, allowed in (("gamma", gamma, "a discount in (0, 1]"), ("scale", scale, scales)):
        if not real_number(value):
            raise NeurohoverError(f"{name}={brief(value)} is not allowed: give a real number, {allowed}")
        number = float(value) if finite_real(value) else math.nan  # nan: out of range either way
        if not (0.0 < number <= 1.0 if name == "gamma" else MIN_SCALE <= number <= MAX_SCALE):
            raise NeurohoverError(f"{name}={brief(value)} is out of range: allowed {allowed}")


def check_env(env, hover: bool = False) -> None:
    """Refuse a wrapper's ``env`` that is no gymnasium Env by name (None was Gymnasium's TypeError; fifteenth trial T15-11),
    and, where ``hover``, one whose unwrapped env is no neurohover HoverEnv: CrashAwareReward's crash charge and squash are
    a hovering env's (CartPole's +1 for staying upright became a penalty of -0.69; T45-B10)."""
    if not isinstance(env, gym.Env):
        raise NeurohoverError(f"env={brief(env)} is not allowed: give a gymnasium Env (gymnasium.make('neurohover/GHH08-Short-v0'), a HoverEnv)")
    if hover and not _hovers(env):
        raise NeurohoverError(
            f"env={brief(env)} is not allowed: it flies a {type(env.unwrapped).__name__}, not a neurohover HoverEnv, whose observations, "
            "actions and rewards this wrapper transforms; give a neurohover env (gymnasium.make('neurohover/GHH08-Short-v0'))"
        )


def _hovers(env: gym.Env) -> bool:
    """Whether ``env`` unwrapped is a neurohover HoverEnv (looked up, not imported: neurohover.envs is a layer above; an
    env made while it was not imported is none)."""
    hover = sys.modules.get("neurohover.envs.hover")
    return hover is not None and isinstance(env.unwrapped, hover.HoverEnv)


def crash_aware(reward, gamma: float = 0.99, scale: float = 1.0):
    """The crash-aware squash of a reward (a float, or an array of them).

    ``reward`` is a neurohover reward, at most 0. ``-log(1 + |r|)`` for an ordinary step; for a crash step (``|r| >= CRASH_STEP_PENALTY``,
    ``left = |r| / CRASH_STEP_PENALTY`` steps charged) ``-log(1 + CRASH_STEP_PENALTY) * (1 -
    gamma**left) / (1 - gamma)``; times ``scale``.
    """
    check_discount_and_scale(gamma, scale)  # gamma=2 or scale=-1 were taken here and refused by the wrapper (fifth trial)
    gamma, scale = float(gamma), float(scale)  # a Fraction would make object arrays
    if isinstance(reward, np.ma.MaskedArray):  # np.asarray dropped the mask: the hidden values were squashed (T47-B11)
        raise NeurohoverError(
            f"reward={brief(reward)} is not allowed: give a real number or an array of them "
            "(not a masked array: its masked entries would be squashed at their hidden values)"
        )
    try:
        raw = np.asarray(reward)
    except ValueError:  # a ragged list was NumPy's "inhomogeneous shape" (twelfth trial T6)
        raw = np.asarray(None)
    if raw.dtype.kind not in "iuf":  # None was nan, "x" NumPy's ValueError
        raise NeurohoverError(f"reward={reward!r:.60} is not allowed: give a real number or an array of them")
    r = np.abs(raw.astype(np.float64))
    if not np.all(np.isfinite(r)):  # nan came out as nan, inf as a crash of endless steps
        raise NeurohoverError(f"reward={reward!r:.60} is not allowed: give finite numbers (a crash is a finite charge)")
    if np.any(raw > 0):  # +5 was squashed as -5 and +2000 charged as a crash (T54-B07)
        raise NeurohoverError(
            f"reward={brief(reward)} is not allowed: give rewards <= 0, as neurohover's are (minus a sum of squares; a crash minus "
            "its charge): a positive reward comes from another environment or an earlier transform"
        )
    left = r / CRASH_STEP_PENALTY
    crash = -WORST_STEP * (left if gamma == 1.0 else (1.0 - gamma**left) / (1.0 - gamma))
    with np.errstate(over="ignore"):  # refused below, by name
        out = scale * np.where(r >= CRASH_STEP_PENALTY, crash, -np.log1p(r))
    if not np.all(np.isfinite(out)):  # a charge far past MAX_EPISODE_STEPS steps, scaled (T35-B08)
        raise NeurohoverError(
            f"reward={reward!r:.60} with scale={brief(scale)} is not allowed: its squashed reward is past the largest float; "
            f"give a crash charge of at most {MAX_EPISODE_STEPS:,} steps (MAX_EPISODE_STEPS), or a smaller scale"
        )
    return float(out) if np.ndim(reward) == 0 else out


def refuse_changed_rewards(env: gym.Env) -> None:
    """Refuse an ``env`` whose rewards a wrapper inside it has changed (a reward wrapper, ``NormalizeReward``) or made
    crash-aware already (a :class:`CrashAwareReward`, as every ``-RL-v0`` id has): :func:`crash_aware` finds a crash by
    ``|r| >= CRASH_STEP_PENALTY``, and a clipped, scaled or normalised crash was squashed as an ordinary step (T34-B05)."""
    layer = env
    while isinstance(layer, gym.Wrapper):
        if isinstance(layer, CrashAwareReward):
            raise NeurohoverError(
                f"env={brief(env)} is not allowed: its rewards are crash-aware already (a CrashAwareReward inside it, as every "
                "neurohover/<NAME>-RL-v0 id has); wrap it once, or wrap a plain id (e.g. neurohover/GHH08-Short-v0)"
            )
        if isinstance(layer, (gym.RewardWrapper, gym.wrappers.NormalizeReward)):
            raise NeurohoverError(
                f"env={brief(env)} is not allowed: its {type(layer).__name__} changes the rewards before CrashAwareReward sees them, "
                f"and a crash (|r| >= {CRASH_STEP_PENALTY:g}) would be squashed as an ordinary step; put reward wrappers outside CrashAwareReward"
            )
        layer = layer.env


class CrashAwareReward(gym.RewardWrapper):
    """Rewards of :func:`crash_aware` (``gamma``: the learner's discount, in (0, 1]; ``scale`` in 1e-300..1e300), over an ``env`` whose
    rewards are a neurohover HoverEnv's own (another env is refused, T45-B10): a reward wrapper, ``NormalizeReward`` or a CrashAwareReward inside (an ``-RL-v0``
    id) is refused (:func:`refuse_changed_rewards`)."""

    def __init__(self, env: gym.Env, gamma: float = 0.99, scale: float = 1.0) -> None:
        check_env(env, hover=True)
        check_discount_and_scale(gamma, scale)
        refuse_changed_rewards(env)
        super().__init__(env)
        self.gamma, self.scale = float(gamma), float(scale)

    def reward(self, reward):
        return crash_aware(reward, self.gamma, self.scale)
