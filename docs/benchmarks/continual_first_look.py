"""docs/benchmarks.md, "An agent that keeps learning": the incremental and the continual agent on GHH-08
test MDPs 0-4 under three drifts, one 80-episode run of 1,000-step episodes per MDP and agent (seed 4;
model evolutions of 600 episodes). A first look, not an experiment in the results store: writes
continual_first_look.json beside this script (a few minutes on 2 cores).

    python docs/benchmarks/continual_first_look.py
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from neurohover.agents.model_based import ModelEvolution
from neurohover.agents.protocol import run_test
from neurohover.agents.registry import agent_spec, policies_from_set
from neurohover.agents.spec import AgentOptions
from neurohover.policysets import load_policy_set
from neurohover.tasks import Drift, get_task_family

DRIFTS = {
    "D_p, D_q x 2.5 at episode 25": Drift(0.0, (("D_p", 2.5), ("D_q", 2.5)), (25, 25)),
    "C_u, C_v x 3 at episode 25": Drift(0.0, (("C_u", 3.0), ("C_v", 3.0)), (25, 25)),
    "log random walk 0.03": Drift(0.03),
    "none": Drift(),
}


def main() -> None:
    family, policy_set = get_task_family("ghh08"), load_policy_set("ghh08")
    evolution = ModelEvolution(budget=600, n_steps=1000)
    out: dict = {}
    for label, drift in DRIFTS.items():
        for name in ("incremental", "continual"):
            spec = agent_spec(name)
            sums, crashes, relearned = [], [], []
            for i in range(5):
                agent = spec.build(policies_from_set(spec, policy_set), AgentOptions(evolution=evolution))
                run = run_test(agent, family, family.mdp(f"test:{i}").with_drift(drift), episodes=80, seed=4, n_steps=1000)
                sums.append(float(run.returns.sum()))
                crashes.append(int(run.crashed.sum()))
                relearned.append(len(getattr(agent, "relearned_at", [])))
            out.setdefault(label, {})[name] = {
                "median_sum_of_returns": float(np.median(sums)),
                "crashes": sum(crashes),
                "relearned": sum(relearned),
                "sums": sums,
            }
            print(label, name, out[label][name])
    Path(__file__).with_name("continual_first_look.json").write_text(json.dumps(out, indent=1) + "\n")


if __name__ == "__main__":
    main()
