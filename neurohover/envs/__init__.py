"""Gymnasium environments, registered on import of :mod:`neurohover`.

Ids: ``neurohover/GHH08-v0``, ``neurohover/GHH09-v0`` and ``neurohover/FGHH-v0`` (which takes
``sigma``, default 0.3): one per task family, the paper's 6000-step episodes in float64; and
``neurohover/<NAME>-Short-v0`` for deep RL: 1000-step episodes whose crash charge counts the
steps left of the short episode, float32 observations and actions (:class:`HoverEnv`'s docstring
has the table); ``neurohover/<NAME>-RL-v0``: the short ones with scaled observations and actions and the
crash-aware reward built in, for a library's default settings (:mod:`neurohover.envs.rl`); and
``neurohover/<NAME>-NoisySensors-v0``, ``-CorrelatedSensors-v0`` and
``-DelayedSensors-v0``: the paper's episodes seen through the harder sensors of its Section 7
(:data:`SENSOR_ENV_SETTINGS`, :mod:`neurohover.tasks.sensor`); and ``-DriftingDynamics-v0`` and
``-AbruptChange-v0``: test runs of one MDP whose dynamics drift between episodes
(:data:`DRIFT_ENV_SETTINGS`, :mod:`neurohover.tasks.drift`). ``gymnasium.make`` builds :class:`HoverEnv`;
``gymnasium.make_vec(..., vectorization_mode="vector_entry_point")`` builds
:class:`HoverVectorEnv`, which steps every helicopter in one kernel call.

Each id's time limit (``max_episode_steps``) is its ``episode_steps``. A time limit that cuts episodes before their
``episode_steps``, the id's beside a longer ``episode_steps`` or one given to ``make``/``make_vec`` below it, is warned of,
not refused: the episodes are truncated there while a crash is still charged for the steps left of ``episode_steps``
(:func:`~neurohover.envs.arguments.check_against_id`; T23-17).
"""

from __future__ import annotations

import gymnasium

from ..sim.constants import EPISODE_STEPS
from ..tasks import TASK_NAMES
from .hover import HoverEnv
from .rl import RL_SETTINGS
from .vector import HoverVectorEnv

#: One id per task family, ``neurohover/<NAME>-v0``.
ENV_IDS: dict[str, str] = {f"neurohover/{name.upper()}-v0": name for name in TASK_NAMES}
SHORT_EPISODE_STEPS = 1000
#: The deep-RL variant of each family, ``neurohover/<NAME>-Short-v0``: its settings over the family's.
SHORT_ENV_IDS: dict[str, str] = {f"neurohover/{name.upper()}-Short-v0": name for name in TASK_NAMES}
SHORT_SETTINGS = {"episode_steps": SHORT_EPISODE_STEPS, "obs_dtype": "float32", "action_dtype": "float32"}


#: The deep-RL ids of each family, ``neurohover/<NAME>-RL-v0`` (:mod:`neurohover.envs.rl`): short float32 episodes with
#: scaled observations and the crash-aware reward built in, for learning with a library's default settings.
RL_ENV_IDS: dict[str, str] = {f"neurohover/{name.upper()}-RL-v0": name for name in TASK_NAMES}


#: The sensor variants' settings, by the suffix of their ids (``neurohover/<NAME>-<suffix>-v0``).
SENSOR_ENV_SETTINGS: dict[str, dict] = {
    "NoisySensors": {"obs_noise": 1.0},  # level 1, white
    "CorrelatedSensors": {"obs_noise": {"level": 1.0, "correlation": 0.95}},  # level 1, AR(1) as motion capture drifts
    "DelayedSensors": {"obs_delay": 2},  # exact readings 0.2 s late
}
#: Every sensor variant id and its task family.
SENSOR_ENV_IDS: dict[str, str] = {f"neurohover/{name.upper()}-{suffix}-v0": name for name in TASK_NAMES for suffix in SENSOR_ENV_SETTINGS}

#: The drifting-dynamics variants' settings (:mod:`neurohover.tasks.drift`), by the suffix of their ids: their
#: episodes are test runs of one MDP (HoverEnv's docstring), so they have no vector entry point.
DRIFT_ENV_SETTINGS: dict[str, dict] = {
    "DriftingDynamics": {"drift": {"walk": 0.01}},  # a slow log random walk of the 11 dynamics parameters
    "AbruptChange": {"drift": {"change": {"D_w": 0.8}}},  # the collective's gain loses 20 % at an episode in 200..800
}
DRIFT_ENV_IDS: dict[str, str] = {f"neurohover/{name.upper()}-{suffix}-v0": name for name in TASK_NAMES for suffix in DRIFT_ENV_SETTINGS}


def register_envs() -> None:
    """Register the environments with Gymnasium; ids already registered are left alone.

    Gymnasium's passive checker is off for them (``disable_env_checker``): in Gymnasium 1.4 it marks its reset check
    done before the first reset returns, so after a refused first reset (a bad seed or MDP) the first step of a
    corrected episode raised a TypeError of its own (ninth trial). The tests run Gymnasium's full ``check_env`` on
    every id instead.
    """
    ids: list[tuple[str, str, dict, int]] = [(env_id, task, {}, EPISODE_STEPS) for env_id, task in ENV_IDS.items()]
    ids += [(env_id, task, SHORT_SETTINGS, SHORT_EPISODE_STEPS) for env_id, task in SHORT_ENV_IDS.items()]
    ids += [(env_id, task, SENSOR_ENV_SETTINGS[env_id.split("-")[1]], EPISODE_STEPS) for env_id, task in SENSOR_ENV_IDS.items()]
    ids += [(env_id, task, DRIFT_ENV_SETTINGS[env_id.split("-")[1]], EPISODE_STEPS) for env_id, task in DRIFT_ENV_IDS.items()]
    for env_id, task in RL_ENV_IDS.items():
        if env_id not in gymnasium.registry:
            gymnasium.register(
                id=env_id,
                entry_point="neurohover.envs.rl:make_rl_env",
                vector_entry_point="neurohover.envs.rl:make_rl_vector_env",
                max_episode_steps=RL_SETTINGS["episode_steps"],
                kwargs={"task": task},
                disable_env_checker=True,
            )
    for env_id, task, settings, limit in ids:
        if env_id in gymnasium.registry:  # re-import or reload: Gymnasium would warn about overriding
            continue
        vector = None if "drift" in settings else "neurohover.envs.vector:HoverVectorEnv"
        gymnasium.register(
            id=env_id,
            entry_point="neurohover.envs.hover:HoverEnv",
            vector_entry_point=vector,
            max_episode_steps=limit,
            kwargs={"task": task, **settings},
            disable_env_checker=True,
        )


register_envs()

__all__ = [
    "DRIFT_ENV_IDS",
    "DRIFT_ENV_SETTINGS",
    "ENV_IDS",
    "RL_ENV_IDS",
    "SENSOR_ENV_IDS",
    "SENSOR_ENV_SETTINGS",
    "SHORT_ENV_IDS",
    "HoverEnv",
    "HoverVectorEnv",
    "register_envs",
]
