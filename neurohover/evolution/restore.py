"""Reading a checkpoint back: each part of it checked before a run (:class:`~.run.Run`) restores any of it.

:meth:`Run.restore <neurohover.evolution.run.Run.restore>` refuses a damaged checkpoint by name through these checks:
its entries, counters, champion, history, race delta, budget, stop reason and MDP stream, each against the others and
against the restored optimiser (its prototype, its champion). A resume continues a stopped run: a run stopped by its
budget goes on under a larger one; one stopped by its optimiser (plateau, generations, cma-stop, optimiser-stop) stops
again at once, so a checkpoint's stop reason must be the one its state stops by (:func:`check_stop_reason`).
"""

from __future__ import annotations

import hashlib
import math
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import NeurohoverError, brief, finite_real, whole_number
from ..flyer import MAX_EPISODE_INDEX
from ..sim.constants import CRASH_STEP_PENALTY, MAX_SECONDS, seconds_allowed
from ..tasks import TaskFamily
from .answers import stopped
from .common import EntryError, Optimiser, check_entries, check_genomes, damage_text, dec_array, dec_float, enc_float
from .config import MAX_BUDGET, Resampling
from .fitness import fitness_range, in_fitness_range
from .generational import GenerationalNE
from .optimisers import OPTIMISERS, SHIPPED_SPECS, usable_specs
from .records import check_history, decode_history
from .steady_state import SteadyStateNE, steady_state_evaluations

if TYPE_CHECKING:
    from .run import Run


def damaged(source: str, err: Exception) -> NeurohoverError:
    """The error of a checkpoint ``source`` that cannot be read back (``err`` says what is wrong)."""
    return NeurohoverError(f"{source} is a damaged checkpoint: {damage_text(err)}; resume from an undamaged copy or start again without resuming")


#: Every entry a checkpoint (:meth:`Run.state`) has held, and every entry of its counters and champion tables.
CHECKPOINT_ENTRIES = (
    *("format", "config", "budget", "optimizer_state", "counters", "mdp_stream", "race_delta", "champion", "history", "stop_reason"),
    "family_draws",  # over a task family registered at run time only (T55-B10)
)
COUNTERS = ("episodes", "next_index", "flown", "steps", "generation", "evaluations", "wall_seconds", "kernel_seconds")
#: The checkpoint entries that are tables, and what each holds (for the message refusing one that is not).
_TABLES = {
    "config": "the run's settings (target, method, optimizer, resampling, topology, prototype, seed, n_steps, settings)",
    "counters": ", ".join(COUNTERS),
    "champion": "genome (a list of numbers, or null before the first champion) and return",
}
#: Why a run stopped, as :func:`stop_reason` says it.
STOP_REASONS = ("budget", "plateau", "generations", *sorted({spec.stop_reason for spec in SHIPPED_SPECS.values()}))


#: The seed and number of the draws whose digest (:func:`family_draws`) a checkpoint over a run-time family records.
FAMILY_DRAWS_SEED, FAMILY_DRAWS = 20261207, 4


def family_draws(family: TaskFamily | None, shipped_too: bool = False) -> str | None:
    """A digest of ``family``'s distribution G (sha256 of :data:`FAMILY_DRAWS` seeded draws of its ``sample_params``,
    16 hex digits) where it is registered at run time (its class not neurohover's own), else None (and for one MDP): a
    family redefined under its name between a run and its resume flew two distributions as one (T55-B10). A shipped
    family's checkpoint records none, its format as before (its class cannot change under its name); ``shipped_too``
    digests one anyway (a checkpoint that records one is compared)."""
    if family is None or (not shipped_too and type(family).__module__.split(".")[0] == "neurohover"):
        return None
    draws = np.ascontiguousarray(family.sample_params(np.random.default_rng(FAMILY_DRAWS_SEED), FAMILY_DRAWS), dtype=np.float64)
    return hashlib.sha256(draws.tobytes()).hexdigest()[:16]


def check_family_draws(state: dict, family: TaskFamily | None, source: str) -> None:
    """NeurohoverError where checkpoint ``state`` records a digest of its family's draws (:func:`family_draws`) that the
    family resuming it no longer gives; a checkpoint without one (older, or a shipped family's) resumes as before."""
    saved = state.get("family_draws")
    if saved is None:
        return
    if family is None or not isinstance(saved, str):
        raise damaged(source, EntryError(f"family_draws={brief(saved)} is not allowed: allowed a digest of text, over a task family only, as the run wrote it"))
    now = family_draws(family, shipped_too=True)
    if now != saved:
        raise NeurohoverError(
            f"{source} was written by a run over another task family {brief(family.name)} (its sample_params' seeded draws have digest {saved}, "
            f"the family's now {now}: it was redefined under its name since), which is not allowed: resume with the family defined as when the run "
            "began, or start again without resuming"
        )


def stop_reason(method: str, opt: Optimiser, budget: int | None, episodes: int, generation: int) -> str | None:
    """Why a run of ``method`` whose optimiser is ``opt`` stops after ``episodes`` episodes and ``generation``
    generations under ``budget`` (None: it goes on): its budget first, then its optimiser's own stop. What
    :meth:`Run._should_stop` asks at each generation boundary, and what a checkpoint's stop reason is checked against."""
    if budget is not None and episodes >= budget:
        return "budget"
    if generation == 0:
        return None
    if method in OPTIMISERS:
        return OPTIMISERS[method].stop_reason if stopped(opt, method) else None
    if stopped(opt, method):
        return "plateau" if method == "steady-state" else "generations"
    return None


def check_tables(state: dict, source: str) -> None:
    """NeurohoverError naming an unknown entry of checkpoint ``state`` or of its counters or champion: one was ignored
    without a word, as the optimiser state's were before (sixteenth trial)."""
    remedy = "resume from an undamaged copy or start again without resuming"
    check_entries(state, "checkpoint", CHECKPOINT_ENTRIES, what=source, remedy=remedy)
    for name, allowed in _TABLES.items():  # "champion": null was Python's "TypeError: 'NoneType' object is not subscriptable" (T33-B15)
        if name in state and not isinstance(state[name], dict):
            raise damaged(source, EntryError(f"{name}={brief(state[name])} is not allowed: allowed a table of {allowed}, as the run wrote it"))
    for name, entries in (("counters", COUNTERS), ("champion", ("genome", "return"))):
        if isinstance(state.get(name), dict):
            check_entries(state[name], "checkpoint", entries, what=f"the {name} table of {source}", remedy=remedy)


def check_run_entries(state: dict, one_mdp: bool) -> None:
    """EntryError unless checkpoint ``state``'s budget, stop reason and MDP stream are what :meth:`Run.state` writes
    (a budget of '100', a stop_reason of 5 and an mdp_stream of 'x' on one MDP were taken; sixteenth trial)."""
    budget, reason, stream = state["budget"], state["stop_reason"], state["mdp_stream"]
    if budget is not None and not (whole_number(budget) and 1 <= budget <= MAX_BUDGET):
        raise EntryError(f"budget={brief(budget)} is not allowed: allowed null or an integer in 1..{MAX_BUDGET:,}")
    reasons = (*STOP_REASONS, *sorted({spec.stop_reason for spec in usable_specs().values()} - set(STOP_REASONS)))  # and those registered since
    if reason is not None and (not isinstance(reason, str) or reason not in reasons):  # a user optimiser's 'my-stop' was refused (T40-B14)
        raise EntryError(f"stop_reason={brief(reason)} is not allowed: allowed null or one of {', '.join(reasons)}")
    if one_mdp and stream is not None:  # (a family's stream is the bit generator's to refuse)
        raise EntryError(f"mdp_stream={brief(stream)} is not allowed: allowed null (a run on one MDP draws no MDPs)")


def check_between_generations(opt: Optimiser) -> None:
    """EntryError if restored optimiser ``opt`` holds a batch asked and not told: a run checkpoints between
    generations only (asked=true was the API's "ask() called again before tell()", naming no checkpoint; T20-03)."""
    if isinstance(opt, GenerationalNE) and opt._asked:
        raise EntryError("optimizer_state's asked=true is not allowed: a run's checkpoint is written between generations (allowed false)")
    if isinstance(opt, SteadyStateNE) and opt._pending is not None:
        raise EntryError("optimizer_state's pending batch is not allowed: a run's checkpoint is written between generations (allowed null)")


def check_prototype(opt: Optimiser, genome: np.ndarray) -> None:
    """EntryError unless restored optimiser ``opt``'s prototype (steady state's and generational NE's keep one) is the
    config's ``genome``, which bred its first population: a prototype gene of 9.0 beside the config's 0.0 was taken (T22-12)."""
    mine = opt.prototype if isinstance(opt, (GenerationalNE, SteadyStateNE)) else None
    if not isinstance(mine, np.ndarray):
        return
    if mine.shape != genome.shape:
        raise EntryError(f"optimizer_state's prototype has {mine.size:,} genes where the config's prototype has {genome.size:,}")
    differ = np.flatnonzero(mine != genome)
    if differ.size:
        k = int(differ[0])
        raise EntryError(
            f"optimizer_state's prototype is not the config's: gene {k} is {brief(float(mine[k]))} where the config's prototype has"
            f" {brief(float(genome[k]))}{f' (and {differ.size - 1} more genes differ)' if differ.size > 1 else ''}; the optimiser's first population"
            " was bred from the config's"
        )


def check_stop_reason(state: dict, method: str, opt: Optimiser, counts: dict[str, int]) -> None:
    """EntryError unless checkpoint ``state``'s stop reason is null (written while the run went on) or the one its
    restored run stops by under its own budget (:func:`stop_reason`): 'plateau' on a run that stopped by its budget was
    taken, and the run went on (T22-12). A resume after a stop continues the run: past a budget stop with a larger
    budget; after the optimiser's own stop (plateau, generations, cma-stop, optimiser-stop) it stops again at once, by
    the same reason, whatever the budget."""
    reason = state["stop_reason"]
    if reason is None:
        return
    found = stop_reason(method, opt, state["budget"], counts["episodes"], counts["generation"])
    if reason != found:
        budget, episodes = state["budget"], counts["episodes"]
        if found is None:
            short = "it has no budget" if budget is None else f"its {episodes:,} episodes are short of its budget of {budget:,}"
            held = f"has not stopped ({short} and its optimiser's stop() is false); allowed null"
        elif found == "budget":
            held = f"stops by 'budget' (its {episodes:,} episodes reached its budget of {budget:,}); allowed 'budget' or null"
        else:
            held = f"stops by {found!r} (its optimiser's own stop() is true); allowed {found!r} or null"
        raise EntryError(f"stop_reason={brief(reason)} is not allowed: the run it holds {held}")


def restored_parts(state: dict, run: Run, opt: Optimiser) -> dict[str, Any]:
    """The counters, champion, history and race delta of checkpoint ``state`` for ``run`` (whose restored optimiser is
    ``opt``), each checked (ValueError, TypeError or KeyError naming what is wrong), before any of them is restored."""
    c = state["counters"]
    counts = _checked_counts(c, run.cfg.n_steps)
    seconds = {k: c[k] for k in ("wall_seconds", "kernel_seconds")}
    for k, v in seconds.items():
        if not (finite_real(v) and v >= 0):  # finite_real: '1.5' was read as 1.5 (sixteenth trial)
            raise EntryError(f"counter {k!r} is {brief(v)}, not a number of seconds >= 0")
        if not seconds_allowed(v):  # 1e300 was resumed into the result, its history and the next checkpoint (T45-B01)
            raise EntryError(f"counter {k!r} is {brief(v)}, more seconds than 100 years: allowed a number in [0, {MAX_SECONDS:.6g}]")
    kernel, wall = seconds["kernel_seconds"], seconds["wall_seconds"]
    if kernel > wall:  # (each kernel call is timed inside the run's wall time; T21-03)
        raise EntryError(f"counter 'kernel_seconds' is {kernel!r}, more than the run's wall_seconds {wall!r} (its kernel time is part of them)")
    _check_tracker_kept(opt)
    _check_generation(opt, counts)
    _check_counts_of_run(counts, run.resampling, opt, run.cfg.n_steps)
    champion = _checked_champion(state["champion"], run.cfg.prototype.genome.size, run.fitness, run.cfg.n_steps)
    own = run.method in OPTIMISERS and run.family is not None
    _check_run_champion(champion, own, counts["generation"], run.method, opt)
    race_delta = _checked_race_delta(state.get("race_delta", run.resampling.delta), run.resampling)  # absent before race:auto
    history = decode_history(state["history"])
    # Generational runs and population optimisers on a family record every generation; the others each new champion.
    # A population optimiser on a family keeps its champion (the best of the last generation) in the champion table;
    # every other run's is its optimiser's (Run._champion_return).
    check_history(history, counts, per_generation=run.method == "generational" or own, champion=champion[1] if own else float(opt.champion_return))
    _check_fitness_values(opt, history, run.cfg.n_steps, run.fitness)  # after: a row off the champion is named as such
    return {"counters": counts, "seconds": seconds, "champion": champion, "history": history, "race_delta": race_delta}


def _check_generation(opt: Optimiser, counts: dict[str, int]) -> None:
    """EntryError unless the counters' generation is the restored optimiser's (steady state and generational NE count
    their tells, one a generation of the run) and, of steady state, its evaluations the ones its generations make
    (:func:`~.steady_state.steady_state_evaluations`): a counters.generation of 5 beside an optimiser at generation 1
    was resumed and written as the run's generations (T26-B05)."""
    if not isinstance(opt, (SteadyStateNE, GenerationalNE)):
        return
    gen = counts["generation"]
    if gen != opt.generation:
        raise EntryError(
            f"counter 'generation' is {gen:,}, but optimizer_state.generation is {opt.generation:,}: "
            f"the optimiser is told once a generation of the run (allowed {opt.generation:,})"
        )
    if isinstance(opt, SteadyStateNE):
        s = opt.settings
        evaluations = steady_state_evaluations(gen, s.pop_size, s.elite_size)
        if counts["evaluations"] != evaluations:
            raise EntryError(
                f"counter 'evaluations' is {counts['evaluations']:,}, but its {gen:,} steady-state generations are {evaluations:,} evaluations "
                f"(pop_size {s.pop_size}, then {s.pop_size - s.elite_size} a generation): allowed {evaluations:,}"
            )


def _check_tracker_kept(opt: Optimiser) -> None:
    """EntryError unless a restored steady-state optimiser with an elite keeps its champion (its tracker's genome) in its
    population, at a row of the champion's return, as :meth:`SteadyStateNE.tell` does (the elite keeps the best rows,
    ties in order, so the first of the best is never dropped). A tracker genome found in no row was resumed and written
    as the run's champion (T23-09). Not required without an elite (the champion may have been replaced), nor of CMA-ES
    or OpenAI-ES (they keep no population; their champion is a past sample) or generational NE (its own check: the
    champion is one of its parents)."""
    if not isinstance(opt, SteadyStateNE) or opt.settings.elite_size == 0:
        return
    genome, population, fitness = opt._tracker.genome, opt._population, opt._fitness
    if genome is None or population is None or fitness is None:  # (no champion yet, or none: the optimiser's own checks)
        return
    best = opt._tracker.best
    if not any(f == best and np.array_equal(row, genome) for row, f in zip(population, fitness)):
        k = int(np.flatnonzero(fitness == best)[0]) if np.any(fitness == best) else None
        row = population[k] if k is not None else None
        differ = (
            ""
            if row is None or row.shape != genome.shape
            else next((f" (gene {i} is {brief(float(genome[i]))}, row {k}'s {brief(float(row[i]))})" for i in np.flatnonzero(row != genome)[:1]), "")
        )
        raise EntryError(
            f"optimizer_state.tracker.genome is not allowed: it is no genome of the population with the champion's return {enc_float(best)}{differ};"
            f" allowed the population's row of that return (the elite of {opt.settings.elite_size} keeps the champion)"
        )


def _check_run_champion(champion: tuple[np.ndarray | None, float], own: bool, generation: int, method: str, opt: Optimiser) -> None:
    """EntryError unless a checkpoint's ``champion`` table is what the run keeps in it: a population optimiser on a
    family (``own``) its champion of the last generation (a genome once a generation is flown; its return is the last
    history row's, :func:`~.records.check_history`); every other run none (genome null, return '-inf'), its champion
    being its optimiser's, in the optimiser state. A zero genome of return 0.0 in a steady-state checkpoint was taken
    and ignored (T22-10): the table is redundant with the history there and with the optimiser state elsewhere."""
    genome, value = champion
    if not own and (genome is not None or value != -math.inf):
        held = f"{'a genome' if genome is not None else 'no genome'} and return {brief(enc_float(value))}"
        raise EntryError(
            f"the champion table holds {held} where a {method} run keeps none (allowed genome null and return '-inf'): its champion is its"
            f" optimiser's, in optimizer_state (return {brief(enc_float(opt.champion_return))}); the table is a population optimiser's on a task family"
        )
    if own and (genome is None) != (generation == 0):
        held = "no champion genome" if genome is None else "a champion genome"
        raise EntryError(
            f"the champion table holds {held} at generation {generation:,}: a population optimiser on a task family has one"
            " exactly once it has flown a generation"
        )


def _checked_race_delta(delta: Any, resampling: Resampling) -> float | None:
    """A checkpoint's race delta for a run of ``resampling``: none but a race's, a fixed race's (or bandit's) its own
    delta, race:auto's a level in (0, 1) (0.5 beside fixed:1 was kept and written back; T20-02)."""
    if resampling.auto:
        if not finite_real(delta) or not 0 < delta < 1:
            raise EntryError(f"race_delta is {brief(delta)}: allowed a confidence level in (0, 1) (race:auto sets one race by race)")
        return float(delta)
    if delta is None and resampling.delta is None:
        return None
    if not finite_real(delta) or float(delta) != resampling.delta:
        allowed = "null (fixed resampling races no candidates)" if resampling.delta is None else f"{resampling.delta!r}, the delta of {resampling}"
        raise EntryError(f"race_delta is {brief(delta)}: allowed {allowed}")
    return float(delta)


def _check_counts_of_run(counts: dict[str, int], resampling: Resampling, opt: Optimiser, n_steps: int) -> None:
    """EntryError unless the counters fit the run's resampling and episode length (its config, which the resumed call
    matches, edited with it): under fixed:K each evaluation flies K episodes (T33-B05: fixed:2 beside 50 episodes of 50
    evaluations was resumed, a run half fixed:1; the command line refused it only after the whole run, naming the policy
    file), and a steady state's population fitness (raw returns, each a mean of K episodes of its own) needs steps: an
    episode that flew s of n_steps steps crashed and was charged the worst step for each step left, so its return is at
    most -CRASH_STEP_PENALTY * (n_steps - s) (T33-B07: n_steps 20 edited to 6000 was resumed, 50 episodes of 434 steps
    in all whose returns said they crashed none but one). Not detectable without flying again: an edited seed."""
    episodes, evaluations = counts["episodes"], counts["evaluations"]
    if resampling.kind == "fixed" and episodes != resampling.k * evaluations:
        k = resampling.k
        raise EntryError(
            f"counter 'episodes' is {episodes:,}, not allowed beside its {evaluations:,} evaluations under the config's resampling {resampling}: "
            f"each evaluation flies {k} episode{'s' if k != 1 else ''}, {k * evaluations:,} in all"
        )
    fitness = opt.fitness if isinstance(opt, SteadyStateNE) else None
    if fitness is not None and resampling.kind == "fixed":
        f = fitness[np.isfinite(fitness)]  # (NaN: an episode that blew up; -inf: one whose fitness is NaN)
        f = np.minimum(f, 0.0) * (1 + 1e-9)  # the rounding of a mean, toward fewer steps
        least = float(np.sum(resampling.k * (n_steps + f / CRASH_STEP_PENALTY)))
        if counts["steps"] < math.floor(least + 1e-6):
            raise EntryError(
                f"counter 'steps' is {counts['steps']:,}, fewer than the {math.floor(least + 1e-6):,} that the population's returns in "
                f"optimizer_state.fitness need in episodes of the config's n_steps {n_steps:,} (an episode that flew s steps crashed, "
                f"charged {CRASH_STEP_PENALTY:.6g} for each of its n_steps - s steps left); allowed the counters and config the run wrote"
            )


def _checked_counts(c: dict, n_steps: int) -> dict[str, int]:
    """Checkpoint counters ``c`` of a run of ``n_steps``-step episodes, each a count in 0..:data:`MAX_COUNT` and in
    step with the others (2**70 as next_index was an OverflowError mid-run, as flown or generation taken; T19-01, T19-08),
    or an EntryError naming the counter (its message as it is: a ValueError's was prefixed "ValueError: "; T21-03)."""
    counts = {k: c[k] for k in ("episodes", "steps", "generation", "evaluations")}
    # Checkpoints before races reserved indices: every index flown was counted.
    counts["next_index"], counts["flown"] = c.get("next_index", c["episodes"]), c.get("flown", c["episodes"])
    for k, v in counts.items():
        if not whole_number(v) or v < 0 or (k != "steps" and v > MAX_COUNT):  # (the steps are bounded by the episodes, below)
            raise EntryError(f"counter {k!r} is {brief(v)}, not a count: allowed an integer in 0..2**62 ({_COUNT_LIMIT})")
    # Rules every run keeps: each counted episode was flown, each flown one had its own index, a generation evaluates at
    # least one candidate, an episode has 1 to n_steps steps (the kernel counts the step an episode crashes on, its first
    # included: steps 3 for 40 episodes was resumed; T21-03) and an evaluation flies at least one episode.
    episodes, evaluations = counts["episodes"], counts["evaluations"]
    for k, v, bound, why in (
        ("flown", counts["flown"], episodes, f"below the {episodes:,} episodes counted (each was flown)"),
        ("next_index", counts["next_index"], counts["flown"], f"below the {counts['flown']:,} episodes flown (each flew its own index)"),
        ("evaluations", evaluations, counts["generation"], f"below the {counts['generation']:,} generations (each evaluates a candidate)"),
        ("steps", counts["steps"], episodes, f"below the {episodes:,} episodes counted (each has a step or more, a crash on its first too)"),
        ("episodes", episodes, evaluations, f"below the {evaluations:,} evaluations (each flies an episode or more)"),
    ):
        if v < bound:
            raise EntryError(f"counter {k!r} is {v:,}, {why}")
    if counts["steps"] > counts["episodes"] * n_steps:
        raise EntryError(f"counter 'steps' is {counts['steps']:,}, more than {counts['episodes']:,} episodes of {n_steps:,} steps can have")
    return counts


#: The most a checkpoint's counters may be (T19-01): half the kernel's episode indices (0..2**63-1), the other half room
#: for the resumed run's episodes (4.6e18: centuries of flying, where the most a budget may be is 1e10).
MAX_COUNT = (MAX_EPISODE_INDEX + 1) // 2
_COUNT_LIMIT = "half the kernel's episode indices 0..2**63-1: the rest is room for the resumed run's episodes"


def _checked_champion(ch: dict, genome_size: int, scale: str, n_steps: int) -> tuple[np.ndarray | None, float]:
    """The champion table ``ch`` of a checkpoint: its genome (or None) and its fitness on ``scale`` (a return of 2**70,
    which no episode can score, was taken; T19-08)."""
    genes = ch["genome"]  # a list of numbers, checked one by one as an optimiser's arrays are: True was read as 1.0 (sixteenth trial)
    genome = check_genomes(
        None if genes is None else dec_array({"shape": [len(genes)], "data": genes}, "the champion genome"), genome_size, "the champion genome", rows=0
    )
    value = dec_float(ch["return"])
    if math.isnan(value):
        raise EntryError("the champion's return is nan")
    if genome is None and value != -math.inf:
        raise EntryError(f"the champion's return is {brief(ch['return'])} without a champion genome: allowed '-inf' (no champion yet)")
    # A mean of its episodes' fitness on the run's scale, within one episode's range of the run's n_steps (fitness.py;
    # a return of -1e9 in a 20-step run was resumed, T27-B03).
    low, high, allowed = fitness_range(n_steps, scale)
    if value != -math.inf and not in_fitness_range(value, low, high):
        raise EntryError(f"the champion's return is {brief(ch['return'])}: allowed '-inf' or {allowed} on the run's fitness scale {scale!r}")
    return genome, value


def _check_fitness_values(opt: Optimiser, history: list, n_steps: int, scale: str) -> None:
    """EntryError naming the first fitness of the restored optimiser ``opt`` (its champion's, a steady state's
    population's) or of the checkpoint's ``history`` rows that no run of ``n_steps``-step episodes on ``scale`` tells
    (:func:`~.fitness.fitness_range`): -1e9 in a 20-step run's optimizer_state.fitness was resumed (T27-B03). -inf (a NaN
    episode's fitness) is allowed, and NaN in a steady state's fitness: it flies raw returns, and an episode that blows
    up on a learned model (or any MDP of the API) is told and written as NaN."""
    low, high, allowed = fitness_range(n_steps, scale)
    told = [("optimizer_state's champion return", np.array([float(opt.champion_return)]), False)]
    if isinstance(opt, SteadyStateNE) and opt._fitness is not None:
        told.append(("optimizer_state.fitness", opt._fitness, True))
    told.append(("history's champion_return column", np.array([h.champion_return for h in history], dtype=np.float64), False))
    for name, values, nan_ok in told:
        bad = np.flatnonzero(~(in_fitness_range(values, low, high) | (values == -math.inf) | (np.isnan(values) & nan_ok)))
        if bad.size:
            k = int(bad[0])
            where = f" data entry {k}" if name == "optimizer_state.fitness" else (f" row {k} (from 0)" if name.startswith("history") else "")
            nan = ", 'nan' (an episode that blew up)" if nan_ok else ""
            raise EntryError(
                f"{name}{where} is {brief(enc_float(float(values[k])))}: not allowed in a run of {n_steps:,}-step episodes on fitness scale {scale!r}:"
                f" allowed '-inf'{nan} or {allowed}"
            )
