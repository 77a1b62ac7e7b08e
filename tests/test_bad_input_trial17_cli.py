"""The seventeenth trial's findings on the command line, the experiments and the path checks (T17-1, T17-5, T17-10,
T17-11): each bad input gives one clear NeurohoverError naming the value and what is allowed, instead of a traceback
or a message that contradicts itself."""

from __future__ import annotations

import datetime
import re
from decimal import Decimal
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest

from neurohover.errors import NeurohoverError

NOT_LISTS = [
    5,
    5.0,
    True,
    np.bool_(True),
    np.int64(5),
    np.array(5),
    np.ma.masked,
    Fraction(1, 2),
    Decimal(1),
    1j,
    datetime.timedelta(1),
    np.timedelta64(5, "s"),
    {"fig2"},
    np.array(["fig2"]),
]


@pytest.mark.parametrize("names", NOT_LISTS, ids=lambda v: type(v).__name__)
def test_write_report_refuses_names_that_are_no_list(names, tmp_path: Path) -> None:
    """T17-5: write_report(store, out, names=5) was "TypeError: 'int' object is not iterable" (any number, a 0-d array,
    np.ma.masked); parse_overrides(5) the same. A list or tuple of names still works."""
    from neurohover.experiments import Store, write_report
    from neurohover.experiments.config import parse_overrides

    store = Store(tmp_path / "s.sqlite")
    with pytest.raises(NeurohoverError, match=re.escape("is not allowed: give a list of experiment names, e.g. ['fig2']")):
        write_report(store, tmp_path / "rep", names=names)
    assert not (tmp_path / "rep").exists()
    for good in (["fig2"], ("fig2",)):  # a list or tuple of names is read, and the missing one named
        with pytest.raises(NeurohoverError, match=re.escape("holds no experiment 'fig2'")):
            write_report(store, tmp_path / "rep", names=good)
    with pytest.raises(NeurohoverError, match=re.escape("is not allowed: give a list of KEY=VALUE texts, or None")):
        parse_overrides(names)
    assert parse_overrides(["runs=3"]) == {"runs": 3} and parse_overrides(None) == {}


@pytest.mark.parametrize("td", [np.timedelta64(5, "s"), np.timedelta64(4)], ids=["seconds", "no unit"])
def test_a_timedelta_is_no_whole_number_of_the_experiments(td) -> None:
    """T17-1: np.timedelta64 (a np.signedinteger) passed the np.integer checks of choose_safe's n (then a TypeError of a
    slice) and build_policy_set's sizes (accepted), and a unit's history_points (NumPy's TypeError mid-run)."""
    from neurohover.experiments import load_config, plan
    from neurohover.experiments.params import unit_params
    from neurohover.policysets import check_build, choose_safe
    from neurohover.tasks import get_task_family

    crashes, returns = np.zeros((3, 3)), np.ones((3, 3))
    with pytest.raises(NeurohoverError, match=re.escape(f"n={td!r} is out of range: allowed an integer in 1..3")):
        choose_safe(crashes, returns, td)
    assert choose_safe(crashes, returns, np.int64(2)) == (0, 1)
    family = get_task_family("ghh08")
    sizes = {"budget": 3, "n_steps": 20, "safety_episodes": 1, "seed": 0}
    with pytest.raises(NeurohoverError, match=re.escape(f"budget={td!r} is out of range: allowed a whole number")):
        check_build(family, None, None, "ne", **{**sizes, "budget": td})
    assert check_build(family, None, None, "ne", **sizes)[0] == "chain"
    params = plan(load_config("fig7", "quick"), {}).units[0].params
    with pytest.raises(NeurohoverError, match=re.escape(f"'evolve' unit's params: history_points = {td!r} is not allowed: give a whole number")):
        unit_params("evolve", {**params, "history_points": td})
    assert unit_params("evolve", {**params, "history_points": np.int64(7)}).history_points == 7


@pytest.mark.parametrize("scale", ["", "  "])
@pytest.mark.parametrize("command", [["wins", "fig7"], ["results", "fig7"], ["report", "--out", "OUT"]])
def test_an_empty_scale_is_refused(command: list[str], scale: str, tmp_path: Path, cli, capsys) -> None:
    """T17-10: --scale '' was read as no scale given: "holds no experiment 'X'; it holds: X (...)" and "holds nothing;
    it holds: ..." contradicted themselves. A real scale is still looked up."""
    from neurohover.cli import main
    from neurohover.experiments import Store

    store = tmp_path / "s.sqlite"
    Store(store).close()
    argv = [a.replace("OUT", str(tmp_path / "rep")) for a in command] + ["--store", str(store)]
    with pytest.raises(SystemExit) as stop:  # argparse's refusal of the option's value
        main([*argv, "--scale", scale])
    err = capsys.readouterr().err
    assert stop.value.code == 2 and f"argument --scale: {scale!r} is not allowed: give quick, paper or a compete run's settings-HASH" in err, err
    rc, _, err = cli(*argv, "--scale", "quick")
    assert rc == 2 and "holds no experiment" in err and "not allowed" not in err, err
    with Store(store) as s:  # the Python API's message keeps its '' (its clause was dropped, as on the command line)
        assert "holds no experiment 'x' at scale ''" in s.missing_message("x", "")


def test_a_symbolic_link_loop_is_named_not_called_missing(tmp_path: Path, cli) -> None:
    """T17-11: a symbolic-link loop was "no such results store", "no such flight-data file", "no such directory" or
    "cannot create the directory (File exists)"; a link to a real store still works."""
    from neurohover.experiments import Store
    from neurohover.paths import input_dir, input_file, output_dir, output_file

    loop = tmp_path / "loopA"
    (tmp_path / "loopB").symlink_to(loop)
    loop.symlink_to(tmp_path / "loopB")
    why = "cannot be read (too many levels of symbolic links)"
    store = tmp_path / "s.sqlite"
    Store(store).close()
    runs = {
        "--store": [
            ["wins", "x", "--store", str(loop)],
            ["results", "x", "--store", str(loop)],
            ["report", "--store", str(loop), "--out", str(tmp_path / "r")],
        ],
        "FLIGHT": [["plot", str(loop)]],
        "--compete": [["plot", "--compete", str(loop)]],
        "--out": [["report", "--store", str(store), "--out", str(loop)], ["report", "--store", str(store), "--out", str(loop / "sub")]],
    }
    for option, argvs in runs.items():
        for argv in argvs:
            rc, _, err = cli(*argv)
            assert rc == 2 and f"{option} {str(loop)!r}" in err.replace(str(loop / "sub"), str(loop)) and why in err, err
    for check in (input_file, input_dir, output_dir, output_file):
        with pytest.raises(NeurohoverError, match=re.escape(f"--x {str(loop)!r} {why}")):
            check(loop, "--x")
    (tmp_path / "link.sqlite").symlink_to(store)
    rc, _, err = cli("wins", "x", "--store", str(tmp_path / "link.sqlite"))
    assert rc == 2 and "holds no experiment" in err, err
