"""Policies evolved on a one-episode OLS model of a GHH-09 training MDP, flown in the true MDP.

    python3 docs/reproduction/model_evolution_check.py ours|gls|eonn-baseline|eonn-generic [REPS] [GENERATIONS]

For each training MDP and repetition: one episode of the shipped generic policy's flight data, an
LR model learned from it, a policy evolved on the model, and that policy flown 5 episodes in the
true MDP. ``ours``: the agents' default (steady state from the generic policy, 2,000 model
episodes; ``gls`` the same with the GLS estimator). ``eonn-*``: an emulation of the authors' code
(their ``functions.evolve``): 50 genomes, each generation every genome flies one more model episode
and is scored by the mean of all its episodes, the 49 best are kept and one child is bred
(tournament of 5, the paper's crossover and mutation operators from ``neurohover.evolution.operators``,
mutation with probability 0.75), 500 generations, from
the baseline policy (as their code) or from the generic policy. Prints one JSON line per run and a
summary (the numbers of the Table 4 and Figure 8 discussions).
"""

from __future__ import annotations

import json
import sys
from dataclasses import replace

import numpy as np

from neurohover import evaluate, get_task_family
from neurohover.agents.model_based import ModelEvolution, evolve_on_model, learn_model
from neurohover.evolution import SteadyStateSettings
from neurohover.evolution.operators import crossover, mutate
from neurohover.policies import Policy, prototype
from neurohover.policysets import load_policy_set

PAPER = SteadyStateSettings()  # mutation (0.1, 0.8, 0.25) and averaging crossover (0.5): eonn's values too
SPAWN = replace(PAPER, mutate_frac=0.5, mutate_std=0.5)  # eonn's initial population


def tournament(pool: list[np.ndarray], fitness: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    sample = rng.choice(len(pool), 5, replace=False)
    return pool[sample[np.argmax(fitness[sample])]]


def eonn_on_model(model, start: Policy, seed: int, generations: int) -> Policy:
    """The authors' generational EA with 49 elites, every genome re-flown each generation."""
    rng = np.random.default_rng(seed)
    pool = [start.genome.copy()] + [mutate(start.genome, rng, SPAWN) for _ in range(49)]
    scores: list[list[float]] = [[] for _ in pool]
    for gen in range(generations + 1):
        if gen:
            fitness = np.array([np.mean(s) for s in scores])
            order = np.argsort(-fitness)[:49]
            mom, dad = (tournament(pool, fitness, rng) for _ in range(2))
            child = crossover(mom, dad, rng, PAPER)
            if rng.random() < 0.75:
                child = mutate(child, rng, PAPER)
            pool = [pool[i] for i in order] + [child]
            scores = [scores[i] for i in order] + [[]]
        returns = evaluate([Policy("mlp", g) for g in pool], model, episodes=1, seed=seed, first_episode=gen, threads=1).returns[:, 0, 0]
        for s, r in zip(scores, returns):
            s.append(float(r))
    return Policy("mlp", pool[int(np.argmax([np.mean(s) for s in scores]))])


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
                policy = eonn_on_model(model, prototype("mlp", "baseline") if variant == "eonn-baseline" else generic, seed, generations)
            else:
                raise SystemExit(f"unknown variant {variant!r}: ours, gls, eonn-baseline or eonn-generic")
            flown = evaluate(policy, [mdp], episodes=5, seed=seed + 7, threads=1)
            rows.append({"mdp": m, "rep": rep, "return": float(flown.returns.mean()), "crashes": int(flown.crashed.sum())})
            print(json.dumps(rows[-1]), flush=True)
    r = np.array([row["return"] for row in rows])
    print(f"{variant}: median {np.median(r):.0f}, mean {r.mean():.0f}, crashed episodes {sum(row['crashes'] for row in rows)} of {5 * len(rows)}")


if __name__ == "__main__":
    main()
