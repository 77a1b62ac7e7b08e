"""``neurohover evaluate-agent``: any trained policy flown as the paper measured its agents, beside the baseline and
the shipped generic on the same gusts (:func:`neurohover.integrations.flying.compare_agent`).

- ``neurohover evaluate-agent --task ghh08 (--policy FILE | --callable MODULE:FUNCTION | --rl-zoo RUN | --sb3 MODEL.zip | --cleanrl RUN)
  [--algo ppo] [--rl-id] [--mdps test|train] [--n-mdps N] [--episodes E] [--seed S] [--episode-steps N] [--json FILE]``
"""

from __future__ import annotations

import argparse
import contextlib
import importlib
import json
import os
import sys
from collections.abc import Iterator
from pathlib import Path

from ..errors import NeurohoverError
from ..integrations import SB3_ALGORITHMS
from ..paths import printable
from ..policies import Policy
from ..sim.constants import MAX_EPISODE_STEPS
from .options import add_sensor_options, add_sigma_option, add_task_option, integer, note_policy_name, note_policy_task, task_family_of

SOURCES = ("policy", "callable", "rl_zoo", "sb3", "cleanrl")


def _reported(fn, spec: str):
    """``fn`` whose failure (a wrong signature, an exception of its own) is one clear message naming it, not a traceback."""

    def act(observations):
        try:
            return fn(observations)
        except (Exception, SystemExit) as err:  # the user's code: what it raised (a sys.exit(0) was the command's silent success; twelfth trial S1)
            raise NeurohoverError(
                f"--callable {spec!r} raised {type(err).__name__}: {err} when called with a batch of observations, an array of shape "
                f"{getattr(observations, 'shape', '?')}: it must take one such array and return actions of shape (B, 4)"
            ) from None

    return act


def _agent(args: argparse.Namespace):
    """The agent of the one source given: a policy file's policy (flown in the kernel), or a batch function
    (observations -> actions)."""
    given = [s for s in SOURCES if getattr(args, s) is not None]
    if len(given) != 1:
        named = ", ".join("--" + s.replace("_", "-") for s in given) or "none"
        raise NeurohoverError(f"give exactly one of --policy, --callable, --rl-zoo, --sb3, --cleanrl (the agent to fly); got {named}")
    if args.algo is not None and args.rl_zoo is None and args.sb3 is None:  # ignored otherwise (second trial)
        raise NeurohoverError(f"--algo {args.algo} applies to --rl-zoo and --sb3 models, not to --{given[0].replace('_', '-')}")
    algo = args.algo or "ppo"
    if args.policy is not None:
        from ..paths import input_file
        from ..policies import load_policy

        if args.policy == "baseline":  # the name load_policy takes wherever a policy file is taken (README)
            note_policy_name(args.policy, "--policy")
            return load_policy("baseline")
        return load_policy(input_file(args.policy, "--policy", "policy file"))
    if args.callable is not None:
        module, _, name = args.callable.partition(":")
        if not module or not name:
            raise NeurohoverError(f"--callable {args.callable!r} is not allowed: give MODULE:FUNCTION (e.g. my_agents:act), importable from here or sys.path")
        try:
            with _working_directory_on_path():
                fn = getattr(importlib.import_module(module), name)
        except (ImportError, AttributeError) as err:
            raise NeurohoverError(f"--callable {args.callable!r}: {err}") from None
        except SyntaxError as err:  # a module that does not compile is named, as a missing one is
            raise NeurohoverError(f"--callable {args.callable!r}: SyntaxError: {err}") from None
        except (Exception, SystemExit) as err:  # its own code at import: a traceback, or sys.exit(0) a silent success (twelfth trial S1)
            raise NeurohoverError(f"--callable {args.callable!r}: importing {module} raised {type(err).__name__}: {err}") from None
        if not callable(fn):
            raise NeurohoverError(f"--callable {args.callable!r} is not a function")
        return _reported(fn, args.callable)
    if args.cleanrl is not None:
        from ..integrations.cleanrl import cleanrl_policy

        return cleanrl_policy(args.cleanrl)
    from ..integrations.sb3_files import rl_zoo_files, sb3_model_file
    from ..paths import input_dir, input_file

    if args.rl_zoo is not None:
        input_dir(args.rl_zoo, "--rl-zoo")  # the path before the library: a typo read as "SB3 is not installed" (third trial)
        sb3_model_file(rl_zoo_files(args.rl_zoo, algo)[0])  # and what it holds: a folder of no run likewise (T38-A05)
        from ..integrations.sb3 import rl_zoo_policy

        return rl_zoo_policy(args.rl_zoo, algo=algo)
    if not Path(f"{args.sb3}.zip").is_file():  # SB3's load adds .zip to a name without it
        sb3_model_file(input_file(args.sb3, "--sb3", "SB3 model file (.zip)"))  # a policy file was "needs stable_baselines3" (T38-A05)
    from ..integrations.sb3 import sb3_policy

    return sb3_policy(args.sb3, algo=algo)


@contextlib.contextmanager
def _working_directory_on_path() -> Iterator[None]:
    """The working directory first on the import path while --callable's module imports, as ``python -m`` has it: the
    ``neurohover`` script's path starts with its own folder, and the documented ``--callable my_agents:act`` beside
    the user's my_agents.py was "No module named 'my_agents'" (T38-A03)."""
    try:
        here = os.getcwd()
    except OSError:  # a removed working directory: nothing to import from it
        here = ""
    added = bool(here) and here not in sys.path
    if added:
        sys.path.insert(0, here)
    try:
        yield
    finally:
        if added and here in sys.path:
            sys.path.remove(here)


def _files_read(args: argparse.Namespace) -> dict[str, str | Path | None]:
    """Every file the agent was read from (option -> path), once it is loaded: --json onto an RL Zoo run's model or
    statistics, a CleanRL run's files or the --callable's module overwrote them (ninth trial)."""
    files: dict[str, str | Path | None] = {"--policy": args.policy, "--sb3": args.sb3}
    if args.callable is not None:
        files["--callable"] = getattr(sys.modules.get(args.callable.partition(":")[0]), "__file__", None)
    if args.rl_zoo is not None:
        from ..integrations.sb3_files import rl_zoo_files

        files["--rl-zoo (its model)"], files["--rl-zoo (its statistics)"] = rl_zoo_files(args.rl_zoo, args.algo or "ppo")
    if args.cleanrl is not None:
        from ..integrations.cleanrl import cleanrl_files

        files["--cleanrl (its model)"], files["--cleanrl (its obs_rms.pkl)"] = cleanrl_files(args.cleanrl)
    return files


#: What evaluate-agent --json writes: refused over a neurohover file of another kind (a policy, a summary; T25-01).
ROWS_KIND, ROWS_ARE = "evaluate-agent rows (--json)", "evaluate-agent writes its rows as JSON"


def _generic_at_other_sigma(family) -> tuple[str, Policy] | None:
    """Why the ``generic`` row is no generic of ``family``'s sigma, and the shipped generic it flies, or None: the
    shipped FGHH generic was evolved over G at the set's sigma. Flown with this note (an evaluation, not a competition),
    where compete refuses the set (T29-A08)."""
    if not family.generic_over_distribution or family.sigma is None:
        return None
    from ..integrations.flying import generic_sigma_problem
    from ..policysets import load_policy_set

    shipped = load_policy_set(family.name)
    built = generic_sigma_problem(family, shipped.manifest.get("sigma"))  # make_agent's decision (T35-B07)
    if built is None:
        return None
    return (
        f"the generic row flies the shipped {family.name} generic, evolved for sigma = {built}, not {family.sigma} (the sigma of these MDPs): "
        "a reference only (compete refuses that set at this sigma)"
    ), shipped.generic


def cmd_evaluate_agent(args: argparse.Namespace) -> int:
    """Fly a trained policy on full paper episodes of a task's training or test MDPs, beside the competition's baseline
    and the shipped generic policy on the same gusts, and print the paper's measures (return per episode, crashes)."""
    with contextlib.ExitStack() as held:  # --json's writer lock, held until the command ends
        return _evaluate_agent(args, held)


def _evaluate_agent(args: argparse.Namespace, held: contextlib.ExitStack) -> int:
    from ..integrations.flying import compare_agent
    from ..paths import output_file, sole_writer, writing
    from ..progress import progress_bar

    family = task_family_of(args)  # with --obs-noise / --obs-delay every policy flies through those sensors
    available = len(family.training_mdps() if args.mdps == "train" else family.test_mdps())
    n = available if args.n_mdps is None else args.n_mdps
    if not 1 <= n <= available:
        raise NeurohoverError(f"--n-mdps {n} is out of range: allowed 1..{available} ({args.task} has {available} {args.mdps} MDPs)")
    for option, value, low, high in (("--episodes", args.episodes, 1, 10**4), ("--episode-steps", args.episode_steps, 1, MAX_EPISODE_STEPS)):
        if not low <= value <= high:
            raise NeurohoverError(f"{option} {value} is out of range: allowed an integer in {low}..{high}")
    inputs = {"--policy": args.policy, "--sb3": args.sb3}  # writing one would destroy what is flown (fourth trial)
    out = None if args.json is None else output_file(args.json, "--json", inputs, kind=ROWS_KIND, suffixes=(".json",), what=ROWS_ARE)
    if out is not None:  # absolute before the agent's code runs: its os.chdir sent the file elsewhere and left the lock (T48-A03)
        out = Path(os.path.abspath(out))
    if args.obs_dtype is not None and args.policy is not None:  # the kernel flies a policy file on float64: ignored (fifth trial)
        raise NeurohoverError("--obs-dtype applies to an agent that receives observations (--callable, --sb3, --rl-zoo, --cleanrl), not to a --policy file")
    if args.rl_id and args.policy is not None:
        raise NeurohoverError("--rl-id applies to an agent trained on a neurohover/<NAME>-RL-v0 id, not to a neurohover --policy file")
    act = _agent(args)
    if out is not None:
        output_file(out, "--json", _files_read(args), kind=ROWS_KIND, suffixes=(".json",), what=ROWS_ARE)
        held.enter_context(sole_writer(out, "--json", args.json))  # one of two runs at once was lost, both saying they wrote it (T41-A02)
    if isinstance(act, Policy):
        note_policy_task(act, family.name, f"--policy {args.policy}")
    if args.rl_id or (args.rl_zoo is not None and "-RL-v0" in str(args.rl_zoo)):
        from ..envs.rl import rl_policy

        act = rl_policy(act, family.name)
    mdps = [family.mdp(f"{args.mdps}:{i}") for i in range(n)]
    # the agent's flight (a kernel policy flies in one call: no steps to count), on a terminal only
    quiet = True if isinstance(act, Policy) else None
    note, generic = _generic_at_other_sigma(family) or (None, None)
    with progress_bar(total=args.episode_steps, desc="agent's episodes", unit="step", disable=quiet, dynamic_ncols=True) as bar:
        rows = compare_agent(  # at another sigma the shipped generic flies as a reference, with the note below
            act, mdps, episodes=args.episodes, seed=args.seed, n_steps=args.episode_steps, obs_dtype=args.obs_dtype, on_step=lambda: bar.update(1),
            generic=generic,
        )  # fmt: skip
    print(f"{args.task} {family.set_name(args.mdps)} MDPs 0-{n - 1}, {args.episodes} episode(s) each of {args.episode_steps} steps, gusts of seed {args.seed}:")
    print(f"{'policy':<10} {'return/episode':>15} {'median over MDPs':>17} {'crashed':>12}")
    for r in rows:
        print(f"{r.name:<10} {r.return_per_episode:>15.6g} {r.median_over_mdps:>17.6g} {f'{r.crashes} of {r.episodes}':>12}")
    if note is not None:
        print(f"neurohover evaluate-agent: note: {note}", file=sys.stderr)
    if out is not None:
        with writing(out, "--json") as path:
            path.write_text(json.dumps({"task": args.task, "mdps": family.set_name(args.mdps), "n_mdps": n, "episodes": args.episodes, "seed": args.seed,
                                        "episode_steps": args.episode_steps, "rows": [r.__dict__ for r in rows]}, indent=1), encoding="utf-8")  # fmt: skip
        print(f"wrote {printable(args.json)}", file=sys.stderr)
    return 0


def register(sub) -> None:
    p = sub.add_parser(
        "evaluate-agent",
        help="fly a trained policy as the paper measured its agents, beside the baseline and the generic",
        description=cmd_evaluate_agent.__doc__,
    )
    add_task_option(p)
    add_sigma_option(p)
    add_sensor_options(p)
    g = p.add_argument_group("the agent (exactly one)")
    g.add_argument("--policy", help="a neurohover policy file (.json or the competition's .net), or baseline")
    g.add_argument(
        "--callable", help="MODULE:FUNCTION mapping a batch of observations (B, 12) to actions (B, 4); MODULE from the working directory or sys.path"
    )
    g.add_argument("--rl-zoo", help="an RL Zoo run folder (logs/ALGO/ENV_N): its final model and frozen observation statistics")
    g.add_argument("--sb3", help="a Stable-Baselines3 model file (MODEL.zip)")
    g.add_argument("--cleanrl", help="a CleanRL ppo_continuous_action run folder (runs/RUN: its model and saved obs_rms.pkl)")
    p.add_argument("--algo", choices=tuple(SB3_ALGORITHMS), help="the algorithm of --rl-zoo / --sb3 (default ppo)")
    p.add_argument(
        "--rl-id",
        action="store_true",
        help="the agent learned on a neurohover/<NAME>-RL-v0 id: fly it through that id's observation and action scaling "
        "(automatic for an RL Zoo run folder of such an id)",
    )
    p.add_argument("--mdps", choices=("test", "train"), default="test", help="the task's test (default) or training MDPs")
    p.add_argument("--n-mdps", type=integer, help="the first N of them (default all)")
    p.add_argument("--episodes", type=integer, default=1, help="episodes per MDP (default 1)")
    p.add_argument("--seed", type=integer, default=0, help="gust seed: episode e on MDP m meets stream (seed, m * episodes + e)")
    p.add_argument("--episode-steps", type=integer, default=6000, help="control steps per episode (default 6000, the paper's)")
    p.add_argument("--obs-dtype", choices=("float32", "float64"), help="what an agent other than a --policy file receives (default float32)")
    p.add_argument("--json", help="also write the rows to this JSON file")
    p.set_defaults(func=cmd_evaluate_agent)
