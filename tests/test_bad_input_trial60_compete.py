"""Bad-input trial 60 (the command line), T60-A01: ``compete --store OUT/summary.json`` (or ``OUT/episodes.csv``) in a
new OUT exited 0 and printed the store's path, but compete then wrote its summary.json (episodes.csv) over the store it
had just filled: the finished runs were lost, and the same command again (the documented resume) was refused as "not a
neurohover results store". ``OUT/cumulative.png`` was refused only once every run had flown. Now a store that is one of
the files compete writes in its output directory (or whose lock file is) is refused before anything is written or
flown, however its path is spelled, through a symbolic or hard link, and where an earlier compete made it a store."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from neurohover.errors import NeurohoverError

COMPETE = ("compete", "--task", "ghh08", "--agent", "baseline", "--runs", "1", "--episodes", "2", "--episode-steps", "20")
OWN = "one of the files compete writes there itself"


@pytest.mark.parametrize("store", ["c/summary.json", "c/episodes.csv", "c/cumulative.png", "./c/summary.json", "c/../c/episodes.csv", "c/.compete.lock"])
def test_a_store_among_competes_own_files_is_refused_before_any_run(cli, tmp_path: Path, monkeypatch, store: str) -> None:
    monkeypatch.chdir(tmp_path)
    (tmp_path / "c").mkdir()  # '..' climbs out of an existing folder only
    rc, out, err = cli(*COMPETE, "--out", "c", "--store", store)
    assert rc == 2, (out, err)
    assert f"--store {str(Path(store))!r} is {Path(store).name} in the output directory 'c', {OWN}" in err, err  # as Path spells it
    assert "Traceback" not in err and "store:" not in out
    assert os.listdir(tmp_path / "c") == []  # no run flown, no store made, no file written


def test_a_store_whose_lock_is_competes_lock_is_refused(cli, tmp_path: Path, monkeypatch) -> None:
    """Its STORE.lock would be compete's .compete.lock: refused as 'in use' by this very process, leaving an empty store."""
    monkeypatch.chdir(tmp_path)
    rc, out, err = cli(*COMPETE, "--out", "c", "--store", "c/.compete")
    assert rc == 2, (out, err)
    assert f"--store 'c/.compete' has its .lock file at .compete.lock in the output directory 'c', {OWN}" in err, err
    assert not (tmp_path / "c").exists()  # the folder it made, left empty, is removed


def test_the_python_api_goes_through_the_same_check(tmp_path: Path, monkeypatch) -> None:
    from neurohover.compete import compete

    monkeypatch.chdir(tmp_path)
    flown: list[str] = []
    for name in ("summary.json", "episodes.csv"):
        with pytest.raises(NeurohoverError, match=f"^store 'c/{name}' is {name} in the output directory 'c', {OWN}"):
            compete("ghh08", "baseline", runs=1, episodes=2, n_steps=20, out="c", store=Path("c", name),
                    on_result=lambda key, _: flown.append(key))  # fmt: skip
        assert flown == [] and os.listdir(tmp_path / "c") == []


def test_a_symbolic_link_in_out_to_the_store_is_refused(tmp_path: Path, monkeypatch) -> None:
    """c/summary.json a link to the new store s.sqlite: compete's summary was written through it onto the store."""
    from neurohover.compete import compete

    monkeypatch.chdir(tmp_path)
    (tmp_path / "c").mkdir()
    (tmp_path / "c" / "summary.json").symlink_to(tmp_path / "s.sqlite")
    with pytest.raises(NeurohoverError, match=f"^store 's.sqlite' is summary.json in the output directory 'c', {OWN}"):
        compete("ghh08", "baseline", runs=1, episodes=2, n_steps=20, out="c", store="s.sqlite")
    assert not (tmp_path / "s.sqlite").exists()


def test_a_store_an_earlier_compete_filled_there_is_refused_and_kept(cli, tmp_path: Path, monkeypatch) -> None:
    """A valid store at c/summary.json (an earlier compete into d) is named as the store, not as a foreign file, and is
    left as it was; the earlier compete still resumes from it (its run reused), and a hard link to it is refused too."""
    monkeypatch.chdir(tmp_path)
    assert cli(*COMPETE, "--out", "d", "--store", "c/summary.json")[0] == 0
    before = (tmp_path / "c" / "summary.json").read_bytes()
    rc, out, err = cli(*COMPETE, "--out", "c", "--store", "c/summary.json")
    assert rc == 2 and f"--store 'c/summary.json' is summary.json in the output directory 'c', {OWN}" in err, (out, err)
    assert (tmp_path / "c" / "summary.json").read_bytes() == before and os.listdir(tmp_path / "c") == ["summary.json"]
    os.link(tmp_path / "c" / "summary.json", tmp_path / "h.sqlite")
    rc, out, err = cli(*COMPETE, "--out", "c", "--store", "h.sqlite")
    assert rc == 2 and f"--store 'h.sqlite' is summary.json in the output directory 'c', {OWN}" in err, (out, err)
    rc, out, err = cli(*COMPETE, "--out", "d", "--store", "c/summary.json")
    assert rc == 0 and "already in" in err, (out, err)
