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
  method of Appendix B (Table 7 defaults), for generic policies. Fitness is estimated by fixed
  resampling (``"fixed:K"``: K episodes per candidate, each on a fresh MDP drawn from G) or by
  selection races (``"race:DELTA"``, docs/model.md, Fitness under noise; confidence level DELTA in (0, 1)).

``optimizer="cma"`` replaces the neuroevolution by CMA-ES (pycma) on either target with the same
budget semantics and the same fixed resampling, so the two can be compared on equal episodes.

Budget, evaluations, champion
-----------------------------
The budget counts **episodes flown** (one evaluation with ``fixed:K`` costs K episodes). It is
checked between generations, so a run may overshoot it by at most one generation (the steady-state
method's first generation is the whole initial population of ``pop_size`` candidates). The
champion is, as in the optimisers, the candidate with the best single fitness ever told for a fixed
MDP (steady state; CMA-ES on an MDP), and the candidate with the best estimate of the last
generation for a task family (generational; CMA-ES on a family), because a best-ever maximum over
noisy estimates of different MDPs is optimistically biased.

Seeding and reproducibility
---------------------------
Everything random derives from ``numpy.random.SeedSequence(seed)``: child ``(0,)`` seeds the
optimiser, ``(1,)`` the stream of MDPs drawn from G, ``(2,)`` the root of the episodes' gust noise.
Every episode flown gets the next index of an episode counter (its noise stream is
``(noise root, index)``), so no two episodes of a run share noise and the result does not depend
on the number of kernel threads.

Checkpoints
-----------
With ``checkpoint=PATH`` the run writes, at most every ``checkpoint_every_s`` seconds, at its end,
and when interrupted, a JSON file (``neurohover-evolution-checkpoint/1``) with the optimiser's
``state_dict`` (CMA-ES: its pickled pycma state, base64), the episode counter, the MDP stream's
state and the history, atomically (written to ``PATH.tmp``, then ``os.replace``). ``resume=True``
continues from it bit-for-bit (same champion, history and counters as an uninterrupted run); the
run's configuration must match the checkpoint's, except the budget, which may be raised.
Interrupts (Ctrl-C, or ``KeyboardInterrupt`` raised by the ``progress`` callback) take effect at
the next generation boundary: the checkpoint is written and :class:`EvolutionInterrupted` (a
``KeyboardInterrupt``) is raised; a second Ctrl-C stops at once without writing.

Example
-------
>>> from neurohover.tasks import get_task_family
>>> from neurohover.evolution.evolve import evolve
>>> result = evolve(get_task_family("ghh08").mdp("train:0"), topology="mlp", budget=300, seed=1, n_steps=300)
>>> result.champion.topology, result.episodes >= 300
('mlp', True)
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
import pickle
import signal
import threading
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numba
import numpy as np

from ..errors import NeurohoverError
from ..evaluate import evaluate_jobs, num_threads
from ..policies import GENOME_LENGTH, TOPOLOGIES, Policy, prototype as make_prototype
from ..sim.constants import EPISODE_STEPS, SAFEGUARD_LIMITS
from ..sim.kernel import GENOME_WIDTH, POLICY_MLP, POLICY_SLP, rollout_batch
from ..tasks import MDP, TaskFamily
from .cmaes import CMAES
from .generational import GenerationalNE, GenerationalSettings
from .races import fixed_resampling, selection_race
from .steady_state import SteadyStateNE, SteadyStateSettings
from .steady_state import SteadyStateNE as _SteadyStateNE  # the class itself (tests may patch the name)

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
    "validation_return",
    "write_history_csv",
]

CHECKPOINT_FORMAT = "neurohover-evolution-checkpoint/1"
#: CMA-ES settings (override with ``settings={"sigma0": ..., "popsize": ...}``). A sweep on GHH-08
#: train:1 (600-step episodes, 1000 episodes, SLP and MLP from the baseline) found sigma0 0.01-0.03
#: best and 0.1 crashing nearly every SLP candidate; popsize None is pycma's 4 + 3 ln D.
CMA_DEFAULTS: dict[str, Any] = {"sigma0": 0.02, "popsize": None}
RACE_T_LIMIT = 10  # docs/model.md, Fitness under noise: t_limit = t_min = t_max = 10
_KIND = {"slp": POLICY_SLP, "mlp": POLICY_MLP}
#: Steady-state settings that checkpoints written before they existed ran with.
_OLD_STEADY_STATE = {"plateau_rule": "literal", "selection": "roulette", "tournament_size": 5,
                     "init_mutate_frac": None, "init_mutate_std": None}
_MAX_SEED = 2**63 - 1


# --------------------------------------------------------------------------------- records


@dataclass(frozen=True)
class Resampling:
    """How a candidate's fitness is estimated: ``fixed`` (mean of ``k`` episodes) or ``race``
    (selection race at confidence level ``delta``). ``str()`` gives the spec back."""

    kind: str
    k: int = 1
    delta: float | None = None

    def __str__(self) -> str:
        return f"fixed:{self.k}" if self.kind == "fixed" else f"race:{self.delta:g}"


def parse_resampling(spec: str | Resampling | None) -> Resampling:
    """``"fixed:K"`` (K >= 1 episodes per candidate) or ``"race:DELTA"`` (0 < DELTA < 1); None is ``fixed:1``."""
    if spec is None:
        return Resampling("fixed", 1)
    if isinstance(spec, Resampling):
        return spec
    text = str(spec).strip().lower()
    kind, sep, value = text.partition(":")
    allowed = "allowed fixed:K (K >= 1 episodes per candidate) or race:DELTA (confidence level 0 < DELTA < 1)"
    if kind == "fixed" and sep:
        if value.isdigit() and int(value) >= 1:
            return Resampling("fixed", int(value))
        raise NeurohoverError(f"bad resampling {spec!r}: K must be an integer >= 1; {allowed}")
    if kind == "race" and sep:
        try:
            delta = float(value)
        except ValueError:
            delta = math.nan
        if 0.0 < delta < 1.0:
            return Resampling("race", 1, delta)
        raise NeurohoverError(f"bad resampling {spec!r}: DELTA must be a number strictly between 0 and 1; {allowed}")
    raise NeurohoverError(f"unknown resampling {spec!r}: {allowed}")


@dataclass(frozen=True)
class HistoryRecord:
    """One line of a run's history.

    Steady state (and CMA-ES on an MDP): one record per new champion, plus the last generation.
    Generational (and CMA-ES on a family): one record per generation.

    Attributes
    ----------
    generation : int
        Generations completed (steady state: one per offspring batch; the initial population is 1).
    evaluations : int
        Candidate fitness estimates made so far.
    episodes : int
        Episodes flown so far (the budget's unit).
    generation_episodes : int
        Episodes flown in this generation (a race's ``episodes_spent``; ``pop_size * K`` for fixed
        resampling).
    champion_return : float
        The champion's fitness (steady state: best ever; generational: best estimate of this generation).
    wall_seconds : float
        Seconds since the start of the run (continued across resumes).
    """

    generation: int
    evaluations: int
    episodes: int
    generation_episodes: int
    champion_return: float
    wall_seconds: float


HISTORY_COLUMNS = tuple(f.name for f in dataclasses.fields(HistoryRecord))


@dataclass(frozen=True)
class ProgressInfo:
    """What the ``progress`` callback sees (at most every ``progress_every_s``, and once at the end)."""

    generation: int
    evaluations: int
    episodes: int
    budget: int | None
    champion_return: float
    wall_seconds: float
    episodes_per_second: float
    done: bool


@dataclass(frozen=True)
class EvolutionResult:
    """Outcome of :func:`evolve`.

    Attributes
    ----------
    champion : Policy
        The champion, with metadata (method, optimizer, resampling, target, seed, budget, ...).
    champion_return : float
        Its fitness (see the module doc for which candidate is the champion).
    history : tuple of HistoryRecord
    episodes, steps : int
        Episodes and control steps flown.
    evaluations, generations : int
    seconds : float
        Wall time of the run (continued across resumes).
    kernel_seconds : float
        Of which inside the simulation kernel.
    stop_reason : str
        ``budget``, ``plateau`` (steady state), ``generations`` (generational), ``cma-stop``.
    settings : dict
        Everything that defines the run (JSON-able): target, method, optimizer, resampling,
        optimiser settings, topology, seed, n_steps, budget.
    champion_crashed : bool
        Steady state: whether the champion's evaluation crashed (False for the other methods).
    """

    champion: Policy
    champion_return: float
    history: tuple[HistoryRecord, ...]
    episodes: int
    steps: int
    evaluations: int
    generations: int
    seconds: float
    kernel_seconds: float
    stop_reason: str
    settings: dict
    champion_crashed: bool = False

    @property
    def episodes_per_second(self) -> float:
        return self.episodes / self.seconds if self.seconds > 0 else math.inf


class EvolutionInterrupted(KeyboardInterrupt):
    """The run was interrupted; ``checkpoint`` is where its state was saved (None: not saved)."""

    def __init__(self, checkpoint: Path | None, episodes: int) -> None:
        super().__init__(f"evolution interrupted after {episodes} episodes" +
                         (f"; checkpoint saved to {checkpoint}" if checkpoint else ""))
        self.checkpoint = checkpoint
        self.episodes = episodes


def write_history_csv(history, path: str | Path) -> Path:
    """Write history records as CSV with the header :data:`HISTORY_COLUMNS`."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    lines = [",".join(HISTORY_COLUMNS)]
    for h in history:
        lines.append(f"{h.generation},{h.evaluations},{h.episodes},{h.generation_episodes},{h.champion_return!r},{h.wall_seconds:.4f}")
    path.write_text("\n".join(lines) + "\n")
    return path


def read_history_csv(path: str | Path) -> list[HistoryRecord]:
    """Read a file written by :func:`write_history_csv`."""
    rows = Path(path).read_text().strip().splitlines()
    if not rows or rows[0] != ",".join(HISTORY_COLUMNS):
        raise NeurohoverError(f"{str(path)!r} is not an evolution history (expected the header {','.join(HISTORY_COLUMNS)})")
    out = []
    for line in rows[1:]:
        g, ev, ep, gep, r, w = line.split(",")
        out.append(HistoryRecord(int(g), int(ev), int(ep), int(gep), float(r), float(w)))
    return out


# --------------------------------------------------------------------------------- seeding


def _child_int(seed: int, key: int) -> int:
    """A 63-bit integer from child ``key`` of ``SeedSequence(seed)``."""
    return int(np.random.SeedSequence(seed, spawn_key=(key,)).generate_state(1, np.uint64)[0] >> np.uint64(1))


def _check_seed(seed) -> int:
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or not 0 <= int(seed) <= _MAX_SEED:
        raise NeurohoverError(f"seed={seed!r} is out of range: allowed an integer in 0..2**63-1")
    return int(seed)


# --------------------------------------------------------------------------------- MDP streams


class _MDPStream:
    """Fresh MDPs drawn from a task family, as kernel rows, in batches (:meth:`TaskFamily.sample_rows`:
    one fixed sequence of MDPs whatever the batch sizes)."""

    def __init__(self, family: TaskFamily, rng: np.random.Generator) -> None:
        self.family = family
        self.rng = rng

    def rows(self, n: int) -> np.ndarray:
        return self.family.sample_rows(self.rng, n)


# --------------------------------------------------------------------------------- kernel path


class _Flyer:
    """Calls the kernel directly with reused buffers (no per-generation validation or objects)."""

    def __init__(self, topology: str, seed: int, n_steps: int) -> None:
        self.kind = _KIND[topology]
        self.dim = GENOME_LENGTH[topology]
        self.seed = np.uint64(seed)
        self.n_steps = int(n_steps)
        self.episodes = 0  # the episode counter: next unused episode index
        self.steps = 0
        self.kernel_seconds = 0.0
        self._p_cap = 0
        self._j_cap = 0
        self._limits = np.asarray(SAFEGUARD_LIMITS, dtype=float)
        self._obs = np.zeros((0, 1, 12))
        self._act = np.zeros((0, 1, 4))
        self._views: dict[int, tuple] = {}
        self.trace: list | None = None  # (genomes, rows, p, m, e) per kernel call, for benchmarks
        self.crashed = np.zeros(0, dtype=np.bool_)  # crash flags of the last call (a view, like its returns)
        self.max_threads = self._threads = 1
        self._ensure(64, 512)

    def start(self) -> None:
        """Take the kernel thread count in force now as the most to use (call inside ``num_threads``)."""
        self.max_threads = self._threads = numba.get_num_threads()

    def _ensure(self, n_pol: int, n_jobs: int) -> None:
        if n_pol > self._p_cap:
            self._p_cap = max(n_pol, 2 * self._p_cap)
            self.genomes = np.zeros((self._p_cap, GENOME_WIDTH))
            self.kinds = np.full(self._p_cap, self.kind, dtype=np.int64)
        if n_jobs > self._j_cap:
            self._j_cap = j = max(n_jobs, 2 * self._j_cap)
            self._buffers = (np.zeros(j, dtype=np.int64), np.arange(j, dtype=np.int64), np.zeros(j, dtype=np.int64),
                             np.full(j, -1, dtype=np.int64), np.zeros(j), np.zeros(j, dtype=np.bool_),
                             np.zeros(j, dtype=np.int64), np.zeros(j, dtype=np.int64))
            self._views = {}

    def _views_for(self, n_jobs: int) -> tuple:
        views = self._views.get(n_jobs)
        if views is None:
            self._ensure(0, n_jobs)
            views = self._views[n_jobs] = tuple(b[:n_jobs] for b in self._buffers)
        return views

    def fly(self, genomes: np.ndarray, rows: np.ndarray, p_idx, m_idx, n_jobs: int) -> np.ndarray:
        """Fly ``n_jobs`` jobs (policy ``p_idx[j]`` of ``genomes`` on MDP row ``m_idx[j]``; None: all
        zeros, ``"range"``: 0..n_jobs-1) with the next ``n_jobs`` episode indices. Returns a view of
        the returns buffer, valid until the next call."""
        n_pol = genomes.shape[0]
        if n_pol > self._p_cap:
            self._ensure(n_pol, 0)
        self.genomes[:n_pol, : self.dim] = genomes
        zeros, arange, e, minus, returns, crashed, steps, sg = self._views_for(n_jobs)
        p = zeros if p_idx is None else (arange if isinstance(p_idx, str) else p_idx)
        m = zeros if m_idx is None else (arange if isinstance(m_idx, str) else m_idx)
        np.add(arange, self.episodes, out=e)
        # Never more threads than jobs: every thread of a parallel call must check in, and on a busy
        # machine a one-episode call on all cores runs up to 10x slower than on one.
        want = n_jobs if n_jobs < self.max_threads else self.max_threads
        if want != self._threads:
            numba.set_num_threads(want)
            self._threads = want
        t0 = time.perf_counter()
        rollout_batch(rows, self.kinds, self.genomes, p, m, e, minus, self.seed, self.n_steps,
                      False, self._limits, minus, self._obs, self._act, returns, crashed, steps, sg)
        self.kernel_seconds += time.perf_counter() - t0
        if self.trace is not None:
            self.trace.append((genomes.copy(), rows, p.copy(), m.copy(), e.copy()))
        self.episodes += n_jobs
        self.steps += int(steps[0]) if n_jobs == 1 else int(steps.sum())
        self.crashed = crashed
        return returns


# --------------------------------------------------------------------------------- interrupts


class _InterruptFlag:
    """First Ctrl-C asks the run to stop at the next generation boundary; a second one raises."""

    def __init__(self) -> None:
        self.set = False
        self._previous = None

    def __enter__(self) -> "_InterruptFlag":
        if threading.current_thread() is threading.main_thread():
            try:
                self._previous = signal.signal(signal.SIGINT, self._handler)
            except ValueError:  # not allowed here (e.g. embedded interpreter)
                self._previous = None
        return self

    def _handler(self, signum, frame) -> None:
        if self.set:
            raise KeyboardInterrupt
        self.set = True

    def __exit__(self, exc_type, exc, tb) -> None:
        if self._previous is not None:
            signal.signal(signal.SIGINT, self._previous)
        if self.set and exc_type is None:
            # Ctrl-C came after the last generation's check: the run is complete, but the
            # interrupt must still reach the caller (e.g. a reproduce loop), never be swallowed.
            raise KeyboardInterrupt


# --------------------------------------------------------------------------------- the run


def _resolve_prototype(prototype, topology: str) -> Policy:
    if topology not in TOPOLOGIES:
        raise NeurohoverError(f"unknown topology {topology!r}: allowed {', '.join(TOPOLOGIES)}")
    if isinstance(prototype, Policy):
        if prototype.topology != topology:
            raise NeurohoverError(f"the prototype is an {prototype.topology} policy but topology={topology!r}")
        return prototype
    if isinstance(prototype, str) and prototype in ("zero", "baseline"):
        return make_prototype(topology, prototype)
    raise NeurohoverError(f"prototype must be a Policy, 'zero' or 'baseline', got {prototype!r}")


def _resolve_target(target):
    """(mdp or None, family or None, description dict)."""
    if isinstance(target, MDP):
        return target, None, {"kind": "mdp", "mdp": target.to_dict()}
    if isinstance(target, TaskFamily):
        desc = {"kind": "family", "family": target.name}
        if target.sigma is not None:
            desc["sigma"] = float(target.sigma)
        return None, target, desc
    if callable(getattr(target, "mdp", None)) and hasattr(target, "method"):  # a LearnedModel
        mdp = target.mdp()
        return mdp, None, {"kind": "mdp", "mdp": mdp.to_dict()}
    raise NeurohoverError(
        f"evolve needs an MDP, a learned model or a task family as target, got {type(target).__name__}"
    )


def _make_settings(method: str, optimizer: str, settings) -> dict | SteadyStateSettings | GenerationalSettings:
    if optimizer == "cma":
        cfg = dict(CMA_DEFAULTS)
        if settings is not None:
            if not isinstance(settings, Mapping):
                raise NeurohoverError("settings for optimizer='cma' must be a dict with keys sigma0, popsize")
            unknown = sorted(set(settings) - set(cfg))
            if unknown:
                raise NeurohoverError(f"unknown CMA-ES setting(s) {', '.join(unknown)}: allowed {', '.join(cfg)}")
            cfg.update(settings)
        s0, pop = cfg["sigma0"], cfg["popsize"]
        if isinstance(s0, bool) or not isinstance(s0, (int, float)) or not (math.isfinite(s0) and s0 > 0):
            raise NeurohoverError(f"CMA-ES sigma0={s0!r} must be a finite number > 0")
        if pop is not None and (isinstance(pop, bool) or not isinstance(pop, (int, np.integer)) or pop < 2):
            raise NeurohoverError(f"CMA-ES popsize={pop!r} must be None or an integer >= 2")
        return {"sigma0": float(s0), "popsize": None if pop is None else int(pop)}
    cls = SteadyStateSettings if method == "steady-state" else GenerationalSettings
    if settings is None:
        return cls()
    if isinstance(settings, cls):
        return dataclasses.replace(settings, budget=None)
    if isinstance(settings, (SteadyStateSettings, GenerationalSettings)):
        raise NeurohoverError(f"the {method} method takes {cls.__name__}, got {type(settings).__name__}")
    if not isinstance(settings, Mapping):
        raise NeurohoverError(f"settings must be a {cls.__name__} or a dict of its fields, got {type(settings).__name__}")
    fields = {f.name for f in dataclasses.fields(cls)} - {"budget"}
    unknown = sorted(set(settings) - fields)
    if unknown:
        raise NeurohoverError(f"unknown {method} setting(s) {', '.join(unknown)}: allowed {', '.join(sorted(fields))}")
    try:
        return cls(**dict(settings))
    except ValueError as err:
        raise NeurohoverError(f"bad {method} settings: {err}") from None


class _Run:
    """State of one evolution run (everything a checkpoint holds)."""

    def __init__(self, target, *, topology, prototype, optimizer, resampling, budget, settings, seed,
                 n_steps, method) -> None:
        self.mdp, self.family, target_desc = _resolve_target(target)
        self.proto = _resolve_prototype(prototype, topology)
        self.topology = topology
        if optimizer not in ("ne", "cma"):
            raise NeurohoverError(f"unknown optimizer {optimizer!r}: allowed ne, cma")
        self.optimizer = optimizer
        self.resampling = parse_resampling(resampling)
        if budget is None and isinstance(settings, (SteadyStateSettings, GenerationalSettings)):
            budget = settings.budget
        if budget is not None and (isinstance(budget, bool) or not isinstance(budget, (int, np.integer)) or budget < 1):
            raise NeurohoverError(f"budget={budget!r} is out of range: allowed an integer >= 1 (episodes)")
        self.budget = None if budget is None else int(budget)
        self.seed = _check_seed(seed)
        if isinstance(n_steps, bool) or not isinstance(n_steps, (int, np.integer)) or not 1 <= n_steps <= 10**7:
            raise NeurohoverError(f"n_steps={n_steps!r} is out of range: allowed an integer in 1..10000000")
        self.n_steps = int(n_steps)
        default_method = "steady-state" if self.mdp is not None else "generational"
        self.method = default_method if method is None else method
        if self.method not in ("steady-state", "generational"):
            raise NeurohoverError(f"unknown method {method!r}: allowed steady-state, generational")
        if self.method == "steady-state" and self.family is not None:
            raise NeurohoverError("the steady-state method evolves on one MDP; a task family needs the generational method")
        if self.optimizer == "cma":
            self.method = "cma"
        if self.resampling.kind == "race" and self.method != "generational":
            raise NeurohoverError(
                f"resampling {self.resampling} (a selection race) needs the generational method "
                "(a task family as target, optimizer 'ne'); use fixed:K here"
            )
        self.settings = _make_settings("steady-state" if self.method == "steady-state" else "generational",
                                       self.optimizer, settings)
        if self.optimizer == "cma" and self.proto.genome.size < 2:
            raise NeurohoverError("CMA-ES needs a genome of at least 2 genes")
        self.config = {
            "target": target_desc, "method": self.method, "optimizer": self.optimizer,
            "resampling": str(self.resampling), "topology": topology,
            "prototype": self.proto.genome.tolist(), "seed": self.seed, "n_steps": self.n_steps,
            "settings": dict(self.settings) if isinstance(self.settings, dict) else dataclasses.asdict(self.settings),
        }
        self.config = json.loads(json.dumps(self.config))  # as a checkpoint would hold it
        self.flyer = _Flyer(topology, _child_int(self.seed, 2), self.n_steps)
        self.stream = None if self.family is None else _MDPStream(self.family, np.random.default_rng(
            np.random.SeedSequence(self.seed, spawn_key=(1,))))
        self.rows = None if self.mdp is None else self.mdp.row()[None, :]
        opt_seed = _child_int(self.seed, 0)
        genome = self.proto.genome
        if self.optimizer == "cma":
            self.opt = CMAES(genome, sigma0=self.settings["sigma0"], seed=opt_seed, popsize=self.settings["popsize"])
        elif self.method == "steady-state":
            self.opt = SteadyStateNE(genome, self.settings, seed=opt_seed)
        else:
            self.opt = GenerationalNE(genome, self.settings, seed=opt_seed)
        self.history: list[HistoryRecord] = []
        self.generation = 0
        self.evaluations = 0
        self.elapsed = 0.0  # wall seconds of earlier sessions (resume)
        self.champion_genome: np.ndarray | None = None  # CMA-ES on a family: best of the last generation
        self.champion_return = -math.inf
        self.stop_reason: str | None = None

    # ----------------------------------------------------------------- checkpoints

    def state(self, wall: float) -> dict:
        opt_state = self.opt.state_dict()
        return {
            "format": CHECKPOINT_FORMAT, "config": self.config, "budget": self.budget,
            "optimizer_state": opt_state,
            "counters": {"episodes": self.flyer.episodes, "steps": self.flyer.steps, "generation": self.generation,
                         "evaluations": self.evaluations, "wall_seconds": wall,
                         "kernel_seconds": self.flyer.kernel_seconds},
            "mdp_stream": None if self.stream is None else self.stream.rng.bit_generator.state,
            "champion": {"genome": None if self.champion_genome is None else self.champion_genome.tolist(),
                         "return": _enc(self.champion_return)},
            "history": [[h.generation, h.evaluations, h.episodes, h.generation_episodes, _enc(h.champion_return), h.wall_seconds]
                        for h in self.history],
            "stop_reason": self.stop_reason,
        }

    def restore(self, state: dict, source: str) -> None:
        if state.get("format") != CHECKPOINT_FORMAT:
            raise NeurohoverError(f"{source} is not an evolution checkpoint (expected format {CHECKPOINT_FORMAT!r})")
        saved = state["config"]
        if saved.get("method") == "steady-state" and "plateau_rule" not in saved.get("settings", {}):
            # Written before these settings existed: it ran Appendix A's literal plateau rule.
            saved = {**saved, "settings": {**_OLD_STEADY_STATE, **saved["settings"]}}
        if saved != self.config:
            diff = sorted(k for k in set(saved) | set(self.config) if saved.get(k) != self.config.get(k))
            raise NeurohoverError(
                f"{source} was written by a different run: {', '.join(diff)} differ; resume with the same "
                "target, method, optimizer, resampling, topology, prototype, seed, episode steps and settings (only the budget may change)"
            )
        opt_state = state["optimizer_state"]
        try:
            if self.optimizer == "cma":
                self.opt = CMAES.from_state_dict(opt_state)
            elif self.method == "steady-state":
                self.opt = SteadyStateNE.from_state_dict(opt_state)
            else:
                self.opt = GenerationalNE.from_state_dict(opt_state)
        except (ValueError, KeyError, TypeError, pickle.UnpicklingError) as err:
            raise NeurohoverError(f"{source}: cannot restore the optimiser ({err})") from None
        c = state["counters"]
        self.flyer.episodes, self.flyer.steps = int(c["episodes"]), int(c["steps"])
        self.flyer.kernel_seconds = float(c["kernel_seconds"])
        self.generation, self.evaluations = int(c["generation"]), int(c["evaluations"])
        self.elapsed = float(c["wall_seconds"])
        if self.stream is not None:
            self.stream.rng.bit_generator.state = state["mdp_stream"]
        ch = state["champion"]
        self.champion_genome = None if ch["genome"] is None else np.array(ch["genome"], dtype=float)
        self.champion_return = float(ch["return"])
        self.history = [HistoryRecord(int(g), int(e), int(ep), int(gep), float(r), float(w))
                        for g, e, ep, gep, r, w in state["history"]]

    # ----------------------------------------------------------------- fitness

    def _fly_fixed(self, genomes: np.ndarray) -> np.ndarray:
        """Fitness of each genome on the fixed MDP: mean of K episodes (fresh episode indices)."""
        n, k = genomes.shape[0], self.resampling.k
        if k == 1:
            if n == 1:
                return self.flyer.fly(genomes, self.rows, None, None, 1).copy()
            return self.flyer.fly(genomes, self.rows, "range", None, n).copy()
        p = np.repeat(np.arange(n, dtype=np.int64), k)
        return self.flyer.fly(genomes, self.rows, p, None, n * k).reshape(n, k).mean(axis=1)

    def _fly_fixed_crashed(self, genomes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`_fly_fixed` and whether each genome crashed (in any of its K episodes)."""
        returns = self._fly_fixed(genomes)
        k = self.resampling.k
        crashed = self.flyer.crashed.copy() if k == 1 else self.flyer.crashed.reshape(-1, k).any(axis=1)
        return returns, crashed

    def _fly_family_fixed(self, genomes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Fixed resampling on G in ONE kernel call: (means, samples (n, k)).

        Column j holds every candidate's j-th episode; episodes and MDPs are numbered column by
        column, i.e. as k consecutive calls of a sample function would number them.
        """
        n, k = genomes.shape[0], self.resampling.k
        p = np.tile(np.arange(n, dtype=np.int64), k)
        if self.stream is None:  # generational on one MDP: only the episodes' noise differs
            returns = self.flyer.fly(genomes, self.rows, p, None, n * k).copy()
        else:
            returns = self.flyer.fly(genomes, self.stream.rows(n * k), p, "range", n * k).copy()
        cols = returns.reshape(k, n)
        calls = iter(range(k))
        result = fixed_resampling(lambda idx: cols[next(calls)], n, k)
        return result.means, result

    def _race_sample_fn(self, genomes: np.ndarray):
        def sample(idx: np.ndarray) -> np.ndarray:
            n = idx.shape[0]
            if self.stream is None:
                return self.flyer.fly(genomes, self.rows, idx.astype(np.int64), None, n).copy()
            return self.flyer.fly(genomes, self.stream.rows(n), idx.astype(np.int64), "range", n).copy()
        return sample

    # ----------------------------------------------------------------- loop

    def run(self, progress, checkpoint: Path | None, checkpoint_every_s: float, progress_every_s: float) -> None:
        start = time.perf_counter() - self.elapsed
        flag_every = checkpoint_every_s if checkpoint is not None else math.inf
        next_ckpt = time.perf_counter() + flag_every
        next_progress = time.perf_counter() + progress_every_s
        budget = self.budget
        step = {"steady-state": self._steady_generation, "generational": self._generational_generation,
                "cma": self._cma_generation}[self.method]
        boundary = True  # False while a generation is half done (its state is not checkpointable)
        with _InterruptFlag() as flag:
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
                        raise KeyboardInterrupt
                    if now >= next_progress and progress is not None:
                        next_progress = now + progress_every_s
                        progress(self._info(now - start, False, budget))
                    if now >= next_ckpt:
                        _write_checkpoint(checkpoint, self.state(now - start))
                        next_ckpt = time.perf_counter() + flag_every
            except KeyboardInterrupt:
                # At a generation boundary (first Ctrl-C, or the progress callback) the state is whole
                # and is saved; a second Ctrl-C mid-generation leaves the last periodic checkpoint.
                if not boundary or checkpoint is None:
                    raise EvolutionInterrupted(None, self.flyer.episodes) from None
                _write_checkpoint(checkpoint, self.state(time.perf_counter() - start))
                raise EvolutionInterrupted(checkpoint, self.flyer.episodes) from None
        wall = time.perf_counter() - start
        self.elapsed = wall
        if checkpoint is not None:
            _write_checkpoint(checkpoint, self.state(wall))
        if progress is not None:
            progress(self._info(wall, True, budget))

    def _info(self, wall: float, done: bool, budget) -> ProgressInfo:
        eps = self.flyer.episodes
        return ProgressInfo(self.generation, self.evaluations, eps, budget, self._champion_return(), wall,
                            eps / wall if wall > 0 else 0.0, done)

    def _should_stop(self) -> str | None:
        if self.budget is not None and self.flyer.episodes >= self.budget:
            return "budget"
        if self.generation == 0:
            return None
        if self.optimizer == "cma":
            return "cma-stop" if self.opt.stop() else None
        if self.opt.stop():
            return "plateau" if self.method == "steady-state" else "generations"
        return None

    def _steady_generation(self, start: float) -> None:
        opt = self.opt
        before = opt.champion_return
        before_eps = self.flyer.episodes
        genomes = opt.ask()
        if isinstance(opt, _SteadyStateNE):
            returns, crashed = self._fly_fixed_crashed(genomes)
            opt.tell(returns, crashed=crashed)
        else:  # an optimiser without crash flags (e.g. a test's frozen reference)
            opt.tell(self._fly_fixed(genomes))
        self.generation += 1
        self.evaluations += genomes.shape[0]
        best = opt.champion_return
        if best != before:
            self.history.append(HistoryRecord(self.generation, self.evaluations, self.flyer.episodes,
                                              self.flyer.episodes - before_eps, best, time.perf_counter() - start))

    def _generational_generation(self, start: float) -> None:
        opt = self.opt
        before_eps = self.flyer.episodes
        genomes = opt.ask()
        if self.resampling.kind == "race":
            race = selection_race(self._race_sample_fn(genomes), genomes.shape[0], opt.settings.select_size,
                                  self.resampling.delta, t_limit=RACE_T_LIMIT)
            opt.tell_race(race)
        else:
            _, result = self._fly_family_fixed(genomes)
            opt.tell_resampled(result)
        self.generation += 1
        self.evaluations += genomes.shape[0]
        self.history.append(HistoryRecord(self.generation, self.evaluations, self.flyer.episodes,
                                          self.flyer.episodes - before_eps, opt.champion_return,
                                          time.perf_counter() - start))

    def _cma_generation(self, start: float) -> None:
        opt = self.opt
        before_eps = self.flyer.episodes
        genomes = opt.ask()
        if self.family is None:
            before = opt.champion_return
            opt.tell(self._fly_fixed(genomes))
            record = opt.champion_return != before
            champion = opt.champion_return
        else:
            means, _ = self._fly_family_fixed(genomes)
            opt.tell(means)
            key = np.where(np.isnan(means), -np.inf, means)
            best = int(np.argmax(key))
            self.champion_genome, self.champion_return = genomes[best].copy(), float(key[best])
            record, champion = True, self.champion_return
        self.generation += 1
        self.evaluations += genomes.shape[0]
        if record:
            self.history.append(HistoryRecord(self.generation, self.evaluations, self.flyer.episodes,
                                              self.flyer.episodes - before_eps, champion, time.perf_counter() - start))

    def _history_with_last(self) -> tuple[HistoryRecord, ...]:
        """The history plus, if the last generation made no record, one for it (not checkpointed)."""
        history = list(self.history)
        if self.generation and (not history or history[-1].generation != self.generation):
            last = history[-1] if history else None
            history.append(HistoryRecord(self.generation, self.evaluations, self.flyer.episodes,
                                         0 if last is None else self.flyer.episodes - last.episodes,
                                         self._champion_return(), self.elapsed))
        return tuple(history)

    def _champion_return(self) -> float:
        if self.optimizer == "cma" and self.family is not None:
            return self.champion_return
        return float(self.opt.champion_return)

    def _champion_genome(self) -> np.ndarray | None:
        if self.optimizer == "cma" and self.family is not None:
            return self.champion_genome
        return self.opt.champion_genome

    def result(self) -> EvolutionResult:
        genome = self._champion_genome()
        if genome is None:
            raise NeurohoverError("the evolution found no candidate with a finite fitness")
        ret = self._champion_return()
        settings = {**self.config, "budget": self.budget}
        settings.pop("prototype")
        target = self.config["target"]
        label = target["mdp"]["label"] if target["kind"] == "mdp" else f"{target['family']}/G" + (
            f"(sigma={target['sigma']:g})" if "sigma" in target else "")
        meta = {
            "method": self.method if self.optimizer == "ne" else "cma-es", "optimizer": self.optimizer,
            "resampling": str(self.resampling), "target": label, "seed": self.seed, "budget": self.budget,
            "episodes": self.flyer.episodes, "evaluations": self.evaluations, "generations": self.generation,
            "champion_return": ret, "n_steps": self.n_steps, "stop_reason": self.stop_reason,
        }
        champion = Policy(self.topology, np.array(genome, dtype=float), {**self.proto.metadata, **meta})
        return EvolutionResult(champion, ret, self._history_with_last(), self.flyer.episodes, self.flyer.steps,
                               self.evaluations, self.generation, self.elapsed, self.flyer.kernel_seconds,
                               self.stop_reason or "", settings,
                               isinstance(self.opt, _SteadyStateNE) and self.opt.champion_crashed)


def _enc(x: float) -> float | str:
    x = float(x)
    return x if math.isfinite(x) else ("nan" if math.isnan(x) else ("inf" if x > 0 else "-inf"))


def _write_checkpoint(path: Path, state: dict) -> None:
    tmp = path.with_name(path.name + ".tmp")
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(tmp, "w") as f:
        json.dump(state, f, allow_nan=False)
        f.flush()
        os.fsync(f.fileno())
    os.replace(tmp, path)


def _read_checkpoint(path: Path) -> dict:
    if not path.is_file():
        raise NeurohoverError(f"no checkpoint to resume from: {str(path)!r} does not exist")
    try:
        return json.loads(path.read_text())
    except (json.JSONDecodeError, UnicodeDecodeError) as err:
        raise NeurohoverError(f"checkpoint {str(path)!r} is not valid JSON: {err}") from None


# --------------------------------------------------------------------------------- public API


def evolve(
    target,
    *,
    topology: str = "mlp",
    prototype: Policy | str = "baseline",
    optimizer: str = "ne",
    resampling: str | Resampling | None = None,
    budget: int | None = None,
    settings=None,
    seed: int = 0,
    n_steps: int = EPISODE_STEPS,
    threads: int | None = None,
    progress: Callable[[ProgressInfo], None] | None = None,
    checkpoint: str | Path | None = None,
    checkpoint_every_s: float = 60.0,
    resume: bool = False,
    method: str | None = None,
    progress_every_s: float = 0.2,
    _trace: list | None = None,
) -> EvolutionResult:
    """Run a whole evolution on the batched kernel and return its champion and history.

    Parameters
    ----------
    target : MDP, LearnedModel or task family
        A fixed MDP (steady state) or a task family G (generational); see the module doc.
    topology : {"slp", "mlp"}
    prototype : Policy or {"zero", "baseline"}
        The genome the initial population is built from.
    optimizer : {"ne", "cma"}
        The paper's neuroevolution, or CMA-ES (pycma) with the same budget and resampling.
    resampling : str, optional
        ``"fixed:K"`` (default ``fixed:1``) or ``"race:DELTA"`` (generational NE on a family only).
    budget : int, optional
        Episodes to fly (checked between generations). Default: the paper's termination
        (steady state: plateau; generational: ``generations``; CMA-ES: pycma's criteria).
    settings : SteadyStateSettings, GenerationalSettings or dict, optional
        Overrides of the optimiser settings (paper Tables 6/7); for CMA-ES a dict with
        ``sigma0`` and ``popsize`` (:data:`CMA_DEFAULTS`).
    seed : int
        Root of all randomness (``numpy.random.SeedSequence(seed)``).
    n_steps : int
        Control steps per episode (6000 in the paper).
    threads : int, optional
        Kernel threads (default: all cores); results do not depend on it.
    progress : callable, optional
        Called with a :class:`ProgressInfo` after a generation at most every ``progress_every_s``
        seconds (default 0.2; 0: every generation) and at the end; may raise ``KeyboardInterrupt``
        to stop the run (the checkpoint is written first).
    checkpoint : path, optional
        Checkpoint file, written every ``checkpoint_every_s`` seconds, at the end and on interrupt.
    resume : bool
        Continue from ``checkpoint`` (which must exist).
    method : {"steady-state", "generational"}, optional
        Default: steady state for an MDP, generational for a family.

    Raises
    ------
    NeurohoverError
        Bad input, or a checkpoint that does not match the run.
    EvolutionInterrupted
        On Ctrl-C or a ``KeyboardInterrupt`` from ``progress``.
    """
    run = _Run(target, topology=topology, prototype=prototype, optimizer=optimizer, resampling=resampling,
               budget=budget, settings=settings, seed=seed, n_steps=n_steps, method=method)
    if not isinstance(checkpoint_every_s, (int, float)) or not checkpoint_every_s > 0:
        raise NeurohoverError(f"checkpoint_every_s={checkpoint_every_s!r} must be a number > 0")
    path = None if checkpoint is None else Path(checkpoint)
    if resume:
        if path is None:
            raise NeurohoverError("resume=True needs the checkpoint path")
        run.restore(_read_checkpoint(path), f"checkpoint {str(path)!r}")
        run.stop_reason = None
    run.flyer.trace = _trace
    # Load (or compile) the kernel before the clock runs, and validate the thread count.
    evaluate_jobs([run.proto], run.rows if run.rows is not None else run.family.zero(), [0], [0], [0],
                  n_steps=1, threads=threads)
    with num_threads(threads if threads is not None else numba.get_num_threads()):  # restores the count after
        run.flyer.start()
        run.run(progress, path, float(checkpoint_every_s), float(progress_every_s))
    return run.result()


def validation_return(policy: Policy, target, *, episodes: int = 10, seed: int = 0,
                      n_steps: int = EPISODE_STEPS, threads: int | None = None) -> np.ndarray:
    """Returns of ``episodes`` fresh episodes of ``policy``: on the MDP, or each on a fresh MDP from G.

    The noise and MDPs come from ``SeedSequence(seed)`` child ``(3,)``, which :func:`evolve` never
    uses, so these episodes are independent of the ones the run flew.
    """
    mdp, family, _ = _resolve_target(target)
    if isinstance(episodes, bool) or not isinstance(episodes, (int, np.integer)) or episodes < 1:
        raise NeurohoverError(f"episodes={episodes!r} is out of range: allowed an integer >= 1")
    seed = _check_seed(seed)
    ss = np.random.SeedSequence(seed, spawn_key=(3,))
    noise_seed, mdp_seed = (int(x >> np.uint64(1)) for x in ss.generate_state(2, np.uint64))
    if mdp is not None:
        rows = mdp.row()[None, :]
        m_idx = np.zeros(episodes, dtype=np.int64)
    else:
        rows = _MDPStream(family, np.random.default_rng(mdp_seed)).rows(episodes)
        m_idx = np.arange(episodes)
    ev = evaluate_jobs([policy], rows, np.zeros(episodes, dtype=np.int64), m_idx, np.arange(episodes),
                       seed=noise_seed, n_steps=n_steps, threads=threads)
    return ev.returns


# --------------------------------------------------------------------------------- benchmark


def _replay_seconds(trace: list, topology: str, noise_seed: int, n_steps: int, threads: int) -> float:
    """Wall time of the raw kernel flying exactly the traced jobs in ONE batch (``evaluate_jobs``)."""
    from ..evaluate import PolicyTable

    genomes = np.vstack([t[0] for t in trace])
    rows = np.vstack([t[1] for t in trace])
    g_off = np.cumsum([0] + [len(t[0]) for t in trace])[:-1]
    r_off = np.cumsum([0] + [len(t[1]) for t in trace])[:-1]
    p = np.concatenate([t[2] + o for t, o in zip(trace, g_off)])
    m = np.concatenate([t[3] + o for t, o in zip(trace, r_off)])
    e = np.concatenate([t[4] for t in trace])
    ev = evaluate_jobs(PolicyTable.from_genomes(genomes, topology), rows, p, m, e, seed=noise_seed,
                       n_steps=n_steps, threads=threads)
    return ev.seconds


def benchmark_evolution(quick: bool = False, repeats: int | None = None) -> dict:
    """Throughput of :func:`evolve` against the raw kernel flying the same episodes (``neurohover bench``).

    Workload of the raw kernel benchmark: MLP from the baseline seed, full 6000-step episodes.
    Steady state on the zero setting on 1 thread (one episode per generation); generational on FGHH
    (sigma 0.3) on all cores, with fixed resampling (k=5: one kernel call per generation) and with
    selection races (delta 0.5: one call per race round). Evolved candidates often crash early, so
    episodes have very different lengths; the fair reference is therefore the raw kernel flying
    exactly the episodes the run flew (same genomes, MDPs and noise), in one batch on the same
    threads: ``ratio_vs_raw_kernel`` = raw seconds / evolve seconds (best of ``repeats`` each).
    """
    import numba

    from ..tasks import get_task_family

    cores = numba.config.NUMBA_NUM_THREADS
    repeats = (1 if quick else 2) if repeats is None else repeats
    budget_ss, budget_gen = (200, 300) if quick else (2000, 5000)  # quick: about a second (2 generations of fixed:5)
    cases = [
        ("evolve_steady_state_1_core", get_task_family("fghh").zero(), 1, budget_ss, None),
        (f"evolve_generational_fixed5_{cores}_cores", get_task_family("fghh", 0.3), cores, budget_gen, "fixed:5"),
        (f"evolve_generational_race0.5_{cores}_cores", get_task_family("fghh", 0.3), cores, budget_gen, "race:0.5"),
    ]
    # Load every compiled function (kernel, genome operators) before any clock starts.
    evolve(get_task_family("fghh").zero(), budget=60, seed=0, n_steps=10, threads=1)
    out: dict = {}
    for name, target, threads, budget, resampling in cases:
        best_evolve, best_raw = math.inf, math.inf
        for _ in range(repeats):
            trace: list = []
            result = evolve(target, topology="mlp", prototype="baseline", budget=budget, resampling=resampling,
                            seed=1, threads=threads, _trace=trace)
            best_evolve = min(best_evolve, result.seconds)
            best_raw = min(best_raw, _replay_seconds(trace, "mlp", _child_int(1, 2), EPISODE_STEPS, threads))
        out[f"{name}_episodes_per_second"] = result.episodes / best_evolve
        out[f"{name}_control_steps_per_second"] = result.steps / best_evolve
        out[f"{name}_raw_kernel_same_episodes_per_second"] = result.episodes / best_raw
        out[f"{name}_ratio_vs_raw_kernel"] = best_raw / best_evolve
    return out
