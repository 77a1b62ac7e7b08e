"""Settings tables read from the settings dataclasses themselves, so each setting is described in one place.

A setting's name, type and default come from its dataclass field, its help from the class's NumPy
docstring (the entry under ``Attributes`` or ``Parameters``; an entry may name several fields,
``a, b : float``). :func:`settings_rows` joins them, :func:`format_settings` prints the table that
``neurohover settings NAME`` shows (as pycma's ``cma.CMAOptions()`` lists its options), and
tests/test_settingsdoc.py holds every registered class to one entry per field and no entry
without a field, so a docstring cannot drift from its code.
"""

from __future__ import annotations

import dataclasses
import inspect
import re
from dataclasses import dataclass

from .errors import NeurohoverError, brief

__all__ = ["SettingRow", "documented", "format_settings", "plain", "settings_rows", "summary"]

_SECTIONS = ("Attributes", "Parameters")
_ENTRY = re.compile(r"^(?P<names>[A-Za-z_][A-Za-z0-9_]*(?:\s*,\s*[A-Za-z_][A-Za-z0-9_]*)*)\s*(?::\s*(?P<type>.*))?$")


@dataclass(frozen=True)
class SettingRow:
    """One setting: its name, its type as the docstring (or the annotation) gives it, its default, its help."""

    name: str
    type: str
    default: str
    help: str


def _is_header(lines: list[str], i: int) -> bool:
    return i + 1 < len(lines) and bool(lines[i].strip()) and set(lines[i + 1].strip()) == {"-"}


def _entries(doc: str) -> dict[str, tuple[str, str]]:
    """Name -> (type, help) of the entries in a NumPy docstring's Attributes and Parameters sections."""
    lines = inspect.cleandoc(doc).splitlines()
    out: dict[str, tuple[str, str]] = {}
    i = 0
    while i < len(lines):
        if not (_is_header(lines, i) and lines[i].strip() in _SECTIONS):
            i += 1
            continue
        i += 2
        while i < len(lines) and not _is_header(lines, i):
            line = lines[i]
            if not line.strip():
                i += 1
                continue
            match = _ENTRY.match(line)
            if line.startswith(" ") or match is None:
                break  # prose after the entries ends the section
            i += 1
            body = []
            while i < len(lines) and (lines[i].startswith(" ") or not lines[i].strip()) and not _is_header(lines, i):
                body.append(lines[i].strip())
                i += 1
            for name in re.split(r"\s*,\s*", match["names"]):
                out[name] = ((match["type"] or "").strip(), " ".join(b for b in body if b))
    return out


def _settings_class(cls: object) -> type:
    """``cls`` if it is a dataclass type (a settings class), else NeurohoverError naming it: None and int were
    AttributeErrors and dataclasses' TypeError, and summary(None) was '.' (thirteenth trial, F5)."""
    if not (isinstance(cls, type) and dataclasses.is_dataclass(cls)):
        raise NeurohoverError(f"cls={brief(cls)} is not allowed: give a settings class (a dataclass type), e.g. SteadyStateSettings")
    return cls


def documented(cls: type) -> dict[str, tuple[str, str]]:
    """The documented settings of ``cls`` and of its dataclass bases (the class's own entry wins)."""
    cls = _settings_class(cls)
    out: dict[str, tuple[str, str]] = {}
    for klass in reversed(cls.__mro__):
        if dataclasses.is_dataclass(klass) and klass.__doc__:
            out.update(_entries(klass.__doc__))
    return out


def settings_rows(cls: type) -> list[SettingRow]:
    """One row per field of the settings dataclass ``cls``, in field order (help empty where undocumented)."""
    cls = _settings_class(cls)
    docs = documented(cls)
    rows = []
    for f in dataclasses.fields(cls):
        if not f.init or f.name.startswith("_"):
            continue
        if f.default is not dataclasses.MISSING:
            default = repr(f.default)
        elif f.default_factory is not dataclasses.MISSING:
            default = repr(f.default_factory())
        else:
            default = "(required)"
        kind, text = docs.get(f.name, ("", ""))
        rows.append(SettingRow(f.name, kind or _annotation_text(f.type), default, text))
    return rows


def _annotation_text(annotation: object) -> str:
    """A field's annotation as its source writes it: 'float', not "<class 'float'>" where a user's class annotates with
    real types (no ``from __future__ import annotations``; T44-B18); text annotations as they are."""
    return annotation if isinstance(annotation, str) else inspect.formatannotation(annotation)


def plain(text: str) -> str:
    """Docstring markup as plain text: ``x`` -> x, :class:`~a.b.X` -> X."""
    if not isinstance(text, str):
        raise NeurohoverError(f"text={brief(text)} is not allowed: give a docstring's text")
    text = re.sub(r":[a-z]+:`~?(?:[\w.]+\.)?([^`]+)`", r"\1", text)
    return text.replace("``", "")


def summary(cls: type) -> str:
    """The first sentence of the class's docstring, as plain text."""
    cls = _settings_class(cls)
    first = inspect.cleandoc(cls.__doc__ or "").split("\n\n")[0].replace("\n", " ")
    return plain(first.split(". ")[0].rstrip(".") + ".")


def format_settings(cls: type, title: str) -> str:
    """The settings table of ``cls`` as plain text: name, default and type, then the help, wrapped."""
    import textwrap

    cls = _settings_class(cls)
    if not isinstance(title, str):
        raise NeurohoverError(f"title={brief(title)} is not allowed: give text")
    out = [f"{title}: {summary(cls)} ({cls.__module__}.{cls.__qualname__})", ""]
    rows = settings_rows(cls)
    for i, row in enumerate(rows):
        out.append(f"{row.name} = {row.default}    [{plain(row.type)}]")
        if i + 1 < len(rows) and row.help and rows[i + 1].help == row.help:
            continue  # one entry documents several settings (a, b : float): its text once, under the last of them
        out += textwrap.wrap(plain(row.help) or "(undocumented)", width=100, initial_indent="    ", subsequent_indent="    ")
    return "\n".join(out)
