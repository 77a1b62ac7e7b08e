"""Bad-input trial 37, files edited by hand: T37-B02 (a flight-data .npz with an encrypted member, a compression method
zipfile lacks or odd flag bits was zipfile's RuntimeError or NotImplementedError), T37-B03 (an array stored without its
.npy name came back as bytes: an AttributeError), T37-B04 (big-endian or float16 flight data skipped the policy_flown
check), T37-B05 (a model file's wind table took unknown entries and read a missing axis as zeros), T37-B07 (a policy set's
safe list reordered against its own tables was flown), T37-B08 (a genome digest of a file the set does not have was
taken) and T37-B10, FlightData.load's part (np.longdouble values past float64's range leaked NumPy's overflow warning)."""

from __future__ import annotations

import io
import json
import struct
import warnings
import zipfile
from pathlib import Path

import numpy as np
import pytest
from flight_edits import recorded
from store_edits import edited_policy_set

from neurohover.errors import NeurohoverError
from neurohover.flightdata import FlightData
from neurohover.manifest import DIGESTS
from neurohover.models import LearnedModel, learn_lr
from neurohover.policysets import load_policy_set


@pytest.fixture(scope="module")
def flight(tmp_path_factory) -> Path:
    """A recording as fly --record writes it (one episode of ghh08 train:1, with its policy_flown)."""
    return recorded(tmp_path_factory.mktemp("flight37"), 1)


def _arrays(flight: Path) -> dict[str, np.ndarray]:
    with np.load(flight) as z:
        return {k: z[k] for k in z.files}


def _zip(path: Path, arrays: dict[str, np.ndarray], raw: dict[str, bytes] | None = None) -> Path:
    """``arrays`` written as an .npz's .npy members, stored (not compressed), and ``raw`` members as they are."""
    with zipfile.ZipFile(path, "w") as zf:
        for name, value in arrays.items():
            buf = io.BytesIO()
            np.lib.format.write_array(buf, value)
            zf.writestr(name + ".npy", buf.getvalue())
        for name, data in (raw or {}).items():
            zf.writestr(name, data)
    return path


def _patched(path: Path, out: Path, flag: int = 0, method: int | None = None) -> Path:
    """``path`` (a stored zip) with ``flag`` set in every member's flag bits, or its compression method set to ``method``,
    in both the local and the central headers: what zip -e, Windows Explorer's Deflate64 or a zstd zip write."""
    data = bytearray(path.read_bytes())
    for sig, flags_at in ((b"PK\x03\x04", 6), (b"PK\x01\x02", 8)):
        i = data.find(sig)
        while i >= 0:
            data[i + flags_at] |= flag
            if method is not None:
                data[i + flags_at + 2 : i + flags_at + 4] = struct.pack("<H", method)
            i = data.find(sig, i + 4)
    out.write_bytes(bytes(data))
    return out


# ---------------------------------------------------------------------------------------------- T37-B02


@pytest.mark.parametrize(
    ("flag", "method", "said"),
    [
        (0x1, None, "is encrypted (flag bit 0)"),
        (0x20, None, "is compressed patched data (flag bit 5)"),
        (0x40, None, "is strongly encrypted (flag bit 6)"),
        (0, 9, "is compressed by method 9, which zipfile does not read"),
        (0, 93, "is compressed by method 93, which zipfile does not read"),
        (0, 99, "is compressed by method 99, which zipfile does not read"),
    ],
)
def test_a_flight_data_zip_zipfile_cannot_read_is_refused_by_name(flight: Path, tmp_path: Path, flag: int, method, said: str) -> None:
    """T37-B02: an encrypted member was zipfile's RuntimeError ('password required'), Deflate64 (9), zstd (93), AES (99)
    and flag bits 5 and 6 its NotImplementedError, through FlightData.load, learn-model and plot."""
    plain = _zip(tmp_path / "plain.npz", _arrays(flight))
    assert FlightData.load(plain) == FlightData.load(flight)  # stored, not compressed: still read
    bad = _patched(plain, tmp_path / "bad.npz", flag, method)
    with pytest.raises(NeurohoverError) as err:
        FlightData.load(bad)
    message = str(err.value)
    assert message.startswith(f"'{bad}' is not a readable flight-data file: its member 'format.npy' {said}: "), message
    assert "allowed an .npz that neurohover or numpy.savez wrote (members stored, deflated, bzip2 or lzma; not encrypted)" in message


def test_an_encrypted_flight_data_file_is_one_line_on_the_command_line(flight: Path, tmp_path: Path, cli) -> None:
    """T37-B02: learn-model --flight-data and plot printed zipfile's traceback."""
    bad = _patched(_zip(tmp_path / "plain.npz", _arrays(flight)), tmp_path / "enc.npz", 0x1)
    for argv in (
        ["learn-model", "--flight-data", str(bad), "--method", "lr", "--out", str(tmp_path / "m.json")],
        ["plot", str(bad), "--out", str(tmp_path / "p")],
    ):
        rc, _, err = cli(*argv)
        assert rc == 2 and "Traceback" not in err and "its member 'format.npy' is encrypted" in err and str(bad) in err, err
    assert not (tmp_path / "m.json").exists()


# ---------------------------------------------------------------------------------------------- T37-B03


@pytest.mark.parametrize("beside", [False, True])
def test_an_array_stored_without_its_npy_name_is_refused_by_name(flight: Path, tmp_path: Path, beside: bool) -> None:
    """T37-B03: a member 'lengths' (no .npy), alone or beside lengths.npy, came back from NumPy as bytes, and load was an
    AttributeError ('bytes' object has no attribute 'ndim')."""
    arrays = _arrays(flight)
    kept = arrays if beside else {k: v for k, v in arrays.items() if k != "lengths"}
    path = _zip(tmp_path / "raw.npz", kept, {"lengths": b"6000"})
    with pytest.raises(NeurohoverError) as err:
        FlightData.load(path)
    assert str(err.value) == (
        f"'{path}' is not a readable flight-data file: its member 'lengths' is not allowed: arrays are .npy members "
        "(lengths.npy), as in an .npz that neurohover or numpy.savez wrote"
    )


# ---------------------------------------------------------------------------------------------- T37-B04


def _with_actions_edited(flight: Path) -> dict[str, np.ndarray]:
    arrays = _arrays(flight)
    arrays["actions"] = arrays["actions"].copy()
    arrays["actions"][:200] += 0.5  # not what policy_flown flew
    return arrays


@pytest.mark.parametrize("dtype", [">f8", "<f8"])
def test_edited_actions_are_refused_in_either_byte_order(flight: Path, tmp_path: Path, dtype: str) -> None:
    """T37-B04: the same edited numbers stored as '>f8' skipped the policy_flown check (its dtype is not np.float64)."""
    arrays = _with_actions_edited(flight)
    arrays = {k: v.astype(dtype) if k in ("observations", "actions") else v for k, v in arrays.items()}
    path = _zip(tmp_path / "edited.npz", arrays)
    with pytest.raises(NeurohoverError, match=r"its metadata policy_flown=.* is not allowed: it did not fly the episodes: at step 0"):
        FlightData.load(path)


@pytest.mark.parametrize("dtype", [">f8", ">f4", np.longdouble])
def test_a_recording_in_another_byte_order_or_wider_loads_as_native_float64(flight: Path, tmp_path: Path, dtype) -> None:
    """T37-B04: what fly --record wrote, stored big-endian or as np.longdouble, loads as the native float64 it holds
    (its policy_flown checked; a big-endian float32's, rounded, left to EC-MER as a float32 file's)."""
    arrays = _arrays(flight)
    path = _zip(tmp_path / "other.npz", {k: v.astype(dtype) if k in ("observations", "actions") else v for k, v in arrays.items()})
    data, want = FlightData.load(path), FlightData.load(flight)
    assert all(a.dtype == np.float64 and a.dtype.isnative for a in data.observations + data.actions)
    if dtype != ">f4":
        assert data == want
    else:
        assert np.array_equal(data.actions[0], want.actions[0].astype(np.float32).astype(np.float64))


def test_a_float16_flight_data_file_is_refused_by_its_dtype(flight: Path, tmp_path: Path) -> None:
    """T37-B04: float16 (a dtype save never writes) skipped the policy_flown check too: edited actions were taken."""
    arrays = _with_actions_edited(flight)
    path = _zip(tmp_path / "half.npz", {k: v.astype(np.float16) if k in ("observations", "actions") else v for k, v in arrays.items()})
    with pytest.raises(NeurohoverError) as err:
        FlightData.load(path)
    assert str(err.value) == (
        f"'{path}' is not a readable flight-data file: its observations and actions are float16 and float16: allowed float32 or "
        "wider (FlightData.save writes float64 or float32)"
    )


# ---------------------------------------------------------------------------------------------- T37-B10 (FlightData.load)


@pytest.mark.parametrize("name", ["observations", "actions"])
def test_longdouble_values_past_float64_are_refused_without_a_warning(flight: Path, tmp_path: Path, name: str) -> None:
    """T37-B10: np.longdouble 1e400 in a flight-data file leaked NumPy's 'overflow encountered in cast' RuntimeWarning
    (a traceback under PYTHONWARNINGS=error); it is refused as no finite float64 number."""
    if np.finfo(np.longdouble).max <= np.finfo(np.float64).max:
        pytest.skip("np.longdouble is float64 here")
    arrays = {k: v.astype(np.longdouble) if k in ("observations", "actions") else v for k, v in _arrays(flight).items()}
    arrays[name][3, 1] = np.longdouble("1e400")
    path = _zip(tmp_path / "long.npz", arrays)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(NeurohoverError) as err:
            FlightData.load(path)
    assert str(err.value).startswith(f"flight-data file '{path}': its {name} row 3 column 1 = ")
    assert str(err.value).endswith("is not allowed: it is no finite float64 number (past float64's range); give flight data as flown")


# ---------------------------------------------------------------------------------------------- T37-B05


@pytest.fixture(scope="module")
def model_file(flight: Path, tmp_path_factory) -> dict:
    """A model file as learn_lr writes it, read as JSON."""
    path = learn_lr(FlightData.load(flight)).save(tmp_path_factory.mktemp("model37") / "m.json")
    return json.loads(path.read_text())


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (
            lambda w: w.__setitem__("X", {"amplitude": 5.0, "omega": 1.0, "phase": 0.0, "offset": 3.0}),
            "its wind entry 'X' is not allowed: a model file's wind holds kind, x, y (x and y each amplitude, omega, phase, offset)",
        ),
        (lambda w: w.__setitem__("comment", "hi"), "its wind entry 'comment' is not allowed: a model file's wind holds kind, x, y"),
        (lambda w: w.pop("y"), "is not allowed: it lacks y; a model file's wind holds kind, x, y"),
        (lambda w: (w.pop("x"), w.pop("y")), "is not allowed: it lacks x, y; a model file's wind holds kind, x, y"),
        (lambda w: w["x"].pop("omega"), "its wind.x {'amplitude': 0.0, 'phase': 0.0, 'offset': 0.0} is not allowed: allowed a JSON object of exactly"),
        (lambda w: w.__setitem__("y", [0, 0, 0, 0]), "its wind.y [0, 0, 0, 0] is not allowed: allowed a JSON object of exactly amplitude"),
        (lambda w: w.clear(), "its wind {} is not allowed: it lacks kind, x, y"),
    ],
)
def test_a_model_files_wind_table_is_as_strict_as_its_other_tables(model_file: dict, tmp_path: Path, edit, message: str) -> None:
    """T37-B05: an entry 'X', 'z' or 'comment' in a model file's wind was dropped without a word, and a missing x or y
    read as all zeros, where a top-level 'note' or an unknown stats entry is refused."""
    d = json.loads(json.dumps(model_file))
    edit(d["wind"])
    path = tmp_path / "m_wind.json"
    path.write_text(json.dumps(d))
    with pytest.raises(NeurohoverError) as err:
        LearnedModel.load(path)
    assert str(err.value).startswith(f"model file '{path}': ") and message in str(err.value), str(err.value)


def test_a_model_file_as_written_and_one_before_winds_still_load(model_file: dict, tmp_path: Path) -> None:
    """T37-B05: what learn_lr writes loads; a file before winds (no wind entry) reads as wind-blind, as before."""
    (tmp_path / "m.json").write_text(json.dumps(model_file))
    assert LearnedModel.load(tmp_path / "m.json").wind.kind == "none"
    older = {k: v for k, v in model_file.items() if k not in ("wind", "d_u")}
    older["stats"] = {k: v for k, v in model_file["stats"].items() if k != "d_u"}  # stats' d_u came after d_u and wind (T56-B05)
    (tmp_path / "old.json").write_text(json.dumps(older))
    assert LearnedModel.load(tmp_path / "old.json").wind.kind == "none"


# ---------------------------------------------------------------------------------------------- T37-B07, T37-B08


@pytest.mark.parametrize(("task", "safe", "rule"), [("ghh08", [2, 6], [6, 2]), ("ghh09", [3, 6], [6, 3])])
def test_a_safe_list_reordered_against_its_tables_is_refused(tmp_path: Path, task: str, safe: list[int], rule: list[int]) -> None:
    """T37-B07: [6, 2] -> [2, 6] was taken, and the hybrid agent flew policy 2 as safe:0 (every run's returns changed)."""
    pd = edited_policy_set(tmp_path, task, lambda m: m.__setitem__("safe", safe))
    with pytest.raises(NeurohoverError) as err:
        load_policy_set(task, pd)
    message = str(err.value)
    assert message.startswith(f"policy-set manifest '{pd / task / 'manifest.json'}': safe={safe} is not allowed: the paper's rule on its ")
    assert f"tables gives {rule} (policy {rule[0]}, with as few crashes there (0) and a mean return of " in message, message
    assert f"give safe {rule}, or rebuild the set (neurohover build-policies --task {task})" in message


def test_a_safe_order_the_tables_cannot_tell_is_taken_either_way(tmp_path: Path) -> None:
    """T37-B07: mean returns within their rounding (0.01 each) order nothing, so either order loads; and a manifest
    without mean_return_on_training_mdps (older) orders only by crashes, as before."""

    def close(m: dict) -> None:  # policy 2's mean return on the other MDPs raised to 0.01 below policy 6's (-825.982)
        returns = m["mean_return_on_training_mdps"]
        shift = -825.992 - float(np.mean([v for j, v in enumerate(returns[2]) if j != 2]))
        returns[2] = [round(v + shift, 2) if j != 2 else v for j, v in enumerate(returns[2])]
        m["table3"]["r_G"] = round(float(np.mean(returns)), 2)
        m["safe"] = [2, 6]

    assert load_policy_set("ghh08", edited_policy_set(tmp_path / "a", "ghh08", close)).safe == (2, 6)
    older = edited_policy_set(tmp_path / "b", "ghh08", lambda m: (m.pop("mean_return_on_training_mdps"), m.pop("table3"), m.__setitem__("safe", [2, 6])))
    assert load_policy_set("ghh08", older).safe == (2, 6)
    for task, safe in (("ghh08", (6, 2)), ("ghh09", (6, 3))):  # the shipped sets, as built
        assert load_policy_set(task).safe == safe


@pytest.mark.parametrize(("task", "name"), [("ghh08", "specialised_10.json"), ("ghh08", "notes.txt"), ("fghh", "generic.json")])
def test_a_digest_of_a_file_the_set_does_not_have_is_refused(tmp_path: Path, task: str, name: str) -> None:
    """T37-B08: genome_sha256['specialised_10.json'] was taken without a word (the file itself is refused)."""
    pd = edited_policy_set(tmp_path, task, lambda m: m[DIGESTS].__setitem__(name, "0123456789abcdef"))
    with pytest.raises(NeurohoverError) as err:
        load_policy_set(task, pd)
    message = str(err.value)
    assert message.startswith(
        f"policy-set manifest '{pd / task / 'manifest.json'}': its {DIGESTS} entry '{name}' is not allowed: the set has no such policy file "
    ), message
    assert "(allowed one entry per file of the set: " in message


def test_an_independent_sets_digest_of_an_ancestor_is_refused(tmp_path: Path) -> None:
    """T37-B08: an independent lineage's set has no ancestor.json; a digest of one names no file of it."""

    def independent(m: dict) -> None:
        m["lineage"] = "independent"

    pd = edited_policy_set(tmp_path, "ghh08", independent)
    (pd / "ghh08" / "ancestor.json").unlink()
    with pytest.raises(NeurohoverError, match=f"its {DIGESTS} entry 'ancestor.json' is not allowed: the set has no such policy file"):
        load_policy_set("ghh08", pd)
