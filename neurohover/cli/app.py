"""The ``neurohover`` command: its parser (each command module registers its commands) and ``main``.

Bad input prints one clear message and exits with status 2 (never a traceback from numba).
"""

from __future__ import annotations

import argparse
import contextlib
import errno
import io
import itertools
import os
import re
import signal
import sqlite3
import sys
import unicodedata
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from typing import NoReturn

from .. import __version__
from ..command import running_as_command
from ..errors import NeurohoverError
from . import agents, evaluate, flying, learning, plots, reproduce, settings

#: Commands that fly the CPU kernel at once; on a fresh install they say so before it compiles.
COMPILING = ("fly", "demo", "bench", "evolve", "build-policies", "compete", "evaluate-agent", "reproduce")


def _once(action, parser, namespace, option_string) -> None:
    """Refuse an option given a second time (argparse would keep the last one, or the flag, without a word)."""
    given = namespace.__dict__.setdefault("_given_options", set())
    if option_string is not None and action.dest in given:
        parser.error(f"{'/'.join(action.option_strings)} is given more than once: give it once")
    given.add(action.dest)


class _StoreOnce(argparse._StoreAction):
    """An option that takes one value: given twice, it is refused."""

    def __call__(self, parser, namespace, values, option_string=None) -> None:
        _once(self, parser, namespace, option_string)
        super().__call__(parser, namespace, values, option_string)


class _FlagOnce(argparse._StoreTrueAction):
    """A flag: given twice (fly --json --json), it is refused as a repeated option is."""

    def __call__(self, parser, namespace, values, option_string=None) -> None:
        _once(self, parser, namespace, option_string)
        super().__call__(parser, namespace, values, option_string)


class _SwitchOnce(argparse.BooleanOptionalAction):
    """A --x/--no-x switch: given twice, in either spelling or an abbreviation, it is refused as a repeated option is."""

    def __call__(self, parser, namespace, values, option_string=None) -> None:
        _once(self, parser, namespace, option_string)
        super().__call__(parser, namespace, values, option_string)


class _Parser(argparse.ArgumentParser):
    """argparse's parser with single-valued options and flags refused when repeated (its subcommands' parsers are of
    this class too; other scripts' digits are refused by main, in every argument)."""

    def __init__(self, *args, **kwargs) -> None:
        super().__init__(*args, **kwargs)
        self.register("action", None, _StoreOnce)
        self.register("action", "store", _StoreOnce)
        self.register("action", "store_true", _FlagOnce)
        self.register("action", argparse.BooleanOptionalAction, _SwitchOnce)  # --prog --no-progress: the last won (T36-A03)

    def _get_option_tuples(self, option_string: str) -> list:
        """argparse's options an abbreviation may mean, one per option: --optim was ambiguous between the two spellings
        of one option, --optimizer and --optimiser (Python < 3.12.7; T44-A01)."""
        found = super()._get_option_tuples(option_string)
        return [t for n, t in enumerate(found) if all(t[0] is not u[0] for u in found[:n])]

    def error(self, message: str) -> NoReturn:
        """argparse's error in one line, as every other refusal (its usage block made 3-7 lines; T22-18), pointing to
        --help for the usage; a 100,000-character value shortened (its "invalid choice: 'ggg...'" echoed it whole)."""
        message = _no_value(message)
        self.exit(2, f"{self.prog}: error: {shorter_numbers(message)} (usage: {self.prog} --help)\n")


def _no_value(message: str) -> str:
    """argparse's ``message``, with its "ignored explicit argument" for a flag or switch given a value (--json=yes,
    --progress=false) said as what is allowed: it named no rule, and "ignored" read as if the run went on (T55-A03)."""
    found = re.fullmatch(r"argument (\S+): ignored explicit argument (.*)", message, re.DOTALL)
    if found is None:
        return message
    names, value = found[1].split("/"), found[2]
    switch = len(names) == 2 and names[1] == "--no-" + names[0].removeprefix("--")  # a BooleanOptionalAction's pair
    allowed = f"{names[0]} or {names[1]}" if switch else f"{' or '.join(names)} alone, or leave it out"
    return f"{found[1]} takes no value, got {value}: give {allowed}"


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="neurohover", description="Generalized helicopter hovering (Koppejan & Whiteson 2011): fly, evolve, learn models, compete, reproduce."
    )
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    for module in (flying, settings, learning, agents, evaluate, reproduce, plots):
        module.register(sub)
    return parser


def _refuse_version_with_more(parser: argparse.ArgumentParser, given: list[str], commands: dict) -> None:
    """Refuse --version (or what argparse takes for it: any unique prefix before the command, --vers; T36-A02) given
    with other arguments: argparse prints the version and drops the rest without a word."""
    head = list(itertools.takewhile(lambda a: a not in commands, given))
    asked = [a for a in head if len(a) > 2 and "--version".startswith(a)]
    if not asked or len(given) == 1:
        return
    if len(asked) > 1:  # "got ''" named nothing (T36-A04)
        parser.error(f"--version is given more than once ({' '.join(asked)}): give it once")
    rest = list(given)
    rest.remove(asked[0])
    parser.error(f"--version takes no other arguments, got {' '.join(rest)!r}")


def _other_scripts_digits(argv: Sequence[str]) -> str | None:
    """The first argument that holds a digit of another script (Python's int() and float() read '\u0661' as 1, inside
    --wind lists, KEY=VALUE settings and sensor text alike), or None."""
    for arg in argv:
        if any(not ch.isascii() and unicodedata.decimal(ch, None) is not None for ch in str(arg)):
            return str(arg)
    return None


def main(argv: Sequence[str] | None = None) -> int:
    """The command line: ``neurohover ARGS`` (``argv``: the arguments, default ``sys.argv[1:]``); the exit status."""
    if argv is None:  # a path of undecodable bytes printed under a strict UTF-8 stdout was a traceback after the results (ninth trial)
        _unwritable_stderr_closed()
        for stream in (sys.stdout, sys.stderr):
            if hasattr(stream, "reconfigure"):
                stream.reconfigure(errors="backslashreplace")
    status = _run(argv)
    if argv is None and running_as_command():  # the command's own process (a program calling main() keeps its signals)
        # The command is over and has said so: a Ctrl-C or SIGTERM now would kill the interpreter while it exits, with
        # no line and a status saying that the finished command was stopped (fourth trial).
        from ..errors import stop_signals

        for signum in (signal.SIGINT, *stop_signals()):  # SIGHUP, SIGUSR1 as SIGTERM (T32-A03)
            signal.signal(signum, signal.SIG_IGN)
        # `python -m` ends by SIGINT itself (status -2, not 130) once a Ctrl-C escaped an eval() of source text, caught or
        # not (namedtuple's, as a module of the command imported); evaluating text again clears CPython's mark of it.
        eval("0")
    return status


def _unwritable_stderr_closed() -> None:
    """Take a standard error open for reading only (``2</dev/null``) as closed, None, as Python takes ``2>&-``: every
    error line then failed again inside its own handler, status 1 and no word anywhere (trial 31); closed, the line goes
    to standard output, as print() sends it."""
    try:
        fd = sys.stderr.fileno() if sys.stderr is not None else None
    except (OSError, ValueError, io.UnsupportedOperation):  # a stream with no descriptor of its own writes as it writes
        return
    if fd is not None:
        try:
            os.write(fd, b"")
        except OSError:
            sys.stderr = None


def _negative_number(arg: str) -> bool:
    """Whether ``arg`` reads as a negative number or list of them: '-1,5', '-.5', and '-inf', '-nan', '-Infinity' in any
    case (argparse took those for options: "expected one argument"; T54-A02)."""
    rest = arg[1:2].isdigit() or arg[1:2] == "." or arg[1:].lower().startswith(("inf", "nan"))
    return arg[:1] == "-" and rest


def _negative_values_attached(parser: argparse.ArgumentParser, given: list[str]) -> list[str]:
    """``--runs -1,5`` as ``--runs=-1,5``: argparse takes a value that starts with '-' and is not a plain number for an
    option and says only "expected one argument" (fourth trial; -inf and -nan too, T54-A02); attached, the option's own check names it. A unique
    abbreviation (``--win -3,1``) is joined too: argparse accepts abbreviations everywhere else."""
    takes_value = {o for a in parser._actions if a.nargs is None for o in a.option_strings}
    every = {o for a in parser._actions for o in a.option_strings}

    def spelled_out(arg: str) -> str:  # '--win' as argparse reads it, '--wind' (an abbreviation was "expected one argument"; eleventh trial, U7)
        matches = [o for o in every if o.startswith(arg)] if arg.startswith("--") and "=" not in arg and arg not in every else []
        return matches[0] if len(matches) == 1 else arg

    out: list[str] = []
    for arg in given:
        if out and spelled_out(out[-1]) in takes_value and _negative_number(arg):
            out[-1] = f"{out[-1]}={arg}"
        else:
            out.append(arg)
    return out


def _run(argv: Sequence[str] | None) -> int:
    if sys.flags.optimize >= 2:  # -OO strips the docstrings the commands' help (and pycma) are built from (T30-A01)
        print(
            f"neurohover: error: PYTHONOPTIMIZE={sys.flags.optimize} (python -OO) is not allowed: it strips the docstrings neurohover's "
            "help and pycma read; unset it, or set it to 1",
            file=sys.stderr,
        )
        return 2
    parser = build_parser()  # a Ctrl-C while it imports the command modules: the package's hook (neurohover/__init__.py)
    given = list(sys.argv[1:] if argv is None else argv)
    action = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    commands: dict[str, argparse.ArgumentParser] = dict(action.choices or {})
    named = next((commands[a] for a in given if a in commands), parser)  # its errors say "neurohover CMD: error:" (third trial)
    odd = _other_scripts_digits(given)
    if odd is not None:
        named.error(f"argument {odd!r} holds digits of another script: give numbers in ASCII digits")
    _refuse_version_with_more(parser, given, commands)
    for option in named._actions:  # argparse keeps the last of --x --no-x without a word (fourth trial)
        if isinstance(option, argparse.BooleanOptionalAction) and all(any(g.split("=")[0] == o for g in given) for o in option.option_strings):
            named.error(f"{' and '.join(option.option_strings)} are both given: give one")
    given = _negative_values_attached(named, given)
    args, extra = parser.parse_known_args(given)
    if extra:  # argparse reports them from the top parser, without the command's name
        named.error(f"unrecognized arguments: {' '.join(extra)}")
    from ..paths import forget_created_dirs, remove_created_dirs

    forget_created_dirs()
    try:
        _refuse_closed_stdout(args)
        if getattr(args, "progress", None) is not False:  # a TQDM_* variable tqdm cannot read, before any work (T29-A03)
            from ..progress import check_progress_variables

            check_progress_variables()
        if getattr(args, "seed", None) is not None:  # every command's --seed, one range, before any work
            from ..evolution.seeding import check_seed

            check_seed(args.seed)
        steps = getattr(args, "episode_steps", None)
        if steps is not None:  # every command's --episode-steps, one range, named by its option (it said n_steps; fourth trial)
            from ..sim.constants import MAX_EPISODE_STEPS

            if not 1 <= steps <= MAX_EPISODE_STEPS:
                raise NeurohoverError(f"--episode-steps {steps} is out of range: allowed an integer in 1..{MAX_EPISODE_STEPS:,}")
        if args.command in COMPILING and not getattr(args, "json", False):
            from ..sim import kernel_compiled

            if not kernel_compiled():  # tens of seconds without output otherwise
                print("neurohover: compiling the simulation kernel (first use of this version on this machine; cached afterwards)", file=sys.stderr)
        from ..procs import interrupts_survive_callbacks, sigterm_as_interrupt

        # SIGTERM (a timeout, kill) ends every command as Ctrl-C does: one line, its cleanup run, no partial file (a
        # bare SIGTERM killed fly, evolve, compete and reproduce without a word; fourth trial); a Ctrl-C landing in
        # numba's compilation is not lost.
        with sigterm_as_interrupt(), interrupts_survive_callbacks(), _stdout_or_nothing(), _whole_stdout_writes():
            status = args.func(args)
            if sys.stdout is not None:
                sys.stdout.flush()  # inside the try: a reader gone away is the BrokenPipeError below, not one at exit
            return status
    except NeurohoverError as err:
        print(f"neurohover {args.command}: error: {shorter_numbers(str(err))}", file=sys.stderr)
        remove_created_dirs()  # a failed command leaves no empty output directory behind
        return 2
    except sqlite3.DatabaseError as err:  # a store file damaged mid-file, or not a store at all
        print(f"neurohover {args.command}: error: {_store_failure(args, err)}", file=sys.stderr)
        remove_created_dirs()
        return 2
    except KeyboardInterrupt as stop:
        from ..procs import stop_words

        how, status = stop_words(stop)
        print(f"neurohover {args.command}: {how}", file=sys.stderr)
        remove_created_dirs()  # an output directory it made and left empty (an interrupted build-policies; fourth trial)
        return status
    except BrokenPipeError:  # the reader went away (`neurohover demo | head -1`): stop quietly with status 1, as Python's
        # docs advise ("Note on SIGPIPE"), and no line: the reader asked for no more (T28-A01)
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())  # so that the interpreter's own flush at exit does not fail again
        return 1
    except OSError as err:  # what no check foresaw (a name too long, a full disk inside a library): one line, not a traceback
        if err.errno in (errno.EMFILE, errno.ENFILE):  # the limit and what to do, not a bare "Too many open files" (T45-A01)
            from ..procs import open_files_line

            print(f"neurohover {args.command}: error: {open_files_line(err, hasattr(args, 'jobs'))}", file=sys.stderr)
            remove_created_dirs()
            return 2
        where = f": {str(err.filename)!r:.120}" if err.filename else ""
        print(f"neurohover {args.command}: error: {shorter_numbers(f'{err.strerror or err}{where}')}", file=sys.stderr)
        remove_created_dirs()
        return 2


def _store_failure(args: argparse.Namespace, err: sqlite3.DatabaseError) -> str:
    """The line for an SQLite error no check foresaw: a write that failed, a file SQLite could not open, or damage."""
    from ..experiments.store_checks import write_failed

    which = f" {str(args.store)!r}" if getattr(args, "store", None) else ""
    if write_failed(err):  # the disk or a file-size limit, not the store (it was called damaged; eighth trial, T32-A04)
        return f"cannot write the results store{which} ({err}); its finished units are kept"
    if getattr(err, "sqlite_errorcode", None) == sqlite3.SQLITE_CANTOPEN:  # a file it could not open, not damage
        from ..procs import cannot_open_line  # a healthy store was called damaged under `ulimit -n 7` (T45-A01)

        return f"the results store{which} {cannot_open_line(str(err)[:60])}"
    return f"the results store{which} cannot be read ({str(err)[:60]}): it is damaged or is no results store"


def _prints_only(args: argparse.Namespace) -> bool:
    """Whether the command ``args`` gives a result on standard output only: no output file of its own, or a --json
    summary asked for beside its files (evolve --json, fly --record F --json exited 0 with the JSON lost; T52-A01)."""
    if args.command in ("demo", "bench", "settings", "wins") or getattr(args, "json", None) is True:
        return True
    only_stdout = {"results": "out", "fly": "record", "evaluate-agent": "json"}
    if args.command in only_stdout:
        return getattr(args, only_stdout[args.command], None) is None
    return args.command == "reproduce" and bool(getattr(args, "list", False))


def _refuse_closed_stdout(args: argparse.Namespace) -> None:
    """Refuse, before any work, a command that prints its result when standard output is closed (``1>&-``: Python's
    sys.stdout is then None; results raised AttributeError, fly and wins lost their output without a word; T28-A01)."""
    if sys.stdout is None and _prints_only(args):
        instead = " (or write them to a file with --out FILE)" if args.command == "results" else ""
        if getattr(args, "json", None) is True and (args.command == "evolve" or getattr(args, "record", None) is not None):
            instead = " (or leave out --json: its files are written without it)"
        raise NeurohoverError(f"standard output is closed: this command prints its results there; run it with standard output open{instead}")


@contextmanager
def _stdout_or_nothing() -> Iterator[None]:
    """Inside this block, a closed standard output (None) is the null device, so that a command writing its files
    prints its notes nowhere instead of failing on them (T28-A01); sys.stdout is None again after it."""
    if sys.stdout is not None:
        yield
        return
    with open(os.devnull, "w", encoding="utf-8") as nothing:
        sys.stdout = nothing
        try:
            yield
        finally:
            sys.stdout = None


class _WholeWrites(io.RawIOBase):
    """Standard output's file descriptor, written whole or not at all: Python's own writer drops the rest of a write
    that a file-size limit (``ulimit -f``) or a full disk cut short, without a word, so that ``results > FILE`` left
    a cut export and status 0 (T32-A05). The first failure is one NeurohoverError (a reader gone away stays the
    BrokenPipeError that ends the command quietly); what is written after it goes nowhere, the error being told."""

    def __init__(self, fd: int) -> None:
        super().__init__()
        self.fd, self.failed = fd, False

    def writable(self) -> bool:
        return True

    def fileno(self) -> int:
        return self.fd

    def isatty(self) -> bool:
        return os.isatty(self.fd)

    def write(self, data) -> int:
        view = memoryview(data).cast("B")
        done = 0
        while done < len(view) and not self.failed:
            try:
                done += os.write(self.fd, view[done:])
            except BrokenPipeError:
                raise
            except OSError as err:
                self.failed = True
                raise NeurohoverError(f"cannot write standard output ({err.strerror}): what the command printed there is cut short") from None
        return len(view)


@contextmanager
def _whole_stdout_writes() -> Iterator[None]:
    """Inside this block, standard output (where it is the process's own file) is written through :class:`_WholeWrites`."""
    old = sys.stdout
    if not isinstance(old, io.TextIOWrapper) or not isinstance(getattr(old.buffer, "raw", old.buffer), io.FileIO):
        yield
        return
    old.flush()
    raw = _WholeWrites(old.fileno())
    layer = raw if isinstance(old.buffer, io.FileIO) else io.BufferedWriter(raw)  # python -u (PYTHONUNBUFFERED): none
    sys.stdout = io.TextIOWrapper(layer, encoding=old.encoding, errors=old.errors, line_buffering=old.line_buffering, write_through=old.write_through)
    try:
        yield
    finally:
        new, sys.stdout = sys.stdout, old
        with contextlib.suppress(Exception):  # a failure was told; a reader gone away is the BrokenPipeError above
            new.flush()
        raw.failed = True  # so that nothing is written again when the wrapper is collected
        new.detach()


def shorter_numbers(message: str) -> str:
    """``message`` with every number of more than 30 digits shown by its first ten and its length (a 400-digit --budget
    was echoed whole; seventh trial), then every other word of more than 200 characters (a path seldom is) by its first 40 and last 20 and
    its length (a 100,000-character name: a settings or agent-setting name, a store's experiment; eleventh trial, U6)."""
    message = re.sub(r"\d(?:,?\d){30,}", lambda m: f"{m[0][:10]}...({len(m[0].replace(',', ''))} digits)", message)  # 1,000,...: too
    return re.sub(r"\S{201,}?(?=[:;,.)]*(?:\s|$))", lambda m: f"{m[0][:40]} ... {m[0][-20:]} ({len(m[0]):,} characters)", message)


if __name__ == "__main__":
    sys.exit(main())
