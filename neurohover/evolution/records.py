"""What an evolution run reports and saves: results, history, progress, history CSV, checkpoint files."""

from __future__ import annotations

import csv
import dataclasses
import io
import json
import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import NeurohoverError, brief, first_difference
from ..filekinds import CSV_KINDS, JSON_KINDS, held_kind, refuse_cut_off
from ..jsontext import JSONError, number_text, strict_json
from ..paths import input_file, output_file, refuse_special_file, writer_file, writing
from ..policies import Policy
from .common import EntryError, enc_float, read_count, read_return, read_seconds
from .state_codec import check_stream

__all__ = [
    "CHECKPOINT_FORMAT",
    "CHECKPOINT_KIND",
    "HISTORY_KIND",
    "HISTORY_COLUMNS",
    "EvolutionInterrupted",
    "EvolutionResult",
    "HistoryRecord",
    "ProgressInfo",
    "check_history",
    "check_stream",
    "config_difference",
    "decode_history",
    "encode_history",
    "read_checkpoint",
    "read_history_csv",
    "refuse_replaced",
    "write_checkpoint",
    "write_history_csv",
]

#: The ``format`` entry of a checkpoint file.
CHECKPOINT_FORMAT = "neurohover-evolution-checkpoint/1"
#: What a checkpoint and a history CSV are called among the kinds of file :func:`~neurohover.filekinds.held_kind` tells
#: apart: each writer replaces only a file of its own kind (a checkpoint or a history over a model or policy; T28-B07).
CHECKPOINT_KIND, HISTORY_KIND = "an evolution checkpoint", "an evolution history (.history.csv)"
assert CHECKPOINT_KIND in JSON_KINDS and HISTORY_KIND in CSV_KINDS


@dataclass(frozen=True)
class HistoryRecord:
    """One line of a run's history.

    Steady state (and CMA-ES on an MDP): one record per new champion, plus the last generation.
    Generational (and CMA-ES on a family): one record per generation.

    Attributes
    ----------
    generation : int
        Generations completed (steady state: one per offspring batch; the initial population is 1).
    evaluations : int
        Candidate fitness estimates made so far.
    episodes : int
        Episodes flown so far (the budget's unit).
    generation_episodes : int
        Episodes flown in this generation (a race's ``episodes_spent``; ``pop_size * K`` for fixed
        resampling).
    champion_return : float
        The champion's fitness (steady state: best ever; generational: best estimate of this generation).
    wall_seconds : float
        Seconds since the start of the run (continued across resumes).
    """

    generation: int
    evaluations: int
    episodes: int
    generation_episodes: int
    champion_return: float
    wall_seconds: float = field(compare=False)  # wall-clock: two equal runs compare equal


#: Columns of a history CSV file, in order (the fields of :class:`HistoryRecord`).
HISTORY_COLUMNS = tuple(f.name for f in dataclasses.fields(HistoryRecord))


@dataclass(frozen=True)
class ProgressInfo:
    """What the ``progress`` callback sees (at most every ``progress_every_s``, and once at the end)."""

    generation: int
    evaluations: int
    episodes: int
    budget: int | None
    champion_return: float
    wall_seconds: float
    episodes_per_second: float
    done: bool


@dataclass(frozen=True)
class EvolutionResult:
    """Outcome of :func:`~neurohover.evolution.evolve.evolve`.

    Attributes
    ----------
    champion : Policy
        The champion, with metadata (method, optimizer, resampling, target, seed, budget, ...).
    champion_return : float
        Its fitness (see :mod:`neurohover.evolution.evolve` for which candidate is the champion).
    history : tuple of HistoryRecord
    episodes, steps : int
        Episodes and control steps flown.
    evaluations, generations : int
    seconds : float
        Wall time of the run (continued across resumes).
    kernel_seconds : float
        Of which inside the simulation kernel.
    stop_reason : str
        ``budget``, ``plateau`` (steady state), ``generations`` (generational), ``cma-stop``.
    settings : dict
        Everything that defines the run (JSON-able): target, method, optimizer, resampling,
        optimiser settings, topology, seed, n_steps, budget.
    champion_crashed : bool
        Steady state: whether the champion's evaluation crashed (False for the other methods).
    parents : np.ndarray or None
        Generational NE: the last generation's selected parents, one genome a row (the candidates
        :func:`~neurohover.evolution.evolve.reevaluated_champion` chooses from); None otherwise.
    hall_of_fame : np.ndarray or None
        Generational NE: the run's best generation champions by estimate, best first (the other candidates
        it chooses from, ``among="best-ever"``); None otherwise.
    """

    champion: Policy
    champion_return: float
    history: tuple[HistoryRecord, ...]
    episodes: int
    steps: int
    evaluations: int
    generations: int
    seconds: float = field(compare=False)  # wall-clock, not part of ==
    kernel_seconds: float = field(compare=False)
    stop_reason: str
    settings: dict
    champion_crashed: bool = False
    parents: np.ndarray | None = field(default=None, compare=False, repr=False)
    hall_of_fame: np.ndarray | None = field(default=None, compare=False, repr=False)

    @property
    def episodes_per_second(self) -> float:
        return self.episodes / self.seconds if self.seconds > 0 else math.inf


class EvolutionInterrupted(KeyboardInterrupt):
    """The run was interrupted; ``checkpoint`` is where its state was saved (None: not saved). ``result`` is the
    finished run's :class:`EvolutionResult` where the interrupt came from the last ``progress`` call (``done``: the
    run had ended; it escaped as a bare KeyboardInterrupt and the result was lost, T28-B08), else None."""

    def __init__(self, checkpoint: Path | None, episodes: int, result: EvolutionResult | None = None) -> None:
        ended = "evolution ended, interrupted in its last progress call," if result is not None else "evolution interrupted"
        super().__init__(f"{ended} after {episodes} episodes" + (f"; checkpoint saved to {checkpoint}" if checkpoint else ""))
        self.checkpoint = checkpoint
        self.episodes = episodes
        self.result = result


# --------------------------------------------------------------------------------- history CSV


def write_history_csv(history, path: str | Path) -> Path:
    """Write history records as CSV with the header :data:`HISTORY_COLUMNS`.

    ``champion_return`` is written exactly (``repr``), ``wall_seconds`` to 0.1 ms. A record a run never keeps (a NaN
    return, a negative count; :data:`_HISTORY_READERS`) is refused by name, and ``path`` must end .csv and hold no
    neurohover file of another kind (a policy or flight data was replaced; T28-B07, T28-B13): nothing is written then.
    """
    rows = [[h.generation, h.evaluations, h.episodes, h.generation_episodes, h.champion_return, h.wall_seconds] for h in history]
    for n, row in enumerate(rows):
        for column, read, value in zip(HISTORY_COLUMNS, _HISTORY_READERS, row):
            try:
                read(value)
            except ValueError as err:
                raise NeurohoverError(f"history record {n} (from 0): {column}={brief(value)} is not allowed ({err}); nothing is written") from None
    path = output_file(path, "history file", kind=HISTORY_KIND, suffixes=(".csv",), what="a history is CSV")
    with writing(path, "history file") as partial, open(partial, "w", newline="", encoding="utf-8") as f:
        writer = csv.writer(f, lineterminator="\n")
        writer.writerow(HISTORY_COLUMNS)
        writer.writerows([*row[:4], repr(float(row[4])), f"{row[5]:.4f}"] for row in rows)
    return path


def read_history_csv(path: str | Path) -> list[HistoryRecord]:
    """Read a file written by :func:`write_history_csv`.

    Raises
    ------
    NeurohoverError
        If the file does not start with the header :data:`HISTORY_COLUMNS`, or a row is not one record as
        :func:`write_history_csv` writes it: each number in ASCII digits (:func:`~neurohover.jsontext.number_text`), counts
        >= 0, a champion's fitness finite or '-inf' (on the run's scale: 1/ln(error) is > 0), seconds finite and >= 0, and the rows as a run records them
        (:func:`check_history`; wall seconds never falling). int() and float() took 'nan', '1_0', other scripts' digits
        and falling counts (T28-B13). The file ends with a newline, as written: a file cut inside its last number read as
        another number (T31-B07).
    """
    input_file(path, "history file")  # a path the file system cannot encode was a UnicodeEncodeError (T31-B03)
    try:  # utf-8-sig: a byte-order mark (a spreadsheet's "UTF-8 with BOM") hid the header (T30-B05)
        with open(path, newline="", encoding="utf-8-sig") as f:
            text = f.read()
    except UnicodeDecodeError as err:
        raise NeurohoverError(f"{str(path)!r} is not an evolution history: it is not UTF-8 text (byte {err.start})") from None
    rows = [row for row in csv.reader(io.StringIO(text, newline="")) if row]
    if not rows or tuple(rows[0]) != HISTORY_COLUMNS:
        raise NeurohoverError(f"{str(path)!r} is not an evolution history (expected the header {','.join(HISTORY_COLUMNS)})")
    refuse_cut_off(path, repr(str(path)), "history neurohover writes")  # ',0.0193' cut to ',0.01' was read as 0.01
    out: list[HistoryRecord] = []
    for n, row in enumerate(rows[1:], start=2):
        if len(row) != len(HISTORY_COLUMNS):
            raise NeurohoverError(f"{str(path)!r}, row {n}: {brief(','.join(row))} is not a history record ({','.join(HISTORY_COLUMNS)})")
        cells: list = []
        for column, read, text in zip(HISTORY_COLUMNS, _HISTORY_READERS, row):
            try:
                number = number_text(text, whole=read is read_count)
            except ValueError as err:
                raise NeurohoverError(f"{str(path)!r}, row {n}: {column} {err}") from None
            try:
                cells.append(read(number))
                if column == "wall_seconds" and out and cells[-1] < out[-1].wall_seconds:
                    raise ValueError(f"below row {n - 1}'s {out[-1].wall_seconds:g}: a run's seconds never fall")
            except ValueError as err:
                raise NeurohoverError(f"{str(path)!r}, row {n}: {column} {brief(text)} is not allowed ({err})") from None
        out.append(HistoryRecord(*cells))
    try:
        check_history(out, {c: getattr(out[-1], c) for c in ("generation", "evaluations", "episodes")} if out else {}, per_generation=False)
    except EntryError as err:
        raise NeurohoverError(f"{str(path)!r}: {err} (row 0 is the file's row 2)") from None
    return out


# --------------------------------------------------------------------------------- checkpoints


def encode_history(history) -> list[list]:
    """History records as a checkpoint holds them: strict-JSON lists in :data:`HISTORY_COLUMNS` order."""
    return [[h.generation, h.evaluations, h.episodes, h.generation_episodes, enc_float(h.champion_return), h.wall_seconds] for h in history]


#: How each cell of a checkpoint's history row is read back, in :data:`HISTORY_COLUMNS` order: a champion's return is
#: finite or '-inf' (no champion yet), as the run records it ('nan' was resumed and written to history.csv; T20-01).
_HISTORY_READERS = (read_count, read_count, read_count, read_count, read_return, read_seconds)


def decode_history(rows) -> list[HistoryRecord]:
    """The records :func:`encode_history` encoded; an :class:`~neurohover.evolution.common.EntryError` naming the row,
    its column and value for a damaged one (a bare "too many values to unpack" named neither; T18-6)."""
    if not isinstance(rows, list):
        raise EntryError(f"history is {brief(rows)}: allowed a list of rows of {', '.join(HISTORY_COLUMNS)}")
    records = []
    for n, row in enumerate(rows):
        if not isinstance(row, list) or len(row) != len(HISTORY_COLUMNS):
            raise EntryError(f"history row {n} (from 0) is {brief(row)}: allowed a list of {len(HISTORY_COLUMNS)} values, {', '.join(HISTORY_COLUMNS)}")
        cells: list = []
        for column, read, value in zip(HISTORY_COLUMNS, _HISTORY_READERS, row):
            try:  # each count and number checked: True was read as 1 and '1.5' as 1.5 (sixteenth trial)
                cells.append(read(value))
            except (TypeError, ValueError) as err:
                raise EntryError(f"history row {n} (from 0): {column}={brief(value)} is not allowed ({err})") from None
        records.append(HistoryRecord(*cells))
    return records


def write_checkpoint(path: Path, state: dict) -> None:
    """Write a checkpoint atomically: strict JSON to ``PATH.PID.TID.tmp``, synced, then renamed over ``path``."""
    path = Path(os.path.realpath(path))  # through a symbolic link: its file is written, the link kept (ninth trial)
    tmp = writer_file(path, ".tmp")  # one per process (tenth trial) and thread (T32-B01); cut where too long (T29-A01)
    path.parent.mkdir(parents=True, exist_ok=True)
    try:
        with open(tmp, "w", encoding="utf-8") as f:
            json.dump(state, f, allow_nan=False)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException as err:  # interrupted or failed mid-write: no truncated temporary file is left (the last checkpoint stands)
        tmp.unlink(missing_ok=True)
        if isinstance(err, OSError):  # a full disk said only "No space left on device" (seventh trial)
            why = err.strerror or err
            raise NeurohoverError(f"checkpoint {str(path)!r}: cannot write it ({why}); no partial file is left (nor changed an earlier checkpoint)") from None
        raise


def refuse_replaced(path: Path, state: dict) -> None:
    """Refuse to write a run's checkpoint over ``path`` once it holds a file neurohover did not write there as a
    checkpoint (as :func:`~neurohover.evolution.evolve` refuses one given up front): a policy file a progress callback
    saved there mid-run was replaced by the next checkpoint without a word (T47-B13). The run is kept: ``state`` is
    written beside it, as NAME.checkpoint.json, which the message names (resume from it)."""
    real = Path(os.path.realpath(path))
    if not real.is_file() or not real.stat().st_size or (held := held_kind(real)) == CHECKPOINT_KIND:
        return
    said = f"checkpoint {str(path)!r} now holds {held or 'a file neurohover did not write'}, written there during the run, and was left as it is"
    beside = real.with_name(f"{real.stem}.checkpoint.json")
    if beside.is_file() and beside.stat().st_size and held_kind(beside) != CHECKPOINT_KIND:
        raise NeurohoverError(f"{said}; {str(beside)!r} is not a checkpoint either, so the run's checkpoint was not written: the run stops")
    write_checkpoint(beside, state)
    raise NeurohoverError(f"{said}; the run's checkpoint was written to {str(beside)!r} instead (resume=True with that path goes on): the run stops")


def check_resumed_checkpoint(path: Path) -> None:
    """Refuse a checkpoint to resume from that is there but no regular file as a run without resume does: a directory
    or a pipe was said not to exist (T46-B13)."""
    if path.is_dir():
        raise NeurohoverError(f"checkpoint {str(path)!r} is a directory; give a file path")
    refuse_special_file(path, "checkpoint")


def read_checkpoint(path: Path) -> dict:
    """The JSON a checkpoint file holds (NeurohoverError if it is missing, no regular file or not JSON)."""
    check_resumed_checkpoint(path)
    if not path.is_file():
        raise NeurohoverError(f"no checkpoint to resume from: {str(path)!r} does not exist")
    try:  # strictly: nested thousands deep (eighth trial), an integer of 5,000 digits (ninth trial), a key twice
        return strict_json(path.read_bytes())
    except JSONError as err:
        raise NeurohoverError(
            f"checkpoint {str(path)!r} is not a checkpoint: {err}" if err.deep else f"checkpoint {str(path)!r} is not valid JSON: {err}"
        ) from None


def check_history(records: list[HistoryRecord], counts: dict[str, int], per_generation: bool, champion: float | None = None) -> None:
    """EntryError unless ``records`` can be the history of a run at checkpoint counters ``counts``: generations rising
    from 1, evaluations and episodes never falling nor past the counters nor below a row's generations and evaluations,
    and, where the run records every generation (``per_generation``), one row each (a history of three copies of its
    one row was resumed and written out; T19-08). Where ``champion`` (the run's champion's return) is given, the last
    row holds it: every run records a row when its champion changes (the others each generation), so only a run
    without a champion ('-inf') has no row (an empty history beside a champion was resumed without its rows; T22-11)."""
    last = None
    for n, h in enumerate(records):
        if h.generation < 1 or (last is not None and h.generation <= last.generation):
            after = "generations start at 1" if last is None else f"after row {n - 1}'s generation {last.generation:,}: generations rise row by row"
            raise EntryError(f"history row {n} (from 0): generation={h.generation:,} is not allowed ({after})")
        for column in ("evaluations", "episodes"):
            if last is not None and getattr(h, column) < getattr(last, column):
                raise EntryError(f"history row {n} (from 0): {column}={getattr(h, column):,} is not allowed (below row {n - 1}'s {getattr(last, column):,})")
        if h.generation_episodes > h.episodes:
            raise EntryError(f"history row {n} (from 0): generation_episodes={h.generation_episodes:,} is not allowed (more than its {h.episodes:,} episodes)")
        for column, v, bound, why in (  # as the counters (evolution.restore): a row holds them as they were (T21-03)
            ("evaluations", h.evaluations, h.generation, f"below its {h.generation:,} generations: each evaluates a candidate"),
            ("episodes", h.episodes, h.evaluations, f"below its {h.evaluations:,} evaluations: each flies an episode or more"),
        ):
            if v < bound:
                raise EntryError(f"history row {n} (from 0): {column}={v:,} is not allowed ({why})")
        last = h
    if last is not None:
        for column in ("generation", "evaluations", "episodes"):
            if getattr(last, column) > counts[column]:
                raise EntryError(f"history's last row has {column}={getattr(last, column):,}, past the checkpoint's {column} counter {counts[column]:,}")
    if per_generation and len(records) != counts["generation"]:
        raise EntryError(f"history has {len(records):,} rows for {counts['generation']:,} generations: this run records every generation, one row each")
    if champion is not None and (last.champion_return if last is not None else -math.inf) != champion:
        held = "it has no rows" if last is None else f"its last row's champion_return is {enc_float(last.champion_return)!r}"
        raise EntryError(
            f"history is not the champion's: {held} where the run's champion (at generation {counts['generation']:,}) has return"
            f" {enc_float(champion)!r}; a run records a row whenever its champion changes, so its last row holds the champion's return"
        )


def _same(saved: Any, given: Any) -> bool:
    """Whether a checkpoint's config value ``saved`` is the run's ``given`` one, a bool never a number: True == 1 took
    crossover_prob=true for 1.0 (T19-08)."""
    if isinstance(saved, dict) and isinstance(given, dict):
        return saved.keys() == given.keys() and all(_same(saved[k], given[k]) for k in saved)
    if isinstance(saved, (list, tuple)) and isinstance(given, (list, tuple)):
        return len(saved) == len(given) and all(_same(a, b) for a, b in zip(saved, given))
    if isinstance(saved, (dict, list, tuple)) or isinstance(given, (dict, list, tuple)):
        return False
    return isinstance(saved, (bool, np.bool_)) == isinstance(given, (bool, np.bool_)) and bool(saved == given)


def config_difference(path: str, saved: Any, given: Any) -> str | None:
    """Where a checkpoint's config value ``saved`` (at ``path``) differs from the ``given`` one of the run resuming it
    (:func:`_same`): the message part that names both, or None where they agree. A table's first differing key (an MDP's
    label says what its other fields would), but every differing key of a settings table (one a try took three runs
    to learn three; T37-A04)."""
    if isinstance(saved, dict) and isinstance(given, dict):
        found = [d for key in sorted(set(saved) | set(given), key=str) if (d := config_difference(f"{path}.{key}", saved.get(key), given.get(key)))]
        return ("; ".join(found) if path.endswith("settings") else found[0]) if found else None
    return None if _same(saved, given) else first_difference(path, saved, given, "the checkpoint's")
