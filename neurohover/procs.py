"""Worker process pools that never outlive their parent.

A spawned worker of a plain :class:`~concurrent.futures.ProcessPoolExecutor` waits forever for its
next task when its parent is killed (SIGKILL, or SIGTERM without a handler): it keeps its cores
busy with a unit nobody will record, then idles as an orphan. The pools made here avoid that:

- each worker watches its parent: on Linux the kernel sends it SIGKILL when the parent dies
  (``PR_SET_PDEATHSIG``), and a daemon thread checks ``os.getppid()`` every
  :data:`WATCH_SECONDS` everywhere (a worker reparented to init or a subreaper exits at once);
- :func:`sigterm_as_interrupt` turns SIGTERM in the parent into :class:`Terminated` (a
  KeyboardInterrupt), so the parent's Ctrl-C path runs: finished work is kept, the workers are
  ended by :func:`stop_pool`, and the command exits as if interrupted; SIGHUP, SIGUSR1, SIGUSR2 and the others of
  :func:`~neurohover.errors.stop_signals` alike (they ended the run without a word, T32-A03, T35-A03);
- a worker never hears Ctrl-C, a hang-up nor a scheduler's warning (they stay blocked in it from its first
  instruction on: a terminal or a scheduler sends them to the whole process group) and dies of SIGTERM at once
  without a word: the parent alone decides, and ends its workers. A worker that raised KeyboardInterrupt as it
  imported, or while formatting an exception the parent's SIGTERM then interrupted, printed its
  tracebacks (T26-A01).
"""

from __future__ import annotations

import _thread
import contextlib
import multiprocessing
import os
import signal
import sys
import threading
import time
from collections.abc import Iterator
from concurrent.futures import ProcessPoolExecutor

from .errors import NeurohoverError, Terminated, brief, raise_terminated, stop_signals, whole_number

WATCH_SECONDS = 0.5  # how often a worker checks that its parent is alive

_PR_SET_PDEATHSIG = 1  # from <linux/prctl.h>


__all__ = [
    "Terminated",
    "interrupts_survive_callbacks",
    "max_jobs",
    "open_files_line",
    "cannot_open_line",
    "refuse_few_descriptors",
    "refuse_gone_cwd_for_workers",
    "sigterm_as_interrupt",
    "stop_pool",
    "stop_words",
    "watch_parent",
    "worker_pool",
]


def _die_with_parent() -> bool:
    """Ask the kernel to SIGKILL this process when its parent thread exits (Linux); True if set."""
    if not sys.platform.startswith("linux"):
        return False
    try:
        import ctypes

        libc = ctypes.CDLL(None, use_errno=True)
        return libc.prctl(_PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0) == 0
    except (OSError, AttributeError):
        return False


def _watch(parent: int) -> None:
    while True:
        if os.getppid() != parent:
            os._exit(1)  # no cleanup: the work of an orphan is never recorded
        time.sleep(WATCH_SECONDS)


def watch_parent(parent: int, pdeathsig: bool = True) -> None:
    """Pool initializer: end this worker process when process ``parent`` is gone.

    Parameters
    ----------
    parent : int
        Pid of the process that started this worker.
    pdeathsig : bool
        Also ask the Linux kernel for SIGKILL on the parent's death. Only right when the worker was
        started from the parent's main thread: the kernel sends the signal when the *thread* that
        started the worker exits, not the process.
    """
    if pdeathsig:
        _die_with_parent()
    _deaf_to_ctrl_c()  # already so where the parent spawned it (:class:`_Pool`); this covers any other spawn
    signal.signal(signal.SIGTERM, signal.SIG_DFL)  # stop_pool's SIGTERM ends it at once, with no Python code run (T26-A01)
    if os.getppid() != parent:  # the parent died before the watch began
        os._exit(1)
    # The thread covers the other systems (a numba kernel holding the GIL may delay it a little).
    threading.Thread(target=_watch, args=(parent,), name="neurohover-parent-watch", daemon=True).start()


def _group_signals() -> set[int]:
    """The signals a terminal or a batch scheduler sends a whole process group, which the parent alone hears: SIGINT
    and the command's :func:`~neurohover.errors.stop_signals` but SIGTERM (stop_pool's, which ends a worker)."""
    return {signal.SIGINT, *stop_signals()} - {signal.SIGTERM}


def _deaf_to_ctrl_c() -> set[int | signal.Signals]:
    """Block the :func:`_group_signals` (SIGINT, SIGHUP, a scheduler's SIGUSR2 warning, ...) in this thread (and the
    threads and processes it starts later); the mask it replaces. A worker they killed broke the pool before the parent
    could stop in order (T35-A03)."""
    if not hasattr(signal, "pthread_sigmask"):  # not POSIX
        return set()
    return signal.pthread_sigmask(signal.SIG_BLOCK, _group_signals())


def _start_resource_tracker() -> None:
    """Start multiprocessing's resource tracker, if not running, with SIGHUP blocked: it ignores SIGINT and SIGTERM of
    its own, but a hang-up sent to the process group killed it, and the pool's shutdown then printed its warning and
    tracebacks (T32-A03)."""
    from multiprocessing import resource_tracker

    if not hasattr(signal, "pthread_sigmask"):  # not POSIX
        resource_tracker.ensure_running()
        return
    previous = signal.pthread_sigmask(signal.SIG_BLOCK, _group_signals() - {signal.SIGINT})
    try:
        resource_tracker.ensure_running()
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, previous)


class _Pool(ProcessPoolExecutor):
    """A ProcessPoolExecutor whose workers start with SIGINT blocked (the mask survives fork and exec), so that a Ctrl-C
    sent to the process group never reaches them, not even while they start (T26-A01). The parent's own Ctrl-C is not
    lost: it waits, pending, the milliseconds the worker takes to start (or another thread takes it)."""

    def _spawn_process(self) -> None:  # where ProcessPoolExecutor starts every worker (Python 3.9 on; not in typeshed)
        if not hasattr(signal, "pthread_sigmask"):
            super()._spawn_process()  # type: ignore[misc]
            return
        _start_resource_tracker()  # started first: starting, it unblocks SIGINT (and SIGTERM) in this thread
        previous = _deaf_to_ctrl_c()
        try:
            super()._spawn_process()  # type: ignore[misc]
        finally:
            signal.pthread_sigmask(signal.SIG_SETMASK, previous)


def max_jobs() -> int:
    """The most worker processes a pool may have: the cores this process may run on (its affinity mask, as numba's
    --threads are bounded; ``reproduce --jobs`` is bounded alike). Bounded by the machine's, ``taskset -c 0`` took
    --jobs 2 and recorded the run as on 2 cores (T37-A06)."""
    try:
        return len(os.sched_getaffinity(0)) or 1
    except (AttributeError, OSError):  # not Linux: the machine's cores
        return os.cpu_count() or 1


def refuse_gone_cwd_for_workers(jobs: int) -> None:
    """Refuse ``jobs`` worker processes (more than 1) when the working directory has been removed: multiprocessing's spawn
    asks for it, and the command failed with a bare "No such file or directory", leaving an empty store or output
    directory behind (T32-A06). Called before anything is written."""
    if jobs <= 1:
        return
    try:
        os.getcwd()
    except FileNotFoundError:
        try:  # Linux names the removed directory
            gone = repr(os.readlink("/proc/self/cwd").removesuffix(" (deleted)")) + " "
        except OSError:
            gone = ""
        raise NeurohoverError(
            f"--jobs {jobs} is not allowed here: the working directory {gone}no longer exists: worker processes cannot start "
            "there; cd to an existing directory (or give --jobs 1)"
        ) from None


def pool_descriptors(jobs: int) -> int:
    """The file descriptors this process needs free to start a pool of ``jobs`` workers: 2 per worker (its sentinel and
    the pipe its task data went down), 6 for the pool's queues and wake-up pipe, 1 for multiprocessing's resource
    tracker, and 4 while a worker is spawned (measured on Linux: one fewer free and the pool failed with EMFILE; T45-A01)."""
    return 2 * jobs + 11


#: What a command opens before its pool starts: the store, its lock, SQLite's second handle, compete's folder lock.
COMMAND_DESCRIPTORS = 4


def _descriptors() -> tuple[int, int, int] | None:
    """(soft limit, hard limit, descriptors free below the soft limit), or None where it is unlimited or cannot be read."""
    import resource

    soft, hard = resource.getrlimit(resource.RLIMIT_NOFILE)
    if soft == resource.RLIM_INFINITY:
        return None
    try:
        held = [int(fd) for fd in os.listdir("/proc/self/fd")]  # Linux; the listing's own descriptor among them
    except (OSError, ValueError):
        return None
    return soft, hard, soft - (sum(fd < soft for fd in held) - 1)


def _limit_words(soft: int, hard: int) -> str:
    import resource

    return f"`ulimit -n`, the open-files limit, is {soft}; its hard limit {'unlimited' if hard == resource.RLIM_INFINITY else hard}"


def refuse_few_descriptors(jobs: int, name: str = "--jobs", opened: int = COMMAND_DESCRIPTORS) -> None:
    """Refuse ``jobs`` worker processes (more than 1) when the open-files limit leaves too few descriptors free to start
    them and to open the ``opened`` files a command opens first: the pool failed with a bare "Too many open files", a
    new output folder and an empty store left behind (T45-A01). Called before anything is written."""
    found = _descriptors()
    if found is None:
        return
    soft, hard, free = found
    need = pool_descriptors(jobs) + opened
    if free >= need:
        return
    fewer = f" or give fewer {name} ({name} 1 starts no worker process)" if name == "--jobs" else ", or start fewer workers"
    workers = f"{jobs} worker process{'es' if jobs > 1 else ''}"
    target = soft - free + need  # the limit that leaves them free (1024, the usual one, where the hard limit allows it)
    suggest = target if 1024 <= target or hard < 1024 else 1024
    raise NeurohoverError(
        f"{name} {jobs} is not allowed here: starting {workers} needs {need} free file descriptors, and {free} are free "
        f"({_limit_words(soft, hard)}); raise the limit (`ulimit -n {suggest}`){fewer}"
    )


def open_files_line(err: OSError, takes_jobs: bool) -> str:
    """The one line for a command ended by EMFILE or ENFILE (too many open files), naming the limit and what to do."""
    import errno

    found = _descriptors()
    limit = f" ({_limit_words(found[0], found[1])})" if found else ""
    fewer = " or give fewer --jobs" if takes_jobs else ""
    where = f" opening {str(err.filename)!r:.120}" if err.filename else ""
    if err.errno == errno.ENFILE:
        return f"too many open files on this system{where} (its table of open files is full, /proc/sys/fs/file-max): close other programs{fewer}"
    return f"too many open files{where}{limit}: raise the limit (`ulimit -n 1024` or more){fewer}"


def cannot_open_line(said: str) -> str:
    """What follows "the results store X" where SQLite could not open a file it needs (SQLITE_CANTOPEN, ``said`` its
    words): the open-files limit or the folder, not damage (a healthy store was called damaged; T45-A01)."""
    found = _descriptors()
    limit = f"too few open files allowed ({_limit_words(found[0], found[1])}: raise it, e.g. `ulimit -n 1024`) or " if found and found[0] < 1024 else ""
    return f"could not open a file it needs (SQLite says: {said}): {limit}its folder's permissions; the store itself is not damaged"


def worker_pool(jobs: int) -> ProcessPoolExecutor:
    """A pool of ``jobs`` (1 to :func:`max_jobs`) spawned worker processes that exit when this process dies.

    Spawned, not forked: numba's thread pools are not fork-safe. The workers never hear Ctrl-C, and SIGTERM ends them
    without a word (:func:`stop_pool` sends it): the parent stops them.
    """
    if not whole_number(jobs) or jobs < 1:  # 0 was concurrent.futures' error, '2' a TypeError (thirteenth trial, F16)
        raise NeurohoverError(f"jobs={brief(jobs)} is not allowed: give a whole number of worker processes >= 1")
    if jobs > max_jobs():  # 10**6 was taken, each worker started as work arrived (fourteenth trial T14-21)
        raise NeurohoverError(f"jobs={brief(jobs)} is not allowed: give at most {max_jobs()} worker processes (the cores this process may use)")
    jobs = int(jobs)
    refuse_gone_cwd_for_workers(jobs)
    refuse_few_descriptors(jobs, "jobs", opened=0)
    main = threading.current_thread() is threading.main_thread()
    _start_resource_tracker()  # before the pool's queues register their semaphores with it
    return _Pool(max_workers=jobs, mp_context=multiprocessing.get_context("spawn"), initializer=watch_parent, initargs=(os.getpid(), main))


def stop_pool(pool: ProcessPoolExecutor) -> None:
    """Cancel the queued tasks and end the running ones at once (on Ctrl-C, SIGTERM or an error).

    Interrupted work is never recorded, so letting a worker finish its task (which the pool's own
    shutdown does, for up to a task's whole run time) would only keep the command waiting.
    """
    if not isinstance(pool, ProcessPoolExecutor):  # None was an AttributeError (thirteenth trial, F16)
        raise NeurohoverError(f"pool={brief(pool)} is not allowed: give the ProcessPoolExecutor that worker_pool made")
    workers = list((getattr(pool, "_processes", None) or {}).values())
    pool.shutdown(wait=False, cancel_futures=True)
    for process in workers:
        process.terminate()
    # The pool's manager thread may reap a worker while join() waits on it; join() then returns
    # before the process is marked dead, so wait for that too.
    deadline = time.monotonic() + 10
    for process in workers:
        process.join(timeout=max(0.0, deadline - time.monotonic()))
        while process.is_alive() and time.monotonic() < deadline:
            time.sleep(0.01)


def stop_words(stop: BaseException) -> tuple[str, int]:
    """How a command says it was stopped by ``stop`` (a KeyboardInterrupt, or one raised while handling it) and its
    exit status: ("terminated", 143) for SIGTERM (129 for SIGHUP, 138 for SIGUSR1, 140 for SIGUSR2), ("interrupted", 130)
    for Ctrl-C (128 + the signal, as shells report)."""
    cause: BaseException | None = stop
    while cause is not None:
        if isinstance(cause, Terminated):
            return "terminated", 128 + cause.signum  # 129 for SIGHUP (T32-A03)
        cause = cause.__cause__ or cause.__context__
    return "interrupted", 130


#: How long a dropped Ctrl-C or SIGTERM waits before it is delivered again (time to leave the C callback).
REDELIVER_SECONDS = 0.05


@contextlib.contextmanager
def interrupts_survive_callbacks() -> Iterator[None]:
    """While inside, a Ctrl-C or SIGTERM whose exception was raised inside a C callback is delivered again.

    Python can only print and drop an exception raised in a ctypes callback; numba's compilation runs one
    (llvmlite's object-cache notify) for every function it compiles, so a signal landing there was lost and
    the command ran on (third trial). The dropped interrupt is re-sent to the main thread from a helper
    thread a moment later, until it lands in Python code.
    """
    previous = sys.unraisablehook

    def hook(unraisable) -> None:
        if not isinstance(unraisable.exc_value, KeyboardInterrupt):
            previous(unraisable)
            return
        signum = unraisable.exc_value.signum if isinstance(unraisable.exc_value, Terminated) else signal.SIGINT  # SIGRTMIN+1 has no name
        threading.Thread(target=_deliver_again, args=(signum,), daemon=True).start()

    sys.unraisablehook = hook
    try:
        yield
    finally:
        sys.unraisablehook = previous


def _deliver_again(signum: int) -> None:
    time.sleep(REDELIVER_SECONDS)
    _thread.interrupt_main(signum)  # type: ignore[arg-type]  # an int: typeshed says Signals, SIGRTMIN+1 has no member


@contextlib.contextmanager
def sigterm_as_interrupt() -> Iterator[None]:
    """While inside, SIGTERM (SIGHUP alike: :func:`~neurohover.errors.stop_signals`) raises :class:`Terminated` in the
    main thread.

    Does nothing outside the main thread; leaves a signal that already has a handler of its own as it is.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    # Not SIGUSR1: the command takes it at import; a program's own (faulthandler's dump registers no Python handler) stays.
    taken = [signum for signum in stop_signals(command=False) if signal.getsignal(signum) == signal.SIG_DFL]
    if not taken:
        yield
        return
    for signum in taken:
        signal.signal(signum, raise_terminated)
    try:
        with interrupts_survive_callbacks():
            yield
    finally:
        for signum in taken:
            signal.signal(signum, signal.SIG_DFL)


def half_free_memory() -> int:
    """Half the memory free now, in bytes (2**62 where the system does not say): what one command may fill."""
    try:
        return os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE") // 2
    except (ValueError, OSError, AttributeError):  # not POSIX: no cap
        return 2**62
