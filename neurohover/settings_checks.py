"""The one check of a registry's settings (an agent spec's, a run-time optimiser's, EONN's): a frozen settings dataclass
read from a table of some of its fields (:func:`settings_from_dict`), each value against its field's plain JSON type
(:func:`setting_type_problem`) and a class's own defaults likewise (:func:`settings_defaults_problem`); an object of it
likewise (:func:`checked_settings`). Settings taken hold plain Python values (:func:`plain_settings`, T57-B02), in a
list or tuple field too (T58-B04).

The rule (T60-B01..B03): every settings value, whatever its field's annotation (``dict``, ``Any``, ``frozenset``, none),
is a plain JSON value once made plain: None, a bool, an int, a finite float, a text, or a list or tuple of them or a
table with text keys of them, nested at most :data:`~neurohover.jsontext.MAX_NOTE_DEPTH` (100) deep and holding no
list or table that holds it (T61-B01); NumPy's scalars and arrays (1-d or more) are read as their plain values
and items, as a typed field's are (:func:`_plain_item`). Anything else (a set, a frozenset, an object, a table with
other keys, NaN anywhere) is refused by name, as a given value and as a default: settings are recorded as JSON, and
json's TypeError came once the run had begun. A field annotated as a dataclass (HybridSettings' DangerousState) also
takes an object of that class, whose own fields are held to the same rule.

Internal: neurohover's plumbing (README, Python API, What is public).
"""

from __future__ import annotations

import dataclasses
import math
import operator
import sys
from typing import Any, NamedTuple

from .errors import NeurohoverError, brief, finite_real, key_text, real_number, setting_float, unknown_keys, whole_number
from .jsontext import MAX_NOTE_DEPTH

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
    a plain-typed field as the plain Python value it is read as (:func:`_plain`), and each list or tuple field's as a
    list or tuple (the field's own) of such values (:func:`_plain_sequence`); the same object where each already is.
    np.float32(0.1), a Fraction, np.int64(3) reached the agent and its recorded settings, which JSON cannot write, and
    -0.0 hashed as another run than 0.0 (T57-B02); in a list field they were JSON's TypeError once the run began (T58-B04).
    A field of any other type holds its value's plain JSON value (:func:`_plain_item`), or a dataclass object its
    annotation names with its own values made plain (T60-B01..B03)."""
    fields = _fields_of(type(settings))
    changes = {}
    for field in dataclasses.fields(settings):
        value = getattr(settings, field.name)
        if field.init:
            plain = _plain_value(fields, field.name, value)
            if not _same(plain, value):
                changes[field.name] = plain
    return dataclasses.replace(settings, **changes) if changes else settings


def _plain_value(fields: _Fields, key: str, value: object) -> object:
    """Field ``key``'s ``value`` as :func:`plain_settings` holds it (``fields``: :func:`_fields_of` its class); ``value``
    itself where it is none that its field takes (which :func:`setting_type_problem` refuses)."""
    if key in fields.kinds:
        return _plain(fields.kinds[key], value) if _takes(fields.kinds[key], value) else value
    if key in fields.sequences:
        sequence = fields.sequences[key]
        return _plain_sequence(sequence, value) if value is not None and not _sequence_problem(sequence, value) else value
    if isinstance(value, fields.nested.get(key, ())):  # a dataclass its annotation names (HybridSettings.dangerous)
        return plain_settings(value)
    try:  # any other field: its plain JSON value (T60-B01..B03)
        return _plain_item(None, value)
    except _Refused:
        return value


def _plain(kinds: tuple[type, ...], value: object) -> object:
    """``value``, one of ``kinds`` (:func:`_takes`), as a plain Python value: a NumPy bool as a bool, an integer (NumPy's)
    as an int, a real number as :func:`~neurohover.errors.setting_float`'s float (np.float32(0.1) as 0.1, -0.0 as 0.0).
    A Fraction is a real number here as in every float setting (finite_real), so it is read as its float; a Decimal is no
    numbers.Real and stays refused by :func:`_takes`, as everywhere (T57-B02). A number past the finite ones is kept as
    given, for :func:`_non_finite` to name (float() of a Fraction of 10**400 raised OverflowError)."""
    if value is None or (str in kinds and isinstance(value, str)):
        return value
    if bool in kinds and _is_bool(value):
        return bool(value)
    if int in kinds and whole_number(value):
        return operator.index(value)
    return setting_float(value) if finite_real(value) else value


def _same(plain: object, value: object, *, signs: bool = True, int_floats: bool = False) -> bool:
    """Whether ``value`` is already ``plain``: of its very type, equal, and of its sign (-0.0 is no 0.0; ``signs`` False:
    either sign), item by item in a list, tuple or table; ``int_floats``: an int where ``plain`` is its float counts."""
    if int_floats and type(value) is int and type(plain) is float:
        return plain == value
    if type(plain) is not type(value):
        return False
    if isinstance(plain, (list, tuple)):
        items: Any = value
        return len(plain) == len(items) and all(_same(a, b, signs=signs, int_floats=int_floats) for a, b in zip(plain, items, strict=True))
    if isinstance(plain, dict):
        table: Any = value
        return plain.keys() == table.keys() and all(_same(plain[k], table[k], signs=signs, int_floats=int_floats) for k in plain)
    if dataclasses.is_dataclass(plain):  # field by field: a nested one's == compared an array's items (T60-B03)
        return all(_same(getattr(plain, f.name), getattr(value, f.name), signs=signs, int_floats=int_floats) for f in dataclasses.fields(plain))
    if plain != value:
        return False
    return not (signs and isinstance(plain, float)) or math.copysign(1.0, plain) == math.copysign(1.0, value)  # type: ignore[arg-type]


#: The plain JSON types a settings field's value is checked against, and what each allows (for messages).
_PLAIN_TYPES: dict[type, str] = {bool: "true or false", int: "an integer", float: "a finite number", str: "a text"}


def _hints(cls: type) -> dict[str, Any]:
    """Each field's annotation of the settings dataclass ``cls``, by name, else (an annotation that does not resolve)
    its default's type: a default_factory's made once, as the class itself makes it (T58-B05)."""
    import typing

    try:
        hints = typing.get_type_hints(cls)
    except Exception:  # a name the class's module cannot resolve (a class defined in a function): its defaults say
        hints = {}
    found: dict[str, Any] = {}
    for field in dataclasses.fields(cls):
        if field.name in hints:
            found[field.name] = hints[field.name]
        elif field.default is not dataclasses.MISSING:
            found[field.name] = type(field.default)
        elif field.default_factory is not dataclasses.MISSING:
            try:
                found[field.name] = type(field.default_factory())
            except Exception:  # settings_defaults_problem names it
                pass
    return found


def _union(hint: Any) -> tuple[Any, ...]:
    """The types of ``hint``: a Union's (``int | None``, Optional) members, or ``hint`` alone."""
    import types
    import typing

    return typing.get_args(hint) if typing.get_origin(hint) in (typing.Union, types.UnionType) else (hint,)


def _annotation(hint: Any) -> str:
    """A field's annotation ``hint`` as a message writes it (``int | None``, ``list[float]``, ``dict``, ``Any``)."""
    import typing

    return " | ".join("None" if kind is type(None) else str(kind) if typing.get_args(kind) else getattr(kind, "__name__", str(kind)) for kind in _union(hint))


def _field_types(hints: dict[str, Any]) -> dict[str, tuple[type, ...]]:
    """The plain JSON types (:data:`_PLAIN_TYPES`, and ``type(None)`` for an Optional) each field of a settings dataclass
    takes, by name, from its annotation (``hints``: :func:`_hints`). A list or tuple field is :func:`_sequence_fields`';
    a field of any other type is none of these: its value is held to plain JSON (:func:`setting_type_problem`)."""
    found = {}
    for name, hint in hints.items():
        kinds = _union(hint)
        if kinds and all(kind in _PLAIN_TYPES or kind is type(None) for kind in kinds) and kinds != (type(None),):
            found[name] = kinds
    return found


#: A list or tuple field's type: its container (list or tuple), its items' plain types (None: any plain JSON value,
#: lists and text-keyed tables of them included), whether None is allowed, and its annotation as a message writes it.
_Sequence = tuple[type, "tuple[type, ...] | None", bool, str]


def _sequence_fields(hints: dict[str, Any]) -> dict[str, _Sequence]:
    """The list and tuple fields of a settings dataclass (``list``, ``list[float]``, ``tuple[int, ...]``, an Optional of
    one; ``hints``: :func:`_hints`), by name, with what their items may be (:data:`_Sequence`): one of items of another
    type (a dataclass) is none, and its value held to plain JSON as any other field's. Their items went unchecked:
    NumPy ints were JSON's TypeError at the run's start (T58-B04)."""
    import typing

    found: dict[str, _Sequence] = {}
    for name, hint in hints.items():
        kinds = _union(hint)
        rest = [kind for kind in kinds if kind is not type(None)]
        container = (typing.get_origin(rest[0]) or rest[0]) if len(rest) == 1 else None
        if container not in (list, tuple):
            continue
        items = tuple(item for arg in typing.get_args(rest[0]) if arg is not Ellipsis for item in _union(arg))
        shown = _annotation(hint)
        if all(item is Any or (typing.get_origin(item) or item) in (list, tuple, dict) for item in items):
            found[name] = (container, None, len(rest) < len(kinds), shown)  # any JSON value (bare ``list``, ``list[list[float]]``)
        elif all(item in _PLAIN_TYPES or item is type(None) for item in items) and set(items) != {type(None)}:
            found[name] = (container, tuple(dict.fromkeys(items)), len(rest) < len(kinds), shown)
    return found


def _nested_fields(hints: dict[str, Any]) -> dict[str, tuple[type, ...]]:
    """The dataclass classes each field's annotation names (``dangerous: DangerousState``, or an Optional of one), by
    name, for the fields that name any (``hints``: :func:`_hints`): an object of one is a value of the field."""
    found = {}
    for name, hint in hints.items():
        classes = tuple(kind for kind in _union(hint) if isinstance(kind, type) and dataclasses.is_dataclass(kind))
        if classes:
            found[name] = classes
    return found


class _Fields(NamedTuple):
    """What the checks read of a settings dataclass's fields, by name (:func:`_fields_of`): the plain-typed fields' types,
    the list and tuple fields', the dataclass classes a field's annotation names, and each annotation as written."""

    kinds: dict[str, tuple[type, ...]]
    sequences: dict[str, _Sequence]
    nested: dict[str, tuple[type, ...]]
    shown: dict[str, str]


def _fields_of(cls: type) -> _Fields:
    """:class:`_Fields` of the settings dataclass ``cls``, its annotations read once."""
    hints = _hints(cls)
    return _Fields(_field_types(hints), _sequence_fields(hints), _nested_fields(hints), {name: _annotation(hint) for name, hint in hints.items()})


def _as_sequence(value: object) -> list | tuple | None:
    """``value`` as the list or tuple it is meant as: itself, or a NumPy array's items (an array of numbers given for a
    list is meant as its numbers, T58-B04); None for anything else (a set has no order, text and tables are no lists)."""
    numpy = sys.modules.get("numpy")  # not imported: the value is no NumPy array
    if isinstance(value, (list, tuple)):
        return value
    array: Any = value
    if numpy is not None and type(array) is numpy.ndarray and array.ndim >= 1:  # a masked array's hidden values: refused
        return list(array)
    return None


class _Refused(Exception):
    """An item of a list or tuple setting that is no value its field takes (``item``, for the message), or ``why`` a
    value is refused whole (nested too deep, or holding itself)."""

    def __init__(self, item: object, why: str = "") -> None:
        super().__init__()
        self.item = item
        self.why = why


def _plain_item(items: tuple[type, ...] | None, item: object, path: tuple[int, ...] = ()) -> object:
    """``item`` of a list or tuple setting as its plain Python value: one of ``items`` read as :func:`_plain` reads it, or
    (``items`` None) any JSON value, NumPy's made plain, lists and text-keyed tables of them item by item; else :class:`_Refused`.
    ``path``: the ids of the lists and tables that hold ``item``, outermost first."""
    if items is not None:
        if not _takes(items, item):
            raise _Refused(item)
        return _plain(items, item)
    if item is None or isinstance(item, str) or _is_bool(item) or real_number(item):
        return _plain((bool, int, float, str, type(None)), item)
    inner = _as_sequence(item)
    table = isinstance(item, dict) and all(isinstance(key, str) for key in item)
    if inner is None and not table:
        raise _Refused(item)
    # checked before going in: 500 levels, or a list holding itself, was a raw RecursionError (T61-B01)
    if id(item) in path:
        raise _Refused(item, "it holds itself (a list or table inside its own), which JSON cannot write")
    if len(path) >= MAX_NOTE_DEPTH:
        raise _Refused(item, f"it is nested more than {MAX_NOTE_DEPTH} lists or tables deep")
    inside = (*path, id(item))
    if inner is not None:
        plain = [_plain_item(None, x, inside) for x in inner]
        return tuple(plain) if isinstance(inner, tuple) else plain
    mapping: Any = item
    return {key: _plain_item(None, x, inside) for key, x in mapping.items()}


def _plain_sequence(kind: _Sequence, value: object) -> list | tuple:
    """``value`` (which :func:`_sequence_problem` took) as its field's container of plain Python values: a tuple given
    for a list field is a list, as JSON reads it back (and a list for a tuple field a tuple)."""
    container, items, _, _ = kind
    plain = [_plain_item(items, item, (id(value),)) for item in _as_sequence(value) or ()]
    return tuple(plain) if container is tuple else plain


def _sequence_problem(kind: _Sequence, value: object) -> str:
    """What is wrong with ``value`` for a list or tuple field of ``kind`` ('' when nothing): no list, tuple or NumPy array
    (a set, text, a number), or an item that is not one the field takes."""
    container, items, none, _ = kind
    other = "tuple" if container is list else "list"
    if items is None:
        allowed = "of plain JSON values (numbers, texts, true or false, None, and lists and text-keyed tables of them)"
    else:
        allowed = "whose items are each " + " or ".join(_PLAIN_TYPES[k] for k in items if k is not type(None)) + (" or None" if type(None) in items else "")
    give = f"give a {container.__name__} (or a {other}) {allowed}{', or None' if none else ''}"
    if _as_sequence(value) is None:
        return give
    try:
        _plain_sequence(kind, value)
    except _Refused as refused:
        return refused.why or f"it holds {brief(refused.item)}: {give}"
    return ""


#: What a field of any other type than a plain one, a list or a tuple takes (T60-B01..B03), for messages.
_JSON_VALUE = "a plain JSON value (a number, a text, true or false, None, or a list, tuple or text-keyed table of them)"


def _json_problem(value: object) -> str:
    """What is wrong with ``value`` for a field of any other type ('' when nothing): it is not, nor holds only, plain
    JSON values once made plain (:func:`_plain_item`: NumPy's scalars and arrays are read as theirs)."""
    try:
        _plain_item(None, value)
    except _Refused as refused:
        if refused.why:
            return refused.why
        return f"give {_JSON_VALUE}" if refused.item is value else f"it holds {brief(refused.item)}: give {_JSON_VALUE}"
    return ""


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
    bools are no numbers), for a list or tuple field no list, tuple or array of its items' types or of JSON values
    (:func:`_sequence_problem`, T58-B04), for a field of any other type no plain JSON value (:func:`_json_problem`;
    T60-B01..B03) nor an object of a dataclass its annotation names whose own values are not refused here, or that is,
    or holds, a number past the finite ones. The one check of an agent's and a
    run-time optimiser's settings, which a class without checks of its own took and handed on: ``k='x'`` for
    ``k: int = 2`` (T55-B01, B02), ``rate=nan``, refused only by the results store after the run's folder was made (T55-B03)."""
    fields = _fields_of(cls)
    for key, value in values.items():
        where, sequence = fields.kinds.get(key), fields.sequences.get(key)
        shown = f"{key_text(key)}={brief(value)}"
        typed = "" if where is None else " | ".join("None" if kind is type(None) else kind.__name__ for kind in where)
        field = f"its field {cls.__name__}.{key} is of type {typed}"
        if where is not None and not _takes(where, value):
            allowed = " or ".join(_PLAIN_TYPES[kind] for kind in where if kind is not type(None))
            return f"{shown} is not allowed: give {allowed}{', or None' if type(None) in where else ''} ({field})"
        if sequence is not None and not (value is None and sequence[2]):  # a list field's items (T58-B04)
            problem = _sequence_problem(sequence, value)
            if problem:
                return f"{shown} is not allowed: {problem} (its field {cls.__name__}.{key} is of type {sequence[3]})"
            value = _plain_sequence(sequence, value)  # an array's items, for the check of finite numbers
        elif where is None and sequence is None:
            # one rule for every other field, whatever its annotation (dict, Any, none): plain JSON (T60-B01..B03)
            if isinstance(value, fields.nested.get(key, ())):  # a dataclass its annotation names: its own values alike
                nested: Any = value
                inner = setting_type_problem(type(nested), {f.name: getattr(nested, f.name) for f in dataclasses.fields(nested)})
                if inner:
                    return f"{shown} is not allowed: its {inner}"
                continue
            problem = _json_problem(value)
            if problem:
                annotated = fields.shown.get(key, "none")
                return f"{shown} is not allowed: {problem} (its field {cls.__name__}.{key} is of type {annotated}; settings are recorded as JSON)"
            value = _plain_item(None, value)  # an array's items, for the check of finite numbers
        if _non_finite(value):
            return f"{shown} is out of range: allowed " + (f"a finite number ({field})" if where else "finite numbers (settings are recorded as JSON)")
    return ""


def settings_defaults_problem(cls: type) -> str:
    """What is wrong with the defaults of the settings dataclass ``cls`` ('' when nothing): a field without one (settings
    left out are the defaults) or one :func:`setting_type_problem` refuses, which flew unchecked (an agent's NaN or
    ``n: int = 'x'``, T56-B01), or one that is not a plain Python value (np.float32(0.1), a Fraction, -0.0: an agent
    makes its defaults itself, unconverted, T57-B02; an int for a float field is one). A field of any type is checked
    (a ``dict``, ``Any`` or ``frozenset`` one's frozenset or NumPy ints were accepted, then json's TypeError once a run
    began, T60-B02); a nested dataclass's object, where its annotation names the class, by its own fields. A
    default_factory's default is made once and checked alike: ``[nan]`` flew a whole run, then its checkpoint was JSON's
    ValueError and the run lost (T58-B05). Run-time optimisers' specs and agents' specs check it (T52-B09), the one
    check of their defaults."""
    fields = dataclasses.fields(cls)
    bare = next((f.name for f in fields if f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING), None)
    if bare is not None:
        return f"field {bare!r} has no default: give every field a default (settings left out are the defaults)"
    defaults: dict[str, Any] = {}
    made = set()
    for f in fields:
        if f.default is not dataclasses.MISSING:
            defaults[f.name] = f.default
        elif f.default_factory is not dataclasses.MISSING:
            try:
                defaults[f.name] = f.default_factory()
            except Exception as err:  # the class cannot make its defaults: named at registration, not at the run
                return f"field {f.name!r}'s default_factory raised {type(err).__name__} {brief(str(err))}: give one that makes the default"
            made.add(f.name)
    for key, value in defaults.items():
        problem = setting_type_problem(cls, {key: value})
        if problem:
            return f"default{' (made by its default_factory)' if key in made else ''} {problem}"
    read = _fields_of(cls)
    for key, value in defaults.items():
        plain = _plain_value(read, key, value)
        if not _same(plain, value, int_floats=True):  # 1 for 1.0: Python's own spelling
            why = "which settings given are read as 0.0" if _same(plain, value, signs=False, int_floats=True) else "no plain JSON value"
            return f"field {key!r}'s default is {type(value).__name__} {brief(value)}, {why}: give {plain!r} (the defaults are used as written)"
    return ""
