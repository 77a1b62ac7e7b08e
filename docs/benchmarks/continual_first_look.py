"""docs/benchmarks.md, "An agent that keeps learning": the incremental and the continual agent on GHH-08
test MDP 3 under three drifts, one 80-episode run of 1,000-step episodes each (seed 4; a model evolution
of 600 episodes). A first look, not an experiment in the results store: about a minute on 2 cores.

    python docs/benchmarks/continual_first_look.py
"""

import time

import numpy as np

from neurohover.agents.model_based import ModelEvolution
from neurohover.agents.protocol import run_test
from neurohover.agents.registry import agent_spec, policies_from_set
from neurohover.agents.spec import AgentOptions
from neurohover.policysets import load_policy_set
from neurohover.tasks import Drift, get_task_family

fam = get_task_family("ghh08")
ev = ModelEvolution(budget=600, n_steps=1000)
for drift in [Drift(0.0, (("D_p", 2.5), ("D_q", 2.5)), (25, 25)), Drift(0.0, (("C_u", 3.0), ("C_v", 3.0)), (25, 25)), Drift(0.03)]:
    for name in ("incremental", "continual"):
        spec = agent_spec(name)
        agent = spec.build(policies_from_set(spec, load_policy_set("ghh08")), AgentOptions(evolution=ev))
        t = time.time()
        r = run_test(agent, fam, fam.mdp("test:3").with_drift(drift), episodes=80, seed=4, n_steps=1000)
        print(
            name,
            drift,
            round(r.returns.sum()),
            int(r.crashed.sum()),
            round(time.time() - t, 1),
            getattr(agent, "relearned_at", None),
            r.policy[-1],
            np.round(r.returns[-5:]).astype(int).tolist(),
        )
