"""NEAT against the paper's fixed topologies on GHH-08 (issue 35; docs/topology.md).

The paper (Section 3.1): NEAT "did not discover topologies that outperformed the manually designed
topology", with no numbers. Here, on GHH-08 training MDP 0 at one episode budget: NEAT (neat-python,
from a fully connected 9 -> 4 network, population 150, one episode a genome; random, zero or the
baseline at the start) against steady-state NE
(the paper's Table 6) evolving the SLP and the paper's MLP, each from zero and from the baseline. Every
champion then flies the same fresh validation episodes (gust streams (VALIDATION_SEED, 0..n-1)).

    python3 docs/topology/neat_ghh08.py --budget 10000 --seeds 3 --out docs/topology/neat-ghh08.json
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np

from neurohover import evaluate, get_task_family
from neurohover.evolution.evolve import evolve
from neurohover.integrations.flying import evaluate_callable
from neurohover.integrations.neat import NeatSettings, evolve_topology
from neurohover.policies import prototype

VALIDATION_SEED = 777
#: neat-python's usual settings; the same from the zero network (NE's zero prototype); from the baseline.
NEAT_VARIANTS = {
    "neat": NeatSettings(),
    "neat-zero": NeatSettings(weight_init_stdev=0.0, bias_init_stdev=0.0),
    "neat-baseline": NeatSettings(start="baseline", activations=("identity", "tanh", "sigmoid")),
    # mutations of the baseline's size (its gains are 0.02-0.8, its collective bias 0.23), a tenth of the weights at a
    # time, as NE's operators make them: no weight drawn afresh, no connection or node deleted, a linear output kept
    # linear; nodes and connections still added
    "neat-baseline-fine": NeatSettings(
        start="baseline",
        activations=("identity", "tanh", "sigmoid"),
        weight_mutate_power=0.02,
        weight_mutate_rate=0.1,
        bias_mutate_power=0.01,
        activation_mutate_rate=0.0,
        replace_rate=0.0,
        conn_delete_prob=0.0,
        node_delete_prob=0.0,
    ),
}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--budget", type=int, default=10000)
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--validation", type=int, default=20)
    ap.add_argument("--mdp", default="train:0")
    ap.add_argument("--out", required=True)
    ap.add_argument("--methods", help="comma-separated subset of the methods (default: all)")
    args = ap.parse_args()
    mdp = get_task_family("ghh08").mdp(args.mdp)
    runs = []
    for seed in range(args.seeds):
        for method, settings in NEAT_VARIANTS.items():
            if args.methods and method not in args.methods.split(","):
                continue
            t0 = time.perf_counter()
            neat = evolve_topology(mdp, budget=args.budget, seed=seed, settings=settings)
            val = evaluate_callable(neat.act, mdp, episodes=args.validation, seed=VALIDATION_SEED, obs_dtype="float64")
            runs.append(
                {"method": method, "seed": seed, "seconds": time.perf_counter() - t0, "champion_estimate": neat.champion_fitness,
                 "nodes": neat.nodes, "connections": neat.connections, "episodes": neat.episodes,
                 "validation_mean": float(np.mean(val.returns)), "validation_crashes": int(np.sum(val.crashed))}
            )  # fmt: skip
            print(runs[-1], flush=True)
        for topology in ("slp", "mlp"):
            for start in ("zero", "baseline"):
                if args.methods and f"{topology}-{start}" not in args.methods.split(","):
                    continue
                t0 = time.perf_counter()
                r = evolve(mdp, topology=topology, prototype=prototype(topology, start), budget=args.budget, seed=seed)
                val = evaluate(r.champion, mdp, episodes=args.validation, seed=VALIDATION_SEED)
                runs.append(
                    {"method": f"{topology}-{start}", "seed": seed, "seconds": time.perf_counter() - t0, "champion_estimate": r.champion_return,
                     "episodes": r.episodes, "validation_mean": float(np.mean(val.returns)), "validation_crashes": int(np.sum(val.crashed))}
                )  # fmt: skip
                print(runs[-1], flush=True)
    with open(args.out, "w") as f:
        json.dump(
            {"mdp": args.mdp, "budget": args.budget, "validation_episodes": args.validation, "validation_seed": VALIDATION_SEED, "runs": runs}, f, indent=1
        )


if __name__ == "__main__":
    main()
