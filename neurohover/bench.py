"""Throughput benchmarks (``neurohover bench``): the kernel against the plain-Python reference.

Every figure comes from this run on this machine: episodes per second, control steps and
simulator substeps per second, and the ratio against the reference simulator measured here too.
The workload is the issue's: full 6000-step episodes of the MLP policy in the zero setting.
"""

from __future__ import annotations

import math
import platform
import random
import time
from collections.abc import Callable

import numba
import numpy as np

from .errors import NeurohoverError, brief, whole_number
from .evaluate import PolicyTable, evaluate_jobs
from .policies import prototype
from .policysets import load_policy_set
from .sim.constants import EPISODE_STEPS, SUBSTEPS
from .sim.reference import fly_episode
from .tasks import get_task_family


def _count(name: str, value: object, what: str) -> int:
    """``value`` as an int >= 1 (NumPy integers too): 0 and negative sizes were rates of 0.0 or tracebacks (thirteenth trial, F3 F4)."""
    if not whole_number(value) or value < 1:
        raise NeurohoverError(f"{name}={brief(value)} is not allowed: give a whole number of {what} >= 1")
    return int(value)


def _best_rate(run: Callable[[], float], repeats: int) -> float:
    """Best of ``repeats`` runs of ``run`` (which returns work units done) in units per second."""
    best = 0.0
    for _ in range(repeats):
        start = time.perf_counter()
        work = run()
        best = max(best, work / (time.perf_counter() - start))
    return best


def reference_episodes_per_second(episodes: int = 1, n_steps: int = EPISODE_STEPS) -> float:
    """Plain-Python reference: MLP episodes of ``n_steps`` control steps, noise drawn with Python's
    ``random``; the rate is in full (6000-step) episodes per second."""
    episodes, n_steps = _count("episodes", episodes, "episodes"), _count("n_steps", n_steps, "control steps")
    policy = prototype("mlp", "baseline")
    mdp = get_task_family("fghh").zero().to_reference()

    def run() -> float:
        for e in range(episodes):
            rng = random.Random(e)
            normals = [[rng.gauss(0.0, 1.0) for _ in range(6)] for _ in range(n_steps)]
            fly_episode(mdp, policy.act, normals, n_steps)
        return episodes * n_steps / EPISODE_STEPS

    return _best_rate(run, 1)


def kernel_episodes_per_second(episodes: int, threads: int, repeats: int = 3) -> float:
    """Compiled kernel: full MLP episodes in the zero setting on ``threads`` threads."""
    episodes, repeats = _count("episodes", episodes, "episodes"), _count("repeats", repeats, "repeats")
    policy = prototype("mlp", "baseline")
    mdp = get_task_family("fghh").zero()
    p_idx = np.zeros(episodes, dtype=np.int64)

    def run() -> float:
        ev = evaluate_jobs([policy], mdp, p_idx, p_idx, np.arange(episodes), seed=1, threads=threads)
        assert not ev.crashed.any()
        return episodes

    evaluate_jobs([policy], mdp, [0, 0], [0, 0], [0, 1], seed=1, n_steps=10, threads=threads)  # warm-up
    return _best_rate(run, repeats)


def vector_env_steps_per_second(num_envs: int = 1024, steps: int = 1000) -> float:
    """Gymnasium vector environment: control steps per second (environment time only, one core).

    The helicopters fly the baseline policy (computed in NumPy, outside the timed region) on the
    zero setting, so they hover rather than crash and reset.
    """
    steps = _count("steps", steps, "control steps")  # num_envs is HoverVectorEnv's to check
    from .envs.vector import HoverVectorEnv
    from .policies import slp_baseline_genome

    genome = slp_baseline_genome()
    weights, bias = genome[:36].reshape(4, 9), genome[36:]
    env = HoverVectorEnv(num_envs, task="fghh", mdp="zero")
    obs, _ = env.reset(seed=0)
    env.step(np.zeros((num_envs, 4)))  # warm-up
    obs, _ = env.reset(seed=0)
    elapsed = 0.0
    for _ in range(steps):
        actions = obs[:, [0, 1, 2, 3, 4, 5, 9, 10, 11]] @ weights.T + bias
        start = time.perf_counter()
        obs, *_ = env.step(actions)
        elapsed += time.perf_counter() - start
    env.close()
    return num_envs * steps / elapsed


def lr_seconds_per_episode_of_flight_data() -> float:
    """LR model learning on one episode (6000 samples) of baseline flight data: best of 5."""
    from .evaluate import evaluate
    from .models import learn_lr
    from .policies import baseline_policy

    flight = evaluate(baseline_policy(), get_task_family("ghh08").training_mdps()[0], record=True, seed=3).flight_data
    assert flight is not None  # recorded
    best = float("inf")
    for _ in range(5):
        start = time.perf_counter()
        learn_lr(flight)
        best = min(best, time.perf_counter() - start)
    return best


def test_run_seconds(agent: str, episodes: int = 1000, task: str = "ghh08") -> float:
    """Wall time of one on-line test run of ``agent`` on test MDP 0 of ``task``, on one core."""
    from .agents.protocol import run_test
    from .agents.registry import make_agent

    family = get_task_family(task)
    start = time.perf_counter()
    run_test(make_agent(agent, family), family, family.test_mdps()[0], episodes=episodes, seed=0, threads=1)
    return time.perf_counter() - start


def _replay_seconds(trace: list, topology: str, noise_seed: int, n_steps: int, threads: int) -> float:
    """Wall time of the raw kernel flying exactly the traced jobs in ONE batch (``evaluate_jobs``); a race
    traces the episodes it used, not those it flew (``evolve(_trace=)``)."""
    genomes = np.vstack([t[0] for t in trace])
    rows = np.vstack([t[1] for t in trace])
    g_off = np.cumsum([0] + [len(t[0]) for t in trace])[:-1]
    r_off = np.cumsum([0] + [len(t[1]) for t in trace])[:-1]
    p = np.concatenate([t[2] + o for t, o in zip(trace, g_off, strict=True)])
    m = np.concatenate([t[3] + o for t, o in zip(trace, r_off, strict=True)])
    e = np.concatenate([t[4] for t in trace])
    ev = evaluate_jobs(PolicyTable.from_genomes(genomes, topology), rows, p, m, e, seed=noise_seed, n_steps=n_steps, threads=threads)
    return ev.seconds


def benchmark_evolution(quick: bool = False, repeats: int | None = None, progress: Callable[[str], None] | None = None) -> dict:
    """Throughput of :func:`~neurohover.evolution.evolve.evolve` against the raw kernel flying the
    same episodes (``neurohover bench``).

    Steady state on the zero setting on 1 thread (one episode per generation; MLP from the baseline
    seed). Generational on FGHH (sigma 0.3), with fixed resampling (k=5: one kernel call per
    generation) and with selection races (delta 0.5: a call per round, idle lanes filled with parked later samples), on 1
    thread (as each worker of ``reproduce --jobs N`` flies) and on all cores, from the shipped
    race generic (an MLP that hovers, so episodes are long and crashes mixed in, as in the later
    generations of a paper-scale run; from the baseline SLP nearly every early candidate crashes
    within steps). Episodes have very different lengths, so the fair reference is the raw kernel
    flying exactly the episodes the run used (same genomes, MDPs and noise; the samples a race flew
    but never used left out) in one batch on the same threads: ``ratio_vs_raw_kernel`` = raw
    seconds / evolve seconds of one run and its replay, flown side by side (every other pair the
    replay first), the median over ``repeats`` pairs (``_lowest``: the lowest pair); the rates are
    the best of the repeats. A run's episodes are fixed by its seed, so every repeat flies the same
    ones. ``flown_steps_per_used`` is the race's overhead in control steps flown. ``progress``, when given, is called
    with the name of each stage (the warm-up, then each case) as it starts.
    """
    from .errors import check_flag
    from .evolution.evolve import evolve
    from .evolution.seeding import noise_seed

    check_flag(quick, "quick", "a short run")  # quick="no" was true (fifteenth trial, T15-26)
    cores = numba.config.NUMBA_NUM_THREADS  # type: ignore[attr-defined]  # numba.config sets it at import, from the environment
    repeats = (1 if quick else 3) if repeats is None else _count("repeats", repeats, "repeats")
    # 20,000 episodes from the race generic average about 2,600 steps an episode, as a paper-scale run
    # does over its 500,000 (a Figure 15 run flies them in 60-330 s of one core); its first 5,000
    # average about 860 (crashing candidates), where a race's rounds wait on a few long episodes.
    budget_ss, budget_gen = (200, 300) if quick else (2000, 20000)  # quick: about a second (2 generations of fixed:5)
    fghh = get_task_family("fghh", 0.3)
    generic = load_policy_set("fghh").generics["race"]
    cases: list[tuple] = [("evolve_steady_state_1_core", get_task_family("fghh").zero(), 1, budget_ss, None, "baseline")]
    for threads in sorted({1, cores}):
        cases.append((f"evolve_generational_fixed5_{threads}_cores", fghh, threads, budget_gen, "fixed:5", generic))
        cases.append((f"evolve_generational_race0.5_{threads}_cores", fghh, threads, budget_gen, "race:0.5", generic))
    say = progress or (lambda _name: None)
    say("evolve: compiling")  # Load every compiled function (kernel, genome operators) before any clock starts.
    evolve(get_task_family("fghh").zero(), budget=60, seed=0, n_steps=10, threads=1)
    evolve(fghh, topology="mlp", prototype=generic, budget=200, resampling="race:0.5", seed=0, n_steps=10, threads=1)
    out: dict = {}
    for name, target, threads, budget, resampling, proto in cases:
        best_evolve, best_raw = math.inf, math.inf
        ratios = []
        used: list = []  # the episodes a run used: fixed by its seed, the same in every repeat
        say(name)
        for i in range(repeats):
            flown: dict = {}
            # Every other pair flies the replay first, so that a machine speeding up or slowing down evens out.
            raw = _replay_seconds(used, "mlp", noise_seed(1), EPISODE_STEPS, threads) if i % 2 else math.nan
            trace: list = []
            result = evolve(target, topology="mlp", prototype=proto, budget=budget, resampling=resampling, seed=1, threads=threads, _trace=trace, _flown=flown)
            used = trace
            if not i % 2:
                raw = _replay_seconds(used, "mlp", noise_seed(1), EPISODE_STEPS, threads)
            best_evolve, best_raw = min(best_evolve, result.seconds), min(best_raw, raw)
            ratios.append(raw / result.seconds)
        out[f"{name}_episodes_per_second"] = result.episodes / best_evolve
        out[f"{name}_control_steps_per_second"] = result.steps / best_evolve
        out[f"{name}_raw_kernel_same_episodes_per_second"] = result.episodes / best_raw
        out[f"{name}_ratio_vs_raw_kernel"] = float(np.median(ratios))
        out[f"{name}_ratio_vs_raw_kernel_lowest"] = min(ratios)
        if resampling and resampling.startswith("race"):
            out[f"{name}_flown_steps_per_used"] = flown["steps"] / result.steps
    return out


def _extra_benchmarks(quick: bool, stage: Callable[[str], None]) -> dict:
    """Benchmarks of later pipeline stages (``stage`` called with each one's name as it starts)."""
    stage("vector env")
    out = {"vector_env_1024_control_steps_per_second_1_core": vector_env_steps_per_second(1024, 200 if quick else 1000)}
    # evolve() against the raw kernel flying the very same episodes (ratio_vs_raw_kernel).
    out.update(benchmark_evolution(quick, progress=stage))
    stage("learning a model")
    out["lr_seconds_6000_samples"] = lr_seconds_per_episode_of_flight_data()
    episodes = 100 if quick else 1000
    for agent in ("model-free", "incremental"):
        stage(f"test run {agent}")
        out[f"test_run_{agent}_{episodes}_episodes_seconds_1_core"] = test_run_seconds(agent, episodes)
    stage("test run hybrid")  # the hybrid agent with the authors' safeguard (the paper's box test fired in most episodes)
    out["test_run_ghh09_hybrid_100_episodes_seconds_1_core"] = test_run_seconds("hybrid", 100, "ghh09")
    return out


class _Stages:
    """``neurohover bench``'s progress on standard error, a terminal only: a bar over its stages, named as each starts
    (it printed nothing for 40 s and more; T20-09). Called with a stage's name, it counts the one before as done."""

    def __init__(self, total: int) -> None:
        from .progress import progress_bar

        self.bar, self.started = progress_bar(total=total, desc="bench", unit="stage"), False

    def __call__(self, name: str) -> None:
        self.bar.update(int(self.started))
        self.started = True
        self.bar.set_description_str(f"bench: {name}")

    def close(self) -> None:
        self.bar.update(int(self.started))
        self.bar.set_description_str("bench")
        self.bar.close()


#: Estimated limit of one core on the benchmark workload (episodes/s): a full episode is 60,000
#: substeps of a few hundred flops plus 36,000 normal draws (issue 12's estimate, 3,000-5,000).
ESTIMATED_LIMIT_PER_CORE = (3000.0, 5000.0)


def run_benchmarks(quick: bool = False) -> dict:
    """Measure everything and return a JSON-able report (``quick``: True for a short run); on a terminal, a bar over the
    stages on standard error shows which one is under way."""
    from .errors import check_flag

    check_flag(quick, "quick", "a short run")  # quick="no" ran the short benchmarks (fifteenth trial, T15-26)
    cores = numba.config.NUMBA_NUM_THREADS  # type: ignore[attr-defined]  # numba.config sets it at import, from the environment
    # reference, 2 kernels, vector env, evolve's warm-up and 1 + 2 x thread counts cases, learning, 3 test runs, GPU
    stage = _Stages(11 + 2 * len({1, cores}))
    try:
        report = _measure(quick, cores, stage)
    finally:
        stage.close()
    return report


def _measure(quick: bool, cores: int, stage: _Stages) -> dict:
    """:func:`run_benchmarks`' measurements, each stage named to ``stage`` as it starts."""
    episodes = 100 if quick else 1000
    repeats = 1 if quick else 3
    stage("reference (plain Python)")  # The hovering baseline costs the same every step, so a sixth of an episode gives the rate.
    ref = reference_episodes_per_second(1, EPISODE_STEPS // 6 if quick else EPISODE_STEPS)
    stage("kernel, 1 core")
    one = kernel_episodes_per_second(episodes, 1, repeats)
    stage(f"kernel, {cores} cores")
    many = kernel_episodes_per_second(episodes * cores, cores, repeats)
    per_episode = EPISODE_STEPS
    report = {
        "machine": {"cores": cores, "cpu": platform.processor() or platform.machine(), "python": platform.python_version(), "numba": numba.__version__},
        "workload": "MLP policy (baseline-equivalent), zero setting, full 6000-step episodes",
        "reference_episodes_per_second": ref,
        "kernel_1_core": {
            "episodes_per_second": one,
            "control_steps_per_second": one * per_episode,
            "substeps_per_second": one * per_episode * SUBSTEPS,
            "speedup_vs_reference": one / ref,
            "fraction_of_estimated_limit": [one / limit for limit in reversed(ESTIMATED_LIMIT_PER_CORE)],
        },
        f"kernel_{cores}_cores": {
            "episodes_per_second": many,
            "control_steps_per_second": many * per_episode,
            "substeps_per_second": many * per_episode * SUBSTEPS,
            "speedup_vs_reference": many / ref,
            "speedup_vs_1_core": many / one,
        },
    }
    report.update(_extra_benchmarks(quick, stage))
    stage("GPU")  # The CUDA build of the kernel when a GPU is present ({"status": "no CUDA device"} otherwise).
    from .bench_gpu import gpu_benchmarks

    report["gpu"] = gpu_benchmarks(quick, cpu_episodes_per_second=many)
    return report


def format_report(report: dict) -> str:
    """Human-readable table of a benchmark report."""
    machine = report.get("machine") if isinstance(report, dict) else None
    if not isinstance(machine, dict) or not {"cores", "cpu"} <= set(machine) or not {"workload", "reference_episodes_per_second"} <= set(report):
        raise NeurohoverError(  # {} was a KeyError, None a TypeError (thirteenth trial, F3); checked, not caught: a formatter's bug stays visible
            f"report={brief(report)} is not allowed: give the table that run_benchmarks returns (machine, workload, reference_episodes_per_second, ...)"
        )
    lines = [f"neurohover bench on {report['machine']['cores']} cores ({report['machine']['cpu']}); {report['workload']}"]
    lines.append(f"  {'reference (plain Python)':<34} {report['reference_episodes_per_second']:>12.3f} episodes/s")
    for key, value in report.items():
        if key.startswith("kernel_"):
            extra = f", x{value['speedup_vs_1_core']:.2f} vs 1 core" if "speedup_vs_1_core" in value else ""
            if "fraction_of_estimated_limit" in value:
                low, high = value["fraction_of_estimated_limit"]
                extra += f", {low:.0%}-{high:.0%} of one core's estimated limit"
            lines.append(
                f"  {key:<34} {value['episodes_per_second']:>12.1f} episodes/s  {value['substeps_per_second'] / 1e6:8.1f} M substeps/s"
                f"  x{value['speedup_vs_reference']:.0f} vs reference{extra}"
            )
        elif key == "gpu":
            from .bench_gpu import format_gpu

            lines += format_gpu(value)
        elif key not in ("machine", "workload", "reference_episodes_per_second"):
            lines.append(f"  {key:<34} {value:>12.4g}" if isinstance(value, float) else f"  {key:<34} {value}")
    return "\n".join(lines)
