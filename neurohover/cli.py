"""Command line: ``neurohover COMMAND --help`` for each command.

Bad input prints one clear message and exits with status 2 (never a traceback from numba).
"""

from __future__ import annotations

import argparse
import importlib
import json
import os
import sqlite3
import sys
from collections.abc import Sequence
from dataclasses import fields

import numpy as np

from . import __version__
from .errors import NeurohoverError
from .sim.constants import EPISODE_STEPS
from .tasks.sensor import Sensor

# Modules of later pipeline stages; each has ``register(subparsers)`` adding its commands.
COMMAND_MODULES: tuple[str, ...] = (
    "neurohover.commands_learning",
    "neurohover.commands_agents",
    "neurohover.commands_evaluate",
    "neurohover.commands_reproduce",
    "neurohover.commands_plots",
)


def parse_floats(text: str, what: str) -> list[float]:
    """Comma-separated numbers of option ``what``, or one clear error."""
    try:
        return [float(x) for x in text.split(",") if x.strip() != ""]
    except ValueError:
        raise NeurohoverError(f"{what} must be comma-separated numbers, got {text!r}") from None


def explicit_mdp(args: argparse.Namespace, family):
    """The MDP set by --wind or --params, with its description (``"wind=..."``), or None without them.

    Refuses both together, either with --mdp, and --wind for a family other than GHH-08
    (shared by ``fly`` and ``evolve``).
    """
    if args.wind is not None and args.params is not None:
        raise NeurohoverError("give either --wind (GHH-08) or --params, not both")
    if (args.wind is not None or args.params is not None) and args.mdp is not None:
        given = "--wind" if args.wind is not None else "--params"
        raise NeurohoverError(f"{given} sets the MDP explicitly; it cannot be combined with --mdp {args.mdp}")
    if args.wind is not None:
        if family.name != "ghh08":
            raise NeurohoverError(f"--wind U,V sets a GHH-08 MDP; task {args.task!r} takes --params")
        return family.make(parse_floats(args.wind, "--wind")), f"wind={args.wind}"
    if args.params is not None:
        return family.make(parse_floats(args.params, "--params")), f"params={args.params}"
    return None


def add_lr_fit_options(p: argparse.ArgumentParser, who: str) -> None:
    """--d-u and --noise-estimate: LR fitted as ours or as the authors' code did (``who`` applies them)."""
    from .models.lr import D_U_CHOICES, NOISE_ESTIMATES

    p.add_argument("--d-u", choices=D_U_CHOICES, help=f"{who}: keep the fitted u constant as the model's D_u (default) or discard it, as the authors' code did")
    p.add_argument(
        "--noise-estimate",
        choices=NOISE_ESTIMATES,
        help=f"{who}: the model's gust noise from the authors' rms one-step error / 0.05 (default) or the residuals' innovations / 0.4",
    )


def add_sensor_options(p: argparse.ArgumentParser) -> None:
    """--obs-noise and --obs-delay: the task seen through noisy or late sensors (:mod:`neurohover.tasks.sensor`)."""
    g = p.add_argument_group("noisy sensors (docs/benchmarks.md; default: exact sensors)")
    g.add_argument(
        "--obs-noise",
        action="append",
        help="sensor noise on what the policy sees: a level (e.g. 0.5: std 0.05 m/s, 0.05 m, 0.05 rad/s, 0.005) or key=value pairs "
        f"of {', '.join(f.name for f in fields(Sensor) if f.name != 'delay')} or level (docs/benchmarks.md)",
    )
    g.add_argument("--obs-delay", type=int, help="control steps (0..10, 0.1 s each) the readings arrive late (default 0)")


def sensor_of(args: argparse.Namespace):
    """The sensor of --obs-noise/--obs-delay (None where neither is given: exact sensors)."""
    noise, delay = getattr(args, "obs_noise", None), getattr(args, "obs_delay", None)
    if noise is not None and len(noise) > 1:  # the option is appended to catch a repeat, which would silently keep the last
        raise NeurohoverError(f"--obs-noise is given {len(noise)} times ({', '.join(map(repr, noise))}): give it once, key=value pairs joined by commas")
    noise = None if noise is None else noise[0]
    return None if noise is None and delay is None else Sensor.of(noise, delay)


def task_family_of(args: argparse.Namespace):
    """The task family of --task/--sigma, seen through the sensor of --obs-noise/--obs-delay."""
    from .tasks import get_task_family

    return get_task_family(args.task, args.sigma, sensor_of(args))


def _family_and_mdps(args: argparse.Namespace, n: int, rng: np.random.Generator):
    """The task family and the MDP of each of ``n`` episodes, from --task/--mdp/--wind/--params/--sigma/--obs-noise/--obs-delay."""
    family = task_family_of(args)
    explicit = explicit_mdp(args, family)
    if explicit is not None:
        return family, [explicit[0]] * n
    if args.mdp == "sample":  # a fresh MDP from G for every episode
        return family, [family.sample(rng, label=f"{family.name}/sample:{i}") for i in range(n)]
    return family, [family.mdp("zero" if args.mdp is None else args.mdp)] * n  # an empty --mdp is refused, not the zero setting


def _add_task_options(p: argparse.ArgumentParser) -> None:
    p.add_argument("--task", required=True, help="task family: ghh08, ghh09 or fghh")
    p.add_argument(
        "--mdp", help="zero (default), train:N, test:N (the competition sets), seeded-train:N, seeded-test:N, or sample (a fresh MDP from G per episode)"
    )
    p.add_argument("--wind", help="GHH-08 only: constant wind U,V in m/s, each in [-5, 5] (instead of --mdp)")
    p.add_argument(
        "--params",
        help="explicit MDP parameters, comma-separated (instead of --mdp): GHH-08 wind_u,wind_v; "
        "GHH-09 its 8 parameters in [0,1]; FGHH the 11 dynamics parameters",
    )
    p.add_argument("--sigma", type=float, help="FGHH breadth sigma (default 0.3)")
    add_sensor_options(p)


# Episodes per kernel call of a progress-reporting fly: large enough to keep every core busy.
FLY_CHUNK = 256
# What one episode of ``fly`` holds in memory (its MDP's slot, index, return, crash flag and list
# entries; a sampled MDP's object; a recorded episode's 12 + 4 float64 a step), for the cap below.
_FLY_BYTES_PER_EPISODE = 64
_SAMPLED_MDP_BYTES = 2000
_RECORD_BYTES_PER_STEP = 16 * 8


def max_in_memory(bytes_each: int) -> int:
    """How many items of ``bytes_each`` bytes fit in half the memory free now (checked before any work)."""
    try:
        free = os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (ValueError, OSError, AttributeError):  # not POSIX: no cap
        return 2**62
    return max(1, free // 2 // bytes_each)


def _fly(policy, mdps: list, args: argparse.Namespace, show_progress: bool):
    """Fly ``policy`` once on each of ``mdps`` (episode i on mdps[i]); chunked under a progress bar."""
    from tqdm import tqdm

    from .evaluate import evaluate_jobs

    unique = list(dict.fromkeys(mdps))
    mdp_index = np.array([unique.index(m) for m in mdps])
    n = len(mdps)
    returns, crashed, seconds, flight = [], [], 0.0, None
    # Every episode's gusts come from (seed, episode index), so chunking changes no result.
    with tqdm(
        total=n,
        desc=f"fly {mdps[0].label if len(unique) == 1 else 'MDPs'}",
        unit="ep",
        file=sys.stderr,
        disable=None if show_progress else True,
        dynamic_ncols=True,
    ) as bar:
        for start in range(0, n, FLY_CHUNK if show_progress else n):
            idx = np.arange(start, min(n, start + (FLY_CHUNK if show_progress else n)))
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
    from .paths import output_file, writing
    from .policies import load_policy

    if args.episodes < 1:
        raise NeurohoverError(f"--episodes {args.episodes} is out of range: allowed >= 1")
    per_episode = _FLY_BYTES_PER_EPISODE + (_SAMPLED_MDP_BYTES if args.mdp == "sample" else 0) + (_RECORD_BYTES_PER_STEP * EPISODE_STEPS if args.record else 0)
    most = max_in_memory(per_episode)
    if args.episodes > most:
        raise NeurohoverError(
            f"--episodes {args.episodes} is out of range: about {per_episode} bytes each, at most {most} fit in half this machine's free memory"
        )
    policy = load_policy(args.policy)
    rng = np.random.default_rng(args.seed)
    family, mdps = _family_and_mdps(args, args.episodes, rng)
    if args.record is not None:
        output_file(args.record, "--record")
    returns, crashed, seconds, fd, n_unique = _fly(policy, mdps, args, show_progress=not args.json)
    if fd is not None:
        fd.metadata.update(
            {"task": family.name, "mdps": [m.to_dict() for m in mdps], "policy": str(args.policy), "seed": args.seed, "returns": returns.tolist()}
        )
        with writing(args.record, "--record") as path:
            fd.save(path, dtype=args.record_dtype)
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
            print(f"{label:>20}: {value:.6g}" if isinstance(value, float) else f"{label:>20}: {value}")
    return 0


def cmd_demo(args: argparse.Namespace) -> int:
    """Fly the baseline and the baseline-equivalent MLP on a few MDPs of each family; print a table."""
    from .evaluate import check_episode_count, evaluate
    from .policies import baseline_policy, prototype
    from .tasks import N_TRAINING, TASK_NAMES, get_task_family

    if not 0 <= args.mdps <= N_TRAINING:
        raise NeurohoverError(f"--mdps {args.mdps} is out of range: allowed 0..{N_TRAINING} (training MDPs per family, beside the zero setting)")
    check_episode_count(2 * (args.mdps + 1) * max(args.episodes, 0), f"2 policies x {args.mdps + 1} MDPs x episodes={args.episodes}")  # before the table
    policies = {"baseline": baseline_policy(), "mlp(baseline seed)": prototype("mlp", "baseline")}
    print(f"{'task':<6} {'mdp':<16} {'policy':<20} {'mean return':>12} {'sd':>10} {'crashes':>8}")
    for name in TASK_NAMES:
        family = get_task_family(name)
        mdps = [family.zero()] + family.training_mdps()[: args.mdps]
        ev = evaluate(list(policies.values()), mdps, episodes=args.episodes, seed=args.seed)
        for i, label in enumerate(policies):
            for m, mdp in enumerate(mdps):
                r = ev.returns[i, m]
                print(f"{name:<6} {mdp.label.split('/')[-1]:<16} {label:<20} {r.mean():>12.1f} {r.std():>10.1f} {int(ev.crashed[i, m].sum()):>8}")
    return 0


def cmd_bench(args: argparse.Namespace) -> int:
    """Measure throughput against the plain-Python reference simulator."""
    from .bench import format_report, run_benchmarks

    report = run_benchmarks(quick=args.quick)
    print(json.dumps(report, indent=1) if args.json else format_report(report))
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="neurohover", description="Generalized helicopter hovering (Koppejan & Whiteson 2011): fly, evolve, learn models, compete, reproduce."
    )
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    p = sub.add_parser("fly", help="fly a policy and print return statistics", description=cmd_fly.__doc__)
    _add_task_options(p)
    p.add_argument("--policy", default="baseline", help="'baseline' or a JSON policy file")
    p.add_argument("--episodes", type=int, default=10, help="number of episodes (default 10)")
    p.add_argument("--seed", type=int, default=0, help="root seed of the noise streams (default 0)")
    p.add_argument("--threads", type=int, help="kernel threads (default: all cores)")
    p.add_argument("--record", metavar="FILE", help="write the flight data of every episode to FILE (.npz)")
    p.add_argument(
        "--record-dtype",
        choices=("float64", "float32"),
        default="float64",
        help="precision of the recorded flight data: float64 (exact; about 0.74 MB a 6000-step episode) or float32 (about half that)",
    )
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(func=cmd_fly)

    p = sub.add_parser("demo", help="fly the baseline and an MLP policy on a few MDPs and print a table", description=cmd_demo.__doc__)
    p.add_argument("--mdps", type=int, default=3, help="training MDPs per family (default 3)")
    p.add_argument("--episodes", type=int, default=5, help="episodes per MDP (default 5)")
    p.add_argument("--seed", type=int, default=0)
    p.set_defaults(func=cmd_demo)

    p = sub.add_parser("bench", help="measure simulator throughput", description=cmd_bench.__doc__)
    p.add_argument("--quick", action="store_true", help="fewer episodes (rough figures in 5-10 seconds on 2 cores)")
    p.add_argument("--json", action="store_true", help="print the report as JSON")
    p.set_defaults(func=cmd_bench)

    for module in COMMAND_MODULES:
        importlib.import_module(module).register(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    from .paths import forget_created_dirs, remove_created_dirs

    forget_created_dirs()
    try:
        if getattr(args, "seed", None) is not None:  # every command's --seed, one range, before any work
            from .evolution.seeding import check_seed

            check_seed(args.seed)
        return args.func(args)
    except NeurohoverError as err:
        print(f"neurohover {args.command}: error: {err}", file=sys.stderr)
        remove_created_dirs()  # a failed command leaves no empty output directory behind
        return 2
    except sqlite3.DatabaseError as err:  # a store file damaged mid-file, or not a store at all
        print(f"neurohover {args.command}: error: a results store cannot be read ({err}): the file is damaged or is no results store", file=sys.stderr)
        remove_created_dirs()
        return 2
    except KeyboardInterrupt as stop:
        from .procs import Terminated

        print(f"neurohover {args.command}: {'terminated' if isinstance(stop, Terminated) else 'interrupted'}", file=sys.stderr)
        return 143 if isinstance(stop, Terminated) else 130  # 128 + the signal's number, as shells report
    except BrokenPipeError:  # the reader went away (`neurohover demo | head -1`): stop quietly, as Python's docs advise
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())  # so that the interpreter's own flush at exit does not fail again
        return 1


if __name__ == "__main__":
    sys.exit(main())
