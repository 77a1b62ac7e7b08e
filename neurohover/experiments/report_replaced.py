"""What a report replaces: ``neurohover report --out DIR`` over a folder that holds a report already (T40-A04).

A report of another store replaced ``report.md`` without a word, and the old report's figures stayed beside the new one,
unreferenced. The report now says, on stderr, when the report.md it replaces was of another results store or showed
figures that the new one does not, and names those figures. They are **left in place**, not removed: each is a file
neurohover wrote, but a README beside the report (``docs/reproduction/README.md``'s own links) or a report of another
selection may still show it, and removing a figure a person may still want is worse than naming it once.
"""

from __future__ import annotations

import re
import sys
from pathlib import Path
from typing import NamedTuple

from ..filekinds import REPORT_KIND, held_kind
from ..paths import printable

#: The line of report.md that names its store, and the lines that show its figures (as report.py writes them).
_STORE = re.compile(r"^Generated .*? from the results store `(.*)`\. Error is", re.MULTILINE)
_FIGURE = re.compile(r"^!\[.*\]\(([^()\s/\\]+\.png)\)\s*$", re.MULTILINE)
#: Figures named in the note, at most (the rest counted).
_NAMED = 8


class HeldReport(NamedTuple):
    """The report.md a report is about to replace: the store it names (as written there) and the figures it shows."""

    store: str | None
    figures: tuple[str, ...]


def held_report(path: Path) -> HeldReport | None:
    """The report at ``path`` (a report.md of ``neurohover report``), None for anything else (no file, another kind)."""
    if held_kind(path) != REPORT_KIND:
        return None
    try:
        text = path.read_text(encoding="utf-8", errors="replace")
    except OSError:
        return None
    store = _STORE.search(text)
    return HeldReport(store.group(1) if store else None, tuple(dict.fromkeys(_FIGURE.findall(text))))


def note_replaced(held: HeldReport | None, path: Path, store: Path) -> None:
    """Say (stderr) what the report just written to ``path`` from ``store`` replaced: a report of another store, and the
    figures of the old report that the new one does not show, left in the folder."""
    if held is None:
        return
    now = held_report(path)
    shown = set(now.figures) if now is not None else set()
    stale = [f for f in held.figures if f not in shown and (path.parent / f).is_file()]
    other = held.store is not None and held.store != printable(store)
    if not other and not stale:  # the same store's report again: nothing to say
        return
    what = f"the report of another results store ({held.store!r})" if other else "a report with other figures"
    note = f"neurohover report: note: {printable(path)!r} held {what}; it is replaced"
    if stale:
        named = ", ".join(stale[:_NAMED]) + (f" and {len(stale) - _NAMED} more" if len(stale) > _NAMED else "")
        note += f"; its figures that this report does not show are left in the folder (remove them if unwanted): {named}"
    print(note, file=sys.stderr)
