"""Bad-input trial 39 (the command line): a store named as another store's SQLite journal ('a.sqlite-journal', '-wal')
was deleted without a word as that store opened, and any file so named beside a store likewise (a policy file); a
directory there was the OS's bare "Is a directory" (T39-A01, T39-A03). -W error::EncodingWarning under
-X warn_default_encoding was numba's traceback in every command (T39-A02)."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from neurohover.errors import NeurohoverError
from neurohover.experiments import Store


@pytest.mark.parametrize("end", ["-journal", "-wal", "-shm"])
def test_a_store_named_as_sqlites_own_side_file_is_refused(cli, tmp_path: Path, end: str) -> None:
    name = tmp_path / f"a.sqlite{end}"
    for given in (str(name), name):
        with pytest.raises(NeurohoverError, match=f"SQLite keeps the {end} file of a store .* under that name"):
            Store(given)
    argv = ("compete", "--task", "ghh08", "--agent", "baseline", "--runs", "1", "--episodes", "2", "--episode-steps", "10")
    rc, _, err = cli(*argv, "--out", str(tmp_path / "c"), "--store", str(name))
    assert rc == 2 and "give a name not ending -journal, -wal, -shm" in err, err
    assert not name.exists()


def test_a_file_sqlite_would_take_for_a_stores_journal_is_refused_and_kept(cli, tmp_path: Path) -> None:
    from neurohover import baseline_policy, save_policy

    store = tmp_path / "b.sqlite"
    with Store(store):
        pass
    save_policy(baseline_policy(), tmp_path / "p.json")
    journal, wal = tmp_path / "b.sqlite-journal", tmp_path / "b.sqlite-wal"
    shutil.copy(tmp_path / "p.json", journal)
    with pytest.raises(NeurohoverError, match="b.sqlite-journal'.* is a policy file, not SQLite's -journal file of the store, and SQLite would delete it"):
        Store(store, create=False)
    assert journal.read_bytes() == (tmp_path / "p.json").read_bytes()
    journal.unlink()
    shutil.copy(store, wal)  # another store
    with pytest.raises(NeurohoverError, match="b.sqlite-wal'.* is a results store \\(SQLite\\), not SQLite's -wal file of the store"):
        Store(store)
    wal.unlink()
    journal.mkdir()
    rc, _, err = cli("results", "x", "--store", str(store))
    assert rc == 2 and "is a directory where SQLite keeps the store's -journal file: remove it" in err, err
    journal.rmdir()
    journal.write_bytes(b"")  # an empty one is SQLite's to remove, as a journal it left
    with Store(store, create=False) as opened:
        assert opened.experiments() == []


@pytest.mark.slow
def test_warnings_of_the_libraries_default_encodings_as_errors_end_no_command() -> None:
    argv = [sys.executable, "-X", "warn_default_encoding", "-W", "error::EncodingWarning", "-m", "neurohover", "fly", "--task", "ghh08", "--episodes", "1"]
    done = subprocess.run(argv, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0 and "EncodingWarning" not in done.stderr, done.stderr[-2000:]


@pytest.mark.slow
def test_compete_names_its_files_once_under_an_out_ending_in_a_slash(cli, tmp_path: Path) -> None:
    """Noticed in trial 39: `--out k18/` printed k18//episodes.csv; and a reproduce of one unit said "ran 1 units"."""
    argv = ("compete", "--task", "ghh08", "--agent", "baseline", "--runs", "1", "--episodes", "2", "--episode-steps", "10")
    rc, out, err = cli(*argv, "--out", str(tmp_path / "k18") + "/")
    assert rc == 0 and f"results: {tmp_path / 'k18'}/episodes.csv," in out and "//" not in out, (out, err)
