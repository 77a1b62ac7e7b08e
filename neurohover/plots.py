"""Plots of flights and competitions, drawn with matplotlib's object-oriented API.

- :func:`flight_figure`: one episode of flight data (``neurohover fly --record``) over time:
  position error, velocity, attitude (roll, pitch, yaw), angular rates and actions, a crash marked.
- :func:`compete_figure`: several ``neurohover compete --out DIR`` results overlaid, mean
  cumulative error per episode on a linear and a log scale (the paper's Figures 4 and 7).

Every figure is a :class:`matplotlib.figure.Figure` on its own
:class:`~matplotlib.backends.backend_agg.FigureCanvasAgg`: nothing here touches pyplot or the
process's matplotlib backend, so plotting is safe in any program (and thread) that uses matplotlib
otherwise. ``neurohover plot`` (:mod:`neurohover.cli.plots`) calls :func:`plot_flight_data`
and :func:`plot_compete`.

Example
-------
>>> from neurohover.flightdata import FlightData
>>> from neurohover.plots import plot_flight_data
>>> paths = plot_flight_data(FlightData.load("flight.npz"), "plots/")  # doctest: +SKIP
"""

from __future__ import annotations

import csv
import json
import math
import os
import textwrap
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import NoReturn

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.ticker import MaxNLocator

from .errors import NeurohoverError, brief, finite_real, whole_number
from .flightdata import FlightData, check_flown, check_metadata, crash_flags
from .paths import input_dir, output_dir, output_file, printable, strict_json
from .sim.constants import ACTION_NAMES, CONTROL_DT, EPISODE_STEPS, MAX_EPISODE_STEPS, WORST_RETURN

__all__ = [
    "CompeteResult",
    "attitude_angles",
    "compete_figure",
    "crashed_episode",
    "episode_crashed",
    "flight_figure",
    "plot_compete",
    "plot_flight_data",
    "read_compete_dir",
    "read_compete_dirs",
    "save_figure",
]

CRASH_COLOR = "tab:red"
COMPETE_FILE = "episodes.csv"
COMPETE_SUMMARY = "summary.json"
COMPETE_CONDITIONS = ("episode_steps", "sigma", "sensor", "drift")  # summary.json keys: curves that differ in one are labelled with it
COMPETE_COLUMNS = ("run", "episode", "return")  # the columns of compete's episodes.csv read here


def new_figure(width: float, height: float, dpi: int = 100) -> Figure:
    """A figure with its own Agg canvas (no pyplot)."""
    fig = Figure(figsize=(width, height), dpi=dpi)
    FigureCanvasAgg(fig)
    return fig


def save_figure(fig: Figure, path: str | Path) -> Path:
    """Write ``fig`` as a PNG to ``path``, checked as every output file is (:func:`~neurohover.paths.output_file`:
    not a directory, device, pipe or socket; missing parent directories are created, saying so)."""
    from .paths import write_png

    if not isinstance(fig, Figure):  # None was an AttributeError mid-write
        raise NeurohoverError(f"fig={brief(fig)} is not allowed: give a matplotlib Figure (e.g. from flight_figure or compete_figure)")
    path = output_file(path, "plot file")  # a FIFO or /dev/full was replaced by the PNG (fourteenth trial, T14-1)
    return write_png(fig, path, "plot file")


def _title(title: object) -> str:
    """A figure's ``title`` as shown: text, its unprintable characters escaped (:func:`~neurohover.paths.printable`)."""
    if not isinstance(title, str):  # None or b"x" was a TypeError or AttributeError (fourteenth trial, T14-11)
        raise NeurohoverError(f"title={brief(title)} is not allowed: give text ('' for none)")
    return printable(title)


def _real_array(values: object, name: str, columns: int, shape: str) -> np.ndarray:
    """``values`` as a 2-D float64 array of ``columns`` columns, or one message naming ``name`` and the ``shape`` expected."""
    try:
        array = np.asarray(values)
    except (ValueError, TypeError):  # ragged nested lists
        array = np.asarray(None)
    masked = isinstance(values, np.ma.MaskedArray)  # np.asarray dropped the mask: the hidden values were plotted (T16-9)
    if masked or array.dtype.kind not in "fiu" or array.ndim != 2 or array.shape[1] != columns:  # 'abc', None or (3, 5) were NumPy's errors
        if masked:
            got = f"={brief(values)} (a masked array)"
        elif array.dtype.kind in "fiu":
            got = f" of shape {array.shape}"
        else:
            got = f" of dtype {array.dtype}" if isinstance(values, np.ndarray) else f"={brief(values)}"
        raise NeurohoverError(f"{name}{got} is not allowed: give a {shape} array of real numbers")
    return array.astype(np.float64, copy=False)


def _check_episode_steps(episode_steps: object) -> int:
    """``episode_steps`` (a full episode's control steps) as an int, or one message saying what is allowed."""
    if not whole_number(episode_steps) or not 1 <= episode_steps <= MAX_EPISODE_STEPS:  # nan or -1 said "no crash" (T14-11)
        raise NeurohoverError(f"episode_steps={brief(episode_steps)} is not allowed: give an integer in 1..{MAX_EPISODE_STEPS:,}")
    return int(episode_steps)


# -- flight data ------------------------------------------------------------------------------


def attitude_angles(observations: np.ndarray) -> np.ndarray:
    """Roll, pitch and yaw (degrees, Z-Y-X Euler angles) of each observation's quaternion.

    Parameters
    ----------
    observations : (T, 12) array
        Observations; entries 9-11 are the quaternion's vector part, its scalar part qw is
        ``sqrt(1 - |q|^2)`` (positive: a helicopter more than 30 degrees from level has crashed).

    Returns
    -------
    (T, 3) array
        Roll, pitch, yaw in degrees.
    """
    q = _real_array(observations, "observations", 12, "(T, 12)")[:, 9:12]
    qx, qy, qz = q[:, 0], q[:, 1], q[:, 2]
    qw = np.sqrt(np.clip(1.0 - (qx * qx + qy * qy + qz * qz), 0.0, 1.0))
    roll = np.arctan2(2.0 * (qw * qx + qy * qz), 1.0 - 2.0 * (qx * qx + qy * qy))
    pitch = np.arcsin(np.clip(2.0 * (qw * qy - qz * qx), -1.0, 1.0))
    yaw = np.arctan2(2.0 * (qw * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz))
    return np.degrees(np.stack([roll, pitch, yaw], axis=1))


def crashed_episode(actions: np.ndarray, episode_steps: int = EPISODE_STEPS) -> bool:
    """Whether an episode of ``actions`` (a (T, 4) array) crashed: it ended before ``episode_steps`` control steps
    (an integer in 1..MAX_EPISODE_STEPS)."""
    steps = _check_episode_steps(episode_steps)
    return _real_array(actions, "actions", 4, "(T, 4)").shape[0] < steps


def flight_figure(
    observations: np.ndarray,
    actions: np.ndarray,
    *,
    title: str = "",
    crashed: bool | None = None,
    episode_steps: int = EPISODE_STEPS,
) -> Figure:
    """One episode over time: position error, velocity, attitude, rates and actions.

    Parameters
    ----------
    observations : (T + 1, 12) array
        The episode's observations (the first one before the first action), finite.
    actions : (T, 4) array
        The actions applied (aileron, elevator, rudder, collective), finite but a crashed episode's last.
    title : str
        Figure title.
    crashed : bool, optional
        Whether the episode crashed; by default, whether it is shorter than ``episode_steps``.
        A crash is marked by a red line at its time on every panel.
    episode_steps : int
        Control steps of a full episode (6000).

    Returns
    -------
    matplotlib.figure.Figure
        Five panels sharing the time axis (seconds at 10 Hz).
    """
    obs = _real_array(observations, "observations", 12, "(T + 1, 12)")
    act = _real_array(actions, "actions", 4, "(T, 4)")
    if act.shape[0] < 1 or obs.shape[0] != act.shape[0] + 1:  # (0, 12) was an IndexError (T14-11)
        raise NeurohoverError(f"observations of shape {obs.shape} and actions of shape {act.shape} are not one episode: give (T + 1, 12) and (T, 4), T >= 1")
    title = _title(title)  # a file or policy name that is no UTF-8 was matplotlib's TypeError (eleventh trial)
    steps = _check_episode_steps(episode_steps)
    if crashed is None:
        crashed = crashed_episode(act, steps)
    elif not isinstance(crashed, (bool, np.bool_)):
        raise NeurohoverError(f"crashed={brief(crashed)} is not allowed: give True, False or None (by the episode's length)")
    check_flown(obs, act, bool(crashed), "flight_figure")
    t_obs = np.arange(obs.shape[0]) * CONTROL_DT
    t_act = np.arange(act.shape[0]) * CONTROL_DT
    fig = new_figure(10.0, 11.0)
    axes = fig.subplots(5, 1, sharex=True)
    panels = [
        ("position error (m, body)", t_obs, obs[:, 3:6], ("x", "y", "z")),
        ("velocity (m/s, body)", t_obs, obs[:, 0:3], ("u", "v", "w")),
        ("attitude (deg)", t_obs, attitude_angles(obs), ("roll", "pitch", "yaw")),
        ("angular rate (rad/s)", t_obs, obs[:, 6:9], ("p", "q", "r")),
        ("action", t_act, act, ACTION_NAMES),
    ]
    for ax, (label, t, values, names) in zip(axes, panels, strict=True):
        for j, name in enumerate(names):
            ax.plot(t, values[:, j], lw=0.8, label=name)
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
        ax.legend(loc="upper right", fontsize=8, ncol=len(names))
        if crashed:
            ax.axvline(t_obs[-1], color=CRASH_COLOR, ls="--", lw=1.2)
    axes[-1].set_ylim(-1.05, 1.05)
    axes[-1].set_xlabel("time (s)")
    end = f"crashed at {t_obs[-1]:.1f} s (step {act.shape[0]})" if crashed else f"{act.shape[0]} steps, no crash"
    fig.suptitle(f"{title}\n{end}" if title else end, color=CRASH_COLOR if crashed else "black")
    fig.tight_layout()
    return fig


def _episode_title(data: FlightData, i: int, stem: str) -> str:
    """'stem: episode i, MDP label, return R, policy P', from what the metadata holds."""
    meta = data.metadata if isinstance(data.metadata, dict) else {}
    parts = [f"{stem}: episode {i}"]
    mdps = meta.get("mdps")
    if isinstance(mdps, list) and i < len(mdps) and isinstance(mdps[i], dict) and mdps[i].get("label"):
        parts.append(str(mdps[i]["label"]))
    returns = meta.get("returns")
    if isinstance(returns, list) and i < len(returns) and isinstance(returns[i], (int, float)):
        parts.append(f"return {returns[i]:.6g}")
    if meta.get("policy"):
        parts.append(f"policy {meta['policy']}")
    return ", ".join(parts)


def episode_crashed(data: FlightData, i: int) -> bool:
    """Whether episode ``i`` of ``data`` crashed: its flag as flown (the ``crashed`` metadata every recording holds),
    or, in files recorded before 2026-12-04, whether it is shorter than the metadata's ``episode_steps`` (default 6000)."""
    _check_flight_data(data)  # None was an AttributeError, episode 5 of 2 an IndexError (fifteenth trial, T15-9)
    i = _episode_list([i], data.n_episodes)[0]
    flags = data.metadata.get("crashed") if isinstance(data.metadata, dict) else None
    if not (isinstance(flags, list) and len(flags) == data.n_episodes):  # by length: episode_steps "x" was int()'s ValueError
        _check_episode_steps(data.metadata.get("episode_steps", EPISODE_STEPS) if isinstance(data.metadata, dict) else EPISODE_STEPS)
    return crash_flags(data)[i]


def plot_flight_data(data: FlightData, out_dir: str | Path, stem: str = "flight", episodes: Sequence[int] | None = None) -> list[Path]:
    """One PNG per episode of ``data`` (:func:`flight_figure`), ``<stem>-episode<i>.png`` in ``out_dir``;
    ``episodes``: only these (a list of distinct 0-based indices; default all). ``out_dir`` is created, saying so, if
    missing; the flight data's metadata is checked as :meth:`FlightData.load` checks a file's.

    Titles take the MDP label, return and policy from the metadata that ``neurohover fly
    --record`` writes (``mdps``, ``returns``, ``policy``); a crash is marked as :func:`episode_crashed` says.

    Returns
    -------
    list of Path
        The files written, in episode order.
    """
    _check_flight_data(data)  # None was an AttributeError (fourteenth trial, T14-10)
    if not isinstance(stem, str) or stem == "" or "\x00" in stem or any(sep and sep in stem for sep in (os.sep, os.altsep)):
        raise NeurohoverError(  # '../zz' wrote outside out_dir, '' the file '-episode0.png' (eleventh trial)
            f"stem={stem!r:.60} is not allowed: give a non-empty file-name prefix without a path separator, e.g. 'flight'"
        )
    check_metadata(data.metadata, np.array([a.shape[0] for a in data.actions], dtype=np.int64), "flight data")  # episode_steps 'x' (T14-10)
    steps = data.metadata.get("episode_steps", EPISODE_STEPS)
    for i, crashed in enumerate(crash_flags(data)):  # every episode before any file is written, as learn-model reads them all
        check_flown(data.observations[i], data.actions[i], crashed, f"flight data, episode {i}")
    width = len(str(max(data.n_episodes - 1, 0)))
    chosen = range(data.n_episodes) if episodes is None else _episode_list(episodes, data.n_episodes)
    out_dir = output_dir(out_dir, "out_dir")  # a file, FIFO or /dev/null was NotADirectoryError (T14-10); made, saying so, if missing
    paths = []
    for i in chosen:
        obs, act = data.observations[i], data.actions[i]
        fig = flight_figure(obs, act, title=_episode_title(data, i, stem), episode_steps=int(steps), crashed=episode_crashed(data, i))
        paths.append(save_figure(fig, out_dir / f"{stem}-episode{i:0{width}d}.png"))
    return paths


def _check_flight_data(data: object) -> None:
    """Refuse anything but :class:`FlightData`, naming it."""
    if not isinstance(data, FlightData):
        raise NeurohoverError(f"data={brief(data)} is not allowed: give FlightData (e.g. FlightData.load('flight.npz'))")


def _episode_list(episodes: object, n: int) -> list[int]:
    """``episodes`` as distinct indices of the ``n`` episodes, or one message saying what is allowed."""
    # 0 was a TypeError; a masked array's masked entries are no indices (T16-9)
    if isinstance(episodes, (str, bytes, np.ma.MaskedArray)) or not isinstance(episodes, (Sequence, np.ndarray)) or getattr(episodes, "ndim", 1) != 1:
        raise NeurohoverError(f"episodes={brief(episodes)} is not allowed: give a list of episode indices, e.g. [0, 2], or None for all")
    chosen = list(episodes)
    if not chosen:  # [] wrote nothing and returned [] without a word (fifteenth trial, T15-25)
        raise NeurohoverError(f"episodes={brief(episodes)} selects no episode: give at least one index of 0..{n - 1}, or None for all")
    bad = [i for i in chosen if not (whole_number(i) and 0 <= i < n)]
    if bad:
        why = "is out of range" if whole_number(bad[0]) else "is not allowed: give integer indices"  # True was taken as 1
        raise NeurohoverError(f"episode {brief(bad[0])} {why}: the flight data hold episodes 0..{n - 1}")
    seen: set[int] = set()
    for i in map(int, chosen):
        if i in seen:  # one file drawn twice, as neurohover plot --episodes 0,0 refuses
            raise NeurohoverError(f"episodes names episode {i} more than once: give each episode once")
        seen.add(i)
    return [int(i) for i in chosen]


# -- competitions -----------------------------------------------------------------------------


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


def compete_figure(results: Sequence[CompeteResult], title: str = "") -> Figure:
    """Mean cumulative error per episode of each result, linear (left) and log scale (right).

    Each axes holds exactly one line per result, in order; a legend names each with its runs
    and crashes.
    """
    if isinstance(results, (str, bytes)) or not isinstance(results, Sequence) or not results or not all(isinstance(r, CompeteResult) for r in results):
        raise NeurohoverError(  # [None] was an AttributeError, [] an empty figure (fourteenth trial, T14-11)
            f"results={brief(results)} is not allowed: give a list of one or more CompeteResult (read_compete_dir or read_compete_dirs)"
        )
    heading = _title(title) or "mean cumulative error over runs"
    fig = new_figure(11.0, 4.5)
    axes = fig.subplots(1, 2)
    labels = [r.label for r in results]
    differ = _differing_conditions(results)
    for r in results:
        name = r.label if labels.count(r.label) == 1 else f"{r.label} [{r.path.name}]"  # same agent twice
        label = f"{printable(name)}: {r.returns.shape[0]} runs, {r.crashes} crashes"  # names that are no UTF-8
        if differ:  # 50-step drifting episodes beside 6000-step ones were overlaid without a word (eleventh trial, S4)
            flown = ", ".join(f"{key} {_condition_text(r.conditions.get(key, '?'))}" for key in differ)
            label += "\n" + textwrap.fill(printable(flown), 70)  # lines of their own: one long line ran off the figure's edge
        error = r.cumulative_error
        episodes = np.arange(1, error.size + 1)
        for ax in axes:
            ax.plot(episodes, error, label=label)
    axes[0].set_ylabel("cumulative error (-cumulative reward)")
    axes[1].set_yscale("log")
    axes[1].set_ylabel("cumulative error (log scale)")
    for ax in axes:
        ax.set_xlabel("episode")
        ax.xaxis.set_major_locator(MaxNLocator(integer=True))
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=8)
    if differ:
        heading += f" (flown under different {', '.join(differ)}: see the legend)"
    fig.suptitle(heading)
    fig.tight_layout()
    return fig


def _differing_conditions(results: Sequence[CompeteResult]) -> list[str]:
    """The :data:`COMPETE_CONDITIONS` whose values differ between ``results`` (a result without a summary differs)."""
    return [key for key in COMPETE_CONDITIONS if len({json.dumps(r.conditions.get(key, "?"), sort_keys=True) for r in results}) > 1]


def _condition_text(value) -> str:
    text = "none" if value is None else value if isinstance(value, str) else json.dumps(value, sort_keys=True, separators=(",", ":"))
    return text if len(text) <= 60 else text[:57] + "..."


def plot_compete(dirs: Sequence[str | Path], out: str | Path) -> tuple[Path, Figure]:
    """Overlay the compete results in ``dirs`` (:func:`compete_figure`) and write the PNG ``out``; ``dirs`` is checked
    as :func:`read_compete_dirs` says."""
    results = read_compete_dirs(dirs)
    fig = compete_figure(results)
    return save_figure(fig, out), fig
