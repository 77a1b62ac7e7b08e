"""Trial 31 (31a), the command line: T31-A02 (two build-policies on one set at once: the second deleted the first's live
.building folder, and both said "policy set written"), the borderline two compete runs into one --out with other
stores (each printed the folder's files as its own), T31-A03 (a --store name that fits but whose -journal does not:
the OS's bare "File name too long", cut mid-name) and T31-A04 (reproduce --progress with standard error closed died in
tqdm with status 1 and no word)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import ROOT, tiny_test_runs

from neurohover.errors import NeurohoverError, brief
from neurohover.filekinds import fitting_name, name_limit
from neurohover.paths import WriterLock, sole_writer

BUILD = ["build-policies", "--task", "ghh08", "--budget", "1", "--episode-steps", "20"]
COMPETE = ["compete", "--task", "ghh08", "--agent", "baseline", "--runs", "1", "--episodes", "2", "--episode-steps", "20"]


@pytest.fixture
def tiny_config(tmp_path: Path) -> Path:
    path = tmp_path / "tiny.toml"
    path.write_text(tiny_test_runs("baseline"))
    return path


# T31-A02: one build of a policy set at a time


def test_a_second_build_of_a_set_being_built_is_refused_and_leaves_its_building_folder(cli, tmp_path: Path) -> None:
    out = tmp_path / "ps"
    live = out / "ghh08.building" / "stages"
    live.mkdir(parents=True)
    (live / "build.json").write_text("{}\n")  # the first build's state (other settings): it was deleted as "interrupted"
    with sole_writer(out / "ghh08", "out"):  # the first build, writing (the lock is the OS's: another process's alike)
        (out / ".ghh08.lock").write_text("4242\n")
        rc, stdout, err = cli(*BUILD, "--out", str(out))
        assert rc == 2 and f"error: out '{out / 'ghh08'}' is being written by another run (pid 4242)" in err, err
        assert "policy set written" not in stdout and "started over" not in err
        assert (live / "build.json").read_text() == "{}\n" and not (out / "ghh08").exists()


def test_build_policy_set_refuses_a_set_another_build_is_writing(tmp_path: Path) -> None:
    from neurohover.policysets import build_policy_set

    out = tmp_path / "ps"
    out.mkdir()
    with sole_writer(out / "ghh08", "out"), pytest.raises(NeurohoverError, match="is being written by another run"):
        build_policy_set("ghh08", out, budget=1, n_steps=20)
    assert not (out / "ghh08.building").exists()


def test_a_killed_builds_lock_and_building_folder_are_cleared(cli, tmp_path: Path) -> None:
    """A killed build leaves its lock file (no lock: the kernel dropped it) and its .building: the next build proceeds."""
    out = tmp_path / "ps"
    (out / "ghh08.building" / "stages").mkdir(parents=True)
    (out / "ghh08.building" / "stages" / "build.json").write_text('{"seed": 99}\n')
    (out / ".ghh08.lock").write_text("4242 h\n")
    rc, stdout, err = cli(*BUILD, "--out", str(out))
    assert rc == 0 and "policy set written" in stdout, err
    assert "holds an interrupted build of other settings; it is started over" in err
    assert sorted(p.name for p in out.iterdir()) == ["ghh08"] and (out / "ghh08" / "manifest.json").is_file()


# Borderline: one competition at a time in one --out, whatever its store


@pytest.mark.slow
def test_a_second_competition_into_a_folder_in_use_is_refused(cli, tmp_path: Path) -> None:
    out = tmp_path / "d"
    out.mkdir()
    lock = WriterLock(out / ".compete.lock")  # a first competition, with its own --store elsewhere
    assert lock.acquire(lambda who: who)
    try:
        rc, stdout, err = cli(*COMPETE, "--out", str(out), "--store", str(tmp_path / "other.sqlite"))
        assert rc == 2 and f"error: --out {brief(str(out))} is in use: another compete run (pid {os.getpid()} on host " in err, err
        assert "give another output directory" in err and "results:" not in stdout
        assert sorted(p.name for p in out.iterdir()) == [".compete.lock"]
    finally:
        lock.release()
    rc, stdout, err = cli(*COMPETE, "--out", str(out), "--store", str(tmp_path / "other.sqlite"))
    assert rc == 0 and f"results: {out}/episodes.csv" in stdout, err
    assert not (out / ".compete.lock").exists()  # released: no file left beside the results


@pytest.mark.slow
def test_a_killed_competitions_lock_file_does_not_block_the_next(cli, tmp_path: Path) -> None:
    out = tmp_path / "d"
    out.mkdir()
    (out / ".compete.lock").write_text("4242 h\n")  # left by a killed run: no process holds it
    rc, _, err = cli(*COMPETE, "--out", str(out))
    assert rc == 0 and (out / "summary.json").is_file() and not (out / ".compete.lock").exists(), err


# T31-A03: a store's name is checked with the -journal SQLite writes beside it


def _long_store(where: Path, spare: int) -> tuple[Path, int]:
    """A store path in ``where`` whose name is ``spare`` bytes under the file system's limit, and that limit."""
    limit = name_limit(where)
    return where / ("s" * (limit - spare - len(".sqlite")) + ".sqlite"), limit


def _refused_long(err: str, option: str, store: Path, limit: int) -> None:
    fits = fitting_name(store.name, limit, len("-journal"))
    assert f"error: {option} {brief(str(store))} is too long: at most {limit} bytes in one file name, with the -journal" in err, err
    assert f"e.g. {brief(str(store.with_name(fits)))}" in err and len(fits) + len("-journal") == limit
    assert "File name too long" not in err


@pytest.mark.parametrize("spare", [7, 0])
def test_reproduce_refuses_a_store_name_whose_journal_would_be_too_long(cli, tmp_path: Path, tiny_config: Path, spare: int) -> None:
    store, limit = _long_store(tmp_path, spare)
    rc, _, err = cli("reproduce", str(tiny_config), "--store", str(store), "--no-progress")
    assert rc == 2
    _refused_long(err, "--store", store, limit)
    assert not store.exists()


def test_reproduce_takes_the_longest_store_name_that_fits(cli, tmp_path: Path, tiny_config: Path) -> None:
    store, _ = _long_store(tmp_path, len("-journal"))
    rc, stdout, err = cli("reproduce", str(tiny_config), "--store", str(store), "--no-progress")
    assert rc == 0 and "finished" in stdout, err


def test_compete_refuses_a_store_name_whose_journal_would_be_too_long(cli, tmp_path: Path) -> None:
    store, limit = _long_store(tmp_path, 5)
    rc, _, err = cli(*COMPETE, "--out", str(tmp_path / "d"), "--store", str(store))
    assert rc == 2
    _refused_long(err, "--store", store, limit)
    assert not store.exists() and not (tmp_path / "d").exists()


def test_the_python_store_refuses_to_create_it_and_reads_one_that_exists(tmp_path: Path) -> None:
    from neurohover.compete import compete
    from neurohover.experiments import Store

    store, limit = _long_store(tmp_path, 3)
    with pytest.raises(NeurohoverError, match=r"^results store .* is too long: at most \d+ bytes in one file name, with the -journal"):
        Store(store)
    with pytest.raises(NeurohoverError, match=r"^store .* is too long: .* with the -journal"):
        compete("ghh08", "baseline", runs=1, episodes=2, n_steps=20, out=tmp_path / "d", store=store)
    assert not store.exists() and not (tmp_path / "d").exists()
    with Store(tmp_path / "short.sqlite") as db:  # made under a short name, then renamed: reading writes no journal
        db.conn  # noqa: B018
    (tmp_path / "short.sqlite").rename(store)
    with Store(store, create=False) as db:
        assert db.experiments() == []


# T31-A04: --progress with standard error closed draws no bar


def test_reproduce_with_progress_runs_with_standard_error_closed(cli, tmp_path: Path, tiny_config: Path, monkeypatch) -> None:
    """It died in tqdm (AttributeError), status 1 and no word, before any unit ran."""
    monkeypatch.setattr(sys, "stderr", None)  # what Python makes of `2>&-`
    rc, stdout, _ = cli("reproduce", str(tiny_config), "--store", str(tmp_path / "s.sqlite"), "--progress")
    assert rc == 0 and "tr1 (quick): finished; ran 1 unit," in stdout, stdout


@pytest.mark.slow
def test_a_bar_asked_for_in_a_process_whose_standard_error_is_closed_is_not_drawn() -> None:
    """Standard error closed as a shell's ``2>&-`` closes it, in a process of its own."""
    code = "from neurohover.progress import progress_bar\nwith progress_bar(total=2, disable=False) as bar:\n    bar.update(2)\nprint('ok')"
    done = subprocess.run([sys.executable, "-c", code], cwd=ROOT, stdout=subprocess.PIPE, text=True, preexec_fn=lambda: os.close(2), timeout=60)
    assert done.returncode == 0 and done.stdout == "ok\n", done.stdout


def test_a_bar_on_a_closed_or_unwritable_stream_is_not_drawn(tmp_path: Path) -> None:
    from neurohover.progress import _Quiet, progress_bar

    assert isinstance(progress_bar(total=3, file=None, disable=False), _Quiet)
    (tmp_path / "f").write_text("")
    with open(tmp_path / "f") as read_only:  # a descriptor reopened for reading under standard error: Errno 9 from tqdm
        assert isinstance(progress_bar(total=3, file=read_only, disable=False), _Quiet)
    closed = open(tmp_path / "g", "w")
    closed.close()
    assert isinstance(progress_bar(total=3, file=closed, disable=False), _Quiet)


@pytest.mark.slow
def test_an_error_with_standard_error_open_for_reading_only_is_said_on_standard_output() -> None:
    """``2</dev/null``: standard error is a descriptor open for reading, so the error line failed again inside the
    command's own handler: status 1 and no word anywhere (trial 31). Taken as closed, the line goes to standard output."""

    def read_only_stderr() -> None:
        fd = os.open(os.devnull, os.O_RDONLY)
        os.dup2(fd, 2)

    code = "import sys; from neurohover.cli.app import main; sys.exit(main())"
    done = subprocess.run(
        [sys.executable, "-c", code, "fly", "--task", "nope"], cwd=ROOT, stdout=subprocess.PIPE, text=True, preexec_fn=read_only_stderr, timeout=60
    )
    assert done.returncode == 2
    assert "neurohover fly: error: unknown task 'nope'" in done.stdout
