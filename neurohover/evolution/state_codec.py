"""How an optimiser's ``state_dict`` is written and read back: numbers and arrays in strict JSON, and the checks that
refuse a damaged state on reading, naming its entry (split out of :mod:`neurohover.evolution.common`, which re-exports
every name here).

Internal: neurohover's plumbing, called with values neurohover has checked: its helpers trust their callers and do not
check their own arguments (README, Python API, What is public).
"""

from __future__ import annotations

import math
import pickle
from collections.abc import Callable
from typing import Any, TypeVar, overload

import numpy as np

from ..errors import NeurohoverError, as_floats, brief, finite_real, real_number, whole_number
from ..policies import MAX_GENE
from ..sim.constants import MAX_SECONDS, seconds_allowed  # MAX_SECONDS re-exported: a state's bound, as every record's

__all__ = [
    "STATE_DAMAGE",
    "STATE_VERSION",
    "EntryError",
    "check_entries",
    "check_genomes",
    "check_state",
    "check_stream",
    "damage_text",
    "dec_array",
    "dec_float",
    "enc_array",
    "enc_float",
    "MAX_COUNT",
    "MAX_SECONDS",
    "read_count",
    "read_entry",
    "read_return",
    "read_settings",
    "read_seconds",
    "required",
    "rng_from_state",
]

#: Version of the optimisers' ``state_dict`` format.
STATE_VERSION = 1


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
    (``'1.5'``) or anything else an :class:`EntryError` (float() took both, and True as 1.0; sixteenth trial; a damaged
    state's message said "ValueError: could not convert ...")."""
    if isinstance(value, str):
        if value in _NON_FINITE:
            return _NON_FINITE[value]
        raise EntryError(f"could not convert string to float: {brief(value)} (a stored number is no text, but for 'nan', 'inf', '-inf')")
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
    for k, v in enumerate(values):
        if type(v) is not float and type(v) is not int and not real_number(v):
            where = f"; it is data entry {k} of {len(values)}"  # which of a genome's thousands (T21-13)
            try:
                as_floats(v, f"{name} data entry", _STORED)  # text, a bool, None: named as every array of real numbers is
            except NeurohoverError as err:
                raise NeurohoverError(f"{err}{where}") from None
            raise EntryError(f"{name} data entry {brief(v)} is no number: allowed {_STORED}{where}")  # a list in the list
    return as_floats(values, f"{name} data", _STORED).reshape(shape)


@overload
def check_genomes(a: np.ndarray, size: int, name: str, rows: int | None = None, genes: bool = True) -> np.ndarray: ...
@overload
def check_genomes(a: None, size: int, name: str, rows: int | None = None, genes: bool = True) -> None: ...
@overload
def check_genomes(a: np.ndarray | None, size: int, name: str, rows: int | None = None, genes: bool = True) -> np.ndarray | None: ...
def check_genomes(a: np.ndarray | None, size: int, name: str, rows: int | None = None, genes: bool = True) -> np.ndarray | None:
    """``a`` (a state's decoded array) unless it is not genomes of ``size`` genes (``rows`` of them, or one genome when
    ``rows`` is 0): ValueError naming ``name``, so that a damaged checkpoint is refused on reading, not mid-run. Genes
    (``genes``; not an array of genome shape that holds other numbers, Adam's moments) are capped as a Policy's are
    (:data:`~neurohover.policies.MAX_GENE`): a population gene of 1e300 was resumed and kept (T33-B06)."""
    if a is None:
        return None
    if rows == 0:
        ok, expected = a.shape == (size,), f"({size},)"
    else:
        ok, expected = a.ndim == 2 and a.shape[1] == size, f"(n, {size})"
    if not ok:
        raise NeurohoverError(f"{name} has shape {a.shape}, expected {expected} (genomes of {size} genes)")
    if a.dtype.kind != "f":
        raise NeurohoverError(f"{name} holds a gene that is not a finite number: its genes are {a.dtype} values, allowed finite floats")

    def where(k: int) -> str:
        return f"gene {k} is {brief(float(a.flat[k]))}" if a.ndim == 1 else f"data entry {k} (genome {k // size}, gene {k % size}) is {brief(float(a.flat[k]))}"

    bad = np.flatnonzero(~np.isfinite(a))  # a NaN gene was resumed without a word (eighth trial); which one, T21-13
    if bad.size:
        more = f", and {bad.size - 1} more" if bad.size > 1 else ""
        raise NeurohoverError(f"{name} holds a gene that is not a finite number: {where(int(bad[0]))}{more}; allowed finite numbers")
    big = np.flatnonzero(np.abs(a) > MAX_GENE) if genes else np.empty(0, dtype=np.intp)  # not Adam's moments, which are no genes
    if big.size:
        raise NeurohoverError(
            f"{name} holds a gene that is out of range: {where(int(big[0]))}; allowed numbers in [-{MAX_GENE:g}, {MAX_GENE:g}] (a policy's genes)"
        )
    if rows and a.shape[0] != rows:  # a pop_size of 60 over 50 genomes was run on (sixteenth trial)
        raise NeurohoverError(f"{name} has {a.shape[0]} genomes where the state's settings make {rows}")
    return a


def rng_from_state(state: dict[str, Any]) -> np.random.Generator:
    """A ``numpy.random.Generator`` in the saved ``bit_generator.state`` (:func:`check_stream`)."""
    check_stream(state, "PCG64", "rng")  # default_rng's, each optimiser's: 2.5 and True were taken (T47-B10)
    bit_generator: Any = np.random.PCG64()
    bit_generator.state = state
    return np.random.Generator(bit_generator)


#: The entries of a PCG64 bit generator's state (numpy's ``bit_generator.state``): the largest value of each, and as text.
_STREAM_TOPS = {"state": (2**128 - 1, "2**128-1"), "inc": (2**128 - 1, "2**128-1"), "has_uint32": (1, "1"), "uinteger": (2**32 - 1, "2**32-1")}


def check_stream(stream: Any, kind: str, what: str = "mdp_stream") -> None:
    """EntryError (a ValueError, said plainly in a damaged checkpoint's message) unless ``stream`` is a state of the
    ``kind`` (PCG64) bit generator as numpy writes it: its setter took a state or inc of True, 1.5 or 2**70 and a
    has_uint32 of -1 (T19-08). ``what``: the entry named (an optimiser's ``rng``, whose 2.5 and True numpy took as well,
    and a resumed run differed from the uninterrupted one without a word; T47-B10)."""
    entries = ("bit_generator", "state", "has_uint32", "uinteger")
    if kind != "PCG64" or not isinstance(stream, dict) or sorted(stream) != sorted(entries) or stream["bit_generator"] != kind:
        raise EntryError(f"{what}={brief(stream)} is not allowed: allowed a {kind} state table ({', '.join(entries)}) as the run wrote it")
    inner = stream["state"]
    if not isinstance(inner, dict) or sorted(inner) != ["inc", "state"]:
        raise EntryError(f"{what}'s state={brief(inner)} is not allowed: allowed a table of state and inc")
    for name, value in (("state.state", inner["state"]), ("state.inc", inner["inc"]), ("has_uint32", stream["has_uint32"]), ("uinteger", stream["uinteger"])):
        top, text = _STREAM_TOPS[name.rpartition(".")[2]]
        if not whole_number(value) or not 0 <= value <= top:
            raise EntryError(f"{what}'s {name}={brief(value)} is not allowed: allowed an integer in 0..{text}")
    if inner["inc"] % 2 == 0:  # numpy sets (seed sequence << 1) | 1
        raise EntryError(f"{what}'s state.inc={brief(inner['inc'])} is not allowed: a PCG64 increment is odd")


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


#: The largest count a state holds, what an int64 holds: a generation of 2**70 was taken and ended a resumed run at once (T19-08).
MAX_COUNT = 2**63 - 1


def read_count(value: Any) -> int:
    """A state's count (a generation, evaluations): an integer in 0..:data:`MAX_COUNT`, not a bool, else :class:`EntryError`."""
    if not whole_number(value) or value < 0:
        raise EntryError("not a count: allowed an integer >= 0")
    if value > MAX_COUNT:
        raise EntryError(f"a count past {MAX_COUNT} (2**63 - 1): allowed an integer in 0..{MAX_COUNT}")
    return int(value)


def read_seconds(value: Any) -> float:
    """A state's seconds: a finite number in [0, :data:`MAX_SECONDS`] (100 years), not a bool, else :class:`EntryError`."""
    if not seconds_allowed(value):
        if finite_real(value) and float(value) > MAX_SECONDS:
            raise EntryError(f"more seconds than 100 years: allowed a number in [0, {MAX_SECONDS:.6g}]")
        raise EntryError("not a number of seconds: allowed a finite number >= 0")
    return float(value)


def read_return(value: Any) -> float:
    """A return an optimiser keeps as a champion's (:func:`dec_float`): a finite number or ``-inf`` (a NaN estimate is
    kept as ``-inf``, +inf is never told), else :class:`EntryError` ('nan' was taken as a champion's return; T19-09)."""
    r = dec_float(value)
    if math.isnan(r) or r == math.inf:
        raise EntryError(f"{brief(value)} is no champion's return: allowed a finite number or '-inf'")
    return r


def read_settings(values: Any, cls: Callable[..., _T], names: tuple[str, ...], old: dict[str, Any]) -> _T:
    """``cls(**values)`` of a state's settings table ``values``, whose fields ``names`` that a checkpoint written before
    one existed lacks default to ``old``'s; every other field must be given ({} was read as the defaults, T19-03).
    EntryError for a missing field; no table and a bad value are ``cls``'s error."""
    missing = [name for name in names if isinstance(values, dict) and name not in values and name not in old]  # no dict: cls's TypeError
    if missing:
        raise EntryError(f"settings lack {', '.join(missing)}: allowed every field, as state_dict() wrote them")
    return cls(**{**old, **values})


def required(value: _T | None, what: str) -> _T:
    """``value`` unless it is None, else :class:`EntryError` naming ``what`` (a population of None was an
    AttributeError at the first ask(); T19-02)."""
    if value is None:
        raise EntryError(f"no {what}: allowed what state_dict() wrote, not null")
    return value
