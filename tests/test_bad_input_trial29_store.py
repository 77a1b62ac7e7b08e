"""Trial 29b's findings in the results store's writes (T29-B04, T29-B05, T29-B06, T29-B07): start_session, put and
end_session refuse, before writing, what the store's own readers then called damaged (a session of an experiment never
begun, of another config hash or counting more units than stored; a unit counted by another experiment's or an ended
session, a Unit of another experiment stored, an ended session ended again); every write needs this Store to hold the
writer lock (a second Store put and started sessions while the first held it); begin and update take only a config the
readers read (any JSON object was taken, and export_results then called the store damaged)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from store_edits import begin, dump, tiny_config

from neurohover.errors import NeurohoverError
from neurohover.experiments import Store, Unit
from neurohover.experiments.export import checked_units


def _unit(name: str = "e1", key: str = "k1") -> Unit:
    return Unit(name, key, "diagnostic", {"value": 1})


@pytest.fixture
def store(tmp_path: Path):
    """A store holding experiments e1 and e2 (quick), nothing run."""
    with Store(tmp_path / "s.sqlite") as s:
        begin(s, "e1")
        begin(s, "e2")
        yield s


def _refused(store: Store, call, message: str) -> None:
    """``call(store)`` raises one NeurohoverError holding ``message`` and leaves the file as it was."""
    before = dump(store.path)
    with pytest.raises(NeurohoverError, match=re.escape(message)):
        call(store)
    assert dump(store.path) == before


H = tiny_config().hash


# ------------------------------------------------------------------------------------------------ T29-B04


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (
            lambda s: s.start_session("ghost", "quick", H, "local", 1, 0),
            "start_session: the store holds no experiment 'ghost' (quick): begin registers it first",
        ),
        (lambda s: s.start_session("e1", "paper", H, "local", 1, 0), "the store holds no experiment 'e1' (paper)"),
        (
            lambda s: s.start_session("e1", "quick", "OTHER", "local", 1, 0),
            f"start_session: config_hash = 'OTHER' is not allowed: experiment e1 (quick) has config hash '{H}'",
        ),
        (lambda s: s.start_session("e1", "quick", H, "local", 1, 99), "start_session: units_before = 99 is not allowed: experiment e1 (quick) stores 0 units"),
    ],
)
def test_b04_start_session_refuses_a_session_the_readers_call_damaged(store: Store, call, message: str) -> None:
    _refused(store, call, message)
    assert store.sessions("e1", "quick") == [] and store.sessions("ghost", "quick", missing_ok=True) == []  # (T38-B05)


def test_b04_start_session_takes_the_units_the_experiment_stores(store: Store) -> None:
    assert store.put("e1", "quick", H, _unit(), {"value": 1, "seed": None}, 0.1)
    session = store.start_session("e1", "quick", H, "local", 1, 1)
    assert [s["units_before"] for s in store.sessions("e1", "quick")] == [1] and session >= 1


# ------------------------------------------------------------------------------------------------ T29-B05


def test_b05_put_refuses_another_experiments_session_and_an_ended_one(store: Store) -> None:
    other = store.start_session("e2", "quick", H, "local", 1, 0)
    _refused(
        store,
        lambda s: s.put("e1", "quick", H, _unit(), {"value": 1, "seed": None}, 0.1, session=other),
        f"put: session = {other} is not allowed: it is a session of experiment 'e2' ('quick') under config hash '{H}', not of e1 (quick)",
    )
    ended = store.start_session("e1", "quick", H, "local", 1, 0)
    store.end_session(ended, "finished")
    _refused(
        store,
        lambda s: s.put("e1", "quick", H, _unit(), {"value": 1, "seed": None}, 0.1, session=ended),
        f"put: session = {ended} is not allowed: it has already ended ('finished'); start_session gives a running one",
    )
    _refused(
        store,
        lambda s: s.put("e1", "quick", H, _unit(), {"value": 1, "seed": None}, 0.1, session=999),
        "put: session = 999 is not allowed: the store has no such session",
    )
    running = store.start_session("e1", "quick", H, "local", 1, 0)
    assert store.put("e1", "quick", H, _unit(), {"value": 1, "seed": None}, 0.1, session=running)
    assert [s["units_run"] for s in store.sessions("e1", "quick")] == [0, 1] and store.sessions("e2", "quick")[0]["units_run"] == 0


def test_b05_put_refuses_a_unit_of_another_experiment(store: Store) -> None:
    _refused(
        store,
        lambda s: s.put("e1", "quick", H, _unit("zz", "k2"), {"value": 2, "seed": None}, 0.1),
        "put: unit 'k2''s experiment = 'zz' is not allowed: give a unit of e1 (its plan's)",
    )
    assert store.results("e1", "quick") == {}


def test_b05_end_session_refuses_a_session_already_ended(store: Store) -> None:
    session = store.start_session("e1", "quick", H, "local", 1, 0)
    store.end_session(session, "finished")
    _refused(store, lambda s: s.end_session(session, "failed"), f"end_session: session = {session} is not allowed: it has already ended ('finished')")
    assert store.sessions("e1", "quick")[0]["status"] == "finished"


# ------------------------------------------------------------------------------------------------ T29-B06


def test_b06_every_write_of_a_second_store_is_refused_while_the_first_holds_the_lock(store: Store) -> None:
    session = store.start_session("e1", "quick", H, "local", 1, 0)  # store holds the lock (begin took it)
    with Store(store.path) as second:
        for call in (
            lambda s: s.put("e1", "quick", H, _unit("e1", "k9"), {"value": 9, "seed": None}, 1.0),
            lambda s: s.start_session("e1", "quick", H, "local", 1, 0),
            lambda s: s.end_session(session, "finished"),
            lambda s: begin(s, "e1"),
            lambda s: s.update("e1", "quick", H, tiny_config("e1").to_dict(), keep=[]),
            lambda s: s.forget_if_empty("e2", "quick"),
        ):
            _refused(second, call, f"results store {str(store.path)!r} is in use: another open Store of this process (pid ")  # T34-B14
        store.close()
        assert second.put("e1", "quick", H, _unit("e1", "k9"), {"value": 9, "seed": None}, 1.0)  # the lock free: the write takes it
        assert second.lock_path.exists()


# ------------------------------------------------------------------------------------------------ T29-B07


@pytest.mark.parametrize(
    ("config", "config_hash", "message"),
    [
        ({"x": 1}, H, "begin: config = {'x': 1} is not allowed: name (None), title (None), kind (None), scale (None), settings (None) missing"),
        (tiny_config("e3", "paper").to_dict(), H, "is not allowed: its row is at scale 'quick' but its config is the 'paper' one"),
        (tiny_config("e3").to_dict(), "h1", f"is not allowed: its config hashes to {H}, but the store records config hash 'h1'"),
        ({**tiny_config("e3").to_dict(), "hash": "h1"}, H, "(its config: 'h1')"),
        ({**tiny_config("e3").to_dict(), "kind": "zzz"}, H, "is not allowed: kind 'zzz' is none of evolution, model_learning, test_runs"),
    ],
)
def test_b07_begin_refuses_a_config_the_readers_call_damaged(store: Store, config: dict, config_hash: str, message: str) -> None:
    _refused(store, lambda s: s.begin("e3", "quick", config_hash, config), message)
    assert [e[0] for e in store.experiments()] == ["e1", "e2"]


def test_b07_update_refuses_such_a_config_and_a_begun_config_exports(store: Store) -> None:
    _refused(store, lambda s: s.update("e1", "quick", H, {"x": 1}, keep=[]), "update: config = {'x': 1} is not allowed: name (None)")
    assert checked_units(store, "e1", "quick")[0] == tiny_config("e1")  # what begin took, the readers' check reads
