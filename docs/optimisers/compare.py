"""Steady-state / generational NE, CMA-ES and OpenAI-ES at equal episode budgets (docs/optimisers.md).

Two settings, 10 seeds each, every optimiser with its defaults and the same prototype (the
baseline-equivalent network) and resampling:

- GHH-08 training MDP 0: the paper's MLP, one episode per candidate (``fixed:1``), 5,000 full
  episodes; the champion flown on 100 fresh episodes of that MDP;
- FGHH (sigma 0.3) over G: the authors' SLP, 5 episodes per candidate (``fixed:5``, each on a fresh
  MDP), 20,000 episodes; the champion flown once on each of the family's 100 test MDPs, the same
  gusts for every champion.

Run from the repository root (``python3 docs/optimisers/compare.py --out docs/optimisers/results.json``);
``--seeds`` and ``--scale`` shrink it for a try.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

import neurohover as nh
from neurohover.evolution.evolve import evolve
from neurohover.evolution.fitness import episode_fitness

SETTINGS = {
    "ghh08-train0": {"target": ("ghh08", "train:0"), "resampling": "fixed:1", "budget": 5000},
    "fghh-G": {"target": ("fghh", None), "resampling": "fixed:5", "budget": 20000},
}
OPTIMISERS = ("ne", "cma", "openai-es")
VALIDATION_SEED = 77


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--out", type=Path, required=True)
    p.add_argument("--seeds", type=int, default=10)
    p.add_argument("--scale", type=float, default=1.0, help="factor on the budgets (1: the documented run)")
    p.add_argument("--threads", type=int, default=1)
    args = p.parse_args(argv)
    rows = json.loads(args.out.read_text())["rows"] if args.out.exists() else []
    done = {(r["setting"], r["optimizer"], r["seed"]) for r in rows}
    for name, s in SETTINGS.items():
        task, mdp_name = s["target"]
        family = nh.get_task_family(task)
        target = family.mdp(mdp_name) if mdp_name else family
        budget = int(s["budget"] * args.scale)
        for seed in range(args.seeds):
            for opt in OPTIMISERS:
                if (name, opt, seed) in done:
                    continue
                t0 = time.perf_counter()
                result = evolve(target, optimizer=opt, resampling=s["resampling"], budget=budget, seed=seed, threads=args.threads)
                seconds = time.perf_counter() - t0
                if mdp_name:
                    ev = nh.evaluate(result.champion, target, episodes=100, seed=VALIDATION_SEED, threads=args.threads)
                else:
                    ev = nh.evaluate(result.champion, family.test_mdps(), episodes=1, seed=VALIDATION_SEED, threads=args.threads)
                returns, crashed = ev.returns.ravel(), ev.crashed.ravel()
                rows.append(
                    {
                        "setting": name,
                        "optimizer": opt,
                        "method": result.champion.metadata["method"],
                        "seed": seed,
                        "budget": budget,
                        "episodes": result.episodes,
                        "generations": result.generations,
                        "seconds": seconds,
                        "validation_mean_return": float(returns.mean()),
                        "validation_median_return": float(np.median(returns)),
                        "validation_mean_inv_log_error": float(episode_fitness(returns, "inv-log-error").mean()),
                        "validation_crashes": int(crashed.sum()),
                        "validation_episodes": int(returns.size),
                    }
                )
                print(json.dumps(rows[-1]), flush=True)
                args.out.write_text(json.dumps({"rows": rows}, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
