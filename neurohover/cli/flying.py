"""``neurohover fly``, ``demo`` and ``bench``: fly policies on MDPs and print what they return."""

from __future__ import annotations

import argparse
import contextlib
import json
import sys
from pathlib import Path

import numpy as np

from ..errors import NeurohoverError
from ..sim.constants import EPISODE_STEPS
from .options import add_task_options, family_and_mdps, integer, max_in_memory, note_policy_name, note_policy_task

# Episodes per kernel call of a progress-reporting fly: large enough to keep every core busy.
FLY_CHUNK = 256
# What one episode of ``fly`` holds in memory (its MDP's slot, index, return, crash flag and list
# entries; a sampled MDP's object; a recorded episode's 12 + 4 float64 a step), for the cap below.
_FLY_BYTES_PER_EPISODE = 64
_SAMPLED_MDP_BYTES = 2000
_RECORD_BYTES_PER_STEP = 16 * 8


def _fly(policy, mdps: list, args: argparse.Namespace, show_progress: bool):
    """Fly ``policy`` once on each of ``mdps`` (episode i on mdps[i]); chunked under a progress bar."""
    from ..evaluate import evaluate_jobs
    from ..progress import progress_bar

    unique = list(dict.fromkeys(mdps))
    mdp_index = np.array([unique.index(m) for m in mdps])
    n = len(mdps)
    returns, crashed, seconds, flight = [], [], 0.0, None
    # Every episode's gusts come from (seed, episode index), so chunking changes no result.
    with progress_bar(
        total=n,
        desc=f"fly {mdps[0].label if len(unique) == 1 else 'MDPs'}",
        unit="ep",
        disable=None if show_progress else True,
        dynamic_ncols=True,
    ) as bar:
        for start in range(0, n, FLY_CHUNK):  # chunked with or without the bar: Ctrl-C is heard between chunks (--json ignored it)
            idx = np.arange(start, min(n, start + FLY_CHUNK))
            ev = evaluate_jobs(
                [policy],
                unique,
                np.zeros(idx.size, dtype=np.int64),
                mdp_index[idx],
                idx,
                seed=args.seed,
                record=np.full(idx.size, args.record is not None),
                threads=args.threads,
            )
            returns.append(ev.returns)
            crashed.append(ev.crashed)
            seconds += ev.seconds
            if ev.flight_data is not None:
                flight = ev.flight_data if flight is None else flight + ev.flight_data
            bar.update(idx.size)
    return np.concatenate(returns), np.concatenate(crashed), seconds, flight, len(unique)


def cmd_fly(args: argparse.Namespace) -> int:
    """Fly a policy and print return statistics."""
    with contextlib.ExitStack() as held:  # --record's writer lock, held until the command ends
        return _fly_command(args, held)


def _fly_command(args: argparse.Namespace, held: contextlib.ExitStack) -> int:
    from ..filekinds import FLIGHT_DATA_KIND
    from ..flightdata import check_npz_name
    from ..paths import output_file, printable, sole_writer
    from ..policies import load_policy

    if args.episodes < 1:
        raise NeurohoverError(f"--episodes {args.episodes} is out of range: allowed >= 1")
    if args.record is None and args.record_dtype is not None:
        raise NeurohoverError(f"--record-dtype {args.record_dtype} applies to the flight data --record FILE writes: give --record, or leave it out")
    per_episode = _FLY_BYTES_PER_EPISODE + (_SAMPLED_MDP_BYTES if args.mdp == "sample" else 0) + (_RECORD_BYTES_PER_STEP * EPISODE_STEPS if args.record else 0)
    most = max_in_memory(per_episode)
    if args.episodes > most:
        raise NeurohoverError(
            f"--episodes {args.episodes} is out of range: about {per_episode} bytes each, at most {most} fit in half this machine's free memory"
        )
    note_policy_name(args.policy, "--policy")
    policy = load_policy(args.policy)
    rng = np.random.default_rng(args.seed)
    family, mdps = family_and_mdps(args, args.episodes, rng)
    note_policy_task(policy, family.name, f"--policy {args.policy}")
    if args.record is not None:
        if Path(args.record).suffix:  # another suffix is refused before output_file makes its directory
            check_npz_name(args.record, "--record")
        record = output_file(args.record, "--record", {"--policy": args.policy}, kind=FLIGHT_DATA_KIND)  # a checkpoint through a link (T34-B03)
        check_npz_name(args.record, "--record")  # no suffix: after output_file's own refusals ('-', a directory, a device)
        held.enter_context(sole_writer(record, "--record"))  # two runs at once both said they wrote it; one's episodes were lost (T41-A02)
    returns, crashed, seconds, fd, n_unique = _fly(policy, mdps, args, show_progress=not args.json)
    if fd is not None:
        fd.metadata.update(
            {"task": family.name, "mdps": [m.to_dict() for m in mdps], "policy": str(args.policy), "seed": args.seed, "returns": returns.tolist()}
        )
        # the policy itself: its file's name alone was looked up from learn-model's directory, another file there (ninth trial)
        fd.metadata["policy_flown"] = {"topology": policy.topology, "genome": policy.genome.tolist()}
        fd.save(args.record, dtype=args.record_dtype or "float64")  # a failed write: one message, no partial file
    summary = {
        "task": family.name,
        **({} if family.sensor.exact else {"sensor": family.sensor.to_dict()}),
        "mdp": mdps[0].label if n_unique == 1 else f"{n_unique} MDPs",
        "policy": str(args.policy),
        "episodes": args.episodes,
        "mean_return": float(returns.mean()),
        "std_return": float(returns.std()),
        "min_return": float(returns.min()),
        "max_return": float(returns.max()),
        "crashes": int(crashed.sum()),
        "episodes_per_second": args.episodes / seconds if seconds > 0 else float("inf"),
    }
    if args.record is not None:
        summary["flight_data"] = str(args.record)
    if args.json:
        print(json.dumps(summary))
    else:
        for key, value in summary.items():
            label = "flight data" if key == "flight_data" else key
            shown = printable(value) if isinstance(value, str) else value  # a newline or U+202E in a name split or reversed the line (T14-24)
            print(f"{label:>20}: {value:.6g}" if isinstance(value, float) else f"{label:>20}: {shown}")
    return 0


def _demo_stats(policies: list, mdp, m: int, args: argparse.Namespace, bar) -> np.ndarray:
    """(mean, sd, crashes) of each policy's ``args.episodes`` episodes on ``mdp``, the ``m``-th MDP of its family, flown in
    calls of :data:`FLY_CHUNK` x 8 episodes: a Ctrl-C or SIGTERM is heard between calls (one call of 4,000,000 episodes heard
    neither for minutes; fifth trial), and episode e keeps the gusts ``evaluate`` gives it, index m x episodes + e."""
    from ..evaluate import evaluate

    count, mean, m2, crashes = 0, np.zeros(len(policies)), np.zeros(len(policies)), np.zeros(len(policies), dtype=np.int64)
    for start in range(0, args.episodes, 8 * FLY_CHUNK):
        n = min(8 * FLY_CHUNK, args.episodes - start)
        ev = evaluate(policies, [mdp], episodes=n, seed=args.seed, first_episode=m * args.episodes + start)
        r = ev.returns[:, 0]  # (policies, n)
        delta = r.mean(axis=1) - mean  # Chan et al.'s pairwise update: the sd of all episodes, without holding them
        mean, m2 = mean + delta * n / (count + n), m2 + ((r - r.mean(axis=1, keepdims=True)) ** 2).sum(axis=1) + delta**2 * count * n / (count + n)
        count += n
        crashes += ev.crashed[:, 0].sum(axis=1)
        bar.update(n * len(policies))
    return np.stack([mean, np.sqrt(m2 / count), crashes])


def cmd_demo(args: argparse.Namespace) -> int:
    """Fly the baseline and the baseline-equivalent MLP on a few MDPs of each family; print a table."""
    from ..evaluate import check_episode_count
    from ..policies import baseline_policy, prototype
    from ..progress import progress_bar
    from ..tasks import N_TRAINING, TASK_NAMES, get_task_family

    if not 0 <= args.mdps <= N_TRAINING:
        raise NeurohoverError(f"--mdps {args.mdps} is out of range: allowed 0..{N_TRAINING} (training MDPs per family, beside the zero setting)")
    if args.episodes < 1:  # refused before the table's header is printed (second trial)
        raise NeurohoverError(f"--episodes {args.episodes} is out of range: allowed an integer >= 1")
    check_episode_count(2 * (args.mdps + 1) * args.episodes, f"2 policies x {args.mdps + 1} MDPs x episodes={args.episodes}")  # before the table
    policies = {"baseline": baseline_policy(), "mlp(baseline seed)": prototype("mlp", "baseline")}
    print(f"{'task':<6} {'mdp':<16} {'policy':<20} {'mean return':>12} {'sd':>10} {'crashes':>8}")
    total = len(TASK_NAMES) * (args.mdps + 1) * args.episodes * len(policies)
    with progress_bar(total=total, desc="demo", unit="episode", leave=False, dynamic_ncols=True) as bar:  # a terminal only
        for name in TASK_NAMES:
            family = get_task_family(name)
            mdps = [family.zero()] + family.training_mdps()[: args.mdps]
            stats = [_demo_stats(list(policies.values()), mdp, m, args, bar) for m, mdp in enumerate(mdps)]
            for i, label in enumerate(policies):
                for mdp, (mean, sd, crashes) in zip(mdps, stats):
                    bar.write(f"{name:<6} {mdp.label.split('/')[-1]:<16} {label:<20} {mean[i]:>12.1f} {sd[i]:>10.1f} {int(crashes[i]):>8}", file=sys.stdout)
    return 0


def cmd_bench(args: argparse.Namespace) -> int:
    """Measure throughput against the plain-Python reference simulator."""
    from ..bench import format_report, run_benchmarks

    report = run_benchmarks(quick=args.quick)
    print(json.dumps(report, indent=1) if args.json else format_report(report))
    return 0


def register(sub) -> None:
    """Add the fly, demo and bench commands to the ``neurohover`` subparsers ``sub``."""
    p = sub.add_parser("fly", help="fly a policy and print return statistics", description=cmd_fly.__doc__)
    add_task_options(p)
    p.add_argument("--policy", default="baseline", help="'baseline' or a JSON policy file")
    p.add_argument("--episodes", type=integer, default=10, help="number of episodes (default 10)")
    p.add_argument("--seed", type=integer, default=0, help="root seed of the noise streams (default 0)")
    p.add_argument("--threads", type=integer, help="kernel threads (default: all cores)")
    p.add_argument("--record", metavar="FILE", help="write the flight data of every episode to FILE (its name ending .npz)")
    p.add_argument(
        "--record-dtype",
        choices=("float64", "float32"),
        help="precision of the recorded flight data: float64 (default; exact, about 0.74 MB a 6000-step episode) or float32 (about half that)",
    )
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(func=cmd_fly)

    p = sub.add_parser("demo", help="fly the baseline and an MLP policy on a few MDPs and print a table", description=cmd_demo.__doc__)
    p.add_argument("--mdps", type=integer, default=3, help="training MDPs per family (default 3)")
    p.add_argument("--episodes", type=integer, default=5, help="episodes per MDP (default 5)")
    p.add_argument("--seed", type=integer, default=0)
    p.set_defaults(func=cmd_demo)

    p = sub.add_parser("bench", help="measure simulator throughput", description=cmd_bench.__doc__)
    p.add_argument("--quick", action="store_true", help="fewer episodes (rough figures in 5-10 seconds on 2 cores)")
    p.add_argument("--json", action="store_true", help="print the report as JSON")
    p.set_defaults(func=cmd_bench)
