"""neurohover: generalized helicopter hovering (Koppejan & Whiteson 2011), fast and faithful.

Data flows one way: task family -> MDP -> batched rollouts of policies -> returns and flight data
-> evolution / model learning -> agents -> experiments.
"""

from __future__ import annotations

import importlib
import importlib.metadata
import importlib.util
import os
import sys


def _interrupted(kind, value, tb) -> None:
    stop, depth = value, 0
    while stop is not None and not isinstance(stop, KeyboardInterrupt) and depth < 20:  # one Python wrapped: a Ctrl-C in a
        stop, depth = stop.__cause__ or stop.__context__, depth + 1  # class body's __set_name__ is a RuntimeError (session 27)
    if isinstance(stop, KeyboardInterrupt):  # Ctrl-C or SIGTERM while NumPy and numba import, before main() can catch it
        kind, value = type(stop), stop
        terminated = issubclass(kind, Terminated)
        print(f"neurohover: {'terminated' if terminated else 'interrupted'}", file=sys.stderr, flush=True)
        os._exit(128 + getattr(value, "signum", 15) if terminated else 130)  # as main() ends them (Python would end by the signal itself)
    else:
        sys.__excepthook__(kind, value, tb)


from .command import running_as_command  # noqa: E402  (stdlib only: before NumPy and numba import)
from .errors import Terminated, raise_terminated, redeliver_ignored_stop, stop_signals  # noqa: E402

if running_as_command():
    import signal

    sys.excepthook = _interrupted
    sys.unraisablehook = redeliver_ignored_stop  # a stop inside an import's callback was ignored, the run went on
    for signum in stop_signals():  # from the first import on, SIGTERM ends the command as Ctrl-C does (fourth trial); SIGHUP too (T32-A03)
        if signum == signal.SIGTERM or signal.getsignal(signum) != signal.SIG_IGN:  # nohup's ignored SIGHUP stays ignored
            signal.signal(signum, raise_terminated)
    if sys.flags.warn_default_encoding:  # -W error::EncodingWarning made numba's import (open() of /proc/cpuinfo) a
        import warnings  # traceback in every command (T39-A02): the libraries' own opens are theirs; ours name UTF-8

        warnings.filterwarnings("ignore", category=EncodingWarning, module=r"(?!neurohover(\.|$))")

from .errors import NeurohoverError  # noqa: E402

#: The most threads NUMBA_NUM_THREADS may ask for: 4096 ran, 99999 killed the process without a word (SIGSEGV, T18-2).
MAX_NUMBA_THREADS = 4096


def _thread_count(value: str) -> bool:
    return value.strip().isascii() and value.strip().isdigit() and 1 <= int(value) <= MAX_NUMBA_THREADS


def _omp_thread_counts(value: str) -> bool:
    """OMP_NUM_THREADS as libgomp reads it: whole numbers > 0 separated by commas, each with spaces or a '+' around."""
    import re

    return all(re.fullmatch(r"\s*\+?[0-9]+\s*", n, re.ASCII) and 0 < int(n) < 2**63 for n in value.split(","))


def _zero_or_one(value: str) -> bool:
    return value.strip() in ("0", "1")


#: The threading layers numba takes (NUMBA_THREADING_LAYER, any case), and the pools some of them need, one of which
#: must load: TBB is no dependency of ours, and numba said "No threading layer could be loaded" at the first flight.
_THREADING_LAYERS = ("default", "safe", "threadsafe", "forksafe", "omp", "tbb", "workqueue")
_LAYER_POOLS = {"tbb": ("tbbpool",), "safe": ("tbbpool",), "omp": ("omppool",), "threadsafe": ("tbbpool", "omppool")}

#: The numba variables our docs name or users set, read by numba as it imports: each one's test and what it allows. A
#: value numba cannot parse was its warning with a traceback, then its default (tenth trial: NUMBA_NUM_THREADS; eleventh:
#: CUDASIM; sixteenth, T16-3: DISABLE_JIT, OPT, BOUNDSCHECK), or its traceback at the first flight (T16-2: THREADING_LAYER).
_NUMBA_VARIABLES = {
    "NUMBA_NUM_THREADS": (_thread_count, f"give a whole number in 1..{MAX_NUMBA_THREADS} (numba's threads), or unset it"),
    "NUMBA_ENABLE_CUDASIM": (_zero_or_one, "give 0 or 1 (1: numba's CUDA simulator stands in for a GPU), or unset it"),
    "NUMBA_DISABLE_JIT": (_zero_or_one, "give 0 or 1 (1: the kernels run as plain Python, very slowly), or unset it"),
    "NUMBA_BOUNDSCHECK": (_zero_or_one, "give 0 or 1 (1: every array index is checked), or unset it"),
    "NUMBA_OPT": (lambda value: value in ("0", "1", "2", "3", "max"), "give 0, 1, 2, 3 or max (the compiler's optimisation level), or unset it"),
    "NUMBA_THREADING_LAYER": (lambda value: value.lower() in _THREADING_LAYERS, f"give one of {', '.join(_THREADING_LAYERS)}, or unset it"),
    "NUMBA_THREADING_LAYER_PRIORITY": (
        lambda value: sorted(value.split()) == ["omp", "tbb", "workqueue"],
        "give tbb, omp and workqueue in the order numba tries them, separated by spaces, or unset it",
    ),
    # read by libgomp as numba's omp layer loads it at the first flight: '1.0' was its "Invalid value" line, then its default (T50)
    "OMP_NUM_THREADS": (_omp_thread_counts, "give a whole number > 0 (OpenMP's threads), or a comma list of them (one per nesting level), or unset it"),
}


def _refuse_setting(message: str) -> None:
    """The command line's exit 2 with ``message`` on one line; a NeurohoverError on import."""
    if running_as_command():
        print(f"neurohover: error: {message}", file=sys.stderr, flush=True)
        sys.exit(2)
    raise NeurohoverError(message)


def _check_numba_variables() -> None:
    """The numba variables of :data:`_NUMBA_VARIABLES` set in the environment, each refused by name where it does not
    pass its test (the command line's exit 2, a NeurohoverError on import): 0 threads or less was numba's traceback
    from every command, --help too, and other text its warning, then its default."""
    for name, (allowed, what) in _NUMBA_VARIABLES.items():
        value = os.environ.get(name)
        if value is None or allowed(value):
            continue
        _refuse_setting(f"environment variable {name}={value!r:.40} is not allowed: {what}")


def _check_source_date_epoch() -> None:
    """Refuse a SOURCE_DATE_EPOCH that NumPy's f2py cannot read, as f2py does (``int()``, then ``time.gmtime``): f2py
    reads it as it imports, and NumPy and SciPy import f2py lazily, so 'abc', '1.5' or 99999999999999999999 was its
    ValueError or OverflowError traceback from fly, evolve and report, and compete's failed units (T38-A01). Set but
    empty is taken as unset, as the reproducible-builds specification has it (a shell's ``SOURCE_DATE_EPOCH=``), and
    removed from the environment for f2py, which would read it as an integer."""
    import time

    value = os.environ.get("SOURCE_DATE_EPOCH")
    if value is None:
        return
    if value == "":
        del os.environ["SOURCE_DATE_EPOCH"]
        return
    try:
        time.gmtime(int(value))
    except (ValueError, OverflowError, OSError):
        _refuse_setting(
            f"environment variable SOURCE_DATE_EPOCH={value!r:.40} is not allowed: give a whole number of seconds since "
            "1970-01-01 UTC (a build date NumPy's f2py reads as it imports), or unset it"
        )


#: The address space (RLIMIT_AS, ``ulimit -v``) a command needs, in MiB: this much, this much more for each OpenBLAS
#: thread (NumPy's and SciPy's copy each reserve a 32 MiB buffer and a stack per thread as they load) and this much for
#: each of numba's (a stack). Fly of ghh08 with 2 threads each ran in 488 MiB (peak 484) and failed in 460; 1 thread
#: each peaked at 395 MiB, 8 each at 957 (T38-A02).
ADDRESS_SPACE_MIB = (315, 75, 10)


def _pool_threads() -> tuple[int, int]:
    """The threads OpenBLAS (OPENBLAS_NUM_THREADS, GOTO_NUM_THREADS or OMP_NUM_THREADS, else one per core, at most 64)
    and numba (NUMBA_NUM_THREADS, else one per core) will start in this process."""
    cores = os.cpu_count() or 1
    numba = os.environ.get("NUMBA_NUM_THREADS", "").strip()
    blas = next((os.environ[k].strip() for k in ("OPENBLAS_NUM_THREADS", "GOTO_NUM_THREADS", "OMP_NUM_THREADS") if os.environ.get(k, "").strip()), "")
    counts = [int(v) if v.isascii() and v.isdigit() and int(v) > 0 else cores for v in (blas, numba)]
    return min(counts[0], 64), counts[1]


def _check_address_space() -> None:
    """Refuse, as the command, an address-space limit (RLIMIT_AS, ``ulimit -v``) below what its thread pools reserve as
    they start: SciPy's OpenBLAS, loaded by numba's first compilation, retried its buffer's mmap for ever (OpenBLAS issue
    5289) with the interpreter's lock held, so the command hung without a word and SIGTERM's handler never ran; a
    little more room and OpenBLAS's failed thread start raised SIGINT ("interrupted"), less and llvmlite would not load
    (T38-A02). A program importing us keeps its own limits."""
    try:
        import resource
    except ImportError:  # not POSIX: no such limit
        return
    soft = resource.getrlimit(resource.RLIMIT_AS)[0]
    if not running_as_command() or soft == resource.RLIM_INFINITY:
        return
    blas, numba = _pool_threads()
    base, per_blas, per_numba = ADDRESS_SPACE_MIB
    need = (base + per_blas * blas + per_numba * numba) * 1024  # KiB, as ulimit -v counts
    if soft // 1024 < need:
        _refuse_setting(
            f"the address-space limit (ulimit -v) {soft // 1024} KiB is not allowed: neurohover needs {need} KiB with {blas} OpenBLAS "
            f"and {numba} numba threads (NumPy's and SciPy's OpenBLAS hang when they cannot reserve their buffers); "
            "raise it, or set OPENBLAS_NUM_THREADS and NUMBA_NUM_THREADS lower, or unset it (ulimit -v unlimited)"
        )


def _import_numba() -> None:
    """Import numba, a variable it cannot parse refused by name: it warned with a traceback and took its default (any
    NUMBA_ variable besides those of :data:`_NUMBA_VARIABLES`, NUMBA_DEBUG=x...; T16-3). Numba's other warnings are
    passed on."""
    import re
    import warnings

    if "numba" in sys.modules:  # imported before us: it has read (and warned about) its variables already
        return
    with warnings.catch_warnings(record=True) as caught:
        try:
            import numba  # noqa: F401
        except ModuleNotFoundError as err:  # numba, or NumPy it imports first: a traceback from every command (T49)
            _missing_dependency(err)
    for w in caught:
        bad = re.match(r"Environment variable '(\w+)' is defined but its associated value '(.*)' could not be parsed", str(w.message), re.S)
        if bad is None:
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
            continue
        why = [line for line in str(w.message).splitlines() if line.strip()][-1]  # the parse's exception, its last line
        given = f"{bad[1]}={bad[2]!r:.40}"
        given = f"environment variable {given}" if bad[1] in os.environ else f"{given} of .numba_config.yaml"
        _refuse_setting(f"{given} is not allowed: numba cannot read it ({why.strip():.80}); give what numba's docs allow, or unset it")


def _missing_dependency(err: ModuleNotFoundError) -> None:
    """A required package that is not installed (``python -S``, another interpreter than the one neurohover was
    installed into), named on one line: the command's exit 2, an ImportError on import. Its traceback was all."""
    name = (err.name or "numba").partition(".")[0]
    message = (
        f"neurohover needs the package {name}, which this Python ({sys.executable}) cannot import ({err}): install it "
        f"(pip install {name}, or pip install neurohover with its dependencies), or run the Python it was installed into"
    )
    if running_as_command():
        print(f"neurohover: error: {message}", file=sys.stderr, flush=True)
        sys.exit(2)
    raise ModuleNotFoundError(message, name=err.name) from None


def _check_threading_layer() -> None:
    """Refuse a NUMBA_THREADING_LAYER whose pool cannot load here (tbb without TBB): numba's traceback at the first
    flight, "No threading layer could be loaded" (sixteenth trial, T16-2)."""
    layer = os.environ.get("NUMBA_THREADING_LAYER", "default").lower()
    pools = _LAYER_POOLS.get(layer, ())
    if pools and not any(_loads(f"numba.np.ufunc.{pool}") for pool in pools):
        needs = " or ".join({"tbbpool": "Intel TBB (pip install tbb)", "omppool": "OpenMP"}[pool] for pool in pools)
        _refuse_setting(
            f"environment variable NUMBA_THREADING_LAYER={layer!r} names a threading layer numba cannot load here: it needs {needs}; "
            "install that, or give default, forksafe or workqueue, or unset it"
        )


def _loads(module: str) -> bool:
    try:
        importlib.import_module(module)
    except ImportError:  # its shared library is missing (libtbb.so)
        return False
    return True


def _check_matplotlib_backend() -> None:
    """Refuse an MPLBACKEND that matplotlib does not know, naming those it does: matplotlib's ValueError at its import
    was a traceback from every command, --help too (pycma imports it; sixteenth trial, T16-1). Matplotlib is imported
    here only where MPLBACKEND is set, without it (which would raise), then given the backend as it does itself."""
    value = os.environ.get("MPLBACKEND")
    if not value or "matplotlib" in sys.modules or importlib.util.find_spec("matplotlib") is None:
        return
    del os.environ["MPLBACKEND"]
    try:
        import matplotlib
        from matplotlib.rcsetup import validate_backend
    finally:
        os.environ["MPLBACKEND"] = value
    try:
        validate_backend(value)
    except ValueError:
        try:
            from matplotlib.backends import backend_registry

            known = backend_registry.list_all()
        except ImportError:  # matplotlib 3.8
            known = list(getattr(matplotlib.rcsetup, "all_backends", ()))
        _refuse_setting(f"environment variable MPLBACKEND={value!r:.40} is not allowed: give one of matplotlib's backends ({', '.join(known)}), or unset it")
    matplotlib.rcParams["backend"] = value  # what matplotlib does with MPLBACKEND as it imports


_check_numba_variables()
_check_source_date_epoch()
_check_address_space()
_check_matplotlib_backend()
_import_numba()
_check_threading_layer()

from .evaluate import DangerousState, Evaluation, PolicyTable, Safeguard, evaluate, evaluate_jobs  # noqa: E402
from .flightdata import FlightData  # noqa: E402
from .policies import Policy, baseline_policy, load_policy, prototype, save_policy  # noqa: E402
from .tasks import FGHH, GHH08, GHH09, MDP, Drift, Sensor, get_task_family  # noqa: E402

try:
    __version__ = importlib.metadata.version("neurohover")  # one source of truth: pyproject.toml, as installed
except importlib.metadata.PackageNotFoundError:  # a source tree on sys.path that was never installed
    __version__ = "0+unknown"

__all__ = [
    "FGHH",
    "GHH08",
    "GHH09",
    "MDP",
    "Sensor",
    "Drift",
    "Evaluation",
    "FlightData",
    "NeurohoverError",
    "Policy",
    "DangerousState",
    "PolicyTable",
    "Safeguard",
    "baseline_policy",
    "evaluate",
    "evaluate_jobs",
    "get_task_family",
    "load_policy",
    "prototype",
    "save_policy",
]

from . import envs as _envs  # noqa: E402,F401  (registers the Gymnasium environments)
from . import policy_records as _policy_records  # noqa: E402,F401  (installs load_policy's check of a policy file's record, T23-11)
