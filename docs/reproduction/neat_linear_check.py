"""Whether NEAT's stored champions are SLPs: each one's network probed, its affine map flown as an SLP (issue 35).

    python3 docs/reproduction/neat_linear_check.py docs/reproduction/results.sqlite [EXPERIMENT ...] [--quick]
    (default: topology-fghh topology-ghh08; every stored NEAT champion of them)

A network whose nodes all have the identity activation computes bias + response * (sum of weighted inputs) at every
node: an affine map of the nine features the paper's networks see, which is what the paper's SLP is (9 x 4 weights and
4 biases). For each stored NEAT champion this script reads its network back (``network_of_record``), probes it at the
zero observation and at each unit feature, and checks the map on 1,000 random observations (largest residual printed).
The map, as an SLP genome, is then flown by the kernel on the champion's own validation episodes (the same MDPs and gusts
the unit flew it on): equal returns mean the champion is that SLP, and NEAT's result is a search result, not a topology's.
Printed per champion: hidden nodes, the activations in use, the residual, the largest return difference relative to the
return, and mean validation 1/ln(error) of the champion (stored) and of its SLP.
"""

from __future__ import annotations

import json
import sqlite3
import sys

import numpy as np

from neurohover.evolution.evolve import validation_return
from neurohover.evolution.fitness import episode_fitness
from neurohover.experiments.params import unit_params
from neurohover.experiments.units import fly_on_test_mdps
from neurohover.integrations.neat import ACTIVATIONS, NEAT_TOPOLOGY, forward, network_of_record
from neurohover.policies import Policy
from neurohover.tasks import MDP, family_from_dict

FEATURES = (0, 1, 2, 3, 4, 5, 9, 10, 11)  # u, v, w, x, y, z, qx, qy, qz of the 12 readings (the SLP's input order)


def affine_map(record) -> tuple[np.ndarray, float]:
    """The SLP genome (9 x 4 weights by output, then 4 biases) of a NEAT record's network, and the largest difference
    between the network and that map on 1,000 random observations (0 up to rounding when the network is affine)."""
    packed = network_of_record(record)

    def act(obs: np.ndarray) -> np.ndarray:
        return forward(packed, np.zeros(len(obs), dtype=np.int64), obs)

    probes = np.zeros((1 + len(FEATURES), 12))
    for j, f in enumerate(FEATURES):
        probes[1 + j, f] = 1.0
    out = act(probes)
    bias, weights = out[0], (out[1:] - out[0]).T  # weights[i, j]: output i's gain on feature j
    obs = np.random.default_rng(0).normal(0.0, 1.0, (1000, 12))
    residual = float(np.max(np.abs(act(obs) - (obs[:, FEATURES] @ weights.T + bias))))
    return np.concatenate([weights.ravel(), bias]), residual


def score(returns) -> float:
    return float(np.mean(episode_fitness(np.asarray(returns, dtype=float), "inv-log-error")))


def main(store: str, experiments: list[str], scale: str) -> None:
    with sqlite3.connect(f"file:{store}?mode=ro", uri=True) as c:
        for name in experiments:
            rows = c.execute("SELECT key, params, result FROM units WHERE name = ? AND scale = ? ORDER BY key", (name, scale)).fetchall()
            for key, params, result in rows:
                params, result = json.loads(params), json.loads(result)
                if result["champion"]["topology"] != NEAT_TOPOLOGY:
                    continue
                record = result["champion"]["genome"]
                n_nodes = int(record[0])
                keys = [int(record[1 + 4 * j]) for j in range(n_nodes)]
                used = sorted({ACTIVATIONS[int(record[4 + 4 * j])] for j in range(n_nodes)})
                genome, residual = affine_map(record)
                slp = Policy("slp", genome)
                q = unit_params("evolve", params)
                target = {k: v for k, v in q.target.items() if k != "kind"}
                if q.target["kind"] == "mdp":
                    returns = validation_return(slp, MDP.from_dict(q.target["mdp"]), episodes=q.validation_episodes, seed=q.seed, n_steps=q.n_steps, threads=1)
                else:
                    returns = fly_on_test_mdps(slp, family_from_dict(target), q.validation_episodes, q.validation_seed, q.n_steps, 1, "cpu").returns
                stored, flown = np.asarray(result["validation"], dtype=float), np.ravel(returns)
                rel = float(np.max(np.abs(flown - stored) / np.maximum(np.abs(stored), 1.0)))
                print(
                    f"{name} {key}: hidden nodes {sum(k >= 4 for k in keys)}, activations {', '.join(used)}; affine residual {residual:.1e}; "
                    f"SLP returns differ by {rel:.1e} (relative); 1/ln(error) NEAT {score(stored):.4f}, its SLP {score(flown):.4f}",
                    flush=True,
                )


if __name__ == "__main__":
    quick = "--quick" in sys.argv  # the quick scale's units: a check of this script
    args = [a for a in sys.argv[1:] if a != "--quick"]
    main(args[0], args[1:] or ["topology-fghh", "topology-ghh08"], "quick" if quick else "paper")
