"""The one progress bar of every command: tqdm on standard error, drawn only on a terminal, and drawn on a terminal that
reports no width too (T19-11)."""

from __future__ import annotations

import os
import sys

__all__ = ["UNSIZED_COLUMNS", "progress_bar"]

#: How wide a progress bar is drawn on a terminal that reports no width.
UNSIZED_COLUMNS = 80


def progress_bar(**settings):
    """A tqdm progress bar (``settings``: tqdm's) on standard error unless ``file`` says otherwise, shown only when
    that stream is a terminal (``disable=None``, tqdm's own test, unless given). On a terminal that reports no width, a
    pseudo-terminal nobody sized (``script``, ``docker exec -t``), it is drawn :data:`UNSIZED_COLUMNS` wide: tqdm drew
    nothing there, and learn-model and evolve sat silent for minutes (T19-11)."""
    from tqdm import tqdm

    stream = settings.pop("file", sys.stderr)
    settings.setdefault("disable", None)
    if _unsized_terminal(stream):
        settings.update(ncols=UNSIZED_COLUMNS, nrows=24, dynamic_ncols=False)
    return tqdm(file=stream, **settings)


def _unsized_terminal(stream) -> bool:
    """Whether ``stream`` is a terminal whose width reads as 0 (False for anything that is no terminal)."""
    try:
        return bool(stream.isatty()) and os.get_terminal_size(stream.fileno()).columns == 0
    except (AttributeError, OSError, ValueError):  # no fileno (a StringIO), a closed stream
        return False
