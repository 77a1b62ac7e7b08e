"""The fourteenth bad-input trial's findings in the plots (neurohover.plots), the shared writer (paths.writing) and the
result lines of fly, compete and plot: each bad value gives one NeurohoverError naming it and what is allowed, and no
device, pipe or socket is ever replaced by an output file."""

from __future__ import annotations

import os
import re
import stat
from pathlib import Path

import numpy as np
import pytest

from neurohover.compete_files import read_compete_dir
from neurohover.errors import NeurohoverError
from neurohover.flightdata import FlightData
from neurohover.paths import printable, write_png, writing
from neurohover.plots import (
    attitude_angles,
    compete_figure,
    crashed_episode,
    flight_figure,
    new_figure,
    plot_compete,
    plot_flight_data,
    save_figure,
)

NOT_REGULAR = "is not a regular file (a device, pipe or socket); give a file path"
OBS, ACT = np.zeros((6, 12)), np.zeros((5, 4))


def _fifo(tmp_path: Path, name: str = "fifo") -> Path:
    path = tmp_path / name
    os.mkfifo(path)  # a FIFO, never the real /dev/full or /dev/null, stands for every file that is not a regular one
    return path


def _is_fifo(path: Path) -> bool:
    return stat.S_ISFIFO(os.stat(path).st_mode)


def _compete_dir(path: Path) -> Path:
    path.mkdir()
    (path / "episodes.csv").write_text("run,episode,return\n0,0,-1.0\n0,1,-2.0\n")
    return path


def test_save_figure_and_plot_compete_refuse_a_fifo_and_keep_it(tmp_path: Path) -> None:
    """T14-1: save_figure(fig, FIFO) and plot_compete(dirs, FIFO) returned the path, the FIFO (as root: /dev/full itself)
    replaced by a PNG."""
    fifo = _fifo(tmp_path)
    with pytest.raises(NeurohoverError, match=re.escape(f"plot file '{fifo}' {NOT_REGULAR}")):
        save_figure(new_figure(2, 2), fifo)
    with pytest.raises(NeurohoverError, match=re.escape(f"plot file '{fifo}' {NOT_REGULAR}")):
        plot_compete([_compete_dir(tmp_path / "c")], fifo)
    assert _is_fifo(fifo)


def test_save_figure_refuses_what_is_no_figure_or_no_path(tmp_path: Path) -> None:
    """T14-1: save_figure(None, p) was an AttributeError, save_figure(fig, 5) a TypeError."""
    with pytest.raises(NeurohoverError, match="fig=None is not allowed: give a matplotlib Figure"):
        save_figure(None, tmp_path / "a.png")  # type: ignore[arg-type]
    with pytest.raises(NeurohoverError, match="plot file=5 is not allowed: give a file path"):
        save_figure(new_figure(2, 2), 5)  # type: ignore[arg-type]
    assert list(tmp_path.iterdir()) == []


def test_writing_never_replaces_a_fifo(tmp_path: Path) -> None:
    """T14-1, in depth: paths.writing itself, under every writer, refuses a FIFO there before the block and one made
    while it ran, leaving no partial file."""
    fifo = _fifo(tmp_path)
    with pytest.raises(NeurohoverError, match=re.escape(f"report '{fifo}' {NOT_REGULAR}")):
        with writing(fifo, "report"):
            raise AssertionError("the block must not run")
    with pytest.raises(NeurohoverError, match=re.escape(f"report figure '{fifo}' {NOT_REGULAR}")):
        write_png(new_figure(2, 2), fifo, "report figure")
    later = tmp_path / "later"
    with pytest.raises(NeurohoverError, match=re.escape(f"table '{later}' {NOT_REGULAR}")):
        with writing(later, "table") as partial:
            partial.write_text("x")
            os.mkfifo(later)
    assert _is_fifo(fifo) and _is_fifo(later) and sorted(p.name for p in tmp_path.iterdir()) == ["fifo", "later"]


@pytest.mark.slow
def test_plot_flight_data_refuses_a_bad_out_dir_episodes_data_or_metadata(tmp_path: Path) -> None:
    """T14-10: a FIFO as out_dir was NotADirectoryError, episodes=0 "'int' object is not iterable", data None an
    AttributeError and metadata episode_steps "x" int()'s ValueError."""
    data = FlightData([OBS], [ACT], {})
    fifo = _fifo(tmp_path)
    cases = [
        (lambda: plot_flight_data(data, fifo), re.escape(f"out_dir '{fifo}' is a file; give a directory")),
        (lambda: plot_flight_data(data, tmp_path, episodes=0), r"episodes=0 is not allowed: give a list of episode indices, e\.g\. \[0, 2\]"),  # type: ignore[arg-type]
        (lambda: plot_flight_data(data, tmp_path, episodes="0"), "episodes='0' is not allowed: give a list of episode indices"),
        (lambda: plot_flight_data(data, tmp_path, episodes=[True]), r"episode True is not allowed: give integer indices: the flight data hold episodes 0\.\.0"),
        (lambda: plot_flight_data(data, tmp_path, episodes=[1]), r"episode 1 is out of range: the flight data hold episodes 0\.\.0"),
        (lambda: plot_flight_data(data, tmp_path, episodes=[0, 0]), "episodes names episode 0 more than once: give each episode once"),
        (lambda: plot_flight_data(None, tmp_path), r"data=None is not allowed: give FlightData \(e\.g\. FlightData\.load"),  # type: ignore[arg-type]
        (
            lambda: plot_flight_data(FlightData([OBS], [ACT], {"episode_steps": "x"}), tmp_path),
            r"flight data: its metadata episode_steps='x' is not allowed: an integer in 1\.\.10,000,000",
        ),
        (lambda: plot_flight_data(FlightData([OBS], [ACT], 5), tmp_path), r"flight data: its metadata 5 is not allowed: give a dict"),  # type: ignore[arg-type]
    ]
    for call, message in cases:
        with pytest.raises(NeurohoverError, match=message):
            call()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["fifo"]  # nothing drawn
    (written,) = plot_flight_data(data, tmp_path / "new", episodes=np.array([0]))  # NumPy indices are indices
    assert written.name == "flight-episode0.png" and written.stat().st_size > 0


@pytest.mark.parametrize("observations", [np.zeros(12), np.zeros((3, 5)), "abc", None, [[0.0] * 12, [0.0]], np.full((2, 12), "a")])
def test_attitude_angles_refuses_what_is_no_observation_array(observations) -> None:
    """T14-11: a 1-D array, (3, 5), 'abc' or None was NumPy's IndexError or ValueError."""
    with pytest.raises(NeurohoverError, match=r"observations.* is not allowed: give a \(T, 12\) array of real numbers"):
        attitude_angles(observations)


def test_flight_figure_refuses_bad_shapes_titles_and_flags() -> None:
    """T14-11: observations (3, 5) or an empty episode were IndexErrors, a title None or b"x" a TypeError or
    AttributeError; crashed="x" was taken as true."""
    cases = [
        (lambda: flight_figure(np.zeros((3, 5)), ACT), r"observations of shape \(3, 5\) is not allowed: give a \(T \+ 1, 12\) array"),
        (lambda: flight_figure(OBS, np.zeros((5, 3))), r"actions of shape \(5, 3\) is not allowed: give a \(T, 4\) array"),
        (lambda: flight_figure(np.zeros((0, 12)), np.zeros((0, 4))), r"shape \(0, 12\) and actions of shape \(0, 4\) are not one episode: .* T >= 1"),
        (lambda: flight_figure(OBS, np.zeros((6, 4))), r"shape \(6, 12\) and actions of shape \(6, 4\) are not one episode"),
        (lambda: flight_figure(OBS, ACT, title=None), r"title=None is not allowed: give text \(''"),  # type: ignore[arg-type]
        (lambda: flight_figure(OBS, ACT, title=b"x"), "title=b'x' is not allowed: give text"),  # type: ignore[arg-type]
        (lambda: flight_figure(OBS, ACT, crashed="x"), "crashed='x' is not allowed: give True, False or None"),  # type: ignore[arg-type]
        (lambda: flight_figure(OBS, ACT, episode_steps=0), r"episode_steps=0 is not allowed: give an integer in 1\.\.10,000,000"),
    ]
    for call, message in cases:
        with pytest.raises(NeurohoverError, match=message):
            call()


@pytest.mark.parametrize("steps", ["x", float("nan"), -1, 0, True, 10**8])
def test_crashed_episode_refuses_what_is_no_episode_length(steps) -> None:
    """T14-11: 'x' was a TypeError, nan and -1 said "no crash" without a word."""
    with pytest.raises(NeurohoverError, match=r"episode_steps=.* is not allowed: give an integer in 1\.\.10,000,000"):
        crashed_episode(ACT, steps)


def test_crashed_episode_refuses_what_is_no_action_array() -> None:
    """T14-11: the actions are checked as flight_figure checks them."""
    with pytest.raises(NeurohoverError, match=r"actions=None is not allowed: give a \(T, 4\) array of real numbers"):
        crashed_episode(None, 10)  # type: ignore[arg-type]
    assert crashed_episode(ACT, np.int64(6)) and not crashed_episode(ACT, 5)


def test_compete_figure_refuses_what_is_no_result_or_title(tmp_path: Path) -> None:
    """T14-11: compete_figure([None]) was an AttributeError, [] an empty figure and title=5 a TypeError."""
    for results in ([None], [], None, "c"):
        with pytest.raises(NeurohoverError, match=r"results=.* is not allowed: give a list of one or more CompeteResult"):
            compete_figure(results)  # type: ignore[arg-type]
    result = read_compete_dir(_compete_dir(tmp_path / "c"))
    with pytest.raises(NeurohoverError, match="title=5 is not allowed: give text"):
        compete_figure([result], title=5)  # type: ignore[arg-type]
    assert compete_figure([result], title="a\nb").texts[0].get_text() == "a\\nb"


def test_printable_escapes_control_and_format_characters() -> None:
    """T14-24: printable() escaped only bytes that are no UTF-8; control characters and U+202E (RIGHT-TO-LEFT OVERRIDE)
    were shown raw, splitting or reversing a result line."""
    assert printable("a\nb\x01c\u202ed\udcffe") == "a\\nb\\x01c\\u202ed\\udcffe"
    assert printable("é 日本/x.npz") == "é 日本/x.npz"  # printable text stays as it is


@pytest.mark.slow
def test_result_lines_of_fly_and_plot_escape_the_names(tmp_path: Path, cli) -> None:
    """T14-24: fly --record 'a\\nb.npz' and plot --out 'p\\nq' printed the names raw (one result over two lines; U+202E
    reversed the rest of the line)."""
    record = tmp_path / "a\nb\u202e.npz"
    rc, out, err = cli("fly", "--task", "ghh08", "--mdp", "zero", "--episodes", "1", "--record", str(record))
    assert rc == 0, err
    assert f"flight data: {tmp_path}/a\\nb\\u202e.npz\n" in out and "\u202e" not in out
    rc, out, err = cli("plot", str(record), "--out", str(tmp_path / "p\nq"))
    assert rc == 0, err
    assert out == f"{tmp_path}/p\\nq/a\\nb\\u202e-episode0.png\n"


@pytest.mark.slow
def test_result_line_of_compete_escapes_the_names(tmp_path: Path, cli) -> None:
    """T14-24: compete --out 'c\\x01d' printed the control character raw in its "results:" line."""
    out_dir = tmp_path / "c\x01d"
    rc, out, err = cli("compete", "--task", "ghh08", "--agent", "baseline", "--runs", "1", "--episodes", "2", "--episode-steps", "20", "--out", str(out_dir))
    assert rc == 0, err
    assert f"results: {tmp_path}/c\\x01d/episodes.csv, {tmp_path}/c\\x01d/summary.json" in out
    assert f"store: {tmp_path}/c\\x01d/results.sqlite" in out and "\x01" not in out
