"""Commands of the learning stage: ``evolve`` (policies) and ``learn-model`` (helicopter models).

``neurohover evolve`` writes three files for ``--out FILE``:

* ``FILE``: the champion as a policy file (JSON, docs/model.md, Policies) with metadata: task, mdp, sigma,
  optimizer, resampling, budget, seed, champion_return (on the scale champion_fitness_scale names:
  ``return``, or ``inv-log-error`` for generational runs, 1/ln(error)), validation_return (mean return of 10 fresh
  episodes: on the MDP, or each on a fresh MDP from G, independent of the evolution's episodes),
  validation_sd, episodes, seconds, stop_reason, ...;
* ``FILE.history.csv``: the run's history, columns
  ``generation,evaluations,episodes,generation_episodes,champion_return,wall_seconds``
  (see :class:`neurohover.evolution.evolve.HistoryRecord`: steady state, one line per new champion and one for the last
  generation; generational, one line per generation, ``generation_episodes`` being the episodes a race or fixed resampling spent on it);
* ``FILE.checkpoint.json``: the run's checkpoint (every ``--checkpoint-every`` seconds, at the end and on Ctrl-C), which
  ``--resume`` continues from, with its own budget unless ``--budget`` raises it.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import math
import sys
import threading
import time
import warnings
from pathlib import Path

import numpy as np

from ..errors import CheckpointReplaced, NeurohoverError, brief
from ..evaluate import DEVICES, check_device, check_episode_count
from ..evolution.config import MAX_BUDGET
from ..evolution.generational import GENERATIONAL_PRESETS
from ..evolution.optimisers import OPTIMISERS, optimiser_names
from ..evolution.records import EvolutionInterrupted
from ..paths import input_file, output_file, printable, sole_writer

MDP_FAMILY = "G"


def _target(args: argparse.Namespace):
    """(target, family, mdp for the metadata: what is flown, FGHH's seeded-test:0 for test:0 at sigma 0.2; T37-A01)."""
    from ..policies import record_problem
    from .options import explicit_mdp, refuse_sigma_on_zero, task_family_of

    family = task_family_of(args)
    explicit = explicit_mdp(args, family)
    spec = args.mdp if args.mdp is not None else (MDP_FAMILY if family.generic_over_distribution else "zero")
    if explicit is None:
        refuse_sigma_on_zero(args, spec)
        if spec == MDP_FAMILY:
            return family, family, MDP_FAMILY
        rng = np.random.default_rng(np.random.SeedSequence(args.seed, spawn_key=(4,)))  # "sample": one MDP from G, the run's seed
        explicit = (family.sample(rng, label=f"{family.name}/sample"), "sample") if spec == "sample" else (family.mdp(spec), family.set_name(spec))
    target, desc = explicit
    problem = record_problem({"task": family.name, "mdp": desc, "target": target.label, "mdp_params": target.to_dict()})
    if problem:  # refused before flying: after the whole budget, the run's work was lost (T37-A01)
        raise NeurohoverError(f"policy file {str(args.out)!r}: {problem} (load_policy would refuse the file; nothing is flown)")
    return target, family, desc


def _seed_policy(args: argparse.Namespace):
    from ..policies import load_policy
    from .options import note_policy_name

    if args.seed_policy in ("zero", "baseline"):
        note_policy_name(args.seed_policy, "--seed-policy", ("zero", "baseline"))
        return args.topology, args.seed_policy  # None: evolve's default (SLP over a family, MLP on one MDP)
    from ..paths import checked_path, input_file

    path = checked_path(args.seed_policy, "--seed-policy", "policy file (or zero, baseline)") if args.seed_policy else Path("")
    if args.seed_policy == "" or path.is_dir() or not path.exists():
        what = "is empty" if args.seed_policy == "" else ("is a directory" if path.is_dir() else "no such file")
        raise NeurohoverError(f"--seed-policy {args.seed_policy!r}: {what} (give zero, baseline or a policy file)")
    path = input_file(path, "--seed-policy", "policy file (or zero, baseline)")  # a FIFO was 'no such file', as fly --policy (T18-7)
    policy = load_policy(path)
    if args.topology is not None and args.topology != policy.topology:
        raise NeurohoverError(f"--seed-policy {args.seed_policy!r} is an {policy.topology} policy but --topology is {args.topology}")
    return policy.topology, policy


def _optimiser_settings(args: argparse.Namespace, over_family: bool) -> dict | None:
    """The optimiser settings of ``evolve`` from --plateau-rule, --preset and --setting (None: the defaults)."""
    from ..experiments.config import parse_overrides

    settings: dict = {}
    if args.plateau_rule is not None:
        if args.optimizer != "ne" or over_family:
            raise NeurohoverError(f"--plateau-rule {args.plateau_rule} applies to the steady-state method only (optimizer ne on one MDP)")
        settings["plateau_rule"] = args.plateau_rule
    if args.preset is not None:
        if args.optimizer != "ne" or not over_family:
            raise NeurohoverError(f"--preset {args.preset} names generational settings: it applies to evolution over a family (--mdp G, optimizer ne)")
        settings["preset"] = args.preset
    for key, value in parse_overrides(args.setting, "--setting").items():
        if key in settings:
            raise NeurohoverError(f"--setting {key}=... repeats --{key.replace('_', '-')}: give it once")
        settings[key] = value
    return settings or None


class _Bar:
    """tqdm progress bar on stderr (silent when stderr is not a terminal; :func:`~neurohover.progress.progress_bar`)."""

    def __init__(self, total: int | None, desc: str, note: str | None = None) -> None:
        from ..progress import progress_bar

        self.bar = progress_bar(total=total, desc=desc, unit="ep", dynamic_ncols=True)
        self.note = note  # said once the run is under way: a run refused at its start overwrites nothing

    def __call__(self, info) -> None:
        if self.note is not None:
            self.bar.write(self.note, file=sys.stderr)
            self.note = None
        if info.episodes > self.bar.n:
            self.bar.update(info.episodes - self.bar.n)
        champion = f"{info.champion_return:.5g}" if math.isfinite(info.champion_return) else "-"
        self.bar.set_postfix_str(f"evals={info.evaluations} champion={champion} {info.episodes_per_second:.0f} ep/s", refresh=False)

    def close(self) -> None:
        self.bar.close()


def _check_evolve_sizes(args: argparse.Namespace) -> None:
    """``evolve``'s sizes and device, refused before any file is touched."""
    if args.budget is not None and not 1 <= args.budget <= MAX_BUDGET:
        raise NeurohoverError(f"--budget {args.budget} is out of range: allowed an integer in 1..{MAX_BUDGET:,} (episodes)")
    if args.episode_steps < 1:
        raise NeurohoverError(f"--episode-steps {args.episode_steps} is out of range: allowed >= 1")
    if not args.checkpoint_every > 0:
        raise NeurohoverError(f"--checkpoint-every {args.checkpoint_every} is out of range: allowed > 0 seconds")
    if args.validation_episodes < 1:
        raise NeurohoverError(f"--validation-episodes {args.validation_episodes} is out of range: allowed >= 1")
    check_episode_count(args.validation_episodes, f"--validation-episodes {args.validation_episodes}")  # before the evolution, not after
    check_device(args.device)  # a GPU missing is one clear error


def _evolve_meta(args, family, target, mdp_desc: str, resampling, result, scale: str, validation, history_name: str) -> dict:
    """What the champion's policy file records about its run."""
    meta = {
        "task": family.name,  # (the sensor its run saw through is the champion's own record: Run.result)
        "mdp": mdp_desc,
        "optimizer": args.optimizer,
        "resampling": str(resampling),
        "settings": result.settings["settings"],
        "budget": args.budget,
        "seed": args.seed,
        "seed_policy": str(args.seed_policy),
        "champion_return": result.champion_return,
        "champion_fitness_scale": scale,
        "validation_return": float(validation.mean()),
        "validation_sd": float(validation.std()),
        "validation_episodes": int(validation.size),
        "episode_steps": args.episode_steps,
        "episodes": result.episodes,
        "evaluations": result.evaluations,
        "generations": result.generations,
        "seconds": round(result.seconds, 3),
        "stop_reason": result.stop_reason,
        "history": history_name,
    }
    if family.sigma is not None:
        meta["sigma"] = float(family.sigma)
    if mdp_desc != MDP_FAMILY:
        meta["mdp_params"] = target.to_dict()
    return meta


def _print_evolve_summary(args: argparse.Namespace, summary: dict, result) -> None:
    """The run's summary (a table or one JSON object), and a note when the run stopped before its budget."""
    if args.json:
        print(json.dumps(summary))
    else:
        for key, value in summary.items():
            print(f"{key:>20}: {value:.6g}" if isinstance(value, float) else f"{key:>20}: {printable(value) if isinstance(value, str) else value}")
    if args.budget is not None and result.stop_reason != "budget" and result.episodes < args.budget:
        why = " (steady state ends at the paper's plateau, 1000 evaluations without a new champion)" if result.stop_reason == "plateau" else ""
        print(
            f"neurohover evolve: note: stopped by {result.stop_reason} after {result.episodes:,} of the --budget {args.budget:,} episodes: the budget "
            "is a cap, not a length" + why,
            file=sys.stderr,
        )
    if args.budget is not None and result.episodes > args.budget:  # a generation (or the first population) is flown whole
        print(
            f"neurohover evolve: note: flew {result.episodes:,} episodes for the --budget {args.budget:,}: the run stops at the first "
            "generation boundary at or past its budget (its first population, or a generation, is flown whole)",
            file=sys.stderr,
        )


def cmd_evolve(args: argparse.Namespace) -> int:
    """Evolve a policy: steady state on one MDP, or generational over the task family's MDPs (--mdp G)."""
    with contextlib.ExitStack() as held:  # the output's writer lock, held until the command ends
        return _evolve_command(args, held)


def _evolve_command(args: argparse.Namespace, held: contextlib.ExitStack) -> int:
    from ..evolution.evolve import evolve, parse_resampling, validation_return, write_history_csv
    from ..evolution.records import CHECKPOINT_KIND, HISTORY_KIND
    from ..filekinds import RUN_FILE_ENDS
    from ..policies import check_json_policy_name, save_policy
    from .options import resumed_budget

    _check_evolve_sizes(args)
    check_json_policy_name(args.out, "--out", tuple(RUN_FILE_ENDS))  # before evolving (at the save, the run was lost): .json, not a run's checkpoint (T24-01)
    resampling = parse_resampling(args.resampling)
    target, family, mdp_desc = _target(args)
    topology, proto = _seed_policy(args)
    out = output_file(args.out, "--out", {"--seed-policy": args.seed_policy}, kind="a policy file", ends=tuple(RUN_FILE_ENDS))
    held.enter_context(sole_writer(out, "--out"))
    history_path = output_file(f"{out}.history.csv", "--out (its history file)", kind=HISTORY_KIND)
    checkpoint = output_file(f"{out}.checkpoint.json", "--out (its checkpoint file)", kind=CHECKPOINT_KIND)
    if args.resume:  # a missing checkpoint refused; --budget left out is the checkpoint's own budget (T44-A03)
        args.budget = resumed_budget(checkpoint, args.budget)
    note = f"neurohover evolve: starting afresh; {checkpoint} will be overwritten (--resume continues it)" if not args.resume and checkpoint.is_file() else None
    held.enter_context(warnings.catch_warnings(action="ignore", category=CheckpointReplaced))  # said by the note, not as evolve() warns
    settings = _optimiser_settings(args, mdp_desc == MDP_FAMILY)
    bar = _Bar(args.budget, f"evolve {family.name}/{mdp_desc}", note)
    before = _modified(checkpoint)
    try:
        result = evolve(
            target,
            topology=topology,
            prototype=proto,
            optimizer=args.optimizer,
            resampling=resampling,
            budget=args.budget,
            seed=args.seed,
            n_steps=args.episode_steps,
            threads=args.threads,
            device=args.device,
            progress=bar,
            checkpoint=checkpoint,
            checkpoint_every_s=args.checkpoint_every,
            resume=args.resume,
            settings=settings,
        )
    except EvolutionInterrupted as err:
        bar.close()
        return _evolve_stopped(err, checkpoint, before, args.resume)
    bar.close()
    # The champion's estimate is on the run's fitness scale (1/ln(error) over a family by default).
    scale = result.settings["settings"].get("fitness", "return") if result.settings.get("method") == "generational" else "return"
    try:
        validation = validation_return(
            result.champion, target, episodes=args.validation_episodes, seed=args.seed, n_steps=args.episode_steps, threads=args.threads, device=args.device
        )
        save_policy(result.champion, out, **_evolve_meta(args, family, target, mdp_desc, resampling, result, scale, validation, history_path.name))
    except KeyboardInterrupt as err:  # the run is over and checkpointed: a stop here said only "interrupted" (trial 44)
        from ..procs import stop_words

        how, status = stop_words(err)
        print(
            f"neurohover evolve: {how} during the champion's validation; the evolution is finished and kept in {printable(checkpoint)} "
            "(run the same command with --resume to validate its champion without evolving again)",
            file=sys.stderr,
        )
        return status
    try:
        write_history_csv(result.history, history_path)  # atomically, as writing() writes
    except NeurohoverError as err:  # said what was written and what was not (fourth trial: "no partial file" beside two files)
        raise NeurohoverError(f"{err}; the champion is written to {str(out)!r} and the run's checkpoint kept in {str(checkpoint)!r}") from None
    summary = {
        "policy": str(out),
        "history": str(history_path),
        "checkpoint": str(checkpoint),
        "champion_return": result.champion_return,
        "champion_fitness_scale": scale,
        "validation_return": float(validation.mean()),
        "validation_sd": float(validation.std()),
        "episodes": result.episodes,
        "generations": result.generations,
        "seconds": result.seconds,
        "episodes_per_second": result.episodes_per_second,
        "stop_reason": result.stop_reason,
    }
    _print_evolve_summary(args, summary, result)
    return 0


def _modified(path: Path) -> int | None:
    """When ``path`` was last modified (ns), None where there is no such file."""
    try:
        return path.stat().st_mtime_ns
    except OSError:
        return None


def _evolve_stopped(err: EvolutionInterrupted, checkpoint: Path, before: int | None, resumed: bool) -> int:
    """Say how the stopped evolve run ``err`` ended and what it left; its exit status (128 + the
    signal). ``before``: the checkpoint's :func:`_modified` when the run began."""
    from ..procs import stop_words

    how, status = stop_words(err)
    if err.checkpoint is not None:
        print(
            f"neurohover evolve: {how} after {err.episodes} episodes; checkpoint saved to {err.checkpoint} (run the same command with --resume to continue)",
            file=sys.stderr,
        )
        return status
    # Stopped again mid-generation: the line named a checkpoint that was not there (T55-A01).
    now = _modified(checkpoint)
    if now is not None and (resumed or now != before):
        left = f"its last checkpoint is {printable(checkpoint)} (run the same command with --resume to continue from it)"
    else:
        left = "no checkpoint of this run was saved"
    print(f"neurohover evolve: {how} mid-generation; {left}", file=sys.stderr)
    return status


class _Ticker:
    """An elapsed-time tqdm bar for steps without progress reports (learning a model; :func:`~neurohover.progress.progress_bar`)."""

    def __init__(self, desc: str) -> None:
        from ..progress import progress_bar

        self.bar = progress_bar(desc=desc, total=None, bar_format="{desc}: {elapsed}")
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)

    def _run(self) -> None:
        while not self._stop.wait(0.5):
            self.bar.refresh()

    def __enter__(self) -> _Ticker:
        self._thread.start()
        return self

    def __exit__(self, *exc) -> None:
        self._stop.set()
        self._thread.join()
        self.bar.close()


def _true_mdp(metadata: dict):
    """The MDP the flight data was flown on, when its metadata names exactly one."""
    from ..tasks import MDP

    mdps = metadata.get("mdps")
    if not isinstance(mdps, list) or not mdps:
        return None, "the flight data's metadata names no MDP"
    try:
        parsed = [MDP.from_dict(d) for d in mdps]
    except (KeyError, TypeError, ValueError) as err:
        return None, f"the flight data's MDP metadata is unreadable ({err})"
    if any(m != parsed[0] for m in parsed[1:]):
        return None, f"the flight data comes from {len(set(parsed))} different MDPs"
    return parsed[0], None


def cmd_learn_model(args: argparse.Namespace) -> int:
    """Learn a helicopter model from flight data (LR, EC-MENO or EC-MER) and print its parameters."""
    from ..agents.model_based import ModelEvolution
    from ..flightdata import FlightData
    from ..models import DEFAULT_NOISE_ESTIMATE, LearnedModel, ec_mer_policy, format_parameter_table, learn_ec_meno, learn_ec_mer, learn_lr, parameter_table
    from .options import check_given, given_settings

    if args.budget is not None and not 1 <= args.budget <= MAX_BUDGET:
        raise NeurohoverError(f"--budget {args.budget} is out of range: allowed an integer in 1..{MAX_BUDGET:,} (evaluations)")
    if args.seed is not None and args.method == "lr":
        raise NeurohoverError("--seed applies to the evolutionary methods (ec-meno, ec-mer), not to --method lr (least squares draws nothing)")
    seed = 0 if args.seed is None else args.seed
    if args.estimator is not None and args.method != "lr":
        raise NeurohoverError(f"--estimator applies to --method lr only (least squares), not to --method {args.method}")
    if args.budget is not None and args.method == "lr":
        raise NeurohoverError("--budget applies to the evolutionary methods (ec-meno, ec-mer), not to --method lr (least squares)")
    for option, value in (
        ("--wind-model", args.wind_model),
        ("--d-u", args.d_u),
        ("--noise-estimate", args.noise_estimate),
        ("--as-authors", args.as_authors or None),
    ):
        if value is not None and args.method != "lr":
            raise NeurohoverError(f"{option} applies to --method lr only (least squares), not to --method {args.method}")
    check_given(ModelEvolution, given_settings(args, args.lr_options), args.lr_options)  # named by their options, before anything is read
    against = [f"{o} {v}" for o, v, own in (("--d-u", args.d_u, "discard"), ("--noise-estimate", args.noise_estimate, "rms")) if v not in (None, own)]
    if args.as_authors and against:  # the preset's own values beside it agree with it (T27, borderline: they were refused)
        raise NeurohoverError(f"--as-authors sets --d-u discard and --noise-estimate rms: {', '.join(against)} contradicts it; give either it or other values")
    if args.policy == "":  # '' fell through to the flight data's policy (second trial)
        raise NeurohoverError("--policy is empty: give the policy file that flew the data, or 'baseline'")
    if args.policy is not None and args.method != "ec-mer":
        raise NeurohoverError(f"--policy applies to --method ec-mer only (the policy that flew the data), not to --method {args.method}")
    data = FlightData.load(input_file(args.flight_data, "--flight-data", "flight-data file"))
    inputs = {"--flight-data": args.flight_data, "--policy": args.policy}
    out = LearnedModel.check_name(output_file(args.out, "--out", inputs, kind="a model file", run_files=True), "--out")  # T23-16, T25-03
    with sole_writer(out, "--out"):  # two runs at once both said they wrote it; one's model was lost (T41-A02)
        start = time.perf_counter()
        extra = {} if args.budget is None else {"budget": args.budget}
        with _Ticker(f"learning a {args.method} model from {data.n_episodes} episodes ({data.n_transitions} steps)"):
            if args.method == "lr":
                d_u, noise = ("discard", "rms") if args.as_authors else (args.d_u or "keep", args.noise_estimate or DEFAULT_NOISE_ESTIMATE)
                model = learn_lr(data, estimator=args.estimator or "ols", wind_model=args.wind_model or "none", d_u=d_u, noise=noise)
            elif args.method == "ec-meno":
                model = learn_ec_meno(data, seed=seed, **extra)
            else:
                model = learn_ec_mer(data, ec_mer_policy(args.policy, data, args.flight_data), seed=seed, **extra)
        truth, why = _true_mdp(data.metadata)
        try:  # before the model is written: a refused MDP left m.json behind its refusal (T23-01)
            rows = parameter_table(model, truth)
        except NeurohoverError as err:
            raise NeurohoverError(f"flight-data file {args.flight_data!r}: its metadata's MDP {brief(truth.label if truth else '')}: {err}") from None
        model.save(out)  # written whole or not at all (a failed write: one message, the old file as it was)
    print(f"{args.method} model written to {printable(out)} ({time.perf_counter() - start:.2f} s)")
    if truth is not None:
        print(f"learned parameters (converted to the simulator's 10 substeps) next to the true ones of {truth.label or 'the MDP'}:")
    else:
        print(f"{why}; learned parameters (converted to the simulator's 10 substeps) next to the simulator's defaults:")
    print(format_parameter_table(rows))
    for line in model_notes(model, data, truth, rows):
        print(f"neurohover learn-model: {line}", file=sys.stderr)
    return 0


def _wind_text(x, y) -> str:
    return "; ".join(f"{n}: {a.amplitude:.4g} sin({a.omega:.5g} t + {a.phase:.4g}) + {a.offset:.4g}" for n, a in (("x", x), ("y", y)))


# Fewer transitions than this (one minute of flight) give unreliable estimates.
RELIABLE_TRANSITIONS = 600
# Episodes the baseline policy flies on the learned model (and the true MDP) to check it is usable.
CHECK_EPISODES = 3


def model_notes(model, data, truth, rows) -> list[str]:
    """Warnings and explanations that keep ``learn-model``'s parameter table from misleading.

    Explains rows without a 10-substep equivalent (nan), and warns when the data are short, when
    the true MDP's wind was absorbed into the model, and when the baseline policy crashes on the
    model (flown ``CHECK_EPISODES`` times) but not in the true MDP. ``rows`` is the
    :func:`~neurohover.models.parameter_table` of ``model`` against ``truth`` (None: unknown).
    """
    import numpy as np

    from ..evaluate import evaluate
    from ..models import PARAM_NAMES
    from ..models.wind import effective_wind, sinusoid_axes
    from ..policies import baseline_policy
    from ..sim.constants import WIND_NONE, WIND_SINUSOID

    notes = []
    nan_axes = [r.name for r in rows if not np.isfinite(r.learned)]
    if nan_axes:
        notes.append(
            f"note: {', '.join(nan_axes)} show nan: on their axis the learned one-step multiplier 1 + 0.1*C is not "
            "positive, which no 10-substep integration can produce; the model itself is still a valid "
            "one-substep model (the model file holds its values)"
        )
    if data.n_transitions < RELIABLE_TRANSITIONS:
        notes.append(
            f"warning: only {data.n_transitions} transitions (fewer than {RELIABLE_TRANSITIONS}, one minute of flight); "
            "estimates from so little data are unreliable"
        )
    if model.wind.kind != "none":
        notes.append(f"note: identified wind (world frame; omega rad/s, phase rad, m/s): {_wind_text(model.wind.x, model.wind.y)}")
        if truth is not None and truth.wind_kind == WIND_SINUSOID:
            true_axes = [effective_wind(a) for a in sinusoid_axes(truth.wind)]
            notes.append(
                f"note: the true wind as a one-substep model sampled at 10 Hz sees it (step-averaged, frequency folded into "
                f"[0, 10 pi]): {_wind_text(*true_axes)}"
            )
    elif truth is not None and truth.wind_kind != WIND_NONE and any(w != 0 for w in truth.wind):
        absorbed = f" (fitted D_u = {model.d_u:.4g})" if model.d_u else ""
        notes.append(
            f"note: the data were flown in wind ({truth.label or truth.wind}); a learned model has no wind, so the "
            f"wind's force is absorbed into its constants{absorbed} and biases the drag terms "
            f"({', '.join(PARAM_NAMES[:3])}): their errors above are not only estimation error"
        )
    mdps = [model.mdp("learned")] + ([truth] if truth is not None else [])
    ev = evaluate(baseline_policy(), mdps, episodes=CHECK_EPISODES, seed=0)
    crashed = ev.crashed.sum(axis=(0, 2))
    if crashed[0] and (truth is None or not crashed[1]):
        steps = ev.steps[0, 0][ev.crashed[0, 0]]
        where = "" if truth is None else ", while it never crashes in the true MDP"
        notes.append(
            f"warning: the baseline policy crashes on this model in {crashed[0]} of {CHECK_EPISODES} episodes "
            f"(after {steps.min()}-{steps.max()} steps){where}: the model's closed-loop dynamics differ from the "
            "helicopter's, so do not read its parameters as the truth, and check any policy planned on it in the true MDP"
        )
    return notes


def register(sub) -> None:
    from ..agents.model_based import ModelEvolution
    from ..evolution.steady_state import SteadyStateSettings
    from .options import add_setting_options, add_task_options, integer, real

    p = sub.add_parser(
        "evolve",
        help="evolve a policy on an MDP (steady state) or over a task family (generational)",
        description=(cmd_evolve.__doc__ or "") + "\n\n" + (__doc__ or "").split("\n\n", 1)[1],
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    add_task_options(
        p,
        mdp_help="zero, train:N, test:N, seeded-train:N, seeded-test:N, sample (one MDP drawn from G with --seed), or G: evolve over "
        "the family's distribution, a fresh MDP per episode (generational). Default: G for fghh, zero otherwise",
        verb="evolve",
    )
    p.add_argument("--topology", choices=("slp", "mlp"), help="network (default: the seed policy file's, else slp over a family (--mdp G) and mlp on one MDP)")
    p.add_argument("--seed-policy", default="baseline", help="prototype: zero, baseline (baseline-equivalent network; default) or a policy FILE")
    p.add_argument(
        "--optimizer",
        "--optimiser",
        choices=optimiser_names(),
        default="ne",
        help="ne: the paper's neuroevolution (default); " + "; ".join(f"{n}: {s.summary}" for n, s in OPTIMISERS.items()) + " (same budget and resampling)",
    )
    p.add_argument(
        "--resampling",
        default="fixed:1",
        help="fixed:K (mean of K episodes per candidate; default fixed:1) or race:DELTA (selection races at confidence 0<DELTA<1; generational only)",
    )
    p.add_argument("--budget", type=integer, help="episodes to fly (default: the paper's plateau (steady state) or 4000 generations; --resume: the run's own)")
    add_setting_options(p, SteadyStateSettings, ("plateau_rule",), who="steady state")  # the rest through --setting
    p.add_argument(
        "--preset",
        choices=tuple(GENERATIONAL_PRESETS),
        help="generational settings over a family: table7 (default: Table 7 with the authors' 1/ln(error) fitness, no survivors), "
        "authors-script (their FGHH script's lambda 30, mu 10, mutation 0.2/1.0) or raw-elitist (mean raw returns, surviving parents)",
    )
    p.add_argument(
        "--setting",
        action="append",
        metavar="KEY=VALUE",
        help="one optimiser setting (repeatable), e.g. --setting fitness=return --setting elitist=true --setting pop_size=30; "
        "`neurohover settings steady-state` (one MDP), `... generational` (over a family) or `... OPTIMIZER` lists them with their defaults",
    )
    p.add_argument("--episode-steps", type=integer, default=6000, help="control steps per episode (default 6000)")
    p.add_argument("--seed", type=integer, default=0, help="root seed of the run (default 0)")
    p.add_argument("--threads", type=integer, help="kernel threads (default: all cores; results do not depend on it)")
    p.add_argument(
        "--device",
        choices=DEVICES,
        default="cpu",
        help="where episodes fly: cpu (default) or cuda, an NVIDIA GPU (docs/gpu.md; results agree to about 1e-12 relative)",
    )
    p.add_argument("--out", required=True, metavar="FILE", help="champion policy file; FILE.history.csv and FILE.checkpoint.json go next to it")
    p.add_argument("--resume", action="store_true", help="continue the run from FILE.checkpoint.json (same options; the budget may be raised)")
    p.add_argument("--checkpoint-every", type=real, default=60.0, metavar="SECONDS", help="checkpoint interval (default 60; inf: at the end and on a stop)")
    p.add_argument("--validation-episodes", type=integer, default=10, help="fresh episodes to validate the champion (default 10)")
    p.add_argument("--json", action="store_true", help="print the summary as one JSON object")
    p.set_defaults(func=cmd_evolve)

    p = sub.add_parser("learn-model", help="learn a helicopter model from flight data", description=cmd_learn_model.__doc__)
    p.add_argument("--flight-data", required=True, metavar="FILE", help="flight data (.npz, e.g. from neurohover fly --record)")
    p.add_argument("--method", required=True, choices=("lr", "ec-meno", "ec-mer"), help="lr (least squares), ec-meno or ec-mer (evolution)")
    p.add_argument("--out", required=True, metavar="FILE", help="model file to write (JSON)")
    p.add_argument(
        "--budget",
        type=integer,
        help="evaluations for ec-meno / ec-mer (defaults: ec-meno runs to the paper's plateau stop, 1000 evaluations without a new champion; ec-mer 500)",
    )
    lr_options = add_setting_options(p, ModelEvolution, ("estimator", "wind_model", "d_u", "noise"), flags={"noise": "noise-estimate"}, who="lr")
    p.add_argument(
        "--as-authors",
        action="store_true",
        help="lr: fit as the authors' code did (--d-u discard --noise-estimate rms; docs/model.md, LR as the authors fitted it)",
    )
    p.add_argument("--seed", type=integer, help="ec-meno, ec-mer: seed of the evolution (default 0)")
    p.add_argument(
        "--policy",
        help="ec-mer: the policy that flew the data (default: the one fly --record stored in the flight data, else the file named there, else "
        "baseline); where the data record or name one, --policy must be that one",
    )
    p.set_defaults(func=cmd_learn_model, lr_options=lr_options)
