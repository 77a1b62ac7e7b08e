"""``neurohover plot`` and neurohover.plots on real files: flights from ``fly --record``, results of ``compete``.

(tests/test_plots.py checks that report and compete leave matplotlib's global state alone.)"""

from __future__ import annotations

import csv
import shutil
import struct
import subprocess
import sys
from pathlib import Path

import matplotlib.image as mpimg
import numpy as np
import pytest

import neurohover as nh
from neurohover.cli import main
from neurohover.compete_files import read_compete_dir
from neurohover.errors import NeurohoverError
from neurohover.flightdata import FlightData
from neurohover.plots import (
    CRASH_COLOR,
    attitude_angles,
    compete_figure,
    crashed_episode,
    flight_figure,
    plot_compete,
    plot_flight_data,
)
from neurohover.policies import prototype, save_policy

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def png_size(path: Path) -> tuple[int, int]:
    """(width, height) of a PNG file, after checking that it is one and that it decodes."""
    data = path.read_bytes()
    assert data[:8] == PNG_SIGNATURE and data[12:16] == b"IHDR"
    width, height = struct.unpack(">II", data[16:24])
    image = mpimg.imread(path)
    assert image.shape[:2] == (height, width)
    return width, height


@pytest.fixture(scope="module")
def files(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """Real inputs: two baseline flights, one crashing flight, and two compete result directories."""
    root = tmp_path_factory.mktemp("plots")
    flight, crash = root / "flights" / "baseline.npz", root / "flights" / "fall.npz"
    assert main(["fly", "--task", "ghh08", "--mdp", "test:3", "--episodes", "2", "--record", str(flight), "--json"]) == 0
    falling = save_policy(prototype("slp", "zero"), root / "zero.json")  # collective 0: falls within a second
    assert main(["fly", "--task", "ghh09", "--policy", str(falling), "--episodes", "1", "--record", str(crash), "--json"]) == 0
    compete = {}
    for agent in ("baseline", "model-free"):
        compete[agent] = root / "results" / agent
        assert main(["compete", "--task", "ghh08", "--agent", agent, "--runs", "2", "--episodes", "4", "--out", str(compete[agent])]) == 0
    return {"flight": flight, "crash": crash, "baseline": compete["baseline"], "model-free": compete["model-free"], "root": root}


# -- flights ----------------------------------------------------------------------------------


@pytest.mark.slow
def test_plot_writes_one_png_per_episode_beside_the_file(files, capsys) -> None:
    capsys.readouterr()
    assert main(["plot", str(files["flight"])]) == 0
    written = capsys.readouterr().out.split()
    expected = [files["flight"].parent / f"baseline-episode{i}.png" for i in range(2)]
    assert [Path(p) for p in written] == expected
    for path in expected:
        width, height = png_size(path)
        assert (width, height) == (1000, 1100) and path.stat().st_size > 50_000  # five panels of 6000 steps


@pytest.mark.slow
def test_plot_out_dir_is_created(files, capsys) -> None:
    out = files["root"] / "new" / "plots"
    assert main(["plot", str(files["crash"]), "--out", str(out)]) == 0
    assert sorted(p.name for p in out.iterdir()) == ["fall-episode0.png"]
    assert png_size(out / "fall-episode0.png") == (1000, 1100)
    assert "created directory" in capsys.readouterr().err


@pytest.mark.slow
def test_flight_figure_panels_hold_the_episode(files) -> None:
    data = FlightData.load(files["flight"])
    obs, act = data.observations[0], data.actions[0]
    fig = flight_figure(obs, act, title="t")
    axes = fig.axes
    assert [len(ax.lines) for ax in axes] == [3, 3, 3, 3, 4]  # no crash line
    np.testing.assert_array_equal(axes[0].lines[1].get_ydata(), obs[:, 4])  # y position error
    np.testing.assert_array_equal(axes[1].lines[0].get_ydata(), obs[:, 0])  # u
    np.testing.assert_array_equal(axes[3].lines[2].get_ydata(), obs[:, 8])  # r
    np.testing.assert_array_equal(axes[4].lines[3].get_ydata(), act[:, 3])  # collective
    assert axes[0].lines[0].get_xdata()[-1] == pytest.approx(600.0)  # 6000 steps at 10 Hz
    assert "no crash" in fig._suptitle.get_text()


def test_crash_is_marked(files) -> None:
    data = FlightData.load(files["crash"])
    obs, act = data.observations[0], data.actions[0]
    assert crashed_episode(act) and len(act) < 6000 and data.metadata["returns"][0] < -1e6
    fig = flight_figure(obs, act)
    for ax in fig.axes:
        crash_lines = [ln for ln in ax.lines if ln.get_color() == CRASH_COLOR]
        assert len(crash_lines) == 1 and crash_lines[0].get_xdata()[0] == pytest.approx(0.1 * len(act))
    assert f"crashed at {0.1 * len(act):.1f} s" in fig._suptitle.get_text()
    assert not crashed_episode(FlightData.load(files["flight"]).actions[0])


@pytest.mark.slow
def test_plot_flight_data_titles_from_the_metadata(files, tmp_path: Path) -> None:
    data = FlightData.load(files["flight"])
    paths = plot_flight_data(data, tmp_path, stem="x")
    assert [p.name for p in paths] == ["x-episode0.png", "x-episode1.png"]
    from neurohover.plots import _episode_title

    title = _episode_title(data, 1, "x")
    assert "ghh08/test:3" in title and f"return {data.metadata['returns'][1]:.6g}" in title and "policy baseline" in title


def test_attitude_angles_of_known_rotations() -> None:
    obs = np.zeros((4, 12))
    half = np.radians(10.0) / 2
    obs[1, 9] = np.sin(half)  # 10 degrees about the body x axis: roll
    obs[2, 10] = np.sin(half)  # pitch
    obs[3, 11] = np.sin(half)  # yaw
    np.testing.assert_allclose(attitude_angles(obs), [[0, 0, 0], [10, 0, 0], [0, 10, 0], [0, 0, 10]], atol=1e-9)


# -- competitions -----------------------------------------------------------------------------


def test_compete_overlay_has_one_line_per_directory(files) -> None:
    results = [read_compete_dir(files["baseline"]), read_compete_dir(files["model-free"])]
    assert [r.label for r in results] == ["baseline (ghh08)", "model-free (ghh08)"]
    assert all(r.returns.shape == (2, 4) for r in results)
    fig = compete_figure(results)
    linear, log = fig.axes
    assert len(linear.lines) == len(log.lines) == 2
    assert log.get_yscale() == "log"
    # The curve is the mean cumulative error, recomputed here from the CSV itself.
    with open(files["baseline"] / "episodes.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    per_run = np.array([[float(row["return"]) for row in rows if row["run"] == str(r)] for r in (0, 1)])
    np.testing.assert_allclose(linear.lines[0].get_ydata(), -np.cumsum(per_run, axis=1).mean(axis=0))
    labels = [t.get_text() for t in linear.get_legend().get_texts()]
    assert labels[0].startswith("baseline (ghh08): 2 runs") and labels[1].startswith("model-free (ghh08)")


@pytest.mark.slow
def test_compete_overlay_of_three_directories(files, tmp_path: Path) -> None:
    again = tmp_path / "baseline-again"  # the same agent twice (a directory given twice is refused)
    shutil.copytree(files["baseline"], again)
    dirs = [files["baseline"], files["model-free"], again]
    path, fig = plot_compete(dirs, tmp_path / "three.png")
    assert all(len(ax.lines) == 3 for ax in fig.axes)
    assert png_size(path) == (1100, 450)


@pytest.mark.slow
def test_plot_compete_command(files, capsys) -> None:
    capsys.readouterr()
    assert main(["plot", "--compete", str(files["baseline"]), str(files["model-free"])]) == 0
    written = Path(capsys.readouterr().out.strip())
    assert written == files["baseline"].parent / "compete.png"  # default: beside the first directory
    assert png_size(written) == (1100, 450) and written.stat().st_size > 20_000
    out = files["root"] / "overlay"
    assert main(["plot", "--compete", str(files["baseline"]), "--out", str(out)]) == 0
    assert png_size(out / "compete.png") == (1100, 450)


def test_compete_runs_of_unequal_length_are_refused_and_equal_ones_read(tmp_path: Path) -> None:
    """compete writes whole runs: a shorter one is a file cut short, refused (it was plotted cut; eighth trial)."""
    (tmp_path / "episodes.csv").write_text("run,mdp,episode,return,crashed\n0,m,0,-1,0\n0,m,1,-2,1\n1,m,0,-3,0\n")
    with pytest.raises(NeurohoverError, match="run 1 has 1 episodes where run 0 has 2: the file is cut short"):
        read_compete_dir(tmp_path)
    (tmp_path / "episodes.csv").write_text("run,mdp,episode,return,crashed\n0,m,0,-1,0\n0,m,1,-2,1\n1,m,0,-3,0\n1,m,1,-4,0\n")
    result = read_compete_dir(tmp_path)
    assert result.returns.tolist() == [[-1.0, -2.0], [-3.0, -4.0]] and result.crashes == 1
    assert result.label == tmp_path.name  # no summary.json: the directory's name


@pytest.mark.parametrize("rows", ["0,m,-5,-1,0\n", "0,m,0,-1,0\n0,m,0,-2,0\n", "-1,m,0,-1,0\n"], ids=["negative", "repeated", "negative-run"])
def test_compete_episodes_numbered_impossibly_are_refused_with_the_line(rows: str, tmp_path: Path) -> None:
    """Fifth trial: a negative or repeated episode number was plotted without a word."""
    (tmp_path / "episodes.csv").write_text("run,mdp,episode,return,crashed\n" + rows)
    with pytest.raises(NeurohoverError, match="episodes.csv', line [23]: run -?[01], episode -?[05] is negative or given twice"):
        read_compete_dir(tmp_path)
    (tmp_path / "episodes.csv").write_text("run,mdp,episode,return,crashed\n0,m,0,-1,0\n0,m,2,-1,0\n")
    with pytest.raises(NeurohoverError, match="run 0 lacks episode 1: each run's episodes are numbered 0, 1, 2"):
        read_compete_dir(tmp_path)  # plotted as 0, 1 (sixth trial)


# -- bad input: one message, exit status 2 ----------------------------------------------------


@pytest.fixture
def bad(files, tmp_path: Path) -> dict[str, str]:
    (tmp_path / "afile").write_text("x")
    (tmp_path / "policy.json").write_text('{"topology": "slp", "genome": []}')
    (tmp_path / "empty").mkdir()
    (tmp_path / "badcsv").mkdir()
    (tmp_path / "badcsv" / "episodes.csv").write_text("a,b\n1,2\n")
    for name, summary in (
        ("badsummary", "{not json"),
        ("oddsummary", '{"agent": 5}'),
        ("ghh10summary", '{"agent": "baseline", "task": "ghh10"}'),  # another task's or competition's summary (eighth trial)
        ("runssummary", '{"agent": "baseline", "task": "ghh08", "runs": 2, "episodes": 1}'),
        ("episodessummary", '{"agent": "baseline", "task": "ghh08", "runs": 1, "episodes": 1.0}'),
        ("twicesummary", '{"agent": "baseline", "agent": "model-free", "task": "ghh08"}'),  # the last was kept (ninth trial)
    ):
        (tmp_path / name).mkdir()
        (tmp_path / name / "episodes.csv").write_text("run,mdp,episode,return,crashed\n0,m,0,-1,0\n")
        (tmp_path / name / "summary.json").write_text(summary)
    return {"dir": str(tmp_path), "flight": str(files["flight"]), "compete": str(files["baseline"])}


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["{dir}/missing.npz"], "FLIGHT '{dir}/missing.npz': no such flight-data file"),
        (["{dir}/policy.json"], "is not a neurohover flight-data file"),
        (["{dir}/empty"], "is a directory; give a flight-data file"),
        (["{flight}", "--out", "/proc/plots"], "--out '/proc/plots': cannot"),
        (["{flight}", "--out", "{dir}/afile"], "is a file; give a directory"),
        (["--compete", "{dir}/empty"], "holds no episodes.csv: give directories written by neurohover compete --out"),
        (["--compete", "{compete}", "{dir}/nothere"], "--compete '{dir}/nothere': no such directory"),
        (["--compete", "{dir}/badcsv"], "is not a compete episodes file: no column run, episode, return"),
        (["--compete", "{compete}", "--out", "/proc/plots"], "--out '/proc/plots': cannot"),
        (["--compete", "{dir}/badsummary"], "summary.json' cannot be read (Expecting property name"),
        (["--compete", "{dir}/oddsummary"], "summary.json' is not a compete summary: no agent and task names"),
        (["--compete", "{dir}/ghh10summary"], "summary.json' names task 'ghh10', not one of ghh08, "),
        (["--compete", "{dir}/runssummary"], "summary.json' says runs 2 where its episodes.csv holds 1: the two are of different"),
        (["--compete", "{dir}/episodessummary"], "summary.json' says episodes 1.0 where its episodes.csv holds 1"),
        (["--compete", "{dir}/twicesummary"], "summary.json' cannot be read (key 'agent' is given more than once)"),
        (["--compete", "{compete}", "--episodes", "0"], "--episodes picks episodes of a flight-data file; it does not apply to --compete"),
        (["{flight}", "--episodes", "0,0"], "--episodes '0,0' names episode 0 more than once"),
        (["{flight}", "--episodes", "0-1,1"], "--episodes '0-1,1' names episode 1 more than once"),
        ([], "nothing to plot"),
        (["{flight}", "--compete", "{compete}"], "not both"),
    ],
)
def test_bad_input_is_one_message_and_exit_2(bad, capsys, args: list[str], message: str) -> None:
    capsys.readouterr()
    assert main(["plot", *[a.format(**bad) for a in args]]) == 2
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert lines[-1].startswith("neurohover plot: error: ") and message.format(**bad) in lines[-1]
    assert captured.out == ""


@pytest.mark.slow
def test_bad_input_in_a_real_process(tmp_path: Path) -> None:
    run = subprocess.run([sys.executable, "-m", "neurohover", "plot", str(tmp_path / "none.npz")], capture_output=True, text=True)
    assert run.returncode == 2 and "Traceback" not in run.stderr
    assert run.stderr.strip() == f"neurohover plot: error: FLIGHT '{tmp_path / 'none.npz'}': no such flight-data file"


@pytest.mark.slow
def test_plot_draws_only_the_episodes_asked_for(tmp_path: Path, capsys) -> None:
    from neurohover.cli import main

    flights = tmp_path / "f.npz"
    nh.evaluate(nh.baseline_policy(), nh.get_task_family("ghh08").zero(), episodes=4, record=True, n_steps=40).flight_data.save(flights)
    assert main(["plot", str(flights), "--episodes", "0,2-3"]) == 0
    assert sorted(p.name for p in tmp_path.glob("*.png")) == ["f-episode0.png", "f-episode2.png", "f-episode3.png"]
    capsys.readouterr()
    assert main(["plot", str(flights), "--episodes", "4"]) == 2
    assert "--episodes '4' is out of range: the flight data hold episodes 0..3" in capsys.readouterr().err


def test_a_deliberately_short_episode_is_not_marked_crashed(tmp_path) -> None:
    """issue 37: an episode flown for fewer than 6000 steps was drawn as a crash; the recording now carries each flag."""
    from neurohover import Policy, baseline_policy, evaluate, get_task_family
    from neurohover.flightdata import FlightData
    from neurohover.plots import episode_crashed

    mdp = get_task_family("ghh08").zero()
    rolling = baseline_policy().genome.copy()
    rolling[36] += 0.5  # rolls over within a few hundred steps
    ev = evaluate([baseline_policy(), Policy("slp", rolling)], mdp, n_steps=400, seed=1, record=True)
    data = ev.flight_data
    assert data.metadata["crashed"] == [bool(c) for c in ev.crashed.ravel()] == [False, True]
    assert [episode_crashed(data, i) for i in range(2)] == [False, True]  # the short baseline episode is no crash
    data.save(tmp_path / "f.npz")
    again = FlightData.load(tmp_path / "f.npz")
    assert [episode_crashed(again, i) for i in range(2)] == [False, True]
    both = data + data  # joined recordings keep every episode's flag
    assert both.metadata["crashed"] == [False, True, False, True]
    old = FlightData(data.observations, data.actions, {})  # a file recorded before the flags: the length rule
    assert [episode_crashed(old, i) for i in range(2)] == [True, True]
