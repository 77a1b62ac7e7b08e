"""The twenty-seventh bad-input trial's findings in experiment configs and results stores (T27-A06 to T27-A09), and the
report's "weaker" verdict: a config of one's own could take compete's own experiment name ``compete-TASK-AGENT``
(T27-A06); a damaged sessions row was refused by report alone, while results, wins, reproduce and compete read on and
reproduce wrote a new session into the store (T27-A07); the drift change_at message called a given change_at the default,
blamed a group for an experiment-wide drift and suggested the command line's syntax inside a config (T27-A08); compete and
reproduce of another experiment wrote into a store SQLite calls malformed (T27-A09); a paper p of "< 0.01" against ours
0.03 read "holds", not "same direction, weaker"."""

from __future__ import annotations

import hashlib
import sqlite3
from pathlib import Path

import pytest
from conftest import CliRun, tiny_test_runs
from store_edits import COMPETE, competed_store, damaged, dump, error

from neurohover.errors import NeurohoverError
from neurohover.experiments import LocalExecutor, Store, reproduce
from neurohover.experiments import config as configs
from neurohover.experiments.config import load_config
from neurohover.experiments.report_base import verdict


@pytest.fixture(scope="module")
def tiny(tmp_path_factory) -> tuple[Path, Path]:
    """A tiny config (tr1: baseline, one 20-step run of 2 episodes) and a store holding it; tests damage copies."""
    from neurohover.cli import main

    where = tmp_path_factory.mktemp("tiny27c")
    config = where / "tr1.toml"
    config.write_text(tiny_test_runs("baseline"))
    assert main(["reproduce", str(config), "--store", str(where / "s.sqlite"), "--no-progress"]) == 0
    return config, where / "s.sqlite"


@pytest.fixture(scope="module")
def competed(tmp_path_factory) -> Path:
    """A store that one tiny compete run (baseline on ghh08) wrote; tests damage copies of it."""
    return competed_store(tmp_path_factory.mktemp("compete27c"))


def _digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


# ------------------------------------------------------------------------------------------------ T27-A06


def test_a06_a_config_may_not_take_competes_name(tmp_path: Path, cli: CliRun) -> None:
    config = tmp_path / "c.toml"
    config.write_text(tiny_test_runs("baseline", name="compete-ghh08-baseline"))
    store = tmp_path / "s.sqlite"
    rc, _, err = cli("reproduce", str(config), "--store", str(store), "--no-progress")
    assert rc == 2, err
    assert (
        f"config {str(config)!r}: name = 'compete-ghh08-baseline' is not allowed: it is in the name space compete-TASK-AGENT of "
        "`neurohover compete`'s own experiments; a config of your own needs a name of its own (not starting with 'compete-')"
    ) in error(err, "reproduce")
    assert not store.exists()
    with Store(tmp_path / "api.sqlite") as db, pytest.raises(NeurohoverError, match="name space compete-TASK-AGENT"):
        reproduce(load_config(str(config), "quick"), db, LocalExecutor(1), progress=False)


def test_a06_one_predicate_names_what_the_code_writes() -> None:
    named = configs.code_written_name
    assert named(configs.compete_name("ghh08", "baseline")) and configs.compete_name("ghh08", "baseline") == "compete-ghh08-baseline"
    assert named("fig2") and named("table3") and named("all")
    assert named("competition") is None and named("mini") is None


def test_a06_competes_own_name_still_runs(competed: Path) -> None:
    with Store(competed, create=False) as db:
        assert [name for name, *_ in db.experiments()] == ["compete-ghh08-baseline"]


# ------------------------------------------------------------------------------------------------ T27-A07


def test_a07_a_damaged_session_is_refused_by_every_command_before_anything_is_written(tiny, tmp_path: Path, cli: CliRun) -> None:
    config, good = tiny
    store = damaged(good, tmp_path / "d.sqlite", "UPDATE sessions SET wall_seconds = -1")
    line = f"results store {str(store)!r}: experiment tr1 (quick), session 1's wall seconds is damaged (-1.0 is no number of seconds >= 0)"
    before = dump(store)
    for argv, command in (
        (("results", "tr1", "--store", str(store)), "results"),
        (("wins", "tr1", "--store", str(store), "--runs", "1", "--draws", "10"), "wins"),
        (("reproduce", str(config), "--store", str(store), "--no-progress"), "reproduce"),
    ):
        rc, _, err = cli(*argv)
        assert rc == 2 and error(err, command) == line, (argv, err)
    rc, _, err = cli("report", "--store", str(store), "--out", str(tmp_path / "r"))
    assert rc == 2 and line in err, err
    assert dump(store) == before


def test_a07_compete_refuses_its_damaged_session(competed: Path, tmp_path: Path, cli: CliRun) -> None:
    store = damaged(competed, tmp_path / "d.sqlite", "UPDATE sessions SET wall_seconds = -1")
    before = dump(store)
    rc, _, err = cli(*COMPETE, "--out", str(tmp_path / "c"), "--store", str(store))
    assert rc == 2 and "session 1's wall seconds is damaged (-1.0 is no number of seconds >= 0)" in error(err, "compete"), err
    assert dump(store) == before


# ------------------------------------------------------------------------------------------------ T27-A08


def test_a08_a_given_change_at_on_the_command_line_is_not_called_the_default(tmp_path: Path, cli: CliRun) -> None:
    rc, _, err = cli(*COMPETE, "--out", str(tmp_path / "c"), "--drift", "D_w=0.8@200-800")
    assert rc == 2 and error(err, "compete") == (
        "--drift 'D_w=0.8@200-800' with --episodes 2: drift change_at=[200, 800] can come after the last of a test run's 2 episodes, "
        "so some runs would never change: give change_at within 0..1 (e.g. D_w=0.8@1-1) or more episodes"
    )
    rc, _, err = cli(*COMPETE, "--out", str(tmp_path / "c"), "--drift", "D_w=0.8")  # the default is still said
    assert rc == 2 and "drift change_at=[200, 800] (the default where no @LO-HI is given)" in err, err


@pytest.mark.parametrize(
    ("drift", "said"),
    [
        (
            "drift = { change = { D_w = 0.8 }, change_at = [200, 800] }",
            "the experiment's drift (every group's): drift change_at=[200, 800] can come after",
        ),
        (
            "drift = { change = { D_w = 0.8 } }",
            "the experiment's drift (every group's): drift change_at=[200, 800] (the default where the drift table gives no change_at) can come",
        ),
    ],
)
def test_a08_a_configs_drift_is_named_where_it_is_given_in_config_syntax(tmp_path: Path, drift: str, said: str) -> None:
    text = tiny_test_runs("baseline", "model-free", name="mini").replace('policies = "shipped"\n', f'policies = "shipped"\n{drift}\n')
    config = tmp_path / "c.toml"
    config.write_text(text)
    with pytest.raises(NeurohoverError) as err:
        load_config(str(config), "quick")
    assert said in str(err.value) and "(e.g. change_at = [1, 1])" in str(err.value) and "group 'baseline'" not in str(err.value), err.value


def test_a08_a_groups_own_drift_is_blamed_on_the_group(tmp_path: Path) -> None:
    text = tiny_test_runs("baseline", name="mini").replace("n_mdps = 1\n", "n_mdps = 1\ndrift = { change = { D_w = 0.8 }, change_at = [0, 5] }\n")
    config = tmp_path / "c.toml"
    config.write_text(text)
    with pytest.raises(NeurohoverError, match=r"group 'baseline': drift change_at=\[0, 5\] can come after .*\(e\.g\. change_at = \[0, 1\]\)"):
        load_config(str(config), "quick")


# ------------------------------------------------------------------------------------------------ T27-A09


def _garbled(good: Path, at: Path) -> Path:
    """A copy of ``good`` with garbage over the units table's root page: SQLite's quick_check calls it malformed."""
    with sqlite3.connect(good) as conn:
        page = conn.execute("PRAGMA page_size").fetchone()[0]
        root = conn.execute("SELECT rootpage FROM sqlite_master WHERE name = 'units'").fetchone()[0]
    conn.close()
    at.write_bytes(good.read_bytes())
    with open(at, "r+b") as f:
        f.seek((root - 1) * page)
        f.write(b"\xab" * page)
    return at


def test_a09_a_malformed_store_is_not_written(tiny, tmp_path: Path, cli: CliRun) -> None:
    config, good = tiny
    store = _garbled(good, tmp_path / "g.sqlite")
    before = _digest(store)
    other = tmp_path / "tr2.toml"  # another experiment: it was run and written into the damaged file
    other.write_text(config.read_text().replace('name = "tr1"', 'name = "tr2"'))
    rc, _, err = cli("reproduce", str(other), "--store", str(store), "--no-progress")
    assert rc == 2 and error(err, "reproduce").startswith(f"results store {str(store)!r} is damaged: SQLite's quick_check says "), err
    assert "nothing was written into it" in err
    rc, _, err = cli(*COMPETE, "--out", str(tmp_path / "c"), "--store", str(store))
    assert rc == 2 and "SQLite's quick_check says" in error(err, "compete") and not (tmp_path / "c").exists(), err
    with Store(store, create=False) as db, pytest.raises(NeurohoverError, match="quick_check"):
        db.start_session("tr2", "quick", "0" * 16, "local", 1, 0)
    assert _digest(store) == before


def test_a09_a_sound_store_is_checked_once_per_open(tiny, tmp_path: Path, monkeypatch) -> None:
    import neurohover.experiments.store as store_module

    _, good = tiny
    store = tmp_path / "s.sqlite"
    store.write_bytes(good.read_bytes())
    calls: list[int] = []
    monkeypatch.setattr(store_module, "sqlite_says", lambda conn: calls.append(1) or "")
    with Store(store, create=False) as db:
        assert db.experiments() and not calls  # reading runs no check
        db.lock()
        session = db.start_session("tr1", "quick", db.config_hash("tr1", "quick"), "local", 1, 1)
        db.end_session(session, "finished")
    assert calls == [1]


# ------------------------------------------------------------------------------------------------ weaker verdict


@pytest.mark.parametrize(
    ("paper", "ours", "said"),
    [
        ("< 0.01", 0.03, "same direction, weaker (p >= 0.01 here)"),  # read "holds"
        ("< 0.01", 0.005, "holds"),
        ("0.009", 0.03, "same direction, weaker (p >= 0.01 here)"),
        ("0.01", 0.03, "holds"),  # 0.01 is not significant at 1%
        ("<= 0.01", 0.03, "holds"),
        ("< 0.0026", 0.03, "same direction, weaker (p >= 0.01 here)"),
        ("< 0.05", 0.03, "holds"),  # T27-A03: significant at 5%, not stated at 1%
        ("< 0.05", 0.2, "same direction, not significant"),
        ("0.0402", 0.03, "holds"),
        ("5.8e-12", 0.001, "holds"),
    ],
)
def test_the_weaker_verdict_follows_the_papers_own_level(paper: str, ours: float, said: str) -> None:
    assert verdict("a", 2.0, 1.0, ours, paper) == said


def test_a_group_label_is_as_long_as_a_name_at_most(tmp_path: Path) -> None:
    """Trial 27 (borderline): a group label of 5,000 characters was taken, where an experiment's name has at most 100."""
    config = tmp_path / "c.toml"
    long = "a" * 5000
    config.write_text(tiny_test_runs("baseline").replace('agent = "baseline"\n', f'agent = "baseline"\nlabel = "{long}"\n'))
    with pytest.raises(NeurohoverError, match=r"group label 'aaaa.*\(5,000 characters\) is not allowed: give at most 100 characters"):
        load_config(config, "quick")
    config.write_text(tiny_test_runs("baseline").replace('agent = "baseline"\n', f'agent = "baseline"\nlabel = "{long[:100]}"\n'))
    assert load_config(config, "quick").settings["groups"][0]["label"] == long[:100]
