"""The twelfth trial's findings in neurohover.experiments: a config's [paper] table of the wrong shape or with values JSON
cannot hold is refused before anything runs, and make_config / reproduce / unit_seed / run_unit / LocalExecutor check
their arguments (one NeurohoverError naming the value and what is allowed)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from conftest import tiny_model_learning

from neurohover.errors import NeurohoverError
from neurohover.experiments import Store, reproduce, run_unit, unit_seed
from neurohover.experiments.config import make_config
from neurohover.experiments.executors import LocalExecutor

SETTINGS = dict(task="ghh08", seed=1, policies="shipped", episodes=2, n_steps=20, groups=[dict(agent="baseline", mdps="test", n_mdps=1)])

ML_CONFIG = tiny_model_learning("ml1", "baseline") + "\n[paper]\n"


@pytest.mark.parametrize(
    ("paper", "message"),
    [
        ('table = { lr = "abc" }', "[paper] table.lr = 'abc' is not allowed: give a table of names, each a table of numbers r_m, r_a, t, sd (r_m and r_a"),
        ("table = 5", "[paper] table = 5 is not allowed: give a table of names, each a table of numbers r_m, r_a, t, sd"),
        ('table = { lr = { t = "abc" } }', "[paper] table.lr has no r_m or r_a: allowed r_m, r_a, t, sd (r_m and r_a required)"),
        ("table = { lr = { r_m = 1, r_a = 2, t = [1, 2] } }", "[paper] table.lr.t = [1, 2] is not allowed: give a finite number"),
        ('groups = { baseline = { crash_rate = "x" } }', "[paper] groups.baseline.crash_rate = 'x' is not allowed: give a rate in 0..1"),
        ("table3 = { slp = { r = 1, x = 2 } }", "[paper] table3.slp has unknown number(s) 'x': allowed r, sd, r_G, sd_G, crashes_G"),
        ("ttests = 5", "[paper] ttests = 5 is not allowed: give a list of tables with a, b and p"),
        ('ttests = "x"', "[paper] ttests = 'x' is not allowed: give a list of tables with a, b and p"),
        ("table = { lr = { r_m = 1, r_a = 2, t = inf } }", "[paper] table.lr.t = inf is not allowed: give a finite number"),
        ("table = { lr = { r_m = 1, r_a = 2, sd = 1e400 } }", "[paper] table.lr.sd = inf is not allowed: give a finite number"),
        ('ttests = [{ a = "lr", b = "lr", p = "0.1", x = nan }]', "unknown [paper] ttests key(s) 'x' in"),  # (T27-A05: before its value)
    ],
)
def test_a_paper_table_of_the_wrong_shape_is_refused_before_reproduce_runs(tmp_path: Path, cli, paper: str, message: str) -> None:
    """Twelfth trial T1-T3: `report` crashed on [paper] table/groups of the wrong shape (after reproduce had run, the
    report half-written); ttests = 5 was a TypeError; inf/nan/1e400 a json ValueError with the store file left behind."""
    config = tmp_path / "ml1.toml"
    config.write_text(ML_CONFIG + paper + "\n", encoding="utf-8")
    store = tmp_path / "ml1.sqlite"
    rc, _, err = cli("reproduce", str(config), "--store", str(store), "--no-progress")
    assert rc == 2 and message in err, err
    assert "Traceback" not in err and not store.exists()


def test_report_says_a_stored_paper_table_of_the_wrong_shape_and_writes_the_report(tmp_path: Path) -> None:
    """Twelfth trial T1: a store written before the check (its [paper] table = { lr = "abc" }) was an AttributeError in
    `report`, which left a figure and no report.md; now its section says what is wrong and report.md is written."""
    from neurohover.experiments.report import write_report

    cfg = make_config("ml1", "test_runs", "quick", SETTINGS)
    with Store(tmp_path / "old.sqlite") as store:
        store.begin(cfg.name, cfg.scale, cfg.hash, {**cfg.to_dict(), "paper": {"groups": {"baseline": {"crash_rate": "x"}}}})
        path = write_report(store, tmp_path / "rep")
    text = path.read_text(encoding="utf-8")
    assert "the stored config: [paper] groups.baseline.crash_rate = 'x' is not allowed: give a rate in 0..1" in text


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"scale": "weird"}, "experiment 'mc1': scale = 'weird' is not allowed: give one of quick, paper (or a compete run's settings-HASH)"),
        ({"paper": "x"}, "experiment 'mc1': [paper] = 'x' is not allowed: give a table (a dict) of notes, claims, ttests"),
        ({"title": 5}, "experiment 'mc1': title = 5 is not allowed: give text"),
        ({"paper": {"groups": {"baseline": {"crash_rate": float("inf")}}}}, "[paper] groups.baseline.crash_rate = inf is not allowed: give a rate"),
        ({"paper": {"x": object()}}, "unknown [paper] key(s) 'x'; allowed: notes, claims, ttests, groups, table, table3"),
        (
            {"paper": {"ttests": [{"a": "baseline", "b": "baseline", "p": "0.1", "w": {1}}]}},
            "unknown [paper] ttests key(s) 'w' in {'a': 'baseline', 'b': 'baseline', 'p': '0.1', 'w': {1}}; allowed: a, b, p",
        ),
    ],
)
def test_make_config_checks_scale_title_and_paper(kwargs: dict, message: str) -> None:
    """Twelfth trial S7, U2, T3: make_config took scale 'weird', paper 'x' and title 5 (later "a stored experiment
    config is damaged"), and never checked paper: inf there was a json ValueError once reproduce wrote the store."""
    args = {"scale": "quick", **kwargs}
    with pytest.raises(NeurohoverError) as info:
        make_config("mc1", "test_runs", args.pop("scale"), SETTINGS, **args)
    assert message in str(info.value)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"progress": "no"}, "progress='no' is not allowed: give True, False or None"),
        ({"on_unit": 5}, "on_unit=5 is not allowed: give a callable (unit key, result), or None"),
        ({"only": [5]}, "only=[5] is not allowed: give a glob pattern of unit keys or a list of them"),
    ],
)
def test_reproduce_refuses_bad_arguments_before_any_unit_runs(tmp_path: Path, kwargs: dict, message: str) -> None:
    """Twelfth trial S7, T7: progress="no" drew the bar; on_unit=5 was a TypeError after the first unit had run."""
    with Store(tmp_path / "s.sqlite") as store:
        with pytest.raises(NeurohoverError) as info:
            reproduce(make_config("mc6", "test_runs", "quick", SETTINGS), store, LocalExecutor(1), **{"progress": False, **kwargs})
        assert message in str(info.value)
        assert store.experiments() == []


def test_reproduce_takes_a_single_only_pattern_as_one(tmp_path: Path) -> None:
    """Twelfth trial U3: only="run/*" was taken as the patterns r, u, n, ... ("--only 'r' matches no unit")."""
    with Store(tmp_path / "s.sqlite") as store:
        summary = reproduce(make_config("mc5", "test_runs", "quick", SETTINGS), store, LocalExecutor(1), progress=False, only="run/**")
    assert summary.succeeded and summary.units_run == 1


def test_unit_seed_and_run_unit_name_what_they_take() -> None:
    """Twelfth trial T7: unit_seed('x') / (-1) were int()'s and NumPy's ValueErrors; run_unit({}) a KeyError,
    run_unit('x') an AttributeError."""
    for root in ("x", -1, 2**63, 2**64):  # 2**64 was taken (sixteenth trial, T16-17)
        with pytest.raises(NeurohoverError, match=rf"root={root!r} is not allowed: give the config's seed, an integer in 0..2\*\*63-1"):
            unit_seed(root, "a", "b")
    assert unit_seed(np.int64(3), "a", "b") == unit_seed(3, "a", "b")
    unit_seed(2**63 - 1, "a", "b")  # the largest seed is still taken
    for unit in ({}, "x"):
        with pytest.raises(NeurohoverError, match=r"is not allowed: give a Unit of a plan .* a dict of experiment, key, kind and params"):
            run_unit(unit)


def test_local_executor_says_a_jobs_of_the_wrong_type_is_the_problem() -> None:
    """Twelfth trial U1: LocalExecutor('2') was "--jobs '2' is out of range: allowed an integer in 1..2" (2 is in range)."""
    with pytest.raises(NeurohoverError, match=r"--jobs '1' is not allowed: give an integer in 1\.\.\d+"):
        LocalExecutor("1")
    with pytest.raises(NeurohoverError, match=r"--jobs 1\.0 is not allowed: give an integer"):
        LocalExecutor(1.0)
    executor = LocalExecutor(np.int64(1))
    assert executor.jobs == 1 and type(executor.jobs) is int
