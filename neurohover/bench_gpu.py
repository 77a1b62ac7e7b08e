"""GPU benchmarks: the CUDA build of the kernel (``neurohover bench``, or ``python -m neurohover.bench_gpu``).

Without a usable CUDA GPU every function here reports ``{"status": "no CUDA device"}`` and
measures nothing (numba's CUDA simulator does not count: it interprets Python). With one:

- the agreement of the GPU with the CPU kernel on full 6000-step episodes (SLP and MLP
  baselines, a perturbed MLP and a crashing SLP; ghh09 with its sinusoidal wind, FGHH samples,
  the zero setting): largest relative difference of returns and any crash or step mismatch;
- episodes per second of the MLP baseline on the zero setting, full episodes, at batches of
  10k, 50k and 100k episodes (the time includes the copies to and from the GPU);
- the time of one FGHH generation: 50 perturbed MLP candidates x 5 episodes, each on a fresh
  MDP from G (sigma 0.3), on the GPU and on every CPU core.
"""

from __future__ import annotations

import argparse
import json
import math
import time

import numba
import numpy as np

from .evaluate import PolicyTable, evaluate_jobs
from .policies import Policy, baseline_policy, prototype
from .sim.constants import EPISODE_STEPS
from .tasks import get_task_family

BATCHES = (10_000, 50_000, 100_000)
QUICK_BATCHES = (10_000,)
GPU_RTOL = 1e-9  # the tolerance docs/gpu.md states; about 1e-12 is expected


def gpu_device() -> dict | None:
    """Name, compute capability and numba CUDA target of the GPU, or None without a usable one."""
    from .sim import cuda as sim_cuda

    if sim_cuda.simulating() or sim_cuda.cuda_problem() is not None:
        return None
    dev = sim_cuda.cuda.get_current_device()
    name = getattr(dev, "name", "?")
    return {
        "name": name.decode() if isinstance(name, bytes) else str(name),
        "compute_capability": ".".join(map(str, getattr(dev, "compute_capability", ()))),
        "numba_cuda": getattr(sim_cuda.cuda, "implementation", "?"),
    }


def _agreement_jobs() -> tuple[PolicyTable, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    rolling = baseline_policy().genome.copy()
    rolling[36] += 0.5  # rolls over: exercises the crash path
    mlp = prototype("mlp", "baseline").genome + np.random.default_rng(0).normal(0, 0.01, 42)
    policies = [baseline_policy(), prototype("mlp", "baseline"), Policy("mlp", mlp), Policy("slp", rolling)]
    fghh = get_task_family("fghh", 0.3)
    rows = np.vstack([get_task_family("ghh09").mdp("train:0").row(), fghh.sample_rows(np.random.default_rng(5), 2), fghh.zero().row()])
    p, m, e = (a.ravel() for a in np.meshgrid(np.arange(len(policies)), np.arange(len(rows)), np.arange(8), indexing="ij"))
    return PolicyTable.from_policies(policies), rows, p, m, m * 8 + e


def agreement(n_steps: int = EPISODE_STEPS) -> dict:
    """Fly 128 full episodes on the CPU and the GPU; how far apart are they?"""
    table, rows, p, m, e = _agreement_jobs()
    cpu = evaluate_jobs(table, rows, p, m, e, seed=3, n_steps=n_steps)
    gpu = evaluate_jobs(table, rows, p, m, e, seed=3, n_steps=n_steps, device="cuda")
    same = (gpu.crashed == cpu.crashed) & (gpu.steps == cpu.steps)
    rel = (np.abs(gpu.returns - cpu.returns) / np.maximum(np.abs(cpu.returns), 1e-300))[same].max(initial=0.0)
    return {
        "episodes": int(p.size),
        "crashed": int(cpu.crashed.sum()),
        "max_relative_return_difference": float(rel),
        "bit_equal_returns": int((gpu.returns == cpu.returns).sum()),
        "crash_or_step_mismatches": int((~same).sum()),
        "within_tolerance": bool(same.all() and rel <= GPU_RTOL),
    }


def gpu_episodes_per_second(episodes: int, repeats: int = 2, n_steps: int = EPISODE_STEPS, threads_per_block: int | None = None) -> float:
    """MLP baseline on the zero setting, one batch of ``episodes`` on the GPU (best of ``repeats``), in
    full (6000-step) episodes per second."""
    from .sim import cuda as sim_cuda

    mdp = get_task_family("fghh").zero()
    idx = np.zeros(episodes, dtype=np.int64)
    best = math.inf
    default = sim_cuda.THREADS_PER_BLOCK
    sim_cuda.THREADS_PER_BLOCK = threads_per_block or default
    try:
        for _ in range(repeats):
            ev = evaluate_jobs([prototype("mlp", "baseline")], mdp, idx, idx, np.arange(episodes), seed=1, n_steps=n_steps, device="cuda")
            assert not ev.crashed.any()
            best = min(best, ev.seconds)
    finally:
        sim_cuda.THREADS_PER_BLOCK = default
    return episodes * n_steps / EPISODE_STEPS / best


def fghh_generation(candidates: int = 50, episodes: int = 5, repeats: int = 3, n_steps: int = EPISODE_STEPS) -> dict:
    """Seconds of one FGHH generation (``candidates`` x ``episodes`` fresh MDPs) on the GPU and on all CPU cores."""
    rng = np.random.default_rng(1)
    genomes = prototype("mlp", "baseline").genome + rng.normal(0, 0.05, (candidates, 42))
    rows = get_task_family("fghh", 0.3).sample_rows(rng, candidates * episodes)
    table = PolicyTable.from_genomes(genomes, "mlp")
    p = np.repeat(np.arange(candidates), episodes)
    m = np.arange(candidates * episodes)
    out: dict = {"jobs": int(p.size)}
    for device in ("cuda", "cpu"):
        best, ev = math.inf, None
        for _ in range(repeats):
            start = time.perf_counter()
            ev = evaluate_jobs(table, rows, p, m, m, seed=2, n_steps=n_steps, device=device)
            best = min(best, time.perf_counter() - start)
        assert ev is not None  # repeats >= 1
        out[f"{device}_seconds"] = best
        out["crashed"], out["mean_steps"] = int(ev.crashed.sum()), float(ev.steps.mean())
    out["cpu_cores"] = numba.config.NUMBA_NUM_THREADS  # type: ignore[attr-defined]  # numba.config sets it at import, from the environment
    return out


def gpu_benchmarks(quick: bool = False, cpu_episodes_per_second: float | None = None) -> dict:
    """Everything above as a JSON-able dict; ``{"status": "no CUDA device"}`` without a GPU.

    ``cpu_episodes_per_second``: the CPU kernel on all cores on the same workload, for the ratio
    (measured here, briefly, when not given).
    """
    from .errors import check_flag

    check_flag(quick, "quick", "a short run")  # before the device: quick="no" was true (fifteenth trial, T15-26)
    device = gpu_device()
    if device is None:
        return {"status": "no CUDA device"}
    from .bench import kernel_episodes_per_second
    from .sim import cuda as sim_cuda

    start = time.perf_counter()
    sim_cuda.load_kernel()
    report: dict = {"device": device, "compile_seconds": time.perf_counter() - start}
    report["agreement"] = agreement()
    report["workload"] = "MLP baseline, zero setting, full 6000-step episodes, one batch per call (copies included)"
    for n in QUICK_BATCHES if quick else BATCHES:
        report[f"episodes_per_second_batch_{n}"] = gpu_episodes_per_second(n, 1 if quick else 2)
    if not quick:  # the launch shape: THREADS_PER_BLOCK is a guess until measured
        report["episodes_per_second_batch_50000_by_block_size"] = {tpb: gpu_episodes_per_second(50_000, 1, threads_per_block=tpb) for tpb in (64, 128, 256)}
    report["fghh_generation_50x5"] = fghh_generation(repeats=1 if quick else 3)
    cores = numba.config.NUMBA_NUM_THREADS  # type: ignore[attr-defined]  # numba.config sets it at import, from the environment
    if cpu_episodes_per_second is None:
        cpu_episodes_per_second = kernel_episodes_per_second(200 * cores, cores, 1)
    report["cpu_kernel_all_cores_episodes_per_second"] = cpu_episodes_per_second
    return report


def format_gpu(report: dict) -> list[str]:
    """Lines of the ``gpu`` section of ``neurohover bench``."""
    if "device" not in report:
        return [f"  {'gpu':<34} {report.get('status', 'no CUDA device')}"]
    d, a, g = report["device"], report["agreement"], report["fghh_generation_50x5"]
    lines = [
        f"  gpu: {d['name']} (compute capability {d['compute_capability']}, numba.cuda {d['numba_cuda']}), "
        f"kernel compiled in {report['compile_seconds']:.1f} s",
        f"    agreement with the CPU kernel on {a['episodes']} full episodes: max relative return difference "
        f"{a['max_relative_return_difference']:.2g}, {a['crash_or_step_mismatches']} crash/step mismatches "
        f"({'within' if a['within_tolerance'] else 'OUTSIDE'} {GPU_RTOL:g})",
    ]
    cpu = report.get("cpu_kernel_all_cores_episodes_per_second")
    for key, value in report.items():
        if key.startswith("episodes_per_second_batch_") and isinstance(value, float):
            ratio = f"  x{value / cpu:.1f} vs the CPU kernel on {g['cpu_cores']} cores" if cpu else ""
            lines.append(f"    {'batch of ' + key.rsplit('_', 1)[1] + ' episodes':<36} {value:>12.1f} episodes/s{ratio}")
    sweep = report.get("episodes_per_second_batch_50000_by_block_size")
    if sweep:
        lines.append("    batch of 50000 by threads per block  " + ", ".join(f"{k}: {v:.0f}/s" for k, v in sweep.items()))
    lines.append(
        f"    FGHH generation (50 x 5 fresh MDPs)   GPU {g['cuda_seconds']:.3f} s, CPU ({g['cpu_cores']} cores) "
        f"{g['cpu_seconds']:.3f} s; {g['crashed']} crashed, {g['mean_steps']:.0f} steps on average"
    )
    return lines


def main(argv: list[str] | None = None) -> int:
    """``python -m neurohover.bench_gpu [--quick] [--json FILE]``: the GPU section of ``neurohover bench`` alone."""
    parser = argparse.ArgumentParser(prog="python -m neurohover.bench_gpu", description=main.__doc__)
    parser.add_argument("--quick", action="store_true", help="one batch size (10k) and one repeat")
    parser.add_argument("--json", metavar="FILE", help="also write the report as JSON to FILE")
    args = parser.parse_args(argv)
    report = gpu_benchmarks(quick=args.quick)
    print("\n".join(format_gpu(report)))
    if args.json:
        with open(args.json, "w", encoding="utf-8") as f:
            json.dump(report, f, indent=2)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
