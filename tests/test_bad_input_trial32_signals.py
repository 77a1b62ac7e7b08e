"""Bad-input trial 32, signals and the run's surroundings: SIGHUP (a closed terminal) and SIGUSR1 ended a run without a
word from neurohover, its pool's semaphores reported leaked by multiprocessing, and evolve without its line (T32-A03);
``--jobs 2`` from a removed working directory failed "No such file or directory", leaving an empty store or output
directory (T32-A06); model-free-risk's ``trials`` filling the whole run was taken, its risk settings then without effect
(T32-A07); the borderline findings: text reads in the locale's encoding, and "(1 simulated competitions)".

Linux only where real processes are signalled (as tests/test_procs.py).
"""

from __future__ import annotations

import ast
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from conftest import ROOT, finish_run, start_gated_run, tiny_test_runs
from test_experiments import SLOW_CONFIG, _finished, _open_gates
from test_procs import LONG_CONFIG, _busy_workers, _end_group, _start

from neurohover.errors import NeurohoverError

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="real processes signalled, found in /proc")

# ------------------------------------------------------------------------------------------- T32-A03


def test_hangup_and_usr1_are_stop_signals_as_sigterm_is() -> None:
    """SIGHUP and SIGUSR1 stop a command as SIGTERM does, with 128 + the signal as its status; SIGQUIT keeps its default."""
    from neurohover.errors import Terminated, raise_terminated, stop_signals
    from neurohover.procs import stop_words

    assert {signal.SIGTERM, signal.SIGHUP, signal.SIGUSR1} <= set(stop_signals())  # and more: T35-A03
    assert set(stop_signals(command=False)) == {signal.SIGTERM, signal.SIGHUP}  # a program calling main() keeps its SIGUSR1
    for signum, status in ((signal.SIGTERM, 143), (signal.SIGHUP, 129), (signal.SIGUSR1, 138)):
        with pytest.raises(Terminated) as caught:
            raise_terminated(signum, None)
        assert stop_words(caught.value) == ("terminated", status)
    assert stop_words(Terminated("signal 15")) == ("terminated", 143)  # the default: SIGTERM's


@pytest.mark.slow
def test_a_hangup_stops_reproduce_as_sigterm_does_keeping_its_finished_units(tmp_path: Path) -> None:
    """T32-A03: the run died at once (the shell said "Hangup"); now it says "terminated", names its finished units, and
    exits 128 + the signal. (SIGUSR1 stops the command alike: test_hangup_and_usr1_are_stop_signals_as_sigterm_is;
    this gated run is a program calling main(), which keeps its own SIGUSR1.)"""
    config = tmp_path / "exp.toml"
    config.write_text(SLOW_CONFIG)
    store, gates = tmp_path / "s.sqlite", tmp_path / "gates"
    gates.mkdir()
    _open_gates(gates, 1)
    proc = start_gated_run(config, store, gates)
    deadline = time.monotonic() + 240  # a safety net against a hung run, not a speed assumption
    while time.monotonic() < deadline and proc.poll() is None and len(_finished(store)) < 1:
        time.sleep(0.02)
    assert proc.poll() is None, proc.communicate()
    proc.send_signal(signal.SIGHUP)
    _, err = finish_run(proc, 120)
    assert proc.returncode == 129, err[-2000:]
    assert "reproduce: terminated; 1 finished units of slowtest are in" in err and "Traceback" not in err, err[-2000:]
    assert len(_finished(store)) == 1


@pytest.mark.slow
def test_a_hangup_to_the_group_of_a_reproduce_with_workers_stops_it_with_one_line(tmp_path: Path) -> None:
    """T32-A03: a terminal's hang-up to the whole process group of ``reproduce --jobs 2``: the command's stop line and
    129, not multiprocessing's "leaked semaphore objects" warning (nor the resource tracker's tracebacks, once a hang-up
    had killed it too)."""
    sig, status = signal.SIGHUP, 129
    config = tmp_path / "long.toml"
    config.write_text(LONG_CONFIG)
    proc = _start(tmp_path, "reproduce", str(config), "--store", str(tmp_path / "s.sqlite"), "--jobs", "2", "--no-progress")
    try:
        _busy_workers(proc, 2, cpu=0.2)
        os.killpg(proc.pid, sig)
        rc = proc.wait(timeout=60)
        time.sleep(0.5)  # the resource tracker, when it warns, does so as the command exits
        err = (tmp_path / "stderr.txt").read_text()
        assert rc == status, err[-2000:]
        assert err.strip().splitlines()[-1].startswith("neurohover reproduce: terminated; 0 finished units of longtest"), err[-2000:]
        assert "leaked" not in err and "resource_tracker" not in err and "Traceback" not in err, err[-2000:]
    finally:
        _end_group(proc)


@pytest.mark.slow
def test_a_hangup_stops_evolve_with_its_line(tmp_path: Path) -> None:
    """T32-A03: evolve printed nothing on SIGHUP; now it stops as on SIGTERM: its line and 129."""
    from test_procs import _cpu_seconds

    argv = ["evolve", "--task", "ghh08", "--mdp", "G", "--budget", "1000000", "--episode-steps", "200", "--out", str(tmp_path / "e.json")]
    proc = _start(tmp_path, *argv)
    try:
        deadline = time.monotonic() + 120  # a safety net: imported, its kernel loaded and flying
        while time.monotonic() < deadline and proc.poll() is None and _cpu_seconds(proc.pid) < 2.5:
            time.sleep(0.05)
        os.kill(proc.pid, signal.SIGHUP)
        rc = proc.wait(timeout=60)
        err = (tmp_path / "stderr.txt").read_text()
        assert rc == 129 and "Traceback" not in err, err[-2000:]
        assert err.strip().splitlines()[-1].startswith("neurohover evolve: terminated"), err[-2000:]
    finally:
        _end_group(proc)


@pytest.mark.slow
def test_a_hangup_leaves_a_command_started_under_nohup_running(tmp_path: Path) -> None:
    """T32-A03's fix keeps ``nohup``: a SIGHUP the command was started ignoring stays ignored; SIGTERM still stops it."""
    from test_procs import _cpu_seconds

    argv = [sys.executable, "-m", "neurohover", "evolve", "--task", "ghh08", "--mdp", "G", "--budget", "1000000", "--episode-steps", "200"]
    err_file = tmp_path / "stderr.txt"
    with open(err_file, "w") as err_out:
        proc = subprocess.Popen(
            [*argv, "--out", str(tmp_path / "e.json")], cwd=ROOT, stdout=subprocess.DEVNULL, stderr=err_out, start_new_session=True,
            preexec_fn=lambda: signal.signal(signal.SIGHUP, signal.SIG_IGN),  # as nohup starts it
        )  # fmt: skip
    try:
        deadline = time.monotonic() + 120  # a safety net: imported, its kernel loaded and flying
        while time.monotonic() < deadline and proc.poll() is None and _cpu_seconds(proc.pid) < 2.5:
            time.sleep(0.05)
        os.kill(proc.pid, signal.SIGHUP)
        time.sleep(1.0)
        assert proc.poll() is None, err_file.read_text()[-2000:]
        os.kill(proc.pid, signal.SIGTERM)
        assert proc.wait(timeout=60) == 143, err_file.read_text()[-2000:]
    finally:
        _end_group(proc)


# ------------------------------------------------------------------------------------------- T32-A06

GONE_CWD = """
import os, sys
from neurohover.cli import main
here = sys.argv[1]
os.mkdir(here)
os.chdir(here)
os.rmdir(here)
sys.exit(main(sys.argv[2:]))
"""


@pytest.mark.slow
@pytest.mark.parametrize("command", ["reproduce", "compete"])
def test_jobs_from_a_removed_working_directory_is_refused_before_anything_is_written(tmp_path: Path, command: str) -> None:
    """T32-A06: "error: No such file or directory" naming nothing, an empty store (compete: its folder) left behind."""
    config = tmp_path / "tr1.toml"
    config.write_text(tiny_test_runs("baseline"))
    argv = {
        "reproduce": ["reproduce", str(config), "--store", str(tmp_path / "s.sqlite"), "--jobs", "2", "--no-progress"],
        "compete": ["compete", "--task", "ghh08", "--agent", "baseline", "--runs", "2", "--episodes", "2", "--episode-steps", "20"]
        + ["--out", str(tmp_path / "c"), "--jobs", "2"],
    }[command]
    done = subprocess.run([sys.executable, "-c", GONE_CWD, str(tmp_path / "gone"), *argv], cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert done.returncode == 2, done.stderr[-2000:]
    assert (
        f"neurohover {command}: error: --jobs 2 is not allowed here: the working directory '{tmp_path / 'gone'}' no longer exists: "
        "worker processes cannot start there; cd to an existing directory (or give --jobs 1)"
    ) in done.stderr, done.stderr[-2000:]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["tr1.toml"]  # no store, no output folder


def test_a_local_executor_with_workers_is_refused_where_the_working_directory_is_gone(tmp_path: Path, monkeypatch) -> None:
    """T32-A06, the Python API: LocalExecutor(2) and worker_pool(2) name the condition; jobs=1 needs no working directory."""
    from neurohover.experiments.executors import LocalExecutor
    from neurohover.procs import worker_pool

    gone = tmp_path / "gone"
    gone.mkdir()
    monkeypatch.chdir(gone)
    gone.rmdir()
    for make in (LocalExecutor, worker_pool):
        with pytest.raises(NeurohoverError, match=r"^--jobs 2 is not allowed here: the working directory .*gone' no longer exists: worker"):
            make(2)
    assert LocalExecutor(1).jobs == 1


# ------------------------------------------------------------------------------------------- T32-A07


def test_risk_trials_that_fill_the_run_are_refused(tmp_path: Path, cli) -> None:
    """T32-A07: trials=1000000 in 25 episodes ran as trials=3 (neither settles): the risk settings had no effect."""
    from neurohover.compete import competition_config

    rc, _, err = cli(
        "compete", "--task", "ghh08", "--agent", "model-free-risk", "--runs", "1", "--episodes", "25", "--episode-steps", "20",
        "--out", str(tmp_path / "c"), "--agent-setting", "trials=1000000",
    )  # fmt: skip
    assert rc == 2 and not (tmp_path / "c").exists(), err
    assert (
        "risk trials=1,000,000 cannot fit in a run of 25 episodes: model-free-risk flies each of its 10 specialised policies trials "
        "times (10,000,000 episodes) before it settles on the best by its risk score, so it would never settle and its criterion "
        "would have no effect; give trials at most 2, or more than 10,000,000 episodes"
    ) in err, err
    with pytest.raises(NeurohoverError, match=r"risk trials=3 cannot fit in a run of 30 episodes: .* give trials at most 2, or more"):
        competition_config("ghh08", "model-free-risk", runs=1, episodes=30, agent_settings={"trials": 3})
    with pytest.raises(NeurohoverError, match=r"risk trials=2 cannot fit in a run of 3 episodes: .*; give more than 20 episodes$"):
        competition_config("ghh08", "model-free-risk", runs=1, episodes=3)  # the default trials too
    competition_config("ghh08", "model-free-risk", runs=1, episodes=31, agent_settings={"trials": 3})  # settles at episode 30
    competition_config("ghh08", "hybrid-risk", runs=1, episodes=3, agent_settings={"criterion": "worst"})  # no trials of its own


# ------------------------------------------------------------------------------------------- borderline


@pytest.mark.slow
def test_every_text_read_or_write_of_the_package_names_its_encoding() -> None:
    """Borderline: tasks/base.py's competition MDPs and compete.py's summary were read in the locale's encoding
    (``-X warn_default_encoding`` named them)."""
    missing = []
    for path in sorted((ROOT / "neurohover").rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if not (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and node.func.attr in ("read_text", "write_text")):
                continue
            if not any(k.arg == "encoding" for k in node.keywords):
                missing.append(f"{path.relative_to(ROOT)}:{node.lineno}")
    assert missing == []


def test_wins_with_one_draw_says_competition(tmp_path: Path, cli) -> None:
    """Borderline: ``wins --draws 1`` printed "(1 simulated competitions)"."""
    config = tmp_path / "tr1.toml"
    config.write_text(tiny_test_runs("baseline", "model-free"))
    store = tmp_path / "s.sqlite"
    assert cli("reproduce", str(config), "--store", str(store), "--no-progress")[0] == 0
    rc, out, err = cli("wins", "tr1", "--store", str(store), "--draws", "1", "--runs", "1")
    assert rc == 0 and "(1 simulated competition)" in out, err
    rc, out, err = cli("wins", "tr1", "--store", str(store), "--draws", "2", "--runs", "1")
    assert rc == 0 and "(2 simulated competitions)" in out, err


STOP_IN_A_CALLBACK = """
import signal, sys, time, weakref
from neurohover.errors import Terminated, raise_terminated, redeliver_ignored_stop
signal.signal(signal.SIGTERM, raise_terminated)
if sys.argv[1] == "hook":
    sys.unraisablehook = redeliver_ignored_stop
class Held: pass
held = Held()
ref = weakref.ref(held, lambda _: raise_terminated(signal.SIGTERM, None))  # as importlib's module-lock callback took it
try:
    del held  # the callback runs: its Terminated is "ignored"
    for _ in range(200):  # the command's work goes on: the stop, sent again, lands in it
        time.sleep(0.01)
    print("ran on")
except Terminated as stop:
    print("stopped", stop.signum)
"""


@pytest.mark.slow
@pytest.mark.parametrize("hook", ["hook", "python's"])
def test_a_stop_raised_inside_a_callback_python_ignores_is_delivered_again(hook: str) -> None:
    """A SIGTERM landing in importlib's weakref callback while the package imported was printed as "Exception ignored"
    and lost: ``fly`` ran on to status 0 (test_procs' SIGTERM at 1.0 s, seen once). The package's unraisable hook sends
    the signal again, and the stop lands where the command handles it."""
    done = subprocess.run([sys.executable, "-c", STOP_IN_A_CALLBACK, hook], cwd=ROOT, capture_output=True, text=True, timeout=60)
    assert done.stdout == ("stopped 15\n" if hook == "hook" else "ran on\n"), done.stdout + done.stderr
    assert ("Exception ignored" in done.stderr) == (hook != "hook"), done.stderr
