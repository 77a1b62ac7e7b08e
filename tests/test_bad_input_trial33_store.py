"""Bad-input trial 33 (the Python API and hand-edited stores): writes a store's own readers then called damaged
(T33-B17: an executor of no session, a unit result of no shape its kind has), counts past SQLite's integers (T33-B18),
and a store whose trigger dropped each unit written (T33-B14)."""

from __future__ import annotations

import sqlite3
from pathlib import Path

import pytest
import store_edits as SE

from neurohover.errors import NeurohoverError
from neurohover.experiments import Store, Unit
from neurohover.experiments.export import checked_units

# T33-B17 ------------------------------------------------------------------------------------------------------------


def test_a_session_of_an_executor_that_runs_none_is_refused_and_the_sessions_still_read(tmp_path: Path) -> None:
    with Store(tmp_path / "s.sqlite") as store:
        h = SE.begin(store)
        for executor in ("LOCAL", "other"):
            with pytest.raises(NeurohoverError, match=f"start_session: executor = '{executor}' is not allowed: give one of 'local', 'ray'"):
                store.start_session("tr1", "quick", h, executor, 1, 0)
        assert store.sessions("tr1", "quick") == []


@pytest.mark.slow
def test_a_unit_result_its_readers_would_call_damaged_is_refused_before_it_is_written(tmp_path: Path) -> None:
    """A test run's result {'x': 1}, and one whose MDP is not its unit's, were stored; results and report then
    refused the whole experiment as damaged."""
    path = SE.competed_store(tmp_path)
    with Store(path) as store:
        name, scale, h, _ = store.experiments()[0]
        unit = store.units(name, scale)[0]
        good = store.results(name, scale)[unit["key"]]
        other = Unit(name, unit["key"] + "x", "test_run", unit["params"])
        with pytest.raises(NeurohoverError, match=r"put: result of test_run unit '.*x': missing key\(s\) agent, .*: give the result run_unit returned"):
            store.put(name, scale, h, other, {"x": 1}, 1.0)
        with pytest.raises(NeurohoverError, match="put: mdp = 'ghh08/test:9' is not allowed: its unit's params.mdp.label is 'ghh08/test:0'"):
            store.put(name, scale, h, other, {**good, "mdp": "ghh08/test:9"}, 1.0)
        checked_units(store, name, scale)  # what results and report read: sound, as before
        assert len(store.units(name, scale)) == 1


# T33-B18 ------------------------------------------------------------------------------------------------------------


def test_counts_past_sqlites_integers_are_refused_by_name(tmp_path: Path) -> None:
    with Store(tmp_path / "s.sqlite") as store:
        h = SE.begin(store)
        big = r"1000000000\.\.\.\(31 digits\) is not allowed"
        with pytest.raises(NeurohoverError, match=rf"start_session: cores = {big}: give a whole number >= 1 \(at most 1,048,576"):  # T47-B12
            store.start_session("tr1", "quick", h, "local", 10**30, 0)
        with pytest.raises(NeurohoverError, match=f"end_session: session = {big}"):
            store.end_session(10**30, "finished")
        assert store.start_session("tr1", "quick", h, "local", 2**20, 0) == 1  # the most cores a session records (T47-B12)


# T33-B14 ------------------------------------------------------------------------------------------------------------


@pytest.mark.slow
def test_a_store_holding_a_trigger_is_refused_naming_it_and_compete_makes_no_output(tmp_path: Path, cli) -> None:
    path = SE.damaged(SE.competed_store(tmp_path), tmp_path / "t.sqlite", "CREATE TRIGGER t BEFORE INSERT ON units BEGIN SELECT RAISE(IGNORE); END")
    rc, _, err = cli(*SE.COMPETE, "--out", str(tmp_path / "o"), "--store", str(path))
    assert rc == 2 and f"results store {str(path)!r} holds a trigger 't' neurohover did not make; give another --store file" in err, err
    assert not (tmp_path / "o").exists()


def test_a_unit_the_store_drops_as_it_is_written_is_refused_not_taken_as_stored(tmp_path: Path) -> None:
    """A trigger made while the store was open (or an index of someone else's) dropped each insert: compete ended in
    "summarise needs at least one test run: results holds none"."""
    with Store(tmp_path / "s.sqlite") as store:
        h = SE.begin(store)
        with sqlite3.connect(store.path) as other:
            other.execute("CREATE TRIGGER t AFTER INSERT ON units BEGIN DELETE FROM units WHERE key = new.key; END")
        other.close()
        with pytest.raises(NeurohoverError, match=r"did not keep unit 'k1' of tr1 \(quick\): its write was dropped"):
            store.put("tr1", "quick", h, Unit("tr1", "k1", "diagnostic", {}), {"value": 1, "seed": None}, 1.0)
