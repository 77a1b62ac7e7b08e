"""Test runs of the on-line agents on device="cuda" (docs/gpu.md), under numba's CUDA simulator.

As in tests/test_cuda_plumbing.py the GPU side runs in a subprocess with NUMBA_ENABLE_CUDASIM=1
(set before numba is imported), on tiny runs compared with the same runs on the CPU.
"""

from __future__ import annotations

import numpy as np
import pytest
from cuda_sim import run_simulated

from neurohover.agents.model_based import ModelEvolution
from neurohover.errors import NeurohoverError

SCRIPT = r"""
import json, warnings
from neurohover.agents.model_based import IncrementalModelBasedAgent, ModelEvolution
from neurohover.agents.protocol import run_test
from neurohover.agents.registry import make_agent
from neurohover.policies import prototype
from neurohover.tasks import get_task_family

warnings.filterwarnings("ignore", "overflow encountered", RuntimeWarning)  # uint64 streams wrap in plain Python
family = get_task_family("ghh08")
mdp = family.test_mdps()[2]
out = {}
for device in ("cpu", "cuda"):
    free = run_test(make_agent("model-free", family), family, mdp, episodes=12, seed=3, n_steps=15, device=device)
    settings = ModelEvolution(budget=12, predict_episodes=2, n_steps=25, device=device)
    agent = IncrementalModelBasedAgent(prototype("mlp", "baseline"), settings, max_learning_episodes=3)
    inc = run_test(agent, family, mdp, episodes=5, seed=4, n_steps=25, device=device)
    out[device] = {"free": free.returns.tolist(), "free_policy": free.policy, "inc": inc.returns.tolist(), "inc_policy": inc.policy}
print(json.dumps(out))
"""


@pytest.mark.slow
def test_agents_fly_the_same_test_runs_on_the_simulated_gpu() -> None:
    out = run_simulated(SCRIPT)
    cpu, gpu = out["cpu"], out["cuda"]
    assert gpu["free_policy"] == cpu["free_policy"] and gpu["inc_policy"] == cpu["inc_policy"]
    np.testing.assert_allclose(gpu["free"], cpu["free"], rtol=1e-9)
    np.testing.assert_allclose(gpu["inc"], cpu["inc"], rtol=1e-9)


def test_a_model_evolution_refuses_an_unknown_device() -> None:
    with pytest.raises(NeurohoverError, match="tpu"):
        ModelEvolution(device="tpu")
