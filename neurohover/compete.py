"""The competition harness: R independent test runs of an agent, summary, files and plots.

``neurohover compete`` writes to its output directory:

- ``episodes.csv``: one row per (run, episode): run, mdp, episode, return, crashed, steps, policy,
  safeguard_fired, offline_seconds. Each run's rows are appended the moment the run finishes, so
  an interrupted competition keeps every finished run.
- ``summary.json``: the summary table below plus the settings.
- ``cumulative.png``: mean cumulative error (minus cumulative return) per episode, on a linear
  and a log scale, like the paper's Figures 4 and 7.

Summary per agent: mean and sd of the cumulative return over runs, crash rate (share of runs
with at least one crash, and crashes per episode), and the mean return per episode after
learning (from the first episode after which the agent's policy no longer changes).
"""

from __future__ import annotations

import csv
import json
import os
from collections.abc import Callable, Sequence
from concurrent.futures import FIRST_COMPLETED, wait
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .agents.hybrid import HybridSettings
from .agents.protocol import RunResult, run_test
from .errors import NeurohoverError
from .procs import sigterm_as_interrupt, stop_pool, worker_pool
from .sim.constants import EPISODE_STEPS
from .tasks import MDP, get_task_family

CSV_COLUMNS = ("run", "mdp", "episode", "return", "crashed", "steps", "policy", "safeguard_fired", "offline_seconds")


@dataclass(frozen=True)
class RunSpec:
    """One unit of work: test run ``index`` of ``agent`` on ``mdp``."""

    index: int
    task: str
    sigma: float | None
    agent: str
    mdp: MDP
    episodes: int
    seed: int
    n_steps: int
    policy_dir: str | None
    hybrid: HybridSettings = HybridSettings()


def run_mdps(task: str, runs: int, mdps: str, seed: int, sigma: float | None = None) -> list[MDP]:
    """The MDP of each run: the test set in turn (``test``) or fresh draws from G (``sample``)."""
    family = get_task_family(task, sigma)
    if mdps == "test":
        test = family.test_mdps()
        return [test[i % len(test)] for i in range(runs)]
    if mdps == "sample":
        rng = np.random.default_rng(np.random.SeedSequence([seed, 0x5A3]))
        return [family.sample(rng, label=f"{family.name}/sample:{i}") for i in range(runs)]
    if mdps == "train":
        train = family.training_mdps()
        return [train[i % len(train)] for i in range(runs)]
    raise NeurohoverError(f"unknown --mdps {mdps!r}: allowed test, sample, train")


def execute(spec: RunSpec, threads: int | None = 1) -> RunResult:
    """Fly one test run (in this process)."""
    from .agents.registry import AgentOptions, make_agent

    family = get_task_family(spec.task, spec.sigma)
    agent = make_agent(spec.agent, family, policy_dir=spec.policy_dir, options=AgentOptions(hybrid=spec.hybrid))
    return run_test(agent, family, spec.mdp, episodes=spec.episodes, seed=spec.seed * 1_000_003 + spec.index,
                    n_steps=spec.n_steps, threads=threads)


def _append_rows(path: Path, spec: RunSpec, result: RunResult) -> None:
    new = not path.exists()
    with open(path, "a", newline="") as f:
        writer = csv.writer(f)
        if new:
            writer.writerow(CSV_COLUMNS)
        for row in result.rows():
            writer.writerow([spec.index, spec.mdp.label, row["episode"], repr(row["return"]), int(row["crashed"]),
                             row["steps"], row["policy"], int(row["safeguard_fired"]), f"{row['offline_seconds']:.6f}"])
        f.flush()
        os.fsync(f.fileno())


def after_learning_start(policy_labels: Sequence[str]) -> int:
    """First episode from which the policy no longer changes."""
    start = len(policy_labels) - 1
    while start > 0 and policy_labels[start - 1] == policy_labels[-1]:
        start -= 1
    return start


def summarise(results: Sequence[RunResult]) -> dict:
    """Summary figures over test runs (see the module docstring)."""
    scores = np.array([r.score for r in results])
    after = [r.returns[after_learning_start(r.policy):] for r in results]
    crashes = np.array([int(r.crashed.sum()) for r in results])
    return {
        "runs": len(results),
        "episodes": int(results[0].returns.size) if results else 0,
        "mean_cumulative_return": float(scores.mean()),
        "sd_cumulative_return": float(scores.std(ddof=1)) if len(results) > 1 else 0.0,
        "crash_rate_runs": float(np.mean(crashes > 0)),
        "crashes_per_episode": float(crashes.sum() / sum(r.returns.size for r in results)),
        "mean_return_after_learning": float(np.mean(np.concatenate(after))),
        "mean_seconds_per_run": float(np.mean([r.seconds for r in results])),
        "mean_offline_seconds_per_run": float(np.mean([r.offline_seconds.sum() for r in results])),
    }


def plot_cumulative(curves: dict[str, np.ndarray], path: Path, title: str) -> Path:
    """Mean cumulative error per episode of each agent, linear and log scale (paper Figs 4 and 7)."""
    # Object-oriented matplotlib (no pyplot): the caller's backend and pyplot figures stay as they are.
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(11, 4))
    FigureCanvasAgg(fig)
    axes = fig.subplots(1, 2)
    for name, cumulative in curves.items():
        error = -cumulative.mean(axis=0)
        episodes = np.arange(1, error.size + 1)
        for ax in axes:
            ax.plot(episodes, error, label=name)
    axes[0].set_ylabel("cumulative error (-cumulative reward)")
    axes[1].set_yscale("log")
    axes[1].set_ylabel("cumulative error (log scale)")
    for ax in axes:
        ax.set_xlabel("episode")
        ax.grid(alpha=0.3)
        ax.legend()
    fig.suptitle(title)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    return path


def compete(
    task: str,
    agent: str,
    *,
    runs: int = 10,
    episodes: int = 1000,
    mdps: str = "test",
    seed: int = 0,
    jobs: int = 1,
    out: str | Path,
    sigma: float | None = None,
    n_steps: int = EPISODE_STEPS,
    policy_dir: str | None = None,
    hybrid: HybridSettings = HybridSettings(),
    on_result: Callable[[RunSpec, RunResult], None] | None = None,
) -> tuple[dict, list[RunResult]]:
    """Run ``runs`` test runs in ``jobs`` processes; write results and plot to ``out``.

    ``hybrid`` sets the safeguard and replacement rule of the hybrid agents (ignored by the others).

    Raises KeyboardInterrupt after saving every finished run when interrupted (SIGTERM too, as
    :class:`~neurohover.procs.Terminated`, while ``jobs > 1``).
    """
    from .agents.registry import check_agent

    for name, value in (("runs", runs), ("episodes", episodes), ("jobs", jobs)):
        if not isinstance(value, int) or value < 1:
            raise NeurohoverError(f"{name}={value!r} is out of range: allowed an integer >= 1")
    check_agent(agent, get_task_family(task, sigma), policy_dir)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    csv_path = out / "episodes.csv"
    if csv_path.exists():
        csv_path.unlink()
    specs = [RunSpec(i, task, sigma, agent, m, episodes, seed, n_steps, policy_dir, hybrid)
             for i, m in enumerate(run_mdps(task, runs, mdps, seed, sigma))]
    results: dict[int, RunResult] = {}

    def finish(spec: RunSpec, result: RunResult) -> None:
        results[spec.index] = result
        _append_rows(csv_path, spec, result)
        if on_result is not None:
            on_result(spec, result)

    if jobs == 1:
        for spec in specs:
            finish(spec, execute(spec, threads=None))
    else:
        # Spawned workers that exit when this process dies; SIGTERM ends them like Ctrl-C.
        pool = worker_pool(jobs)
        try:
            with sigterm_as_interrupt():
                pending = {pool.submit(execute, spec, 1): spec for spec in specs}
                while pending:
                    done, _ = wait(pending, return_when=FIRST_COMPLETED)
                    for future in done:
                        finish(pending.pop(future), future.result())
        except BaseException:
            stop_pool(pool)  # an unfinished run is never written: end the others at once
            raise
        pool.shutdown(wait=True)
    ordered = [results[i] for i in sorted(results)]
    summary = {"task": task, "agent": agent, "mdps": mdps, "seed": seed, **summarise(ordered)}
    (out / "summary.json").write_text(json.dumps(summary, indent=1) + "\n")
    plot_cumulative({agent: np.array([r.cumulative for r in ordered])}, out / "cumulative.png",
                    f"{task}: {agent}, {len(ordered)} runs")
    return summary, ordered
