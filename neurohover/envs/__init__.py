"""Gymnasium environments, registered on import of :mod:`neurohover`.

Ids: ``neurohover/GHH08-v0``, ``neurohover/GHH09-v0`` and ``neurohover/FGHH-v0`` (which takes
``sigma``, default 0.3): one per task family. ``gymnasium.make`` builds :class:`HoverEnv`;
``gymnasium.make_vec(..., vectorization_mode="vector_entry_point")`` builds
:class:`HoverVectorEnv`, which steps every helicopter in one kernel call.
"""

from __future__ import annotations

import gymnasium

from ..sim.constants import EPISODE_STEPS
from ..tasks import TASK_NAMES
from .hover import HoverEnv
from .vector import HoverVectorEnv

#: One id per task family, ``neurohover/<NAME>-v0``.
ENV_IDS: dict[str, str] = {f"neurohover/{name.upper()}-v0": name for name in TASK_NAMES}


def register_envs() -> None:
    """Register the environments with Gymnasium; ids already registered are left alone."""
    for env_id, task in ENV_IDS.items():
        if env_id in gymnasium.registry:  # re-import or reload: Gymnasium would warn about overriding
            continue
        gymnasium.register(
            id=env_id,
            entry_point="neurohover.envs.hover:HoverEnv",
            vector_entry_point="neurohover.envs.vector:HoverVectorEnv",
            max_episode_steps=EPISODE_STEPS,
            kwargs={"task": task},
        )


register_envs()

__all__ = ["ENV_IDS", "HoverEnv", "HoverVectorEnv", "register_envs"]
