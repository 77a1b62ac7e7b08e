"""Plots of flights and competitions, drawn with matplotlib's object-oriented API.

- :func:`flight_figure`: one episode of flight data (``neurohover fly --record``) over time:
  position error, velocity, attitude (roll, pitch, yaw), angular rates and actions, a crash marked.
- :func:`compete_figure`: several ``neurohover compete --out DIR`` results overlaid, mean
  cumulative error per episode on a linear and a log scale (the paper's Figures 4 and 7); the
  directories are read by :mod:`neurohover.compete_files`.

Every figure is a :class:`matplotlib.figure.Figure` on its own
:class:`~matplotlib.backends.backend_agg.FigureCanvasAgg`: nothing here touches pyplot or the
process's matplotlib backend, so plotting is safe in any program (and thread) that uses matplotlib
otherwise. ``neurohover plot`` (:mod:`neurohover.cli.plots`) calls :func:`plot_flight_data`
and :func:`plot_compete`.

House style: the figures are the paper's, from stored results, so they do not depend on the user's matplotlibrc
(``./matplotlibrc``, ``$MATPLOTLIBRC``, ``~/.config/matplotlib``). Every public function here that makes, draws or
saves a figure, and :func:`neurohover.experiments.report.write_report`, runs in matplotlib's default style
(:func:`house_style`: ``matplotlib.rcdefaults()`` inside ``matplotlib.rc_context()``, the backend left as it is, and
the caller's rcParams back as they were afterwards). An rc with ``text.usetex: True`` and no LaTeX, ``savefig.dpi: 1``
or an empty ``axes.prop_cycle`` made every drawing command a traceback (T46-A04). The rcParams are process-wide: a
thread of the caller's that draws while one of these runs sees the defaults.

Example
-------
>>> from neurohover.flightdata import FlightData
>>> from neurohover.plots import plot_flight_data
>>> paths = plot_flight_data(FlightData.load("flight.npz"), "plots/")  # doctest: +SKIP
"""

from __future__ import annotations

import contextlib
import functools
import json
import os
import re
import sys
import textwrap
import threading
import warnings
from collections.abc import Callable, Iterator, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, ParamSpec, TypeVar

import numpy as np

from .compete_files import COMPETE_CONDITIONS, CompeteResult, read_compete_dirs
from .errors import NeurohoverError, brief, finite_real, real_number, refuse_reloaded, whole_in, whole_number
from .flightdata import FlightData, check_flown, check_metadata, crash_flags
from .paths import output_dir, output_file, printable
from .sim.constants import ACTION_NAMES, CONTROL_DT, EPISODE_STEPS, MAX_EPISODE_STEPS, OBS_NAMES

if TYPE_CHECKING:  # matplotlib is imported by what draws: every command line imports this module
    from matplotlib.figure import Figure

__all__ = [
    "attitude_angles",
    "compete_figure",
    "crashed_episode",
    "episode_crashed",
    "flight_figure",
    "house_style",
    "noting_missing_glyphs",
    "plot_compete",
    "plot_flight_data",
    "save_figure",
]

CRASH_COLOR = "tab:red"
_P = ParamSpec("_P")
_R = TypeVar("_R")


def house_style(fn: Callable[_P, _R]) -> Callable[_P, _R]:
    """``fn`` run in matplotlib's default style, whatever the user's matplotlibrc says: ``matplotlib.rcdefaults()``
    (which leaves the backend alone) inside ``matplotlib.rc_context()``, so the caller's rcParams are back afterwards.
    A figure made and saved inside one call looks the same everywhere (T46-A04, the module's House style)."""

    @functools.wraps(fn)
    def styled(*args: _P.args, **kwargs: _P.kwargs) -> _R:
        import matplotlib  # loaded by what draws, not by every command

        with matplotlib.rc_context():
            matplotlib.rcdefaults()
            return fn(*args, **kwargs)

    return styled


#: The largest figure side new_figure draws, in inches, and in pixels (Agg's own limit: 2**16).
MAX_FIGURE_INCHES, MAX_FIGURE_PIXELS = 100.0, 2**16


@house_style
def new_figure(width: float, height: float, dpi: int = 100) -> Figure:
    """A figure of ``width`` x ``height`` inches (each in (0, 100]) at ``dpi`` dots per inch (1..1000, each side 1 to
    2**16 pixels) with its own Agg canvas (no pyplot). -1, NaN or '1' inches and dpi=10**9 were matplotlib's ValueError or
    TypeError, the last only as the figure was saved (T33-B04)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg  # loaded by what draws, not by every command
    from matplotlib.figure import Figure

    for name, value in (("width", width), ("height", height)):
        allowed = f"allowed a number of inches, 0 < {name} <= {MAX_FIGURE_INCHES:g}"
        if not real_number(value):
            raise NeurohoverError(f"figure {name}={brief(value)} is not allowed: {allowed}")
        if not (finite_real(value) and 0 < value <= MAX_FIGURE_INCHES):
            raise NeurohoverError(f"figure {name}={brief(value)} is out of range: {allowed}")
    dpi = whole_in(dpi, "figure dpi", 1, 1000)
    for name, value in (("width", width), ("height", height)):
        if value * dpi < 1:  # 0.001 inches was taken, and save_figure failed with PIL's "cannot write empty image" (T40-B10)
            raise NeurohoverError(
                f"figure {name}={brief(value)} is out of range: {value:g} inches at dpi {dpi} is {value * dpi:.3g} pixels, and a side is at "
                f"least 1 pixel (allowed {1 / dpi:g} <= {name} <= {MAX_FIGURE_INCHES:g} inches at dpi {dpi})"
            )
    if max(width, height) * dpi > MAX_FIGURE_PIXELS:
        side = f"{max(width, height):g} inches at dpi {dpi} is {max(width, height) * dpi:,.0f} pixels"
        raise NeurohoverError(f"figure dpi={dpi} is out of range: {side}, and a side is at most {MAX_FIGURE_PIXELS:,} pixels")
    fig = Figure(figsize=(float(width), float(height)), dpi=dpi)
    FigureCanvasAgg(fig)
    return fig


#: matplotlib's warning for a character its font lacks, which it draws as a box: "Glyph 20013 (...) missing from font(s) DejaVu Sans."
_MISSING_GLYPH = re.compile(r"Glyph (\d+) \(.*\) missing from font\(s\) (.+?)\.?$")
_NOTED_GLYPHS: set[str] = set()  # the characters noted in this process: a report's figures share a title


@contextlib.contextmanager
def noting_missing_glyphs() -> Iterator[None]:
    """Draw in the block with matplotlib's "Glyph ... missing from font(s)" UserWarnings (each with its source line: a name or
    title with 𝄞 or CJK; T31-A01) replaced by one neurohover note naming the characters the font lacks, each once a process;
    every other warning is shown as it was."""
    caught: list[warnings.WarningMessage] = []
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.filterwarnings("always", _MISSING_GLYPH.pattern, UserWarning)  # also under PYTHONWARNINGS=error
            yield
    finally:  # outside the catching: a warning shown here is the caller's
        missing: dict[str, str] = {}
        for w in caught:
            match = _MISSING_GLYPH.match(str(w.message)) if issubclass(w.category, UserWarning) else None
            if match is None:
                warnings.showwarning(w.message, w.category, w.filename, w.lineno, w.file, w.line)
            elif chr(int(match[1])) not in _NOTED_GLYPHS:
                missing.setdefault(chr(int(match[1])), match[2])
        if missing:
            _NOTED_GLYPHS.update(missing)
            chars = ", ".join(f"{c!r} (U+{ord(c):04X})" for c in missing)
            fonts = ", ".join(dict.fromkeys(missing.values()))
            print(f"neurohover: note: the plot font ({fonts}) has no glyph for {chars}: drawn as boxes", file=sys.stderr)


@house_style
def save_figure(fig: Figure, path: str | Path) -> Path:
    """Write ``fig`` as a PNG to ``path``, a name ending .png (any case), checked as every output file is
    (:func:`~neurohover.paths.output_file`: not a directory, device, pipe or socket; missing parent directories are
    created, saying so)."""
    from matplotlib.figure import Figure

    from .paths import write_png

    if not isinstance(fig, Figure):  # None was an AttributeError mid-write
        raise NeurohoverError(f"fig={brief(fig)} is not allowed: give a matplotlib Figure (e.g. from flight_figure or compete_figure)")
    # A FIFO or /dev/full was replaced by the PNG (fourteenth trial, T14-1); 'figure.pdf' got PNG bytes (T35-B05).
    path = output_file(path, "plot file", suffixes=(".png",), what="a plot is PNG")
    with noting_missing_glyphs():
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


def _check_episode_steps(episode_steps: object, flown: int = 0) -> int:
    """``episode_steps`` (a full episode's control steps) as an int, or one message saying what is allowed; not below
    ``flown``, the steps of the episode drawn (10 for 6,000 was drawn as "no crash", as FlightData refuses; T41-B07)."""
    if not whole_number(episode_steps) or not 1 <= episode_steps <= MAX_EPISODE_STEPS:  # nan or -1 said "no crash" (T14-11)
        raise NeurohoverError(f"episode_steps={brief(episode_steps)} is not allowed: give an integer in 1..{MAX_EPISODE_STEPS:,}")
    if flown > episode_steps:
        raise NeurohoverError(
            f"the episode has {flown:,} steps, more than episode_steps={int(episode_steps):,} (every episode ends at that budget): "
            f"give its episode's budget, an integer in {flown:,}..{MAX_EPISODE_STEPS:,}"
        )
    return int(episode_steps)


# -- flight data ------------------------------------------------------------------------------


def attitude_angles(observations: np.ndarray) -> np.ndarray:
    """Roll, pitch and yaw (degrees, Z-Y-X Euler angles) of each observation's quaternion.

    Parameters
    ----------
    observations : (T, 12) array
        Observations, finite; entries 9-11 are the quaternion's vector part, its scalar part qw is
        ``sqrt(1 - |q|^2)`` (positive: a helicopter more than 30 degrees from level has crashed). A noisy
        sensor's reading may lie past the unit ball (|q| > 1, as recorded flights of ``Sensor(attitude=1)`` do):
        it is taken as the nearest rotation, its vector part scaled to norm 1 (qw = 0).

    Returns
    -------
    (T, 3) array
        Roll, pitch, yaw in degrees.
    """
    q = _real_array(observations, "observations", 12, "(T, 12)")[:, 9:12]
    bad = np.argwhere(~np.isfinite(q))
    if bad.size:  # NaN readings gave NaN angles; flight_figure refuses them (check_flown) (T48-B06)
        k, j = (int(x) for x in bad[0])
        raise NeurohoverError(
            f"observations row {k}: its {OBS_NAMES[9 + j]} {q[k, j]} is not allowed: no flight records a NaN or infinite reading; give finite observations"
        )
    norm = np.hypot(np.hypot(q[:, 0], q[:, 1]), q[:, 2])  # no overflow: 1e300 readings squared were NumPy's RuntimeWarnings (T48-B01)
    q = np.where((norm > 1.0)[:, None], q / np.maximum(norm, 1.0)[:, None], q)  # a noisy reading past the unit ball: its nearest rotation
    qx, qy, qz = q[:, 0], q[:, 1], q[:, 2]
    qw = np.sqrt(np.clip(1.0 - (qx * qx + qy * qy + qz * qz), 0.0, 1.0))
    roll = np.arctan2(2.0 * (qw * qx + qy * qz), 1.0 - 2.0 * (qx * qx + qy * qy))
    pitch = np.arcsin(np.clip(2.0 * (qw * qy - qz * qx), -1.0, 1.0))
    yaw = np.arctan2(2.0 * (qw * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz))
    return np.degrees(np.stack([roll, pitch, yaw], axis=1))


def crashed_episode(actions: np.ndarray, episode_steps: int = EPISODE_STEPS) -> bool:
    """Whether an episode of ``actions`` (a (T, 4) array, T >= 1) crashed: it ended before ``episode_steps`` control steps
    (an integer in 1..MAX_EPISODE_STEPS)."""
    flown = _real_array(actions, "actions", 4, "(T, 4)").shape[0]
    if flown < 1:  # (0, 4) was called a crash (T48-B05), as FlightData.load refuses such an episode
        raise NeurohoverError(f"actions of shape ({flown}, 4) are not an episode: it has 0 steps (a flown one has at least 1); give a (T, 4) array, T >= 1")
    return flown < _check_episode_steps(episode_steps, flown)


@house_style
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
    steps = _check_episode_steps(episode_steps, act.shape[0])
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
    with noting_missing_glyphs():
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


@house_style
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
    lengths = np.array([a.shape[0] for a in data.actions], dtype=np.int64)  # episode_steps 'x' (T14-10); returns after making (T23-03)
    check_metadata(data.metadata, lengths, "flight data", (data.observations, data.actions))
    steps = data.metadata.get("episode_steps", EPISODE_STEPS)
    for i, crashed in enumerate(crash_flags(data)):  # every episode before any file is written, as learn-model reads them all
        check_flown(data.observations[i], data.actions[i], crashed, f"flight data, episode {i}")
    width = len(str(max(data.n_episodes - 1, 0)))
    chosen = range(data.n_episodes) if episodes is None else _episode_list(episodes, data.n_episodes)
    out_dir = output_dir(out_dir, "out_dir")  # a file, FIFO or /dev/null was NotADirectoryError (T14-10); made, saying so, if missing
    paths = []
    with sole_plot(out_dir, "out_dir"):  # two flights of one name at once mixed their episodes (T47-A03)
        for i in chosen:
            obs, act = data.observations[i], data.actions[i]
            fig = flight_figure(obs, act, title=_episode_title(data, i, stem), episode_steps=int(steps), crashed=episode_crashed(data, i))
            paths.append(save_figure(fig, out_dir / f"{stem}-episode{i:0{width}d}.png"))
    return paths


#: The lock file a plot being drawn holds in its output directory (:func:`sole_plot`).
LOCK_FILE = ".plot.lock"
_HELD = threading.local()  # the folders this thread holds (.dirs): neurohover plot holds its --out around plot_flight_data


@contextlib.contextmanager
def sole_plot(out: Path, option: str) -> Iterator[None]:
    """Be the only plot writing into the directory ``out`` (named ``option`` in a refusal) inside this block: a second
    one there is refused, naming the first's pid. Two flights of one name plotted into one --out at once both exited 0,
    the folder left with a mix of their episodes' figures and no note (T47-A03). A lock on :data:`LOCK_FILE` in ``out``,
    as compete's (:func:`~neurohover.compete_folder.sole_competition`); a thread already holding ``out`` goes on."""
    from .locks import holding

    try:
        st = os.stat(out)
        key: object = (st.st_dev, st.st_ino)
    except OSError:  # its writes say what is wrong with it
        key = str(out)
    held: set = _HELD.__dict__.setdefault("dirs", set())
    if key in held:
        yield
        return
    busy = "is in use: another plot run ({}) is writing its files; wait for it to end, or give another output directory"
    with holding(out / LOCK_FILE, lambda who: f"{option} {brief(str(out))} {busy.format(who)}"):
        held.add(key)
        try:
            yield
        finally:
            held.discard(key)


def _check_flight_data(data: object) -> None:
    """Refuse anything but :class:`FlightData`, naming it."""
    if not isinstance(data, FlightData):
        refuse_reloaded(data, FlightData, "data")  # T42-B08
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


@house_style
def compete_figure(results: Sequence[CompeteResult], title: str = "") -> Figure:
    """Mean cumulative error per episode of each result, linear (left) and log scale (right).

    Each axes holds exactly one line per result, in order; a legend names each with its runs
    and crashes.
    """
    if isinstance(results, (str, bytes)) or not isinstance(results, Sequence) or not results or not all(isinstance(r, CompeteResult) for r in results):
        raise NeurohoverError(  # [None] was an AttributeError, [] an empty figure (fourteenth trial, T14-11)
            f"results={brief(results)} is not allowed: give a list of one or more CompeteResult (read_compete_dir or read_compete_dirs)"
        )
    from matplotlib.ticker import MaxNLocator

    heading = _title(title) or "mean cumulative error over runs"
    fig = new_figure(11.0, 4.5)
    axes = fig.subplots(1, 2)
    labels = [r.label for r in results]
    differ = _differing_conditions(results)
    curves: list[tuple[str, np.ndarray]] = []
    for r in results:
        name = r.label if labels.count(r.label) == 1 else f"{r.label} [{r.path.name}]"  # same agent twice
        label = f"{printable(name)}: {r.returns.shape[0]} runs, {r.crashes} crashes"  # names that are no UTF-8
        if differ:  # 50-step drifting episodes beside 6000-step ones were overlaid without a word (eleventh trial, S4)
            flown = ", ".join(f"{key} {_condition_text(r.conditions.get(key, '?'))}" for key in differ)
            label += "\n" + textwrap.fill(printable(flown), 70)  # lines of their own: one long line ran off the figure's edge
        curves.append((label, r.cumulative_error))
    draw_cumulative(axes, curves)
    for ax in axes:
        ax.xaxis.set_major_locator(MaxNLocator(integer=True))
    axes[0].legend(fontsize=8)
    if differ:
        heading += f" (flown under different {', '.join(differ)}: see the legend)"
    fig.suptitle(heading)
    with noting_missing_glyphs():
        fig.tight_layout()
    return fig


def _differing_conditions(results: Sequence[CompeteResult]) -> list[str]:
    """The :data:`COMPETE_CONDITIONS` whose values differ between ``results`` (a result without a summary differs)."""
    return [key for key in COMPETE_CONDITIONS if len({json.dumps(r.conditions.get(key, "?"), sort_keys=True) for r in results}) > 1]


def _condition_text(value) -> str:
    text = "none" if value is None else value if isinstance(value, str) else json.dumps(value, sort_keys=True, separators=(",", ":"))
    return text if len(text) <= 60 else text[:57] + "..."


@house_style
def plot_compete(dirs: Sequence[str | Path], out: str | Path) -> tuple[Path, Figure]:
    """Overlay the compete results in ``dirs`` (:func:`compete_figure`) and write the PNG ``out``; ``dirs`` is checked
    as :func:`read_compete_dirs` says."""
    results = read_compete_dirs(dirs)
    fig = compete_figure(results)
    return save_figure(fig, out), fig


@house_style
def draw_cumulative(axes, curves: list[tuple[str, np.ndarray]]) -> None:
    """Each (label, cumulative error after each episode) on a linear and a log panel (the paper's Figs 4 and 7)."""
    for label, error in curves:
        episodes = np.arange(1, error.size + 1)
        for ax in axes:
            ax.plot(episodes, error, label=label)
    axes[0].set_ylabel("cumulative error (-cumulative reward)")
    axes[1].set_yscale("log")
    axes[1].set_ylabel("cumulative error (log scale)")
    for ax in axes:
        ax.set_xlabel("episode")
        ax.grid(alpha=0.3)


@house_style
def plot_cumulative(curves: Mapping[str, object], path: str | Path, title: str) -> Path:
    """Mean cumulative error per episode of each agent, linear and log scale (paper Figs 4 and 7), written as the PNG
    ``path`` as :func:`save_figure` writes one (a name ending .png). ``curves``: label -> cumulative rewards after each
    episode, a 2-D array of runs x episodes (the mean over runs is drawn) or a 1-D one of one run, of finite numbers <= 0."""
    # Object-oriented matplotlib (no pyplot): the caller's backend and pyplot figures stay as they are.
    drawn = [(printable(label), -(cumulative / cumulative.shape[0]).sum(axis=0)) for label, cumulative in _cumulative_curves(curves)]
    heading = _title(title)
    path = output_file(path, "plot file", suffixes=(".png",), what="a plot is PNG")  # 'cum.pdf' got PNG bytes (T40-B11)
    fig = new_figure(11.0, 4.0, dpi=110)
    axes = fig.subplots(1, 2)
    draw_cumulative(axes, drawn)
    for ax in axes:
        ax.legend()
    fig.suptitle(heading)
    with noting_missing_glyphs():
        fig.tight_layout()
    return save_figure(fig, path)


def _cumulative_curves(curves: object) -> list[tuple[str, np.ndarray]]:
    """:func:`plot_cumulative`'s ``curves`` as (label, runs x episodes float64 array), or one message naming the bad
    curve and what is allowed: a str path and a list, None or text curve were AttributeErrors, NaN, 3-D or no curves
    drawn without a word (T40-B09, T40-B11)."""
    allowed = "a 2-D array of runs x episodes (or 1-D, one run) of cumulative rewards, finite numbers <= 0, at least one episode"
    if not isinstance(curves, Mapping) or not curves:
        raise NeurohoverError(f"curves={brief(curves)} is not allowed: give a dict of one or more label -> {allowed}")
    checked = []
    for label, values in curves.items():
        if not isinstance(label, str):
            raise NeurohoverError(f"curves' label {brief(label)} is not allowed: give text naming the curve")
        try:
            array = np.asarray(values)
        except (ValueError, TypeError):  # ragged nested lists
            array = np.asarray(None)
        if isinstance(values, np.ma.MaskedArray) or array.dtype.kind not in "fiu" or array.ndim not in (1, 2) or array.size == 0:
            got = f" of shape {array.shape}" if array.dtype.kind in "fiu" else f"={brief(values)}"
            raise NeurohoverError(f"curve {brief(label)}{got} is not allowed: give {allowed}")
        array = np.atleast_2d(array.astype(np.float64))
        bad = ~(np.isfinite(array) & (array <= 0))
        if bad.any():  # every reward is minus a sum of squares
            raise NeurohoverError(f"curve {brief(label)}'s entry {brief(float(array[bad][0]))} is not allowed: give {allowed}")
        checked.append((label, array))
    return checked
