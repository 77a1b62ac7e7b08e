"""Reading ``neurohover compete --out DIR`` directories: ``episodes.csv`` and ``summary.json``, each checked against
what compete writes and against each other (:func:`read_compete_dir`, :func:`read_compete_dirs`), as ``neurohover plot
--compete`` (:func:`neurohover.plots.plot_compete`) reads them.

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
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import NoReturn

import numpy as np

from .errors import NeurohoverError, brief, finite_real, whole_number
from .paths import input_dir, strict_json
from .sim.constants import MAX_EPISODE_STEPS, WORST_RETURN

__all__ = ["COMPETE_COLUMNS", "COMPETE_CONDITIONS", "COMPETE_FILE", "COMPETE_SUMMARY", "CompeteResult", "read_compete_dir", "read_compete_dirs"]

COMPETE_FILE = "episodes.csv"
COMPETE_SUMMARY = "summary.json"
COMPETE_CONDITIONS = ("episode_steps", "sigma", "sensor", "drift")  # summary.json keys: curves that differ in one are labelled with it
COMPETE_COLUMNS = ("run", "episode", "return")  # the columns of compete's episodes.csv read here


@dataclass(frozen=True)
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
    label and each (crashed, steps) first appears on, the crashes and the runs with one."""

    mdps: dict[str, int] = field(default_factory=dict)
    steps: dict[tuple[bool, int], int] = field(default_factory=dict)
    crashes: int = 0
    crashed_runs: set[int] = field(default_factory=set)
    has_crashed: bool = False
    run_lines: dict[int, int] = field(default_factory=dict)


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


def read_compete_dir(path: str | Path) -> CompeteResult:
    """Read ``episodes.csv`` (and ``summary.json``, for the label) of a compete output directory.

    Raises
    ------
    NeurohoverError
        If ``path`` is no directory, or it has no ``episodes.csv`` or not one compete wrote, or a ``summary.json`` that
        contradicts it (:func:`_check_summary_matches`).
    """
    path = input_dir(path, "--compete")  # None or 5 was pathlib's TypeError (eleventh trial)
    csv_path = path / COMPETE_FILE
    if not csv_path.is_file():
        raise NeurohoverError(f"--compete {str(path)!r} holds no {COMPETE_FILE}: give directories written by neurohover compete --out")
    runs: dict[int, list[tuple[int, float]]] = {}
    seen: dict[int, set[int]] = {}  # each run's episode numbers so far
    facts = _Rows()
    try:
        with open(csv_path, newline="", encoding="utf-8-sig") as f:
            reader = csv.DictReader(f)
            missing = [c for c in COMPETE_COLUMNS if c not in (reader.fieldnames or [])]
            if missing:
                raise NeurohoverError(f"--compete {str(csv_path)!r} is not a compete episodes file: no column {', '.join(missing)}")
            facts.has_crashed = "crashed" in (reader.fieldnames or [])
            for line, row in enumerate(reader, start=2):
                try:
                    run, episode, ret = int(row["run"]), int(row["episode"]), float(row["return"])
                    crashed, steps = int(row.get("crashed") or 0), int(row["steps"]) if row.get("steps") else None
                except (TypeError, ValueError):
                    raise NeurohoverError(f"--compete {str(csv_path)!r}, line {line}: run, episode, return, crashed and steps must be numbers") from None
                _check_row(f"--compete {str(csv_path)!r}, line {line}", row, crashed, steps)
                if not (math.isfinite(ret) and -WORST_RETURN <= ret <= 0):  # -1e308 overflowed the plot (eighth trial); every reward is <= 0 (ninth)
                    raise NeurohoverError(
                        f"--compete {str(csv_path)!r}, line {line}: return {row['return']!r:.30} is not an episode's "
                        f"(finite, in [{-WORST_RETURN:.3g}, 0]: every reward is minus a sum of squares)"
                    )
                if run < 0 or episode < 0 or episode in seen.setdefault(run, set()):  # plotted without a word (fifth trial)
                    raise NeurohoverError(
                        f"--compete {str(csv_path)!r}, line {line}: run {run}, episode {episode} is negative or given twice: "
                        "each run's episodes are numbered once each from 0"
                    )
                seen[run].add(episode)
                facts.run_lines.setdefault(run, line)
                runs.setdefault(run, []).append((episode, ret))
                facts.crashes += crashed
                facts.mdps.setdefault(row.get("mdp") or "", line)
                if crashed:
                    facts.crashed_runs.add(run)
                if steps is not None:
                    facts.steps.setdefault((bool(crashed), steps), line)
    except (OSError, UnicodeDecodeError, csv.Error) as err:
        raise NeurohoverError(f"--compete {str(csv_path)!r}: cannot read it ({err})") from None
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
    n = min(lengths.values())
    returns = np.array([[r for _, r in sorted(rows)[:n]] for _, rows in sorted(runs.items())])
    label = path.resolve().name  # no summary (an interrupted competition): the directory's name labels it
    summary_path = path / COMPETE_SUMMARY
    if summary_path.exists():
        try:
            summary = strict_json(summary_path.read_text(encoding="utf-8-sig"))  # a key given twice too (ninth trial)
        except (OSError, ValueError) as err:  # damaged: refused, not silently relabelled (second trial)
            raise NeurohoverError(f"--compete {str(summary_path)!r} cannot be read ({err}); remove it to label the curve by its directory's name") from None
        if not (isinstance(summary, dict) and isinstance(summary.get("agent"), str) and isinstance(summary.get("task", ""), str)):
            raise NeurohoverError(f"--compete {str(summary_path)!r} is not a compete summary: no agent and task names")
        _check_summary_matches(summary_path, summary, returns, facts)
        label = f"{summary['agent']} ({summary.get('task', '?')})"
        conditions = {key: summary[key] for key in COMPETE_CONDITIONS if key in summary}
        return CompeteResult(label, returns, facts.crashes, path, conditions)
    return CompeteResult(label, returns, facts.crashes, path)


def _check_summary_matches(path: Path, summary: dict, returns: np.ndarray, rows: _Rows) -> None:
    """Refuse a summary whose parts contradict each other or its episodes.csv, naming the field and both values: it is
    another competition's, or edited, and labelled the curve without a word (eighth trial; a task edited from ghh08 to
    ghh09 over ghh08's rows, T21-07). Checked, each where the summary holds it: task (a task family, that of every
    row's MDP and of its experiment ``compete-<task>-<agent>``), agent (its experiment's), mdps (every row's MDP set),
    runs and episodes, episode_steps (every uncrashed episode's steps, no crash later), crash figures and the mean and
    sd of the cumulative return (the rows')."""
    from .tasks import TASK_NAMES

    def refuse(key: str, found: str) -> NoReturn:
        raise NeurohoverError(
            f"--compete {str(path)!r} says {key} {brief(summary[key])} where {found}: "
            "the two are of different competitions, or one was edited (run compete again, or remove summary.json)"
        )

    task, experiment = summary.get("task"), summary.get("experiment")
    if task is not None and task not in TASK_NAMES:
        raise NeurohoverError(f"--compete {str(path)!r} names task {task!r:.40}, not one of {', '.join(TASK_NAMES)}: it is no compete summary")
    for label, line in rows.mdps.items():  # compete's MDP labels: '<task>/<set>:<i>'
        family, slash, rest = label.partition("/")
        if slash and task is not None and family != task:
            refuse("task", f"its episodes.csv holds {family} MDPs (line {line}: mdp {brief(label)})")
        if slash and ":" in rest and "mdps" in summary and rest.partition(":")[0] != summary["mdps"]:
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
    _check_conditions(path, summary)
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
    for key, value, tolerance, found in figures if rows.has_crashed else figures[:2]:
        given = summary.get(key)
        if given is not None and not (finite_real(given) and math.isclose(given, value, rel_tol=1e-9, abs_tol=tolerance)):
            refuse(key, found)
    for label, line in rows.mdps.items() if task is not None else ():  # mdp 'zzz' was plotted as ghh08's (T22-04)
        _, slash, rest = label.partition("/")
        kind, _, index = rest.partition(":")
        if label and not (slash and kind in ("test", "train", "sample") and index.isascii() and index.isdigit()):
            where = f"--compete {str(path.with_name(COMPETE_FILE))!r}, line {line}"
            raise NeurohoverError(f"{where}: mdp {brief(label)} is not allowed: a {task} MDP's label, {task}/SET:I (SET test, train or sample)")


def _check_conditions(path: Path, summary: dict) -> None:
    """Refuse a summary's sigma, sensor or drift that compete cannot have flown under, naming it (a sigma NaN, a sensor
    {"level": -5} and a drift "junk" labelled the curves without a word; T22-04): sigma finite and >= 0, a sensor and a
    drift as their parsers read them (Sensor.from_dict, Drift.from_dict; no drift as compete writes Drift() too)."""
    from .tasks import Drift, Sensor

    for key, value in ((k, summary.get(k)) for k in ("sigma", "sensor", "drift")):
        try:
            if key == "sigma" and value is not None and not (finite_real(value) and value >= 0):
                raise NeurohoverError("a family's breadth is a finite number >= 0, or null")
            if key == "sensor" and value is not None:
                Sensor.from_dict(value)
            if key == "drift" and value is not None:  # {walk 0, change {}}: compete's Drift(), which from_dict calls no drift
                Drift.from_dict({k: v for k, v in value.items() if k != "walk" or v != 0} if isinstance(value, dict) else value)
        except NeurohoverError as err:
            raise NeurohoverError(f"--compete {str(path)!r} says {key} {brief(value)}, which compete never flies under: {err}") from None


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
