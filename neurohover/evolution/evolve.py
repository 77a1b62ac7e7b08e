"""Whole evolution runs on the batched kernel: :func:`evolve` (docs/model.md, Neuroevolution).

Two kinds of target
-------------------
* a fixed :class:`~neurohover.tasks.MDP` (a GHH-08/09 MDP, any explicit MDP, or a learned model's
  ``.mdp()``; a :class:`~neurohover.models.LearnedModel` itself is accepted too): the
  **steady-state** method of Appendix A (Table 6 defaults). A candidate's fitness is the return of
  one episode, or the mean of ``K`` episodes with ``resampling="fixed:K"``. The run stops when no
  new champion appeared in ``plateau_threshold`` evaluations, or at the episode budget. By default
  (``plateau_rule="no-crash"``) those evaluations count only while the champion's own evaluation
  did not crash (with ``fixed:K``: none of its K episodes crashed), so a run whose champion still
  crashes ends only at its budget; ``plateau_rule="literal"`` is Appendix A as written.
* a task family G (``get_task_family("fghh", 0.3)``; any family works): the **generational**
  method of Appendix B (Table 7 defaults) for generic policies, as the authors' FGHH code ran it:
  SLP networks from the baseline, each episode scored ``1/ln(error)`` and a candidate's estimate
  the mean over its episodes (``fitness="return"``: mean raw returns), no surviving parents.
  Fitness is estimated by fixed resampling (``"fixed:K"``: K episodes per candidate, each on a
  fresh MDP drawn from G) or by selection races (``"race:DELTA"``, docs/model.md, Fitness under
  noise; confidence level DELTA in (0, 1)), whose bounds are then on the fitness scale too.

``optimizer="cma"`` (CMA-ES, pycma) or ``"openai-es"`` (OpenAI-ES), or any population optimiser
of the registry (:mod:`neurohover.evolution.optimisers`), replaces the neuroevolution on either
target with the same budget semantics and the same fixed resampling, so they can be compared on
equal episodes.

Budget, evaluations, champion
-----------------------------
The budget counts **episodes flown** (one evaluation with ``fixed:K`` costs K episodes). It is
checked between generations, so a run may overshoot it by at most one generation (the steady-state
method's first generation is the whole initial population of ``pop_size`` candidates). The
champion is, as in the optimisers, the candidate with the best single fitness ever told for a fixed
MDP (steady state; a population optimiser on an MDP), and the candidate with the best estimate of the last
generation for a task family (generational: the best selected parent; a population optimiser on a family), because a best-ever maximum over
noisy estimates of different MDPs is optimistically biased.

Seeding and reproducibility
---------------------------
Everything random derives from ``numpy.random.SeedSequence(seed)``: child ``(0,)`` seeds the
optimiser, ``(1,)`` the stream of MDPs drawn from G, ``(2,)`` the root of the episodes' gust noise
(:mod:`neurohover.evolution.seeding`). Every episode flown gets the next index of an episode
counter (its noise stream is ``(noise root, index)``; a selection race reserves λ·t_limit indices
and MDPs at its start, candidate i's t-th sample being index ``base + t·λ + i``), so no two
episodes of a run share noise and the result depends neither on the number of kernel threads nor
on how a race batches its episodes.

Checkpoints
-----------
With ``checkpoint=PATH`` the run writes, at most every ``checkpoint_every_s`` seconds, at its end,
and when interrupted, a JSON file (``neurohover-evolution-checkpoint/1``) with the optimiser's
``state_dict`` (CMA-ES: its pickled pycma state, base64), the episode counter, the MDP stream's
state and the history, atomically (written to ``PATH.PID.TID.tmp``, then ``os.replace``). ``resume=True``
continues from it bit-for-bit (same champion, history and counters as an uninterrupted run); the
run's configuration must match the checkpoint's, except the budget, which may be raised.
Interrupts (Ctrl-C, a stop signal the command takes as SIGTERM: SIGTERM, SIGHUP, SIGUSR1, or a
``KeyboardInterrupt`` raised by the ``progress`` callback) take effect at the next generation boundary:
the checkpoint is written and :class:`EvolutionInterrupted` (a ``KeyboardInterrupt``; raised from
:class:`~neurohover.errors.Terminated` for a stop signal) is raised; a second one stops at once without writing.

Modules
-------
This module is the public entry point; the run itself lives in :mod:`~neurohover.evolution.config`
(what defines a run), :mod:`~neurohover.evolution.run` (the loop), :mod:`~neurohover.evolution.records`
(results, history, checkpoint files) and :mod:`~neurohover.evolution.seeding`; the candidates fly
through :class:`neurohover.flyer.KernelFlyer`.

Example
-------
>>> from neurohover.tasks import get_task_family
>>> from neurohover.evolution.evolve import evolve
>>> result = evolve(get_task_family("ghh08").mdp("train:0"), topology="mlp", budget=300, seed=1, n_steps=300)
>>> result.champion.topology, result.episodes >= 300
('mlp', True)
"""

from __future__ import annotations

import contextlib
import math
import os
import warnings
from collections.abc import Callable
from pathlib import Path

import numba
import numpy as np

from ..errors import CheckpointReplaced, NeurohoverError, brief, check_arity, check_flag, real_number, whole_in
from ..evaluate import MAX_EPISODES_PER_CALL, evaluate_jobs, num_threads
from ..filekinds import held_kind
from ..paths import output_file, sole_writer
from ..policies import Policy
from ..sim.constants import EPISODE_STEPS
from ..tasks import MDP
from .config import CMA_DEFAULTS, Resampling, RunConfig, parse_resampling, resolve_target
from .fitness import episode_fitness
from .records import (
    CHECKPOINT_FORMAT,
    CHECKPOINT_KIND,
    HISTORY_COLUMNS,
    EvolutionInterrupted,
    EvolutionResult,
    HistoryRecord,
    ProgressInfo,
    check_resumed_checkpoint,
    read_checkpoint,
    read_history_csv,
    write_history_csv,
)
from .run import Run
from .seeding import check_seed, reevaluation_seeds, validation_seeds

__all__ = [
    "CHECKPOINT_FORMAT",
    "CMA_DEFAULTS",
    "HISTORY_COLUMNS",
    "EvolutionInterrupted",
    "EvolutionResult",
    "HistoryRecord",
    "ProgressInfo",
    "Resampling",
    "evolve",
    "parse_resampling",
    "read_history_csv",
    "REEVALUATION_POOLS",
    "reevaluated_champion",
    "validation_return",
    "write_history_csv",
]


#: What ``checkpoint_every_s=None`` and ``progress_every_s=None`` stand for (seconds).
CHECKPOINT_EVERY_S, PROGRESS_EVERY_S = 60.0, 0.2


def _intervals(checkpoint, checkpoint_every_s, progress, progress_every_s) -> tuple[float, float]:
    """The seconds between checkpoints and between progress calls, checked: a number (not a bool: True was 1 second),
    and given only with its ``checkpoint`` / ``progress`` (alone it was ignored without a word; T17-9)."""
    if checkpoint_every_s is None:
        checkpoint_every_s = CHECKPOINT_EVERY_S
    elif not real_number(checkpoint_every_s) or not checkpoint_every_s > 0:
        raise NeurohoverError(f"checkpoint_every_s={brief(checkpoint_every_s)} must be a number > 0 (seconds), or None ({CHECKPOINT_EVERY_S:g})")
    elif checkpoint is None:
        raise NeurohoverError(f"checkpoint_every_s={brief(checkpoint_every_s)} needs checkpoint= (the file it writes): give both, or neither")
    if progress_every_s is None:
        progress_every_s = PROGRESS_EVERY_S
    elif not real_number(progress_every_s) or not 0 <= progress_every_s < math.inf:
        # np.array(0.1), refused for its type, was called out of range (T33-B16)
        refused = "is out of range" if real_number(progress_every_s) else "is not a number"
        raise NeurohoverError(
            f"progress_every_s={brief(progress_every_s)} {refused}: allowed a finite number of seconds >= 0 (0: every generation), "
            f"or None ({PROGRESS_EVERY_S:g})"
        )
    elif progress is None:
        raise NeurohoverError(f"progress_every_s={brief(progress_every_s)} needs progress= (the callable it paces): give both, or neither")
    return float(checkpoint_every_s), float(progress_every_s)


def _checkpoint_path(checkpoint, progress, resume: bool) -> Path | None:
    """Check the checkpoint and progress options; the checkpoint's path, made absolute once, as the run starts: a
    relative one was resolved at every write, and after an os.chdir the checkpoint went to another folder (T34-B10)."""
    if progress is not None and not callable(progress):  # progress=3 was "'int' object is not callable" mid-run (second trial)
        raise NeurohoverError(f"progress={progress!r:.60} is not allowed: give a callable taking a ProgressInfo, or None")
    # a wrong arity failed after the first generation (T40-B02)
    check_arity("progress", progress, 1, "the run calls progress(info)", "a callable of one ProgressInfo, or None")
    check_flag(resume, "resume", "continue from the checkpoint")  # resume="no" resumed (its truth), fifteenth trial
    if checkpoint is None or resume:
        path = None if checkpoint is None else Path(checkpoint)
    else:  # checked before the run; a JSON name, no file of another kind (a model file was replaced; T28-B07)
        path = output_file(checkpoint, "checkpoint", kind=CHECKPOINT_KIND, suffixes=(".json",), what="a checkpoint is JSON")
        if path.is_file() and path.stat().st_size and held_kind(path) != CHECKPOINT_KIND:  # notes.json was replaced (T46-B14)
            raise NeurohoverError(
                f"checkpoint {os.fspath(checkpoint)!r} is a file neurohover did not write: give another path (writing {CHECKPOINT_KIND} there would destroy it)"
            )
    if resume and path is None:
        raise NeurohoverError("resume=True needs the checkpoint path")
    if resume and path is not None:
        check_resumed_checkpoint(path)  # a directory or a pipe was "does not exist" (T46-B13)
    return None if path is None else path.absolute()


def _prepare(run: Run, path: Path | None, resume: bool, threads: int | None, device: str, trace: list | None) -> None:
    """Restore the run from its checkpoint ``path`` on ``resume``, and load (or compile) the kernel before the run's clock
    starts (which also validates the thread count)."""
    if resume:
        assert path is not None  # _checkpoint_path refused resume without one
        run.restore(read_checkpoint(path), f"checkpoint {str(path)!r}")
        run.stop_reason = None
    run.flyer.trace = trace
    if run.rows is not None:
        warm_up: np.ndarray | MDP = run.rows
    else:
        assert run.family is not None  # a run has one MDP (its rows) or a family
        warm_up = run.family.zero()
    evaluate_jobs([run.cfg.prototype], warm_up, [0], [0], [0], n_steps=1, threads=threads, device=device)


def evolve(
    target,
    *,
    topology: str | None = None,
    prototype: Policy | str = "baseline",
    optimizer: str = "ne",
    resampling: str | Resampling | None = None,
    budget: int | None = None,
    settings=None,
    seed: int = 0,
    n_steps: int = EPISODE_STEPS,
    threads: int | None = None,
    device: str = "cpu",
    progress: Callable[[ProgressInfo], None] | None = None,
    checkpoint: str | Path | None = None,
    checkpoint_every_s: float | None = None,
    resume: bool = False,
    method: str | None = None,
    progress_every_s: float | None = None,
    _trace: list | None = None,
    _flown: dict | None = None,
) -> EvolutionResult:
    """Run a whole evolution on the batched kernel and return its champion and history.

    Parameters
    ----------
    target : MDP, LearnedModel or task family
        A fixed MDP (steady state) or a task family G (generational); see the module doc.
    topology : {"slp", "mlp"}, optional
        Default: the prototype policy's; else ``"slp"`` on a task family (the authors' FGHH
        generics are SLPs) and ``"mlp"`` on one MDP.
    prototype : Policy or {"zero", "baseline"}
        The genome the initial population is built from.
    optimizer : {"ne", "cma", "openai-es", "uh-cma"} or another registered name
        The paper's neuroevolution, or a population optimiser (:mod:`neurohover.evolution.optimisers`)
        with the same budget and resampling.
    resampling : str, optional
        ``"fixed:K"`` (default ``fixed:1``) or ``"race:DELTA"`` (generational NE on a family only).
    budget : int, optional
        Episodes to fly (checked between generations). Default: a settings object's ``budget`` (both
        given and different is refused), else the paper's termination (steady state: plateau;
        generational: ``generations``; CMA-ES: pycma's criteria; OpenAI-ES has none: give a budget).
    settings : SteadyStateSettings, GenerationalSettings, dict or str, optional
        Overrides of the optimiser settings (paper Tables 6/7): a settings object, a dict of
        fields, or for the generational method a preset's name (``"table7"``, the default;
        ``"authors-script"``; ``"raw-elitist"``; a dict may start from one with ``"preset"``),
        including the fitness scale (``fitness="inv-log-error"`` or ``"return"``); for a population
        optimiser its settings object or a dict of its fields (CMA-ES: ``sigma0``, ``popsize``,
        :data:`CMA_DEFAULTS`; OpenAI-ES: :class:`~neurohover.evolution.optimisers.openai_es.OpenAIESSettings`).
    seed : int
        Root of all randomness (``numpy.random.SeedSequence(seed)``).
    n_steps : int
        Control steps per episode (6000 in the paper).
    threads : int, optional
        Kernel threads (default: all cores); results do not depend on it. Unused on ``"cuda"``.
    device : {"cpu", "cuda"}
        Where the candidates fly: the CPU kernel (default) or its CUDA build on a GPU (:class:`~neurohover.flyer.KernelFlyer`);
        results agree to within docs/gpu.md's tolerance. Not part of the run's config: a checkpoint resumes on either device.
    progress : callable, optional
        Called with a :class:`ProgressInfo` after a generation at most every ``progress_every_s``
        seconds and at the end; may raise ``KeyboardInterrupt`` to stop the run (the checkpoint is
        written first).
    checkpoint : path, optional
        Checkpoint file, written every ``checkpoint_every_s`` seconds, at the end and on interrupt. A relative path
        is taken from the folder current when the run starts; while it runs, another run on the same checkpoint is
        refused (a writer lock, ``.NAME.lock`` beside it, as the CLI's ``--out``). A file there that is no checkpoint
        (another neurohover kind, or one neurohover did not write) is refused, not replaced; an empty file is taken.
    checkpoint_every_s : float, optional
        Seconds between checkpoints (> 0; ``math.inf``: only at the end and when stopped); None: 60. Only with ``checkpoint``.
    resume : bool
        Continue from ``checkpoint`` (which must exist); False replaces one, with a ``CheckpointReplaced`` warning.
    method : {"steady-state", "generational"}, optional
        Default: steady state for an MDP, generational for a family.
    progress_every_s : float, optional
        Seconds between ``progress`` calls (>= 0; 0: every generation); None: 0.2. Only with ``progress``.
    _trace, _flown : list, dict, optional
        For benchmarks: receive every kernel call's jobs (:attr:`KernelFlyer.trace <neurohover.flyer.KernelFlyer>`),
        and ``steps``, the control steps the kernel flew (a race flies some it does not use).

    Raises
    ------
    NeurohoverError
        Bad input, or a checkpoint that does not match the run.
    EvolutionInterrupted
        On Ctrl-C, a stop signal (SIGTERM, SIGHUP, SIGUSR1) or a ``KeyboardInterrupt`` from ``progress`` (from its last
        call, ``done``: with the run's ``result``).
    """
    cfg = RunConfig.build(
        target, topology=topology, prototype=prototype, optimizer=optimizer, resampling=resampling, budget=budget, settings=settings, seed=seed,
        n_steps=n_steps, method=method,
    )  # fmt: skip
    every_checkpoint, every_progress = _intervals(checkpoint, checkpoint_every_s, progress, progress_every_s)
    run = Run(cfg, device=device)
    path = _checkpoint_path(checkpoint, progress, resume)
    _fly_run(run, path, resume, threads, device, _trace, lambda: run.run(progress, path, every_checkpoint, every_progress))
    if _flown is not None:
        _flown["steps"] = run.flyer.flown_steps
    return run.result()


def _fly_run(run: Run, path: Path | None, resume: bool, threads: int | None, device: str, trace: list | None, fly: Callable[[], None]) -> None:
    """Prepare ``run`` (resumed from ``path`` if asked) and ``fly()`` it on ``threads``, holding its checkpoint's writer lock
    throughout: one run on a checkpoint at a time, as the CLI's --out (two both ran and overwrote it; T34-B08)."""
    with contextlib.ExitStack() as held:
        if path is not None:
            held.enter_context(sole_writer(path, "checkpoint"))
            # once the lock is held: a run refused as a second writer warned first that it replaced the checkpoint (T43-B16);
            # a notebook's cell run again replaced an unfinished run's without a word (T38-B08), as the CLI says
            if not resume and path.is_file() and path.stat().st_size:  # an empty file holds no run's checkpoint (T46-B14)
                warnings.warn(f"checkpoint {str(path)!r} holds a run's checkpoint: this run starts afresh and replaces it (resume=True continues it)",
                              CheckpointReplaced, stacklevel=3)  # fmt: skip
        _prepare(run, path, resume, threads, device, trace)
        with num_threads(threads if threads is not None else numba.get_num_threads()):  # restores the count after
            run.flyer.start()
            fly()


def validation_return(
    policy: Policy, target, *, episodes: int = 10, seed: int = 0, n_steps: int = EPISODE_STEPS, threads: int | None = None, device: str = "cpu"
) -> np.ndarray:
    """Returns of ``episodes`` fresh episodes of ``policy``: on the MDP, or each on a fresh MDP from G.

    The noise and MDPs come from ``SeedSequence(seed)`` child ``(3,)``, which :func:`evolve` never
    uses, so these episodes are independent of the ones the run flew. ``device`` as in :func:`evolve`.
    """
    noise_seed, mdp_seed = validation_seeds(check_seed(seed))
    rows, m_idx = _fresh_episodes(target, episodes, mdp_seed, "validation_return")
    ev = evaluate_jobs(
        [policy], rows, np.zeros(episodes, dtype=np.int64), m_idx, np.arange(episodes), seed=noise_seed, n_steps=n_steps, threads=threads, device=device
    )
    return ev.returns


def _fresh_episodes(target, episodes: int, mdp_seed: int, caller: str) -> tuple[np.ndarray, np.ndarray]:
    """The kernel rows and each episode's row index of ``episodes`` fresh episodes of ``target``: all on its MDP, or
    each on a fresh MDP from G drawn with ``mdp_seed``."""
    mdp, family, _ = resolve_target(target, caller)
    # T24-11: whole_in, so 1.5 or True "is not allowed" and 0 "is out of range"; the bound check_episode_count had
    episodes = whole_in(episodes, "episodes", 1, MAX_EPISODES_PER_CALL, f"{MAX_EPISODES_PER_CALL:,} (episodes in one call)")
    if mdp is not None:
        return mdp.row()[None, :], np.zeros(episodes, dtype=np.int64)
    assert family is not None  # resolve_target gives an MDP or a family
    return family.sample_rows(np.random.default_rng(mdp_seed), episodes), np.arange(episodes)


#: The candidates :func:`reevaluated_champion` chooses among: the last generation's selected parents, or the run's
#: best generation champions by estimate (its hall of fame).
REEVALUATION_POOLS = ("last", "best-ever")


def reevaluated_champion(
    result: EvolutionResult,
    target,
    *,
    episodes: int,
    among: str = "last",
    n_steps: int = EPISODE_STEPS,
    threads: int | None = None,
    device: str = "cpu",
) -> tuple[Policy, np.ndarray]:
    """The run's champion chosen again: the last generation's selected parents (``among="last"``, ``result.parents``)
    or the run's best generation champions by estimate (``"best-ever"``, ``result.hall_of_fame``), each flown the
    same ``episodes`` fresh episodes (each on a fresh MDP from G, or on the MDP), the best mean fitness on the run's
    scale winning (ties: the first parent). A generation's champion is otherwise the best of its noisy estimates,
    the luckiest of mu short ones where no candidate is decided; these episodes come from ``SeedSequence(seed)``
    child ``(4,)`` of the run's seed, which the run and :func:`validation_return` never use.

    Returns the chosen policy (its metadata the run's champion's, with ``reevaluated_from`` = its index in the
    pool) and every candidate's mean fitness over the episodes.
    """
    if not isinstance(among, str) or among not in REEVALUATION_POOLS:  # text first: an array's `in` was NumPy's error (sixteenth trial)
        raise NeurohoverError(f"among={brief(among)} is not allowed: choose one of {', '.join(REEVALUATION_POOLS)}")
    pool = result.parents if among == "last" else result.hall_of_fame
    if pool is None or len(pool) == 0:
        raise NeurohoverError("the run has no selected parents to choose from again: generational evolution keeps them, other methods do not")
    noise_seed, mdp_seed = reevaluation_seeds(check_seed(int(result.settings["seed"])))
    rows, m = _fresh_episodes(target, episodes, mdp_seed, "reevaluated_champion")
    k = len(pool)
    champion = result.champion
    policies = [Policy(champion.topology, np.array(g, dtype=float), champion.metadata) for g in pool]
    p_idx, m_idx, e_idx = np.repeat(np.arange(k), episodes), np.tile(m, k), np.tile(np.arange(episodes), k)
    ev = evaluate_jobs(policies, rows, p_idx, m_idx, e_idx, seed=noise_seed, n_steps=n_steps, threads=threads, device=device)
    scale = result.settings.get("settings", {}).get("fitness", "return") if result.settings.get("method") == "generational" else "return"
    means = episode_fitness(np.asarray(ev.returns).reshape(k, episodes), scale).mean(axis=1)
    best = int(np.argmax(means))
    chosen = policies[best]
    return Policy(chosen.topology, chosen.genome, {**champion.metadata, "reevaluated_from": best}), means
