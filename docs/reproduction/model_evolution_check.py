"""Policies evolved on a one-episode OLS model of a GHH-09 training MDP, flown in the true MDP.

    python3 docs/reproduction/model_evolution_check.py ours|gls|eonn-baseline|eonn-generic [REPS] [GENERATIONS]

For each training MDP and repetition: one episode of the shipped generic policy's flight data, an
LR model learned from it, a policy evolved on the model, and that policy flown 5 episodes in the
true MDP. ``ours``: the agents' default (steady state from the generic policy, 2,000 model
episodes; ``gls`` the same with the GLS estimator). ``eonn-*``: the authors' ``eonn`` as their
helicopter code shipped it (:func:`neurohover.evolution.eonn.eonn_evolve`: 50 genomes, one offspring
a generation, a kept genome keeps its first score), 500 generations, from the baseline SLP (as
their code: ``model_policy = "authors"``) or from the generic MLP. Prints one JSON line per run and
a summary.
"""

from __future__ import annotations

import json
import sys

import numpy as np

from neurohover import baseline_policy, evaluate, get_task_family
from neurohover.agents.model_based import ModelEvolution, evolve_on_model, learn_model
from neurohover.evolution.eonn import EonnSettings, eonn_evolve
from neurohover.policysets import load_policy_set


def main() -> None:
    variant = sys.argv[1]
    reps = int(sys.argv[2]) if len(sys.argv) > 2 else 2
    generations = int(sys.argv[3]) if len(sys.argv) > 3 else 500
    family = get_task_family("ghh09")
    generic = load_policy_set("ghh09").generic
    rows = []
    for m, mdp in enumerate(family.training_mdps()):
        for rep in range(reps):
            seed = 1000 * m + rep
            flight = evaluate(generic, [mdp], episodes=1, seed=seed, record=True, threads=1).flight_data
            assert flight is not None
            model = learn_model(flight, "gls" if variant == "gls" else "ols")
            if variant in ("ours", "gls"):
                policy, _ = evolve_on_model(model, generic, ModelEvolution(), seed)
            elif variant in ("eonn-baseline", "eonn-generic"):
                start = baseline_policy() if variant == "eonn-baseline" else generic
                policy = eonn_evolve(model, start, settings=EonnSettings(generations=generations), seed=seed, threads=1).champion
            else:
                raise SystemExit(f"unknown variant {variant!r}: ours, gls, eonn-baseline or eonn-generic")
            flown = evaluate(policy, [mdp], episodes=5, seed=seed + 7, threads=1)
            rows.append({"mdp": m, "rep": rep, "return": float(flown.returns.mean()), "crashes": int(flown.crashed.sum())})
            print(json.dumps(rows[-1]), flush=True)
    r = np.array([row["return"] for row in rows])
    print(f"{variant}: median {np.median(r):.0f}, mean {r.mean():.0f}, crashed episodes {sum(row['crashes'] for row in rows)} of {5 * len(rows)}")


if __name__ == "__main__":
    main()
