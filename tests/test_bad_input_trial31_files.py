"""Bad-input trial 31, files: T31-B01 (a 1-byte file given as a results store was written over with a fresh store),
T31-B03 (under an ASCII file-system encoding a non-ASCII path was os.fsencode's UnicodeEncodeError at every API file
entry point), T31-B06 (a lone surrogate in a store's text field was SQLite's UnicodeEncodeError) and T31-B07 (a history
CSV cut inside its last number read as another number)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import store_edits

import neurohover as nh
from neurohover.errors import NeurohoverError
from neurohover.evolution.records import HISTORY_COLUMNS, read_history_csv
from neurohover.experiments import Store, Unit

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.parametrize("body", [b"x", b"\n", b"\x00", b"S", b"SQLite format 3", b"not a store at all, longer than a header"])
@pytest.mark.parametrize("create", [False, True])
def test_a_non_empty_file_without_sqlites_header_is_no_store(tmp_path: Path, body: bytes, create: bool) -> None:
    """T31-B01: Store(path) on a 1-byte file (``echo > results.sqlite``) took it as an empty database and wrote the schema
    over it, create=False too; any non-empty file not starting with SQLite's header is refused, and left as it was."""
    path = tmp_path / "one.sqlite"
    path.write_bytes(body)
    with pytest.raises(NeurohoverError, match=r"'.*one\.sqlite' is not a neurohover results store \(it does not start with SQLite's header"):
        Store(path, create=create)
    assert path.read_bytes() == body


def test_a_store_and_an_empty_file_are_still_taken(tmp_path: Path) -> None:
    """T31-B01: the header rule leaves a real store and create=True's 0-byte file (reproduce's emptied store) as they were."""
    Store(tmp_path / "s.sqlite").close()
    assert Store(tmp_path / "s.sqlite", create=False).experiments() == []
    (tmp_path / "e.sqlite").write_bytes(b"")
    Store(tmp_path / "e.sqlite").close()
    assert (tmp_path / "e.sqlite").read_bytes().startswith(b"SQLite format 3\x00")


_ASCII_ENTRY_POINTS = r"""
import json, sys
import numpy as np
import neurohover as nh
from neurohover.errors import NeurohoverError
from neurohover.evolution.records import read_history_csv, write_history_csv
from neurohover.experiments import Store
from neurohover.models import LearnedModel
from neurohover.policysets import load_policy_set

if sys.getfilesystemencoding() != "ascii":
    print(json.dumps({"skip": sys.getfilesystemencoding()}))
    raise SystemExit
fd = nh.FlightData((np.zeros((3, 12)),), (np.zeros((2, 4)),), {})
calls = {
    "load_policy": lambda: nh.load_policy("\u76f4\u5347\u673a.json"),
    "save_policy": lambda: nh.save_policy(nh.baseline_policy(), "\u76f4\u5347\u673a.json"),
    "FlightData.load": lambda: nh.FlightData.load("\U0001f681.npz"),
    "FlightData.save": lambda: fd.save("new\u00e9/f.npz"),
    "LearnedModel.load": lambda: LearnedModel.load("m\u00e9.json"),
    "Store": lambda: Store("s\u00e9.sqlite"),
    "Store(create=False)": lambda: Store("s\u00e9.sqlite", create=False),
    "load_policy_set": lambda: load_policy_set("ghh08", directory="d\u00e9"),
    "read_history_csv": lambda: read_history_csv("h\u00e9.history.csv"),
    "write_history_csv": lambda: write_history_csv([], "h\u00e9.history.csv"),
}
said = {}
for name, call in calls.items():
    try:
        call()
        said[name] = "no error"
    except NeurohoverError as err:
        said[name] = str(err)
    except Exception as err:
        said[name] = f"{type(err).__name__}: {err}"
print(json.dumps(said))
"""


@pytest.mark.slow
def test_a_path_the_file_systems_encoding_cannot_encode_is_refused_by_name(tmp_path: Path) -> None:
    """T31-B03: under LC_ALL=C PYTHONUTF8=0 (file-system encoding 'ascii') a non-ASCII path was os.fsencode's
    UnicodeEncodeError from every API file entry point; each is one NeurohoverError naming the path and the encoding."""
    env = {**os.environ, "LC_ALL": "C", "PYTHONUTF8": "0", "PYTHONPATH": str(ROOT)}
    env.pop("PYTHONIOENCODING", None)
    done = subprocess.run([sys.executable, "-c", _ASCII_ENTRY_POINTS], cwd=tmp_path, env=env, capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    said = json.loads(done.stdout.splitlines()[-1])
    if "skip" in said:
        pytest.skip(f"LC_ALL=C PYTHONUTF8=0 gives the file-system encoding {said['skip']!r} here, not 'ascii'")
    for name, message in said.items():
        assert "the file system's encoding (ascii) cannot encode" in message and "UTF-8 locale" in message, (name, message)
    assert "'\\u76f4\\u5347\\u673a.json'" in said["load_policy"] or "'直升机.json'" in said["load_policy"]
    assert list(tmp_path.iterdir()) == []  # nothing written, no directory made


def test_a_lone_surrogate_in_a_path_is_refused_by_name(tmp_path: Path) -> None:
    """T31-B03: a lone surrogate no encoding takes (not a surrogate-escaped byte) was the same UnicodeEncodeError."""
    with pytest.raises(NeurohoverError, match=r"policy file .* cannot encode the characters '\\ud800'"):
        nh.load_policy(str(tmp_path / "p\ud800.json"))
    with pytest.raises(NeurohoverError, match=r"results store .* cannot encode the characters '\\ud800'"):
        Store(str(tmp_path / "s\ud800.sqlite"))


def test_a_lone_surrogate_in_a_stored_text_field_is_refused_by_name(tmp_path: Path) -> None:
    """T31-B06: a lone surrogate in a unit's key, a worker or a session's executor was SQLite's UnicodeEncodeError."""
    store = Store(tmp_path / "sur.sqlite")
    h = store_edits.begin(store, "tr2")
    calls = {
        "the unit's key": lambda: store.put("tr2", "quick", h, Unit("tr2", "x\ud800", "diagnostic", {}), {"value": 1, "seed": None}, 1.0),
        "worker": lambda: store.put("tr2", "quick", h, Unit("tr2", "w1", "diagnostic", {}), {"value": 1, "seed": None}, 1.0, worker="w\ud800"),
        "executor": lambda: store.start_session("tr2", "quick", h, "loc\ud800", 1, 0),
    }
    for what, call in calls.items():
        with pytest.raises(NeurohoverError, match=rf"{what} = '\w+\\ud800' is not allowed: it holds '\\ud800', a lone surrogate"):
            call()
    assert store.put("tr2", "quick", h, Unit("tr2", "w1", "diagnostic", {}), {"value": 1, "seed": None}, 1.0, worker="w")


def test_a_lone_surrogate_in_policy_and_flight_metadata_reads_back(tmp_path: Path) -> None:
    """T31-B06 (not a bug): JSON writes a lone surrogate in metadata as an escape, which reads back as it was."""
    path = nh.save_policy(nh.baseline_policy(), tmp_path / "p.json", note="x\ud800")
    assert nh.load_policy(path).metadata["note"] == "x\ud800"
    fd = nh.FlightData((np.zeros((3, 12)),), (np.zeros((2, 4)),), {"note": "x\ud800"})
    assert nh.FlightData.load(fd.save(tmp_path / "f.npz")).metadata == {"note": "x\ud800"}


def test_a_history_csv_cut_inside_its_last_number_is_refused(tmp_path: Path) -> None:
    """T31-B07: a history cut from ',0.0193' to ',0.01' read as 0.01; a file neurohover writes ends with a newline."""
    whole = tmp_path / "p.json.history.csv"
    whole.write_text(",".join(HISTORY_COLUMNS) + "\n1,1,1,1,-5.0,0.0100\n2,3,4,3,-4.0,0.0193\n")
    assert read_history_csv(whole)[-1].wall_seconds == 0.0193
    cut = tmp_path / "cut.history.csv"
    cut.write_bytes(whole.read_bytes()[:-3])
    with pytest.raises(NeurohoverError, match=r"'.*cut\.history\.csv' does not end with a newline.*looks cut off \(its last line '2,3,4,3,-4.0,0.01'\)"):
        read_history_csv(cut)
    header_only = tmp_path / "h.history.csv"
    header_only.write_text(",".join(HISTORY_COLUMNS))
    with pytest.raises(NeurohoverError, match="looks cut off"):
        read_history_csv(header_only)
    with pytest.raises(NeurohoverError, match=r"history file '.*gone\.history\.csv': no such file"):
        read_history_csv(tmp_path / "gone.history.csv")


@pytest.mark.slow
def test_a_compete_episodes_file_cut_inside_its_last_row_is_refused(tmp_path: Path) -> None:
    """T31-B07's twin in compete's episodes.csv: a row cut inside its return read as another return, a cut-off
    safeguard_fired '1' as 0; every episodes file compete writes ends with a newline."""
    from neurohover.compete import compete
    from neurohover.compete_files import read_compete_dir

    out = tmp_path / "c"
    compete("ghh08", "baseline", out=out, runs=1, episodes=2, n_steps=20)
    read_compete_dir(out)
    csv_path = out / "episodes.csv"
    csv_path.write_bytes(csv_path.read_bytes().rstrip(b"\r\n")[:-2])
    with pytest.raises(NeurohoverError, match=r"^--compete '.*episodes\.csv' does not end with a newline.*looks cut off \(its last line '0,.*,baseline'\)"):
        read_compete_dir(out)
