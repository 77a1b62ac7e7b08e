"""Trial 32's command-line findings on the results store and standard output: T32-A01 (``--store :memory:`` ran a whole
experiment into SQLite's in-memory database), T32-A02 (a ``--store file:...`` name was opened as a SQLite URI, another
file written), T32-A04 (a write refused by a file-size limit called the store "damaged"), T32-A05 (standard output cut
short by a file-size limit, status 0) and T32-A08 (a hard link to a store got around its writer lock)."""

from __future__ import annotations

import json
import os
import resource
import sqlite3
import subprocess
import sys
from pathlib import Path

import pytest
import store_edits as SE

from neurohover.errors import NeurohoverError
from neurohover.experiments import Store

TESTS = Path(__file__).resolve().parent


@pytest.fixture(scope="module")
def competed(tmp_path_factory) -> Path:
    """A store one tiny compete run wrote (experiment compete-ghh08-baseline)."""
    return SE.competed_store(tmp_path_factory.mktemp("competed"))


# ------------------------------------------------------------------ T32-A01, T32-A02: names SQLite reads as no file


@pytest.mark.parametrize("name", [":memory:", "file:", "file::memory:", "file:x.sqlite?mode=memory", "file:s03.sqlite", "FILE:u.sqlite"])
def test_store_names_sqlite_reads_as_no_file_are_refused(tmp_path: Path, monkeypatch, name: str) -> None:
    monkeypatch.chdir(tmp_path)
    with pytest.raises(NeurohoverError, match=r"^results store '.*' (is not allowed: it is SQLite's in-memory|looks like a SQLite URI: give a file path)"):
        Store(name)
    assert os.listdir(tmp_path) == []


@pytest.mark.parametrize("name", [":memory:", "file:s03.sqlite", "file::memory:"])
@pytest.mark.parametrize("command", ["reproduce", "results", "report", "wins", "compete"])
def test_every_command_refuses_a_store_name_sqlite_reads_as_no_file(cli, tmp_path: Path, monkeypatch, command: str, name: str) -> None:
    monkeypatch.chdir(tmp_path)
    argv = {
        "reproduce": ["reproduce", "fig7"],
        "results": ["results", "fig7"],
        "report": ["report", "--out", "r"],
        "wins": ["wins", "fig7"],
        "compete": [*SE.COMPETE, "--out", "c"],
    }[command]
    rc, out, err = cli(*argv, "--store", name)
    assert rc == 2 and out == ""
    assert err.splitlines()[-1].startswith(f"neurohover {command}: error: --store {name!r} ")  # after a first use's "compiling" note
    assert "in-memory database" in err if name == ":memory:" else "looks like a SQLite URI: give a file path" in err
    assert os.listdir(tmp_path) == []


def test_a_store_named_like_a_uri_given_as_a_path_is_that_file(tmp_path: Path, monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)
    with Store("./file:s03.sqlite") as store:
        SE.begin(store)
    with Store(str(tmp_path / "x.sqlite?mode=memory#f%41")) as store:  # opened by its path, never a URI: '?', '#', '%' are the name's
        SE.begin(store)
    assert sorted(os.listdir(tmp_path)) == ["file:s03.sqlite", "x.sqlite?mode=memory#f%41"]
    with Store(Path("file:s03.sqlite"), create=False) as store:  # a Path object is a path (pathlib drops './')
        assert [e[0] for e in store.experiments()] == ["tr1"]


@pytest.mark.slow
def test_compete_names_the_file_its_store_is_in(cli, tmp_path: Path, monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)
    rc, out, err = cli(*SE.COMPETE, "--out", "c", "--store", "./file:c.sqlite")
    assert rc == 0, err
    stored = json.loads(Path("c/summary.json").read_text())["store"]
    assert Path(stored).resolve() == (tmp_path / "file:c.sqlite").resolve()
    rc, out, err = cli("results", "compete-ghh08-baseline", "--store", "./file:c.sqlite")
    assert rc == 0 and out.startswith("experiment,"), err


# ------------------------------------------------------------------ T32-A08: a hard link and the writer lock


def test_a_hard_link_to_a_store_being_written_is_refused(tmp_path: Path) -> None:
    first = Store(tmp_path / "hl.sqlite")
    SE.begin(first)  # it holds the writer lock from here
    os.link(tmp_path / "hl.sqlite", tmp_path / "hl_hard.sqlite")
    with Store(tmp_path / "hl.sqlite", create=False) as reader:  # SQLite closing a descriptor of the file drops no lock
        assert [e[0] for e in reader.experiments()] == ["tr1"]
    second = Store(tmp_path / "hl_hard.sqlite")
    with pytest.raises(NeurohoverError, match=r"^results store '.*hl_hard.sqlite' is in use: another run is writing it under another name"):
        SE.begin(second, "tr2")
    assert not (tmp_path / "hl_hard.sqlite.lock").exists()  # the refused one holds no lock file either
    first.close()
    SE.begin(second, "tr2")  # the first run closed the store: the second writes it
    second.close()


@pytest.mark.slow
def test_a_hard_link_is_refused_to_another_process(tmp_path: Path) -> None:
    (tmp_path / "hold.py").write_text(
        "import sys\nsys.path.insert(0, sys.argv[2])\nimport store_edits as SE\nfrom neurohover.experiments import Store\n"
        "store = Store(sys.argv[1])\nSE.begin(store)\nprint('held', flush=True)\nsys.stdin.read()\nstore.close()\n"
    )
    holder = subprocess.Popen(
        [sys.executable, str(tmp_path / "hold.py"), str(tmp_path / "hl.sqlite"), str(TESTS)], stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True
    )
    try:
        assert holder.stdout is not None and holder.stdout.readline() == "held\n"
        os.link(tmp_path / "hl.sqlite", tmp_path / "hl_hard.sqlite")
        with Store(tmp_path / "hl_hard.sqlite") as second, pytest.raises(NeurohoverError, match="is in use: another run is writing it"):
            SE.begin(second, "tr2")
    finally:
        holder.communicate("", timeout=30)
    assert holder.returncode == 0


# ------------------------------------------------------------------ T32-A04: a write a file-size limit refuses

_LIMITED_PUT = """
import os, resource, sys
sys.path.insert(0, sys.argv[2])
import store_edits as SE
from neurohover.errors import NeurohoverError
from neurohover.experiments import Store, Unit
with Store(sys.argv[1]) as store:
    h = SE.begin(store)
    store.put("tr1", "quick", h, Unit("tr1", "k1", "diagnostic", {}), {"value": 1, "seed": None}, 1.0)
    resource.setrlimit(resource.RLIMIT_FSIZE, (os.path.getsize(sys.argv[1]), resource.RLIM_INFINITY))
    try:
        store.put("tr1", "quick", h, Unit("tr1", "k2", "diagnostic", {}), {"value": "x" * 100000, "seed": None}, 1.0)
    except NeurohoverError as err:
        print(err)
"""


@pytest.mark.slow
def test_a_write_a_file_size_limit_refuses_says_so_and_keeps_the_store(tmp_path: Path) -> None:
    path = tmp_path / "u.sqlite"
    done = subprocess.run([sys.executable, "-c", _LIMITED_PUT, str(path), str(TESTS)], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    said = done.stdout.strip()
    assert said.startswith(f"cannot write the results store {str(path)!r} (disk I/O error: the disk is full or a file-size limit"), said
    assert said.endswith("its finished units are kept, and the same command resumes once there is room")
    with Store(path, create=False) as store:
        assert store.conn.execute("PRAGMA integrity_check").fetchone() == ("ok",)
        assert [u["key"] for u in store.units("tr1", "quick")] == ["k1"]


def test_the_command_line_calls_a_refused_write_no_damage(cli, tmp_path: Path, monkeypatch) -> None:
    from neurohover.cli import reproduce

    def refused(args) -> int:
        err = sqlite3.OperationalError("disk I/O error")
        err.sqlite_errorname = "SQLITE_IOERR_WRITE"  # type: ignore[attr-defined]
        raise err

    monkeypatch.setattr(reproduce, "cmd_results", refused)
    rc, out, err = cli("results", "tr1", "--store", str(tmp_path / "s.sqlite"))
    assert rc == 2
    assert err == f"neurohover results: error: cannot write the results store {str(tmp_path / 's.sqlite')!r} (disk I/O error); its finished units are kept\n"


# ------------------------------------------------------------------ T32-A05: standard output under a file-size limit


def _limited(size: int):
    return lambda: resource.setrlimit(resource.RLIMIT_FSIZE, (size, resource.RLIM_INFINITY))


@pytest.mark.slow
@pytest.mark.parametrize("unbuffered", ["1", ""])
def test_results_cut_short_on_standard_output_fail(competed: Path, tmp_path: Path, unbuffered: str) -> None:
    out = tmp_path / "o.csv"
    env = {**os.environ, "PYTHONUNBUFFERED": unbuffered}
    argv = [sys.executable, "-c", "import sys; from neurohover.cli import main; sys.exit(main())", "results", "compete-ghh08-baseline"]
    with open(out, "w") as sink:
        done = subprocess.run([*argv, "--store", str(competed)], stdout=sink, stderr=subprocess.PIPE, text=True, env=env, preexec_fn=_limited(1024), timeout=60)
    assert done.returncode == 2
    assert done.stderr == "neurohover results: error: cannot write standard output (File too large): what the command printed there is cut short\n"
    assert out.stat().st_size == 1024
    if unbuffered:
        return  # the buffered writer's case below shows what room for all of it gives
    with open(out, "w") as sink:  # room for all of it: all of it, status 0
        done = subprocess.run([*argv, "--store", str(competed)], stdout=sink, stderr=subprocess.PIPE, text=True, env=env, timeout=60)
    assert done.returncode == 0 and done.stderr == ""
    with Store(competed, create=False) as store:
        from neurohover.experiments import export_results

        assert out.read_bytes() == export_results(store, "compete-ghh08-baseline").encode()
