"""PPO.learn through SB3VecEnv vs make_vec_env (DummyVecEnv), side by side: total time and the time in the env's step.

python docs/benchmarks/sb3_learn_speed.py      # needs stable-baselines3 (docs/deep-rl.md, "By id alone")
"""

import time

import torch
from stable_baselines3 import PPO
from stable_baselines3.common.env_util import make_vec_env
from stable_baselines3.common.vec_env import VecMonitor

import neurohover  # noqa: F401  (registers the ids)
from neurohover.integrations.sb3 import SB3VecEnv

torch.set_num_threads(1)
n_envs, steps = 64, 64 * 512


def timed(env):
    """The env with its step_wait timed (seconds in a one-element list)."""
    spent = [0.0]
    step_wait = env.step_wait

    def wrapped():
        t = time.perf_counter()
        out = step_wait()
        spent[0] += time.perf_counter() - t
        return out

    env.step_wait = wrapped
    return env, spent


for _rep in range(2):
    for name in ("native", "dummy"):
        env = (
            VecMonitor(SB3VecEnv("neurohover/GHH08-RL-v0", num_envs=n_envs))
            if name == "native"
            else make_vec_env("neurohover/GHH08-RL-v0", n_envs=n_envs, seed=0)
        )
        inner = env.venv if name == "native" else env
        inner, spent = timed(inner)
        model = PPO("MlpPolicy", env, n_steps=512, batch_size=2048, seed=0, device="cpu")
        t = time.perf_counter()
        model.learn(steps)
        total = time.perf_counter() - t
        print(f"{name}: {steps} steps in {total:.1f} s ({steps / total:,.0f}/s); env step {spent[0]:.1f} s; the rest {total - spent[0]:.1f} s", flush=True)
