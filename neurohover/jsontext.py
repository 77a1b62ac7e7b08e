"""Strict JSON and number text: the one reading every neurohover file, stored row and CSV cell shares.

Internal: neurohover's plumbing (README, Python API, What is public). :func:`strict_json` refuses what Python's own
reader keeps without a word (a key twice, nesting too deep to follow, integers past a float's range);
:func:`number_text` reads a number only as Python writes one; :func:`plain_json` writes the NumPy numbers of metadata.
"""

from __future__ import annotations

import json
import re
import unicodedata
from typing import TypeVar

from .errors import NeurohoverError, brief, float_of

__all__ = [
    "MAX_NOTE_DEPTH",
    "JSONError",
    "json_text",
    "nesting_depth",
    "number_text",
    "odd_character",
    "parse_json",
    "plain_json",
    "strict_json",
    "toml_odd_character",
    "toml_twice",
    "unwritable_key",
]


def _unique_keys(pairs: list) -> dict:
    value = dict(pairs)
    if len(value) < len(pairs):  # counted once per object, not once per key: a store's large rows stay quick (ninth trial)
        keys = [k for k, _ in pairs]
        twice = sorted({k for k in keys if keys.count(k) > 1})
        raise ValueError(f"key {twice[0]!r} is given more than once")
    return value


class JSONError(ValueError):
    """JSON text :func:`strict_json` refuses; the message says why in words (``deep``: it is nested too deeply)."""

    def __init__(self, why: str, deep: bool = False) -> None:
        super().__init__(why)
        self.deep = deep


def strict_json(text: str | bytes):
    """The value of the JSON ``text``, strictly, or one :class:`JSONError` saying why not: text that is no JSON, a key
    given twice (Python keeps the last without a word), nesting deeper than Python can follow and integers past a
    float's range (4,301 digits and more were int()'s own ValueError). The one decision every reader of a JSON file or
    stored row shares, each wrapping the reason in its own message (ninth trial)."""
    try:
        return json.loads(text, object_pairs_hook=_unique_keys, parse_int=_json_int)
    except RecursionError:
        raise JSONError("its JSON is nested too deeply", deep=True) from None
    except (ValueError, TypeError) as err:  # json.JSONDecodeError, UnicodeDecodeError (bytes), TypeError (no text at all)
        named = "" if "BOM" in str(err) else odd_character(getattr(err, "doc", None), getattr(err, "pos", None), "JSON")
        raise JSONError(f"{err}{named}") from None


_QUOTES = {"'": "\u2018\u2019\u201a\u201b\u2032\u00b4", '"': "\u201c\u201d\u201e\u201f\u2033\u00ab\u00bb"}


def _ascii_form(char: str) -> str | None:
    """The ASCII that ``char`` looks like or stands for where text was pasted from a slide or a word processor: a curly
    quote's straight one, a space (a no-break space, U+3000...), '' (a zero-width character), a full-width character's or
    a dash's ASCII; None for ASCII and other characters."""
    quote = next((q for q, alike in _QUOTES.items() if char in alike), None)
    category = unicodedata.category(char)
    if char.isascii() or quote:
        return quote
    if category == "Zs":
        return " "
    if category == "Cf":
        return ""
    if category == "Pd" or char == "\u2212":
        return "-"
    form = unicodedata.normalize("NFKC", char)
    return form if form.isascii() and len(form) == 1 else None


def odd_character(text: object, pos: object, language: str) -> str:
    """``": 'X' (U+.... NAME) is not allowed there: ..."`` naming the character other than ASCII at ``pos`` of ``text``,
    where the reader of ``language`` ('JSON', 'TOML') stopped, or else a look-alike of ASCII before it on its line (a
    curly quote closing a key), with what is allowed; '' where there is none. The readers gave only a position, and
    a curly quote or a no-break space pasted from a slide is not seen there (T49-A04, T49-A05)."""
    if not isinstance(text, str) or not isinstance(pos, int) or not 0 <= pos <= len(text):
        return ""
    line = text.rfind("\n", 0, pos) + 1
    at = pos if pos < len(text) and not text[pos].isascii() else None
    at = at if at is not None else next((i for i in range(pos - 1, line - 1, -1) if _ascii_form(text[i]) is not None), None)
    if at is None:
        return ""
    char, form = text[at], _ascii_form(text[at])
    shown = f"{char!r} (U+{ord(char):04X} {unicodedata.name(char, 'a character with no name')})"
    if form in _QUOTES:
        quotes = '(")' if language == "JSON" else f"({form})"
        noun, rule = "an ASCII quote", f"{language} strings take ASCII {'double ' if language == 'JSON' else ''}quotes {quotes}"
    elif form == " ":
        noun, rule = "an ASCII space", f"outside strings {language} takes ASCII spaces (' ')"
    else:
        noun = "ASCII"
        rule = f"outside strings {language} takes ASCII characters only" + (f": write {form!r}" if form else ": delete it" if form == "" else "")
    if at == pos:
        return f": {shown} is not allowed there: {rule}"
    return f": near it, at column {at - line + 1}, {shown} is not {noun}: {rule}"


def toml_odd_character(text: str, err: ValueError) -> str:
    """:func:`odd_character` at the position tomllib's error ``err`` names ("(at line L, column C)") in ``text``."""
    where = re.search(r"\(at (?:line (\d+), column (\d+)|end of document)\)$", str(err))
    if where is None:
        return ""
    lines = text.split("\n")
    row = int(where[1] or len(lines)) - 1
    pos = sum(len(line) + 1 for line in lines[:row]) + (int(where[2]) - 1 if where[2] else len(lines[row]) if row < len(lines) else 0)
    return odd_character(text, pos, "TOML")


def _toml_key(line: str) -> str:
    """The key of TOML line ``line`` (``key = value``, quotes and spaces around dots dropped), or '' where it is none."""
    if line.lstrip().startswith("[") or "=" not in line:
        return ""
    return ".".join(part.strip().strip("\"'") for part in line.split("=", 1)[0].split("."))


def toml_twice(text: str, err: ValueError) -> str:
    """tomllib's "Cannot overwrite a value (at line L, ...)" in ``text`` said as the key given twice and where, or ''
    for any other error: it named neither the key nor the rule (T56-A04)."""
    where = re.fullmatch(r"Cannot overwrite a value \(at (?:line (\d+), column \d+|end of document)\)", str(err))
    lines = text.split("\n")
    row = int(where[1] or len(lines)) - 1 if where else -1
    key = _toml_key(lines[row]) if 0 <= row < len(lines) else ""
    if not key:
        return ""
    top = max((i for i in range(row) if lines[i].lstrip().startswith("[")), default=-1)  # the table the line is in
    table = f" in {lines[top].strip()}" if top >= 0 else ""
    before = [i + 1 for i in range(top + 1, row) if _toml_key(lines[i]) == key]
    said = f"lines {before[-1]} and {row + 1}" if before else f"line {row + 1}; a line above gives it, or a table it names, a value"
    return f"key {key!r} is given twice{table} ({said}): give each key once"


def json_text(value, **dumps) -> str:
    """``value`` written as strict JSON (``json.dumps(value, allow_nan=False, **dumps)``) that :func:`strict_json` reads
    back, or the TypeError / ValueError / RecursionError saying why not (an object, a NaN, a key twice as 1 and '1', an
    integer past a float's range, nesting too deep): the one test of a value about to be stored, each caller naming it."""
    text = json.dumps(value, allow_nan=False, **dumps)
    strict_json(text)
    return text


#: How deep a free-form value read from a file (a policy's or flight data's metadata note) may nest lists and tables:
#: Python's JSON reader follows about 990 levels, and what it read 600 deep could not be deep-copied or pickled, a
#: RecursionError (T33-B03).
MAX_NOTE_DEPTH = 100


def nesting_depth(value) -> int:
    """How many lists (or tuples) and dicts ``value`` nests, at its deepest (0 for a number or text), counted without
    recursion, and no further than one past :data:`MAX_NOTE_DEPTH`."""
    depth, level = 0, [value]
    while depth <= MAX_NOTE_DEPTH:
        inner = [v for v in level if isinstance(v, (list, tuple, dict))]
        if not inner:
            break
        depth += 1
        level = [item for v in inner for item in (v.values() if isinstance(v, dict) else v)]
    return depth


def parse_json(text: str, name: str):
    """The JSON ``text`` of the file ``name``, strictly (:func:`strict_json`): a key given twice, nesting deeper than
    Python can follow and numbers past a float's range are refused by name (third trial)."""
    try:
        return strict_json(text)
    except JSONError as err:
        raise NeurohoverError(f"{name} is not allowed: {err}" if err.deep else f"{name} is not valid JSON: {err}") from None


def _json_int(text: str) -> int:
    if len(text) > 400:  # past a float's range, and past int()'s 4,300 digits a ValueError of its own (ninth trial)
        raise ValueError(f"the number {text[:20]}... ({len(text)} digits) is out of range")
    value = int(text)
    try:
        float(value)  # past a float's range no genome or parameter can hold it (an OverflowError later)
    except OverflowError:
        raise ValueError(f"the number {text[:20]}... ({len(text)} digits) is out of range") from None
    return value


_WHOLE_TEXT = re.compile(r"0|-?[1-9][0-9]{0,18}")  # as str(int) writes one, up to 19 digits (2**63 - 1 has 19)
_REAL_TEXT = re.compile(r"-?(?:[0-9]+(?:\.[0-9]+)?(?:e[-+]?[0-9]+)?|inf)|nan")  # as repr(float) writes one


def number_text(text: str, whole: bool = False) -> int | float:
    """The number a CSV cell ``text`` holds as Python writes one (``str(int)``, ``repr(float)``: ``20``, ``-7.38``,
    ``1e-05``, ``-inf``, ``nan``; ``whole``: an integer, no sign before 0), else a ValueError saying what is allowed:
    ``int()`` and ``float()`` also read '1_0', other scripts' digits ('\u0661'), spaces and '+5' (T28-B12, T28-B13).
    The range of the number is the caller's to check."""
    if isinstance(text, str) and (_WHOLE_TEXT if whole else _REAL_TEXT).fullmatch(text):
        return int(text) if whole else float_of(text)
    allowed = "a whole number (at most 19 digits)" if whole else "a number"
    raise ValueError(f"{brief(text)} is not allowed: allowed {allowed} in ASCII digits, as Python writes it")


_K = TypeVar("_K")


def plain_json(value: object) -> object:
    """A NumPy number or (unmasked) array as the plain number or list JSON writes (``json.dumps``' ``default``): values
    made in Python may hold them (``np.argmax``'s np.int64, a float32 score, ``(a > 0).any()``); anything else is json's
    TypeError. The one conversion of the metadata and statistics neurohover writes as JSON: flight data's metadata, a
    policy file's metadata (:func:`~neurohover.policies.save_policy`) and a model's stats (their NumPy numbers were
    refused, T36-B08)."""
    import numpy as np  # here: the package installs its signal handlers before numpy (errors)

    if isinstance(value, (np.generic, np.ndarray)) and not isinstance(value, np.ma.MaskedArray):
        plain = value.tolist()  # a date or a complex number stays one, and is refused as such
        if not isinstance(plain, (np.generic, np.ndarray)):
            return plain
    raise TypeError(f"Object of type {type(value).__name__} is not JSON serializable")


def unwritable_key(table: dict[_K, object]) -> _K | None:
    """The first key of ``table`` whose entry alone JSON cannot write (strictly, NumPy numbers as :func:`plain_json`
    writes them), None when each can: the entry a refusal names (json's own message names no key, and no NaN)."""
    return next((k for k, v in table.items() if not _json_ok({k: v})), None)


def _json_ok(value: object) -> bool:
    """Whether the JSON of metadata (flight data's, a policy file's, a model's stats) writes ``value``."""
    try:
        json_text(value, default=plain_json)
    except (TypeError, ValueError, RecursionError):
        return False
    return True
