"""The fifteenth bad-input trial's findings in the plots of flight data, flight data themselves, the benchmarks and the
results store's path and sessions: each bad value gives one NeurohoverError naming it and what is allowed."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from store_edits import begin

from neurohover.bench import benchmark_evolution, run_benchmarks
from neurohover.errors import NeurohoverError
from neurohover.experiments.store import SESSION_STATUSES, Store
from neurohover.flightdata import FlightData
from neurohover.paths import make_dirs
from neurohover.plots import episode_crashed, plot_flight_data

OBS, ACT = np.zeros((6, 12)), np.zeros((5, 4))
TWO = FlightData([OBS, OBS], [ACT, ACT], {})


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda: episode_crashed(TWO, 5), "episode 5 is out of range: the flight data hold episodes 0..1"),
        (lambda: episode_crashed(TWO, -1), "episode -1 is out of range: the flight data hold episodes 0..1"),
        (lambda: episode_crashed(TWO, True), "episode True is not allowed: give integer indices"),
        (lambda: episode_crashed(None, 0), "data=None is not allowed: give FlightData"),  # type: ignore[arg-type]
    ],
)
def test_episode_crashed_names_a_bad_episode_or_data(call, message: str) -> None:
    """T15-9: an episode past the data was an IndexError, None an AttributeError."""
    with pytest.raises(NeurohoverError, match=re.escape(message)):
        call()


def test_episode_crashed_takes_numpy_indices() -> None:
    """T15-9: the check keeps NumPy integers, as a Python int."""
    assert episode_crashed(TWO, np.int64(1)) is True  # 5 steps of a 6000-step budget: shorter, so crashed


def test_plot_flight_data_refuses_an_empty_selection(tmp_path: Path) -> None:
    """T15-25: episodes=[] returned [] and wrote nothing, without a word."""
    for empty in ([], np.array([], dtype=int)):
        with pytest.raises(NeurohoverError, match=re.escape("selects no episode: give at least one index of 0..1, or None for all")):
            plot_flight_data(TWO, tmp_path, episodes=empty)
    assert list(tmp_path.iterdir()) == []


def test_store_path_under_a_file_is_named(tmp_path: Path) -> None:
    """T15-10: a store path whose parent is a regular file was pathlib's FileExistsError."""
    (tmp_path / "txt.sqlite").write_text("x")
    message = f"{str(tmp_path / 'txt.sqlite')!r} is a file, not a directory: give a path in a directory"
    with pytest.raises(NeurohoverError, match=re.escape(message)):
        Store(tmp_path / "txt.sqlite" / "x.sqlite")
    with pytest.raises(NeurohoverError, match=re.escape(message)):  # deeper: the file is named, not the missing directory
        Store(tmp_path / "txt.sqlite" / "a" / "x.sqlite")
    with pytest.raises(NeurohoverError, match=re.escape(message)):
        make_dirs(tmp_path / "txt.sqlite" / "a", "--out", "x")
    assert (tmp_path / "txt.sqlite").read_text() == "x"


def test_store_makes_missing_directories(tmp_path: Path) -> None:
    """T15-10: the shared directory maker still makes a new store's missing directories."""
    with Store(tmp_path / "a" / "b" / "s.sqlite") as store:
        assert store.experiments() == []
    assert (tmp_path / "a" / "b" / "s.sqlite").is_file()


def test_end_session_names_an_unknown_session_and_status(tmp_path: Path) -> None:
    """T15-22: an unknown session id matched nothing, and a free-text status was stored, both without a word."""
    with Store(tmp_path / "s.sqlite") as store:
        with pytest.raises(NeurohoverError, match=re.escape("end_session: session = 99999 is not allowed:") + ".*has no such session"):
            store.end_session(99999, "finished")
        h = begin(store, "e")  # a session of an experiment the store holds (T29-B04)
        session = store.start_session("e", "quick", h, "local", 1, 0)
        allowed = "give one of 'finished', 'selection finished', 'interrupted', 'failed'"
        with pytest.raises(NeurohoverError, match=re.escape(f"end_session: status = 'weird' is not allowed: {allowed}")):
            store.end_session(session, "weird")
        for status in SESSION_STATUSES:  # each ends a session of its own: an ended one is not ended again (T29-B05)
            store.end_session(store.start_session("e", "quick", h, "local", 1, 0), status)
        assert [s["status"] for s in store.sessions("e", "quick")] == ["running", *SESSION_STATUSES]


@pytest.mark.parametrize("run", [run_benchmarks, benchmark_evolution])
@pytest.mark.parametrize("quick", ["no", 1, None])
def test_benchmarks_refuse_a_flag_that_is_no_bool(run, quick) -> None:
    """T15-26: quick='no' ran the short benchmarks (any truthy value counted as True)."""
    with pytest.raises(NeurohoverError, match=re.escape(f"quick={quick!r} is not allowed: give True (a short run) or False")):
        run(quick=quick)


@pytest.mark.parametrize("metadata", [None, [1], "x"])
def test_flight_data_metadata_is_a_dict_from_the_start(metadata) -> None:
    """T15-29: metadata None or [1] was taken at construction, and refused only when saved."""
    with pytest.raises(NeurohoverError, match=re.escape(f"flight data: its metadata {metadata!r} is not allowed: give a dict (a JSON object)")):
        FlightData((OBS,), (ACT,), metadata)


def test_float32_save_refuses_values_past_its_range(tmp_path: Path) -> None:
    """T15-29: 1e300 was written as float32's inf, without a word; float64 keeps it, and NaN is no overflow."""
    data = FlightData((np.full((6, 12), 1e300),), (ACT,), {})
    with pytest.raises(NeurohoverError, match=re.escape("flight data observations hold 1e+300, past float32's largest value 3.403e+38")):
        data.save(tmp_path / "f.npz", "float32")
    assert not (tmp_path / "f.npz").exists()
    act = np.full((5, 4), -1e39)
    with pytest.raises(NeurohoverError, match=re.escape("flight data actions hold 1e+39, past float32's largest value")):
        FlightData((OBS,), (act,), {}).save(tmp_path / "f.npz", "float32")
    assert FlightData.load(data.save(tmp_path / "f.npz")) == data
    nan = FlightData((np.full((6, 12), np.nan),), (ACT,), {})  # no overflow, but no flight: refused as load() refuses it
    with pytest.raises(NeurohoverError, match=re.escape("flight data to save, episode 0: step 0 reads u = nan")):
        nan.save(tmp_path / "n.npz", "float32")
    assert not (tmp_path / "n.npz").exists()
