"""Fly an RL Zoo run's trained policy on full 6000-step episodes, beside the baseline and the NE generic.

RL Zoo trains on the short deep-RL variants with the shipped recipe
(``neurohover.integrations.rlzoo_ppo``); this script then flies the run's final model, with its
frozen observation statistics, on the paper's full episodes of the raw environment, beside the
competition's baseline and the shipped generic policy (the paper's neuroevolution), all on the
gusts ``neurohover.evaluate`` gives, and prints one row per MDP::

    pip install 'neurohover[examples]' rl_zoo3          # for a CPU build of torch first: pip install torch==2.13.0
    python -m rl_zoo3.train --algo ppo --env neurohover/GHH08-Short-v0 --gym-packages neurohover \\
        --conf-file neurohover.integrations.rlzoo_ppo --seed 0 --num-threads 1 -f logs
    python examples/evaluate_rl_zoo.py logs/ppo/neurohover-GHH08-Short-v0_1 --mdps train --episodes 20

``docs/deep-rl.md`` ("RL Zoo") has the measured table.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

try:
    from neurohover.integrations.sb3 import rl_zoo_policy
except ValueError as missing:  # NeurohoverError: the examples extra is not installed
    print(f"examples/evaluate_rl_zoo.py: {missing}", file=sys.stderr)
    raise SystemExit(2) from None

import neurohover as nh
from neurohover.integrations.flying import evaluate_callable
from neurohover.policysets import load_policy_set


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0], formatter_class=argparse.ArgumentDefaultsHelpFormatter)
    p.add_argument("run", type=Path, help="an RL Zoo run folder (logs/ALGO/ENV_N)")
    p.add_argument("--algo", default="ppo", help="the run's algorithm")
    p.add_argument("--task", default="ghh08", help="task family of the MDPs")
    p.add_argument("--mdps", default="train", help="'train' (the competition's training MDPs), 'test', or a comma list (zero,train:3,...)")
    p.add_argument("--episodes", type=int, default=20, help="full episodes per MDP")
    p.add_argument("--seed", type=int, default=0, help="gust-noise seed, as neurohover evaluate's")
    p.add_argument("--out", type=Path, help="write the rows as JSON here")
    return p.parse_args(argv)


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    try:
        family = nh.get_task_family(args.task)
        names = [s for s in args.mdps.split(",") if s]
        if names in (["train"], ["test"]):
            fixed = family.training_mdps() if names == ["train"] else family.test_mdps()
            names = [f"{names[0]}:{i}" for i in range(len(fixed))]
        mdps = [family.mdp(name) for name in names]
        act = rl_zoo_policy(args.run, algo=args.algo)
        learned = evaluate_callable(act, mdps, episodes=args.episodes, seed=args.seed)
    except nh.NeurohoverError as err:
        print(f"examples/evaluate_rl_zoo.py: {err}", file=sys.stderr)
        return 2
    # The competition's baseline and the shipped generic policy (the paper's neuroevolution), on the same gusts.
    generic = load_policy_set(family.name).generic
    others = nh.evaluate([nh.baseline_policy(), generic], mdps, episodes=args.episodes, seed=args.seed)
    rows = []
    print(f"{'MDP':<9} {'learned':>11} {'crashes':>7} {'baseline':>11} {'crashes':>7} {'NE generic':>11} {'crashes':>7}")
    for m, name in enumerate(names):
        row = {
            "mdp": name,
            "episodes": args.episodes,
            "learned_mean_return": float(learned.returns[m].mean()),
            "learned_sd_return": float(learned.returns[m].std()),
            "learned_crashes": int(learned.crashed[m].sum()),
            "baseline_mean_return": float(others.returns[0, m].mean()),
            "baseline_crashes": int(others.crashed[0, m].sum()),
            "generic_mean_return": float(others.returns[1, m].mean()),
            "generic_crashes": int(others.crashed[1, m].sum()),
        }
        rows.append(row)
        print(
            f"{name:<9} {row['learned_mean_return']:>11.6g} {row['learned_crashes']:>7} {row['baseline_mean_return']:>11.6g} "
            f"{row['baseline_crashes']:>7} {row['generic_mean_return']:>11.6g} {row['generic_crashes']:>7}"
        )
    total = int(learned.crashed.sum())
    print(f"learned: {total} crashes in {learned.episodes} full episodes; mean return {np.mean(learned.returns):.6g} ({learned.seconds:.1f} s)")
    if args.out:
        args.out.write_text(json.dumps({"run": str(args.run), "seed": args.seed, "rows": rows}, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
