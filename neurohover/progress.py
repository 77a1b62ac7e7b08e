"""The one progress bar of every command: tqdm on standard error, drawn only on a terminal, and drawn on a terminal that
reports no width too (T19-11). A bar that is not drawn is a stand-in that never imports tqdm, and a TQDM_* environment
variable tqdm cannot read is refused by name (T29-A03)."""

from __future__ import annotations

import os
import sys

from .errors import NeurohoverError

__all__ = ["UNSIZED_COLUMNS", "check_progress_variables", "progress_bar"]

#: How wide a progress bar is drawn on a terminal that reports no width.
UNSIZED_COLUMNS = 80


def progress_bar(**settings):
    """A tqdm progress bar (``settings``: tqdm's) on standard error unless ``file`` says otherwise, shown only when
    that stream is a terminal (``disable=None``, tqdm's own test, unless given). On a terminal that reports no width, a
    pseudo-terminal nobody sized (``script``, ``docker exec -t``), it is drawn :data:`UNSIZED_COLUMNS` wide: tqdm drew
    nothing there, and learn-model and evolve sat silent for minutes (T19-11). A bar not drawn (``disable=True``, or
    ``None`` off a terminal, or on a closed stream) is a :class:`_Quiet` stand-in: tqdm is not imported, nor are its TQDM_* variables read."""
    stream = settings.pop("file", sys.stderr)
    settings.setdefault("disable", None)
    if settings["disable"] or (settings["disable"] is None and not _terminal(stream)) or _closed(stream):
        return _Quiet(stream, settings.get("iterable"), settings.get("total"), settings.get("initial", 0))
    tqdm = _tqdm()
    if _unsized_terminal(stream):
        settings.update(ncols=UNSIZED_COLUMNS, nrows=24, dynamic_ncols=False)
    return tqdm(file=stream, **settings)


def check_progress_variables() -> None:
    """Refuse a TQDM_* environment variable that tqdm cannot read (:func:`_tqdm`), before a command does any work; nothing
    is imported where none is set."""
    if any(name.startswith("TQDM_") for name in os.environ):
        _tqdm()


def _tqdm():
    """tqdm's bar class, a TQDM_* variable it cannot read refused by name: tqdm converts each TQDM_<PARAMETER> to its
    parameter's type as it imports, and TQDM_MININTERVAL=abc was its ValueError's traceback from fly, evolve, compete,
    learn-model, reproduce (--no-progress too) and report (T29-A03)."""
    try:
        from tqdm import tqdm
    except ValueError as err:
        given = {name: value for name, value in os.environ.items() if name.startswith("TQDM_")}
        bad = [name for name, value in given.items() if repr(value) in str(err)] or list(given)
        names = " or ".join(f"{name}={given[name]!r:.40}" for name in bad)
        raise NeurohoverError(
            f"environment variable {names} is not allowed: tqdm (the progress bar) cannot read it ({str(err):.80}); "
            "give what tqdm's docs allow (a number for TQDM_MININTERVAL, TQDM_POSITION and the like), or unset it"
        ) from None
    _check_bar_format(tqdm, os.environ.get("TQDM_BAR_FORMAT"))
    return tqdm


def _check_bar_format(tqdm, bar_format: str | None) -> None:
    """Refuse a TQDM_BAR_FORMAT tqdm cannot draw: it is read as tqdm imports but used only when a bar is first drawn,
    so '{bogus}' was a KeyError traceback mid-command, a store's session left 'running' (T51-A01). Drawn here as a bar's
    first frame (no rate, no postfix yet) and a later one, of a total and of none."""
    if bar_format is None:
        return
    try:
        for n, total, elapsed, postfix in ((0, None, 0.0, None), (0, 10, 0.0, None), (3, 10, 1.2, "x"), (3, None, 1.2, "x")):
            tqdm.format_meter(n, total, elapsed, ncols=80, prefix="unit", unit="it", bar_format=bar_format, postfix=postfix)
    except Exception as err:  # tqdm formats the user's text with str.format: any error of it (KeyError, ValueError, IndexError, ...)
        raise NeurohoverError(
            f"environment variable TQDM_BAR_FORMAT={bar_format!r:.60} is not allowed: tqdm (the progress bar) cannot draw a "
            f"bar with it ({type(err).__name__}: {str(err):.60}); give a format of tqdm's fields, e.g. '{{l_bar}}{{bar}}{{r_bar}}', "
            "or unset it"
        ) from None


class _Quiet:
    """A progress bar that draws nothing: what the commands use of tqdm's (``update``, ``n``, ``total``, ``refresh``,
    ``set_description_str``, ``set_postfix_str``, ``write``, ``close``, iteration and ``with``), without tqdm."""

    def __init__(self, stream, iterable=None, total=None, initial=0) -> None:
        self.stream, self.iterable, self.total, self.n = stream, iterable, total, initial

    def __iter__(self):
        for item in self.iterable if self.iterable is not None else ():
            yield item
            self.n += 1

    def __enter__(self) -> _Quiet:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def update(self, n: float = 1) -> None:
        self.n += n

    def refresh(self, *args, **kwargs) -> None:
        pass

    def set_description_str(self, *args, **kwargs) -> None:
        pass

    def set_postfix_str(self, *args, **kwargs) -> None:
        pass

    def close(self) -> None:
        pass

    def write(self, text: str, file=None, end: str = "\n") -> None:
        """``text`` on ``file`` (standard output unless given), as tqdm.write."""
        out = sys.stdout if file is None else file
        if out is None:
            return
        out.write(text + end)
        out.flush()


def _closed(stream) -> bool:
    """Whether ``stream`` is no stream to draw on: None (standard error closed, ``2>&-``: --progress died in tqdm with
    AttributeError and status 1, before any work; T31-A04), a closed file or one whose descriptor is closed. Such a bar is off, as a closed standard
    output is the null device for a command that writes files (T28-A01)."""
    if stream is None or getattr(stream, "closed", False):
        return True
    try:
        fd = stream.fileno()
    except (AttributeError, OSError, ValueError):  # no file descriptor (a StringIO): open
        return False
    try:
        os.write(fd, b"")  # a descriptor closed, or reopened for reading only, under the stream (tqdm's Errno 9)
    except OSError:
        return True
    return False


def _terminal(stream) -> bool:
    """Whether ``stream`` is a terminal (tqdm's own test of ``disable=None``)."""
    try:
        return bool(stream.isatty())
    except (AttributeError, OSError, ValueError):  # no isatty, a closed stream
        return False


def _unsized_terminal(stream) -> bool:
    """Whether ``stream`` is a terminal whose width reads as 0 (False for anything that is no terminal)."""
    try:
        return bool(stream.isatty()) and os.get_terminal_size(stream.fileno()).columns == 0
    except (AttributeError, OSError, ValueError):  # no fileno (a StringIO), a closed stream
        return False
