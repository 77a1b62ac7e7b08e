"""Reading ``neurohover compete --out DIR`` directories: ``episodes.csv`` and ``summary.json``, each checked against what compete writes and against
each other (:func:`read_compete_dir`, :func:`read_compete_dirs`), as ``neurohover plot --compete`` (:func:`neurohover.plots.plot_compete`) reads them.

A row is checked as it is read (a value compete never writes: a flag other than 0 or 1, a column it never writes, a run on two MDPs); a summary in one
place, :func:`_check_summary`, against itself and its rows: each key compete writes for its kind and range (:data:`SUMMARY_FIELDS`), each figure
against the one its rows give, the conditions its task can fly under, the MDPs its runs fly and the rows its agent writes. A key compete never writes
is refused, not ignored (a misspelt one would leave a curve unlabelled without a word); one compete writes may be absent (older summaries hold fewer),
as may the columns after run, episode and return in older episodes files; the offline_seconds column of files written before a8bc471 is read as that
older layout (:data:`OLDER_COLUMNS`).

Example
-------
>>> from neurohover.compete_files import read_compete_dir
>>> result = read_compete_dir("out/")  # doctest: +SKIP
>>> result.label, result.returns.shape  # doctest: +SKIP
('baseline (ghh08)', (2, 3))
"""

from __future__ import annotations

import csv
import math
import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import NoReturn

import numpy as np

from .compete_labels import COMPETE_SCALE, NO_OFFLINE, NO_SAFEGUARD, policy_label_problem
from .errors import NeurohoverError, brief, finite_real, whole_number
from .filekinds import refuse_cut_off
from .flightmeta import compared_by_value
from .jsontext import number_text, strict_json
from .paths import input_dir, refuse_special_file
from .sim.constants import CRASH_STEP_PENALTY, MAX_EPISODE_STEPS, MAX_SECONDS, WORST_RETURN, crash_charge, crash_return_ceiling, lowest_return, seconds_allowed
from .sim.rng import MAX_SEED
from .tasks import N_TEST, N_TRAINING, set_name

__all__ = [
    "COMPETE_COLUMNS",
    "COMPETE_CONDITIONS",
    "COMPETE_FILE",
    "COMPETE_SUMMARY",
    "CSV_COLUMNS",
    "SUMMARY_FIELDS",
    "CompeteResult",
    "read_compete_dir",
    "read_compete_dirs",
]

COMPETE_FILE = "episodes.csv"
COMPETE_SUMMARY = "summary.json"
COMPETE_CONDITIONS = ("episode_steps", "sigma", "sensor", "drift")  # summary.json keys: curves that differ in one are labelled with it
COMPETE_COLUMNS = ("run", "episode", "return")  # the columns of compete's episodes.csv read here
#: Every column compete writes to episodes.csv (compete.CSV_COLUMNS is this); older files hold fewer, none holds others (T23-07).
CSV_COLUMNS = ("run", "mdp", "episode", "return", "crashed", "steps", "policy", "safeguard_fired")
#: The columns of an older layout, read and ignored: offline_seconds, each episode's, last in the files compete wrote
#: before a8bc471 (2026-11-27; summary.json's mean_offline_seconds_per_run holds it now; T37-A03).
OLDER_COLUMNS = ("offline_seconds",)
#: The MDP sets a summary's mdps names, as its rows' labels name them (TaskFamily.set_name: seeded-test at FGHH sigma 0.2).
MDP_SETS, SETS_TEXT = ("test", "train", "seeded-test", "seeded-train", "sample"), "test, train, seeded-test, seeded-train or sample"


def _real_in(low: float, high: float) -> Callable[[object], bool]:
    return lambda value: finite_real(value) and low <= value <= high  # type: ignore[operator]


_SECONDS = (_real_in(0.0, math.inf), "a finite number of seconds >= 0")  # at most MAX_SECONDS: _check_seconds
#: Every key compete writes to summary.json, in order, with its check and what it allows (None: checked against the
#: rows, or as a condition, by the checks that say so); a key compete never writes is refused (T23-06).
SUMMARY_FIELDS: dict[str, tuple[Callable[[object], bool] | None, str]] = {
    "task": (None, "a task's name"),
    "agent": (lambda v: isinstance(v, str) and v != "", "an agent's name"),
    "mdps": (lambda v: v in MDP_SETS, f"{SETS_TEXT} (the MDP set)"),
    "seed": (lambda v: whole_number(v) and 0 <= v <= MAX_SEED, "an integer in 0..2**63-1"),
    "store": (lambda v: isinstance(v, str) and v != "", "the results store's path"),
    "episode_steps": (None, "a number of control steps"),
    "sigma": (None, "a family's breadth"),
    "sensor": (None, "a sensor's settings"),
    "drift": (None, "a drift's settings"),
    "experiment": (lambda v: isinstance(v, str) and v.startswith("compete-"), "compete-TASK-AGENT"),
    "scale": (lambda v: isinstance(v, str) and COMPETE_SCALE.fullmatch(v) is not None, "settings- and 10 hex digits (a digest of the settings)"),
    "runs": (lambda v: whole_number(v) and v >= 1, "an integer >= 1"),
    "episodes": (lambda v: whole_number(v) and v >= 1, "an integer >= 1"),
    "mean_cumulative_return": (_real_in(-math.inf, 0.0), "a finite number <= 0 (every reward is minus a sum of squares)"),
    "sd_cumulative_return": (_real_in(0.0, math.inf), "a finite number >= 0"),
    "crash_rate_runs": (_real_in(0.0, 1.0), "a share in [0, 1]"),
    "crashes_per_episode": (_real_in(0.0, 1.0), "a share in [0, 1]"),
    "mean_return_after_learning": (_real_in(-WORST_RETURN, 0.0), f"an episode's mean return, in [{-WORST_RETURN:.3g}, 0]"),
    "mean_seconds_per_run": _SECONDS,
    "mean_offline_seconds_per_run": _SECONDS,
}


@compared_by_value  # == by value: arrays whole (T46-B08)
@dataclass(frozen=True, eq=False)
class CompeteResult:
    """The returns of one ``neurohover compete --out DIR``.

    Attributes
    ----------
    label : str
        Legend label: agent and task from ``summary.json`` (else the directory's name).
    returns : (runs, episodes) array
        Return of each episode of each run (runs cut to the shortest, should they differ).
    crashes : int
        Crashed episodes over all runs (the ``crashed`` column, where present).
    path : Path
        The directory.
    conditions : dict
        What its episodes were flown under, from ``summary.json`` (:data:`COMPETE_CONDITIONS`; empty without one).
    """

    label: str
    returns: np.ndarray
    crashes: int
    path: Path
    conditions: dict = field(default_factory=dict)

    @property
    def cumulative_error(self) -> np.ndarray:
        """Mean over runs of the cumulative error (minus the cumulative return) after each episode."""
        return -np.cumsum(self.returns, axis=1).mean(axis=0)


@dataclass
class _Rows:
    """What the summary check compares of an episodes.csv, kept small (a file may hold 10**8 rows): the line each MDP
    label, each (crashed, steps) and each policy label first appears on, the crashes and the runs with one, the first
    line whose safeguard fired, and the mean return after learning where the policy column gives it."""

    mdps: dict[str, int] = field(default_factory=dict)
    steps: dict[tuple[bool, int], int] = field(default_factory=dict)
    crashes: int = 0
    crashed_runs: set[int] = field(default_factory=set)
    has_crashed: bool = False
    run_lines: dict[int, int] = field(default_factory=dict)
    run_mdps: dict[int, tuple[str, int]] = field(default_factory=dict)
    policies: dict[str, int] = field(default_factory=dict)
    fired_line: int | None = None
    split_run: str | None = None  # the refusal of the first row of a run on a second MDP, said once the labels are checked
    after_learning: float | None = None
    least_charged: tuple[float, int, float, int] | None = None  # the crashed row nearest its charge: return / P - steps, line, return, steps
    lowest: tuple[float, int] | None = None  # the lowest return and its line


def _check_row(where: str, row: dict, crashed: int, steps: int | None) -> None:
    """Refuse a row's values compete never writes, naming ``where`` (the file and line) and the value: a crashed or
    safeguard_fired flag other than 0 or 1 (crashed -1 was counted as -1 crashes, T22-03; safeguard_fired 7 and steps
    -5 were taken, T22-04), steps not in 1..MAX_EPISODE_STEPS."""
    for name, value, meaning in (
        ("crashed", crashed, "the episode crashed"),
        ("safeguard_fired", row.get("safeguard_fired") or "0", "the safeguard took over"),
    ):
        if value not in (0, 1, "0", "1"):
            raise NeurohoverError(f"{where}: {name} {brief(row[name])} is not allowed: 0 or 1 (whether {meaning})")
    if steps is not None and not 1 <= steps <= MAX_EPISODE_STEPS:
        raise NeurohoverError(f"{where}: steps {brief(row['steps'])} is not allowed: an episode's steps, an integer in 1..{MAX_EPISODE_STEPS:,}")


def _after_learning_start(labels: list[str]) -> int:
    """The first episode from which a run's policy no longer changes: agents.protocol.after_learning_start, which
    compete's summary takes (this layer may not import the agents)."""
    start = len(labels) - 1
    while start > 0 and labels[start - 1] == labels[-1]:
        start -= 1
    return start


def _row_numbers(where: str, row: dict[str, str]) -> tuple:
    """A row's run, episode, return, crashed (0 where absent, as in older files) and steps (None where absent), each
    written as compete writes it (:func:`~neurohover.jsontext.number_text`): int() and float() took '0_0', '\u0660' and
    full-width digits (T28-B12); steps '20.0' was "must be numbers"."""
    cells: list[int | float | None] = []
    for column in ("run", "episode", "return", "crashed", "steps"):
        text = row.get(column)
        if not text and column in ("crashed", "steps"):  # absent from older files
            cells.append(0 if column == "crashed" else None)
            continue
        try:
            cells.append(number_text(text or "", whole=column != "return"))
        except ValueError as err:
            raise NeurohoverError(f"{where}: {column} {err}") from None
    return tuple(cells)


def _read_rows(csv_path: Path) -> tuple[dict[int, list[tuple[int, float, str]]], dict[int, set[int]], _Rows]:
    """Each run's (episode, return, policy) rows of the episodes file ``csv_path``, each run's episode numbers, and the
    facts the summary check compares; a row compete never writes refused, naming the line."""
    runs: dict[int, list[tuple[int, float, str]]] = {}
    seen: dict[int, set[int]] = {}  # each run's episode numbers so far
    facts = _Rows()
    labels: dict[str, str] = {}  # one string per policy label (a file may hold 10**8 rows)
    try:
        with open(csv_path, newline="", encoding="utf-8-sig") as f:
            reader = csv.DictReader(f)
            columns = list(reader.fieldnames or [])
            missing = [c for c in COMPETE_COLUMNS if c not in columns]
            if missing:
                raise NeurohoverError(f"--compete {str(csv_path)!r} is not a compete episodes file: no column {', '.join(missing)}")
            odd = next((c for c in columns if c not in CSV_COLUMNS + OLDER_COLUMNS or columns.count(c) > 1), None)
            if odd is not None:  # T23-07: an extra column was ignored without a word
                raise NeurohoverError(
                    f"--compete {str(csv_path)!r}, line 1: column {brief(odd)} is not allowed: compete writes the columns {', '.join(CSV_COLUMNS)}, "
                    f"each once (older versions also {', '.join(OLDER_COLUMNS)})"
                )
            refuse_cut_off(csv_path, f"--compete {str(csv_path)!r}", "episodes file compete writes")  # a cut '-123.45' read as -123.4
            facts.has_crashed = "crashed" in columns
            for line, row in enumerate(reader, start=2):
                where = f"--compete {str(csv_path)!r}, line {line}"
                if None in row or None in row.values():  # T23-07: values past the header's columns were ignored
                    count = len(columns) + len(row.get(None) or ()) - sum(v is None for k, v in row.items() if k is not None)
                    raise NeurohoverError(f"{where}: it holds {count} values where the header names {len(columns)} columns: give one value per column")
                run, episode, ret, crashed, steps = _row_numbers(where, row)
                _check_row(where, row, crashed, steps)
                if not (math.isfinite(ret) and -WORST_RETURN <= ret <= 0):  # -1e308 overflowed the plot (eighth trial); every reward is <= 0 (ninth)
                    raise NeurohoverError(
                        f"{where}: return {row['return']!r:.30} is not an episode's "
                        f"(finite, in [{-WORST_RETURN:.3g}, 0]: every reward is minus a sum of squares)"
                    )
                if run < 0 or episode < 0 or episode in seen.setdefault(run, set()):  # plotted without a word (fifth trial)
                    raise NeurohoverError(
                        f"{where}: run {run}, episode {episode} is negative or given twice: each run's episodes are numbered once each from 0"
                    )
                mdp = row.get("mdp") or ""
                first = facts.run_mdps.setdefault(run, (mdp, line))
                if first[0] != mdp and facts.split_run is None:  # T23-07: one run on two MDPs was plotted as one run
                    facts.split_run = f"{where}: mdp {brief(mdp)} is not allowed: run {run} flies {brief(first[0])} (line {first[1]}), and a run flies one MDP"
                policy = labels.setdefault(row.get("policy") or "", row.get("policy") or "")
                seen[run].add(episode)
                facts.run_lines.setdefault(run, line)
                runs.setdefault(run, []).append((episode, ret, policy))
                facts.crashes += crashed
                if facts.lowest is None or ret < facts.lowest[0]:
                    facts.lowest = (ret, line)
                facts.mdps.setdefault(mdp, line)
                facts.policies.setdefault(policy, line)
                if facts.fired_line is None and row.get("safeguard_fired") == "1":
                    facts.fired_line = line
                if crashed:
                    facts.crashed_runs.add(run)
                if steps is not None:
                    facts.steps.setdefault((bool(crashed), steps), line)
                    if crashed and (facts.least_charged is None or ret / CRASH_STEP_PENALTY - steps > facts.least_charged[0]):
                        facts.least_charged = (ret / CRASH_STEP_PENALTY - steps, line, ret, steps)
    except (OSError, UnicodeDecodeError, csv.Error) as err:
        raise NeurohoverError(f"--compete {str(csv_path)!r}: cannot read it ({err})") from None
    return runs, seen, facts


def read_compete_dir(path: str | Path) -> CompeteResult:
    """Read ``episodes.csv`` (and ``summary.json``, for the label) of a compete output directory.

    Raises
    ------
    NeurohoverError
        If ``path`` is no directory, or it has no ``episodes.csv`` or not one compete wrote, or a ``summary.json`` that
        compete never writes or that contradicts it (:func:`_check_summary`).
    """
    path = input_dir(path, "--compete")  # None or 5 was pathlib's TypeError (eleventh trial)
    csv_path, summary_path = path / COMPETE_FILE, path / COMPETE_SUMMARY
    for held in (csv_path, summary_path):  # a FIFO summary.json hung plot --compete for ever (T28-A08)
        refuse_special_file(held, "--compete", instead="give directories written by neurohover compete --out")
    if not csv_path.is_file():
        raise NeurohoverError(f"--compete {str(path)!r} holds no {COMPETE_FILE}: give directories written by neurohover compete --out")
    runs, seen, facts = _read_rows(csv_path)
    if not runs:
        raise NeurohoverError(f"--compete {str(csv_path)!r} holds no episodes")
    absent = next((r for r in range(len(runs)) if r not in runs), None)  # run 10**30 was plotted as a second run (T22-04)
    if absent is not None:
        odd = max(runs)
        raise NeurohoverError(
            f"--compete {str(csv_path)!r}, line {facts.run_lines[odd]}: run {brief(odd)} is not allowed: compete numbers its runs 0, 1, 2, ... "
            f"(the file's {len(runs)} runs: 0..{len(runs) - 1}; it has no run {absent})"
        )
    for run, numbers in seen.items():  # 0, 2, 3 was plotted as 0, 1, 2 (sixth trial)
        if max(numbers) != len(numbers) - 1:
            gap = min(set(range(max(numbers))) - numbers)
            raise NeurohoverError(f"--compete {str(csv_path)!r}: run {run} lacks episode {gap}: each run's episodes are numbered 0, 1, 2, ...")
    lengths = {run: len(rows) for run, rows in runs.items()}
    if len(set(lengths.values())) > 1:  # compete writes whole runs: a shorter one is a file cut short (plotted cut; eighth trial)
        short = min(lengths, key=lengths.__getitem__)
        raise NeurohoverError(
            f"--compete {str(csv_path)!r}: run {short} has {lengths[short]} episodes where run {max(lengths, key=lengths.__getitem__)} has "
            f"{max(lengths.values())}: the file is cut short (compete writes whole runs; run it again to rewrite it)"
        )
    ordered = [sorted(rows) for _, rows in sorted(runs.items())]
    returns = np.array([[r for _, r, _ in rows] for rows in ordered])
    if "" not in facts.policies:  # every row names its policy: the mean return after learning, as compete.summarise takes it
        after = [ret for rows in ordered for _, ret, _ in rows[_after_learning_start([p for _, _, p in rows]) :]]
        facts.after_learning = math.fsum(after) / len(after)
    label = path.resolve().name  # no summary (an interrupted competition): the directory's name labels it
    conditions, episode_steps = {}, None
    if summary_path.exists():
        summary = read_summary(summary_path)
        _check_summary(summary_path, summary, returns, facts)
        label = f"{summary['agent']} ({summary.get('task', '?')})"
        conditions = {key: summary[key] for key in COMPETE_CONDITIONS if key in summary}
        episode_steps = summary.get("episode_steps")
    if facts.split_run is not None:  # after the summary's check of each label: a label of no MDP is named as such first
        raise NeurohoverError(facts.split_run)
    _check_run_mdps(csv_path, facts, len(runs))
    _check_lengths(csv_path, facts, episode_steps)
    _check_crash_charge(csv_path, facts, episode_steps)
    return CompeteResult(label, returns, facts.crashes, path, conditions)


def read_summary(summary_path: Path) -> dict:
    """A compete folder's ``summary.json``, read strictly: damaged (a key given twice, not UTF-8, empty, nested or a number
    past what strict_json reads) or no table naming its agent and task refused by name. The one reading of it, by
    :func:`read_compete_dir` and :func:`neurohover.compete.check_against_store` (whose own copy leaked a JSONError and an
    AttributeError: T49-B03); the checks against its rows are :func:`_check_summary`'s."""
    try:
        summary = strict_json(summary_path.read_text(encoding="utf-8-sig"))  # a key given twice too (ninth trial)
    except (OSError, ValueError) as err:  # damaged: refused, not silently relabelled (second trial)
        raise NeurohoverError(f"--compete {str(summary_path)!r} cannot be read ({err}); remove it to label the curve by its directory's name") from None
    if not (isinstance(summary, dict) and isinstance(summary.get("agent"), str) and isinstance(summary.get("task", ""), str)):
        raise NeurohoverError(f"--compete {str(summary_path)!r} is not a compete summary: no agent and task names")
    return summary


def _check_lengths(csv_path: Path, rows: _Rows, episode_steps: object) -> None:
    """Refuse rows of episodes of different lengths and a return below the lowest an episode of the competition's length
    can have (:func:`~neurohover.sim.constants.lowest_return`). An episode that does not crash flies the whole episode,
    so without a summary (whose check holds each row to its episode_steps) every uncrashed row's steps are one n and a
    crashed row's at most n: steps 5 and 20 both uncrashed were plotted (T27-B04), as was a 20-step return of -1e9
    (T27-B03)."""
    n = episode_steps if whole_number(episode_steps) else None
    whole = sorted((line, steps) for (crashed, steps), line in rows.steps.items() if not crashed)
    if n is None and whole:
        (first, n), where = whole[0], f"--compete {str(csv_path)!r}, line"
        for (crashed, steps), line in sorted(rows.steps.items(), key=lambda item: item[1]):
            if steps != n and (not crashed or steps > n):
                what = f"a crash at step {steps}" if crashed else f"an uncrashed episode of {steps} steps"
                why = f"line {first}'s uncrashed episode flies {n} steps, an uncrashed episode flies the whole episode"
                raise NeurohoverError(f"{where} {line}: steps {steps} is not allowed: {what}, where {why}: allowed {n} (a crash's at most {n})")
    if n is not None and rows.lowest is not None and rows.lowest[0] < lowest_return(n):
        ret, line = rows.lowest
        bound = f"{lowest_return(n):.10g} (the worst step, {CRASH_STEP_PENALTY:.6g}, for each of its {n} steps)"
        raise NeurohoverError(f"--compete {str(csv_path)!r}, line {line}: return {ret!r} is not allowed: allowed at least {bound}")


def _check_crash_charge(csv_path: Path, rows: _Rows, episode_steps: object) -> None:
    """Refuse a crashed row whose return is above the crash's charge: a crash at step t of an n-step episode is charged
    CRASH_STEP_PENALTY for each of its n - t steps left (sim.kernel.crash_charge; none for a crash on the last step), so
    its return is at most -CRASH_STEP_PENALTY * (n - t). n is the summary's episode_steps, else the file's longest
    episode (at most n: a bound that holds). A crash at step 10 of 20 returning -6.1 was plotted (T26-B09)."""
    if rows.least_charged is None:
        return
    n = episode_steps if whole_number(episode_steps) else max(steps for _, steps in rows.steps)
    _, line, ret, steps = rows.least_charged
    if ret > crash_return_ceiling(n, steps):
        raise NeurohoverError(
            f"--compete {str(csv_path)!r}, line {line}: return {ret!r} is not allowed: the episode crashed at step {steps} of its {n}, and a crash is "
            f"charged {CRASH_STEP_PENALTY:.6g} for each step left: allowed at most {crash_charge(n, steps):.10g}"
        )


def _check_run_mdps(csv_path: Path, rows: _Rows, runs: int) -> None:
    """Refuse a run on another MDP than compete gives it, naming the line, the value and the one allowed: compete's runs
    fly its MDP set's MDPs in turn (compete._group, runs ordered by MDP), so where a set holds at least the file's runs
    (or draws one MDP per run, 'sample') run i flies SET:i; two runs on test:0 of a 2-run competition were plotted
    (T26-B10). A label of no such shape is not checked here (the summary's task names it), nor runs past a set's size
    (older competitions flew its MDPs over again in another order)."""
    for run, (label, line) in sorted(rows.run_mdps.items()):
        _, slash, rest = label.partition("/")
        kind, colon, index = rest.partition(":")
        size = {"test": N_TEST, "train": N_TRAINING}.get(kind, runs)
        if not (slash and colon and kind in ("test", "train", "sample") and index.isascii() and index.isdigit()) or runs > size:
            continue
        if int(index) != run:
            allowed = f"{label[: len(label) - len(rest)]}{kind}:{run}"
            raise NeurohoverError(
                f"--compete {str(csv_path)!r}, line {line}: mdp {brief(label)} is not allowed: compete flies its {kind} MDPs in turn, "
                f"run i on {kind}:i, so run {run} of its {runs} runs flies {allowed}"
            )


def _check_summary(path: Path, summary: dict, returns: np.ndarray, rows: _Rows) -> None:
    """The one check of a summary.json, against itself and its episodes.csv: no key compete never writes (T23-06), a task's
    name, then the rows its agent never writes (:func:`_check_rows_of_agent`), what its rows contradict
    (:func:`_check_summary_matches`: named with what they hold), each value's kind and range (:func:`_check_fields`),
    its offline seconds against its seconds and agent (:func:`_check_seconds`), the conditions its task can fly under
    (:func:`_check_conditions`) and the MDPs (:func:`_check_mdp_labels`)."""
    from .tasks import task_names

    unknown = next((key for key in summary if key not in SUMMARY_FIELDS), None)
    if unknown is not None:
        raise NeurohoverError(f"--compete {str(path)!r}: its key {brief(unknown)} is not allowed: compete writes the keys {', '.join(SUMMARY_FIELDS)}")
    task, names = summary.get("task"), task_names()  # the registry as it is (T46-B07)
    if task is not None and task not in names:
        raise NeurohoverError(f"--compete {str(path)!r} names task {task!r:.40}, not one of {', '.join(names)}: it is no compete summary")
    experiment, agent = summary.get("experiment"), summary.get("agent")
    if isinstance(experiment, str) and task is not None and agent is not None and experiment != f"compete-{task}-{agent}":
        _check_summary_matches(path, summary, returns, rows)  # an agent its experiment contradicts: the summary's fault, named so
    _check_rows_of_agent(path, summary, rows)  # first: a row's own fault (a policy, say) named, not the figures it moves
    _check_summary_matches(path, summary, returns, rows)  # then a value the rows contradict, named with what they hold
    _check_fields(path, summary)
    _check_seconds(path, summary)
    _check_conditions(path, summary)
    _check_mdp_labels(path, summary, returns.shape[0], rows)


def _check_fields(path: Path, summary: dict) -> None:
    """Refuse a value of a kind or range compete never writes, naming the key, the value and what is allowed (T23-06: seed
    'x', scale 'paper', seconds -5 or NaN, a positive mean return were taken). A key compete writes may be absent (older
    summaries hold fewer); a key it never writes is refused by :func:`_check_summary`, not ignored: a misspelt
    condition ('sgima') would otherwise leave the curve unlabelled without a word."""
    for key, (fits, allowed) in SUMMARY_FIELDS.items():
        if key in summary and fits is not None and not fits(summary[key]):
            raise NeurohoverError(f"--compete {str(path)!r}: its {key} {brief(summary[key])} is not allowed: {allowed} (what compete writes)")


def _check_seconds(path: Path, summary: dict) -> None:
    """Refuse seconds past :data:`MAX_SECONDS` (1e300 was taken), offline seconds that are not part of the run's seconds,
    or above 0 for an agent that does no work between episodes (:data:`NO_OFFLINE`; 5.0 of a 0.14-second baseline run
    was taken), naming the values (T24-07). Tolerance: result_checks.run_inconsistency's of a stored run's offline
    seconds against its seconds, whose means these are."""
    for key in ("mean_seconds_per_run", "mean_offline_seconds_per_run"):
        if not seconds_allowed(summary.get(key, 0)):  # (finite and >= 0 by SUMMARY_FIELDS, checked before)
            raise NeurohoverError(
                f"--compete {str(path)!r}: its {key} {brief(summary[key])} is not allowed: at most {MAX_SECONDS:.6g} seconds (100 years: no run lasts longer)"
            )
    offline, seconds, agent = summary.get("mean_offline_seconds_per_run"), summary.get("mean_seconds_per_run"), summary.get("agent")
    where = f"--compete {str(path)!r}: its mean_offline_seconds_per_run {brief(offline)} is not allowed"
    if offline is not None and seconds is not None and offline > seconds * (1 + 1e-9) + 1e-6:
        raise NeurohoverError(f"{where}: the agent's work between episodes is part of the run's mean_seconds_per_run {brief(seconds)}: allowed at most that")
    if offline is not None and agent in NO_OFFLINE and offline != 0:
        raise NeurohoverError(f"{where}: agent {agent} does no work between episodes (its first choice holds for the whole run): allowed 0")


def _check_summary_matches(path: Path, summary: dict, returns: np.ndarray, rows: _Rows) -> None:
    """Refuse a summary whose parts contradict each other or its episodes.csv, naming the field and both values: it is
    another competition's, or edited, and labelled the curve without a word (eighth trial; a task edited from ghh08 to
    ghh09 over ghh08's rows, T21-07). Checked, each where the summary holds it: task (a task family, that of every
    row's MDP and of its experiment ``compete-<task>-<agent>``), agent (its experiment's), mdps (every row's MDP set),
    runs and episodes, episode_steps (every uncrashed episode's steps, no crash later), crash figures, the mean and
    sd of the cumulative return and the mean return after learning (the rows', where they name each episode's policy)."""

    def refuse(key: str, found: str) -> NoReturn:
        raise NeurohoverError(
            f"--compete {str(path)!r} says {key} {brief(summary[key])} where {found}: "
            "the two are of different competitions, or one was edited (run compete again, or remove summary.json)"
        )

    task, experiment = summary.get("task"), summary.get("experiment")
    for label, line in rows.mdps.items():  # compete's MDP labels: '<task>/<set>:<i>'
        family, slash, rest = label.partition("/")
        if slash and task is not None and family != task:
            refuse("task", f"its episodes.csv holds {family} MDPs (line {line}: mdp {brief(label)})")
        if slash and ":" in rest and "mdps" in summary and rest.partition(":")[0] != set_name(task, summary.get("sigma"), summary["mdps"]):
            refuse("mdps", f"its episodes.csv holds {rest.partition(':')[0]} MDPs (line {line}: mdp {brief(label)})")
    if isinstance(experiment, str) and task is not None and experiment != f"compete-{task}-{summary['agent']}":  # task names hold no '-'
        refuse("task" if experiment.split("-")[1:2] != [task] else "agent", f"its experiment is {brief(experiment)} (compete-TASK-AGENT)")
    for key, count in (("runs", returns.shape[0]), ("episodes", returns.shape[1])):
        given = summary.get(key)
        if given is not None and (not whole_number(given) or given != count):
            refuse(key, f"its episodes.csv holds {count}")
    if summary.get("episode_steps") is not None and not (whole_number(summary["episode_steps"]) and 1 <= summary["episode_steps"] <= MAX_EPISODE_STEPS):
        shown = brief(summary["episode_steps"])
        raise NeurohoverError(
            f"--compete {str(path)!r} says episode_steps {shown}, not a number of steps (an integer in 1..{MAX_EPISODE_STEPS:,}): it is no compete summary"
        )
    limit = int(summary.get("episode_steps") or 0)
    for (crashed, steps), line in rows.steps.items() if limit else ():
        if steps > limit or (steps != limit and not crashed):
            refuse("episode_steps", f"its episodes.csv holds {'a crash at' if crashed else 'an uncrashed episode of'} {steps} steps (line {line})")
    totals = returns.sum(axis=1)
    mean, sd = float(totals.mean()), float(totals.std(ddof=1)) if totals.size > 1 else 0.0
    runs, crashed_runs, crashes = returns.shape[0], len(rows.crashed_runs), f"{rows.crashes} crash{'es' * (rows.crashes != 1)}"
    figures = [  # tolerance: results.TestRunResult's check of a score against its returns; crash figures are ratios of counts
        ("mean_cumulative_return", mean, 1e-6, f"its episodes.csv's runs return {mean:.10g} in all on average"),
        ("sd_cumulative_return", sd, 1e-6, f"its episodes.csv's runs' cumulative returns have an sd of {sd:.10g}"),
        ("crashes_per_episode", rows.crashes / returns.size, 0.0, f"its episodes.csv holds {crashes} in {returns.size} episodes"),
        ("crash_rate_runs", crashed_runs / runs, 0.0, f"its episodes.csv holds {crashed_runs} of {runs} runs with a crash"),
    ]
    if rows.after_learning is not None:  # T23-06: 5.0 was taken; compete.summarise's mean of each run's returns from its last policy on
        after = f"its episodes.csv's returns average {rows.after_learning:.10g} from each run's last policy on"
        figures.append(("mean_return_after_learning", rows.after_learning, 1e-6, after))
    for key, value, tolerance, found in figures if rows.has_crashed else (f for f in figures if not f[0].startswith("crash")):
        given = summary.get(key)
        if given is not None and not (finite_real(given) and math.isclose(given, value, rel_tol=1e-9, abs_tol=tolerance)):
            refuse(key, found)


def _check_conditions(path: Path, summary: dict) -> None:
    """Refuse a summary's sigma, sensor or drift that compete cannot have flown under, naming it (a sigma NaN, a sensor
    {"level": -5} and a drift "junk" labelled the curves without a word; T22-04): sigma finite and >= 0, a sensor and a
    drift as their parsers read them (Sensor.from_dict, Drift.from_dict; no drift as compete writes Drift() too), and
    each one that its task takes (a sigma on ghh08 was taken, T23-06: compete asks the task family, as here)."""
    from .tasks import Drift, Sensor, get_task_family, task_names

    task = summary.get("task")
    flown: dict[str, object] = {}  # the conditions read so far, as compete hands them to get_task_family
    for key, value in ((k, summary.get(k)) for k in ("sigma", "sensor", "drift")):
        try:
            if key == "sigma" and value is not None and not (finite_real(value) and value >= 0):
                raise NeurohoverError("a family's breadth is a finite number >= 0, or null")
            if key == "sigma":
                flown[key] = value
            if key == "sensor" and value is not None:
                flown[key] = Sensor.from_dict(value)
            if key == "drift" and value is not None:  # {walk 0, change {}}: compete's Drift(), which from_dict calls no drift
                flown[key] = Drift.from_dict({k: v for k, v in value.items() if k != "walk" or v != 0} if isinstance(value, dict) else value)
            if task in task_names():
                get_task_family(task, **flown)  # type: ignore[arg-type]
        except NeurohoverError as err:
            raise NeurohoverError(f"--compete {str(path)!r} says {key} {brief(value)}, which compete never flies under: {err}") from None


def _check_mdp_labels(path: Path, summary: dict, runs: int, rows: _Rows) -> None:
    """Refuse an MDP that is no label of the summary's task (mdp 'zzz', T22-04) or none of the MDPs its runs fly
    (test:999 of a 2-run competition, T23-07), naming the line, the value and what is allowed."""
    task = summary.get("task")
    for label, line in rows.mdps.items() if task is not None else ():
        _, slash, rest = label.partition("/")
        kind, _, index = rest.partition(":")
        where = f"--compete {str(path.with_name(COMPETE_FILE))!r}, line {line}"
        if label and not (slash and kind in MDP_SETS and index.isascii() and index.isdigit()):
            raise NeurohoverError(f"{where}: mdp {brief(label)} is not allowed: a {task} MDP's label, {task}/SET:I (SET {SETS_TEXT})")
        flown = min(runs, {"test": N_TEST, "train": N_TRAINING}.get(kind.removeprefix("seeded-"), runs))  # compete._group: a run per MDP, or the whole set
        if label and (len(index) > 9 or int(index) >= flown):
            raise NeurohoverError(
                f"{where}: mdp {brief(label)} is not allowed: a competition of {runs} runs on {task}'s {kind} MDPs "
                f"flies {task}/{kind}:0 to {task}/{kind}:{flown - 1}"
            )


def _check_rows_of_agent(path: Path, summary: dict, rows: _Rows) -> None:
    """Refuse a row that the summary's agent never writes, naming the line, the value and what is allowed: a safeguard
    that fired for an agent that flies under none, a policy other than the one a one-policy agent flies (T23-07)."""
    agent = summary.get("agent")
    csv_path = path.with_name(COMPETE_FILE)
    if rows.fired_line is not None and agent in NO_SAFEGUARD:
        raise NeurohoverError(
            f"--compete {str(csv_path)!r}, line {rows.fired_line}: safeguard_fired '1' is not allowed: agent {agent} flies under no safeguard "
            "(0 for each of its episodes; agents with one: the hybrid agents, continual, authors-*)"
        )
    for label, line in rows.policies.items():
        problem = policy_label_problem(agent, label) if label else ""
        if problem:
            raise NeurohoverError(f"--compete {str(csv_path)!r}, line {line}: {problem}")


def read_compete_dirs(dirs: Sequence[str | Path]) -> list[CompeteResult]:
    """:func:`read_compete_dir` of each of ``dirs``, every one checked before any is read: none, or one given twice
    (one run overlaid on itself; fourth trial), refused as ``neurohover plot --compete`` refuses them."""
    if isinstance(dirs, (str, os.PathLike)) or not isinstance(dirs, Sequence) or len(dirs) == 0:  # [] drew an empty figure (eleventh trial)
        raise NeurohoverError(f"--compete {dirs!r:.60} is not allowed: give a list of one or more directories written by neurohover compete --out")
    paths = [input_dir(d, "--compete") for d in dirs]
    twice = [str(d) for i, d in enumerate(paths) if any(d.resolve() == e.resolve() for e in paths[:i])]
    if twice:
        raise NeurohoverError(f"--compete names {twice[0]!r} more than once: give each competition's directory once")
    return [read_compete_dir(d) for d in paths]
