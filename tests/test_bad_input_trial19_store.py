"""The nineteenth bad-input trial's findings in damaged results stores: a refused reproduce leaves the store as it was
(T19-04); wins refuses the damage results refuses, by the same check (T19-05); compete refuses a damaged config or units
whose config is gone, and does not rewrite it (T19-06); report says each damaged experiment on stderr and exits 2 when
nothing could be reported (T19-07); results' messages name the store and the unit (T19-14). The twentieth trial's: every
command refuses a config hash that is not its config's, or a unit's that is not its experiment's (T20-04), and a unit key
of no shape the experiment's plan gives (T20-05)."""

from __future__ import annotations

import sqlite3
from pathlib import Path

import pytest
from conftest import CliRun, tiny_test_runs
from store_edits import COMPETE, competed_store, damaged, dump, error

from neurohover.errors import NeurohoverError
from neurohover.experiments import LocalExecutor, Store, reproduce
from neurohover.experiments.config import make_config

RUN = "run/baseline/test0/rep0"


@pytest.fixture(scope="module")
def tiny(tmp_path_factory) -> tuple[Path, Path]:
    """A config of two agents (tr1: baseline and generic, one 20-step run of 2 episodes each) and a store holding its
    two finished test runs; tests damage copies of the store."""
    from neurohover.cli import main

    where = tmp_path_factory.mktemp("tiny19")
    config = where / "tr1.toml"
    config.write_text(tiny_test_runs("baseline", "generic"))
    assert main(["reproduce", str(config), "--store", str(where / "s.sqlite"), "--no-progress"]) == 0
    return config, where / "s.sqlite"


@pytest.fixture(scope="module")
def competed(tmp_path_factory) -> Path:
    """A store that one tiny compete run (baseline on ghh08, one run) wrote; tests damage copies of it."""
    return competed_store(tmp_path_factory.mktemp("compete19"))


@pytest.mark.parametrize("sql", ["ALTER TABLE units DROP COLUMN result", "DROP TABLE units", "ALTER TABLE sessions DROP COLUMN status"])
def test_a_refused_reproduce_leaves_a_store_of_damaged_tables_as_it_was(tiny, tmp_path: Path, cli: CliRun, sql: str) -> None:
    """T19-04: reproduce into a store whose units table lacked a column wrote a new experiments row, then said the store
    was damaged; now the damage is found when the store is opened, before anything is written."""
    config, good = tiny
    store = damaged(good, tmp_path / "s.sqlite", sql)
    before = dump(store)
    other = tmp_path / "other.toml"  # an experiment the store does not hold yet: its row was the one written
    other.write_text(config.read_text().replace('name = "tr1"', 'name = "tr2"'))
    rc, _, err = cli("reproduce", str(other), "--store", str(store), "--no-progress")
    assert rc == 2 and f"results store {str(store)!r} is damaged: its table" in err, err
    assert dump(store) == before


def test_a_refused_reproduce_of_damaged_units_writes_nothing(tiny, tmp_path: Path) -> None:
    """T19-04: a stored unit that does not read back was found after begin() had rewritten the experiment's config;
    now the stored units are checked first."""
    config, good = tiny
    path = damaged(good, tmp_path / "s.sqlite", f"UPDATE units SET kind = 'bogus' WHERE key = '{RUN}'")
    with sqlite3.connect(path) as conn:
        conn.execute("UPDATE experiments SET config = json_set(config, '$.title', 'older title')")
    conn.close()
    before = dump(path)
    from neurohover.experiments import load_config

    with Store(path) as store, pytest.raises(NeurohoverError, match=f"experiment tr1 \\(quick\\), is damaged: unit '{RUN}': unknown unit kind 'bogus'"):
        reproduce(load_config(str(config), "quick"), store, LocalExecutor(1), progress=False)
    assert dump(path) == before


@pytest.mark.parametrize(
    ("sql", "says"),
    [
        (f"UPDATE units SET kind = 'bogus' WHERE key = '{RUN}'", f"unit '{RUN}': unknown unit kind 'bogus'"),
        (f"UPDATE units SET params = '[1,2' WHERE key = '{RUN}'", f"unit {RUN}'s params is damaged (not JSON"),
        (f"UPDATE units SET seconds = -5 WHERE key = '{RUN}'", f"unit {RUN}'s seconds is damaged (-5.0 is no number of seconds >= 0)"),
        (f"UPDATE units SET kind = 'evolve' WHERE key = '{RUN}'", f"result of evolve unit '{RUN}': missing key(s)"),
    ],
)
def test_wins_refuses_the_damage_results_refuses(tiny, tmp_path: Path, cli: CliRun, sql: str, says: str) -> None:
    """T19-05: wins printed a full table (a unit of kind 'bogus' counted as a test run) where results called the store
    damaged; now both read the experiment through one check and say the same."""
    store = damaged(tiny[1], tmp_path / "s.sqlite", sql)
    rc, out, err = cli("wins", "tr1", "--store", str(store), "--runs", "1", "--draws", "10")
    assert rc == 2 and out == "" and says in err and str(store) in err, err
    rc, _, err_results = cli("results", "tr1", "--store", str(store))
    assert rc == 2 and error(err_results, "results") == error(err, "wins")


@pytest.mark.parametrize(
    ("sql", "says"),
    [
        ("UPDATE experiments SET config = 'nope'", "'s config is damaged (not JSON"),
        ("UPDATE experiments SET config = '[]'", "'s config is damaged (a JSON list, not an object)"),
        ("UPDATE experiments SET config = '{}'", "is damaged: a stored experiment config is damaged"),
        ("DELETE FROM experiments", "is damaged: it holds 1 finished unit(s) of it but no record of its config"),
    ],
)
def test_compete_refuses_a_damaged_config_and_leaves_the_store_as_it_was(competed: Path, tmp_path: Path, cli: CliRun, sql: str, says: str) -> None:
    """T19-06: compete took a store whose config was 'nope' or '[]', or whose experiments row was gone while its units
    stayed, said "1 of 1 units reused" and wrote the config anew; now it refuses, writing nothing."""
    store = damaged(competed, tmp_path / "s.sqlite", sql)
    before = dump(store)
    rc, _, err = cli(*COMPETE, "--out", str(tmp_path / "c"), "--store", str(store))
    assert rc == 2 and says in err and str(store) in err and "reused" not in err, err
    assert dump(store) == before


@pytest.mark.slow
def test_report_warns_of_each_damaged_experiment_and_exits_2_when_none_is_reported(tiny, tmp_path: Path, cli: CliRun) -> None:
    """T19-07: a report of a store whose every experiment was damaged exited 0 with "report written", the damage said
    only inside report.md; now each damaged experiment is one warning line on stderr, and nothing reported is exit 2."""
    store = damaged(tiny[1], tmp_path / "s.sqlite", f"UPDATE units SET kind = 'bogus' WHERE key = '{RUN}'")
    rc, out, err = cli("report", "--store", str(store), "--out", str(tmp_path / "r"))
    warning = f"neurohover report: warning: tr1 (quick) is not reported: results store {str(store)!r}, experiment tr1 (quick), is damaged: unit '{RUN}'"
    assert rc == 2 and out == "" and warning in err and "nothing could be reported" in err, err
    assert not (tmp_path / "r").exists()
    with Store(store) as held:  # a second experiment, undamaged: reported as before, the damaged one warned of
        cfg = make_config(
            "e2",
            "test_runs",
            "quick",
            dict(task="ghh08", seed=1, policies="shipped", episodes=2, n_steps=20, groups=[dict(agent="baseline", mdps="test", n_mdps=1)]),
        )
        reproduce(cfg, held, LocalExecutor(1), progress=False)
    rc, out, err = cli("report", "--store", str(store), "--out", str(tmp_path / "r"))
    assert rc == 0 and "report written" in out and err.count("warning:") == 1 and warning in err, err
    text = (tmp_path / "r" / "report.md").read_text()
    assert "## e2 [quick]" in text and "**Not reported: the store's copy is damaged.**" in text


@pytest.mark.parametrize(
    ("sql", "says"),
    [
        (f"UPDATE units SET kind = 'bogus' WHERE key = '{RUN}'", "unknown unit kind 'bogus'"),
        (
            f"UPDATE units SET result = json_set(result, '$.score', 'nan') WHERE key = '{RUN}'",
            "is inconsistent: its score 'nan' is not the sum of its 2 returns",
        ),
    ],
)
def test_results_names_the_store_and_the_unit(tiny, tmp_path: Path, cli: CliRun, sql: str, says: str) -> None:
    """T19-14: results said "unknown unit kind 'bogus'" and "test run of baseline on ... is inconsistent" naming neither
    the store nor the unit."""
    store = damaged(tiny[1], tmp_path / "s.sqlite", sql)
    rc, _, err = cli("results", "tr1", "--store", str(store))
    assert rc == 2 and f"results store {str(store)!r}, experiment tr1 (quick), is damaged: unit '{RUN}': " in err and says in err, err


@pytest.mark.parametrize(
    ("sql", "says"),
    [
        ("UPDATE experiments SET config_hash = 'deadbeef'", "but the store records config hash 'deadbeef'"),
        ("UPDATE experiments SET config = json_remove(config, '$.hash')", "(its config: None)"),
        (
            "UPDATE experiments SET config = json_set(config, '$.settings.seed', 2)",
            "the config or its hash was changed after its units were run",
        ),
        (f"UPDATE units SET config_hash = 'x' WHERE key = '{RUN}'", f"unit '{RUN}' was run under config hash 'x', not the experiment's"),
    ],
)
def test_every_command_refuses_a_config_hash_that_is_not_its_configs(tiny, tmp_path: Path, cli: CliRun, sql: str, says: str) -> None:
    """T20-04: an experiment whose config_hash was 'deadbeef' was exported and reported (rc 0), and a unit run under
    hash 'x' was reused by reproduce; now the shared check refuses both, in results, wins, report and reproduce alike."""
    config, good = tiny
    store = damaged(good, tmp_path / "s.sqlite", sql)
    before = dump(store)
    where = f"results store {str(store)!r}, experiment tr1 (quick), is damaged: "
    rc, out, err = cli("results", "tr1", "--store", str(store), "--format", "json")
    assert rc == 2 and out == "" and where in err and says in err, err
    rc, _, err = cli("wins", "tr1", "--store", str(store), "--runs", "1", "--draws", "10")
    assert rc == 2 and where in err and says in err, err
    rc, _, err = cli("report", "--store", str(store), "--out", str(tmp_path / "r"))
    assert rc == 2 and where in err and says in err and not (tmp_path / "r").exists(), err
    rc, _, err = cli("reproduce", str(config), "--store", str(store), "--no-progress")
    assert rc == 2 and where in err and says in err and "already in the store" not in err, err
    assert dump(store) == before


@pytest.mark.parametrize("key", ["run/../../x", "run/baseline/test0/rep00", "model/lr/test0", "u00"])
def test_every_command_refuses_a_unit_key_of_no_planned_shape(tiny, tmp_path: Path, cli: CliRun, key: str) -> None:
    """T20-05: a unit key changed to 'run/../../x' was exported by results and drawn by report (rc 0), and wins said "no
    stored test runs"; now the shared check refuses a key of no shape the experiment's kind plans, naming the unit."""
    store = damaged(tiny[1], tmp_path / "s.sqlite", f"UPDATE units SET key = '{key}' WHERE key = 'run/generic/test0/rep0'")
    says = f"experiment tr1 (quick), is damaged: unit {key!r}: its key is of no shape a test_runs experiment plans"
    for argv in (
        ("results", "tr1", "--store", str(store)),
        ("results", "tr1", "--store", str(store), "--format", "json"),
        ("wins", "tr1", "--store", str(store), "--runs", "1", "--draws", "10"),
        ("report", "--store", str(store), "--out", str(tmp_path / "r")),
    ):
        rc, out, err = cli(*argv)
        assert rc == 2 and says in err and "report written" not in out, (argv, err)
    assert not (tmp_path / "r").exists()


def test_the_shared_check_keeps_a_sound_store_and_a_diagnostic_units_own_key(tiny, tmp_path: Path) -> None:
    """T20-04, T20-05: the sound store reads back whole, and a 'diagnostic' unit (the tests' own plans name them
    freely) is not refused for its key."""
    from neurohover.experiments.export import checked_units

    with Store(tiny[1], create=False) as store:
        config, units, results = checked_units(store, "tr1", "quick")
    assert config.hash and sorted(results) == [RUN, "run/generic/test0/rep0"] and len(units) == 2
    store_path = damaged(tiny[1], tmp_path / "s.sqlite", f"DELETE FROM units WHERE key != '{RUN}'")
    with sqlite3.connect(store_path) as conn:
        conn.execute("UPDATE units SET key = 'u00', kind = 'diagnostic', result = '{\"value\":1,\"seed\":3}'")
        conn.execute("UPDATE sessions SET units_run = 1")  # the session ran the one unit left (the shared check reads sessions: T27-A07)
    conn.close()
    with Store(store_path, create=False) as store:
        assert list(checked_units(store, "tr1", "quick")[2]) == ["u00"]


def test_an_experiment_row_whose_config_is_of_another_scale_is_refused(tiny, tmp_path: Path, cli: CliRun) -> None:
    """T21-01: a copy of a quick experiment's row at scale 'paper' was reported as a paper-scale section, its quick
    numbers printed under "Claims and conclusions (paper scale)"; the shared check now refuses the row."""
    store = damaged(tiny[1], tmp_path / "s.sqlite", "INSERT INTO experiments SELECT name, 'paper', config_hash, config, created FROM experiments")
    says = f"results store {str(store)!r}, experiment tr1 (paper), is damaged: its row is at scale 'paper' but its config is the 'quick' one"
    rc, _, err = cli("report", "--store", str(store), "--out", str(tmp_path / "r"), "--scale", "paper")
    assert rc == 2 and says in err, err
