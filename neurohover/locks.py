"""One process writing an output at a time: :class:`WriterLock`, an OS advisory lock on a lock file beside the output,
:func:`sole_writer`, evolve's guard of its ``--out``, and :func:`writer_file`, the temporary file one writer writes
(re-exported by :mod:`neurohover.paths`, where they were).

Internal: neurohover's plumbing, called with values neurohover has checked: its helpers trust their callers and do not
check their own arguments (README, Python API, What is public).
"""

from __future__ import annotations

import errno
import os
import re
import socket
import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

from .errors import NeurohoverError
from .filekinds import fitting_name, name_limit

try:
    import fcntl
except ImportError:  # not POSIX: no output lock; one run per output is then the user's care
    fcntl = None  # type: ignore[assignment]

__all__ = ["WriterLock", "hold_file", "sole_writer"]


class WriterLock:
    """One process writing an output at a time: an OS advisory lock (``flock``) on a lock file beside it.

    The holder writes its pid and host into the file. The kernel drops the lock when its process ends in any way, so a
    killed run never blocks the next one; :meth:`release` removes the file while still holding the lock, and a run that
    opened the old file meanwhile sees, once it gets the lock, that the path names another file and starts over. Used by
    :func:`sole_writer` (evolve's ``--out``) and by the results store (``STORE.lock``).
    """

    def __init__(self, path: Path, attempts: int = 100) -> None:
        self.path = path  # the lock file
        self.attempts = attempts
        self.fd = -1

    @property
    def held(self) -> bool:
        return self.fd >= 0

    def open_file(self) -> int:
        """The lock file, created if missing, opened for reading and writing (an OSError where it cannot be)."""
        return os.open(self.path, os.O_RDWR | os.O_CREAT, 0o644)

    def acquire(self, busy: Callable[[str], str]) -> bool:
        """Take the lock (nothing if this object holds it). Another process holding it raises NeurohoverError with
        ``busy(who)``, ``who`` naming the holder ("pid 12 on host h"). False where the lock cannot be taken at all (not
        POSIX, or a filesystem without locks): the output is then written unguarded. Opening the file may raise OSError."""
        if self.held:
            return True
        if fcntl is None:
            return False
        for _ in range(self.attempts):
            fd = self.open_file()
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError as err:
                holder = os.read(fd, 256).decode(errors="replace").split()
                os.close(fd)
                if err.errno not in (errno.EAGAIN, errno.EWOULDBLOCK, errno.EACCES):
                    return False  # ENOLCK and the like: the filesystem cannot lock
                who = f"pid {holder[0]} on host {holder[1]}" if len(holder) >= 2 else f"pid {holder[0]}" if holder else "another process"
                raise NeurohoverError(busy(who)) from None
            if self._names(fd):
                break
            os.close(fd)  # the previous holder removed it as it released: lock the path's new file
        else:
            raise NeurohoverError(f"could not lock {str(self.path)!r}: it kept being replaced by other runs")
        self.fd = fd
        try:
            os.ftruncate(fd, 0)
            os.write(fd, f"{os.getpid()} {socket.gethostname()}\n".encode())
        except OSError:  # no room for the pid: the lock holds all the same
            pass
        return True

    def _names(self, fd: int) -> bool:
        """Whether the lock path still is the file ``fd`` holds (not removed or replaced since it was opened)."""
        try:
            now = os.stat(self.path)
        except FileNotFoundError:
            return False
        held = os.fstat(fd)
        return (now.st_dev, now.st_ino) == (held.st_dev, held.st_ino)

    def release(self) -> None:
        """Remove the lock file, then drop the lock (nothing if not held)."""
        if not self.held:
            return
        try:
            self.path.unlink()
        except OSError:
            pass
        os.close(self.fd)
        self.fd = -1


@contextmanager
def holding(lock_path: Path, busy: Callable[[str], str]) -> Iterator[None]:
    """Hold a :class:`WriterLock` on ``lock_path`` inside this block, refused with ``busy(who)`` while another run holds
    it; a folder where it cannot be made (full, read-only) is left to the output's own write to name."""
    lock = WriterLock(lock_path)
    try:
        lock.acquire(busy)
    except OSError:
        pass
    try:
        yield
    finally:
        lock.release()


@contextmanager
def sole_writer(path: str | os.PathLike, option: str, given: str | os.PathLike | None = None) -> Iterator[None]:
    """Be the only run writing the output ``path`` (and the files named after it) inside this block: a second run on
    the same output is refused, naming the first's pid. Two evolve runs on one --out both said they finished and left
    one's policy beside the other's checkpoint (tenth trial). A :class:`WriterLock` on ``.NAME.lock`` beside it
    (:func:`holding`). ``path``: a str or path object (a str was an AttributeError 'with_name'; T44-B19); ``given``:
    the path as the user gave it, for the message, where ``path`` was made absolute (T48-A03)."""
    path = Path(path)
    named = str(path if given is None else given)
    with holding(
        path.with_name(f".{path.name}.lock"),
        lambda who: f"{option} {named!r} is being written by another run ({who}): wait for it to end, or give another {option}",
    ):
        remove_dead_writers_files(path)
        yield


def writer_file(path: Path, ending: str, hidden: bool = False, pid: int | None = None, tid: int | None = None) -> Path:
    """The temporary file beside ``path`` one writer writes before it moves it onto ``path``: ``NAME.PID.TID{ending}``
    (``hidden``: with a leading dot), one per process and thread (this one's, unless ``pid`` and ``tid`` are given).
    Named by the process only, threads saving one path at once truncated and moved each other's: a corrupt file, one
    save said done and the others "No such file or directory" (T32-B01). The name is cut where the file's own fits and
    this one would not (T29-A01)."""
    tail = f".{os.getpid() if pid is None else pid}.{threading.get_native_id() if tid is None else tid}{ending}"
    dot = "." if hidden else ""
    return path.with_name(dot + fitting_name(path.name, name_limit(path.parent), len(os.fsencode(dot + tail))) + tail)


#: The writer files :func:`writer_file` names for the outputs a :func:`sole_writer` guards: (ending, hidden).
WRITER_FILES = ((".tmp", False), (".partial", True))
_WRITER_NAME = re.compile(r"\.(\d{1,10})\.(\d{1,20})(\.tmp|\.partial)\Z")


def remove_dead_writers_files(path: Path) -> list[Path]:
    """Remove the temporary files of writers of ``path`` (:func:`writer_file`) whose process no longer runs, and return
    them: a writer killed mid-write (SIGKILL, or a signal whose default stops the process: SIGQUIT's core dump) left its
    half-written file beside the output for ever (T35-A03). Called while :func:`sole_writer` holds ``path``, so no live
    neurohover writes them; a file of a live process (this one's threads, or a pid reused since) is left alone."""
    removed: list[Path] = []
    try:
        names = os.listdir(path.parent)
    except OSError:  # an unreadable folder: its writes say so
        return removed
    for name in names:
        found = _WRITER_NAME.search(name)
        if found is None:
            continue
        pid, tid = int(found[1]), int(found[2])
        if not any(writer_file(path, ending, hidden, pid, tid).name == name for ending, hidden in WRITER_FILES if ending == found[3]):
            continue  # another file's, or another output's (an output named '.x' has a leading dot of its own)
        if pid != os.getpid() and not _running(pid):
            try:
                (path.parent / name).unlink()
                removed.append(path.parent / name)
            except OSError:
                pass
    return removed


def _running(pid: int) -> bool:
    """Whether process ``pid`` runs on this host (one of another user's counts as running)."""
    try:
        os.kill(pid, 0)
    except (ProcessLookupError, OverflowError):  # no such process (a pid past the system's is none)
        return False
    except PermissionError:  # another user's
        pass
    return True


def hold_file(path: str | os.PathLike, busy: str) -> int:
    """Take an exclusive ``flock`` on the file ``path`` itself and return its descriptor (close it to let go; -1 where
    locks are not to be had), or raise NeurohoverError with ``busy`` where another holds it. A lock file named after a
    path is got around by a hard link, another name of the same file (two runs wrote one store at once; T32-A08); this
    one follows the file. ``flock`` locks are apart from SQLite's own (POSIX ``fcntl`` locks, dropped when any of the
    process's descriptors of the file closes), so SQLite never drops it. Opening the file may raise OSError."""
    if fcntl is None:
        return -1
    fd = os.open(path, os.O_RDONLY)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError as err:
        os.close(fd)
        if err.errno in (errno.EAGAIN, errno.EWOULDBLOCK, errno.EACCES):
            raise NeurohoverError(busy) from None
        return -1  # ENOLCK and the like: the filesystem cannot lock
    return fd
