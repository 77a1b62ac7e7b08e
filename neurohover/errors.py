"""The one exception type for bad input, so the CLI can print its message and exit with status 2."""

from __future__ import annotations

import dataclasses
import datetime
import math
import numbers
import operator
import re
import signal
import sys
from typing import TYPE_CHECKING, Any, TypeGuard

if TYPE_CHECKING:  # numpy is imported where used: the package installs its signal handlers after this module, before numpy
    import numpy as np


class NeurohoverError(ValueError):
    """Bad input: the message names the bad value and what is allowed."""


class OutputError(NeurohoverError):
    """An output file could not be written (a full disk, a read-only place): the output's fault, not the input's."""


class CheckpointReplaced(UserWarning):
    """An evolution started afresh where its checkpoint file holds a run's checkpoint (``resume=True`` continues it)."""


class Terminated(KeyboardInterrupt):
    """A stop signal (:func:`stop_signals`: SIGTERM, SIGHUP, SIGUSR1) arrived where the command handles it (like Ctrl-C:
    finished work kept, one line, status 128 + ``signum``: 143 for SIGTERM, 129 for SIGHUP)."""

    def __init__(self, *args: object, signum: int = 15) -> None:
        super().__init__(*args)
        self.signum = signum


#: The signals whose default ends a process and that the command takes as SIGTERM: a batch scheduler's warnings before
#: its kill (SIGUSR1/SIGUSR2: SGE's -notify, Slurm's --signal; SIGXCPU: a CPU-time limit), the timers (T35-A03), a UPS's
#: SIGPWR, SIGIO and SIGSTKFLT (T38-A04); and the real-time signals (:func:`stop_signals`).
_ALSO_STOPPING = ("SIGUSR1", "SIGUSR2", "SIGXCPU", "SIGALRM", "SIGVTALRM", "SIGPROF", "SIGPWR", "SIGIO", "SIGSTKFLT")


def stop_signals(command: bool = True) -> list[int]:
    """The signals the command takes as SIGTERM (:class:`Terminated`): SIGTERM, SIGHUP (a closed terminal or a dropped SSH
    session), SIGUSR1, SIGUSR2, SIGXCPU, SIGALRM, SIGVTALRM, SIGPROF, SIGPWR, SIGIO, SIGSTKFLT and SIGRTMIN..SIGRTMAX,
    where the system has them: every signal whose default ends a process without a core dump but SIGPIPE, and SIGXCPU.
    SIGPIPE stays ignored, as Python sets it: a reader gone away is a BrokenPipeError, the command's quiet status 1
    (``neurohover demo | head -1``), which a handler would make a "terminated" stop (T44-A02). Python's
    defaults ended a run at once without a word, and evolve without its checkpoint (T32-A03, T35-A03, T38-A04). SIGQUIT and SIGTRAP keep
    their defaults: the stop at once, with a core dump, that they ask for (as SIGKILL, the temporary files such a stop
    leaves are removed by the next run of the output: :func:`~neurohover.locks.remove_dead_writers_files`).
    ``command`` False: those a program calling neurohover hands over while it runs (SIGTERM and SIGHUP; the others
    are often a program's own: faulthandler's stack dump, a log rotation, its own timers)."""
    names = ("SIGTERM", "SIGHUP", *_ALSO_STOPPING) if command else ("SIGTERM", "SIGHUP")
    found = [int(getattr(signal, name)) for name in names if hasattr(signal, name)]
    if command and hasattr(signal, "SIGRTMIN"):  # most have no name of their own: numbers
        found += range(signal.SIGRTMIN, signal.SIGRTMAX + 1)
    return found


def whole_number(value: object) -> TypeGuard[int]:
    """Whether ``value`` is an integer, NumPy's included, and not a bool (True is an int, and was taken as 1). The one
    test of every integer argument; the type checker takes it as an int (NumPy's integers compare and index alike).
    An int subclass whose ``int()`` is not its value is not: the value checked must be the value used (T28-B01). A test
    only: where the value is used, use the Python int :func:`whole_in` returns (or ``operator.index``), not the value
    given, whose NumPy arithmetic wraps (np.int8(127) + 1 is -128: evaluate's n_steps + 1, T31-B02)."""
    if not (isinstance(value, numbers.Integral) and not isinstance(value, bool) and type(value).__name__ not in _TIMES):
        return False
    return type(value) is int or _honest_int(value)


def _honest_int(value: Any) -> bool:
    """Whether ``int(value)``, ``float(value)`` and the integer that comparisons see (``operator.index``) agree: an int
    subclass with ``__int__`` returning 10**9 passed n_steps=I(20) and flew 10**9 steps (T28-B01)."""
    try:
        exact = operator.index(value)
        if int(value) != exact:
            return False
    except (TypeError, ValueError, OverflowError):
        return False
    return _same_float(value, exact)


def _same_float(value: Any, exact: float | int) -> bool:
    """Whether ``float(value)`` is ``float(exact)`` (NaN is NaN; both past a float's range count as alike)."""
    try:
        given = float(value)
    except OverflowError:
        given = None
    except (TypeError, ValueError):
        return False
    try:
        true = float(exact)
    except OverflowError:
        true = None
    return given == true or (given is not None and true is not None and math.isnan(given) and math.isnan(true))


#: NumPy's time types: np.timedelta64 is a np.signedinteger (so Integral) whose int() raises (seventeenth trial, T17-1).
_TIMES = ("timedelta64", "datetime64")


def whole_in(value: object, name: str, low: int, high: int, high_text: str | None = None) -> int:
    """``value`` (the argument ``name``) as an int, or one NeurohoverError: a non-integer (20.0, '20', True, a NumPy time
    span) "is not allowed", an integer outside ``low..high`` "is out of range", each with the allowed integers
    (``high_text`` writes ``high``, e.g. '2**63-1'). 20.0 was called out of range (T22-14)."""
    allowed = f"allowed an integer in {low}..{high_text or high}"
    if not whole_number(value):
        raise NeurohoverError(f"{name}={brief(value)} is not allowed: {allowed}")
    exact = operator.index(value)  # the integer checked is the integer returned (T28-B01)
    if not low <= exact <= high:
        raise NeurohoverError(f"{name}={brief(value)} is out of range: {allowed}")
    return exact


def check_length(length: object, what: str, least: int = 1) -> None:
    """Refuse a ``length`` (how many numbers ``what`` holds) that is no whole number >= ``least``: the one check of
    :func:`neurohover.tasks.finite_vector`'s (0: an MDP without wind holds none) and :func:`neurohover.models.check_vector`'s
    (an array was NumPy's "truth value is ambiguous" in finite_vector, T45-B05; '2' was "x must be 2 numbers, got 2" in
    check_vector, T14-13)."""
    if not whole_number(length) or length < least:
        raise NeurohoverError(f"length={brief(length)} is not allowed: give a whole number >= {least} (how many numbers {what} holds)")


def real_number(value: object) -> TypeGuard[float]:
    """Whether ``value`` is a real number, NumPy's included: not a bool (True is an int) nor a NumPy time (an Integral
    whose float() and int() raise, T17-1). The one test of a number argument; :func:`finite_real` adds finiteness.
    A float or int subclass whose ``float()`` (or ``int()``) is not its value is not: MDP(d_u=F(0.0)) with a NaN
    ``__float__`` stored NaN (T28-B01)."""
    if not (isinstance(value, numbers.Real) and not isinstance(value, bool) and type(value).__name__ not in _TIMES):
        return False
    if type(value) in (float, int) or not isinstance(value, (float, int)):
        return True
    return _same_float(value, float.__float__(value)) if isinstance(value, float) else _honest_int(value)


def finite_real(value: object) -> bool:
    """Whether ``value`` is a real number (not a bool) that a float holds finitely: an int past a float's range (10**400)
    is not (``math.isfinite`` raised OverflowError on it; eighth trial)."""
    if not real_number(value):
        return False
    try:
        return math.isfinite(float(value))  # the value converted, as callers store it (T28-B01)
    except (OverflowError, TypeError, ValueError):
        return False


def lowest_allowed(bound: float) -> str:
    """A range's lower ``bound`` in three significant digits, rounded up so that the number shown is allowed: the
    smallest sensor std, level and drift walk (2**-52 and multiples) were shown rounded down, as 2.22e-16, a number
    the same range refuses."""
    text = f"{bound:.3g}"
    if float(text) >= bound:
        return text
    mantissa, _, exponent = f"{bound:.2e}".partition("e")
    return f"{float(mantissa) + 0.01:.3g}e{int(exponent):+03d}"


def brief(value: object) -> str:
    """``repr(value)`` for a message: an int of more than 30 digits as its first ten and its length, a text of more than
    60 characters as paths are shown (its first 40 and last 20 and its length), any other repr cut at 60 characters (a
    settings class echoed 10**400 whole, a 100,000-character task or agent name a 100 kB line; eleventh trial)."""
    if isinstance(value, str) and len(value) > 60:
        return f"{value[:40]!r} ... {value[-20:]!r} ({len(value):,} characters)"
    if whole_number(value):
        try:
            digits = str(abs(int(value)))
        except ValueError:  # past Python's int_max_str_digits (4300): no str() at all
            return f"an integer of about {int(int(value).bit_length() * math.log10(2)) + 1} digits"
        if len(digits) > 30:
            return f"{'-' if value < 0 else ''}{digits[:10]}...({len(digits)} digits)"
    if isinstance(value, (datetime.date, datetime.time)):  # a TOML date or time: as TOML writes it, not datetime.date(...)
        kind = "date and time" if isinstance(value, datetime.datetime) else "date" if isinstance(value, datetime.date) else "time"
        return f"{value.isoformat()} (a {kind})"
    try:
        text = repr(value)
        text = " ".join(text.split()) if "\n" in text else text  # an array's repr spans lines: one line in a message
    except Exception:  # a container of such an int; any repr that raises: a message must not (T17-1)
        text = f"a {type(value).__name__}"
    if isinstance(value, (int, float)) and type(value).__module__ not in ("builtins", "numpy") and not real_number(value):
        text = f"{type(value).__name__}({text})"  # a number whose int()/float() lie: F(0.0), not 0.0 (T28-B01)
    return text if len(text) <= 60 else text[:57] + "..."


class FloatRangeError(ValueError):
    """A number written past a float's range (:func:`float_of`), or a whole number of more digits than Python reads
    (:func:`int_of`)."""


def int_of(text: str) -> int:
    """``int(text)``, but a whole number of more digits than Python reads (``sys.get_int_max_str_digits()``, 4,300) is
    a :class:`FloatRangeError` saying it is out of range, not int()'s "Exceeds the limit" ValueError, which callers
    reported as text that is no number (``plot --episodes``, ``wins --runs``, a drift's ``@LO-HI``; T53-A01..A03)."""
    try:
        return int(text)
    except ValueError:
        digits = str(text).strip().lstrip("+-")
        limit = sys.get_int_max_str_digits()
        if digits.isascii() and digits.isdigit() and limit and len(digits) > limit:
            raise FloatRangeError(f"{digits[:10]}...({len(digits):,} digits) is out of range: past every range neurohover allows") from None
        raise


def float_of(text: str) -> float:
    """``float(text)``, but a number past a float's range is a :class:`FloatRangeError` naming it, not inf: '1' and 400
    zeros was read as inf and reported as a value the user never typed (eighth trial). 'inf' written as such stays inf;
    text that is no number is float()'s own ValueError, as is one with '_' between its digits, which float() reads
    ('1_0' as 10: a sensor flew at level 10 for "level=1_0"; fifteenth trial, T15-13)."""
    if isinstance(text, str) and "_" in text:
        raise ValueError(f"could not convert string to float: {text!r} (no '_' between digits)")
    value = float(text)
    if math.isinf(value) and "inf" not in str(text).lower():
        shown = str(text).strip()
        shown = shown if len(shown) <= 30 else f"{shown[:10]}...({len(shown)} characters)"
        raise FloatRangeError(f"{shown} is past a float's range (about 1.8e308)")
    return value


def setting_float(value: Any) -> float:
    """A real setting ``value`` (checked by :func:`finite_real`) as the float it is read as: a NumPy float narrower than
    float64 (np.float32, np.float16) as the decimal it prints as, and -0.0 as 0.0. np.float32(0.3) was kept as
    0.30000001192092896, so FGHH flew its seeded sets (T56-B03); a -0.0 sensor or drift was hashed as another competition (T56-B04)."""
    numpy = sys.modules.get("numpy")  # not imported: the value is no NumPy float
    if numpy is not None and isinstance(value, numpy.floating) and value.itemsize < 8:
        return float(str(value)) + 0.0  # str: NumPy's shortest repr, '0.3'; exact values (0.25) read the same
    return float(value) + 0.0


def comma_separated(part: str) -> str | None:
    """``part``, one KEY=VALUE setting of a comma-separated list, written with commas where it holds more settings
    separated by spaces or ';' ('level=0.5;delay=1' -> 'level=0.5,delay=1'), else None: a sensor's and a drift's text
    said only that its first value needs a number (T49-A03)."""
    pieces = [p for p in re.split(r"[\s;]+", re.sub(r"\s*=\s*", "=", str(part).strip())) if p]
    return ",".join(pieces) if len(pieces) > 1 and all("=" in p for p in pieces) else None


def frozen_dataclass_class(cls: object) -> bool:
    """Whether ``cls`` is a class that is a frozen dataclass (itself or by inheritance): what a registry's settings are
    (an agent spec's, an optimiser spec's), not an object of one."""
    return isinstance(cls, type) and dataclasses.is_dataclass(cls) and bool(cls.__dataclass_params__.frozen)  # type: ignore[attr-defined]


def check_name_text(what: str, value: object, naming: str, *, empty: bool = False) -> str:
    """``value`` (the argument ``what``) checked to be a name in the run's records: text of printable characters, one line,
    non-empty unless ``empty`` (a Choice's label, an agent's name: None, 5 and 'x\\ny' were taken, T39-B04; an MDP's
    label, which may be '': 'wind\\nrun 2' was taken, T40-B13)."""
    if not isinstance(value, str) or not value.isprintable() or not (value.strip() or (empty and not value)):
        kind = "a text" if empty else "a non-empty text"
        raise NeurohoverError(f"{what}={brief(value)} is not allowed: give {kind} (one line, printable) naming {naming}")
    return value


def check_flag(value: Any, name: str, meaning: str) -> bool:
    """The Python bool of a flag, or one error refusing one that is not a bool: any truthy value counted as True
    (``fresh='no'`` deleted every stored unit, T14-4; ``quick='no'``, ``fit_drags='no'``, fifteenth trial). The one
    check of a True/False argument. A NumPy bool (``(a > 0).any()``, a flag read from an .npz) is one, as evaluate's
    ``record`` and a Choice take it (it was refused, T36-B07)."""
    if isinstance(value, bool):
        return value
    numpy = sys.modules.get("numpy")  # not imported: the value is no NumPy bool
    if numpy is not None and isinstance(value, numpy.bool_):
        return bool(value)
    raise NeurohoverError(f"{name}={brief(value)} is not allowed: give True ({meaning}) or False")


def raise_terminated(signum, frame) -> None:
    """A handler of the :func:`stop_signals`: the signal as :class:`Terminated` in the main thread."""
    raise Terminated(f"signal {signum}", signum=int(signum))


def redeliver_ignored_stop(unraisable: Any) -> None:
    """A ``sys.unraisablehook``: a stop (:class:`Terminated`, or Ctrl-C's KeyboardInterrupt) raised inside a callback
    whose exceptions Python ignores (importlib's module-lock weakref callback while the package imported, a ``__del__``)
    was printed as "Exception ignored" and lost, the command running on to status 0; its signal is sent again, to be
    handled where the command can stop. Anything else goes to Python's own hook."""
    stop = unraisable.exc_value
    if isinstance(stop, KeyboardInterrupt):
        import os
        import threading

        # A moment later, from another thread: sent now (raise_signal handles it at once), it would be ignored again here.
        signum = stop.signum if isinstance(stop, Terminated) else signal.SIGINT
        later = threading.Timer(0.05, os.kill, (os.getpid(), signum))
        later.daemon = True
        later.start()
        return
    sys.__unraisablehook__(unraisable)


def refused_signature(fn: Any, n: int) -> str | None:
    """The signature of ``fn``, as text, where it cannot be called with ``n`` positional arguments; '' where it can; None
    where it has none to read (a builtin's: its call says). The one arity check of a user's callable (an act given to
    evaluate_callable, an agent's choose; T37-B11, T39-B01)."""
    import inspect

    try:
        signature = inspect.signature(fn)
    except (TypeError, ValueError):
        return None
    try:
        signature.bind(*(None,) * n)
    except TypeError:
        return str(signature)
    return ""


def check_arity(name: str, fn: Any, n: int, called: str, give: str) -> None:
    """Refuse a user's callback ``name`` that cannot be called with the ``n`` positional arguments it is called with
    (``called``: how it is called; ``give``: what to give instead); None, and one with no signature to read (a builtin's),
    pass. One of the wrong arity was a bare TypeError at its first call, often after work was done (T40-B02, T41-B01)."""
    refused = None if fn is None else refused_signature(fn, n)
    if refused:
        raise NeurohoverError(f"{name} of signature {brief(refused)} is not allowed: {called}; give {give}")


def registry_entry_problem(registry: str, name: object, value: object, kind: type, shipped: Any, what: str, noun: str) -> str:
    """What is wrong with the entry ``registry[name] = value`` of an extension point's registry ('' when nothing), the
    checks the agents', optimisers' and task families' registries share (T41-B02..B04, T43-B10, T44-B14/B15): ``value``
    is no ``kind`` (a subclass of it where ``kind``'s instances are classes, as task families are), a shipped name
    holds another value, or a key other than the value's own name. ``shipped``: the shipped entries by name; ``what``:
    the kind of entry in words ("agent"); ``noun``: what the value is called ("spec", "class")."""
    var = "cls" if noun == "class" else noun
    entry = f"{registry}[{brief(name)}] = {brief(value)} is not allowed"
    is_kind = isinstance(value, type) and issubclass(value, kind) if noun == "class" else isinstance(value, kind)
    if not is_kind:
        article = "an" if kind.__name__[:1] in "AEIOU" else "a"
        return f"{entry}: register {article} {kind.__name__}{' subclass' if noun == 'class' else ''} under its name ({registry}[{var}.name] = {var})"
    if isinstance(name, str) and name in shipped:
        if value == shipped[name]:
            return ""
        return f"{entry}: {name!r} is a shipped {what}'s name and holds its shipped {noun}; register yours under a name of its own"
    own = getattr(value, "name", None)
    if not isinstance(name, str) or own != name:  # an array key: NumPy's ambiguous truth (T47-B06)
        return f"{entry}: its {noun}'s name {brief(own)} is not its key; register a {noun} under its own name ({registry}[{var}.name] = {var})"
    return ""


def package_path(package: object, example: str, contents: str) -> list[str]:
    """The ``__path__`` of the package called ``package`` (an extension point's ``discover``); NeurohoverError naming a
    value that is no dotted name, a package that is not importable or a module that is not a package (they leaked
    ValueError, ModuleNotFoundError, TypeError or AttributeError; T44-B06, T52-B16). ``example``: a package's name to
    give; ``contents``: what its modules are ("agent modules")."""
    import importlib

    allowed = f"give an importable package's dotted name, e.g. {example!r}"
    if not isinstance(package, str) or not all(part.isidentifier() for part in package.split(".")):
        raise NeurohoverError(f"package={brief(package)} is not allowed: {allowed}")
    try:
        module = importlib.import_module(package)
    except ModuleNotFoundError as err:  # the package itself (or a package above it), not a module its code imports
        if err.name is None or not (package == err.name or package.startswith(f"{err.name}.")):
            raise
        raise NeurohoverError(f"package={package!r} is not allowed: no module named {err.name!r} is importable; {allowed}") from None
    path = getattr(module, "__path__", None)
    if path is None:
        raise NeurohoverError(f"package={package!r} is not allowed: it is a module, not a package of {contents}; {allowed}")
    return list(path)


def reloaded_text(cls: type) -> str:
    """Why a ``cls`` of another import of its module is refused, as a message's reason: after ``importlib.reload`` of a
    neurohover module its classes are new class objects, while neurohover's other modules hold the first ones, so an
    object of either is no instance of the other's (a Policy, T36-B10; a Sensor, Drift, FlightData or MDP, T42-B07..B09)."""
    name, module = cls.__qualname__, cls.__module__
    article = "an" if name[:1] in "AEIOU" or (name.isupper() and name[:1] in "FHLMNRSX") else "a"
    return (
        f"it is {article} {name} of another import of {module} (the module was reloaded?), while neurohover's other modules "
        f"hold the first import's {name}; restart the interpreter instead of reloading a neurohover module"
    )


def other_import(value: object, cls: type) -> str:
    """:func:`reloaded_text` where ``value``'s class, or one it derives from, has ``cls``'s module and qualified name yet is
    another class object (of another import of that module); '' where none is. An isinstance check that failed names
    this cause first: "sensor must be a neurohover Sensor, got Sensor(...)" named none (T42-B07..B09)."""
    same = (c for c in type(value).__mro__ if c.__module__ == cls.__module__ and c.__qualname__ == cls.__qualname__)
    return reloaded_text(cls) if any(c is not cls for c in same) else ""


def refuse_reloaded(value: object, cls: type, what: str) -> None:
    """Refuse ``value`` (called ``what``) where :func:`other_import` names a reload as why it is no ``cls``: call it where an
    isinstance check of ``cls`` failed, before that check's own message."""
    reason = other_import(value, cls)
    if reason:
        raise NeurohoverError(f"{what} {brief(value)} is not allowed: {reason}")


def key_text(key: Any) -> str:
    """A table's key as a message names it: text as written (one of more than 60 characters shortened by :func:`brief`),
    any other key (b'pop_size', 1) as its repr."""
    return key if isinstance(key, str) and len(key) <= 60 else brief(key)


def unknown_keys(keys: Any, known: Any) -> str:
    """The ``keys`` not among ``known``, named for a message, '' only if there are none: each key as its repr (a
    100,000-character one shortened, :func:`brief`), so the key '' is named ``''`` and a trailing space shows; sorted by
    ``str``, so keys of mixed types sort, and ``", ".join`` of non-text keys raised TypeError (evolve settings={1: 10},
    T33-B02). Named as written, the key '' read '', which every caller took as "none unknown" (T58-B01..B03)."""
    known = set(known)
    unknown = sorted((key for key in set(keys) if key not in known), key=str)
    return ", ".join(brief(key) or f"a {type(key).__name__} whose repr is ''" for key in unknown)  # never '' for a key


def first_difference(path: str, saved: Any, given: Any, saved_as: str = "the stored") -> str:
    """Where a stored setting ``saved`` and the ``given`` one first differ (tables compared key by key), with both
    values cut at 60 characters: for messages that refuse a resume or a store of other settings (tenth trial)."""
    if isinstance(saved, dict) and isinstance(given, dict):
        for key in sorted(set(saved) | set(given), key=str):
            if saved.get(key) != given.get(key):
                return first_difference(f"{path}.{key}", saved.get(key), given.get(key), saved_as)
    if isinstance(saved, list) and isinstance(given, list) and len(saved) == len(given) and brief(saved).endswith("..."):
        # two long lists (genomes) cut at the same place read alike: their first differing entry (T27-A01)
        i = next((i for i, (a, b) in enumerate(zip(saved, given, strict=True)) if a != b), None)
        if i is not None:
            return first_difference(f"{path}[{i}]", saved[i], given[i], saved_as)
    return f"{path}: {saved_as} {brief(saved)}, given {brief(given)}"


#: What values of each refused NumPy dtype kind are, for the message (real numbers are kinds "f", "i" and "u").
_NOT_REAL = {"b": "booleans", "c": "complex numbers", "M": "dates", "m": "time spans", "U": "text", "S": "bytes", "O": "Python objects", "V": "raw records"}


def _not_floats(values: Any, name: str, allowed: str, what: str) -> NeurohoverError:
    """:func:`as_floats`' error: ``values`` shown on one line (an array's repr breaks its rows over lines)."""
    shown = " ".join(brief(values).split())
    return NeurohoverError(f"{name}={shown} is not allowed: give {allowed}" + (f" (real numbers, not {what})" if what else ""))


def masked_note(values: Any) -> str:
    """The note a refusal of ``values`` ends with when they are a masked array (whose hidden values would be used), else ''."""
    import numpy as np

    return " (a masked array: give its values, e.g. .filled())" if isinstance(values, np.ma.MaskedArray) else ""


def as_floats(values: Any, name: str, allowed: str) -> np.ndarray:
    """A float64 copy of ``values`` if they are real numbers (a NumPy dtype of kind float, int or unsigned int), or
    NeurohoverError naming ``name``, what they are and what is ``allowed``: the one check of every array of real
    numbers given (returns, genomes, samples, MDP parameters, actions). Text, booleans, dates, Python objects (None,
    Decimal), complex numbers and masked arrays are refused (SteadyStateNE("abc") was NumPy's "could not convert",
    eleventh trial; a date was taken as its day number, None as
    NaN, '-1' as -1, a complex number's imaginary part dropped and a mask ignored, fourteenth trial)."""
    import numpy as np

    if isinstance(values, np.ma.MaskedArray):  # np.asarray drops the mask: the masked entries would count
        raise _not_floats(values, name, allowed, "a masked array")
    try:
        a = np.asarray(values)
    except (TypeError, ValueError, OverflowError):  # a ragged list
        raise _not_floats(values, name, allowed, "") from None
    if a.dtype.kind not in "fiu":  # one dtype test: this runs at every tell()
        raise _not_floats(values, name, allowed, _NOT_REAL.get(a.dtype.kind, a.dtype.name))
    return float64_of(a)


def float64_of(a: np.ndarray, copy: bool = True) -> np.ndarray:
    """``a`` (real numbers) as float64 (a copy unless ``copy`` is False and it is float64 already): a value past
    float64's range (an np.longdouble 1e400) is +-inf, as float() makes it, without NumPy's "overflow encountered in
    cast" warning (a traceback under PYTHONWARNINGS=error; T37-B10), for the caller's own test of non-finite values.
    The one conversion of given real arrays to float64."""
    import numpy as np

    if a.dtype.kind == "f" and a.dtype.itemsize > 8:  # only a longdouble can overflow the cast
        with np.errstate(over="ignore"):
            return a.astype(np.float64)
    return a.astype(np.float64, copy=copy)


def refuse_non_text_keys(data: object, where: str, what: str = "metadata") -> None:
    """Refuse ``data`` (``what`` about to be written as JSON: metadata, a unit's result) holding a key that is not text at
    any depth, naming it and the top-level key it is under: JSON writes every key as text, and {1: 2} came back as {'1': 2}
    (flight data T21-08, policy files T28-B14, store results T32-B11). A NumPy object array's dicts are looked into (flight
    data may hold them). It names the key; :func:`neurohover.jsontext.json_text` then tests the values."""
    stack: list[tuple[object, object]] = [(None, data)]  # (the top-level key it is under, a value)
    seen: set[int] = set()  # a dict that holds itself: json_text names it
    while stack:
        top, value = stack.pop()
        if getattr(getattr(value, "dtype", None), "kind", "") == "O":  # an object array: its dicts' keys too
            value = value.tolist()  # type: ignore[attr-defined]
        if isinstance(value, (dict, list, tuple)) and id(value) not in seen:
            seen.add(id(value))
            items = value.items() if isinstance(value, dict) else ((None, item) for item in value)
            for key, item in items:
                if isinstance(value, dict) and not isinstance(key, str):
                    under = "" if top is None else f" (under {brief(top)})"
                    raise NeurohoverError(
                        f"{where} {what} key {brief(key)}{under} is not allowed: give text keys (JSON writes every key as text, "
                        "so the file would load back with other keys)"
                    )
                stack.append((key if top is None else top, item))
