"""Bad-input trial 47 (the command line), T47-A01: a compete folder holding a results.sqlite left by an earlier compete,
rewritten by a compete with --store elsewhere whose store was then moved, was checked against the leftover file, and
``plot --compete`` refused the genuine summary as "an edit by hand"; a summary naming a --store that is gone is not read."""

from __future__ import annotations

from pathlib import Path

import pytest

from neurohover.errors import NeurohoverError

COMPETE = ("compete", "--task", "ghh08", "--agent", "baseline", "--runs", "1", "--episode-steps", "20")


@pytest.mark.slow
def test_a_leftover_own_store_is_not_read_once_the_named_store_is_gone(cli, tmp_path: Path, monkeypatch) -> None:
    from neurohover.compete import check_against_store

    monkeypatch.chdir(tmp_path)
    assert cli(*COMPETE, "--episodes", "2", "--out", "c1")[0] == 0  # leaves c1/results.sqlite
    assert cli(*COMPETE, "--episodes", "4", "--out", "c1", "--store", "s.sqlite")[0] == 0
    assert (tmp_path / "c1" / "results.sqlite").is_file()
    (tmp_path / "s.sqlite").rename(tmp_path / "moved.sqlite")
    check_against_store(tmp_path / "c1")  # not read: no refusal
    rc, out, err = cli("plot", "--compete", "c1", "--out", "p")
    assert rc == 0 and out.strip().endswith("compete.png"), err


@pytest.mark.slow
def test_a_moved_folder_is_still_checked_against_its_own_default_store(cli, tmp_path: Path, monkeypatch) -> None:
    """T46-B05 kept: a folder whose summary names its own default store is checked against it after a move."""
    import json

    from neurohover.compete import check_against_store

    monkeypatch.chdir(tmp_path)
    assert cli(*COMPETE, "--episodes", "2", "--out", "c1")[0] == 0
    (tmp_path / "c1").rename(tmp_path / "c2")
    summary = tmp_path / "c2" / "summary.json"
    edited = json.loads(summary.read_text()) | {"seed": 7}
    summary.write_text(json.dumps(edited))
    with pytest.raises(NeurohoverError, match="is not what its store"):
        check_against_store(tmp_path / "c2")
