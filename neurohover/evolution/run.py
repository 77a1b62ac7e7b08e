"""The evolution run loop: ask, fly, tell, record, checkpoint (what :func:`~neurohover.evolution.evolve.evolve` drives).

A :class:`Run` holds one run's whole state: its optimiser (any :class:`~.common.Optimiser`), the
:class:`~neurohover.flyer.KernelFlyer` that flies the candidates and counts the episodes, the
generator of the task family's MDPs, counters and history. :meth:`Run.state` is the checkpoint
and :meth:`Run.restore` continues from one bit-for-bit, after :mod:`~neurohover.evolution.restore`'s checks of it.
"""

from __future__ import annotations

import copy
import dataclasses
import math
import signal
import threading
import time
from collections.abc import Callable
from pathlib import Path
from types import FrameType
from typing import Any, cast

import numpy as np

from ..errors import NeurohoverError, Terminated, brief, raise_terminated, stop_signals
from ..flyer import KernelFlyer
from ..launch import Parking
from ..policies import Policy
from ..sim.lanes import LANES
from .answers import (
    AnswerError,
    Held,
    asked_genomes,
    check_made,
    check_restored,
    check_state_json,
    check_state_nesting,
    checked_champion,
    checked_champion_genome,
    held_champion,
    read_only,
    told_champion,
)
from .bandits import BANDITS, top_mu_bandit
from .common import STATE_DAMAGE, Optimiser, TellInfo, damage_text, enc_float
from .config import RACE_T_LIMIT, RunConfig, next_auto_delta, preset_hint, upgrade_saved_config
from .fitness import episode_fitness
from .generational import GenerationalNE
from .optimisers import OPTIMISERS, SHIPPED, recorded_names
from .race_sampler import RaceSampler
from .races import fixed_resampling, selection_race
from .records import (
    CHECKPOINT_FORMAT,
    EvolutionInterrupted,
    EvolutionResult,
    HistoryRecord,
    ProgressInfo,
    check_stream,
    config_difference,
    encode_history,
    refuse_replaced,
    write_checkpoint,
)
from .restore import (
    check_between_generations,
    check_family_draws,
    check_prototype,
    check_run_entries,
    check_stop_reason,
    check_tables,
    damaged,
    family_draws,
    restored_parts,
    stop_reason,
)
from .seeding import mdp_rng, noise_seed, optimiser_seed
from .steady_state import SteadyStateNE

__all__ = ["InterruptFlag", "Run"]

#: A race's look-ahead per kernel thread where it cannot park (:class:`RaceSampler`): 4 lane loads of LANES episodes, the
#: best of 0-32 lane loads measured on FGHH (docs/performance.md): more fills the lanes but flies samples never used.
RACE_BATCH_PER_THREAD = 4 * LANES


class InterruptFlag:
    """Context manager: a first Ctrl-C (SIGINT), or a first stop signal the command takes as SIGTERM (the
    :func:`~neurohover.errors.stop_signals` whose handler is :func:`~neurohover.errors.raise_terminated`), sets
    :attr:`set`, so that the run stops at the next generation boundary and saves its checkpoint; a second one raises
    at once (``KeyboardInterrupt``, or :class:`~neurohover.errors.Terminated`). :attr:`signum` is the first signal.
    Outside the main thread it installs no handler."""

    def __init__(self) -> None:
        self.set = False
        self.signum: int | None = None
        self._previous: dict[int, Callable[[int, FrameType | None], Any] | int | None] = {}  # the handlers signal.signal replaced

    def __enter__(self) -> InterruptFlag:
        if threading.current_thread() is threading.main_thread():
            # A SIGTERM raised mid-generation and lost the run, where Ctrl-C saved it (T55-A01); a program's own handler stays.
            taken = [signal.SIGINT, *(s for s in stop_signals() if signal.getsignal(s) is raise_terminated)]
            for signum in taken:
                try:
                    self._previous[signum] = signal.signal(signum, self._handler)
                except ValueError:  # not allowed here (e.g. embedded interpreter)
                    pass
        return self

    def stop(self, signum: int | None = None) -> KeyboardInterrupt:
        """The stop ``signum`` (default: the first signal) asks for: Ctrl-C's ``KeyboardInterrupt``, a stop signal's
        :class:`~neurohover.errors.Terminated` (the command says "terminated", status 128 + the signal)."""
        signum = self.signum if signum is None else signum
        if signum is None or signum == signal.SIGINT:
            return KeyboardInterrupt()
        return Terminated(f"signal {signum}", signum=int(signum))

    def _handler(self, signum, frame) -> None:
        if self.set:
            raise self.stop(signum)
        self.set, self.signum = True, int(signum)

    def __exit__(self, exc_type, exc, tb) -> None:
        for signum, previous in self._previous.items():
            if previous is not None:  # None: a handler not set from Python, which cannot be put back
                signal.signal(signum, previous)
        if self.set and exc_type is None:
            # The signal came after the last generation's check: the run is complete, but the
            # stop must still reach the caller (e.g. a reproduce loop), never be swallowed.
            raise self.stop()


class Run:
    """State of one evolution run (everything a checkpoint holds).

    Parameters
    ----------
    config : RunConfig
        The checked run definition; seeds follow :mod:`neurohover.evolution.seeding`.
    """

    def __init__(self, config: RunConfig, device: str = "cpu") -> None:
        self.cfg = config
        self.mdp, self.family, self.method = config.mdp, config.family, config.method
        self.resampling, self.budget = config.resampling, config.budget
        self.config = config.to_dict()
        # The device is not part of the config (nor of a checkpoint): results agree across devices.
        self.flyer = KernelFlyer(config.topology, noise_seed(config.seed), config.n_steps, device=device)
        self.mdp_rng = None if self.family is None else mdp_rng(config.seed)
        self.rows = None if self.mdp is None else self.mdp.row()[None, :]
        # The scale of one episode's fitness (fitness.py): generational runs choose it, the others fly raw returns.
        self.fitness = config.settings.fitness if self.method == "generational" else "return"
        genome, settings, seed = config.prototype.genome, config.settings, optimiser_seed(config.seed)
        # Classes looked up here at run time (a test may replace SteadyStateNE by a reference).
        self.opt: Optimiser
        if self.method in OPTIMISERS:
            self.opt = OPTIMISERS[self.method].make(genome, settings, seed)
            check_made(self.opt, config.optimizer)  # None was an AttributeError at the first ask (T52-B08)
        elif self.method == "steady-state":
            self.opt = SteadyStateNE(genome, settings, seed=seed)
        else:
            self.opt = GenerationalNE(genome, settings, seed=seed)
        self.history: list[HistoryRecord] = []
        self.generation = 0
        self.evaluations = 0
        self.elapsed = 0.0  # wall seconds of earlier sessions (resume)
        self.champion_genome: np.ndarray | None = None  # a population optimiser on a family: best of the last generation
        self.champion_return = -math.inf
        # On one MDP, the optimiser's champion as last checked (.answers.checked_champion); None: read it from the optimiser
        # (a restored one, whose return check_restored compared with the history's).
        self._held: Held | None = (None, -math.inf)
        self.stop_reason: str | None = None
        self._parking: Parking | None = None  # slots of a race's parked episodes, reused from race to race
        self.race_delta = self.resampling.delta  # race:auto changes it race by race (in the checkpoint)
        self._family_draws = family_draws(self.family)  # None on one MDP and over a shipped family

    # ----------------------------------------------------------------- checkpoints

    def state(self, wall: float) -> dict:
        """The checkpoint (strict JSON) after ``wall`` seconds of the run."""
        return {
            "format": CHECKPOINT_FORMAT,
            "config": self.config,
            "budget": self.budget,
            "optimizer_state": self.opt.state_dict(),
            "counters": {
                "episodes": self.flyer.episodes,
                "next_index": self.flyer.next_index,
                "flown": self.flyer.flown,
                "steps": self.flyer.steps,
                "generation": self.generation,
                "evaluations": self.evaluations,
                "wall_seconds": wall,
                "kernel_seconds": self.flyer.kernel_seconds,
            },
            "mdp_stream": None if self.mdp_rng is None else self.mdp_rng.bit_generator.state,
            "race_delta": self.race_delta,
            "champion": {"genome": None if self.champion_genome is None else self.champion_genome.tolist(), "return": enc_float(self.champion_return)},
            "history": encode_history(self.history),
            "stop_reason": self.stop_reason,
        } | ({} if self._family_draws is None else {"family_draws": self._family_draws})  # a run-time family's G (T55-B10)

    def restore(self, state: dict, source: str) -> None:
        """Continue from checkpoint ``state`` (read from ``source``, named in errors); its run must
        be this one, except the budget. A damaged checkpoint is refused by name, nothing restored."""
        if not isinstance(state, dict) or state.get("format") != CHECKPOINT_FORMAT:
            raise NeurohoverError(f"{source} is not an evolution checkpoint (expected format {CHECKPOINT_FORMAT!r})")
        check_tables(state, source)
        try:
            saved = upgrade_saved_config(state["config"])
            if not isinstance(saved, dict):
                raise TypeError(f"its config is a {type(saved).__name__}, not a table")
        except (KeyError, TypeError, ValueError, AttributeError) as err:
            raise damaged(source, err) from None
        found = [d for k in sorted(set(saved) | set(self.config), key=str) if (d := config_difference(k, saved.get(k), self.config.get(k))) is not None]
        if found:
            values = "; ".join(found)
            raise NeurohoverError(  # the values named, not only their keys (tenth trial)
                f"{source} was written by a different run ({values}); resume with the same "
                "target, method, optimizer, resampling, topology, prototype, seed, episode steps and settings (only the budget may change)"
                + preset_hint(saved, self.config)
            )
        check_family_draws(state, self.family, source)  # the family's name alike, its G too (T55-B10)
        user = self._runtime_optimiser
        written, since = copy.deepcopy(state.get("optimizer_state")) if user else None, time.perf_counter()  # as read: from_state_dict may edit it
        try:
            opt = type(self.opt).from_state_dict(state["optimizer_state"])
        except STATE_DAMAGE as err:  # from_state_dict names the damaged entry; a state's own class may raise more
            raise NeurohoverError(f"{source}: cannot restore the optimiser ({damage_text(err)})") from None
        if user:  # named, not "a damaged checkpoint" (T52-B12); its whole state read back, over a family too (T55-B04)
            check_restored(opt, state, self.cfg, written, since)
        mine, theirs = (getattr(o, "settings", None) for o in (self.opt, opt))  # the state's own copy was flown, unchecked
        if dataclasses.is_dataclass(mine) and dataclasses.is_dataclass(theirs) and not isinstance(mine, type) and not isinstance(theirs, type):
            differs = config_difference("optimizer_state.settings", dataclasses.asdict(theirs), dataclasses.asdict(mine))
            if differs is not None:
                raise NeurohoverError(
                    f"{source} was written by a different run ({differs}): its optimiser's settings are not its config's; resume from an undamaged copy"
                )
        try:
            check_between_generations(opt)
            check_prototype(opt, self.cfg.prototype.genome)
            parts = restored_parts(state, self, opt)
            check_run_entries(state, self.mdp_rng is None)
            check_stop_reason(state, self.method, opt, parts["counters"])
            if self.mdp_rng is not None:
                check_stream(state["mdp_stream"], type(self.mdp_rng.bit_generator).__name__)
                stream = np.random.Generator(type(self.mdp_rng.bit_generator)())
                stream.bit_generator.state = state["mdp_stream"]
        except AnswerError:  # the optimiser's answer (its stop()), not the file
            raise
        except (KeyError, TypeError, ValueError, AttributeError, IndexError, OverflowError) as err:
            raise damaged(source, err) from None
        counts, seconds = parts["counters"], parts["seconds"]
        # a lowered budget stopped it at once "by budget", a plateau's run (seventh trial); its own budget, which the first
        # population may overrun (budget 10, flew 50), resumes finished, as any finished run does (T37-B09)
        if self.budget is not None and counts["episodes"] > self.budget and state.get("budget") != self.budget:
            raise NeurohoverError(
                f"budget {self.budget:,} is below the {counts['episodes']:,} episodes {source}'s run has flown: a resumed run's budget may only be raised "
                f"(give at least {counts['episodes']:,}, or its own budget, {brief(state.get('budget'))})"
            )
        self.opt = opt
        if self.mdp_rng is not None:
            self.mdp_rng = stream
        self.flyer.episodes, self.flyer.steps, self.flyer.next_index, self.flyer.flown = (counts[k] for k in ("episodes", "steps", "next_index", "flown"))
        self.generation, self.evaluations = counts["generation"], counts["evaluations"]
        self.flyer.kernel_seconds, self.elapsed = seconds["kernel_seconds"], seconds["wall_seconds"]
        self.champion_genome, self.champion_return = parts["champion"]
        self._held = None
        self.history = parts["history"]
        self.race_delta = parts["race_delta"]

    # ----------------------------------------------------------------- fitness

    def _fly_fixed(self, genomes: np.ndarray) -> np.ndarray:
        """Fitness of each genome on the fixed MDP: mean of K episodes (fresh episode indices)."""
        n, k, rows = genomes.shape[0], self.resampling.k, self.rows
        assert rows is not None  # only runs on one MDP fly fixed (steady state, CMA-ES on an MDP)
        if k == 1:
            if n == 1:
                return self.flyer.fly(genomes, rows, None, None, 1).copy()
            return self.flyer.fly(genomes, rows, "range", None, n).copy()
        p = np.repeat(np.arange(n, dtype=np.int64), k)
        return self.flyer.fly(genomes, rows, p, None, n * k).reshape(n, k).mean(axis=1)

    def _crashed(self) -> np.ndarray:
        """Whether each genome of the last :meth:`_fly_fixed` crashed (in any of its K episodes)."""
        k = self.resampling.k
        # cast: numpy's stubs allow a scalar from any(axis=1), which a 2-d array never gives
        return self.flyer.crashed.copy() if k == 1 else cast(np.ndarray, self.flyer.crashed.reshape(-1, k).any(axis=1))

    def _fly_family_fixed(self, genomes: np.ndarray):
        """Fixed resampling on G in ONE kernel call: (means, ResamplingResult).

        Column j holds every candidate's j-th episode; episodes and MDPs are numbered column by
        column, i.e. as k consecutive calls of a sample function would number them.
        """
        n, k = genomes.shape[0], self.resampling.k
        p = np.tile(np.arange(n, dtype=np.int64), k)
        rows, family = self.rows, self.family
        if self.mdp_rng is None:  # generational on one MDP: only the episodes' noise differs
            assert rows is not None  # mdp_rng is None exactly when the run has one MDP
            returns = self.flyer.fly(genomes, rows, p, None, n * k).copy()
        else:
            assert family is not None  # mdp_rng is set exactly when the run has a family
            returns = self.flyer.fly(genomes, family.sample_rows(self.mdp_rng, n * k), p, "range", n * k).copy()
        cols = episode_fitness(returns, self.fitness).reshape(k, n)
        calls = iter(range(k))
        result = fixed_resampling(lambda idx: cols[next(calls)], n, k)
        return result.means, result

    def _race_sampler(self, genomes: np.ndarray, mu: int) -> RaceSampler:
        """A race's ``sample_fn`` in which candidate i's t-th episode is fixed: episode index
        ``base + t * n + i`` and MDP row ``t * n + i``, reserved and drawn when the race starts, so
        parking or look-ahead (which fly samples the race may not use) change no result."""
        n = genomes.shape[0]
        base = self.flyer.reserve(n * RACE_T_LIMIT)
        if self.family is None:
            assert self.rows is not None  # a run has one MDP (its rows) or a family
            rows = self.rows
        else:
            assert self.mdp_rng is not None  # set exactly when the run has a family
            rows = self.family.sample_rows(self.mdp_rng, n * RACE_T_LIMIT)
        parking = None
        if self.flyer.can_park(rows):
            if self._parking is None or self._parking.steps.shape[0] < n * RACE_T_LIMIT:
                self._parking = Parking.empty(n * RACE_T_LIMIT)
            parking = self._parking
        look_ahead = RACE_BATCH_PER_THREAD * self.flyer.max_threads
        return RaceSampler(self.flyer, genomes, rows, base, self.family is not None, self.fitness, RACE_T_LIMIT, mu, look_ahead, parking)

    # ----------------------------------------------------------------- loop

    def run(self, progress, checkpoint: Path | None, checkpoint_every_s: float, progress_every_s: float) -> None:
        """Fly generations until a stop reason (:meth:`_should_stop`), reporting ``progress`` and
        writing ``checkpoint``; on an interrupt, save it and raise :class:`EvolutionInterrupted`."""
        start = time.perf_counter() - self.elapsed
        flag_every = checkpoint_every_s if checkpoint is not None else math.inf
        next_ckpt = time.perf_counter() + flag_every
        next_progress = time.perf_counter() + progress_every_s
        budget = self.budget
        if checkpoint is not None:  # a state JSON cannot write, refused before anything flies (T40-B06)
            self._check_state_json(self.opt.state_dict())
        if self.method == "generational":
            step = self._generational_generation
        elif self.method == "steady-state" or self.family is None:
            step = self._best_ever_generation
        else:
            step = self._population_family_generation
        boundary = True  # False while a generation is half done (its state is not checkpointable)
        with InterruptFlag() as flag:
            try:
                while True:
                    reason = self._should_stop()
                    if reason is not None:
                        self.stop_reason = reason
                        break
                    boundary = False
                    step(start)
                    boundary = True
                    now = time.perf_counter()
                    if flag.set:
                        raise flag.stop()  # Terminated for SIGTERM: the command says so, status 143 (T55-A01)
                    if now >= next_progress and progress is not None:
                        next_progress = now + progress_every_s
                        progress(self._info(now - start, False, budget))
                    if checkpoint is not None and now >= next_ckpt:  # (next_ckpt is inf without a checkpoint)
                        self._write_checkpoint(checkpoint, now - start)
                        next_ckpt = time.perf_counter() + flag_every
            except KeyboardInterrupt:
                # At a generation boundary (a first Ctrl-C or SIGTERM, or the progress callback) the state is
                # whole and is saved; a second one mid-generation leaves the last periodic checkpoint.
                if not boundary or checkpoint is None:
                    raise EvolutionInterrupted(None, self.flyer.episodes) from None
                self._write_checkpoint(checkpoint, time.perf_counter() - start)
                raise EvolutionInterrupted(checkpoint, self.flyer.episodes) from None
        wall = time.perf_counter() - start
        self.elapsed = wall
        if checkpoint is not None:
            self._write_checkpoint(checkpoint, wall)
        if progress is not None:
            try:
                progress(self._info(wall, True, budget))
            except KeyboardInterrupt:  # the run has ended (and its checkpoint is written): its result goes with the interrupt (T28-B08)
                raise EvolutionInterrupted(checkpoint, self.flyer.episodes, self.result()) from None

    def _info(self, wall: float, done: bool, budget) -> ProgressInfo:
        eps = self.flyer.episodes
        return ProgressInfo(self.generation, self.evaluations, eps, budget, self._champion_return(), wall, eps / wall if wall > 0 else 0.0, done)

    def _should_stop(self) -> str | None:
        return stop_reason(self.method, self.opt, self.budget, self.flyer.episodes, self.generation)

    def _record(self, before_eps: int, champion: float, start: float) -> None:
        self.history.append(
            HistoryRecord(self.generation, self.evaluations, self.flyer.episodes, self.flyer.episodes - before_eps, champion, time.perf_counter() - start)
        )

    def _best_ever_generation(self, start: float) -> None:
        """Steady state, or a population optimiser on an MDP: the champion is the best single fitness ever told;
        a record per new champion."""
        opt = self.opt
        # A run-time optimiser's champion is checked against what the run flew (T54-B03, B06); the shipped ones' answers
        # are the package's own (tested), and the check cost a steady-state run of 200-step episodes 14 % of its time.
        user = self._runtime_optimiser
        if self._held is None:
            self._held = held_champion(opt, self.cfg) if user else (None, self._told_champion())
        before = self._held[1]
        before_eps = self.flyer.episodes
        genomes = self._asked()
        returns = self._fly_fixed(genomes)
        asked = genomes.copy() if user else genomes  # (an optimiser may reuse its ask()'s array in its tell)
        opt.tell(read_only(returns), TellInfo(crashed=self._crashed()))  # tell writing into it changed the run's records (T54-B04)
        self.generation += 1
        self.evaluations += genomes.shape[0]
        self._held = checked_champion(opt, self.cfg, self._held, asked, returns) if user else (None, self._told_champion())
        champion = self._held[1]
        if champion != before:
            self._record(before_eps, champion, start)

    def _generational_generation(self, start: float) -> None:
        """Generational NE: fixed resampling or a selection race; a record per generation."""
        opt = cast(GenerationalNE, self.opt)
        before_eps = self.flyer.episodes
        genomes = self._asked()
        if self.resampling.selects:
            delta = self.race_delta
            assert delta is not None  # every race has its delta (Run() formats it in config.to_dict() first)
            sampler = self._race_sampler(genomes, opt.settings.select_size)
            traced = None if self.flyer.trace is None else len(self.flyer.trace)
            size = (genomes.shape[0], opt.settings.select_size)
            if self.resampling.kind in BANDITS:  # the two least certain candidates a round (neurohover.evolution.bandits)
                race = top_mu_bandit(sampler, *size, delta, rule=self.resampling.kind, t_limit=RACE_T_LIMIT)
            else:
                race = selection_race(sampler, *size, delta, t_limit=RACE_T_LIMIT, batch=sampler.batch, rule=self.resampling.rule)
            # Count the episodes the race used (parking or look-ahead flew more): what depends on no speed setting.
            self.flyer.episodes += race.episodes_spent
            if self.resampling.auto:  # the next race's delta, from this one's cost against fixed:K's
                self.race_delta = next_auto_delta(delta, race.episodes_spent, self.resampling.k * genomes.shape[0])
            used = sampler.used(race.n_samples)
            self.flyer.steps += int(sampler.slot_steps[used].sum())
            if self.flyer.trace is not None:  # for benchmarks: the race's calls replaced by the episodes it used
                del self.flyer.trace[traced:]
                m = used if self.family is not None else np.zeros_like(used)
                self.flyer.trace.append((genomes.copy(), sampler.rows, used % genomes.shape[0], m, sampler.base + used))
            opt.tell(race.means, TellInfo(selected=race.selected, episodes=race.episodes_spent))
        else:
            _, result = self._fly_family_fixed(genomes)
            opt.tell(result.means, TellInfo(episodes=result.episodes_spent))
        self.generation += 1
        self.evaluations += genomes.shape[0]
        self._record(before_eps, opt.champion_return, start)

    def _population_family_generation(self, start: float) -> None:
        """A population optimiser on a family: the champion is the best estimate of the last generation (a
        best-ever maximum over noisy estimates would be biased); a record per generation."""
        opt = self.opt
        before_eps = self.flyer.episodes
        genomes = self._asked()
        means, _ = self._fly_family_fixed(genomes)
        key = np.where(np.isnan(means), -np.inf, means)
        best = int(np.argmax(key))
        champion = genomes[best].copy(), float(key[best])  # before tell, which may reuse its ask()'s array
        opt.tell(read_only(means))  # tell writing into it changed the run's records (T54-B04)
        self.champion_genome, self.champion_return = champion
        self.generation += 1
        self.evaluations += genomes.shape[0]
        self._record(before_eps, self.champion_return, start)

    # ----------------------------------------------------------------- a user optimiser's answers, checked (.answers)

    def _asked(self) -> np.ndarray:
        return asked_genomes(self.opt, self.cfg)

    @property
    def _runtime_optimiser(self) -> bool:
        """Whether the run's optimiser is one registered at run time (its answers are checked against what the run flew,
        its restored state against the checkpoint's), not a shipped one."""
        return self.method in OPTIMISERS and self.method not in SHIPPED

    def _told_champion(self) -> float:
        return told_champion(self.opt, self.cfg)

    def _write_checkpoint(self, path: Path, wall: float) -> None:
        """Write the checkpoint after ``wall`` seconds; an optimiser state JSON cannot write refused by its key (T40-B06)."""
        state = self.state(wall)
        refuse_replaced(path, state)  # a policy file a progress callback saved there (T47-B13)
        check_state_nesting(state["optimizer_state"], self.cfg.optimizer)  # a state turned 900 deep was written, and never resumed (T61-B02)
        try:
            write_checkpoint(path, state)
        except (TypeError, ValueError) as err:
            if not isinstance(err, NeurohoverError):
                self._check_state_json(state["optimizer_state"])
            raise

    def _check_state_json(self, state: Any) -> None:
        check_state_json(state, self.cfg.optimizer)

    # ----------------------------------------------------------------- result

    def _history_with_last(self) -> tuple[HistoryRecord, ...]:
        """The history plus, if the last generation made no record, one for it (not checkpointed)."""
        history = list(self.history)
        if self.generation and (not history or history[-1].generation != self.generation):
            last = history[-1] if history else None
            history.append(
                HistoryRecord(
                    self.generation,
                    self.evaluations,
                    self.flyer.episodes,
                    0 if last is None else self.flyer.episodes - last.episodes,
                    self._champion_return(),
                    self.elapsed,
                )
            )
        return tuple(history)

    def _champion_return(self) -> float:
        if self.method in OPTIMISERS and self.family is not None:
            return self.champion_return
        return self._told_champion()

    def _champion_genome(self) -> np.ndarray | None:
        if self.method in OPTIMISERS and self.family is not None:
            return self.champion_genome
        return checked_champion_genome(self.opt, self.cfg)

    def result(self) -> EvolutionResult:
        """The run's :class:`EvolutionResult` (NeurohoverError if no candidate had a finite fitness)."""
        genome = self._champion_genome()
        if genome is None:
            raise NeurohoverError("the evolution found no candidate with a finite fitness")
        ret = self._champion_return()
        settings = {**self.config, "budget": self.budget}
        settings.pop("prototype")
        target = self.config["target"]
        label = target["mdp"]["label"] if target["kind"] == "mdp" else f"{target['family']}/G" + (f"(sigma={target['sigma']:g})" if "sigma" in target else "")
        cfg = self.cfg
        method, optimizer = recorded_names(cfg.optimizer) if cfg.optimizer in OPTIMISERS else (self.method, cfg.optimizer)
        sensor = cfg.mdp.sensor if cfg.mdp is not None else cfg.family.sensor if cfg.family is not None else None
        meta = {
            **({} if sensor is None or sensor.exact else {"sensor": sensor.to_dict()}),  # what the run saw through: the API's and the CLI's (T41-B08)
            "method": method,
            "optimizer": optimizer,
            "resampling": str(self.resampling),
            "target": label,
            "seed": cfg.seed,
            "budget": self.budget,
            "episodes": self.flyer.episodes,
            "evaluations": self.evaluations,
            "generations": self.generation,
            "champion_return": ret,
            "n_steps": cfg.n_steps,
            "stop_reason": self.stop_reason,
        }
        # The champion records this run alone: a seed policy's own record (its sigma, MDP, validation) is another run's
        # (T25-12); only where the lineage started, its "prototype" (zero or baseline), is carried on.
        start = {"prototype": cfg.prototype.metadata["prototype"]} if "prototype" in cfg.prototype.metadata else {}
        champion = Policy(cfg.topology, np.array(genome, dtype=float), {**start, **meta})
        return EvolutionResult(
            champion,
            ret,
            self._history_with_last(),
            self.flyer.episodes,
            self.flyer.steps,
            self.evaluations,
            self.generation,
            self.elapsed,
            self.flyer.kernel_seconds,
            self.stop_reason or "",
            settings,
            bool(getattr(self.opt, "champion_crashed", False)),
            parents=getattr(self.opt, "parents", None),
            hall_of_fame=getattr(self.opt, "hall_of_fame", None),
        )
