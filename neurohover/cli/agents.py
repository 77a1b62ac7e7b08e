"""Commands of the on-line stage: ``build-policies`` and ``compete``."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ..errors import NeurohoverError
from ..evaluate import DEVICES


def cmd_build_policies(args: argparse.Namespace) -> int:
    """Evolve a task family's generic and specialised policies (the agents' policy set)."""
    from ..paths import output_dir, printable
    from ..policysets import SHIPPED, build_policy_set, check_build, replaceable_set
    from ..tasks import get_task_family

    if args.budget < 1:
        raise NeurohoverError(f"--budget {args.budget} is out of range: allowed >= 1")
    if args.fghh_budget is not None and args.fghh_budget < 1:  # refused before the first run, not after it
        raise NeurohoverError(f"--fghh-budget {args.fghh_budget} is out of range: allowed >= 1")
    check_build(get_task_family(args.task), args.lineage, args.fghh_budget, args.optimizer, budget=args.budget, seed=args.seed, n_steps=args.episode_steps)
    final = replaceable_set(args.task, args.out)
    output_dir(args.out, "--out")  # made once every option is checked
    if final.exists():  # said before hours of work replace it (a set in --out was replaced without a word; fourth trial)
        whose = "the package's shipped set" if final.resolve().parent == SHIPPED.resolve() else "the set"
        print(f"neurohover build-policies: note: {whose} {printable(final)} is replaced once the build completes", file=sys.stderr)
    ps = build_policy_set(
        args.task,
        args.out,
        budget=args.budget,
        seed=args.seed,
        n_steps=args.episode_steps,
        fghh_budget=args.fghh_budget,  # None: the default, where it applies (build_policy_set refuses it elsewhere)
        lineage=args.lineage,
        optimizer=args.optimizer,
        progress=lambda msg: print(msg, file=sys.stderr, flush=True),
    )
    print(f"policy set written to {printable(ps.directory)}")  # names escaped as messages show them (fourteenth trial, T14-24)
    return 0


def _named_out(err: NeurohoverError) -> NeurohoverError:
    """``err`` of compete(), naming its directory as the command's --out where it names the API's parameter ``out`` (its
    path follows, as repr() or brief() shows it: a dangling link as --out said "out 'd6' is a symbolic link"; trial 45),
    and its store as --store where it names ``store`` (a store among compete's own files in --out; T60-A01)."""
    said = str(err)
    if said.startswith(("out '", 'out "', "store '", 'store "')):
        err.args = ("--" + said, *err.args[1:])
    return err


def cmd_compete(args: argparse.Namespace) -> int:
    """Run R independent test runs of an agent; print a summary and write results and a plot."""
    from ..agents.hybrid import HybridSettings
    from ..agents.model_based import ModelEvolution
    from ..agents.registry import HYBRID_AGENTS, agent_spec, usable_agents
    from ..compete import agents_with_settings, check_sizes, compete
    from ..filekinds import refuse_long_store_name
    from ..paths import checked_path, input_dir, output_file, printable
    from ..tasks import Drift
    from .options import check_given, given_settings, sensor_of

    spec = agent_spec(args.agent, args.task)  # an unknown agent, or one for another task, before anything else is read or made
    given = [o.flag for o in args.hybrid_options if getattr(args, o.dest) is not None]
    if given and args.agent not in HYBRID_AGENTS:
        own = args.agent in agents_with_settings()
        raise NeurohoverError(
            f"{', '.join(given)} appl{'ies' if len(given) == 1 else 'y'} to the hybrid agents only ({', '.join(HYBRID_AGENTS)}), not to --agent {args.agent}"
            + (f" (its own settings are --agent-setting KEY=VALUE: neurohover settings {args.agent})" if own else "")
        )
    hybrid = HybridSettings.from_dict(given_settings(args, args.hybrid_options))  # the option's field names are its keys
    model = given_settings(args, args.model_options)
    for option in args.model_options:
        if option.field in model and not spec.learns_models:
            learners = ", ".join(name for name, s in usable_agents().items() if s.learns_models)
            raise NeurohoverError(f"{option.flag} applies to the agents that learn models ({learners}), not to --agent {args.agent}")
        if option.field in model and option.field in spec.idle_model_options:  # taken and ignored (T40-A03)
            takers = ", ".join(n for n, s in usable_agents().items() if s.learns_models and option.field not in s.idle_model_options)
            raise NeurohoverError(
                f"{option.flag} applies to the agents that evolve policies on their models as it says ({takers}), not to --agent "
                f"{args.agent}, which would ignore it (its evolution on the model is always its own); leave it out"
            )
    check_given(ModelEvolution, model, args.model_options)
    wind_model = str(model.pop("wind_model", "none"))
    check_sizes(args.runs, args.episodes)
    sensor = sensor_of(args)
    drift = None if args.drift is None else Drift.parse(args.drift)
    if drift is not None:
        drift.check_run(args.episodes, f"--drift {args.drift!r} with --episodes {args.episodes}", at_given="@" in args.drift)  # named by its options
    agent_settings = None
    if args.agent_setting:
        from ..compete import check_agent_settings
        from ..experiments.config import parse_overrides

        agent_settings = check_agent_settings(args.agent, parse_overrides(args.agent_setting, "--agent-setting"), args.episode_steps)
    if args.policy_dir is not None:
        if not spec.needs:  # it flies no policy of a set: the option would be ignored (second trial)
            raise NeurohoverError(f"--policy-dir applies to agents that fly a policy set's policies, not to --agent {args.agent}")
        input_dir(args.policy_dir, "--policy-dir")
    if args.store is not None:
        refuse_long_store_name(args.store, "--store")  # its -journal too (T31-A03)
        output_file(args.store, "--store", store=True)  # --out is made by compete once it has checked every setting
    checked_path(args.out, "--out", "directory path")  # named as typed: compete() calls it out (eleventh trial, U8)
    try:
        summary, _ = compete(
            args.task,
            args.agent,
            runs=args.runs,
            episodes=args.episodes,
            mdps=args.mdps,
            seed=args.seed,
            jobs=args.jobs,
            out=args.out,
            sigma=args.sigma,
            n_steps=args.episode_steps,
            policy_dir=args.policy_dir,
            hybrid=hybrid,
            store=args.store,
            progress=None,
            device=args.device,
            sensor=sensor,
            drift=drift,
            wind_model=wind_model,
            lr_fit=model,  # d_u, noise, model_policy, model_substeps where given (ModelEvolution checks them)
            agent_settings=agent_settings,
        )
    except NeurohoverError as err:
        raise _named_out(err) from None
    except KeyboardInterrupt as stop:
        from ..compete import FINISHED_RUNS
        from ..procs import stop_words

        how, status = stop_words(stop)
        finished = getattr(stop, FINISHED_RUNS, None)  # None: stopped before or after the runs, no file to name
        if finished:
            runs = "its 1 finished run is" if finished == 1 else f"its {finished} finished runs are"
            said = f"{runs} in {printable(Path(args.out) / 'episodes.csv')} and the results store; run the same command again to resume"
        elif finished == 0:  # it named an episodes.csv that was never written (T26-A08)
            said = "no run had finished; run the same command again to start"
        else:
            said = "run the same command again to resume"
        print(f"neurohover compete: {how}; {said}", file=sys.stderr)
        return status
    print(f"{'agent':<18} {'runs':>5} {'mean cum. return':>17} {'sd':>12} {'crash rate':>11} {'return/ep after learning':>25}")
    print(
        f"{summary['agent']:<18} {summary['runs']:>5} {summary['mean_cumulative_return']:>17.5g} {summary['sd_cumulative_return']:>12.4g} "
        f"{summary['crash_rate_runs']:>11.1%} {summary['mean_return_after_learning']:>25.5g}"
    )
    out = printable(Path(args.out))  # a newline or U+202E in --out split or reversed the line (fourteenth trial, T14-24); 'k/' as 'k'
    print(f"results: {out}/episodes.csv, {out}/summary.json, {out}/cumulative.png; store: {printable(summary['store'])}")
    return 0


def register(sub) -> None:
    from ..agents.hybrid import HybridSettings
    from ..agents.model_based import ModelEvolution
    from ..agents.registry import usable_agents
    from ..compete import LR_FIT_KEYS
    from ..evaluate import DangerousState
    from ..evolution.optimisers import optimiser_names
    from ..models.model import default_model_substeps
    from ..policysets import FGHH_POLICY_BUDGET, POLICY_BUDGET
    from .options import add_sensor_options, add_setting_options, add_sigma_option, add_task_option, integer

    p = sub.add_parser("build-policies", help="evolve the generic and specialised policies of a task", description=cmd_build_policies.__doc__)
    add_task_option(p)
    p.add_argument(
        "--out",
        required=True,
        help="directory to write <task>/ into (neurohover/data/policies, the package's own, rebuilds the shipped set)",
    )
    p.add_argument("--budget", type=integer, default=POLICY_BUDGET, help=f"episodes per steady-state evolution (default {POLICY_BUDGET})")
    p.add_argument("--fghh-budget", type=integer, help=f"fghh only: episodes per generic-policy evolution over G (default {FGHH_POLICY_BUDGET})")
    p.add_argument("--episode-steps", type=integer, default=6000, help="control steps per episode (default 6000)")
    p.add_argument("--seed", type=integer, default=0)
    p.add_argument(
        "--lineage",
        help="GHH-08/09 only: chain (default: every run seeded from an ancestor evolved over the training MDPs in turn, as the authors' policies were) "
        "or independent (every run from the baseline policy)",
    )
    p.add_argument(
        "--optimizer",
        "--optimiser",
        choices=optimiser_names(),
        default="ne",
        help="ne (default: the paper's neuroevolution) or a population optimiser for the runs on one MDP and FGHH's fixed generic",
    )
    p.set_defaults(func=cmd_build_policies)

    p = sub.add_parser("compete", help="run test runs of an on-line agent", description=cmd_compete.__doc__)
    add_task_option(p)
    p.add_argument("--agent", required=True, help="; ".join(f"{name} ({', '.join(spec.tasks)}): {spec.summary}" for name, spec in usable_agents().items()))
    p.add_argument("--runs", type=integer, default=10, help="independent test runs (default 10)")
    p.add_argument("--episodes", type=integer, default=1000, help="episodes per run (default 1000)")
    p.add_argument("--mdps", default="test", help="test (the fixed test MDPs in turn), sample (fresh from G) or train")
    add_sigma_option(p)
    add_sensor_options(p)
    p.add_argument(
        "--drift",
        help="drifting dynamics over each run (docs/benchmarks.md): walk=STD (a log random walk of the 11 dynamics parameters per episode) "
        "and/or PARAM=FACTOR@LO-HI (an abrupt change at an episode drawn from LO..HI), e.g. D_w=0.8@200-800",
    )
    p.add_argument("--seed", type=integer, default=0)
    p.add_argument("--jobs", type=integer, default=1, help="runs in parallel processes (default 1)")
    p.add_argument(
        "--device",
        choices=DEVICES,
        default="cpu",
        help="where the units' episodes fly: cpu (default) or cuda (docs/gpu.md; the agents' test runs themselves still fly on the CPU)",
    )
    p.add_argument("--episode-steps", type=integer, default=6000, help="control steps per episode (default 6000)")
    p.add_argument("--policy-dir", help="policy sets directory (default: the shipped ones)")
    p.add_argument("--out", required=True, help="output directory (episodes.csv, summary.json, cumulative.png, results.sqlite)")
    p.add_argument("--store", help="results store to keep the runs in (default: OUT/results.sqlite); finished runs are not flown again")
    model_options = add_setting_options(
        p,
        ModelEvolution,
        ("wind_model", *LR_FIT_KEYS),
        flags={"noise": "noise-estimate"},
        who="model-based agents",
        default_text={"model_substeps": f"{default_model_substeps('ghh08')} on GHH-08/09, {default_model_substeps('fghh')} on FGHH"},
    )
    p.add_argument(
        "--agent-setting",
        action="append",
        metavar="KEY=VALUE",
        help='one of the agent\'s own settings (repeatable; VALUE in TOML syntax), e.g. --agent hybrid-risk --agent-setting criterion="lcb" '
        "--agent-setting level=3, --agent continual --agent-setting cooldown=10, or --agent incremental --agent-setting max_learning_episodes=10 "
        "(neurohover settings AGENT lists them; the hybrid agents' are the --safeguard-*/--hybrid-* options; docs/model.md, docs/benchmarks.md)",
    )
    g = p.add_argument_group("hybrid agents (defaults: the authors' code; see docs/model.md, Safeguard)")
    hybrid_options = add_setting_options(g, DangerousState, ("rule", "box", "tilt"), prefix="safeguard-")
    hybrid_options += add_setting_options(g, HybridSettings, ("replacement", "model_from"), prefix="hybrid-")
    p.set_defaults(model_options=model_options, hybrid_options=hybrid_options)  # the generated options, for cmd_compete
    p.set_defaults(func=cmd_compete)
