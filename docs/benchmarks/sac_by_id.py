"""SAC on ``neurohover/GHH08-RL-v0`` by id: its training episodes' length and its deterministic policy's, as it learns.

The runs of docs/deep-rl.md ("SAC"), 2026-12-05::

    OMP_NUM_THREADS=1 python docs/benchmarks/sac_by_id.py default 15000 1
    OMP_NUM_THREADS=1 python docs/benchmarks/sac_by_id.py ent01 100000 1 '{"ent_coef": 0.01}'
    OMP_NUM_THREADS=1 python docs/benchmarks/sac_by_id.py ent01-8env 300000 8 '{"ent_coef": 0.01}'
    OMP_NUM_THREADS=1 python docs/benchmarks/sac_by_id.py tent0 100000 1 '{"target_entropy": 0.0}'

Arguments: a name for the run, its environment steps, its environments (``make_vec_env``), SAC's keyword arguments as
JSON and the environment's (``env_kwargs``, e.g. ``'{"obs_delay": 2}'``); every other setting SB3's default, seed 0.
Every 25,000 steps (10,000 with one environment) it prints the mean length and return of the last training episodes,
the entropy coefficient, and the steps the deterministic policy flies on test MDPs 0-4 (1000-step episodes). Needs
stable-baselines3 (``pip install '.[examples]'``).
"""

from __future__ import annotations

import json
import sys
import time

import gymnasium as gym
import numpy as np
import torch
from stable_baselines3 import SAC
from stable_baselines3.common.callbacks import BaseCallback
from stable_baselines3.common.env_util import make_vec_env

import neurohover  # noqa: F401  (registers the ids)

ENV_ID = "neurohover/GHH08-RL-v0"


def deterministic_lengths(model: SAC, mdps: int = 5) -> list[int]:
    """Steps the deterministic policy flies on test MDPs 0..mdps-1 (1000 at most)."""
    lengths = []
    for i in range(mdps):
        env = gym.make(ENV_ID, mdp=f"test:{i}")
        obs, _ = env.reset(seed=100 + i)
        flown, done = 0, False
        while flown < 1000 and not done:
            obs, _, terminated, truncated, _ = env.step(model.predict(obs, deterministic=True)[0])
            flown, done = flown + 1, terminated or truncated
        lengths.append(flown)
    return lengths


class Log(BaseCallback):
    """Prints the learning curve every ``every`` environment steps."""

    def __init__(self, name: str, every: int) -> None:
        super().__init__()
        self.name, self.every, self.next, self.start = name, every, every, time.time()

    def _on_step(self) -> bool:
        if self.num_timesteps >= self.next:
            self.next += self.every
            episodes = list(self.model.ep_info_buffer)
            length = np.mean([e["l"] for e in episodes]) if episodes else 0.0
            ret = np.mean([e["r"] for e in episodes]) if episodes else 0.0
            coef = self.model.logger.name_to_value.get("train/ent_coef", float("nan"))
            print(
                f"{self.name} step {self.num_timesteps} {time.time() - self.start:.0f}s episode length {length:.0f} "
                f"return {ret:.1f} ent_coef {coef:.4g} deterministic {deterministic_lengths(self.model)}",
                flush=True,
            )
        return True


def main() -> None:
    name, steps, n_envs = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
    settings = json.loads(sys.argv[4]) if len(sys.argv) > 4 else {}
    env_kwargs = json.loads(sys.argv[5]) if len(sys.argv) > 5 else {}
    torch.set_num_threads(1)
    model = SAC("MlpPolicy", make_vec_env(ENV_ID, n_envs=n_envs, seed=0, env_kwargs=env_kwargs), seed=0, device="cpu", **settings)
    model.learn(steps, callback=Log(name, 10_000 if n_envs == 1 else 25_000))
    model.save(f"sac-{name}")


if __name__ == "__main__":
    main()
