"""What the optimisers share: the ask/tell protocol, champion tracking, checks and state encoding.

Sign convention
---------------
The optimisers MAXIMISE returns. In the helicopter domain returns are negative (accumulated
negative reward), so "best" means "closest to zero"; the paper's "error" of a genome is
``-return``. Non-finite returns (NaN or ``-inf``, e.g. from a diverged simulation) rank as the
worst possible; ``+inf`` is refused.

Checkpointing
-------------
``state_dict()`` returns a plain, strictly JSON-serialisable dict (non-finite floats are stored as
strings, see :func:`enc_float`) including the ``numpy.random.Generator`` state; ``from_state_dict``
rebuilds an optimiser that continues bit-for-bit identically, also when saved between ``ask()``
and ``tell()``.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Any, Protocol, TypeVar

import numpy as np

from ..errors import NeurohoverError, as_floats, brief, finite_real, lowest_allowed, setting_float, whole_number
from ..flightmeta import compared_by_value
from .state_codec import (
    STATE_DAMAGE,
    STATE_VERSION,
    EntryError,
    check_entries,
    check_genomes,
    check_state,
    damage_text,
    dec_array,
    dec_float,
    enc_array,
    enc_float,
    read_count,
    read_entry,
    read_return,
    read_seconds,
    read_settings,
    required,
    rng_from_state,
)

__all__ = [
    "STATE_DAMAGE",
    "STATE_VERSION",
    "AskTellOrderError",
    "ChampionRecord",
    "ChampionTracker",
    "ChampionViews",
    "Clock",
    "EntryError",
    "Optimiser",
    "TellInfo",
    "as_floats",
    "as_returns",
    "check_entries",
    "check_info",
    "check_prototype",
    "check_returns",
    "check_settings",
    "crash_flags",
    "check_genomes",
    "check_state",
    "damage_text",
    "dec_array",
    "dec_float",
    "enc_array",
    "enc_float",
    "rank",
    "read_entry",
    "read_count",
    "read_return",
    "read_settings",
    "read_seconds",
    "required",
    "require_episodes",
    "MAX_EPISODES",
    "require_int",
    "require_population",
    "MAX_POPULATION",
    "MAX_SPREAD",
    "require_spread",
    "selected_indices",
    "require_prob",
    "require_std",
    "rng_from_state",
    "set_field",
    "validate_variation_settings",
]


@compared_by_value  # == by value: arrays whole (T46-B08)
@dataclass(frozen=True, eq=False)
class TellInfo:
    """What an evolution run knows of a generation besides its fitness values; each optimiser
    reads what it uses and ignores the rest.

    Attributes
    ----------
    crashed : np.ndarray of bool, optional
        Per genome, whether its evaluation crashed (steady state's ``no-crash`` plateau rule).
    selected : np.ndarray of int, optional
        The parents a selection race chose (generational NE).
    episodes : int, optional
        Episodes the generation cost (generational NE's history and budget): an integer in 0..:data:`MAX_EPISODES`, and
        at a ``tell`` no fewer than the genomes asked (:meth:`check`).

    Raises
    ------
    NeurohoverError
        For episodes that are no such integer; every ``tell`` refuses crashed and selected that do not fit the genomes
        it asked (:meth:`check`).
    """

    crashed: np.ndarray | None = None
    selected: np.ndarray | None = None
    episodes: int | None = None

    def __post_init__(self) -> None:
        if self.episodes is not None:
            object.__setattr__(self, "episodes", require_episodes(self.episodes))

    def check(self, asked: int) -> None:
        """NeurohoverError naming the field unless ``crashed``, ``selected`` and ``episodes`` fit a tell of ``asked``
        genomes: the one check of the three, which every ``tell`` makes (through :func:`check_returns`), also of a field
        it does not read (one crash flag for four genomes, selected index -1 or 4 of four were taken; T21-10). Each
        genome's evaluation flies one episode or more, so a generation costs at least ``asked`` episodes: episodes=0
        left a GenerationalNE's evaluations (the episodes its budget counts) at 0 and its run never stopped (T22-13)."""
        if self.episodes is not None and self.episodes < asked:
            raise NeurohoverError(
                f"TellInfo episodes={self.episodes:,} is not allowed: fewer than the {asked:,} genomes asked, each of whose evaluations"
                f" flies an episode or more; allowed an integer in {asked:,}..{MAX_EPISODES:,}"
            )
        if self.crashed is not None:
            crash_flags(self.crashed, asked)
        if self.selected is not None:
            selected_indices(self.selected, asked)


def crash_flags(values: Any, asked: int, name: str = "TellInfo crashed") -> np.ndarray:
    """``values`` as a bool array, or NeurohoverError unless one flag per asked genome: booleans (or the integers 0 and 1)."""
    c = _array(values)
    if c is None or c.ndim != 1 or c.size != asked:
        got = "no array" if c is None else f"shape {c.shape}" if c.ndim != 1 else f"{c.size} flag{'' if c.size == 1 else 's'}"
        raise NeurohoverError(f"{name} must be {asked} booleans, one per asked genome; got {got}: {brief(values)}")
    if c.dtype != np.bool_ and not (c.dtype.kind in "iu" and np.isin(c, (0, 1)).all()):
        raise NeurohoverError(f"{name} must be {asked} booleans, one per asked genome; got {c.dtype} values: {brief(values)}")
    return c.astype(bool)


def selected_indices(values: Any, asked: int, name: str = "TellInfo selected") -> np.ndarray:
    """``values`` as an int array, or NeurohoverError unless distinct integer indices of the ``asked`` genomes (1 to ``asked`` of them)."""
    s = _array(values)
    allowed = f"{name} must be distinct integer indices in 0..{asked - 1} of the {asked} asked genomes (1 to {asked} of them)"
    if s is None or s.ndim != 1 or not 1 <= s.size <= asked:
        got = "no array" if s is None else f"shape {s.shape}" if s.ndim != 1 else f"{s.size} {'index' if s.size == 1 else 'indices'}"
        raise NeurohoverError(f"{allowed}; got {got}: {brief(values)}")
    if s.dtype.kind not in "iu":
        raise NeurohoverError(f"{allowed}; got {s.dtype} values: {brief(values)}")
    outside = s[(s < 0) | (s >= asked)]
    if outside.size:
        raise NeurohoverError(f"{allowed}; got index {int(outside[0])}: {brief(values)}")
    if np.unique(s).size != s.size:
        twice = int(next(v for k, v in enumerate(s) if v in s[:k]))
        raise NeurohoverError(f"{allowed}; got index {twice} twice: {brief(values)}")
    return s.astype(np.int64)


def _array(values: Any) -> np.ndarray | None:
    """``np.asarray(values)``, or None for what NumPy makes no array of (a ragged list)."""
    try:
        return np.asarray(values)
    except (TypeError, ValueError, OverflowError):
        return None


#: The most episodes one generation may cost: a run's largest budget, evolution.config.MAX_BUDGET (not imported: config
#: imports the optimisers, which import this module). 10**30 was taken and made a run's evaluations 1e30 (T19-10).
MAX_EPISODES = 10**10


def require_episodes(value: Any, name: str = "episodes") -> int:
    """The episodes a generation cost as an int, or NeurohoverError unless an integer (not a bool) in 0..:data:`MAX_EPISODES`."""
    allowed = f"allowed an integer in 0..{MAX_EPISODES:,} (the episodes one generation cost)"
    if not whole_number(value):  # a type problem, not a range one: 3.0 was "out of range" (T22-14)
        raise NeurohoverError(f"{name}={brief(value)} is not allowed: {allowed}")
    if not 0 <= value <= MAX_EPISODES:
        raise NeurohoverError(f"{name}={brief(value)} is out of range: {allowed}")
    return int(value)


class Optimiser(Protocol):
    """The ask/tell surface of every optimiser here (:class:`SteadyStateNE`, :class:`GenerationalNE`,
    :class:`CMAES`, the population optimisers of :mod:`neurohover.evolution.optimisers`), which
    is what an evolution run (:mod:`neurohover.evolution.run`) uses: one ``tell(fitness, info)``.
    """

    def ask(self) -> np.ndarray:
        """The genomes to evaluate next, shape ``(n, D)``."""

    def tell(self, fitness: np.ndarray, info: TellInfo | None = None, /) -> None:
        """One return (or fitness estimate) per genome of the last :meth:`ask`, maximised, and what else the run knows."""

    def stop(self) -> bool:
        """Whether the optimiser's own termination criterion has fired."""

    @property
    def champion_genome(self) -> np.ndarray | None:
        """The champion (None before any finite fitness was told)."""

    @property
    def champion_return(self) -> float:
        """The champion's fitness (``-inf`` before any finite fitness was told)."""

    def state_dict(self) -> dict[str, Any]:
        """A plain JSON-serialisable snapshot of the whole state."""

    @classmethod
    def from_state_dict(cls, state: dict[str, Any]) -> Optimiser:
        """The optimiser :meth:`state_dict` saved; it continues bit-for-bit identically."""


class AskTellOrderError(NeurohoverError, RuntimeError):
    """ask() and tell() called out of order: a NeurohoverError, and still the RuntimeError it was for callers that catch that."""


#: What an out-of-order call is told to do (eleventh trial: a bare RuntimeError, which ``except NeurohoverError`` missed).
TELL_FIRST = "tell() called without a pending ask(): call ask() first, then tell() one return per genome it gave"
ASK_AGAIN = "ask() called again before tell() of the previous {what}: tell() its returns first, one per genome it gave"
BUSY = (
    "ask() or tell() called while another ask() or tell() of this optimiser is running (another thread's?): "
    "one sequence of calls only; give each thread its own optimiser"
)


# --------------------------------------------------------------------------- settings checks


def require_int(name: str, value: Any, minimum: int) -> int:
    """``value`` as an int, or NeurohoverError unless it is an integer (not a bool) ``>= minimum``."""
    if not whole_number(value) or value < minimum:
        raise NeurohoverError(f"{name}={brief(value)} must be an integer >= {minimum}")
    return int(value)


def require_prob(name: str, value: Any) -> float:
    """``value`` as a float (:func:`~neurohover.errors.setting_float`), or NeurohoverError unless it is a probability in [0, 1]."""
    if not finite_real(value) or not 0.0 <= float(value) <= 1.0:  # finite_real first: float(10**400) overflowed (eleventh trial)
        raise NeurohoverError(f"{name}={brief(value)} must be a probability in [0, 1]")
    return setting_float(value)  # np.float32(0.3) as 0.3, -0.0 as 0.0, as every other settings class stores them (T57-B01)


def require_std(name: str, value: Any) -> float:
    """``value`` as a float (:func:`~neurohover.errors.setting_float`: -0.0 as 0.0), or NeurohoverError unless it is a finite number >= 0."""
    if not finite_real(value) or float(value) < 0.0:
        raise NeurohoverError(f"{name}={brief(value)} must be a finite number >= 0")
    return setting_float(value)  # -0.0 as 0.0: NumPy's normal() refused a scale of -0.0 (fourteenth trial); np.float32(0.3) as 0.3 (T57-B01)


#: The largest spread (a mutation's or a search distribution's standard deviation, a step size) any optimiser takes:
#: far below a float's 1.8e308, so that genes drawn at that spread, and pycma's adaptation of it, stay finite
#: (sigma0=1e308 was pycma's AssertionError, sigma and mutate_std=1e308 a late "genome must hold finite numbers"; eleventh trial).
MAX_SPREAD = 1e100
#: The smallest positive spread a positive one may be: pycma's adaptation of sigma0=1e-320 (a subnormal) lost every
#: digit and failed its own "assert np.isfinite" (T35-A01); 1e-100 is as far below any useful step as MAX_SPREAD above.
MIN_POSITIVE_SPREAD = 1e-100
#: The smallest mutation spread but 0, 2**-52: N(0, std) (relative with a mutation_floor) moves no gene of size 1 below it (T57-A01).
MIN_SPREAD = float(np.finfo(np.float64).eps)


def require_spread(name: str, value: Any, *, positive: bool = False, what: str = "") -> float:
    """``value`` as a float (:func:`~neurohover.errors.setting_float`), or NeurohoverError unless a spread <= :data:`MAX_SPREAD`: 0 or
    from :data:`MIN_SPREAD`, or from :data:`MIN_POSITIVE_SPREAD` if ``positive``; ``what`` leads the message (the optimiser's name)."""
    if not finite_real(value) or not (MIN_POSITIVE_SPREAD <= float(value) if positive else 0.0 <= float(value)) or float(value) > MAX_SPREAD:
        low = f">= {MIN_POSITIVE_SPREAD:g}" if positive else ">= 0"
        raise NeurohoverError(f"{what}{name}={brief(value)} must be a finite number {low} and <= {MAX_SPREAD:g} (a larger one overflows the genes)")
    spread = setting_float(value)  # np.float32(0.3) as 0.3 (T57-B01); -0.0 as 0.0: NumPy's "scale < 0" mid-run (fourteenth trial)
    if not positive and 0.0 < spread < MIN_SPREAD:
        low = f"0 (no mutation) or a number in {lowest_allowed(MIN_SPREAD)}..{MAX_SPREAD:g}"
        raise NeurohoverError(f"{what}{name}={brief(value)} is out of range, too small to move a gene (below 2**-52): allowed {low}")
    return spread


def set_field(obj: Any, name: str, value: Any) -> None:
    """Set a field of a frozen settings dataclass (in ``__post_init__``)."""
    # Frozen dataclass: store plain Python numbers so that asdict() is JSON-able.
    object.__setattr__(obj, name, value)


#: The largest population any optimiser takes: a generation of it fits in one kernel call's episodes and in memory
#: (pop_size 1,000,000,000 hung, popsize 100,000,000,000 ran on without a word; third trial).
MAX_POPULATION = 100_000


def require_population(name: str, value: Any) -> int:
    """A population size: an integer in 2..:data:`MAX_POPULATION`, or ValueError."""
    size = require_int(name, value, 2)
    if size > MAX_POPULATION:
        raise NeurohoverError(f"{name}={brief(size)} must be an integer in 2..{MAX_POPULATION:,}")
    return size


def validate_variation_settings(obj: Any) -> None:
    """Check and normalise the fields both neuroevolution settings share (population, variation, budget)."""
    set_field(obj, "pop_size", require_population("pop_size", obj.pop_size))
    for name in ("crossover_prob", "averaging_prob", "mutate_prob", "mutate_frac", "mutate_repl"):
        set_field(obj, name, require_prob(name, getattr(obj, name)))
    set_field(obj, "mutate_std", require_spread("mutate_std", obj.mutate_std))
    if obj.budget is not None:
        set_field(obj, "budget", require_int("budget", obj.budget, 1))


# --------------------------------------------------------------------------- genomes and returns


_Settings = TypeVar("_Settings")


def as_returns(values: Any, name: str, allowed: str, minimum: int = 1) -> np.ndarray:
    """:func:`as_floats` of a population's returns that must also be a 1-D array of at least ``minimum`` of them
    (``allowed`` says what else, for values that are no numbers); NeurohoverError naming the shape otherwise (an empty
    or 2-D array came back as empty or 2-D weights; fifteenth trial)."""
    r = as_floats(values, name, allowed)
    if r.ndim != 1 or r.size < minimum:
        allowed = "a non-empty 1-D array of returns" if minimum == 1 else f"a 1-D array of {minimum} or more returns"
        raise NeurohoverError(f"{name} has shape {r.shape}: give {allowed} (real numbers)")
    return r


def check_settings(settings: Any, cls: type[_Settings]) -> _Settings:
    """``settings``, or ``cls()`` for None; NeurohoverError unless it is a ``cls`` (another optimiser's settings or a
    dict were an AttributeError at construction or at the first ask(); fourteenth trial)."""
    if settings is None:
        return cls()
    if not isinstance(settings, cls):
        raise NeurohoverError(f"settings={brief(settings)} is not allowed: give a {cls.__name__} (or None for its defaults)")
    return settings


def check_prototype(prototype: np.ndarray) -> np.ndarray:
    """A float64 copy of a non-empty 1-D genome of finite genes a Policy takes (ValueError otherwise; T48-B04: genes of
    1e300, past :data:`~neurohover.policies.MAX_GENE`, were evolved, refused only when the champion became a Policy)."""
    p = as_floats(prototype, "prototype", "a non-empty 1-D genome of finite numbers")
    if p.ndim != 1 or p.size == 0:
        raise NeurohoverError(f"prototype must be a non-empty 1-D genome, got shape {p.shape}")
    return check_genomes(p, p.size, "prototype", rows=0)


def check_info(info: Any, asked: int | None = None) -> None:
    """NeurohoverError unless ``info`` (what a ``tell`` is told besides the returns) is a :class:`TellInfo` or None (a dict
    was an AttributeError; fifteenth trial) whose fields fit a tell of ``asked`` genomes (:meth:`TellInfo.check`)."""
    if info is not None and not isinstance(info, TellInfo):
        raise NeurohoverError(f"info={brief(info)} is not allowed: give a TellInfo (its crashed, selected, episodes) or None")
    if info is not None and asked is not None:
        info.check(asked)


def check_returns(values: Any, n: int, what: str = "fitness", info: Any = None) -> np.ndarray:
    """``n`` returns as float64, one per asked genome; ``+inf`` is refused (ValueError). The one check of a ``tell``'s
    arguments: ``info`` too (:func:`check_info`), its fields against the ``n`` genomes asked."""
    check_info(info)
    f = as_floats(values, what, f"{n} returns, one per asked genome")
    if f.shape != (n,):
        raise NeurohoverError(f"{what} must have shape ({n},), one return per asked genome; got shape {f.shape}")
    if np.count_nonzero(f == np.inf):
        raise NeurohoverError(f"{what} contains +inf; returns must be finite, NaN or -inf")
    check_info(info, n)
    return f


def rank(returns: np.ndarray) -> np.ndarray:
    """Indices best first; NaN/-inf last; ties keep their order (deterministic)."""
    key = np.fmax(returns, -np.inf)  # NaN -> -inf
    return (-key).argsort(kind="stable")


# --------------------------------------------------------------------------- champions


class Clock:
    """Wall-clock seconds since the start of a run, continued across checkpoints."""

    def __init__(self, elapsed: float = 0.0) -> None:
        self._start = time.perf_counter() - elapsed

    def __call__(self) -> float:
        return time.perf_counter() - self._start


@dataclass(frozen=True)
class ChampionRecord:
    """A new champion: evaluations done so far, its return, seconds since the start, and whether
    its evaluation crashed (as told to ``SteadyStateNE.tell``; False without crash flags)."""

    evaluations: int
    champion_return: float
    wall_seconds: float
    crashed: bool = False


class ChampionTracker:
    """Best single return ever told, evaluations since it, and its history.

    The champion's crash flag is its history record's (the last one): it is fixed for the
    champion's lifetime, so the ``no-crash`` plateau count is ``since`` or 0 (:meth:`plateau`)
    and needs no state of its own.
    """

    def __init__(self) -> None:
        self.evaluations = 0
        self.genome: np.ndarray | None = None
        self.best = -math.inf
        self.since = 0
        self.history: list[ChampionRecord] = []

    def update(self, genomes: np.ndarray, returns: np.ndarray, wall: float, crashed: np.ndarray | None = None) -> None:
        """Count one evaluation per genome; a strictly better return makes a new champion."""
        for k, (g, r) in enumerate(zip(genomes, returns, strict=True)):
            self.evaluations += 1
            if r > self.best:  # strict; NaN compares False
                self.best = float(r)
                self.genome = np.array(g, dtype=np.float64)
                self.since = 0
                hit = crashed is not None and bool(crashed[k])
                self.history.append(ChampionRecord(self.evaluations, self.best, wall, hit))
            else:
                self.since += 1

    @property
    def champion_crashed(self) -> bool:
        return bool(self.history) and self.history[-1].crashed

    def plateau(self, literal: bool) -> int:
        """Evaluations counted towards the plateau: all since the champion (``literal``), or
        only while the champion's evaluation did not crash (``no-crash``)."""
        return self.since if literal or not self.champion_crashed else 0

    def to_dict(self) -> dict[str, Any]:
        """Strict-JSON state (the ``tracker`` entry of ``SteadyStateNE.state_dict``)."""
        return {
            "evaluations": self.evaluations,
            "genome": enc_array(self.genome),
            "best": enc_float(self.best),
            "since": self.since,
            "history": [  # a 4th element only for a crashed champion (the format stays as it was)
                [h.evaluations, enc_float(h.champion_return), h.wall_seconds] + ([True] if h.crashed else []) for h in self.history
            ],
        }

    @classmethod
    def from_dict(cls, d: dict[str, Any], size: int | None = None) -> ChampionTracker:
        """The tracker :meth:`to_dict` saved, its champion a genome of ``size`` genes (any size if None); EntryError or
        NeurohoverError for a damaged one (evaluations -1, True as a count and a genome of bools were taken; sixteenth trial)."""
        t = cls()
        t.evaluations, t.since = read_count(d["evaluations"]), read_count(d["since"])
        if t.since > t.evaluations:
            raise EntryError(f"since={t.since} is more than its evaluations ({t.evaluations}): allowed 0..evaluations")
        t.genome = dec_array(d["genome"], "tracker genome")
        if t.genome is not None:
            check_genomes(t.genome, t.genome.size if size is None else size, "tracker genome", rows=0)
        t.best = dec_float(d["best"])
        if math.isnan(t.best) or t.best == math.inf or (t.genome is None) != (t.best == -math.inf):
            raise EntryError(f"best={brief(d['best'])} is not allowed: a finite return with a champion genome, -inf without one")
        if not isinstance(d["history"], list):  # {} was read as no history (T19-09)
            raise EntryError(f"history={brief(d['history'])} is not allowed: a list of [evaluations, return, seconds] records")
        t.history = [_champion_record(h) for h in d["history"]]
        _check_history(t)
        return t


def _champion_record(h: Any) -> ChampionRecord:
    """One :class:`ChampionRecord` of a saved tracker's history: evaluations, return, seconds and, if crashed, true."""
    if not isinstance(h, list) or len(h) not in (3, 4) or (len(h) == 4 and h[3] is not True):
        raise EntryError(f"history record {brief(h)} is not allowed: [evaluations, return, seconds] or, for a crashed champion, [..., true]")
    return ChampionRecord(read_count(h[0]), dec_float(h[1]), read_seconds(h[2]), len(h) == 4)


def _check_history(t: ChampionTracker) -> None:
    """EntryError unless ``t``'s history is what :meth:`ChampionTracker.update` makes of its counts and champion: one
    record per strictly better finite return, the last one the champion ``since`` evaluations ago (NaN, 'nan' and
    disordered returns, and a best that disagreed with them, were taken; T19-09)."""
    if t.genome is None:
        if t.history or t.since != t.evaluations:
            raise EntryError(
                f"without a champion there is no history and since equals evaluations ({t.evaluations}); got {len(t.history)} records, since={t.since}"
            )
        return
    if not t.history:
        raise EntryError("a champion without a history record: every champion has one")
    previous = ChampionRecord(0, -math.inf, 0.0)
    for h in t.history:
        if not (previous.evaluations < h.evaluations <= t.evaluations and previous.champion_return < h.champion_return < math.inf):
            raise EntryError(
                f"history record [{h.evaluations}, {enc_float(h.champion_return)}, ...] is not allowed: each record's evaluations and return"
                f" are above the one before ({previous.evaluations}, {enc_float(previous.champion_return)}),"
                f" its evaluations at most {t.evaluations}, its return finite"
            )
        previous = h
    if previous.champion_return != t.best or previous.evaluations != t.evaluations - t.since:
        raise EntryError(
            f"the last history record [{previous.evaluations}, {enc_float(previous.champion_return)}, ...] is not the champion's: best={enc_float(t.best)}"
            f" found at evaluation {t.evaluations - t.since} (evaluations - since)"
        )


class ChampionViews:
    """Read-outs of an optimiser's champion tracking (shared by SteadyStateNE and CMAES)."""

    _tracker: ChampionTracker

    @property
    def evaluations(self) -> int:
        """Number of returns told so far."""
        return self._tracker.evaluations

    @property
    def champion_genome(self) -> np.ndarray | None:
        """Genome with the best single return ever told (None before any finite return)."""
        return None if self._tracker.genome is None else self._tracker.genome.copy()

    @property
    def champion_return(self) -> float:
        """Best single return ever told (``-inf`` before any finite return)."""
        return self._tracker.best

    @property
    def evaluations_since_champion(self) -> int:
        """Evaluations told since the current champion appeared."""
        return self._tracker.since

    @property
    def champion_crashed(self) -> bool:
        """Whether the champion's evaluation was told as crashed (False without crash flags)."""
        return self._tracker.champion_crashed

    @property
    def history(self) -> list[ChampionRecord]:
        """One record per new champion, in order."""
        return list(self._tracker.history)


class PopulationOptimiser(ChampionViews):
    """Base of the registry's population optimisers (evosax-style ask/tell over flat genomes).

    The base keeps the asked batch (asked again before a tell, the same batch comes back, as after a
    resumed checkpoint), checks the returns told against it, and tracks the champion and the wall
    clock; an optimiser writes ``_ask()`` (its next batch, shape ``(n, D)``), ``_tell(genomes, returns,
    info)`` (its update, returns maximised and already checked), ``stop()``, ``popsize`` and its state.
    """

    def __init__(self) -> None:
        self._tracker = ChampionTracker()
        self._clock = Clock()
        self._pending: np.ndarray | None = None

    def _ask(self) -> np.ndarray:
        raise NotImplementedError

    def _tell(self, genomes: np.ndarray, returns: np.ndarray, info: TellInfo | None) -> None:
        raise NotImplementedError

    _busy = False  # True while ask() draws or tell() updates: a call meanwhile (another thread's) is refused (T36-B04)

    def _claim(self) -> None:
        if self._busy:
            raise AskTellOrderError(BUSY)
        self.__dict__["_busy"] = True  # in the instance only while busy: a state_dict() is as before

    def ask(self) -> np.ndarray:
        """The next batch of genomes, shape ``(n, D)``."""
        if self._pending is None:
            self._claim()
            try:
                self._pending = np.asarray(self._ask(), dtype=np.float64)
            finally:
                self.__dict__.pop("_busy", None)
        elif self._busy:  # the batch being told: its update is under way
            raise AskTellOrderError(BUSY)
        return self._pending.copy()

    def tell(self, fitness: np.ndarray, info: TellInfo | None = None) -> None:
        """One return per asked genome (maximised; non-finite ones never become champion)."""
        genomes = self._pending
        if genomes is None:
            raise AskTellOrderError(BUSY if self._busy else TELL_FIRST)
        f = check_returns(fitness, genomes.shape[0], info=info)
        self._claim()  # a second tell() of this batch (another thread's) was pycma's RuntimeError (T36-B04)
        try:
            self._tell(genomes, f, info)
            self._tracker.update(genomes, f, self._clock())
            self._pending = None
        finally:
            self.__dict__.pop("_busy", None)
