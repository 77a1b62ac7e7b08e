"""Trial 49, side B (Python API): a policy-set manifest's built time in exactly the form a build writes (T49-B01),
compete.check_against_store's reading of a damaged summary.json or a non-path argument (T49-B03) and compete's lr_fit
given as no mapping (T49-B04)."""

from __future__ import annotations

import json
import re
import shutil
from pathlib import Path

import pytest

import neurohover
from neurohover.errors import NeurohoverError

SHIPPED = Path(neurohover.__file__).parent / "data" / "policies"
BUILD_TIME = "give the build's time as YYYY-MM-DD HH:MM:SS"


def _set_with_built(tmp_path: Path, built: str) -> Path:
    """A copy of the shipped ghh08 set under ``tmp_path``/sets, its manifest's built edited to ``built``."""
    shutil.copytree(SHIPPED / "ghh08", tmp_path / "sets" / "ghh08")
    manifest = tmp_path / "sets" / "ghh08" / "manifest.json"
    manifest.write_text(json.dumps(json.loads(manifest.read_text()) | {"built": built}))
    return tmp_path / "sets"


@pytest.mark.parametrize(
    "built",
    ["2026-12-07\n10:40:59", "2026-12-07 \t 10:40:59", "2026-12-07\xa010:40:59", "2026-12-07\t10:40:59", "２０２６-1-7\n1:2:3",
     "\u0662\u0660\u0662\u0666-12-07 10:40:59", "2026-1-7 1:2:3", "2026-12-07 10:40:59\n", " 2026-12-07 10:40:59", "2026-12-07  10:40:59",
     "2026-02-30 10:40:59", "2026-12-07T10:40:59"],
)  # fmt: skip
def test_a_manifests_built_is_exactly_a_build_time(tmp_path: Path, built: str) -> None:
    """T49-B01: strptime took any whitespace for the space, Unicode digits and one-digit fields; the form is exact now."""
    from neurohover.policysets import load_policy_set

    sets = _set_with_built(tmp_path, built)
    with pytest.raises(NeurohoverError, match=re.escape(BUILD_TIME)) as err:
        load_policy_set("ghh08", sets)
    assert repr(built)[:20] in str(err.value)


def test_every_written_built_time_still_loads(tmp_path: Path) -> None:
    """T49-B01: the shipped sets, and a built time as build_policy_set writes it (time.strftime), load."""
    import time

    from neurohover.policysets import load_policy_set

    for task in ("ghh08", "ghh09", "fghh"):
        load_policy_set(task)
    sets = _set_with_built(tmp_path, time.strftime("%Y-%m-%d %H:%M:%S"))
    assert load_policy_set("ghh08", sets).manifest["built"]


@pytest.fixture(scope="module")
def competed(tmp_path_factory) -> Path:
    """A small competition's folder (its own store inside it)."""
    from neurohover.compete import compete

    out = tmp_path_factory.mktemp("t49") / "c"
    compete("ghh08", "baseline", runs=1, episodes=2, n_steps=20, out=out)
    return out


def _summary_holding(competed: Path, tmp_path: Path, text: str | bytes) -> Path:
    folder = tmp_path / "c"
    shutil.copytree(competed, folder)
    (folder / "summary.json").write_bytes(text.encode() if isinstance(text, str) else text)
    return folder


@pytest.mark.parametrize(
    ("summary", "says"),
    [("twice", "cannot be read"), ("[1, 2]", "is not a compete summary"), (b'{"agent": "caf\xe9"}', "cannot be read"),
     ("", "cannot be read"), ("[" * 5000 + "]" * 5000, "cannot be read"), ('{"agent": "baseline", "runs": ' + "9" * 5000 + "}", "cannot be read")],
    ids=["key-twice", "list", "latin-1", "empty", "nested-5000", "digits-5000"],
)  # fmt: skip
def test_check_against_store_refuses_a_damaged_summary_as_read_compete_dir_does(competed: Path, tmp_path: Path, summary, says: str) -> None:
    """T49-B03: a key given twice was a JSONError, [1, 2] an AttributeError ... now read_compete_dir's refusal, the same."""
    from neurohover.compete import check_against_store
    from neurohover.compete_files import read_compete_dir

    if summary == "twice":
        summary = (competed / "summary.json").read_text().replace('"runs": 1,', '"runs": 1, "runs": 1,')
        assert summary.count('"runs"') == 2
    folder = _summary_holding(competed, tmp_path, summary)
    with pytest.raises(NeurohoverError, match=says) as by_reader:
        read_compete_dir(folder)
    with pytest.raises(NeurohoverError, match=says) as err:
        check_against_store(folder)
    assert str(err.value).startswith(f"--compete {str(folder / 'summary.json')!r}")
    assert str(err.value) == str(by_reader.value)


@pytest.mark.parametrize("folder", [None, 5, b"c", ""])
def test_check_against_store_refuses_a_non_path_by_name(folder) -> None:
    """T49-B03: None or 5 was os.fspath's TypeError; refused as read_compete_dir refuses them."""
    from neurohover.compete import check_against_store

    with pytest.raises(NeurohoverError, match="--compete"):
        check_against_store(folder)


def test_check_against_store_still_passes_a_written_folder_and_refuses_a_missing_one(competed: Path, tmp_path: Path) -> None:
    from neurohover.compete import check_against_store

    check_against_store(competed)
    check_against_store(str(competed))
    with pytest.raises(NeurohoverError, match="no such directory"):
        check_against_store(tmp_path / "gone")


@pytest.mark.parametrize("lr_fit", ["noise=rms", 5, ["noise"], (("estimator", "ols"),), b"x", "", 0, []])
def test_a_non_mapping_lr_fit_is_refused_by_name(lr_fit) -> None:
    """T49-B04: 'noise=rms' was an AttributeError ('str' object has no attribute 'items'); '' and [] were taken as none."""
    from neurohover.compete import LR_FIT_KEYS, competition_config

    says = f"lr_fit={neurohover.errors.brief(lr_fit)} is not allowed: give a dict of LR fit choices (keys {', '.join(LR_FIT_KEYS)})"
    with pytest.raises(NeurohoverError, match=re.escape(says)):
        competition_config("ghh08", "model-based", runs=1, episodes=1, lr_fit=lr_fit)


def test_compete_refused_for_its_lr_fit_creates_nothing(tmp_path: Path) -> None:
    """T49-B04: refused before its output folder is made."""
    from neurohover.compete import compete, competition_config

    competition_config("ghh08", "model-based", runs=1, episodes=1, lr_fit=None)  # as before
    with pytest.raises(NeurohoverError, match="lr_fit='ols' is not allowed"):
        compete("ghh08", "model-based", runs=1, episodes=1, n_steps=20, lr_fit="ols", out=tmp_path / "out")
    assert not (tmp_path / "out").exists()
