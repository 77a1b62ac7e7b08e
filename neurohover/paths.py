"""Checks of the command line's file and directory arguments, made before any long computation.

Internal: neurohover's plumbing (README, Python API, What is public): its checks refuse a bad path by name, and its
other helpers (``printable``, ...) trust their callers, which give them checked values.

Each check refuses a bad path with one :class:`~neurohover.errors.NeurohoverError` that names the
option, the path and what is expected. Output checks really create (and remove again) a file, so
an unwritable place is found even where permission bits do not tell (``/proc``, read-only mounts,
running as root). Missing parent directories of an output are created, and a note on standard
error says so: a typo in a path shows up at once instead of silently. When the command then
fails, :func:`remove_created_dirs` takes away those it created that are still empty, so a refused
or failed run leaves nothing behind (a directory holding any result stays). An output is never
written through a symbolic link to a missing target, and a '..' may climb out of an existing
directory only, never out of one the check would create (left empty beside the output; T19-12).
"""

from __future__ import annotations

import errno
import os
import stat
import sys
import tempfile
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from pathlib import Path

from .errors import NeurohoverError, OutputError, brief
from .filekinds import CHECKPOINT_KIND, NAME_MAX, PNG_KIND, SQLITE_HEADER, held_kind, name_limit, output_name, refuse_policy_set, refuse_unencodable
from .locks import WriterLock, sole_writer, writer_file

__all__ = [
    "WriterLock",
    "checked_path",
    "created_dirs_removed_on_failure",
    "input_file",
    "input_dir",
    "make_dirs",
    "output_dir",
    "output_file",
    "printable",
    "refuse_dangling_link",
    "refuse_foreign_output",
    "refuse_gone_cwd",
    "refuse_link_loop",
    "refuse_special_file",
    "remove_created_dirs",
    "sole_writer",
    "temp_text_file",
    "write_png",
    "writer_file",
    "writing",
]

_created: list[Path] = []  # directories this process's checks created, deepest first


def _why(err: OSError) -> str:
    return err.strerror or type(err).__name__


def make_dirs(directory: Path, option: str, given: str) -> None:
    """Create ``directory`` and any missing parents, saying so on standard error; refuse a file in the way, naming it,
    a symbolic link to a missing target on the way and a '..' that would climb out of a directory it creates.

    Parameters
    ----------
    directory : Path
        The directory to have.
    option : str
        What the messages call the path (``"results store"``, ``"--out"``).
    given : str
        The path as the user gave it (a file in it, or the file's directory), shown in the messages.
    """
    _refuse_climb_or_dangling(directory, option, given)
    missing = []
    here = directory
    while not here.exists():
        missing.append(here)
        if here.parent == here:
            break
        here = here.parent
    if here.exists() and not here.is_dir():
        raise NeurohoverError(f"{option} {given!r}: {str(here)!r} is a file, not a directory: give a path in a directory")
    if not missing:
        return
    try:
        directory.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        raise NeurohoverError(f"{option} {given!r}: cannot create the directory {str(directory)!r} ({_why(err)})") from None
    _created[:0] = missing
    print(f"neurohover: created directory {str(missing[-1])!r}" + (f" and {len(missing) - 1} below it" if len(missing) > 1 else ""), file=sys.stderr)


def _refuse_climb_or_dangling(directory: Path, option: str, given: str) -> None:
    """Refuse a ``directory`` to be made that holds a dangling symbolic link (mkdir's "File exists", T19-12) or a '..'
    right after a part that does not exist yet. The rule: a '..' may climb out of a directory that exists, never out of
    one this check would create, which would be left behind empty while the files went above it ('pp/x/..' made pp/x
    and wrote into pp; T19-12); '..' is not dropped lexically, since after a symbolic link it names another place."""
    parts = directory.parts
    for i in range(1, len(parts) + 1):
        here = Path(*parts[:i])
        if parts[i - 1] == ".." and not os.path.lexists(here.parent):
            raise NeurohoverError(
                f"{option} {given!r}: '..' climbs out of {str(here.parent)!r}, which does not exist: it would be created "
                f"only to be left empty; give the path without it ({os.path.realpath(given)!r})"
            )
        refuse_dangling_link(here, option, given)


def refuse_dangling_link(path: str | os.PathLike, option: str, given: str | os.PathLike | None = None) -> None:
    """Refuse an output ``path`` that is a symbolic link to a missing target: written through, a file appeared wherever
    the link pointed (outside the work folder) and a directory was "File exists" (T19-12, T19-16). ``given``: the path
    as the user gave it (default ``path``)."""
    if os.path.islink(path) and not os.path.exists(path):
        target, shown = os.readlink(os.fspath(path)), os.fspath(path if given is None else given)
        real = Path(os.path.realpath(path))
        where = f", whose directory {str(real.parent)!r} does not exist" if not real.parent.is_dir() else ""
        link = f"{str(path)!r}, a symbolic link" if os.fspath(path) != shown else "a symbolic link"
        raise NeurohoverError(
            f"{option} {shown!r} is {link} to {target!r}{where}: a symbolic link to a missing target is not written "
            "through; give another path, or remove the link"
        )


def _path_max() -> int:
    try:
        limit = int(os.pathconf("/", "PC_PATH_MAX"))
    except (AttributeError, OSError, ValueError):  # not POSIX, or the system cannot say
        limit = 0
    return limit if limit > 0 else 4096


#: The whole path's limit in bytes, its terminating NUL included (PATH_MAX: ``os.pathconf``'s PC_PATH_MAX, else 4096),
#: so the longest path is one byte less; the longest name, :data:`~neurohover.filekinds.NAME_MAX`, is where the file
#: system cannot say (:func:`~neurohover.filekinds.name_limit`).
PATH_MAX = _path_max()

_DIRECTORY_ENDS = tuple(sorted({f"{sep}{end}" for sep in {"/", os.sep} for end in ("", ".", "..")}, key=len, reverse=True))


def path_text(path) -> str | None:
    """The text of ``path`` (a str or os.PathLike), or None for anything else: a path object whose ``__fspath__`` gives no
    str too, which :func:`checked_path` then names (os.fspath's TypeError on an int named no value; T47-B07)."""
    text = path if isinstance(path, str) else type(path).__fspath__(path) if isinstance(path, os.PathLike) else None
    return text if isinstance(text, str) else None


def checked_path(path, option: str, what: str = "file path", ends: tuple[str, ...] = (), file: bool = False) -> Path:
    """``path`` (a str or path object) as a Path: empty, another type, a NUL byte or a name longer than the file system
    takes refused by name (the OS's TypeError, ValueError and OSError before); ``what`` says what to give instead.
    ``ends``: what the command adds to the file's name for the files it writes beside it (evolve's ``NAME.history.csv``
    and ``NAME.checkpoint.json``), whose longest must fit too: a name of 250 bytes was taken, and the run's history file
    then refused (T29-A01). The whole path is counted as given and made absolute, as every check and write then uses
    it: a relative path of 4,081 bytes in a directory of 26 was an OSError "File name too long" (T32-B06).
    ``file``: the path names a file, so one ending in '/', '/.' or '/..' that is no directory is refused (Path()
    drops the first two: 'p.json/' and 'p.json/.' were read and written as p.json; T32-B07, T32-B08); an existing
    directory is the caller's to name."""
    if not isinstance(path, (str, os.PathLike)):
        raise NeurohoverError(f"{option}={path!r:.60} is not allowed: give a {what}")
    text = path_text(path)
    if text is None:  # os.fspath's TypeError on an int named no value (T47-B07)
        given = path.__fspath__() if isinstance(path, os.PathLike) else path
        raise NeurohoverError(f"{option}={path!r:.60} is not allowed: its __fspath__() gives {brief(given)}: give a {what} as text")
    if text == "":
        raise NeurohoverError(f"{option} is empty; give a {what}")
    if "\x00" in text:
        raise NeurohoverError(f"{option} {text!r:.80} holds a NUL character: give a {what}")
    refuse_unencodable(text, option)
    refuse_gone_cwd(text, option)
    parts = Path(text).parts  # "." has no parts (fifth trial)
    end = max(ends, key=lambda e: len(os.fsencode(e)), default="")
    sizes = [len(os.fsencode(part)) for part in parts]
    if sizes and end and parts[-1] != os.sep:
        sizes[-1] += len(os.fsencode(end))
    longest, whole = max(sizes, default=0), len(os.fsencode(text + end))
    absolute = len(os.fsencode(os.path.abspath(text) + end))  # the current directory's length too (T32-B06)
    limit = name_limit(Path(text).parent) if longest > 14 else NAME_MAX  # (no file system takes fewer than 14)
    if longest > limit or max(whole, absolute) >= PATH_MAX:
        beside = f" with the {end} it writes beside it" if end and sizes[-1] == longest and longest > limit else ""
        made = f", {absolute:,} made absolute" if absolute != whole else ""
        raise NeurohoverError(
            f"{option} {brief(text)} is too long: at most {limit} bytes in one file or directory name "
            f"(here {longest:,}{beside}) and {PATH_MAX - 1:,} in the whole path (here {whole:,}{made})"
        )
    refuse_link_loop(text, option)
    if file:
        tail = next((e for e in _DIRECTORY_ENDS if text.endswith(e)), "")
        if tail and not Path(text).is_dir():
            raise NeurohoverError(f"{option} {text!r} ends in {tail!r}, which names a directory: give a {what}")
    return Path(text)


def refuse_gone_cwd(path: str | os.PathLike, option: str) -> None:
    """Refuse a relative ``path`` when the current directory has been removed: os.getcwd() fails, and the command said
    only "No such file or directory", naming no path (T28-A12)."""
    if os.path.isabs(path):
        return
    try:
        os.getcwd()
    except FileNotFoundError:
        raise NeurohoverError(f"{option} {os.fspath(path)!r}: the current directory no longer exists: give an absolute path") from None


def refuse_link_loop(path: str | os.PathLike, option: str) -> None:
    """Refuse a ``path`` that a symbolic-link loop makes unreachable, which no command can read or write: Path.exists()
    is False for one, so a loop was "no such results store" or "cannot create the directory (File exists)" (seventeenth
    trial, T17-11); the words are the policy sets' (:mod:`neurohover.policysets`)."""
    try:
        os.stat(path)
    except OSError as err:
        if err.errno == errno.ELOOP:
            raise NeurohoverError(f"{option} {os.fspath(path)!r} cannot be read (too many levels of symbolic links)") from None


def _no_dash(path: str | os.PathLike, option: str, what: str, stdout: bool) -> None:
    """Refuse ``-``, which by custom means standard output, as a name: it was written as a hidden-looking file named '-'
    (eleventh trial); ``stdout``: leaving ``option`` out writes to standard output."""
    if path_text(path) == "-":
        instead = f"leave {option} out for standard output" if stdout else f"give a {what} name (./- for one called '-')"
        raise NeurohoverError(f"{option} '-' is not a {what} name here: {instead}")


def refuse_pseudo_fs(path: Path, option: str, given: str | os.PathLike, into: bool = False, instead: str = "") -> None:
    """Refuse to create a file or directory ``path`` (``into``: files in the directory ``path``) directly in /dev or
    anywhere under /proc or /sys: ``plot /dev/stdin`` wrote its PNGs into /dev, ``--out /dev/stdout.csv`` made a
    regular file there (T46-A05). An existing path (/dev/null, /dev/stdout, /dev/shm/x) is taken as before."""
    try:
        if not into and os.path.lexists(path):
            return
        above = path if into else path.parent
        while not above.exists() and above != above.parent:  # the nearest existing directory: the new one is made in it
            above = above.parent
        real = Path(os.path.realpath(above))
    except (OSError, ValueError):  # named by the checks that follow
        return
    if real == Path("/dev") or real.is_relative_to("/proc") or real.is_relative_to("/sys"):
        made = "write files" if above == path else "create a file" if above == path.parent else "create a folder"
        instead = instead or f"give {option} {'DIR' if into else 'FILE'} elsewhere"
        raise NeurohoverError(
            f"{option} {str(given)!r}: cannot {made} in {str(real)!r} (in /dev, /proc or /sys: a pseudo file system, where "
            f"nothing neurohover writes belongs); {instead}"
        )


def output_file(
    path: str | os.PathLike,
    option: str,
    inputs: Mapping[str, str | os.PathLike | None] | None = None,
    *,
    store: bool = False,
    stdout: bool = False,
    kind: str | None = None,
    suffixes: tuple[str, ...] = (),
    what: str = "",
    run_files: bool = False,
    ends: tuple[str, ...] = (),
) -> Path:
    """Check that the file ``path`` can be written (an existing file is kept as it is).

    Refuses ``-`` (standard output, which ``stdout`` says leaving ``option`` out gives), a directory, a parent that is
    a file, a symbolic link to a missing target (:func:`refuse_dangling_link`), a '..' after a missing directory
    (:func:`make_dirs`), any place where a file cannot be created, the file of one of ``inputs`` (option -> path: writing it would
    destroy what the command reads) and, unless ``store`` (the path is a results store's own), an existing results
    store; given the ``kind`` of file written (one of :data:`~neurohover.filekinds.JSON_KINDS`' names), an existing neurohover file of
    another kind (:func:`~neurohover.filekinds.held_kind`; T25-01 to T25-03) or a non-empty file that is no neurohover
    file at all (T53-A04, T55-A02; a checkpoint's is :func:`~neurohover.evolution.evolve.evolve`'s), and a name of a
    suffix not in ``suffixes`` (``what`` says why) or
    (``run_files``) an evolve run's own file names (:func:`~neurohover.filekinds.output_name`), a name too long for the
    file system, it or it with the longest of ``ends`` (what the command adds to it for files beside it:
    :func:`checked_path`), and a file in a policy set's directory (:func:`~neurohover.filekinds.refuse_policy_set`), a
    symbolic link to one too; creates missing parent directories (saying so on standard error).
    """
    _no_dash(path, option, "file", stdout)
    p = checked_path(path, option, ends=ends, file=True)  # 'x.json/' and 'x.json/.' too (seventh trial, T32-B08)
    for name, given in (inputs or {}).items():
        if given is not None and str(given) != "" and p.exists() and Path(given).exists() and p.samefile(given):
            raise NeurohoverError(f"{option} {str(path)!r} is the file of {name}: give another path (writing it would destroy what is read)")
    if not store and p.is_file():
        try:
            with open(p, "rb") as f:
                head = f.read(len(SQLITE_HEADER))
        except OSError:
            head = b""  # unreadable: the write check below names it
        if head == SQLITE_HEADER:  # results --out onto another store turned it into CSV (fifth trial)
            raise NeurohoverError(f"{option} {str(path)!r} is a results store (SQLite): give another path (writing it would destroy its results)")
    if p.is_dir():
        raise NeurohoverError(f"{option} {str(path)!r} is a directory; give a file path")
    refuse_special_file(p, option, path)
    if suffixes or run_files:  # flight data, a checkpoint replaced by JSON rows, CSV or a model (T25-01 to T25-03)
        output_name(path, option, suffixes or ("",), what, run_files, ends)
    refuse_policy_set(p.parent, option, path)
    if p.is_symlink():  # written through: a file link into a set replaced the set's policy (T42-A04)
        refuse_policy_set(Path(os.path.realpath(p)).parent, option, path, link=True)
    size = _size(p)  # before its kind is read: a file another thread saved in between was called not neurohover's (T32-B01)
    held = None if kind is None else held_kind(p)
    if held is not None and held != kind:  # a policy, a checkpoint, a summary replaced by another kind of file (T25-01 to T25-03)
        raise NeurohoverError(f"{option} {brief(os.fspath(path))} is {held}: give another path (writing {kind} there would destroy it)")
    # a user's own archive (T53-A04), notes at a policy's, model's or export's name (T55-A02) were replaced; a checkpoint
    # is evolve()'s to judge, which knows whether it resumes from it (a damaged one is named there; T46-B14)
    if kind not in (None, CHECKPOINT_KIND) and held is None and size:
        raise NeurohoverError(f"{option} {brief(os.fspath(path))} is a file neurohover did not write: give another path (writing {kind} would destroy it)")
    refuse_dangling_link(p, option, path)  # a link to nothing was written through, wherever it pointed (T19-12)
    refuse_pseudo_fs(p, option, path)
    make_dirs(p.parent, option, str(path))
    real = Path(os.path.realpath(p))
    existed = real.exists()
    try:
        existed = not _probe(real)
    except OSError as err:
        what = "write this file" if existed else f"create a file in {str(real.parent)!r}"
        raise NeurohoverError(f"{option} {str(path)!r}: cannot {what} ({_why(err)})") from None
    return p


def _size(p: Path) -> int:
    """The size of the regular file ``p``; 0 for anything else, or where it is gone (a probe's file, removed)."""
    try:
        return p.stat().st_size if p.is_file() else 0
    except OSError:
        return 0


def _probe(real: Path) -> bool:
    """Open the file ``real`` for writing, appending nothing (an existing file's content and time stay as they are);
    True where the probe created it, and then removed it again, unless another writer has put its own file there
    meanwhile: a thread's check removed the file another had just saved (T32-B01)."""
    for _ in range(100):  # a file another thread's probe made and removed between our two opens: try again
        try:
            fd = os.open(real, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)
            break
        except FileExistsError:
            try:
                os.close(os.open(real, os.O_WRONLY | os.O_APPEND))
                return False
            except FileNotFoundError:
                continue
    else:
        raise FileNotFoundError(errno.ENOENT, "the file came and went a hundred times while it was checked", str(real))
    try:
        made = os.fstat(fd)
    finally:
        os.close(fd)
    try:
        now = os.stat(real)
        if (now.st_dev, now.st_ino) == (made.st_dev, made.st_ino):
            real.unlink()  # the file the check made, not a link to it (which unlink would remove instead)
    except FileNotFoundError:
        pass
    return True


def refuse_special_file(path: str | os.PathLike, option: str, given: str | os.PathLike | None = None, instead: str = "give a file path") -> None:
    """Refuse an existing ``path`` that is neither a regular file nor a directory: written by replacing it, a device node
    (/dev/full, as root) or a FIFO became a PNG (fourteenth trial); read, a FIFO hung the command for ever (T28-A08).
    ``given``: the path as the user gave it (default ``path``); ``instead``: what to do."""
    try:  # one stat, not exists() then is_file(): a file another thread's check made and removed between them was "a device"
        mode = os.stat(path).st_mode
    except (OSError, ValueError):
        return
    if not (stat.S_ISREG(mode) or stat.S_ISDIR(mode)):
        raise NeurohoverError(f"{option} {str(path if given is None else given)!r} is not a regular file (a device, pipe or socket); {instead}")


def refuse_foreign_output(path: str | os.PathLike, option: str, kind: str) -> None:
    """Refuse to write ``kind`` (one of :func:`~neurohover.filekinds.held_kind`'s words, e.g. ``"a PNG image"``) at the
    output name ``path`` a command chose itself (a figure, report.md) unless it is absent, empty or already ``kind``:
    a user's notes at report.md and a text file at a figure's name were replaced without a word (T28-A04, T28-A05). A
    symbolic link is refused too (report.md was written through one to a file outside --out), and so are a directory
    and a device, pipe or socket, by name: an :class:`~neurohover.errors.OutputError`, the output's fault (report called
    the experiment whose figure was blocked damaged; T50-A04)."""
    shown = repr(os.fspath(path))
    if os.path.islink(path):
        raise OutputError(
            f"{option} {shown} is a symbolic link (to {os.readlink(os.fspath(path))!r}): {kind} is not written through one; "
            "remove the link or give another directory"
        )
    p = Path(path)
    if p.is_dir():
        raise OutputError(f"{option} {shown} is a directory: {kind} would be written there; move it away or give another directory")
    try:
        refuse_special_file(p, option)
    except NeurohoverError as err:
        raise OutputError(str(err)) from None
    if not p.is_file() or p.stat().st_size == 0:
        return
    held = held_kind(p)
    if held != kind:
        raise OutputError(
            f"{option} {shown} is {held or 'a file neurohover did not write'}: it would be replaced with {kind}; move it away or give another directory"
        )


@contextmanager
def writing(path: str | os.PathLike, option: str) -> Iterator[Path]:
    """Write the output file ``path`` inside this block, through the path it yields (a temporary file beside it, moved
    onto ``path`` once the block ends): a failed write (disk full, read-only, permission) becomes one NeurohoverError
    naming ``option`` and the file, and an interrupted one (Ctrl-C, SIGTERM) stops as it was; either way the temporary
    file is removed and ``path`` is as it was before, so that no later run takes a partial file for a result. A device,
    pipe or socket at ``path`` is refused (:func:`refuse_special_file`), before the block and again before the move, and
    so is a symbolic link to a missing target (:func:`refuse_dangling_link`); a link to a file writes that file."""
    refuse_dangling_link(path, option)  # every writer: one to nothing wrote wherever it pointed (T19-12)
    p = Path(os.path.realpath(path))  # through a symbolic link: its file is written, the link kept (not replaced by a file)
    refuse_special_file(p, option, path)  # every writer, not only those checked by output_file first (fourteenth trial)
    partial = writer_file(p, ".partial", hidden=True)
    try:
        yield partial
        refuse_special_file(p, option, path)  # made while the block ran
        os.replace(partial, p)
    except OSError as err:
        raise OutputError(f"{option} {str(path)!r}: cannot write it ({_why(err)}); no partial file is left") from None
    finally:
        partial.unlink(missing_ok=True)


@contextmanager
def temp_text_file(text: str, what: str) -> Iterator[str]:
    """The path of a file in the temporary folder holding ``text`` (``what`` names it in the message), removed after the
    block. A temporary folder that cannot take it (removed mid-session, as a job's TMPDIR is; read-only; full) is one
    :class:`~neurohover.errors.OutputError` naming it, not a traceback (T50-B01)."""
    folder = tempfile.gettempdir()  # Python keeps the first one it found for the whole process
    try:
        fd, path = tempfile.mkstemp(suffix=".tmp", prefix="neurohover-")
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(text)
    except OSError as err:
        raise OutputError(
            f"the temporary folder {folder!r}: cannot write {what} in it ({_why(err)}); allowed: TMPDIR naming a writable directory when neurohover starts"
        ) from None
    try:
        yield path
    finally:
        Path(path).unlink(missing_ok=True)


def write_png(fig, path: str | os.PathLike, what: str, dpi: float | None = None) -> Path:
    """Write the matplotlib figure ``fig`` as a PNG to ``path`` through :func:`writing` (whole or not at all: a full
    disk left an empty PNG and a traceback), only where no file of another kind sits (:func:`refuse_foreign_output`)."""
    refuse_foreign_output(path, what, PNG_KIND)
    with writing(path, what) as partial:
        fig.savefig(partial, format="png", dpi=dpi)
    return Path(path)


def output_dir(path: str | os.PathLike, option: str) -> Path:
    """Check that files can be written in the directory ``path`` (not ``-``), creating it (saying so) if missing; a
    symbolic link to a missing target and a '..' after a missing directory are refused (:func:`make_dirs`), and so is a
    policy set's directory (:func:`~neurohover.filekinds.refuse_policy_set`)."""
    _no_dash(path, option, "directory", False)
    p = checked_path(path, option, "directory")
    if p.exists() and not p.is_dir():
        raise NeurohoverError(f"{option} {str(path)!r} is a file; give a directory")
    refuse_policy_set(p, option, path)
    refuse_pseudo_fs(p, option, path, into=True)
    make_dirs(p, option, str(path))
    try:
        with tempfile.TemporaryFile(dir=p):
            pass
    except OSError as err:
        raise NeurohoverError(f"{option} {str(path)!r}: cannot write files in this directory ({_why(err)})") from None
    return p


def input_file(path: str | os.PathLike, option: str, what: str = "file") -> Path:
    """Check that ``path`` is an existing, readable regular file."""
    p = checked_path(path, option, what, file=True)  # 'p.json/' was read as p.json (T32-B08)
    if not p.exists():
        raise NeurohoverError(f"{option} {str(path)!r}: no such {what}")
    if p.is_dir():
        raise NeurohoverError(f"{option} {str(path)!r} is a directory; give a {what}")
    if not p.is_file():
        raise NeurohoverError(f"{option} {str(path)!r} is not a regular file; give a {what}")
    try:
        with open(p, "rb") as f:
            f.read(1)
    except OSError as err:
        raise NeurohoverError(f"{option} {str(path)!r}: cannot read this {what} ({_why(err)})") from None
    return p


def input_dir(path: str | os.PathLike, option: str) -> Path:
    """Check that ``path`` is an existing directory ('' refused by name: Path('') is the current one; fifth trial)."""
    p = checked_path(path, option, "directory")
    if not p.exists():
        raise NeurohoverError(f"{option} {str(path)!r}: no such directory")
    if not p.is_dir():
        raise NeurohoverError(f"{option} {str(path)!r} is a file; give a directory")
    return p


def remove_created_dirs(since: int | None = None) -> list[Path]:
    """Remove the directories the checks above created that are still empty (a failed command's); returns them.
    ``since``: only those created after :func:`created_count` gave it (one failed API call's, not earlier calls')."""
    mine = list(_created) if since is None else _created[: len(_created) - since]  # newest first
    removed = []
    for directory in mine:
        try:
            directory.rmdir()  # only an empty directory goes
        except OSError:
            continue
        removed.append(directory)
    del _created[: len(mine)]
    if removed:
        print(f"neurohover: removed the empty directory {str(removed[-1])!r} it had created", file=sys.stderr)
    return removed


def created_count() -> int:
    """How many directories the checks have created so far in this process (see :func:`remove_created_dirs`)."""
    return len(_created)


@contextmanager
def created_dirs_removed_on_failure() -> Iterator[None]:
    """Inside this block, a failure removes the directories the checks created in it that are still empty, as the
    command line does for a failed command: an API call (write_report) left the directory it announced (eleventh trial)."""
    since = created_count()
    try:
        yield
    except BaseException:
        remove_created_dirs(since)
        raise


def printable(text: str | os.PathLike) -> str:
    """``text`` (a path) with every character that does not print as itself written as an escape, the way messages
    (``repr``) show it: bytes that are no UTF-8 (kept by Python as surrogates; a UnicodeEncodeError in a report, matplotlib's
    TypeError in a plot title), control characters (a newline split a result line; fourteenth trial) and format characters
    such as U+202E, RIGHT-TO-LEFT OVERRIDE (which showed the rest of the line reversed)."""
    text = os.fspath(text)
    if not isinstance(text, str):
        raise NeurohoverError(f"{text!r:.60} is not allowed: give a name as text")
    if text.isprintable():  # the common case, at C speed
        return text
    return "".join(ch if ch.isprintable() else repr(ch)[1:-1] for ch in text)


def forget_created_dirs() -> None:
    """Start a command afresh: what earlier commands in this process created is theirs."""
    _created.clear()
