"""The one check of a registry's settings (an agent spec's, a run-time optimiser's, EONN's): a frozen settings dataclass
read from a table of some of its fields (:func:`settings_from_dict`), each value against its field's plain JSON type
(:func:`setting_type_problem`) and a class's own defaults likewise (:func:`settings_defaults_problem`); an object of it
likewise (:func:`checked_settings`). Settings taken hold plain Python values (:func:`plain_settings`, T57-B02).

Internal: neurohover's plumbing (README, Python API, What is public).
"""

from __future__ import annotations

import dataclasses
import math
import operator
import sys
from typing import Any

from .errors import NeurohoverError, brief, finite_real, key_text, real_number, setting_float, unknown_keys, whole_number

__all__ = ["checked_settings", "plain_settings", "setting_type_problem", "settings_defaults_problem", "settings_from_dict"]


def settings_from_dict(cls: type, values: Any, *, unknown_what: str, bad_what: str) -> Any:
    """An instance of the settings dataclass ``cls`` from a dict of some of its fields: unknown keys, values ``cls``
    refuses (TypeError, ValueError) and values it takes that are not their field's plain type or not finite
    (:func:`setting_type_problem`) become one NeurohoverError each, naming them; the class's own NeurohoverError first,
    which names its range. The settings taken hold their plain Python values (:func:`plain_settings`)."""
    fields = [f.name for f in dataclasses.fields(cls)]
    named = unknown_keys(values, fields)
    if named:
        raise NeurohoverError(f"unknown {unknown_what} setting(s) {named}: allowed {', '.join(fields)}")
    try:
        settings = cls(**values)
    except NeurohoverError as err:  # the class's own check, which names its range
        raise NeurohoverError(f"bad {bad_what}: {err}") from None
    except (TypeError, ValueError, OverflowError) as err:  # OverflowError: an int past a float's range (eighth trial)
        raise NeurohoverError(f"bad {bad_what}: {setting_type_problem(cls, values) or err}") from None
    problem = setting_type_problem(cls, values)  # what a class without checks of its own took (T55-B01, B02)
    if problem:
        raise NeurohoverError(f"bad {bad_what}: {problem}")
    return plain_settings(settings)


def checked_settings(settings: Any, *, bad_what: str) -> Any:
    """An object ``settings`` of a settings dataclass, checked as a dict of its fields is (:func:`setting_type_problem`;
    ``S(k='x', rate=inf)`` flew unchecked, T56-B01) and with its plain Python values (:func:`plain_settings`), or one
    NeurohoverError ``bad <bad_what>: ...`` naming the value. The one check of an object an agent or an optimiser is given."""
    problem = setting_type_problem(type(settings), {f.name: getattr(settings, f.name) for f in dataclasses.fields(settings)})
    if problem:
        raise NeurohoverError(f"bad {bad_what}: {problem}")
    return plain_settings(settings)


def plain_settings(settings: Any) -> Any:
    """``settings`` (an object of a settings dataclass whose values :func:`setting_type_problem` took) with each value of
    a plain-typed field as the plain Python value it is read as (:func:`_plain`); the same object where each already is.
    np.float32(0.1), a Fraction, np.int64(3) reached the agent and its recorded settings, which JSON cannot write, and
    -0.0 hashed as another run than 0.0 (T57-B02)."""
    kinds = _field_types(type(settings))
    changes = {}
    for field in dataclasses.fields(settings):
        value = getattr(settings, field.name)
        if field.init and field.name in kinds and _takes(kinds[field.name], value):
            plain = _plain(kinds[field.name], value)
            if not _same(plain, value):
                changes[field.name] = plain
    return dataclasses.replace(settings, **changes) if changes else settings


def _plain(kinds: tuple[type, ...], value: object) -> object:
    """``value``, one of ``kinds`` (:func:`_takes`), as a plain Python value: a NumPy bool as a bool, an integer (NumPy's)
    as an int, a real number as :func:`~neurohover.errors.setting_float`'s float (np.float32(0.1) as 0.1, -0.0 as 0.0).
    A Fraction is a real number here as in every float setting (finite_real), so it is read as its float; a Decimal is no
    numbers.Real and stays refused by :func:`_takes`, as everywhere (T57-B02)."""
    if value is None or (str in kinds and isinstance(value, str)):
        return value
    if bool in kinds and _is_bool(value):
        return bool(value)
    if int in kinds and whole_number(value):
        return operator.index(value)
    return setting_float(value)


def _same(plain: object, value: object) -> bool:
    """Whether ``value`` is already ``plain``: of its very type, equal, and of its sign (-0.0 is no 0.0)."""
    if type(plain) is not type(value) or plain != value:
        return False
    return not isinstance(plain, float) or math.copysign(1.0, plain) == math.copysign(1.0, value)  # type: ignore[arg-type]


#: The plain JSON types a settings field's value is checked against, and what each allows (for messages).
_PLAIN_TYPES: dict[type, str] = {bool: "true or false", int: "an integer", float: "a finite number", str: "a text"}


def _field_types(cls: type) -> dict[str, tuple[type, ...]]:
    """The plain JSON types (:data:`_PLAIN_TYPES`, and ``type(None)`` for an Optional) each field of the settings
    dataclass ``cls`` takes, by name: from its annotation, else (an annotation that does not resolve) its default's
    type. A field of any other type is left out: the class's own ``__post_init__`` checks it."""
    import types
    import typing

    try:
        hints = typing.get_type_hints(cls)
    except Exception:  # a name the class's module cannot resolve (a class defined in a function): its defaults say
        hints = {}
    found = {}
    for field in dataclasses.fields(cls):
        hint = hints.get(field.name, type(field.default) if field.default is not dataclasses.MISSING else None)
        kinds = typing.get_args(hint) if typing.get_origin(hint) in (typing.Union, types.UnionType) else (hint,)
        if kinds and all(kind in _PLAIN_TYPES or kind is type(None) for kind in kinds) and kinds != (type(None),):
            found[field.name] = kinds
    return found


def _is_bool(value: object) -> bool:
    """Whether ``value`` is a bool, NumPy's included."""
    numpy = sys.modules.get("numpy")  # not imported: the value is no NumPy bool
    return isinstance(value, bool) or (numpy is not None and isinstance(value, numpy.bool_))


def _takes(kinds: tuple[type, ...], value: object) -> bool:
    """Whether ``value`` is one of ``kinds``: a bool is no number, an integer (NumPy's too) is a float's number."""
    return (
        (value is None and type(None) in kinds)
        or (bool in kinds and _is_bool(value))
        or (int in kinds and whole_number(value))
        or (float in kinds and real_number(value))
        or (str in kinds and isinstance(value, str))
    )


def _non_finite(value: object) -> bool:
    """Whether ``value`` is, or holds in its lists and tables, a number no JSON writes (NaN, an infinity)."""
    if isinstance(value, (list, tuple)):
        return any(map(_non_finite, value))
    if isinstance(value, dict):
        return any(map(_non_finite, value.values()))
    return real_number(value) and not finite_real(value)


def setting_type_problem(cls: type, values: Any) -> str:
    """What is wrong with the given ``values`` of the settings dataclass ``cls``'s fields ('' when nothing): a value
    that is not its field's plain JSON type (int, float, bool, text, or an Optional of one; ints are taken for floats,
    bools are no numbers) or that is, or holds, a number past the finite ones. The one check of an agent's and a
    run-time optimiser's settings, which a class without checks of its own took and handed on: ``k='x'`` for
    ``k: int = 2`` (T55-B01, B02), ``rate=nan``, refused only by the results store after the run's folder was made (T55-B03)."""
    kinds = _field_types(cls)
    for key, value in values.items():
        where = kinds.get(key)
        shown = f"{key_text(key)}={brief(value)}"
        typed = "" if where is None else " | ".join("None" if kind is type(None) else kind.__name__ for kind in where)
        field = f"its field {cls.__name__}.{key} is of type {typed}"
        if where is not None and not _takes(where, value):
            allowed = " or ".join(_PLAIN_TYPES[kind] for kind in where if kind is not type(None))
            return f"{shown} is not allowed: give {allowed}{', or None' if type(None) in where else ''} ({field})"
        if _non_finite(value):
            return f"{shown} is out of range: allowed " + (f"a finite number ({field})" if where else "finite numbers (settings are recorded as JSON)")
    return ""


def settings_defaults_problem(cls: type) -> str:
    """What is wrong with the defaults of the settings dataclass ``cls`` ('' when nothing): a field without one (settings
    left out are the defaults) or one :func:`setting_type_problem` refuses, which flew unchecked (an agent's NaN or
    ``n: int = 'x'``, T56-B01), or one that is not a plain Python value (np.float32(0.1), a Fraction, -0.0: an agent
    makes its defaults itself, unconverted, T57-B02; an int for a float field is one); a field of another type (a nested
    dataclass) is left to the class. Run-time optimisers' specs and agents' specs check it (T52-B09)."""
    fields = dataclasses.fields(cls)
    bare = next((f.name for f in fields if f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING), None)
    if bare is not None:
        return f"field {bare!r} has no default: give every field a default (settings left out are the defaults)"
    defaults = {f.name: f.default for f in fields if f.default is not dataclasses.MISSING}
    problem = setting_type_problem(cls, defaults)
    if problem:
        return f"default {problem}"
    kinds = _field_types(cls)
    for key, value in defaults.items():
        plain = _plain(kinds[key], value) if key in kinds else value
        if not (_same(plain, value) or (type(value) is int and type(plain) is float)):  # 1 for 1.0: Python's own spelling
            why = "no plain JSON value" if type(plain) is not type(value) else "which settings given are read as 0.0"
            return f"field {key!r}'s default is {type(value).__name__} {brief(value)}, {why}: give {plain!r} (the defaults are used as written)"
    return ""
