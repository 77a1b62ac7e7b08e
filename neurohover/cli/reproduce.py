"""Commands of the reproduction stage: ``reproduce``, ``results`` and ``report``.

- ``neurohover reproduce NAME|all|FILE.toml --scale quick|paper --store FILE [--executor local|ray]
  [--address ADDR] [--jobs J] [--set KEY=VALUE ...] [--fresh | --update]``: run an experiment's units
  (skipping those already in the store), with a progress bar over its units.
- ``neurohover results NAME --store FILE [--scale S] [--format csv|json] [--out FILE]``: export.
- ``neurohover report --store FILE --out DIR [--scale S] [NAME ...]``: figures and report.md.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import sys
from pathlib import Path

from ..errors import FloatRangeError, NeurohoverError, brief
from ..evaluate import DEVICES, check_device
from ..experiments.config import shipped_name
from ..filekinds import refuse_sqlite_name
from ..paths import printable
from .options import integer


def cmd_reproduce(args: argparse.Namespace) -> int:
    """Run a paper experiment (or all of them); every finished unit goes to the results store at once."""
    from ..experiments import Store, load_configs, make_executor, reproduce
    from ..experiments.config import check_own_name, experiment_names, parse_overrides
    from ..experiments.plans import source_experiments
    from ..experiments.runner import check_patterns_once, check_restart
    from ..filekinds import refuse_long_store_name
    from ..paths import output_file
    from ..procs import stop_words

    if args.list:
        if args.name is not None:  # the name was ignored (fourth trial)
            raise NeurohoverError(f"--list lists every experiment and takes no NAME (got {args.name!r}): give one or the other")
        others = _options_beside_list(args)
        if others:  # --store, --set, --fresh ... were dropped without a word (eleventh trial, S1)
            raise NeurohoverError(f"--list lists every experiment and takes no other options (got {', '.join(others)}): give one or the other")
        for name in experiment_names():
            print(name)
        return 0
    if args.name is None:
        raise NeurohoverError("give an experiment NAME (" + ", ".join(experiment_names()) + "), 'all', or a .toml config file")
    if args.store is None:
        raise NeurohoverError("give the results store file with --store FILE (it is created if missing)")
    check_restart(args.fresh, args.update, args.only or ())  # before the store file is made
    check_patterns_once(args.only or (), "--only")
    if args.executor == "ray" and args.jobs != 1:
        raise NeurohoverError("--jobs applies to --executor local; Ray runs one unit per CPU of the cluster")
    if args.address is not None and args.executor != "ray":
        raise NeurohoverError(f"--address {args.address} names a Ray cluster; add --executor ray (or leave out --address)")
    check_device(args.device)
    refuse_long_store_name(args.store, "--store")  # its -journal too (T31-A03)
    output_file(args.store, "--store", store=True)
    overrides = parse_overrides(args.set)
    try:
        configs = load_configs(args.name, args.scale, overrides)
    except NeurohoverError as err:
        if args.name == "all" and overrides:  # fig2 refused episodes=2 without saying why it was asked (trial 30, borderline)
            raise NeurohoverError(f"{err} (--set applies to every experiment of 'all': give one NAME to set what only some have)") from None
        raise
    for config in configs:
        check_own_name(config)  # before a store is made
    named = [c.name for c in configs]
    sources_added: set[str] = set()
    for config in list(configs):  # experiments that draw from others run after them (e.g. fig16 after fig13 and fig15)
        for source in source_experiments(config):
            if source not in named:
                print(f"neurohover reproduce: {config.name} draws its generic policies from {source}: running {source} first", file=sys.stderr)
                configs.insert(configs.index(config), load_configs(source, args.scale)[0])
                named.append(source)
                sources_added.add(source)
    if args.only and len(configs) > 1 and args.name != "all":
        raise NeurohoverError(
            f"--only selects units of one experiment; {args.name} also runs {', '.join(c.name for c in configs if c.name != args.name)} first"
        )
    if args.only and len(configs) > 1:
        raise NeurohoverError(f"--only selects units of one experiment: give its NAME instead of {args.name!r}")
    executor = make_executor(args.executor, jobs=args.jobs, address=args.address, device=args.device)
    failed = False
    was = Path(args.store).stat().st_size if Path(args.store).is_file() else None  # None: no file yet; 0: an empty one
    try:
        with Store(args.store) as store:
            for config in configs:
                try:
                    # --fresh applies to the experiments named, never to the sources run first (their results stay).
                    fresh = args.fresh and config.name not in sources_added
                    update = args.update and config.name not in sources_added
                    summary = reproduce(config, store, executor, fresh=fresh, update=update, progress=args.progress, only=tuple(args.only or ()))
                except KeyboardInterrupt as stop:
                    done = len(store.results(config.name, config.scale, missing_ok=True))
                    how, status = stop_words(stop)
                    print(
                        f"neurohover reproduce: {how}; {done} finished units of {config.name} are in {args.store}; run the same command again to resume",
                        file=sys.stderr,
                    )
                    return status
                print(summary.line())
                failed = failed or not summary.succeeded
    except NeurohoverError:
        if was in (None, 0):  # a refusal leaves no store it made that holds no unit (an empty file stays empty; T16-8)
            _remove_if_empty(Path(args.store), keep_file=was == 0)
        raise
    finally:
        executor.close()
    return 1 if failed else 0


def _options_beside_list(args: argparse.Namespace) -> list[str]:
    """The options given beside ``reproduce --list``, as typed (single-valued ones and flags are recorded as they are parsed)."""
    given = sorted(getattr(args, "_given_options", set()) - {"list", "name", "progress"})  # NAME: refused above; progress: as typed, below
    given += [d for d in ("set", "only") if getattr(args, d, None)]  # repeatable: not recorded
    names = [f"--{d.replace('_', '-')}" for d in given]
    if args.progress is not None:
        names.append("--progress" if args.progress else "--no-progress")
    return names


def _remove_if_empty(path: Path, keep_file: bool = False) -> None:
    """Delete the store file at ``path`` if it holds no finished unit (``keep_file``: empty it to 0 bytes instead, as
    the user's empty file was)."""
    from ..experiments import Store

    if not path.exists() or path.stat().st_size == 0:  # a store that could not be made (a full disk) is already gone, or never written
        return
    with Store(path, create=False) as store:
        empty = not any(store.units(name, scale) for name, scale, *_ in store.experiments())
    if empty and keep_file:
        os.truncate(path, 0)
    elif empty:
        path.unlink(missing_ok=True)


def cmd_results(args: argparse.Namespace) -> int:
    """Export an experiment's finished units from the results store as CSV or JSON."""
    from ..experiments import Store, export_results
    from ..paths import input_file, output_file, sole_writer, writing

    refuse_sqlite_name(args.store, "--store")  # before "no such results store" (T32-A02)
    input_file(args.store, "--store", "results store")
    args.name = shipped_name(args.name)  # table3 as reproduce takes it: fig2 (T37-A05)
    fmt = _results_format(args.format, args.out)  # before output_file makes --out's directory
    kind = f"a results export (results --format {fmt})"  # never over another kind's file: compete's episodes.csv (T25-12)
    suffixes, what = (".csv", ".json"), "results are written as CSV or JSON"  # CSV over flight data, JSON over a policy (T25-02)
    out = (
        None
        if args.out is None
        else output_file(args.out, "--out", {"--store": args.store}, stdout=True, kind=kind, suffixes=suffixes, what=what, run_files=True)
    )
    with contextlib.ExitStack() as held:
        if out is not None:  # one of two runs at once was lost, both saying they wrote it (T41-A02)
            held.enter_context(sole_writer(out, "--out"))
        with Store(args.store, create=False) as store:
            text = export_results(store, args.name, fmt, args.scale)
        if out is not None:
            with writing(out, "--out") as path:
                path.write_text(text, encoding="utf-8")  # the locale's encoding wrote escapes or failed (T31-A05)
    if out is not None:
        print(f"wrote {printable(args.out)}", file=sys.stderr)
    else:
        sys.stdout.write(text)
    return 0


def _results_format(given: str | None, out) -> str:
    """--format, or the one --out's .csv/.json suffix names (else csv); a suffix that names the other format refused (CSV
    was written into r2.json without a word; twelfth trial, S2)."""
    suffix = "" if out is None else Path(out).suffix.lower().lstrip(".")
    named = suffix if suffix in ("csv", "json") else None
    if given is not None and named is not None and given != named:
        raise NeurohoverError(f"--format {given} is not allowed beside --out {brief(str(out))}, whose name says {named}: give one that agrees")
    return given or named or "csv"


def _positive_ints(text: str, option: str) -> list[int]:
    try:
        values = [integer(v) for v in text.split(",")]
    except FloatRangeError as err:  # more digits than Python reads (T53-A02)
        raise NeurohoverError(f"{option} {err}; give whole numbers >= 1, comma-separated (e.g. 1,5,20)") from None
    except ValueError:
        values = []
    if not values or min(values) < 1:
        raise NeurohoverError(f"{option} {text!r} is not allowed: give whole numbers >= 1, comma-separated (e.g. 1,5,20)")
    if len(set(values)) != len(values):  # a column printed twice (second trial)
        raise NeurohoverError(f"{option} {text!r} names a number twice: give each once")
    return values


def stored_scale(text: str) -> str:
    """``--scale`` of wins, results and report: a stored scale's name ('' read as none given and said the store held no
    experiment it then listed; seventeenth trial, T17-10)."""
    if text.strip() == "":
        raise argparse.ArgumentTypeError(f"{text!r} is not allowed: give quick, paper or a compete run's settings-HASH")
    return text


def cmd_wins(args: argparse.Namespace) -> int:
    """Each agent's probability of winning a competition of N runs against the others, simulated from an
    experiment's stored test runs (neurohover.experiments.wins: the bootstrap over the MDPs every agent
    flew, one stored run per agent and MDP, ties sharing the win), so the agent or risk level to enter
    can be chosen for N. With --against LABEL, each agent against that one alone."""
    from ..experiments import Store
    from ..experiments.export import checked_units, resolve_scale
    from ..experiments.wins import one_agent, several_groups, stored_runs, win_probabilities
    from ..paths import input_file

    refuse_sqlite_name(args.store, "--store")  # before "no such results store" (T32-A02)
    input_file(args.store, "--store", "results store")
    lengths = _positive_ints(args.runs, "--runs")
    args.name = shipped_name(args.name)  # table3: fig2 (T37-A05)
    with Store(args.store, create=False) as store:
        scale = resolve_scale(store, args.name, args.scale)
        config, units, _ = checked_units(store, args.name, scale)  # results' check: a unit of kind 'bogus' was a test run here (T19-05)
        runs = stored_runs({u["key"]: u["result"] for u in units})
        groups = config.settings.get("groups", [])
        comparable = several_groups(store) if len(runs) == 1 else []
    planned = {g.get("label") for g in groups if isinstance(g, dict)} if isinstance(groups, list) else set()
    foreign = sorted(set(runs) - planned)
    if foreign:  # a unit of no planned group was entered as an agent (sixth trial)
        where = f"results store {str(args.store)!r}"
        raise NeurohoverError(f"{where} is damaged: it holds test runs of group {foreign[0]!r}, which {args.name} ({scale}) does not plan")
    if not runs:
        raise NeurohoverError(f"experiment {args.name!r} ({scale}) has no stored test runs: wins compares the agents of a test-runs experiment")
    if len(runs) == 1:  # every compete experiment: "a competition needs at least two agents, got ['baseline']" (T34-A03)
        raise NeurohoverError(one_agent(args.name, scale, next(iter(runs)), comparable))
    for option, value in (("--agents", args.agents), ("--against", args.against)):  # '' entered every agent (second trial)
        if value is not None and not all(p.strip() for p in value.split(",")):  # named alone: the other may not have been given (fifth trial)
            raise NeurohoverError(f"{option} {value!r}: an agent's label is empty; allowed {', '.join(runs)}")
    # spaces around a label are no part of it (a group's label holds none), as --runs reads "1, 5": "a, b" was refused (T58-A02)
    chosen = [a.strip() for a in args.agents.split(",")] if args.agents else list(runs)
    args.against = args.against and args.against.strip()
    for label in [*chosen, *([args.against] if args.against else [])]:
        if label not in runs:
            raise NeurohoverError(f"agent {label!r} has no test runs in {args.name!r} ({scale}): allowed {', '.join(runs)}")
    if len(set(chosen)) != len(chosen):
        raise NeurohoverError(f"--agents {args.agents!r} names an agent twice: give each once")
    if len(chosen) == 1 and not args.against:  # "a competition needs at least two agents, got ['x']" (T34-A03)
        raise NeurohoverError(f"--agents {args.agents!r} names one agent: a competition needs two or more; give more of {', '.join(runs)}, or --against")
    others = ",".join(a for a in chosen if a != args.against)
    if args.against and args.agents and args.against in chosen and others:  # it was dropped from the table without a word (twelfth trial, S4)
        raise NeurohoverError(f"--against {args.against} is also in --agents {args.agents!r}: an agent is not compared with itself; give --agents {others}")
    if args.against:
        fields = {a: {args.against: runs[args.against], a: runs[a]} for a in chosen if a != args.against}
        if not fields:
            raise NeurohoverError(f"--against {args.against} leaves no other agent to compare with it: give --agents others of {', '.join(runs)}")
    else:
        fields = {"all": {a: runs[a] for a in chosen}}
    rows = []
    for field in fields.values():
        odds = {n: win_probabilities(field, n, draws=args.draws, seed=args.seed) for n in lengths}
        for agent in field:
            if args.against and agent == args.against:
                continue
            rows.append({"agent": agent, "mdps": odds[lengths[0]].mdps, **{str(n): odds[n][agent] for n in lengths}})
    if args.json:
        print(json.dumps({"experiment": args.name, "scale": scale, "against": args.against, "draws": args.draws, "seed": args.seed, "rows": rows}, indent=1))
        return 0
    what = f"against {args.against} alone" if args.against else "against the others"
    draws = f"{args.draws:,} simulated competition{'' if args.draws == 1 else 's'}"  # not "1 simulated competitions" (trial 32)
    print(f"{args.name} ({scale}): probability of winning a competition of N runs {what} ({draws})")
    width = max(len(r["agent"]) for r in rows)
    print(f"{'agent':<{width}}  MDPs  " + "  ".join(f"{'N = ' + str(n):>8}" for n in lengths))
    for r in rows:
        print(f"{r['agent']:<{width}}  {r['mdps']:>4}  " + "  ".join(f"{r[str(n)]:>8.1%}" for n in lengths))
    return 0


def cmd_report(args: argparse.Namespace) -> int:
    """Draw the paper's figures from the results store and write a Markdown report beside the paper's numbers."""
    from ..experiments import Store, write_report
    from ..experiments.export import orphan_message
    from ..experiments.report import check_names
    from ..paths import input_file, output_dir

    refuse_sqlite_name(args.store, "--store")  # before "no such results store" (T32-A02)
    input_file(args.store, "--store", "results store")
    check_names(args.names or None)  # before anything is opened or made (T23-18)
    args.names = [shipped_name(n) for n in args.names] if args.names else args.names  # table3: fig2 (T37-A05)
    with Store(args.store, create=False) as store:
        held = {n for n, s, _, _ in store.experiments() if args.scale is None or s == args.scale}
        missing = [n for n in args.names or () if n not in held]
        # units of an experiment that has no config row to report them under (T21-15; those of one reported are its section's damage)
        asked = [o for o in store.orphan_units() if (args.scale is None or o[1] == args.scale) and (not args.names or o[0] in args.names)]
        orphans = [o for o in asked if o[0] not in held]
        if orphans and (missing or not held):  # asked for, or all there is: refused before --out is made
            raise NeurohoverError(orphan_message(store, *orphans[0]))
        for o in orphans:
            print(f"neurohover report: warning: {o[0]} ({o[1]}) is not reported: {orphan_message(store, *o)}", file=sys.stderr)
        if missing:  # before --out is made: one line, not a directory made and removed around it (sixth trial)
            raise NeurohoverError(store.missing_message(missing[0], args.scale))
        if not held and args.scale is not None:  # a scale the store lacks, before --out is made too (eleventh trial)
            raise NeurohoverError(store.missing_message(None, args.scale))
        output_dir(args.out, "--out")
        path = write_report(store, args.out, scale=args.scale, names=args.names or None, refuse_all_damaged=True)  # exit 2 (T19-07)
    print(f"report written to {printable(path)}")
    return 0


def register(sub) -> None:
    p = sub.add_parser("reproduce", help="run a paper experiment into a results store", description=cmd_reproduce.__doc__)
    from ..experiments.config import experiment_names

    p.add_argument("name", nargs="?", help=f"experiment ({', '.join(experiment_names())}), 'all', or a .toml config")
    p.add_argument("--scale", choices=("quick", "paper"), default="quick", help="quick (minutes; the default) or paper (the paper's protocol)")
    p.add_argument("--store", help="results store file (SQLite; created if missing; finished units are skipped)")
    p.add_argument("--executor", choices=("local", "ray"), default="local", help="local processes (default) or a Ray cluster")
    p.add_argument("--address", help="Ray cluster address (default: start a local Ray instance)")
    p.add_argument("--jobs", type=integer, default=1, help="local worker processes (default 1: this process, kernel on all cores)")
    p.add_argument(
        "--device",
        choices=DEVICES,
        default="cpu",
        help="where the units fly: cpu (default) or cuda, an NVIDIA GPU (evolve, robustness, safety and model units; "
        "test runs stay on the CPU); not part of the config: results agree to about 1e-12 relative (docs/gpu.md)",
    )
    p.add_argument("--set", action="append", metavar="KEY=VALUE", help="override a setting of the config (TOML value), e.g. --set episodes=50")
    p.add_argument(
        "--only",
        action="append",
        metavar="PATTERN",
        help="run only the units whose keys match this glob (repeatable), e.g. 'run/hybrid/*/rep0': '*' and '?' match within one part of a key "
        "(not across '/', as a group label may hold one), '**' across parts; the policies they fly are always made",
    )
    p.add_argument("--fresh", action="store_true", help="discard the experiment's stored results at this scale first")
    p.add_argument(
        "--update",
        action="store_true",
        help="the config changed: keep the stored units it plans with the same key, kind and params (seed included), run the others",
    )
    p.add_argument("--progress", action=argparse.BooleanOptionalAction, default=None, help="progress bar (default: when stderr is a terminal)")
    p.add_argument("--list", action="store_true", help="list the experiments and exit")
    p.set_defaults(func=cmd_reproduce)

    p = sub.add_parser("results", help="export an experiment's results as CSV or JSON", description=cmd_results.__doc__)
    p.add_argument("name", help="experiment name")
    p.add_argument("--store", required=True, help="results store file")
    p.add_argument(
        "--scale", metavar="SCALE", type=stored_scale, help="which scale: quick, paper or a compete run's settings-HASH (needed when the store holds several)"
    )
    p.add_argument(
        "--format",
        choices=("csv", "json"),
        help="csv: one row per unit, one plain value per cell (a long list as its count and mean); json: every unit in full "
        "(default: what --out's suffix names, else csv; a suffix naming the other is refused)",
    )
    p.add_argument("--out", help="output file, its name ending .csv or .json (default: standard output)")
    p.set_defaults(func=cmd_results)

    p = sub.add_parser("wins", help="each agent's odds of winning an N-run competition, from stored test runs", description=cmd_wins.__doc__)
    p.add_argument("name", help="experiment name (a test-runs experiment of two or more groups; a compete experiment holds one agent)")
    p.add_argument("--store", required=True, help="results store file")
    p.add_argument("--scale", metavar="SCALE", type=stored_scale, help="which scale: quick or paper (needed when the store holds several)")
    p.add_argument("--runs", default="1,5,20", help="competition lengths N, comma-separated (default 1,5,20)")
    p.add_argument("--agents", help="group labels to enter, comma-separated (default: every group of the experiment)")
    p.add_argument("--against", metavar="LABEL", help="each agent against this group alone (head to head); not also one of --agents")
    p.add_argument("--draws", type=integer, default=10_000, help="simulated competitions (default 10000)")
    p.add_argument("--seed", type=integer, default=0, help="seed of the bootstrap (default 0)")
    p.add_argument("--json", action="store_true", help="print JSON")
    p.set_defaults(func=cmd_wins)

    p = sub.add_parser("report", help="draw the figures and write report.md from a results store", description=cmd_report.__doc__)
    p.add_argument("names", nargs="*", help="experiments to include (default: all in the store)")
    p.add_argument("--store", required=True, help="results store file")
    p.add_argument("--out", required=True, help="output directory")
    p.add_argument(
        "--scale", metavar="SCALE", type=stored_scale, help="only this scale: quick, paper or a compete run's settings-HASH (default: every scale in the store)"
    )
    p.set_defaults(func=cmd_report)
