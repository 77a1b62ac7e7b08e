"""Bad-input trial 18, names and files: array names, flight-data metadata, --seed-policy FIFO (T18-3, T18-4, T18-7)."""

from __future__ import annotations

import os
import re
from pathlib import Path

import numpy as np
import pytest

from neurohover.errors import NeurohoverError
from neurohover.flightdata import FlightData

ARRAY = np.array([[1, 2]])


def _flight(metadata: dict | None = None) -> FlightData:
    """One episode of 20 steps, small states (a valid helicopter observation)."""
    rng = np.random.default_rng(0)
    return FlightData((0.01 * rng.normal(size=(21, 12)),), (0.01 * rng.normal(size=(20, 4)),), metadata or {"episode_steps": 20})


def _store(tmp_path: Path):
    from store_edits import begin

    from neurohover.experiments import Store

    store = Store(tmp_path / "s.sqlite")
    begin(store, "fig2")
    return store


def _calls(tmp_path: Path, store, value):
    """Each call that takes a name, given ``value`` as that name (None: a good one)."""
    from neurohover.experiments import write_report
    from neurohover.experiments.config import load_config
    from neurohover.experiments.executors import make_executor
    from neurohover.experiments.export import export_results
    from neurohover.models.ec import learn_ec_meno
    from neurohover.models.lr import learn_lr

    fd = _flight()
    return {
        "intercepts": lambda: learn_lr(fd, "uv" if value is None else value),
        "estimator": lambda: learn_lr(fd, estimator="ols" if value is None else value),
        "scaling": lambda: learn_ec_meno(fd, budget=10, scaling="data" if value is None else value),
        "config scale": lambda: load_config("fig2", "quick" if value is None else value),
        "export fmt": lambda: export_results(store, "fig2", "csv" if value is None else value, "quick"),
        "export scale": lambda: export_results(store, "fig2", "csv", "quick" if value is None else value),
        "report scale": lambda: write_report(store, tmp_path / "rep", scale="quick" if value is None else value),
        "executor": lambda: make_executor("local" if value is None else value),
    }


@pytest.mark.parametrize("which", ["intercepts", "estimator", "scaling", "config scale", "export fmt", "export scale", "report scale", "executor"])
def test_array_names_refused(which: str, tmp_path: Path) -> None:
    """T18-3: a 2-d array as a name (an option, a scale, a format, an executor) was numpy's ValueError "The truth value
    of an array with more than one element is ambiguous" from ``x in CHOICES``; now a NeurohoverError naming it."""
    with _store(tmp_path) as store:
        with pytest.raises(NeurohoverError, match=re.escape("array([[1, 2]])")):
            _calls(tmp_path, store, ARRAY)[which]()
        try:  # the good name still passes its check (export has no finished unit to export: said as such)
            _calls(tmp_path, store, None)[which]()
        except NeurohoverError as err:
            assert which in ("export fmt", "export scale"), err
            assert "no finished unit yet" in str(err)


@pytest.mark.parametrize(
    ("metadata", "message"),
    [
        ({"episode_steps": -5}, "episode_steps=-5 is not allowed"),
        ({"crashed": "x"}, "crashed='x' is not allowed"),
        ({"crashed": [True] * 3}, "crashed=[True, True, True] is not allowed: one true or false per episode (1)"),
    ],
)
def test_flight_data_metadata_checked_when_made(metadata: dict, message: str, tmp_path: Path) -> None:
    """T18-4: FlightData took metadata that load() refuses (episode_steps -5, crashed 'x', 3 crash marks for 1 episode);
    save() wrote it and load() refused the file. Now refused when made, with load's message."""
    with pytest.raises(NeurohoverError, match=re.escape(f"flight data: its metadata {message}")):
        _flight(metadata)
    good = _flight({"episode_steps": 20, "crashed": [False]})
    good.save(tmp_path / "f.npz")
    assert FlightData.load(tmp_path / "f.npz").metadata["crashed"] == [False]


def test_flight_data_metadata_changed_after_making_is_refused_by_save(tmp_path: Path) -> None:
    """T18-4 follow-up: metadata is a dict, changeable after the check when made; save() wrote episode_steps -5 and load()
    refused the file. Now save() checks it again and writes nothing."""
    flight = _flight({"episode_steps": 20})
    flight.metadata["episode_steps"] = -5
    with pytest.raises(NeurohoverError, match=re.escape("flight data: its metadata episode_steps=-5 is not allowed")):
        flight.save(tmp_path / "f.npz")
    assert list(tmp_path.iterdir()) == []


def test_seed_policy_fifo_is_no_regular_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """T18-7: ``evolve --seed-policy FIFO`` said "no such file" of a FIFO that exists; now, as ``fly --policy``, "is not a
    regular file" (and a missing file is still "no such file")."""
    from neurohover.cli import main

    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    base = ["evolve", "--task", "ghh08", "--budget", "10", "--episode-steps", "10", "--out", str(tmp_path / "o.json")]
    assert main([*base, "--seed-policy", str(fifo)]) == 2
    assert f"--seed-policy {str(fifo)!r} is not a regular file" in capsys.readouterr().err
    assert main([*base, "--seed-policy", str(tmp_path / "nope.json")]) == 2
    assert "no such file" in capsys.readouterr().err
