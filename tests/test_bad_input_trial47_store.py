"""Trial 47, side B: hand-edited stores and checkpoints, path objects. A BLOB in a store's text cell (a unit's key or
worker) was returned as bytes by results() and was export's TypeError (T47-B03): refused, naming table, row and column.
A session claiming 2**62 cores was read and exported (T47-B12): cores are 1..2**20, written and read. A checkpoint's rng
state of 2.5 or True was resumed on another stream without a word (T47-B10): refused as the MDP stream's is. An
os.PathLike whose __fspath__ gives an int was a TypeError from every reader and writer (T47-B07): named. A policy file
a progress callback saved at the run's checkpoint path was replaced by the next checkpoint (T47-B13): left as it is,
the checkpoint written beside it."""

from __future__ import annotations

import json
import math
import os
import shutil
import sqlite3
from pathlib import Path

import pytest
from store_edits import competed_store

import neurohover as nh
from neurohover.errors import NeurohoverError


@pytest.fixture(scope="module")
def store_file(tmp_path_factory) -> Path:
    return competed_store(tmp_path_factory.mktemp("t47"))


def edited(store_file: Path, at: Path, sql: str, *args) -> Path:
    """A copy of the store at ``at`` with ``sql`` run on it."""
    shutil.copyfile(store_file, at)
    with sqlite3.connect(at) as conn:
        conn.execute(sql, args)
    conn.close()
    return at


@pytest.mark.parametrize(
    "sql, said",
    [
        ("UPDATE units SET key = ?", r"its table units, row 1, column key holds a BLOB \(b'\\x00'\), not the text"),
        ("UPDATE units SET worker = ?", r"its table units, row 1 \(unit 'run/.*'\), column worker holds a BLOB \(b'\\x00'\)"),
        ("UPDATE sessions SET executor = ?", r"its table sessions, row 1, column executor holds a BLOB"),
    ],
)
def test_t47_b03_a_blob_in_a_text_cell_is_refused_by_table_row_and_column(store_file: Path, tmp_path: Path, sql: str, said: str) -> None:
    from neurohover.experiments import Store, export_results

    with Store(edited(store_file, tmp_path / "d.sqlite", sql, b"\x00"), create=False) as store:
        ((name, scale, *_),) = store.experiments()
        for read in (lambda: store.results(name, scale), lambda: export_results(store, name, "json", scale), lambda: store.sessions(name, scale)):
            with pytest.raises(NeurohoverError, match=f"results store .* is damaged: {said}"):
                read()


def test_t47_b03_a_blob_experiment_name_is_not_listed_as_bytes(store_file: Path, tmp_path: Path) -> None:
    from neurohover.experiments import Store

    with Store(edited(store_file, tmp_path / "d.sqlite", "UPDATE experiments SET name = ?", b"fig7"), create=False) as store:
        with pytest.raises(NeurohoverError, match=r"its table experiments, row 1, column name holds a BLOB \(b'fig7'\)"):
            store.experiments()


def test_t47_b03_orphan_units_of_a_blob_name_are_not_listed_as_bytes(store_file: Path, tmp_path: Path) -> None:
    """The T47-B03 fixer's note: units whose name is a BLOB have no config row, and orphan_units() listed them as bytes."""
    from neurohover.experiments import Store

    with Store(edited(store_file, tmp_path / "d.sqlite", "UPDATE units SET name = ?", b"fig7"), create=False) as store:
        with pytest.raises(NeurohoverError, match=r"its table units holds units of experiment b'fig7', scale 'settings-[0-9a-f]+', not the text"):
            store.orphan_units()
    with Store(store_file, create=False) as store:
        assert store.orphan_units() == []


def test_t47_b12_session_cores_past_2_20_are_refused_written_and_read(store_file: Path, tmp_path: Path) -> None:
    from neurohover.experiments import Store

    with Store(edited(store_file, tmp_path / "d.sqlite", "UPDATE sessions SET cores = ?", 2**62), create=False) as store:
        ((name, scale, config_hash, _),) = store.experiments()
        with pytest.raises(NeurohoverError, match=r"is damaged: cores 4611686018427387904 is not allowed: allowed a whole number from 1 to 1,048,576"):
            store.sessions(name, scale)
    with Store(edited(store_file, tmp_path / "e.sqlite", "UPDATE sessions SET cores = ?", 2**20)) as store:
        assert store.sessions(name, scale)[0]["cores"] == 2**20
        with pytest.raises(NeurohoverError, match=r"start_session: cores = 1048577 is not allowed: give a whole number >= 1 \(at most 1,048,576\)"):
            store.start_session(name, scale, config_hash, "local", 2**20 + 1, 0)


@pytest.fixture(scope="module")
def checkpoint(tmp_path_factory) -> Path:
    from neurohover.evolution import evolve

    path = tmp_path_factory.mktemp("t47ck") / "ck.json"
    evolve(nh.get_task_family("ghh08").training_mdps()[0], budget=40, n_steps=20, seed=1, checkpoint=path, checkpoint_every_s=math.inf)
    return path


@pytest.mark.parametrize(
    "entry, value, said",
    [
        (("state", "state"), 2.5, "rng's state.state=2.5 is not allowed: allowed an integer in 0..2\\*\\*128-1"),
        (("state", "state"), True, "rng's state.state=True is not allowed"),
        (("has_uint32",), 2.5, "rng's has_uint32=2.5 is not allowed: allowed an integer in 0..1"),
        (("has_uint32",), -1, "rng's has_uint32=-1 is not allowed"),
        (("has_uint32",), True, "rng's has_uint32=True is not allowed"),
        (("uinteger",), 2.5, "rng's uinteger=2.5 is not allowed: allowed an integer in 0..2\\*\\*32-1"),
        (("uinteger",), True, "rng's uinteger=True is not allowed"),
    ],
)
def test_t47_b10_a_checkpoints_rng_words_must_be_integers_in_range(checkpoint: Path, tmp_path: Path, entry, value, said: str) -> None:
    from neurohover.evolution import evolve

    state = json.loads(checkpoint.read_text())
    held = state["optimizer_state"]["rng"]
    for key in entry[:-1]:
        held = held[key]
    held[entry[-1]] = value
    path = tmp_path / "ck.json"
    path.write_text(json.dumps(state))
    with pytest.raises(NeurohoverError, match=f"'rng' entry .* is damaged \\({said}"):
        evolve(nh.get_task_family("ghh08").training_mdps()[0], budget=80, n_steps=20, seed=1, checkpoint=path, resume=True)


class IntPath(os.PathLike):
    def __fspath__(self):  # type: ignore[override]
        return 5


def test_t47_b07_a_path_object_giving_an_int_is_named(tmp_path: Path) -> None:
    from neurohover.experiments import Store
    from neurohover.flightdata import FlightData
    from neurohover.models import LearnedModel

    fd = nh.evaluate(nh.baseline_policy(), nh.get_task_family("ghh08").training_mdps()[0], episodes=1, n_steps=20, record=True).flight_data
    for call in (
        lambda: nh.save_policy(nh.baseline_policy(), IntPath()),
        lambda: nh.load_policy(IntPath()),
        lambda: fd.save(IntPath()),
        lambda: FlightData.load(IntPath()),
        lambda: LearnedModel.load(IntPath()),
        lambda: Store(IntPath()),
    ):
        with pytest.raises(NeurohoverError, match=r"=<.*IntPath object at .* is not allowed: its __fspath__\(\) gives 5: give a .* as text"):
            call()


def test_t47_b13_a_policy_saved_at_the_checkpoint_mid_run_is_kept(tmp_path: Path, monkeypatch) -> None:
    from neurohover.evolution import evolve

    monkeypatch.chdir(tmp_path)
    mdp = nh.get_task_family("ghh08").training_mdps()[0]

    def save(info) -> None:
        if info.generation == 1:
            nh.save_policy(nh.baseline_policy(), "mine.json")

    beside = str(tmp_path / "mine.checkpoint.json")
    with pytest.raises(NeurohoverError, match=f"now holds a policy file, written there during the run, and was left as it is; .* to {beside!r} instead"):
        evolve(mdp, budget=60, n_steps=20, seed=1, checkpoint="mine.json", progress=save, progress_every_s=0)
    assert nh.load_policy("mine.json").metadata["name"] == "baseline"
    resumed = evolve(mdp, budget=60, n_steps=20, seed=1, checkpoint=beside, resume=True)
    assert resumed.champion_return == evolve(mdp, budget=60, n_steps=20, seed=1).champion_return
