"""A resolved config's settings, read-only (:class:`~.config.ExperimentConfig`), and settings as plain JSON values.

:func:`read_only` gives a table's read-only copy: a :class:`ReadOnlyDict` of :class:`ReadOnlyList` s, which read, compare,
print, pickle and serialise to JSON as the dict and lists they hold, and refuse every edit with one NeurohoverError
naming the way to change a setting (``load_config(..., overrides=...)``). An edit went through unchecked: runs=-1 was
``max()``'s ValueError in plan, and runs=1 made after a first plan() was ignored while the settings read 1 (T43-B13).
``copy.deepcopy`` of one is a plain, editable dict (or list) to give :func:`~.config.make_config`.

:func:`plain` gives the values a config stores (JSON): NumPy integers and floats as Python's (a loop over
``np.arange`` gave ``seed = np.int64(3)``, refused; T43-B11), read-only tables as plain ones, the rest as given (the
schema's checks refuse what they do not allow).
"""

from __future__ import annotations

import copy
from typing import Any, NoReturn

import numpy as np

from ..errors import NeurohoverError, brief, real_number, whole_number

_HOW = (
    "a config's settings (their tables and lists too) are read-only (checked when it was made): give the change as load_config(NAME, SCALE, "
    "overrides={...}), or settings of your own (copy.deepcopy(cfg.settings), edited) to make_config"
)


def _refusing(name: str) -> Any:
    """The method ``name`` of a read-only table: one NeurohoverError naming the edit."""

    def refuse(self: Any, *args: Any, **kwargs: Any) -> NoReturn:
        if name == "__setitem__" and len(args) == 2:
            what = f"[{brief(args[0])}] = {brief(args[1])}"
        elif name == "__delitem__" and len(args) == 1:
            what = f"del [{brief(args[0])}]"
        else:
            what = f".{name}({', '.join([*map(brief, args), *(f'{k}={brief(v)}' for k, v in kwargs.items())])})"
        raise NeurohoverError(f"ExperimentConfig.settings: the edit {what} is not allowed: {_HOW}")

    return refuse


class ReadOnlyDict(dict):
    """A dict that refuses edits (:func:`read_only`): a config's settings table, or one of its tables."""

    __slots__ = ()
    __setitem__ = _refusing("__setitem__")
    __delitem__ = _refusing("__delitem__")
    __ior__ = _refusing("__ior__")
    clear = _refusing("clear")
    pop = _refusing("pop")
    popitem = _refusing("popitem")
    setdefault = _refusing("setdefault")
    update = _refusing("update")

    def __reduce__(self) -> tuple:
        return (ReadOnlyDict, (dict(self),))

    def __copy__(self) -> ReadOnlyDict:
        return self

    def __deepcopy__(self, memo: dict) -> dict:
        return {copy.deepcopy(k, memo): copy.deepcopy(v, memo) for k, v in self.items()}


class ReadOnlyList(list):
    """A list that refuses edits (:func:`read_only`): a config's list setting, or its list of tables."""

    __slots__ = ()
    __setitem__ = _refusing("__setitem__")
    __delitem__ = _refusing("__delitem__")
    __iadd__ = _refusing("__iadd__")
    __imul__ = _refusing("__imul__")
    append = _refusing("append")
    clear = _refusing("clear")
    extend = _refusing("extend")
    insert = _refusing("insert")
    pop = _refusing("pop")
    remove = _refusing("remove")
    reverse = _refusing("reverse")
    sort = _refusing("sort")

    def __reduce__(self) -> tuple:
        return (ReadOnlyList, (list(self),))

    def __copy__(self) -> ReadOnlyList:
        return self

    def __deepcopy__(self, memo: dict) -> list:
        return [copy.deepcopy(v, memo) for v in self]


def read_only(value: Any) -> Any:
    """``value`` with every dict and list in it (nested) a read-only copy; other values as they are."""
    if isinstance(value, dict):
        return value if type(value) is ReadOnlyDict else ReadOnlyDict((k, read_only(v)) for k, v in value.items())
    if isinstance(value, list):
        return value if type(value) is ReadOnlyList else ReadOnlyList(read_only(v) for v in value)
    return value


def plain(value: Any) -> Any:
    """``value`` as a config stores it: a NumPy integer (not a bool, nor a time span) as a Python int, a NumPy float as a
    Python float, dicts and lists (read-only ones too) as plain copies of such values; anything else as it is."""
    if isinstance(value, dict):
        return {k: plain(v) for k, v in value.items()}
    if isinstance(value, list):
        return [plain(v) for v in value]
    if isinstance(value, np.integer) and whole_number(value):
        return int(value)
    if isinstance(value, np.floating) and real_number(value):
        return float(value)
    return value
