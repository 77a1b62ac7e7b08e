"""``HoverVectorEnv(device="cuda")``: the vector environment stepped on the GPU (docs/gpu.md).

As in tests/test_cuda.py, the GPU side runs under numba's CUDA simulator in a subprocess
(NUMBA_ENABLE_CUDASIM=1 must be set before numba is imported) and is compared with the same
vector environment on the CPU: four sub-environments of GHH-09 (sinusoidal wind) on different
MDPs, one fed a non-finite action (a crash, then an autoreset) and a short ``max_episode_steps``
(truncations, then autoresets), over a few steps.
"""

from __future__ import annotations

import numpy as np
import pytest
from cuda_sim import run_simulated

from neurohover import NeurohoverError
from neurohover.envs import HoverVectorEnv

SIM_RTOL = 1e-9  # docs/gpu.md's tolerance for the simulator

SCRIPT = r"""
import json, warnings
import gymnasium as gym
import numpy as np
import neurohover
from neurohover.envs import HoverVectorEnv
from neurohover.sim import cuda as sim_cuda

warnings.filterwarnings("ignore", "overflow encountered", RuntimeWarning)  # uint64 streams wrap in plain Python
N_STEPS = 8
mdps = ["zero", "train:0", "test:1", "sample"]
actions = np.random.default_rng(1).uniform(-0.3, 0.3, size=(N_STEPS, 4, 4))
actions[2, 1] = np.nan  # sub-environment 1 crashes at step 3 and resets at step 4
actions[:, 3] = 1.0  # full deflection: sub-environment 3 flies away
out = {"simulating": sim_cuda.simulating()}
for device in ("cpu", "cuda"):
    if device == "cuda":
        env = gym.make_vec("neurohover/GHH09-v0", num_envs=4, vectorization_mode="vector_entry_point", mdp=mdps, max_episode_steps=5, device="cuda")
    else:
        env = HoverVectorEnv(4, task="ghh09", mdp=mdps, max_episode_steps=5)
    obs, _ = env.reset(seed=3)
    run = {"device": env.unwrapped.device, "obs": [obs.tolist()], "rew": [], "term": [], "trunc": [], "crashed": [], "steps": []}
    for k in range(N_STEPS):
        obs, rew, term, trunc, info = env.step(actions[k])
        run["obs"].append(obs.tolist())
        run["rew"].append(rew.tolist())
        run["term"].append(term.tolist())
        run["trunc"].append(trunc.tolist())
        run["crashed"].append(info["crashed"].tolist())
        run["steps"].append(env.unwrapped.steps.tolist())
    # A masked reset of one sub-environment, then one more step.
    obs, _ = env.reset(options={"reset_mask": np.array([False, False, True, False]), "noise": (5, 7)})
    obs, rew, term, trunc, info = env.step(actions[0])
    run["obs"].append(obs.tolist())
    run["rew"].append(rew.tolist())
    out[device] = run
print(json.dumps(out))
"""


@pytest.fixture(scope="module")
def simulated() -> dict:
    return run_simulated(SCRIPT)


@pytest.mark.slow
def test_vector_env_on_cuda_matches_the_cpu(simulated: dict) -> None:
    assert simulated["simulating"]
    cpu, gpu = simulated["cpu"], simulated["cuda"]
    assert cpu["device"] == "cpu" and gpu["device"] == "cuda"
    np.testing.assert_allclose(gpu["obs"], cpu["obs"], rtol=SIM_RTOL, atol=1e-12)
    np.testing.assert_allclose(gpu["rew"], cpu["rew"], rtol=SIM_RTOL, atol=1e-12)
    for key in ("term", "trunc", "crashed", "steps"):
        assert gpu[key] == cpu[key], key


@pytest.mark.slow
def test_the_case_crashes_truncates_and_autoresets(simulated: dict) -> None:
    cpu = simulated["cpu"]
    term = np.array(cpu["term"])
    assert term[2, 1] and not term[3, 1]  # the non-finite action, then the autoreset step
    assert np.array(cpu["obs"])[4, 1].tolist() == [0.0] * 12  # its new episode's first observation
    assert term[1, 3] and not term[2, 3]  # full deflection crashes, then the autoreset step
    assert np.array(cpu["trunc"])[4, 0]  # max_episode_steps=5
    assert np.array(cpu["steps"])[3].tolist() == [4, 0, 4, 1]  # reset sub-environments count from 0 again
    assert np.abs(np.array(cpu["obs"])).max() > 0.1  # the helicopters moved


def test_vector_env_refuses_a_bad_device() -> None:
    with pytest.raises(NeurohoverError, match="device='tpu' is unknown"):
        HoverVectorEnv(2, device="tpu")
    from neurohover.sim.cuda import cuda_problem

    if cuda_problem() is not None:
        with pytest.raises(NeurohoverError, match="device='cuda' cannot run here"):
            HoverVectorEnv(2, device="cuda")
