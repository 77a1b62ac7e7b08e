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
import pickle
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Protocol, TypeVar, overload

import numpy as np

from ..errors import NeurohoverError, as_floats, brief, finite_real, real_number, whole_number

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
    "read_seconds",
    "require_int",
    "require_population",
    "MAX_POPULATION",
    "MAX_SPREAD",
    "require_spread",
    "require_prob",
    "require_std",
    "rng_from_state",
    "set_field",
    "validate_variation_settings",
]

#: Version of the optimisers' ``state_dict`` format.
STATE_VERSION = 1


@dataclass(frozen=True)
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
        Episodes the generation cost (generational NE's history).
    """

    crashed: np.ndarray | None = None
    selected: np.ndarray | None = None
    episodes: int | None = None


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


# --------------------------------------------------------------------------- settings checks


def require_int(name: str, value: Any, minimum: int) -> int:
    """``value`` as an int, or NeurohoverError unless it is an integer (not a bool) ``>= minimum``."""
    if not whole_number(value) or value < minimum:
        raise NeurohoverError(f"{name}={brief(value)} must be an integer >= {minimum}")
    return int(value)


def require_prob(name: str, value: Any) -> float:
    """``value`` as a float, or NeurohoverError unless it is a probability in [0, 1]."""
    if not finite_real(value) or not 0.0 <= float(value) <= 1.0:  # finite_real first: float(10**400) overflowed (eleventh trial)
        raise NeurohoverError(f"{name}={brief(value)} must be a probability in [0, 1]")
    return float(value)


def require_std(name: str, value: Any) -> float:
    """``value`` as a float (-0.0 as 0.0), or NeurohoverError unless it is a finite number >= 0."""
    if not finite_real(value) or float(value) < 0.0:
        raise NeurohoverError(f"{name}={brief(value)} must be a finite number >= 0")
    return float(value) + 0.0  # -0.0 + 0.0 is 0.0, any other float unchanged: NumPy's normal() refused a scale of -0.0 (fourteenth trial)


#: The largest spread (a mutation's or a search distribution's standard deviation, a step size) any optimiser takes:
#: far below a float's 1.8e308, so that genes drawn at that spread, and pycma's adaptation of it, stay finite
#: (sigma0=1e308 was pycma's AssertionError, sigma and mutate_std=1e308 a late "genome must hold finite numbers"; eleventh trial).
MAX_SPREAD = 1e100


def require_spread(name: str, value: Any, *, positive: bool = False, what: str = "") -> float:
    """``value`` as a float, or NeurohoverError unless it is a spread in [0, :data:`MAX_SPREAD`] (``(0, ...]`` if
    ``positive``); ``what`` leads the message (the optimiser's name)."""
    if not finite_real(value) or not (0.0 < float(value) if positive else 0.0 <= float(value)) or float(value) > MAX_SPREAD:
        low = "> 0" if positive else ">= 0"
        raise NeurohoverError(f"{what}{name}={brief(value)} must be a finite number {low} and <= {MAX_SPREAD:g} (a larger one overflows the genes)")
    return float(value) + 0.0  # -0.0 made 0.0: mutate_std=-0.0 was taken, then NumPy's "scale < 0" mid-run (fourteenth trial)


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
    """A float64 copy of a non-empty, finite 1-D genome (ValueError otherwise)."""
    p = as_floats(prototype, "prototype", "a non-empty 1-D genome of finite numbers")
    if p.ndim != 1 or p.size == 0:
        raise NeurohoverError(f"prototype must be a non-empty 1-D genome, got shape {p.shape}")
    if not np.all(np.isfinite(p)):
        raise NeurohoverError("prototype must be finite")
    return p


def check_info(info: Any) -> None:
    """NeurohoverError unless ``info`` (what a ``tell`` is told besides the returns) is a :class:`TellInfo` or None (a dict
    was an AttributeError; fifteenth trial)."""
    if info is not None and not isinstance(info, TellInfo):
        raise NeurohoverError(f"info={brief(info)} is not allowed: give a TellInfo (its crashed, selected, episodes) or None")


def check_returns(values: Any, n: int, what: str = "fitness", info: Any = None) -> np.ndarray:
    """``n`` returns as float64, one per asked genome; ``+inf`` is refused (ValueError). The one check of a ``tell``'s
    arguments: ``info`` too (:func:`check_info`)."""
    check_info(info)
    f = as_floats(values, what, f"{n} returns, one per asked genome")
    if f.shape != (n,):
        raise NeurohoverError(f"{what} must have shape ({n},), one return per asked genome; got shape {f.shape}")
    if np.count_nonzero(f == np.inf):
        raise NeurohoverError(f"{what} contains +inf; returns must be finite, NaN or -inf")
    return f


def rank(returns: np.ndarray) -> np.ndarray:
    """Indices best first; NaN/-inf last; ties keep their order (deterministic)."""
    key = np.fmax(returns, -np.inf)  # NaN -> -inf
    return (-key).argsort(kind="stable")


# --------------------------------------------------------------------------- state encoding


def enc_float(x: float) -> float | str:
    """A float for strict JSON: non-finite values become ``"nan"``, ``"inf"`` or ``"-inf"``
    (``float()`` reads them back)."""
    x = float(x)
    if math.isfinite(x):
        return x
    return "nan" if math.isnan(x) else ("inf" if x > 0 else "-inf")


def enc_array(a: np.ndarray | None) -> dict[str, Any] | None:
    """An array for strict JSON: its shape and its values through :func:`enc_float`."""
    if a is None:
        return None
    a = np.asarray(a, dtype=np.float64)
    return {"shape": list(a.shape), "data": [enc_float(v) for v in a.ravel()]}


#: What :func:`enc_float` writes for a non-finite float, read back as it (other text is no number of a state).
_NON_FINITE = {"nan": math.nan, "inf": math.inf, "-inf": -math.inf}
_STORED = "real numbers or 'nan', 'inf', '-inf' as state_dict() wrote them"


def dec_float(value: Any) -> float:
    """The float :func:`enc_float` encoded: a real number (not a bool) or ``"nan"``, ``"inf"``, ``"-inf"``; other text
    (``'1.5'``) a ValueError, anything else an :class:`EntryError` (float() took both, and True as 1.0; sixteenth trial)."""
    if isinstance(value, str):
        if value in _NON_FINITE:
            return _NON_FINITE[value]
        raise ValueError(f"could not convert string to float: {brief(value)} (a stored number is no text, but for 'nan', 'inf', '-inf')")
    if not real_number(value):  # a bool, or a time span (Real to numbers, T17-1)
        raise EntryError(f"{brief(value)} is no number: allowed {_STORED}")
    return float(value)


@overload
def dec_array(d: dict[str, Any], name: str = "array") -> np.ndarray: ...
@overload
def dec_array(d: None, name: str = "array") -> None: ...
@overload
def dec_array(d: dict[str, Any] | None, name: str = "array") -> np.ndarray | None: ...
def dec_array(d: dict[str, Any] | None, name: str = "array") -> np.ndarray | None:
    """The array :func:`enc_array` encoded; NeurohoverError naming ``name`` unless every value is a real number (not a
    bool) or a non-finite float's text: bools and numeric text were read as numbers (every gene True as 1.0, a return
    '1.5' as 1.5; sixteenth trial), so each value is checked before any is cast."""
    if d is None:
        return None
    data, shape = d["data"], [read_count(n) for n in d["shape"]]
    values = [_NON_FINITE.get(v, v) if isinstance(v, str) else v for v in data]
    for v in values:
        if type(v) is not float and type(v) is not int and not real_number(v):
            as_floats(v, f"{name} data entry", _STORED)  # text, a bool, None: named as every array of real numbers is
            raise EntryError(f"{name} data entry {brief(v)} is no number: allowed {_STORED}")  # a list in the list
    return as_floats(values, f"{name} data", _STORED).reshape(shape)


@overload
def check_genomes(a: np.ndarray, size: int, name: str, rows: int | None = None) -> np.ndarray: ...
@overload
def check_genomes(a: None, size: int, name: str, rows: int | None = None) -> None: ...
@overload
def check_genomes(a: np.ndarray | None, size: int, name: str, rows: int | None = None) -> np.ndarray | None: ...
def check_genomes(a: np.ndarray | None, size: int, name: str, rows: int | None = None) -> np.ndarray | None:
    """``a`` (a state's decoded array) unless it is not genomes of ``size`` genes (``rows`` of them, or one genome when
    ``rows`` is 0): ValueError naming ``name``, so that a damaged checkpoint is refused on reading, not mid-run."""
    if a is None:
        return None
    if rows == 0:
        ok, expected = a.shape == (size,), f"({size},)"
    else:
        ok, expected = a.ndim == 2 and a.shape[1] == size, f"(n, {size})"
    if not ok:
        raise NeurohoverError(f"{name} has shape {a.shape}, expected {expected} (genomes of {size} genes)")
    if a.dtype.kind != "f" or not np.all(np.isfinite(a)):  # a NaN gene was resumed without a word (eighth trial)
        raise NeurohoverError(f"{name} holds a gene that is not a finite number")
    if rows and a.shape[0] != rows:  # a pop_size of 60 over 50 genomes was run on (sixteenth trial)
        raise NeurohoverError(f"{name} has {a.shape[0]} genomes where the state's settings make {rows}")
    return a


def rng_from_state(state: dict[str, Any]) -> np.random.Generator:
    """A ``numpy.random.Generator`` in the saved ``bit_generator.state``."""
    if not isinstance(state, dict) or state.get("bit_generator") not in ("PCG64", "PCG64DXSM", "MT19937", "Philox", "SFC64"):
        raise NeurohoverError(f"random state {state!r:.80} is not one of a numpy bit generator")
    bit_generator = getattr(np.random, state["bit_generator"])()
    bit_generator.state = state
    return np.random.Generator(bit_generator)


def check_state(state: dict[str, Any], kind: str) -> None:
    """ValueError unless ``state`` is a ``state_dict`` of type ``kind`` in :data:`STATE_VERSION`."""
    if not isinstance(state, dict):
        raise NeurohoverError(f"state dict is a {type(state).__name__}, not a dict")
    if state.get("type") != kind:
        raise NeurohoverError(f"state dict is for {brief(state.get('type'))}, not {kind!r}")
    version = state.get("version")
    if isinstance(version, bool) or version != STATE_VERSION:  # True == 1 was taken as version 1 (fourteenth trial)
        raise NeurohoverError(f"unsupported state version {brief(version)}: allowed {STATE_VERSION}")


def check_entries(state: dict[str, Any], kind: str, entries: tuple[str, ...], what: str = "", remedy: str = "") -> None:
    """NeurohoverError naming the entries of a ``kind`` state dict that are none of ``entries`` (every entry any
    version of its ``state_dict`` wrote): an unknown one was ignored without a word (fifteenth trial). ``what`` and
    ``remedy`` replace the message's "KIND state dict" and its advice (a checkpoint's own tables; sixteenth trial)."""
    unknown = [key for key in state if key not in entries]
    if unknown:
        shown = ", ".join(brief(key) for key in unknown[:5]) + (f" and {len(unknown) - 5} more" if len(unknown) > 5 else "")
        remedy = remedy or f"give a dict that {kind}.state_dict() returned"
        raise NeurohoverError(f"{what or kind + ' state dict'} has unknown entries {shown}: allowed {', '.join(entries)}; {remedy}")


#: What reading back a damaged entry of a state raises besides NeurohoverError: a value of the wrong type, a missing
#: key inside it, text that is no number, no base64 or no pickle.
STATE_DAMAGE = (KeyError, TypeError, ValueError, AttributeError, IndexError, OverflowError, EOFError, ImportError, pickle.UnpicklingError)

_T = TypeVar("_T")
_REQUIRED = object()


class EntryError(ValueError):
    """What a reader of :func:`read_entry` raises for a value of the wrong kind; its message says what is allowed."""


def damage_text(err: BaseException) -> str:
    """What an error reading back a damaged state or checkpoint says, in a few words."""
    if isinstance(err, KeyError):
        return f"it has no {brief(err.args[0]) if err.args else 'such'} entry"
    return str(err) if isinstance(err, (NeurohoverError, EntryError)) else f"{type(err).__name__}: {err}"


def read_entry(state: dict[str, Any], kind: str, key: str, read: Callable[[Any], _T], default: Any = _REQUIRED) -> _T:
    """``read(state[key])`` (``default`` for a missing entry, if given): entry ``key`` of a ``kind`` state dict read
    back, or one NeurohoverError naming the entry when it is missing or damaged ('x' as a generation or a tracker was a
    bare ValueError, TypeError or KeyError; fourteenth trial). A NeurohoverError of ``read`` (it names what it read)
    goes through as it is."""
    if key not in state and default is _REQUIRED:
        raise NeurohoverError(f"{kind} state dict has no {key!r} entry: give a dict that {kind}.state_dict() returned")
    value = state.get(key, default)
    try:
        return read(value)
    except NeurohoverError:
        raise
    except STATE_DAMAGE as err:
        raise NeurohoverError(
            f"{kind} state dict's {key!r} entry {brief(value)} is damaged ({damage_text(err)}): give a dict that {kind}.state_dict() returned"
        ) from None


def read_count(value: Any) -> int:
    """A state's count (a generation, evaluations): an integer >= 0, not a bool, else :class:`EntryError`."""
    if not whole_number(value) or value < 0:
        raise EntryError("not a count: allowed an integer >= 0")
    return int(value)


def read_seconds(value: Any) -> float:
    """A state's seconds: a finite number >= 0, not a bool, else :class:`EntryError`."""
    if not finite_real(value) or float(value) < 0.0:
        raise EntryError("not a number of seconds: allowed a finite number >= 0")
    return float(value)


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
        t.history = [_champion_record(h) for h in d["history"]]
        return t


def _champion_record(h: Any) -> ChampionRecord:
    """One :class:`ChampionRecord` of a saved tracker's history: evaluations, return, seconds and, if crashed, true."""
    if not isinstance(h, list) or len(h) not in (3, 4) or (len(h) == 4 and h[3] is not True):
        raise EntryError(f"history record {brief(h)} is not allowed: [evaluations, return, seconds] or, for a crashed champion, [..., true]")
    return ChampionRecord(read_count(h[0]), dec_float(h[1]), read_seconds(h[2]), len(h) == 4)


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

    def ask(self) -> np.ndarray:
        """The next batch of genomes, shape ``(n, D)``."""
        if self._pending is None:
            self._pending = np.asarray(self._ask(), dtype=np.float64)
        return self._pending.copy()

    def tell(self, fitness: np.ndarray, info: TellInfo | None = None) -> None:
        """One return per asked genome (maximised; non-finite ones never become champion)."""
        if self._pending is None:
            raise AskTellOrderError(TELL_FIRST)
        genomes = self._pending
        f = check_returns(fitness, genomes.shape[0], info=info)
        self._tell(genomes, f, info)
        self._tracker.update(genomes, f, self._clock())
        self._pending = None
