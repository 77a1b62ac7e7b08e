"""Why UH-CMA-ES does worse than CMA-ES with k = 5 in fig15-uh-cma: stored runs flown again, watched (issue 35).

    python3 docs/reproduction/uh_cma_check.py docs/reproduction/results.sqlite [RUN ...] [--quick]   (default: runs 0 1 2)

Each named run of both variants is run again from its stored params (the same seed, so the same run: its champion's
validation returns must equal the stored ones, checked), with the optimiser watched after every tell: its step size
sigma and, for UH-CMA-ES, the episodes each solution is flown (pycma's NoiseHandler.evaluations, rounded). At the end the
distribution's mean (pycma's recommendation under noise) is flown on the champion's validation episodes beside it.
Printed per run and variant: sigma at the start, its largest value and at the end, the median and largest episodes per solution,
the stop reason, and mean validation 1/ln(error) and crash rate of the champion and of the final mean.
"""

from __future__ import annotations

import json
import sqlite3
import sys

import numpy as np

from neurohover.evolution.fitness import episode_fitness
from neurohover.evolution.optimisers.cma import CMAES
from neurohover.experiments.params import unit_params
from neurohover.experiments.units import fly_on_test_mdps, run_unit
from neurohover.policies import Policy
from neurohover.tasks import get_task_family

WATCHED: list[dict] = []  # one record per optimiser made while a unit runs


def _watch() -> None:
    """Record sigma and the episodes per solution at every ask of every CMA-ES and UH-CMA-ES made from here on."""
    ask = CMAES.ask  # UHCMAES inherits it

    def watched_ask(self):
        if not WATCHED or WATCHED[-1]["optimiser"] is not self:
            WATCHED.append({"optimiser": self, "sigma": [], "evaluations": []})
        WATCHED[-1]["sigma"].append(self.sigma)
        WATCHED[-1]["evaluations"].append(getattr(self, "evaluations_per_solution", 0))  # UH-CMA-ES's (its re-evaluation rounds too)
        return ask(self)

    CMAES.ask = watched_ask


def _score(returns, crashed) -> tuple[float, float]:
    return float(np.mean(episode_fitness(np.asarray(returns, dtype=float), "inv-log-error"))), float(np.mean(crashed))


def main(store: str, runs: list[int], scale: str = "paper") -> None:
    _watch()
    with sqlite3.connect(f"file:{store}?mode=ro", uri=True) as c:
        for r in runs:
            for variant in ("cma-k5", "uh-cma"):
                key = f"evolve/{variant}/run{r}"
                kind, params, stored = c.execute(
                    "SELECT kind, params, result FROM units WHERE name = 'fig15-uh-cma' AND scale = ? AND key = ?", (scale, key)
                ).fetchone()
                params, stored = json.loads(params), json.loads(stored)
                WATCHED.clear()
                again = run_unit({"experiment": "fig15-uh-cma", "key": key, "kind": kind, "params": params}, threads=1)
                assert again["validation"] == stored["validation"], f"{key}: not the stored run"
                w = WATCHED[-1]
                q = unit_params("evolve", params)
                mean = Policy(q.topology, w["optimiser"].mean)
                ev = fly_on_test_mdps(mean, get_task_family("fghh", sigma=0.3), q.validation_episodes, q.validation_seed, q.n_steps, 1, "cpu")
                champ = _score(stored["validation"], stored["validation_crashed"])
                final = _score(np.ravel(ev.returns), np.ravel(ev.crashed))
                sig = np.array(w["sigma"])
                evals, uh = np.array(w["evaluations"]), variant == "uh-cma"
                print(
                    f"run {r} {variant:7s}: sigma start {sig[0]:.4f} max {sig.max():.4f} end {sig[-1]:.4f}; asks {len(sig)}; "
                    f"episodes/solution median {np.median(evals) if uh else 5:g}, max {evals.max() if uh else 5}; stop {again['stop_reason']}; "
                    f"champion {champ[0]:.4f} ({champ[1]:.0%} crashed), final mean {final[0]:.4f} ({final[1]:.0%} crashed)",
                    flush=True,
                )


if __name__ == "__main__":
    quick = "--quick" in sys.argv  # the quick scale's units: a check of this script
    args = [a for a in sys.argv[1:] if a != "--quick"]
    main(args[0], [int(x) for x in args[1:]] or [0, 1, 2], "quick" if quick else "paper")
