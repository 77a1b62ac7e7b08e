"""Issue 37, the eleventh fresh trial: its findings about files, paths, plots, reports and the environment (T3, T4, T5,
T9, S5, S7, S9, U3, U8 in part) each give one clear message (exit 2 / NeurohoverError) or are taken as a user would
expect."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from conftest import tiny_test_runs

from neurohover.errors import NeurohoverError


@pytest.mark.parametrize("value", ["abc", "2", ""])
def test_the_cuda_simulator_variable_numba_cannot_take_is_named(value: str, tmp_path: Path) -> None:
    """T5: NUMBA_ENABLE_CUDASIM=abc was numba's warning with a traceback, then its default (0), from every command."""
    env = {**os.environ, "NUMBA_ENABLE_CUDASIM": value}
    proc = subprocess.run([sys.executable, "-m", "neurohover", "--help"], env=env, cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2 and proc.stdout == "", proc.stderr
    assert proc.stderr == (
        f"neurohover: error: environment variable NUMBA_ENABLE_CUDASIM={value!r} is not allowed: give 0 or 1 "
        "(1: numba's CUDA simulator stands in for a GPU), or unset it\n"
    )


@pytest.fixture
def tiny_store(tmp_path: Path, cli) -> Path:
    """A store holding one tiny experiment (tr1, quick scale), its file name holding a byte that is no UTF-8."""
    config = tmp_path / "tr1.toml"
    config.write_text(tiny_test_runs("baseline"))
    store = tmp_path / "s\udcff.sqlite"  # the byte 0xff, as Python keeps it
    rc, _, err = cli("reproduce", str(config), "--store", str(store), "--no-progress")
    assert rc == 0, err
    return store


@pytest.mark.slow
def test_a_report_on_a_store_whose_name_is_no_utf8_is_written(tiny_store: Path, tmp_path: Path, cli) -> None:
    """T3: report.md copies the store's name, and a byte that is no UTF-8 in it was a UnicodeEncodeError after the
    figures were written (report.md missing); the name is now escaped as messages show it."""
    rc, _, err = cli("report", "--store", str(tiny_store), "--out", str(tmp_path / "repA"))
    assert rc == 0, err
    text = (tmp_path / "repA" / "report.md").read_text()
    assert f"from the results store `{tmp_path}/s\\udcff.sqlite`" in text


def test_a_failed_write_report_removes_the_directory_it_created(tiny_store: Path, tmp_path: Path) -> None:
    """S9 and U8: write_report(scale='x') announced the directory it created and left it when it failed, as the
    command line does not; the message said the store "holds no experiment '(any)'"."""
    from neurohover.experiments import Store
    from neurohover.experiments.report import write_report

    (tmp_path / "keep").mkdir()  # an empty directory of the user's own stays
    with Store(tiny_store) as store, pytest.raises(NeurohoverError) as caught:
        write_report(store, tmp_path / "keep" / "rep3" / "deeper", scale="x")
    assert str(caught.value) == f"results store '{tmp_path}/s\\udcff.sqlite' holds nothing at scale 'x'; it holds: tr1 (quick)"
    assert not (tmp_path / "keep" / "rep3").exists() and (tmp_path / "keep").is_dir()


def test_a_closed_store_is_named_as_closed_not_damaged(tiny_store: Path) -> None:
    """U3: a closed Store was "results store ... is damaged: its list of experiments cannot be read", of a good file."""
    from neurohover.experiments import Store

    store = Store(tiny_store)
    store.close()
    store.close()  # closing again does nothing
    for call in (store.experiments, lambda: store.results("tr1", "quick"), store.lock):
        with pytest.raises(NeurohoverError, match=r"^this Store \('.*s\\udcff.sqlite'\) was closed: open it again with Store\(path\)$"):
            call()
    assert Store(tiny_store).experiments()[0][:2] == ("tr1", "quick")


def _flight_data(path: Path, policy: str) -> Path:
    """A 5-step recording (zeros) that names ``policy`` as its flier, saved to ``path``."""
    import numpy as np

    from neurohover import FlightData

    FlightData((np.zeros((6, 12)),), (np.zeros((5, 4)),), {"policy": policy, "episode_steps": 5, "crashed": [False]}).save(path)
    return path


@pytest.mark.slow
def test_flight_data_whose_file_or_policy_name_is_no_utf8_is_plotted(tmp_path: Path) -> None:
    """T4: a flight-data file, or the policy its metadata names, whose name holds a byte that is no UTF-8 was
    matplotlib's TypeError from the figure's title (``neurohover plot`` takes the file's name as the stem); the title
    now shows it escaped, as messages do."""
    from neurohover import FlightData
    from neurohover.plots import flight_figure, plot_flight_data

    data = FlightData.load(_flight_data(tmp_path / "x\udcff.npz", "p\udcff"))
    (written,) = plot_flight_data(data, tmp_path, stem="x\udcff")
    assert written == tmp_path / "x\udcff-episode0.png" and written.stat().st_size > 0
    title = flight_figure(np.zeros((6, 12)), np.zeros((5, 4)), title="p\udcff").texts[0].get_text()
    assert title.startswith("p\\udcff\n")


def _compete_dir(path: Path) -> Path:
    """A compete output directory of one run of two episodes (episodes.csv only: labelled by its name)."""
    path.mkdir()
    (path / "episodes.csv").write_text("run,episode,return\n0,0,-1\n0,1,-2\n")
    return path


@pytest.mark.slow
def test_compete_curves_named_with_bytes_that_are_no_utf8_are_plotted(tmp_path: Path, cli) -> None:
    """T4: a competition directory named with a byte that is no UTF-8 labels its curve; it was matplotlib's TypeError."""
    rc, _, err = cli("plot", "--compete", str(_compete_dir(tmp_path / "c\udcff")), "--out", str(tmp_path / "pl"))
    assert rc == 0 and (tmp_path / "pl" / "compete.png").is_file(), err


@pytest.mark.parametrize("value", [None, 5])
def test_read_compete_dir_and_policy_dir_name_a_value_that_is_no_path(value) -> None:
    """T9: read_compete_dir(None) and (5) were pathlib's TypeError, policy_dir(None) a TypeError on '/'."""
    from neurohover.compete_files import read_compete_dir
    from neurohover.policysets import policy_dir

    with pytest.raises(NeurohoverError, match=rf"^--compete={value!r} is not allowed: give a directory$"):
        read_compete_dir(value)
    with pytest.raises(NeurohoverError, match=rf"^unknown task {value!r}: allowed ghh08, ghh09, fghh$"):
        policy_dir(value)


def test_plot_compete_refuses_what_the_command_line_refuses(tmp_path: Path) -> None:
    """S5: plot_compete([]) wrote an empty figure and plot_compete([c1, c1]) overlaid one run on itself (the command
    line refuses both); "c1" alone was read as the directories c and 1."""
    from neurohover.plots import plot_compete

    c1 = _compete_dir(tmp_path / "c1")
    for dirs in ([], str(c1)):
        with pytest.raises(NeurohoverError, match=r"is not allowed: give a list of one or more directories written by neurohover compete --out$"):
            plot_compete(dirs, tmp_path / "x.png")
    with pytest.raises(NeurohoverError, match=r"--compete names '.*c1' more than once: give each competition's directory once$"):
        plot_compete([c1, f"{c1}/"], tmp_path / "y.png")
    assert not (tmp_path / "x.png").exists() and not (tmp_path / "y.png").exists()
    assert plot_compete([c1], tmp_path / "z.png")[0].is_file()


@pytest.mark.parametrize("stem", ["../zz", "", "a/b", None])
def test_plot_flight_data_refuses_a_stem_that_is_no_file_name_prefix(stem, tmp_path: Path) -> None:
    """S5: stem='../zz' wrote ./zz-episode0.png outside out_dir, stem='' the file '-episode0.png'."""
    from neurohover import FlightData
    from neurohover.plots import plot_flight_data

    data = FlightData.load(_flight_data(tmp_path / "f.npz", "baseline"))
    (tmp_path / "pl").mkdir()
    with pytest.raises(NeurohoverError, match=r"is not allowed: give a non-empty file-name prefix without a path separator, e.g. 'flight'$"):
        plot_flight_data(data, tmp_path / "pl", stem=stem)
    assert list((tmp_path / "pl").iterdir()) == [] and not (tmp_path / "zz-episode0.png").exists()


def test_a_dash_is_no_output_file_name(tmp_path: Path, cli, monkeypatch) -> None:
    """S7: '-' as an output path (fly --record -, results --out -) wrote a hidden-looking file named '-'."""
    from neurohover.paths import output_dir, output_file

    monkeypatch.chdir(tmp_path)
    rc, _, err = cli("fly", "--task", "ghh08", "--episodes", "1", "--record", "-")
    assert rc == 2 and "--record '-' is not a file name here: give a file name (./- for one called '-')" in err, err
    with pytest.raises(NeurohoverError, match=r"^--out '-' is not a file name here: leave --out out for standard output$"):
        output_file("-", "--out", stdout=True)
    with pytest.raises(NeurohoverError, match=r"^--out '-' is not a directory name here: give a directory name \(./- for one called '-'\)$"):
        output_dir("-", "--out")
    assert list(tmp_path.iterdir()) == []
    assert output_file("./-", "--out") == Path("-")  # a file of that name, asked for as such


def test_fghh_budget_beside_another_task_says_to_leave_it_out(cli, tmp_path: Path) -> None:
    """U8: "... not to 'ghh08': give budget" named the Python parameter where the user typed --budget."""
    rc, _, err = cli("build-policies", "--task", "ghh08", "--out", str(tmp_path / "bp"), "--budget", "20", "--fghh-budget", "10")
    assert (
        rc == 2
        and (
            "fghh_budget (--fghh-budget) applies to task fghh (its generics over G), not to 'ghh08': leave it out "
            "(budget, --budget on the command line, sizes every policy of this task)"
        )
        in err
    ), err


@pytest.mark.slow
def test_overlaid_competitions_name_the_conditions_they_differ_in(tmp_path: Path) -> None:
    """S4: 50-step drifting episodes were overlaid on 6000-step ones as if comparable; summary.json kept neither."""
    import json

    from neurohover.compete import compete
    from neurohover.plots import plot_compete
    from neurohover.tasks.drift import Drift

    compete("ghh08", "baseline", runs=1, episodes=2, n_steps=20, out=tmp_path / "a")
    compete("ghh08", "baseline", runs=1, episodes=2, n_steps=30, out=tmp_path / "b", drift=Drift.parse("walk=0.1"))
    summary = json.loads((tmp_path / "b" / "summary.json").read_text())
    assert summary["episode_steps"] == 30 and summary["drift"] == Drift.parse("walk=0.1").to_dict() and summary["sensor"] is None
    _, fig = plot_compete([tmp_path / "a", tmp_path / "b"], tmp_path / "ab.png")
    labels = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert labels[0] == "baseline (ghh08) [a]: 1 runs, 0 crashes\nepisode_steps 20, drift none" and "\nepisode_steps 30, drift {" in labels[1], labels
    assert "(flown under different episode_steps, drift: see the legend)" in fig.texts[0].get_text()
    compete("ghh08", "model-free", runs=1, episodes=2, n_steps=20, out=tmp_path / "c")
    _, fig = plot_compete([tmp_path / "a", tmp_path / "c"], tmp_path / "ac.png")  # alike: labelled as before
    assert [t.get_text() for t in fig.axes[0].get_legend().get_texts()] == ["baseline (ghh08): 1 runs, 0 crashes", "model-free (ghh08): 1 runs, 0 crashes"]
