"""RL Zoo hyperparameters for PPO on the short deep-RL variants (``docs/deep-rl.md``, "RL Zoo").

RL Zoo reads a Python module's ``hyperparams`` dict when ``--conf-file`` names the module::

    python -m rl_zoo3.train --algo ppo --env neurohover/GHH08-Short-v0 --gym-packages neurohover \\
        --conf-file neurohover.integrations.rlzoo_ppo --seed 0 --num-threads 1

The recipe is ``examples/ppo_ghh08.py``'s, measured there and in ``docs/deep-rl.md``: 8
environments x 512 steps per rollout, batch 256, 10 epochs, learning rate 3e-4, no entropy
bonus, initial log std -1; observations normalised by ``VecNormalize`` (rewards not: the
crash-aware squash, :class:`neurohover.wrappers.CrashAwareReward`, already bounds them and keeps a
crash worse than any way of flying on). Add ``--env-kwargs mdp:"'train:3'"`` to train on one MDP
(the default, ``sample``, draws a fresh MDP of the family for every episode).
Importing this module needs nothing beyond neurohover: RL Zoo itself imports SB3.
"""

from __future__ import annotations

from typing import Any

from ..envs import SHORT_ENV_IDS

GAMMA = 0.99
N_TIMESTEPS = 500_000  # docs/deep-rl.md: the steps the recipe was measured to hover in

PPO: dict[str, Any] = {
    "policy": "MlpPolicy",
    "n_timesteps": N_TIMESTEPS,
    "n_envs": 8,
    "n_steps": 512,
    "batch_size": 256,
    "n_epochs": 10,
    "learning_rate": 3e-4,
    "gamma": GAMMA,
    "gae_lambda": 0.95,
    "clip_range": 0.2,
    "ent_coef": 0.0,
    "max_grad_norm": 0.5,
    "policy_kwargs": "dict(log_std_init=-1.0)",  # SB3's default 64-64 tanh actor and critic
    "normalize": "{'norm_obs': True, 'norm_reward': False}",
    "env_wrapper": [{"neurohover.wrappers.CrashAwareReward": {"gamma": GAMMA, "scale": 0.1}}],
}

#: One entry per short id (RL Zoo looks its ``--env`` up here).
hyperparams: dict[str, dict[str, Any]] = {env_id: dict(PPO) for env_id in SHORT_ENV_IDS}
