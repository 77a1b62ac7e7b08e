"""Deep-RL baseline: Stable-Baselines3 PPO (or SAC) on GHH-08 hovering, through the Gymnasium API.

A single-file, CleanRL-style script: read it top to bottom. It

1. builds training environments with ``gymnasium.make("neurohover/GHH08-v0", ...)`` and
   Gymnasium wrappers only: float32 observations, short training episodes (``episode_steps``),
   raw episode statistics, and a reward transform that tames the crash penalty (below);
2. trains PPO (default) or SAC from Stable-Baselines3, with running observation normalisation
   (``VecNormalize``, observations only), and records the training curve;
3. evaluates the trained policy, deterministically, on full 6000-step episodes of the raw
   environment (the returns the paper reports) on the training setting and on a few GHH-08 test
   MDPs, next to the competition's baseline policy flying the very same gusts;
4. prints a small table and writes ``OUT/results.json`` (plus the model and the normalisation
   statistics).

Install and run (``docs/deep-rl.md`` has the comparison with neuroevolution)::

    pip install -e '.[examples]'          # stable-baselines3 (and torch)
    python examples/ppo_ghh08.py --mdp zero --total-steps 500000 --seed 0 --out runs/ppo-zero
    python examples/ppo_ghh08.py --mdp train:3 --total-steps 500000 --seed 0 --out runs/ppo-train3
    python examples/ppo_ghh08.py --mdp sample --total-steps 500000 --out runs/ppo-G   # a fresh MDP from G per episode

Why the reward transform. A step earns minus the sum of squares of the observation (about -0.2
in calm air, -5 to -20 in wind); a crash earns once the worst possible step (``P =
CRASH_STEP_PENALTY``, 1748.8) times the steps left, up to about -1.75e6 in a 1000-step training
episode. Value targets mixing -1 and -1e6 would make the critic's loss all about crashes, and
since PPO clips the gradient norm of the joint loss, the policy's step too (not tried here). Squashing every reward with ``-log(1 + |r|)`` (the
README's example) bounds them, but then a crash (about -14) is *cheaper* than flying on at -1 per
step for the discount horizon, and the agent learns to crash. So :class:`neurohover.wrappers.CrashAwareReward` squashes
the ordinary steps, ``-log(1 + |r|)``, and keeps the meaning of the crash penalty, "the worst step
for every step left", in the squashed and discounted currency: ``-log(1 + P) * (1 + g + ... +
g**(k-1))`` for the k steps left (the crashing one included). A crash is then always worse than
any way of flying on. ``--reward log`` trains on the README's plain squashing instead, for
comparison: with it PPO learned to crash at the first step of every episode (docs/deep-rl.md).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import gymnasium as gym
import numpy as np

try:
    import torch
    from stable_baselines3 import PPO, SAC
    from stable_baselines3.common.callbacks import BaseCallback
    from stable_baselines3.common.vec_env import DummyVecEnv, VecNormalize
except ModuleNotFoundError as missing:  # the examples extra is not installed: one clear line, exit 2
    print(
        f"examples/ppo_ghh08.py needs {missing.name}: pip install 'neurohover[examples]' (for a CPU build of torch first: pip install torch==2.13.0)",
        file=sys.stderr,
    )
    raise SystemExit(2) from None

import neurohover  # noqa: F401  (registers the neurohover/* environments)
from neurohover import baseline_policy
from neurohover.wrappers import CrashAwareReward

ENV_ID = "neurohover/GHH08-v0"
FULL_EPISODE = 6000  # steps of the paper's episodes (10 minutes at 10 Hz)


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0], formatter_class=argparse.ArgumentDefaultsHelpFormatter)
    p.add_argument("--algo", choices=("ppo", "sac"), default="ppo", help="Stable-Baselines3 algorithm")
    p.add_argument("--mdp", default="zero", help="training MDP: zero, train:N, test:N, or sample (a fresh MDP from G per episode)")
    p.add_argument("--total-steps", type=int, default=500_000, help="environment steps of training")
    p.add_argument("--episode-steps", type=int, default=1000, help="steps per training episode (evaluation always flies 6000)")
    p.add_argument("--seed", type=int, default=0, help="seed of the training run (networks, environments)")
    p.add_argument("--n-envs", type=int, default=8, help="parallel training environments (PPO)")
    p.add_argument("--n-steps", type=int, default=512, help="PPO: steps per environment per rollout")
    p.add_argument("--gamma", type=float, default=0.99, help="discount factor (also used by the reward transform)")
    p.add_argument("--reward", choices=("crash-aware", "log"), default="crash-aware", help="reward transform for learning (see the module docstring)")
    p.add_argument("--reward-scale", type=float, default=0.1, help="factor on the transformed rewards")
    p.add_argument("--learning-rate", type=float, default=3e-4)
    p.add_argument("--eval-episodes", type=int, default=20, help="full 6000-step episodes per evaluation MDP")
    p.add_argument("--eval-seed", type=int, default=0, help="gust noise of evaluation episode i is stream (eval-seed, i), as `neurohover fly --seed`")
    p.add_argument("--test-mdps", default="test:0,test:1,test:2,test:3,test:4", help="comma-separated GHH-08 MDPs also evaluated ('' for none)")
    p.add_argument("--threads", type=int, default=1, help="torch threads (small networks run best on one)")
    p.add_argument("--out", type=Path, default=Path("runs/ppo-ghh08"), help="output directory")
    p.add_argument("--quiet", action="store_true", help="no progress lines while training")
    return p.parse_args(argv)


# ---------------------------------------------------------------------------------------------
# Environments
# ---------------------------------------------------------------------------------------------


def make_train_env(args: argparse.Namespace):
    """A function building one training environment (what Stable-Baselines3's vector envs want)."""

    def thunk() -> gym.Env:
        env = gym.make(ENV_ID, mdp=args.mdp, obs_dtype="float32", episode_steps=args.episode_steps, max_episode_steps=args.episode_steps)
        env = gym.wrappers.RecordEpisodeStatistics(env)  # info["episode"]: raw return "r", length "l"
        if args.reward == "log":  # the README's example: sign(r) log(1 + |r|), a crash about -14
            return gym.wrappers.TransformReward(env, lambda r: args.reward_scale * float(np.sign(r) * np.log1p(abs(r))))
        return CrashAwareReward(env, args.gamma, args.reward_scale)

    return thunk


# ---------------------------------------------------------------------------------------------
# Training
# ---------------------------------------------------------------------------------------------


class TrainingCurve(BaseCallback):
    """Collects every finished training episode (raw return, length, crash) and prints progress every ``every`` steps."""

    def __init__(self, quiet: bool, every: int = 10_000) -> None:
        super().__init__()
        self.quiet, self.every, self.next_print = quiet, every, every
        self.episodes: list[dict] = []  # {"step", "return", "length", "crashed"}
        self.start = time.perf_counter()

    def _on_step(self) -> bool:
        for info, done in zip(self.locals["infos"], self.locals["dones"]):
            if done and "episode" in info:
                ep = info["episode"]
                self.episodes.append({"step": self.num_timesteps, "return": float(ep["r"]), "length": int(ep["l"]), "crashed": bool(info["crashed"])})
        return True

    def _on_rollout_end(self) -> None:  # PPO: after each rollout; SAC: after every step
        if self.quiet or not self.episodes or self.num_timesteps < self.next_print:
            return
        self.next_print += self.every * ((self.num_timesteps - self.next_print) // self.every + 1)
        last = self.episodes[-20:]
        sps = self.num_timesteps / (time.perf_counter() - self.start)
        print(
            f"step {self.num_timesteps:>8}  episodes {len(self.episodes):>6}  last {len(last)}: "
            f"return {np.mean([e['return'] for e in last]):>12.4g}  length {np.mean([e['length'] for e in last]):>7.1f}  "
            f"crashed {np.mean([e['crashed'] for e in last]):4.0%}  ({sps:.0f} steps/s)",
            flush=True,
        )


def train(args: argparse.Namespace):
    n_envs = args.n_envs if args.algo == "ppo" else 1
    venv = DummyVecEnv([make_train_env(args) for _ in range(n_envs)])
    venv = VecNormalize(venv, norm_obs=True, norm_reward=False, clip_obs=10.0, gamma=args.gamma)
    if args.algo == "ppo":
        model = PPO(
            "MlpPolicy",
            venv,
            n_steps=args.n_steps,
            batch_size=256,
            n_epochs=10,
            learning_rate=args.learning_rate,
            gamma=args.gamma,
            gae_lambda=0.95,
            clip_range=0.2,
            ent_coef=0.0,
            max_grad_norm=0.5,
            # A Gaussian policy, its actions clipped to [-1, 1] by SB3 (and the simulator).
            policy_kwargs={"net_arch": {"pi": [64, 64], "vf": [64, 64]}, "log_std_init": -1.0},
            seed=args.seed,
            device="cpu",
            verbose=0,
        )
    else:  # SAC: a tanh-squashed Gaussian policy, actions in [-1, 1] by construction
        model = SAC(
            "MlpPolicy",
            venv,
            learning_rate=args.learning_rate,
            buffer_size=min(args.total_steps, 1_000_000),
            learning_starts=min(5000, args.total_steps // 10),
            batch_size=256,
            gamma=args.gamma,
            policy_kwargs={"net_arch": [256, 256]},
            seed=args.seed,
            device="cpu",
            verbose=0,
        )
    curve = TrainingCurve(args.quiet)
    start = time.perf_counter()
    model.learn(total_timesteps=args.total_steps, callback=curve)
    seconds = time.perf_counter() - start
    venv.training = False  # freeze the observation statistics for evaluation
    return model, venv, curve.episodes, seconds


# ---------------------------------------------------------------------------------------------
# Evaluation on full 6000-step episodes of the raw environment
# ---------------------------------------------------------------------------------------------


def fly(act, mdp: str, episodes: int, seed: int) -> dict:
    """Fly ``act`` (a batch of float32 observations -> a batch of actions) for ``episodes`` full episodes.

    Episode i meets the gust stream (seed, i), the one ``neurohover fly --seed SEED`` flies as its
    episode i, so every policy evaluated here faces the same gusts. All episodes step in lockstep
    so that the network runs once per step for the whole batch.
    """
    start = time.perf_counter()
    envs = [gym.make(ENV_ID, mdp=mdp, obs_dtype="float32") for _ in range(episodes)]  # 6000 steps, raw rewards
    obs = np.stack([env.reset(seed=seed * 100_003 + i, options={"noise": (seed, i)})[0] for i, env in enumerate(envs)])
    returns, steps, crashed = np.zeros(episodes), np.zeros(episodes, dtype=int), np.zeros(episodes, dtype=bool)
    alive = np.ones(episodes, dtype=bool)
    while alive.any():
        live = np.flatnonzero(alive)
        actions = act(obs[live])
        for a, i in zip(actions, live):
            obs[i], reward, terminated, truncated, _ = envs[i].step(a)
            returns[i] += reward
            steps[i] += 1
            crashed[i] |= terminated
            alive[i] = not (terminated or truncated)
    for env in envs:
        env.close()
    return {
        "mdp": mdp,
        "episodes": episodes,
        "mean_return": float(returns.mean()),
        "std_return": float(returns.std()),  # population sd, as `neurohover fly` gives it
        "crashes": int(crashed.sum()),
        "mean_steps": float(steps.mean()),
        "seconds": time.perf_counter() - start,
        "returns": returns.tolist(),
    }


def evaluate(model, venv: VecNormalize, args: argparse.Namespace) -> list[dict]:
    def agent(obs: np.ndarray) -> np.ndarray:
        return model.predict(venv.normalize_obs(obs), deterministic=True)[0]

    baseline = baseline_policy()

    def reference(obs: np.ndarray) -> np.ndarray:
        return np.array([baseline.act(o) for o in obs])

    mdps = [args.mdp] + [m for m in args.test_mdps.split(",") if m and m != args.mdp]
    rows = []
    for mdp in mdps:
        for name, act in ((args.algo, agent), ("baseline", reference)):
            rows.append({"policy": name, **fly(act, mdp, args.eval_episodes, args.eval_seed)})
    return rows


def print_table(rows: list[dict]) -> None:
    print(f"\n{'policy':<9} {'MDP':<8} {'episodes':>8} {'mean return':>13} {'sd':>11} {'crashes':>7} {'mean steps':>10} {'wall s':>7}")
    for r in rows:
        print(
            f"{r['policy']:<9} {r['mdp']:<8} {r['episodes']:>8} {r['mean_return']:>13.6g} {r['std_return']:>11.4g} "
            f"{r['crashes']:>7} {r['mean_steps']:>10.0f} {r['seconds']:>7.1f}"
        )


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    torch.set_num_threads(args.threads)
    args.out.mkdir(parents=True, exist_ok=True)

    model, venv, curve, train_seconds = train(args)
    model.save(args.out / "model.zip")
    venv.save(str(args.out / "vecnormalize.pkl"))
    done = curve[-20:]
    print(
        f"trained {args.algo} on {ENV_ID} mdp={args.mdp}: {args.total_steps} steps ({args.total_steps / FULL_EPISODE:.1f} full-episode equivalents), "
        f"{len(curve)} training episodes, {train_seconds:.0f} s; last {len(done)} episodes: "
        f"mean length {np.mean([e['length'] for e in done]) if done else float('nan'):.0f} of {args.episode_steps}, "
        f"{sum(e['crashed'] for e in done)} crashed"
    )

    rows = evaluate(model, venv, args)
    print_table(rows)
    results = {
        "env_id": ENV_ID,
        "args": {k: str(v) if isinstance(v, Path) else v for k, v in vars(args).items()},
        "training": {
            "steps": args.total_steps,
            "full_episode_equivalents": args.total_steps / FULL_EPISODE,
            "episodes": len(curve),
            "seconds": train_seconds,
            "curve": curve,
        },
        "evaluation": rows,
    }
    (args.out / "results.json").write_text(json.dumps(results, indent=1))
    print(f"\nwrote {args.out / 'results.json'}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
