"""neurohover.procs and the long runs it guards, with real processes: worker processes never outlive a killed
``reproduce`` or ``compete``, a bad or dead Ray address ends at once with a clear message, and one
store has one writer at a time.

Linux only: the tests find a process's children in /proc.
"""

from __future__ import annotations

import ctypes
import os
import signal
import sqlite3
import subprocess
import sys
import time
from pathlib import Path

import pytest
from conftest import ROOT, start_gated_run

from neurohover.experiments import Store
from neurohover.procs import Terminated, sigterm_as_interrupt

ENV = dict(os.environ)  # with this checkout on PYTHONPATH (conftest)

# An evolution experiment whose units each take tens of seconds (far longer than the tests wait).
LONG_CONFIG = """
name = "longtest"
title = "orphan test"
kind = "evolution"
[settings]
task = "fghh"
sigma = 0.3
seed = 5
target = "family"
runs = 4
[[settings.variants]]
key = "k1"
label = "k = 1"
[scales.quick]
budget = 400000
n_steps = 200
[scales.paper]
budget = 400000
n_steps = 200
"""


def _start(tmp_path: Path, *argv: str, env: dict[str, str] | None = None) -> subprocess.Popen:
    """``neurohover ARGV`` in its own session (so a failed test can end the whole group), in ``env`` (None: ENV)."""
    out = open(tmp_path / "stdout.txt", "w")
    err = open(tmp_path / "stderr.txt", "w")
    try:
        return subprocess.Popen([sys.executable, "-m", "neurohover", *argv], cwd=ROOT, env=env or ENV, stdout=out, stderr=err, start_new_session=True)
    finally:
        out.close()
        err.close()


def _children(pid: int) -> set[int]:
    found: set[int] = set()
    for task in Path(f"/proc/{pid}/task").glob("*"):
        try:
            found.update(int(x) for x in (task / "children").read_text().split())
        except OSError:
            pass
    return found


def _alive(pid: int) -> bool:
    """Whether ``pid`` runs (a zombie, dead but not yet reaped by its new parent, does not)."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return False
    return stat.rsplit(")", 1)[1].split()[0] not in ("Z", "X")


def _cpu_seconds(pid: int) -> float:
    try:
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    except OSError:
        return 0.0
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def _is_worker(pid: int) -> bool:
    try:
        return b"spawn_main" in Path(f"/proc/{pid}/cmdline").read_bytes()
    except OSError:
        return False


def _busy_workers(proc: subprocess.Popen, n: int, cpu: float = 1.0, timeout: float = 180) -> set[int]:
    """Every child of ``proc`` once ``n`` of them are pool workers that have each run ``cpu`` s."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        assert proc.poll() is None, f"the command ended early ({proc.returncode})"
        children = _children(proc.pid)
        workers = [p for p in children if _is_worker(p)]
        if len(workers) >= n and all(_cpu_seconds(p) >= cpu for p in workers):
            return children
        time.sleep(0.1)
    raise AssertionError(f"no {n} busy workers after {timeout} s: children {_children(proc.pid)}")


def _gone_within(pids: set[int], seconds: float) -> set[int]:
    """The pids of ``pids`` still alive after ``seconds``."""
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline and any(_alive(p) for p in pids):
        time.sleep(0.05)
    return {p for p in pids if _alive(p)}


def _end_group(proc: subprocess.Popen) -> None:
    """Clean up after a failed test: SIGKILL everything left in the command's process group."""
    try:
        os.killpg(proc.pid, signal.SIGKILL)
    except ProcessLookupError:
        pass
    proc.communicate(timeout=30)  # reaps it and closes its pipes (unclosed, they warn in a later test)


# --------------------------------------------------------------------------------- no orphans


@pytest.mark.slow
@pytest.mark.parametrize("sig", [signal.SIGKILL, signal.SIGTERM], ids=["SIGKILL", "SIGTERM"])
def test_the_workers_of_a_killed_reproduce_exit(tmp_path: Path, sig: int) -> None:
    config = tmp_path / "long.toml"
    config.write_text(LONG_CONFIG)
    store = tmp_path / "s.sqlite"
    proc = _start(tmp_path, "reproduce", str(config), "--store", str(store), "--jobs", "2", "--no-progress")
    try:
        children = _busy_workers(proc, 2)
        os.kill(proc.pid, sig)
        rc = proc.wait(timeout=30)
        assert not _gone_within(children, 10), "worker processes outlived their parent"
        if sig == signal.SIGTERM:  # handled like Ctrl-C: the run is marked interrupted; the command says terminated, 143
            assert rc == 143, (tmp_path / "stderr.txt").read_text()[-2000:]
            assert "reproduce: terminated" in (tmp_path / "stderr.txt").read_text()
            with Store(store) as s:
                assert [x["status"] for x in s.sessions("longtest", "quick")] == ["interrupted"]
        else:
            assert rc == -signal.SIGKILL
    finally:
        _end_group(proc)


@pytest.mark.slow
@pytest.mark.parametrize("sig", [signal.SIGKILL, signal.SIGTERM], ids=["SIGKILL", "SIGTERM"])
def test_the_workers_of_a_killed_compete_exit(tmp_path: Path, sig: int) -> None:
    proc = _start(
        tmp_path, "compete", "--task", "ghh08", "--agent", "baseline", "--runs", "2", "--jobs", "2", "--episodes", "200000", "--out", str(tmp_path / "out")
    )
    try:
        children = _busy_workers(proc, 2)
        os.kill(proc.pid, sig)
        rc = proc.wait(timeout=30)
        assert not _gone_within(children, 10), "worker processes outlived their parent"
        assert rc == (143 if sig == signal.SIGTERM else -signal.SIGKILL), (tmp_path / "stderr.txt").read_text()[-2000:]
    finally:
        _end_group(proc)


def _importing_the_package(proc: subprocess.Popen, timeout: float = 120) -> None:
    """Wait until the child has begun the package's import (NumPy's core is mapped): before it, Python itself is starting,
    where a signal ends it without a word (a documented choice); on a loaded machine that took over a second."""
    maps = Path(f"/proc/{proc.pid}/maps")
    end = time.monotonic() + timeout
    while time.monotonic() < end and proc.poll() is None:
        try:
            if "_multiarray_umath" in maps.read_text():
                return
        except OSError:
            return  # no /proc (another system): the fixed delays alone
        time.sleep(0.02)


def _ctrl_c_as_in_a_terminal() -> None:
    """The child starts with Ctrl-C's default disposition, as a terminal's command does, whatever this worker's is."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


@pytest.mark.slow
@pytest.mark.parametrize("delay", [0.6, 1.2, 2.5])  # from the package's import on (before it, Python itself is starting)
def test_ctrl_c_at_any_moment_ends_with_one_line_and_130(delay: float) -> None:
    """issue 37, third trial: a Ctrl-C while the package imported NumPy and numba was a KeyboardInterrupt traceback (the
    package is imported before main() runs); later ones were already one line."""
    proc = subprocess.Popen(
        [sys.executable, "-m", "neurohover", "fly", "--task", "ghh08", "--episodes", "100000"], stderr=subprocess.PIPE, text=True, env=ENV,
        preexec_fn=_ctrl_c_as_in_a_terminal,
    )  # fmt: skip
    _importing_the_package(proc)
    time.sleep(delay - 0.6)  # wherever it lands, the outcome must be the same
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130 and "Traceback" not in err and err.strip().splitlines()[-1].endswith("interrupted"), err[-1500:]


@pytest.mark.slow
@pytest.mark.parametrize("delay", [1.0, 2.5, 6.0])  # from the package import on (before it, Python itself starts), then while it flies
def test_sigterm_at_any_moment_ends_any_command_with_one_line_and_143(delay: float) -> None:
    """issue 37, fourth trial: SIGTERM (a timeout, kill) ended fly, evolve, compete and reproduce without a line."""
    proc = subprocess.Popen([sys.executable, "-m", "neurohover", "fly", "--task", "ghh08", "--episodes", "100000"], stderr=subprocess.PIPE, text=True, env=ENV)
    _importing_the_package(proc)
    time.sleep(delay - 1.0)
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 143 and "Traceback" not in err and err.strip().splitlines()[-1].endswith("terminated"), err[-1500:]


def test_a_stop_is_named_by_its_signal_also_when_raised_while_handling_it() -> None:
    from neurohover.evolution import EvolutionInterrupted
    from neurohover.procs import stop_words

    assert stop_words(KeyboardInterrupt()) == ("interrupted", 130) and stop_words(Terminated("signal 15")) == ("terminated", 143)
    try:
        try:
            raise Terminated("signal 15")
        except KeyboardInterrupt:
            raise EvolutionInterrupted(None, 3) from None  # as the evolution turns a stop into its own, with a checkpoint
    except EvolutionInterrupted as err:
        assert stop_words(err) == ("terminated", 143)  # build-policies said "interrupted", 130 for a SIGTERM (fourth trial)


@pytest.mark.slow
def test_a_terminated_build_leaves_no_half_built_set(tmp_path: Path) -> None:
    """issue 37, third trial: SIGTERM (timeout, kill) left <out>/ghh08.building without a word; now it ends as Ctrl-C
    does, keeping only the finished runs beside the set, which the same build resumes from (fourth trial)."""
    out = tmp_path / "bp"
    # The build's kernels compiled (or loaded) first by a tiny build, so the SIGTERM lands in the evolution; one landing in
    # numba's compilation is test_an_interrupt_dropped_in_a_c_callback_is_delivered_again's case.
    warm = ["build-policies", "--task", "ghh08", "--budget", "2", "--episode-steps", "20", "--out", str(tmp_path / "warm")]
    subprocess.run([sys.executable, "-m", "neurohover", *warm], cwd=ROOT, env=ENV, capture_output=True, check=True)
    # faulthandler on: SIGABRT after the wait below prints every thread's Python stack (two full runs hung here)
    proc = _start(tmp_path, "build-policies", "--task", "ghh08", "--budget", "1000000", "--out", str(out), env={**ENV, "PYTHONFAULTHANDLER": "1"})
    try:
        building = out / "ghh08.building"
        for _ in range(600):  # the build under way (its kernel loaded from the cache)
            if building.is_dir() or proc.poll() is not None:
                break
            time.sleep(0.1)
        assert building.is_dir(), (tmp_path / "stderr.txt").read_text()[-2000:]
        os.kill(proc.pid, signal.SIGTERM)
        try:  # twice in the twenty-sixth session's full runs it did not end within 60 s: its stderr says where it was
            status = proc.wait(timeout=60)
        except subprocess.TimeoutExpired:
            os.kill(proc.pid, signal.SIGABRT)  # faulthandler's dump of where it is, then the end
            proc.wait(timeout=30)
            pytest.fail("build-policies did not end within 60 s of SIGTERM; its stderr: " + (tmp_path / "stderr.txt").read_text()[-6000:])
        assert status == 143  # terminated, also when the stop lands mid-evolution (it said interrupted, 130)
        err = (tmp_path / "stderr.txt").read_text()
        assert "the finished runs are kept in" in err and err.strip().splitlines()[-1].endswith("terminated"), err[-1500:]
        assert not (out / "ghh08").exists() and sorted(p.name for p in building.iterdir()) == ["stages"]  # no half-built set
    finally:
        _end_group(proc)


def _raise(stop: BaseException) -> None:
    raise stop


@pytest.mark.parametrize("stop", [Terminated("signal 15"), KeyboardInterrupt()], ids=["SIGTERM", "Ctrl-C"])
def test_an_interrupt_dropped_in_a_c_callback_is_delivered_again(stop: BaseException) -> None:
    """issue 37, third trial: a SIGTERM landing in numba's compilation was raised inside llvmlite's ctypes callback,
    where Python prints and drops it, and the command ran on (3 of 10 terminated compile loops ran on before the fix)."""
    callback = ctypes.CFUNCTYPE(None)(lambda: _raise(stop))
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)  # Python's Ctrl-C, whatever this worker's is
    try:
        _deliver_again_and_wait(callback, stop)
    finally:
        signal.signal(signal.SIGINT, previous)


def _deliver_again_and_wait(callback, stop: BaseException) -> None:
    with pytest.raises(type(stop)), sigterm_as_interrupt():
        callback()  # the exception is dropped here, as in llvmlite's object-cache notify
        deadline = time.monotonic() + 30
        while time.monotonic() < deadline:  # ends at once when the interrupt is delivered again
            time.sleep(0.01)


# --------------------------------------------------------------------------------- Ray addresses


@pytest.mark.slow
@pytest.mark.parametrize(
    "address, message",
    [
        ("notanaddress", "--address 'notanaddress' is not a Ray cluster address: allowed host:port (port 1 to 65535"),
        ("127.0.0.1:1", "--address '127.0.0.1:1': no Ray cluster is listening at 127.0.0.1:1 (connection refused)"),
    ],
)
def test_a_bad_or_dead_ray_address_ends_at_once_with_one_clear_line(tmp_path: Path, address: str, message: str) -> None:
    env = {k: v for k, v in ENV.items() if k != "RAY_ADDRESS"}
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "neurohover",
            "reproduce",
            "fig2",
            "--executor",
            "ray",
            "--address",
            address,
            "--store",
            str(tmp_path / "s.sqlite"),
            "--no-progress",
        ],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
    )
    # One line, from neurohover's own check of the address (the message), not Ray's retries and their logs.
    assert proc.returncode == 2, proc.stderr[-2000:]
    assert "Traceback" not in proc.stderr
    assert proc.stderr.strip().splitlines() == [proc.stderr.strip()]  # one line
    assert proc.stderr.startswith(f"neurohover reproduce: error: {message}")


@pytest.mark.parametrize(
    "address, endpoint",
    [
        ("10.0.0.5:6379", ("10.0.0.5", 6379)),
        ("head-node:1", ("head-node", 1)),
        ("ray://head:10001", ("head", 10001)),
        ("[::1]:65535", ("::1", 65535)),
        ("auto", None),
        ("local", None),
    ],
)
def test_ray_address_forms_that_ray_accepts(address: str, endpoint) -> None:
    from neurohover.experiments.executors import ray_endpoint

    assert ray_endpoint(address) == endpoint


@pytest.mark.parametrize("address", ["notanaddress", "h:0", "h:65536", "h:abc", ":6379", "::1:6379", "ray://head", "h: 1", "http://h:1", "h:1:2", ""])
def test_malformed_ray_addresses_are_refused(address: str) -> None:
    from neurohover.errors import NeurohoverError
    from neurohover.experiments.executors import ray_endpoint

    with pytest.raises(NeurohoverError, match="is not a Ray cluster address: allowed host:port"):
        ray_endpoint(address)


@pytest.mark.slow
def test_a_bad_ray_address_environment_variable_is_named(tmp_path: Path) -> None:
    proc = subprocess.run(
        [sys.executable, "-m", "neurohover", "reproduce", "fig2", "--executor", "ray", "--store", str(tmp_path / "s.sqlite"), "--no-progress"],
        cwd=ROOT,
        env={**ENV, "RAY_ADDRESS": "127.0.0.1:1"},
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.returncode == 2 and "Traceback" not in proc.stderr
    assert "RAY_ADDRESS '127.0.0.1:1': no Ray cluster is listening at 127.0.0.1:1" in proc.stderr


# --------------------------------------------------------------------------------- one writer per store

TINY_CONFIG = LONG_CONFIG.replace('"longtest"', '"tinytest"').replace("runs = 4", "runs = 1").replace("400000", "200")


def _running_session(store: Path, name: str) -> bool:
    """Whether a run of ``name`` is under way in ``store`` (which another process is writing)."""
    try:
        conn = sqlite3.connect(store, timeout=5)
        try:
            return conn.execute("SELECT count(*) FROM sessions WHERE name = ? AND status = 'running'", (name,)).fetchone()[0] > 0
        finally:
            conn.close()
    except sqlite3.OperationalError:
        return False


@pytest.mark.slow
def test_a_store_that_a_live_run_writes_is_refused_and_a_killed_run_blocks_nothing(tmp_path: Path, cli) -> None:
    # The holder is a process of its own; this process plays the second writer and the readers.
    store = tmp_path / "s.sqlite"
    lock = tmp_path / "s.sqlite.lock"
    (tmp_path / "long.toml").write_text(LONG_CONFIG)
    (tmp_path / "tiny.toml").write_text(TINY_CONFIG)
    tiny = ["reproduce", str(tmp_path / "tiny.toml"), "--store", str(store), "--no-progress"]
    assert cli(*tiny)[0] == 0
    (tmp_path / "gates").mkdir()  # never opened: the holder waits at its first unit until it is killed
    holder = start_gated_run(tmp_path / "long.toml", store, tmp_path / "gates", name="longtest")
    try:
        deadline = time.monotonic() + 120
        while not _running_session(store, "longtest"):
            assert holder.poll() is None and time.monotonic() < deadline, "the holding run ended or never began its session"
            time.sleep(0.05)
        # A second writer is refused at once, naming the store and the run that holds it ...
        rc, out, err = cli(*tiny)
        assert rc == 2 and "Traceback" not in err
        assert f"results store {str(store)!r} is in use: another run (pid {holder.pid} on host" in err
        assert len(err.strip().splitlines()) == 1 and "ran 0 units" not in out
        # ... while reading the store still works.
        rc, out, err = cli("results", "tinytest", "--store", str(store), "--format", "json")
        assert rc == 0 and "evolve/k1/run0" in out, err[-2000:]
        rc, _, err = cli("report", "tinytest", "--store", str(store), "--out", str(tmp_path / "report"))
        assert rc == 0 and (tmp_path / "report" / "report.md").exists(), err[-2000:]
        assert holder.poll() is None
        # A killed holder leaves its lock file (with its pid) but no lock: the next run proceeds.
        holder.kill()
        holder.wait(timeout=30)
        assert lock.read_text().split()[0] == str(holder.pid)
        rc, out, err = cli(*tiny, "--fresh")
        assert rc == 0, err[-2000:]
        assert "ran 1 unit, 0 already in the store" in out
    finally:
        _end_group(holder)


def test_two_stores_on_one_file_in_one_process_take_turns(tmp_path: Path) -> None:
    from store_edits import begin

    from neurohover.errors import NeurohoverError

    path = tmp_path / "s.sqlite"
    with Store(path) as first, Store(path) as second:
        h = begin(first, "x")
        with pytest.raises(NeurohoverError, match=rf"is in use: another open Store of this process \(pid {os.getpid()} on host "):
            begin(second, "x")
        assert first.experiments() == second.experiments() == [("x", "quick", h, 0)]  # reading needs no lock
        first.close()
        assert not first.lock_path.exists()  # a closed Store removes its lock file ...
        begin(second, "x")  # ... and releases its lock
        assert second.lock_path.read_text().split()[0] == str(os.getpid())
    assert not path.with_name("s.sqlite.lock").exists()


def test_a_run_that_opened_the_lock_file_as_its_writer_removed_it_locks_the_new_one(tmp_path: Path, monkeypatch) -> None:
    from neurohover.paths import WriterLock

    path = tmp_path / "s.sqlite"
    first = Store(path)
    first.lock()
    stale = os.open(first.lock_path, os.O_RDWR)  # the next run opened the file while the first still held it
    first.close()  # removes the file, then releases the lock: flock on `stale` would now succeed
    second = Store(path)
    opened = []
    real_open = WriterLock.open_file

    def open_file(self):
        opened.append(1)
        return stale if len(opened) == 1 else real_open(self)

    monkeypatch.setattr(WriterLock, "open_file", open_file)
    second.lock()
    assert len(opened) == 2  # it saw that its first file was gone and locked the path's new one
    third = Store(path)
    with pytest.raises(ValueError, match="is in use"):  # so the lock still excludes a third writer
        third.lock()
    second.close()
    third.close()


def test_a_terminated_command_exits_with_143_and_an_interrupt_with_130(monkeypatch, capsys) -> None:
    import neurohover.cli.app as cli
    from neurohover.procs import Terminated

    def stop(exc):
        def run(args):
            raise exc

        return run

    for exc, status, word in ((Terminated(), 143, "terminated"), (KeyboardInterrupt(), 130, "interrupted")):
        parser = cli.build_parser()
        args = parser.parse_args(["demo"])
        monkeypatch.setattr(cli, "build_parser", lambda p=parser: p)
        monkeypatch.setattr(parser, "parse_known_args", lambda argv=None, namespace=None, a=args: (a, []))
        args.func = stop(exc)
        assert cli.main(["demo"]) == status
        assert capsys.readouterr().err.strip() == f"neurohover demo: {word}"


class _CommitThenInterrupt:
    """A store connection on which Ctrl-C lands just after a transaction commits."""

    def __init__(self, conn: sqlite3.Connection) -> None:
        self.conn = conn

    def execute(self, sql: str, *args):
        out = self.conn.execute(sql, *args)
        if sql == "COMMIT":
            raise KeyboardInterrupt
        return out

    def __getattr__(self, name: str):
        return getattr(self.conn, name)


def test_a_ctrl_c_just_after_a_unit_commits_stays_a_ctrl_c_and_keeps_the_unit(tmp_path: Path) -> None:
    from store_edits import begin

    from neurohover.experiments.units import Unit

    with Store(tmp_path / "s.sqlite") as store:
        h = begin(store, "exp")
        conn = store.conn
        store.conn = _CommitThenInterrupt(conn)  # type: ignore[assignment]
        with pytest.raises(KeyboardInterrupt):  # not sqlite's "cannot rollback - no transaction is active"
            store.put("exp", "quick", h, Unit("exp", "u0", "diagnostic", {"value": 1}), {"value": 1, "seed": None}, 0.1)
        store.conn = conn
        assert list(store.results("exp", "quick")) == ["u0"]  # committed: kept


def test_main_called_in_a_program_leaves_its_signals_as_they_were(monkeypatch, capsys) -> None:
    """The command ignores Ctrl-C and SIGTERM once it is done (so they cannot kill it while it exits), but only as the
    ``neurohover`` process itself: main() called from Python without arguments left a test worker deaf to Ctrl-C."""
    from neurohover.cli import main

    monkeypatch.setattr(sys, "argv", ["a-program", "settings"])
    before = signal.getsignal(signal.SIGINT), signal.getsignal(signal.SIGTERM)
    assert main() == 0
    assert (signal.getsignal(signal.SIGINT), signal.getsignal(signal.SIGTERM)) == before


@pytest.mark.slow
def test_a_large_demo_hears_sigterm_between_its_calls() -> None:
    """Fifth trial: demo --episodes 4000000 flew each family in one kernel call and heard neither SIGTERM nor Ctrl-C for
    minutes (SIGKILL ended it). Now it flies in calls of a few thousand episodes and stops at the next one."""
    proc = subprocess.Popen([sys.executable, "-m", "neurohover", "demo", "--episodes", "4000000"], stderr=subprocess.PIPE, text=True, env=ENV)
    deadline = time.monotonic() + 120  # a safety net: imported, its kernel loaded and flying its first call
    while time.monotonic() < deadline and proc.poll() is None and _cpu_seconds(proc.pid) < 4.0:
        time.sleep(0.05)
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=60)  # one call of 4,000,000 episodes takes hours here
    assert proc.returncode == 143 and "Traceback" not in err and err.strip().splitlines()[-1].endswith("terminated"), err[-1500:]


@pytest.mark.slow
def test_demo_in_calls_prints_what_one_call_prints(monkeypatch, capsys) -> None:
    from neurohover.cli import flying, main

    assert main(["demo", "--episodes", "20", "--mdps", "1"]) == 0
    whole = capsys.readouterr().out
    monkeypatch.setattr(flying, "FLY_CHUNK", 1)  # 8 episodes a call: three calls per MDP, the last one short
    assert main(["demo", "--episodes", "20", "--mdps", "1"]) == 0
    assert capsys.readouterr().out == whole and len(whole.splitlines()) == 1 + 3 * 2 * 2
