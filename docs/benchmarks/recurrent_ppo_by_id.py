"""RecurrentPPO on ``neurohover/GHH08-RL-v0`` by id, with delayed sensors: its learning curve and checkpoints.

The run of docs/deep-rl.md ("RecurrentPPO"), 2026-12-05::

    OMP_NUM_THREADS=1 python docs/benchmarks/recurrent_ppo_by_id.py 500000 8 '{"batch_size": 1024}' '{"obs_delay": 2}'

Arguments: environment steps, environments (``make_vec_env``), RecurrentPPO's keyword arguments as JSON and the
environment's (``env_kwargs``); every other setting sb3-contrib's default, seed 0. Every 50,000 steps it prints the
mean length and return of the last training episodes and saves ``rppo-STEPS.zip``, flown afterwards on full paper
episodes with ``neurohover evaluate-agent --sb3 rppo-STEPS.zip --algo ppo_lstm --rl-id --obs-delay 2 --mdps test``.
Needs sb3-contrib (``pip install '.[examples]'``).
"""

from __future__ import annotations

import json
import sys
import time

import numpy as np
import torch
from sb3_contrib import RecurrentPPO
from stable_baselines3.common.callbacks import BaseCallback
from stable_baselines3.common.env_util import make_vec_env

import neurohover  # noqa: F401  (registers the ids)

ENV_ID = "neurohover/GHH08-RL-v0"
EVERY = 50_000


class Log(BaseCallback):
    """Prints the learning curve and saves the model every ``EVERY`` environment steps."""

    def __init__(self) -> None:
        super().__init__()
        self.next, self.start = EVERY, time.time()

    def _on_step(self) -> bool:
        if self.num_timesteps >= self.next:
            self.next += EVERY
            episodes = list(self.model.ep_info_buffer)
            length = np.mean([e["l"] for e in episodes]) if episodes else 0.0
            ret = np.mean([e["r"] for e in episodes]) if episodes else 0.0
            print(f"step {self.num_timesteps} {time.time() - self.start:.0f}s episode length {length:.0f} return {ret:.1f}", flush=True)
            self.model.save(f"rppo-{self.num_timesteps}")
        return True


def main() -> None:
    steps, n_envs = int(sys.argv[1]), int(sys.argv[2])
    settings = json.loads(sys.argv[3]) if len(sys.argv) > 3 else {}
    env_kwargs = json.loads(sys.argv[4]) if len(sys.argv) > 4 else {}
    torch.set_num_threads(1)
    env = make_vec_env(ENV_ID, n_envs=n_envs, seed=0, env_kwargs=env_kwargs)
    model = RecurrentPPO("MlpLstmPolicy", env, seed=0, device="cpu", **settings)
    model.learn(steps, callback=Log())
    model.save("rppo-final")


if __name__ == "__main__":
    main()
