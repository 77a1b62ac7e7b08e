"""Which neurohover file a path holds, and the names an output may not take.

Internal: neurohover's plumbing, called with values neurohover has checked: its helpers trust their callers and do not
check their own arguments (README, Python API, What is public).

:func:`held_kind` tells a results store, flight data and each kind of JSON or CSV file neurohover writes apart by
their content, so that an output of one kind is never written over a file of another (T25-01 to T25-03, T25-12);
:func:`output_name` and :func:`refuse_suffix` hold the rules of output names (the suffix of the kind written, never an
evolve run's own ``FILE.checkpoint.json`` or ``FILE.history.csv``). :mod:`neurohover.paths` applies them in
:func:`~neurohover.paths.output_file`.
"""

from __future__ import annotations

import json
import os
import re
import sys
from collections.abc import Callable
from pathlib import Path

from .errors import NeurohoverError, brief

__all__ = [
    "CSV_KINDS",
    "FLIGHT_DATA_KIND",
    "JSON_KINDS",
    "NAME_MAX",
    "PNG_KIND",
    "PNG_SIGNATURE",
    "REPORT_HEADER",
    "REPORT_KIND",
    "POLICY_SET_KIND",
    "RUN_FILE_ENDS",
    "SQLITE_HEADER",
    "SQLITE_SIDE_ENDS",
    "SQLITE_SIDE_FILES",
    "STORE_ENDS",
    "UTF8_BOM",
    "fitting_name",
    "held_kind",
    "name_limit",
    "output_name",
    "refuse_policy_set",
    "refuse_long_store_name",
    "refuse_sqlite_side_files",
    "refuse_sqlite_name",
    "refuse_run_file_name",
    "refuse_suffix",
    "refuse_unencodable",
]

SQLITE_HEADER = b"SQLite format 3\x00"  # the first bytes of every SQLite database: a results store
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"  # the first bytes of every PNG file: the only file a figure or plot replaces (T28-A05)
PNG_KIND = "a PNG image"
#: The first line of every ``report.md`` that ``neurohover report`` writes: the only report.md it replaces (T28-A04).
REPORT_HEADER = "# Reproduction report: Koppejan & Whiteson (2011)\n"
REPORT_KIND = "a reproduction report (report.md)"


#: What held_kind calls an evolve run's checkpoint (its format first: told apart at any size).
CHECKPOINT_KIND = "an evolution checkpoint"
#: The neurohover files a JSON output can be told apart by (what it is called -> a test of its parsed JSON object):
#: an output of one kind is not written over a file of another (T25-01 to T25-03: a policy, a checkpoint, a compete
#: summary replaced by rows or a model without a word).
JSON_KINDS: dict[str, Callable[[dict], bool]] = {
    "a policy file": lambda d: {"topology", "genome"} <= d.keys(),
    "a model file": lambda d: str(d.get("format", "")).startswith("neurohover-model/"),
    CHECKPOINT_KIND: lambda d: str(d.get("format", "")).startswith("neurohover-evolution-checkpoint/"),
    "a competition summary (summary.json)": lambda d: {"experiment", "agent", "task", "runs"} <= d.keys(),
    # every manifest build-policies writes (a default build's has no "optimizer"; T29-A04), and the shipped sets'
    "a policy set's manifest": lambda d: {"task", "budget", "seed", "n_steps", "built"} <= d.keys() and "rows" not in d,
    "evaluate-agent rows (--json)": lambda d: {"rows", "n_mdps", "episode_steps"} <= d.keys(),
    "a results export (results --format json)": lambda d: {"experiment", "config_hash", "units"} <= d.keys(),
}
#: The neurohover CSV files an output can be told apart by (what it is called -> the cells its header holds, in any
#: order): a results export over compete's episodes.csv replaced the competition's episodes (T25-12's CSV leftover).
#: Tested against the columns compete (older files too: run, episode, return), evolve and results write.
CSV_KINDS: dict[str, frozenset[str]] = {
    "a competition's episodes (episodes.csv)": frozenset({"run", "episode", "return"}),
    "an evolution history (.history.csv)": frozenset({"generation", "evaluations", "episodes", "champion_return"}),
    "a results export (results --format csv)": frozenset({"experiment", "scale", "key", "kind"}),
}
_STRING = rb'"(?:[^"\\]|\\.)*"'  # a JSON string
#: How the JSON kinds of a size past :data:`_KIND_READ_LIMIT` begin (the keys their writers put first, in order).
_LARGE_JSON_STARTS = {
    CHECKPOINT_KIND: rb'\{\s*"format"\s*:\s*"neurohover-evolution-checkpoint/',
    "a results export (results --format json)": rb'\{\s*"experiment"\s*:\s*' + _STRING + rb'\s*,\s*"scale"\s*:\s*' + _STRING + rb'\s*,\s*"config_hash"\s*:',
}
FLIGHT_DATA_KIND = "flight data (a NumPy archive)"  # what held_kind calls an .npz: FlightData.save writes over no other kind (T34-B03)
POLICY_SET_KIND = "a policy set's manifest"  # what held_kind calls a set's manifest.json: no other writer adds files beside it
UTF8_BOM = b"\xef\xbb\xbf"  # a byte-order mark ("UTF-8 with BOM"): held_kind reads a JSON or CSV file after it, as its readers do
_KIND_READ_LIMIT = 64 * 2**20  # a larger JSON file is no neurohover JSON file told apart here (it is parsed whole)
_END_READ = 2**20  # the bytes read from each end of a file: the kinds other than JSON are told apart by them, whatever its size


def _ends(path: Path) -> tuple[bytes, bytes, int] | None:
    """The first and the last :data:`_END_READ` bytes of the regular file ``path`` (one read where it is no longer) and
    its size; None where it is no such file or cannot be read."""
    try:
        if not path.is_file():
            return None
        with open(path, "rb") as f:
            head = f.read(_END_READ)
            size = max(os.fstat(f.fileno()).st_size, len(head))
            if size <= len(head):
                return head, head, size
            f.seek(max(size - _END_READ, len(head)))
            return head, f.read(_END_READ), size
    except OSError:
        return None


def held_kind(path: str | os.PathLike) -> str | None:
    """What neurohover file the existing regular file ``path`` is, in words (``"a policy file"``), read from its
    content: a results store (SQLite), a PNG image, a report.md of ``neurohover report``, flight data (a NumPy archive),
    one of :data:`JSON_KINDS` or :data:`CSV_KINDS`; None for anything
    else (no such file, unreadable, another file). The one test of "which kind of neurohover file is this" that
    :func:`output_file` refuses to write another kind over. All but a JSON file are told apart by the ends of the file
    (:func:`_ends`), so size does not matter: flight data over 64 MiB was no flight data, and any output replaced it
    without a word (T41-A01); a JSON file is parsed whole, up to :data:`_KIND_READ_LIMIT`."""
    p = Path(path)
    ends = _ends(p)
    if ends is None:
        return None
    head, tail, size = ends
    if head.startswith(SQLITE_HEADER):
        return "a results store (SQLite)"
    if head.startswith(PNG_SIGNATURE):
        return PNG_KIND
    if head.startswith(REPORT_HEADER.encode()):
        return REPORT_KIND
    if head.startswith(b"PK\x03\x04"):  # a zip: a NumPy archive (.npz) holds its arrays as NAME.npy, named in its
        # first member's header (flight data's format comes first) and in the central directory at its end
        return FLIGHT_DATA_KIND if b"format.npy" in head or b"format.npy" in tail else None
    head = head.removeprefix(UTF8_BOM)  # neurohover's readers read a JSON or CSV file after a byte-order mark (T38-B03)
    start = head.lstrip()[:1]
    if start not in (b"{", b""):
        line, newline, _ = head.partition(b"\n")
        if not newline and size > _END_READ:  # a first line longer than every neurohover header
            return None
        header = {c.decode("latin-1") for c in line.rstrip(b"\r").split(b",")}
        return next((kind for kind, cells in CSV_KINDS.items() if cells <= header), None)
    if size > _KIND_READ_LIMIT:  # told apart by how it begins: a checkpoint of a large genome's CMA state, a large
        # experiment's export (a file of no kind is not written over: after T46-B14, T55-A02)
        return next((kind for kind, start in _LARGE_JSON_STARTS.items() if re.match(start, head.lstrip())), None)
    try:
        body = head if size <= _END_READ else p.read_bytes().removeprefix(UTF8_BOM)  # the head is the whole of a small file
        value = json.loads(body)
    except (OSError, ValueError, RecursionError):
        return None
    return next((kind for kind, test in JSON_KINDS.items() if isinstance(value, dict) and test(value)), None)


#: The ends of the names of what ``neurohover evolve --out FILE`` writes beside FILE (end -> what that file is): no other
#: output is written under them (a policy, a model or an export over another run's checkpoint or history; T24-01, T25-03).
RUN_FILE_ENDS = {".checkpoint.json": "checkpoint (which --resume continues)", ".history.csv": "history (one line per new champion or generation)"}


#: The longest name of one file or directory in bytes where the file system cannot say (Linux's NAME_MAX).
NAME_MAX = 255


def refuse_unencodable(text: str, option: str) -> None:
    """Refuse a path ``text`` the file system's encoding cannot encode: a non-ASCII name under an ASCII locale
    (``LC_ALL=C PYTHONUTF8=0``), a lone surrogate under any; each was os.fsencode's UnicodeEncodeError (T31-B03)."""
    try:
        os.fsencode(text)
    except UnicodeEncodeError as err:
        coding = sys.getfilesystemencoding()
        hint = " or run under a UTF-8 locale (LC_ALL=C.UTF-8, or PYTHONUTF8=1)" if coding.lower().replace("-", "") != "utf8" else ""
        raise NeurohoverError(
            f"{option} {brief(text)} is not allowed: the file system's encoding ({coding}) cannot encode the characters "
            f"{ascii(err.object[err.start : err.end])} in it: give a name of characters it can encode{hint}"
        ) from None


def name_limit(path: str | os.PathLike) -> int:
    """The longest name in bytes that the file system holding ``path`` takes (``PC_NAME_MAX`` of its nearest existing
    directory), :data:`NAME_MAX` where it cannot say."""
    try:
        here = Path(os.path.abspath(path))
    except (OSError, ValueError):  # the working directory is gone
        return NAME_MAX
    for directory in (here, *here.parents):
        try:
            if directory.is_dir():
                limit = os.pathconf(directory, "PC_NAME_MAX")
                return limit if limit > 0 else NAME_MAX
        except (OSError, ValueError):  # a part too long itself, no such setting here
            continue
    return NAME_MAX


def fitting_name(name: str, limit: int, room: int = 0) -> str:
    """``name`` with the end of its stem cut (its suffix kept) until it and ``room`` more bytes (the longest end a
    command adds to it) fit ``limit`` bytes: a name suggested in a message is one the command then takes (T29-A01)."""
    suffix = Path(name).suffix
    stem = name[: len(name) - len(suffix)]
    while stem and len(os.fsencode(stem + suffix)) + room > limit:
        stem = stem[:-1]
    return stem + suffix


#: What SQLite and the store's writer lock add to a results store's name for the files they write beside it
#: (``STORE-journal`` the longest, then ``STORE.lock``).
STORE_ENDS = ("-journal", ".lock")
#: The files SQLite keeps beside a store X under X's name and these ends, and the bytes each of its own starts with (a
#: rollback journal's header may be zeroed; -shm is WAL mode's, which neurohover's stores never enter).
SQLITE_SIDE_FILES = {"-journal": (b"\xd9\xd5\x05\xf9\x20\xa1\x63\xd7", bytes(8)), "-wal": (b"\x37\x7f\x06\x82", b"\x37\x7f\x06\x83")}
SQLITE_SIDE_ENDS = (*SQLITE_SIDE_FILES, "-shm")


def refuse_sqlite_name(path: object, option: str) -> None:
    """Refuse a results store ``path`` (``option``) that SQLite reads as no file: ``:memory:`` (a database thrown away
    when the run ends: a whole experiment ran into one and said "finished", T32-A01) and a name beginning ``file:`` (any
    case), a SQLite URI (``file:s03.sqlite`` wrote s03.sqlite, ``file:`` alone a temporary database; T32-A02). The store
    is opened by its absolute path, so such a name would be a file of that name, which is most likely not what was
    meant: given as ``./file:x``, it is that file, and so is a Path object (pathlib has no URIs, and drops the './':
    compete's OUT/results.sqlite under an --out 'file:d' is d's file). What is no path is
    :func:`~neurohover.paths.checked_path`'s."""
    named = os.fspath(path) if isinstance(path, (str, os.PathLike)) else None
    if isinstance(named, str) and named.endswith(SQLITE_SIDE_ENDS):  # SQLite deleted it as X opened (T39-A01)
        end = next(end for end in SQLITE_SIDE_ENDS if named.endswith(end))
        raise NeurohoverError(
            f"{option} {brief(named)} is not allowed: SQLite keeps the {end} file of a store {brief(named[: -len(end)])} under that name, "
            f"and deletes it as that store opens; give a name not ending {', '.join(SQLITE_SIDE_ENDS)}"
        )
    if not isinstance(path, str):
        return
    text = path
    if text == ":memory:":
        raise NeurohoverError(f"{option} {text!r} is not allowed: it is SQLite's in-memory database, lost when the run ends; give a file path")
    if text[:5].lower() == "file:":
        raise NeurohoverError(f"{option} {brief(text)} looks like a SQLite URI: give a file path ({brief('./' + text)} for a file of that name)")


def refuse_sqlite_side_files(store: Path, given: object) -> None:
    """Refuse to open the results store ``store`` (``given``) where a file beside it under a name SQLite keeps for it
    (:data:`SQLITE_SIDE_FILES`) is not SQLite's: as it opened X, SQLite deleted X-journal, another store or a policy
    file so named, without a word (T39-A01); a directory there was the OS's bare "Is a directory" (T39-A03). An empty
    one, or one that starts as SQLite's own do, is SQLite's to roll back or remove."""
    named = f"results store {brief(os.fspath(given)) if isinstance(given, (str, os.PathLike)) else brief(given)}"
    for end, heads in SQLITE_SIDE_FILES.items():
        side = store.with_name(store.name + end)
        where = f"{named}: {brief(str(side))}"
        try:
            is_dir = side.is_dir()
        except OSError:  # a name too long for one beside a store that exists: read only (T31-A03)
            continue
        if is_dir:
            raise NeurohoverError(f"{where} is a directory where SQLite keeps the store's {end} file: remove it, or give the store another name")
        try:
            with open(side, "rb") as f:
                head = f.read(len(heads[0]))
        except OSError:  # none there (or unreadable: SQLite says so)
            continue
        if head and head not in heads:
            held = held_kind(side) or "a file of its own"
            raise NeurohoverError(
                f"{where} is {held}, not SQLite's {end} file of the store, and SQLite would delete it as the store opens: "
                "move it away, or give the store another name"
            )


def refuse_long_store_name(path: object, option: str) -> None:
    """Refuse a results store ``path`` (``option``) to be written whose name, with the longest of :data:`STORE_ENDS`,
    is longer than the file system takes, naming the limit and a name that fits: a name of 249 to 255 bytes was taken,
    and the run then failed on its ``-journal`` with the OS's bare "File name too long", the name cut (T31-A03). What is
    no path to check is :func:`~neurohover.paths.checked_path`'s to refuse. A name SQLite reads as no file is refused
    first (:func:`refuse_sqlite_name`)."""
    refuse_sqlite_name(path, option)
    if not isinstance(path, (str, os.PathLike)) or not isinstance(text := os.fspath(path), str) or "\x00" in text:
        return
    name = Path(text).name
    try:
        size = len(os.fsencode(name))
    except UnicodeError:  # unencodable: refused by name elsewhere
        return
    end = max(STORE_ENDS, key=lambda e: len(os.fsencode(e)))
    room = len(os.fsencode(end))
    limit = name_limit(Path(text).parent) if size + room > 14 else NAME_MAX
    if name and size + room > limit:
        like = str(Path(text).with_name(fitting_name(name, limit, room)))
        raise NeurohoverError(
            f"{option} {brief(text)} is too long: at most {limit} bytes in one file name, with the {end} SQLite writes beside "
            f"the store (here {size:,} + {room} = {size + room:,}); give a shorter name, e.g. {brief(like)}"
        )


def refuse_run_file_name(path: str, option: str) -> None:
    """Refuse a name ``path`` ending (any case) one of :data:`RUN_FILE_ENDS`, naming it as ``option``: the one message
    of every output that may not replace an evolve run's checkpoint or history."""
    end = next((end for end in RUN_FILE_ENDS if path.lower().endswith(end)), None)
    if end is not None:
        raise NeurohoverError(
            f"{option} {brief(path)} is not allowed: evolve --out FILE writes FILE{end} beside FILE as its run's {RUN_FILE_ENDS[end]}; "
            f"give a name not ending {' or '.join(RUN_FILE_ENDS)}"
        )


def output_name(path: object, option: str, suffixes: tuple[str, ...], what: str, run_files: bool = False, ends: tuple[str, ...] = ()) -> None:
    """Refuse a name ``path`` whose suffix (any case) is none of ``suffixes``, naming ``option`` and ``what`` the output
    is ("evaluate-agent's rows are JSON"), and (``run_files``) a name of an evolve run's own files
    (:func:`refuse_run_file_name`); what is no path is :func:`output_file`'s to refuse. evaluate-agent --json f.npz wrote
    JSON over flight data (T25-01), results --out f.npz CSV (T25-02), learn-model --out P.checkpoint.json a model over
    evolve's checkpoint (T25-03); a link of such a name to a file of another suffix, a config, was written through (T30-A04).
    ``ends``: what the command adds to the name for files beside it (:func:`refuse_suffix`)."""
    text = os.fspath(path) if isinstance(path, (str, os.PathLike)) else None
    if not isinstance(text, str) or text in ("", "-") or text.endswith(("/", os.sep)) or Path(text).is_dir():
        return
    if run_files:
        refuse_run_file_name(text, option)
    if suffixes != ("",):
        refuse_suffix(text, option, suffixes, what, f"out{suffixes[0]}", ends)
        target = os.path.realpath(text)  # a link's own name passed, the file written is its target's (T30-A04)
        if os.path.islink(text) and os.path.exists(target) and Path(target).suffix.lower() not in suffixes:
            raise NeurohoverError(
                f"{option} {brief(text)} is a symbolic link to {brief(target)}, a name that is not allowed: {what}; "
                f"give a path ending {' or '.join(suffixes)} that is no link to another kind of file"
            )


def refuse_suffix(path: str, option: str, suffixes: tuple[str, ...], what: str, example: str, ends: tuple[str, ...] = ()) -> None:
    """Refuse a file name ``path`` whose suffix (any case) is none of ``suffixes``, naming it as ``option``, saying
    ``what`` the file is ("a model file is JSON") and the name with the first suffix (``example`` where ``path`` has no
    file name), shortened where it, or it with the longest of ``ends`` (what the command adds to it for the files it
    writes beside it: evolve's :data:`RUN_FILE_ENDS`), would be too long (:func:`fitting_name`): the one message of
    output names (:func:`output_name`), flight data, model and policy files."""
    if Path(path).suffix.lower() not in suffixes:
        name = Path(path).name
        like = str(Path(path).with_suffix(suffixes[0])) if name else example
        if name.lower() in suffixes:  # '.json' is a hidden file without a suffix: out.json, not '.json.csv', was meant
            like = str(Path(path).with_name("out" + name))
        if name:
            room = max((len(os.fsencode(end)) for end in ends), default=0)
            like = str(Path(like).with_name(fitting_name(Path(like).name, name_limit(Path(like).parent), room)))
        if name.lower() in suffixes:  # the name ends in the suffix: say why it is refused (T47-B15)
            raise NeurohoverError(
                f"{option} {brief(path)} is not allowed: {brief(name)} is a hidden file's name with no stem: give a name before the suffix (e.g. {brief(like)})"
            )
        raise NeurohoverError(f"{option} {brief(path)} is not allowed: {what}; give a path ending {' or '.join(suffixes)} (e.g. {brief(like)})")


def refuse_policy_set(directory: Path, option: str, given: str | os.PathLike, link: bool = False) -> None:
    """Refuse to write ``given`` (``option``) into ``directory`` where it holds a policy set's manifest.json: a set holds
    only the files its build wrote, and compete --policy-dir refused a set that compete --out, evaluate-agent --json or
    evolve --out had written into (T29-A06). build-policies writes its sets through a directory of its own. ``link``:
    ``given`` is a symbolic link to a file in ``directory``, which a writer writes through (T42-A04)."""
    manifest = directory / "manifest.json"
    if held_kind(manifest) == POLICY_SET_KIND:
        if link:
            where = f"is a symbolic link to a file in {brief(str(directory))}, which is"
        else:
            where = "is" if Path(given) == directory else f"is in {brief(str(directory))}, which is"
        raise NeurohoverError(
            f"{option} {brief(os.fspath(given))} {where} a policy set's directory (its manifest.json): a set holds only "
            "what build-policies writes (its loader refuses a JSON file no build writes, and leaves other files alone as notes); give another directory"
        )


def refuse_cut_off(path: str | os.PathLike, where: str, kind: str) -> None:
    """Refuse a text file whose last byte is not a newline, as every ``kind`` neurohover writes ends, ``where`` naming
    the file: a file cut inside its last line read ',0.0193' cut to ',0.01' as another number (T31-B07)."""
    with open(path, "rb") as f:
        size = f.seek(0, os.SEEK_END)
        f.seek(max(size - 200, 0))
        tail = f.read()
    if size and not tail.endswith(b"\n"):
        last = tail.rsplit(b"\n", 1)[-1].decode("utf-8", "replace")
        raise NeurohoverError(f"{where} does not end with a newline, as every {kind} does: it looks cut off (its last line {brief(last)}); give the whole file")
