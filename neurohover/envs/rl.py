"""The deep-RL ids ``neurohover/<NAME>-RL-v0``: the hovering task made learnable with a library's default settings.

By id alone (``gym.make("neurohover/GHH08-RL-v0")``, SB3's ``make_vec_env``, RL Zoo's ``--env`` without a
``--conf-file``, CleanRL's ``--env-id``) a stock agent meets rewards of -1e7 at a crash and observations
of very different sizes, and learns to crash (docs/deep-rl.md). These ids are the short-episode variant
with the two transforms our recipe needed built in, so that no wrapper and no hyperparameter is asked of
the user:

=====================  ===========================================================================
episodes               1000 control steps (100 s); a crash charges the steps left of the 1000
observation            the 12 readings divided by the crash limits (:data:`OBS_LIMITS`: 5 m/s, 20 m,
                       4 pi rad/s, 1), so a reading is within [-1, 1] until the helicopter crashes;
                       float32
action                 4 numbers in [-1, 1] (clipped), float32: the controls ``ACTION_OFFSET + A (a +
                       4 a^3) / 5`` (:func:`controls`); a non-finite number (NaN or infinity) is a
                       crash, as on the plain ids; a = 0 is the baseline policy's action at
                       rest (0.02, 0, 0, 0.23), a small a moves a control by A a / 5 (a library's
                       usual unit exploration noise stays survivable) and a = +-1 reaches the
                       family's authority A (:data:`ACTION_AUTHORITY`: what the paper's policies
                       need, measured on the test MDPs)
reward                 :func:`neurohover.wrappers.crash_aware` with gamma 0.99 and scale 0.1:
                       ``-0.1 log(1 + |r|)`` a step, a crash the squashed worst step for every
                       step left, discounted (about -75 at the first step)
=====================  ===========================================================================

The MDP is drawn from G at every reset (``mdp="sample"``; pass ``mdp="train:3"`` for one MDP), as the
other ids. A policy trained here flies the paper's episodes through :func:`rl_policy` (its observations
scaled, its actions made controls): ``neurohover evaluate-agent --rl-id`` applies it, and the return it
prints is the raw one of full 6000-step episodes, comparable with the paper's.
"""

from __future__ import annotations

from functools import partial
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium.wrappers.vector import TransformAction as VectorTransformAction
from gymnasium.wrappers.vector import TransformObservation as VectorTransformObservation
from gymnasium.wrappers.vector import TransformReward as VectorTransformReward

from ..errors import NeurohoverError, brief
from ..sim.constants import ACTION_DIM, MAX_POSITION, MAX_RATE, MAX_VELOCITY
from ..tasks import TaskFamily, get_task_family
from ..wrappers import CrashAwareReward, check_env, crash_aware
from .arguments import real_values
from .hover import HoverEnv
from .vector import HoverVectorEnv

#: The crash limits of the 12 readings (u, v, w; x, y, z; p, q, r; qx, qy, qz): what :func:`scale_observation` divides by.
OBS_LIMITS = np.array((MAX_VELOCITY,) * 3 + (MAX_POSITION,) * 3 + (MAX_RATE,) * 3 + (1.0,) * 3)
#: The controls of an RL id's action a: ``ACTION_OFFSET + A * (a + CUBIC * a**3) / (1 + CUBIC)``, a clipped to [-1, 1].
ACTION_OFFSET = np.array([0.02, 0.0, 0.0, 0.23])  # the baseline policy's action at rest
CUBIC = 4.0  # near a = 0 a control moves by A / 5 per unit of a; at a = +-1 by A
#: Each family's authority A: the largest control moves from ACTION_OFFSET that the paper's policies make, rounded up
#: (GHH-08 and GHH-09 generics on their training and test MDPs: 0.43, 0.21, 0.018, 0.17; FGHH generics: the whole range).
ACTION_AUTHORITY: dict[str, np.ndarray] = {
    "ghh08": np.array([0.5, 0.25, 0.05, 0.2]),
    "ghh09": np.array([0.5, 0.25, 0.05, 0.2]),
    "fghh": np.array([1.0, 1.0, 0.05, 1.0]),
}
FULL_AUTHORITY = np.array([1.0, 1.0, 1.0, 1.0])  # a family without a measured one
#: The reward transform's discount and scale (those of the shipped PPO recipe, docs/deep-rl.md).
RL_GAMMA, RL_REWARD_SCALE = 0.99, 0.1
#: What the RL ids set over the family's environment (their reward and observation transforms come on top).
RL_SETTINGS: dict[str, Any] = {"episode_steps": 1000, "obs_dtype": "float32", "action_dtype": "float32"}


def scale_observation(obs: np.ndarray) -> np.ndarray:
    """Readings (..., 12) divided by their crash limits, in their own dtype: what an RL id's policy sees."""
    given = obs
    try:
        obs = np.asarray(obs)
    except ValueError:  # ragged
        obs = np.asarray(None)
    if obs.dtype.kind not in "iuf" or obs.ndim == 0 or obs.shape[-1] != OBS_LIMITS.size:  # 11 readings were a broadcast error (T15-6)
        shape = f" (shape {obs.shape})" if obs.dtype.kind in "iuf" else ""
        raise NeurohoverError(f"observation {brief(given)}{shape} is not allowed: observations must be (..., 12) real numbers")
    return (obs / OBS_LIMITS).astype(obs.dtype if obs.dtype.kind == "f" else np.float64, copy=False)


def authority(task: str) -> np.ndarray:
    """The action authority of family ``task`` (any spelling :func:`neurohover.tasks.get_task_family` takes): an unknown
    task is refused, where it silently had full authority (fifteenth trial T15-18)."""
    found = ACTION_AUTHORITY.get(task) if isinstance(task, str) else None  # the usual spelling: a dict look-up a step
    return found if found is not None else ACTION_AUTHORITY.get(get_task_family(task).name, FULL_AUTHORITY)


def controls(action: np.ndarray, task: str) -> np.ndarray:
    """The task's controls (..., 4), float64, of an RL id's actions on family ``task``: an action clipped to [-1, 1], a
    non-finite one (NaN or infinity) NaN controls, which crash the helicopter as on the plain ids."""
    scale = authority(task)
    a = real_values(action, f"action {action!r:.80} is not allowed: give 4 real numbers in [-1, 1] per helicopter")
    if a.ndim == 0 or a.shape[-1] != ACTION_DIM:
        raise NeurohoverError(f"action has shape {a.shape}, expected (..., 4): 4 numbers in [-1, 1] per helicopter")
    # T24-10: clipping made an infinite action full control; a non-finite action is a crash, as on the plain ids (NaN).
    a = np.where(np.isinf(a), np.nan, np.clip(a, -1.0, 1.0))
    return ACTION_OFFSET + scale * (a + CUBIC * a**3) / (1.0 + CUBIC)


def rl_policy(act, task: str):
    """A policy of the paper's observations (a batch (n, 12) -> controls (n, 4)) from ``act``, one trained on the RL id
    of family ``task`` (scaled observations -> its actions): what :func:`neurohover.integrations.flying.evaluate_callable`
    flies."""
    if not callable(act):  # it failed only when the policy was flown (T15-18)
        raise NeurohoverError(f"act={brief(act)} is not allowed: give a callable (scaled observations (n, 12) -> actions (n, 4))")
    task = get_task_family(task).name  # an unknown task refused here, not at the first step

    if getattr(act, "indexed", False):  # a recurrent policy: its episodes' indices pass through

        def indexed(obs: np.ndarray, episodes: np.ndarray) -> np.ndarray:
            return controls(act(scale_observation(np.asarray(obs, dtype=np.float32)), episodes), task)

        indexed.indexed = True  # type: ignore[attr-defined]
        return indexed

    def policy(obs: np.ndarray) -> np.ndarray:
        return controls(act(scale_observation(np.asarray(obs, dtype=np.float32))), task)

    return policy


def refuse_carried(env: gym.Env, wrapper: type, transform: str) -> None:
    """Refuse an ``env`` that carries ``wrapper`` already (every ``-RL-v0`` id carries both :class:`ScaledObservation`
    and :class:`ScaledAction`): stacked, the transform was applied twice (forty-second trial T42-B04), as the crash-aware
    reward was before :func:`neurohover.wrappers.refuse_changed_rewards` (T34-B05)."""
    layer = env
    while isinstance(layer, gym.Wrapper):
        if isinstance(layer, wrapper):
            raise NeurohoverError(
                f"env={brief(env)} is not allowed in {wrapper.__name__}: it carries that transform already, {transform} (a "
                f"{wrapper.__name__} inside it, as every neurohover/<NAME>-RL-v0 id has); wrap it once, or wrap a plain id "
                "(e.g. neurohover/GHH08-Short-v0)"
            )
        layer = layer.env


def refuse_shape(env: gym.Env, kind: str, size: int, what: str) -> None:
    """Refuse an ``env`` whose ``kind`` ("observation" or "action") space is not a Box of rows of ``size`` numbers
    (frames stacked are rows): the RL transforms take any env of a helicopter's shapes (a user's own too), not another
    task's (after T45-B10)."""
    space = getattr(env, f"{kind}_space", None)
    if not isinstance(space, gym.spaces.Box) or space.shape[-1:] != (size,):
        shown = f"a Box of shape {space.shape}" if isinstance(space, gym.spaces.Box) else brief(space)
        raise NeurohoverError(
            f"env={brief(env)} is not allowed: its {kind} space is {shown}, and this transform takes {what} (a Box of shape "
            f"({size},)); give a neurohover env (gymnasium.make('neurohover/GHH08-Short-v0')) or one of a helicopter's shapes"
        )


class ScaledObservation(gym.ObservationWrapper):
    """Observations of :func:`scale_observation` (the space keeps its shape and dtype; its bounds are infinite), over an
    ``env`` whose observations are not scaled already (an ``-RL-v0`` id's are: refused, T42-B04)."""

    def __init__(self, env: gym.Env) -> None:
        check_env(env)
        refuse_shape(env, "observation", 12, "the 12 readings of a helicopter")  # CartPole was taken, its first reset refused
        refuse_carried(env, ScaledObservation, "its observations are divided by the crash limits")
        super().__init__(env)

    def observation(self, observation: np.ndarray) -> np.ndarray:
        return scale_observation(observation)


class ScaledAction(gym.ActionWrapper):
    """Actions in [-1, 1] made the task's controls by :func:`controls`, over an ``env`` whose actions are controls (an
    ``-RL-v0`` id's are scaled already: refused, T42-B04); ``task`` must be the env's own family where it has one
    (another family's authority was flown silently, T42-B05)."""

    def __init__(self, env: gym.Env, task: str) -> None:
        check_env(env)
        refuse_shape(env, "action", 4, "a helicopter's 4 controls")  # Pendulum's one torque was taken, its first step refused
        self.task = get_task_family(task).name  # refused by name, not flown with full authority (T15-18)
        refuse_carried(env, ScaledAction, "its actions in [-1, 1] are made controls")
        family = getattr(env.unwrapped, "family", None)
        if isinstance(family, TaskFamily) and family.name != self.task:
            raise NeurohoverError(
                f"task={brief(task)} is not allowed: the env flies family {family.name!r}, and the action authority of family "
                f"{self.task!r} would be flown on it; give task={family.name!r}, the env's own"
            )
        super().__init__(env)

    def action(self, action: np.ndarray) -> np.ndarray:
        return controls(action, self.task).astype(self.env.action_space.dtype)


def make_rl_env(**kwargs: Any) -> gym.Env:
    """The single environment of an RL id: :class:`HoverEnv` with :data:`RL_SETTINGS`, scaled observations and actions,
    and the crash-aware reward (keyword arguments as :class:`HoverEnv`'s; the id's settings may be overridden)."""
    env = HoverEnv(**{**RL_SETTINGS, **kwargs})
    return CrashAwareReward(ScaledAction(ScaledObservation(env), env.family.name), gamma=RL_GAMMA, scale=RL_REWARD_SCALE)


def make_rl_vector_env(**kwargs: Any) -> gym.vector.VectorEnv:
    """The native vector environment of an RL id (``gym.make_vec(..., vectorization_mode="vector_entry_point")``,
    :class:`neurohover.integrations.sb3.SB3VecEnv`): the same transforms on every helicopter."""
    env = HoverVectorEnv(**{**RL_SETTINGS, **kwargs})
    scaled = VectorTransformObservation(env, scale_observation, env.observation_space)
    # module-level functions, not local lambdas: the vector env pickles as the plain one does (T42-B01)
    acting = VectorTransformAction(scaled, partial(typed_controls, task=env.family.name, dtype=env.action_space.dtype), env.action_space)
    return VectorTransformReward(acting, rl_reward)


def typed_controls(action: np.ndarray, task: str, dtype: Any) -> np.ndarray:
    """:func:`controls` in the env's action ``dtype``: the native vector env's action transform."""
    return controls(action, task).astype(dtype)


def rl_reward(reward: np.ndarray) -> np.ndarray:
    """The RL ids' reward: :func:`crash_aware` with :data:`RL_GAMMA` and :data:`RL_REWARD_SCALE`, float64."""
    return np.asarray(crash_aware(reward, RL_GAMMA, RL_REWARD_SCALE), dtype=np.float64)
