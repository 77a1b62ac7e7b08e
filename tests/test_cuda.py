"""The CUDA build of the kernel (neurohover.sim.cuda) against the CPU kernel, under numba's CUDA simulator.

The simulator must be switched on before numba is imported, so the comparison runs in a subprocess
with NUMBA_ENABLE_CUDASIM=1; it interprets the kernel's Python source one thread per job, so the
cases are small (20 jobs of 40 steps: a few seconds).
"""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest
from cuda_sim import run_simulated

from neurohover import NeurohoverError, baseline_policy, evaluate, evaluate_jobs, get_task_family

SIM_RTOL = 1e-9  # the tolerance docs/gpu.md states for the simulator (plain Python against the FMA-contracting CPU kernel)

SCRIPT = r"""
import json, warnings
import numpy as np
from numba.core.registry import CPUDispatcher
from neurohover import Policy, PolicyTable, Safeguard, baseline_policy, evaluate, get_task_family, prototype
from neurohover.sim import cuda as sim_cuda

warnings.filterwarnings("ignore", "overflow encountered", RuntimeWarning)  # uint64 streams wrap in plain Python
mlp = prototype("mlp", "baseline").genome + np.random.default_rng(0).normal(0, 0.01, 42)
rolling = baseline_policy().genome.copy()
rolling[36] += 0.5  # a1 bias: rolls over within 15 steps, unless the safeguard's fallback takes over
policies = [baseline_policy(), Policy("mlp", mlp), Policy("slp", rolling), prototype("mlp", "baseline")]
table = PolicyTable.from_policies(policies)
genomes = table.genomes.copy()
genomes[3, [18, 34]] = 1e200  # l1 = 1e200 v, a1 = 1e200 l1: an infinite action once v != 0 (a table: a Policy's genes are bounded)
table = PolicyTable(table.kinds, genomes)
mdps = [get_task_family("ghh09").mdp("train:0"), get_task_family("fghh", 0.3).mdp("sample", 3)]
out = {"simulating": sim_cuda.simulating()}
for device in ("cpu", "cuda"):
    ev = evaluate(table, mdps, episodes=2, seed=11, n_steps=40, device=device)
    sg = evaluate(policies[2], mdps, episodes=2, seed=11, n_steps=40, record=True, device=device,
                  safeguard=Safeguard(baseline_policy()))
    out[device] = {
        "returns": ev.returns.ravel().tolist(), "crashed": ev.crashed.ravel().tolist(), "steps": ev.steps.ravel().tolist(),
        "sg_returns": sg.returns.ravel().tolist(), "sg_steps": sg.steps.ravel().tolist(),
        "sg_step": sg.safeguard_step.ravel().tolist(),
        "obs": [o.tolist() for o in sg.flight_data.observations], "act": [a.tolist() for a in sg.flight_data.actions],
    }
built = {f.py_func.__name__: f.py_func for f in sim_cuda._DEVICE.values()}
out["device_functions"] = sorted(built)
out["cpu_callees_left"] = sorted(f"{name}.{g}" for name, f in built.items()
                                 for g, v in f.__globals__.items() if isinstance(v, CPUDispatcher))
# The GPU benchmark's pieces, on a few steps (they fly 6000 on a real GPU).
from neurohover import bench_gpu
report = {"device": {"name": "simulator", "compute_capability": "0.0", "numba_cuda": "simulated"}, "compile_seconds": 0.0,
          "agreement": bench_gpu.agreement(n_steps=5), "episodes_per_second_batch_8": bench_gpu.gpu_episodes_per_second(8, 1, 5),
          "fghh_generation_50x5": bench_gpu.fghh_generation(4, 2, 1, n_steps=5)}
out["bench"] = {"report": report, "lines": bench_gpu.format_gpu(report), "no_gpu": bench_gpu.gpu_benchmarks(quick=True)}
print(json.dumps(out))
"""


@pytest.fixture(scope="module")
def simulated() -> dict:
    return run_simulated(SCRIPT)


@pytest.mark.slow
def test_cuda_kernel_matches_cpu_kernel_under_the_simulator(simulated: dict) -> None:
    cpu, gpu = simulated["cpu"], simulated["cuda"]
    assert simulated["simulating"]
    # 4 policies x 2 MDPs x 2 episodes: hovering ones fly all 40 steps, the rolling SLP crashes, the
    # infinite MLP is stopped by its non-finite action.
    assert cpu["steps"][:8] == [40] * 8 and max(cpu["steps"][8:12]) < 40 and max(cpu["steps"][12:]) < 40
    assert cpu["crashed"] == [False] * 8 + [True] * 8
    assert gpu["crashed"] == cpu["crashed"] and gpu["steps"] == cpu["steps"]
    np.testing.assert_allclose(gpu["returns"], cpu["returns"], rtol=SIM_RTOL, atol=0)


@pytest.mark.slow
def test_cuda_safeguard_and_flight_data_match_the_cpu_kernel(simulated: dict) -> None:
    cpu, gpu = simulated["cpu"], simulated["cuda"]
    assert min(cpu["sg_step"]) > 0 and cpu["sg_steps"] == [40] * 4  # the fallback took over and saved every episode
    assert gpu["sg_step"] == cpu["sg_step"] and gpu["sg_steps"] == cpu["sg_steps"]
    np.testing.assert_allclose(gpu["sg_returns"], cpu["sg_returns"], rtol=SIM_RTOL, atol=0)
    for key in ("obs", "act"):
        assert [len(x) for x in gpu[key]] == [len(x) for x in cpu[key]]
        for g, c in zip(gpu[key], cpu[key], strict=True):
            np.testing.assert_allclose(g, c, rtol=SIM_RTOL, atol=1e-12)


@pytest.mark.slow
def test_cuda_build_compiles_the_cpu_sources_with_every_callee_retargeted(simulated: dict) -> None:
    # The physics and the streams come from the CPU kernel's own functions, none hand-copied ...
    for name in (
        "fly_job",
        "policy_action",
        "integrate",
        "observe",
        "crashed",
        "dangerous",
        "update_noise",
        "unpack_mdp",
        "competition_time",
        "_half_angle_quaternion",
        "seed_stream",
        "splitmix64",
        "next_normal",
        "_normal_slow",
        "next_u64",
    ):
        assert name in simulated["device_functions"]
    # ... and no device function calls back into a CPU-compiled one.
    assert simulated["cpu_callees_left"] == []


@pytest.mark.slow
def test_gpu_benchmark_pieces_run_under_the_simulator(simulated: dict) -> None:
    bench = simulated["bench"]
    agreement = bench["report"]["agreement"]
    assert agreement["episodes"] == 128 and agreement["crash_or_step_mismatches"] == 0 and agreement["within_tolerance"]
    assert bench["report"]["fghh_generation_50x5"]["jobs"] == 8
    assert "agreement with the CPU kernel on 128 full episodes" in bench["lines"][1]
    assert any("batch of 8 episodes" in line for line in bench["lines"])
    assert bench["no_gpu"] == {"status": "no CUDA device"}  # the simulator is no GPU to benchmark


PTX_SCRIPT = r"""
import sys
import numba.cuda.dispatcher as dispatcher
from numba import cuda, types as t

if getattr(cuda, "implementation", "") != "NVIDIA":
    sys.exit("SKIP numba-cuda is not installed")
try:
    cuda.compile_ptx(lambda x: None, "void(float64[:])", cc=(9, 0))
except Exception as exc:
    sys.exit(f"SKIP no NVVM to compile with: {type(exc).__name__}")


class Hopper:  # device functions compile for the current device's capability: name one, no GPU needed
    compute_capability = (9, 0)


dispatcher.get_current_device = lambda: Hopper()
import neurohover.sim.cuda as sim_cuda

sim_cuda.cuda_problem = lambda: None
f1, f2, f3 = (t.Array(t.float64, d, "C") for d in (1, 2, 3))
i1, b1 = t.Array(t.int64, 1, "C"), t.Array(t.boolean, 1, "C")
sig = t.void(f2, i1, f2, i1, i1, i1, i1, t.uint64, t.int64, t.boolean, f1, i1, f3, f3, f1, b1, i1, i1)
ptx, _ = cuda.compile_ptx(sim_cuda._rebind(sim_cuda._rollout_thread), sig, cc=(9, 0))
print(ptx.count(".entry"), ptx.count("ld.const.f64") > 0, ptx.count("mul.rn.f64") > 0)
"""


@pytest.mark.slow
def test_cuda_kernel_compiles_for_a_real_gpu() -> None:
    # Where numba-cuda and NVVM are installed (a GPU machine, or pip install 'neurohover[cuda]' plus the
    # CUDA compiler wheels), the kernel compiles to PTX without a GPU; elsewhere this test is skipped.
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_ENABLE_CUDASIM"}
    proc = subprocess.run([sys.executable, "-c", PTX_SCRIPT], env=env, capture_output=True, text=True, timeout=600)
    if proc.returncode != 0 and proc.stderr.strip().startswith("SKIP"):
        pytest.skip(proc.stderr.strip()[5:])
    assert proc.returncode == 0, proc.stderr[-3000:]
    # one kernel; ziggurat tables read from constant memory; the competition clock's products not fused
    assert proc.stdout.split() == ["1", "True", "True"]


def test_bench_without_a_gpu_says_so() -> None:
    from neurohover.bench_gpu import format_gpu, gpu_benchmarks
    from neurohover.sim.cuda import cuda_problem

    if cuda_problem() is None:
        pytest.skip("a CUDA GPU is usable here")
    report = gpu_benchmarks(quick=True)
    assert report == {"status": "no CUDA device"}
    assert format_gpu(report) == [f"  {'gpu':<34} no CUDA device"]


def test_cuda_without_a_gpu_is_one_clear_error() -> None:
    from neurohover.sim.cuda import cuda_problem

    if cuda_problem() is None:
        pytest.skip("a CUDA GPU (or the simulator) is usable here")
    mdp = get_task_family("ghh08").zero()
    with pytest.raises(NeurohoverError, match=r"device='cuda' cannot run here: .*neurohover\[cuda\].*NUMBA_ENABLE_CUDASIM"):
        evaluate(baseline_policy(), mdp, n_steps=10, device="cuda")
    with pytest.raises(NeurohoverError, match="device='cuda' cannot run here"):
        evaluate_jobs([baseline_policy()], mdp, [0], [0], [0], n_steps=10, device="cuda")


def test_unknown_device_is_refused() -> None:
    with pytest.raises(NeurohoverError, match="device='gpu' is unknown: allowed 'cpu' or 'cuda'"):
        evaluate(baseline_policy(), get_task_family("ghh08").zero(), n_steps=10, device="gpu")


@pytest.mark.slow
def test_cuda_module_restores_the_numpy_alias_numba_cuda_needs() -> None:
    # numba-cuda 0.30.4 overloads np.row_stack when it builds its first kernel; NumPy 2.5 removed that alias, and
    # on an H200 with NumPy 2.5.2 no kernel compiled. Importing the CUDA module puts the alias back.
    script = (
        "import numpy as np\n"
        "if hasattr(np, 'row_stack'): del np.row_stack  # as NumPy 2.5 ships\n"
        "import neurohover.sim.cuda\n"
        "print(np.row_stack is np.vstack)\n"
    )
    proc = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert proc.stdout.split() == ["True"]
