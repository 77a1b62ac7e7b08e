"""Bad-input trial 21, flight data: metadata JSON cannot write back as given (T21-08), a file name not ending .npz (T21-09), a
file of no episodes refused for its metadata first (T21-12), metadata mdps null or
of an MDP of dt 0 (T21-05)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from neurohover.errors import NeurohoverError
from neurohover.flightdata import FlightData

OBS, ACTS = (np.zeros((3, 12)),), (np.zeros((2, 4)),)


@pytest.mark.parametrize(
    ("metadata", "named"),
    [
        ({1: 2}, "metadata key 1 is not allowed: give text keys"),
        ({"a": {"b": [{2.5: 1}]}}, r"metadata key 2\.5 \(under 'a'\) is not allowed: give text keys"),
        ({"x": float("nan")}, r"metadata cannot be saved as JSON: give strict JSON values \(numbers finite\), not x=nan "),
        ({"x": object()}, "metadata cannot be saved as JSON: .*, not x=<object object at .*> "),
        ({"x": np.array([1.0, np.nan])}, r"metadata cannot be saved as JSON: .*, not x=array\(\[ 1., nan\]\) "),
        ({"x": np.array([{3: 1}], dtype=object)}, r"metadata key 3 \(under 'x'\) is not allowed"),
    ],
)
def test_metadata_json_would_not_read_back_is_refused_when_made_and_when_saved(tmp_path: Path, metadata: dict, named: str) -> None:
    """T21-08: {1: 2} was taken and saved as {'1': 2} (other metadata when loaded); a NaN or an object() was refused by
    save() only. Now one check refuses each when the flight data are made, and again at save() (metadata may change)."""
    with pytest.raises(NeurohoverError, match=f"^flight data {named}"):
        FlightData(OBS, ACTS, metadata)
    data = FlightData(OBS, ACTS, {"task": "ghh08"})
    data.metadata.update(metadata)  # changed after making
    with pytest.raises(NeurohoverError, match=f"^flight data {named}"):
        data.save(tmp_path / "f.npz")
    assert not (tmp_path / "f.npz").exists()


def test_metadata_callers_write_still_round_trips(tmp_path: Path) -> None:
    """T21-08: what fly --record, evaluate(record=True) and a join write (text keys, lists, NumPy floats) is taken, and
    NumPy numbers and arrays, which flight data made in Python may hold (``==`` compares them), are saved as plain JSON."""
    metadata = {"task": "ghh08", "seed": 3, "returns": [np.float64(-1.5)], "crashed": [False], "nested": {"a": [1, {"b": None}]}}
    data = FlightData(OBS, ACTS, {**metadata, "n": np.int64(2), "ok": np.bool_(True), "x": np.ones(2), "t": (1, 2)})
    loaded = FlightData.load((data + data).save(tmp_path / "f.npz")).metadata
    assert loaded["returns"] == [-1.5, -1.5] and loaded["nested"] == metadata["nested"]
    assert (loaded["n"], loaded["ok"], loaded["x"], loaded["t"]) == (2, True, [1.0, 1.0], [1, 2])


@pytest.mark.parametrize("name", ["x.txt", "flight", "new/flight"])
def test_a_flight_data_file_not_named_npz_is_refused_as_fly_record_refuses_it(tmp_path: Path, monkeypatch, name: str) -> None:
    """T21-09: save('x.txt') wrote a NumPy archive under that name; fly --record refuses any FILE not ending .npz."""
    monkeypatch.chdir(tmp_path)
    data = FlightData(OBS, ACTS)
    like = str(Path(name).with_suffix(".npz"))  # the path as given, as fly --record says it
    with pytest.raises(NeurohoverError, match=f"^flight-data file '{name}' is not allowed: .*give a path ending .npz \\(e.g. '{like}'\\)"):
        data.save(name)
    assert sorted(p.name for p in tmp_path.iterdir()) == []  # nothing written, no directory made
    assert FlightData.load(data.save(tmp_path / "f.NPZ")) == data


def _rewritten(path: Path, out: Path, metadata: dict | None = None, **arrays: np.ndarray) -> Path:
    """The flight-data file ``path`` written again to ``out`` with some of its arrays (and its metadata) replaced."""
    with np.load(path) as z:
        members = {name: z[name] for name in z.files}
    members.update(arrays)
    if metadata is not None:
        members["metadata"] = np.array(json.dumps(metadata))
    np.savez(out, **members)
    return out


def test_a_file_of_no_episodes_is_refused_as_such_before_its_metadata(tmp_path: Path, cli) -> None:
    """T21-12: a file of zero episodes was refused for its metadata (a list printed half, cut at 40 characters) before
    saying it holds no transitions."""
    returns = [-1062.845583996776, -1001.1944074392666]
    full = FlightData(OBS * 2, ACTS * 2, {"task": "ghh08", "returns": returns}).save(tmp_path / "full.npz")
    empty = {"lengths": np.zeros(0, dtype=np.int64), "observations": np.zeros((0, 12)), "actions": np.zeros((0, 4))}
    path = _rewritten(full, tmp_path / "zero.npz", **empty)
    with pytest.raises(NeurohoverError, match=f"^flight-data file '{path}' holds no transitions$"):
        FlightData.load(path)
    rc, _, err = cli("plot", str(path), "--out", str(tmp_path / "p"))
    assert rc == 2 and err.strip().endswith("holds no transitions"), err


def test_metadata_values_in_messages_are_shown_briefly_not_cut_mid_number() -> None:
    """T21-12: messages cut a metadata value at 40 characters ('returns=[-1062.845583996776, -1001.1944074392666 is not')."""
    with pytest.raises(NeurohoverError, match=r"returns=\[-1062\.845583996776, -1001\.1944074392666, 3\.5\] is not allowed: one number per"):
        FlightData(OBS, ACTS, {"returns": [-1062.845583996776, -1001.1944074392666, 3.5]})
    with pytest.raises(NeurohoverError, match=r"returns=\[1\.5, 1\.5, .*\.\.\. is not allowed: one number per episode \(1\)"):
        FlightData(OBS, ACTS, {"returns": [1.5] * 40})


@pytest.mark.parametrize(
    ("change", "named"),
    [
        ({"mdps": None}, r"its metadata mdps=None is not allowed: one MDP \(a table\) per episode \(2\), or no mdps entry"),
        ({"mdps": "abc"}, r"its metadata mdps='abc' is not allowed: one MDP"),
        ({"returns": None}, r"its metadata returns=None is not allowed: one number per episode \(2\)"),
        ({"dt": 0}, r"its metadata mdps entry 1 is not allowed: MDP dt=0\.0 is out of range: allowed a substep length > 0"),
        ({"dt": float("nan")}, r"its metadata mdps entry 1 is not allowed: MDP dt=nan is not allowed: give a finite number"),
        ({"substeps": -3}, r"its metadata mdps entry 1 is not allowed: MDP substeps=-3 is out of range"),
    ],
)
def test_metadata_mdps_null_or_of_a_bad_mdp_is_refused_by_plot_and_learn_model(tmp_path: Path, cli, change: dict, named: str) -> None:
    """T21-05: a file whose metadata held "mdps": null, or an MDP of dt 0, was plotted and learned from (learn-model said
    only that the MDP metadata were unreadable); each is refused by name, as a file and as flight data made in Python."""
    from neurohover.tasks import get_task_family

    table = get_task_family("ghh08").zero().to_dict()
    metadata = {"task": "ghh08", "mdps": [table, table], "returns": [0.0, 0.0]}  # what still readings give (T23-03: 1.0 was taken)
    full = FlightData(OBS * 2, ACTS * 2, metadata).save(tmp_path / "full.npz")  # as recorded: taken
    if "mdps" in change or "returns" in change:
        metadata.update(change)
    else:
        metadata["mdps"] = [table, {**table, **change}]
    path = _rewritten(full, tmp_path / "bad.npz", metadata)
    with pytest.raises(NeurohoverError, match=f"^flight-data file '{path}': {named}"):
        FlightData.load(path)
    if change.get("dt") == 0 or "mdps" in change:
        for argv in (
            ("plot", str(path), "--out", str(tmp_path / "p")),
            ("learn-model", "--flight-data", str(path), "--method", "lr", "--out", str(tmp_path / "m.json")),
        ):
            rc, out, err = cli(*argv)
            assert rc == 2 and out == "" and f"'{path}': its metadata mdps" in err and len(err.strip().splitlines()) == 1, err
    if not any(isinstance(v, float) and v != v for v in change.values()):  # a NaN is refused first as no strict JSON
        with pytest.raises(NeurohoverError, match=f"^flight data: {named}"):
            FlightData(OBS * 2, ACTS * 2, metadata)
    assert FlightData(OBS * 2, ACTS * 2, {"mdps": [{}, table]}).metadata["mdps"][0] == {}  # {}: an MDP not recorded, as joins keep it
