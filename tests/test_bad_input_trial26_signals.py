"""Bad-input trial 26, stopping and starting ``neurohover compete``: a Ctrl-C to the whole process group (as a terminal
sends it) or a SIGTERM while ``--jobs 2`` workers start or run printed the workers' tracebacks (T26-A01); a competition
stopped before any run finished named an episodes.csv that was never written (T26-A08); ``--out DIR`` replaced flight
data, a model or a policy file at DIR/summary.json or DIR/episodes.csv without a word (T26-A06).

Linux only where real processes are signalled: the workers are found in /proc.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from conftest import ROOT, finish_run
from test_procs import _children, _is_worker

from neurohover.errors import NeurohoverError, brief

# ------------------------------------------------------------------------------------------- T26-A01

#: The command as its installed script runs it: its workers are handed sys.argv, whose 'neurohover' made them take the
#: command's signal handlers (python -m neurohover's workers did not).
SCRIPT = "import sys\nfrom neurohover.cli import main\n\nif __name__ == '__main__':\n    sys.exit(main())\n"


def _workers_started(proc: subprocess.Popen, n: int = 2, timeout: float = 120) -> None:
    """Wait until ``proc`` has ``n`` pool workers (they are then starting: importing NumPy, numba and the package)."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline and proc.poll() is None:
        if sum(_is_worker(p) for p in _children(proc.pid)) >= n:
            return
        time.sleep(0.01)
    raise AssertionError(f"no {n} workers started (the command's status: {proc.poll()})")


def _stopped_compete(tmp_path: Path, delay: float, to_group: bool = True) -> tuple[int, str]:
    """A ``--jobs 2`` compete, stopped ``delay`` s after its workers appeared: SIGINT to its process group (a terminal's
    Ctrl-C), or SIGTERM to the command alone; its exit status and what it wrote (stdout and stderr together)."""
    script = tmp_path / "neurohover"
    script.write_text(SCRIPT)
    argv = ["compete", "--task", "ghh08", "--agent", "incremental", "--runs", "6", "--episodes", "200", "--jobs", "2", "--out", str(tmp_path / "c")]
    proc = subprocess.Popen(
        [sys.executable, str(script), *argv], cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
        preexec_fn=lambda: (signal.signal(signal.SIGINT, signal.SIG_DFL), os.setsid()),  # Ctrl-C's disposition, a group of its own
    )  # fmt: skip
    try:
        _workers_started(proc)
        time.sleep(delay)
        if to_group:
            os.killpg(proc.pid, signal.SIGINT)
        else:
            proc.send_signal(signal.SIGTERM)
        out, _ = finish_run(proc, 60)
    finally:
        try:
            os.killpg(proc.pid, signal.SIGKILL)  # anything left (nothing should be)
        except ProcessLookupError:
            pass
        proc.communicate()
    return proc.returncode, out


def _only_the_commands_line(out: str, how: str) -> None:
    for noise in ("Traceback", "Error in sys.excepthook", "Process SpawnProcess", "neurohover: interrupted", "neurohover: terminated"):
        assert noise not in out, out[-3000:]
    assert out.strip().splitlines()[-1].startswith(f"neurohover compete: {how}; "), out[-3000:]


@pytest.mark.slow
@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="finds the workers in /proc")
@pytest.mark.parametrize("delay", [0.05, 0.3, 0.8])  # as the workers start (their imports take about a second), and later
def test_ctrl_c_to_the_group_during_a_jobs_2_compete_prints_one_line(tmp_path: Path, delay: float) -> None:
    rc, out = _stopped_compete(tmp_path, delay)
    assert rc == 130, out[-3000:]
    _only_the_commands_line(out, "interrupted")


@pytest.mark.paper  # a longer soak: more moments, SIGTERM too
@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="finds the workers in /proc")
@pytest.mark.parametrize("to_group", [True, False], ids=["ctrl-c-to-group", "sigterm-to-command"])
@pytest.mark.parametrize("delay", [0.0, 0.15, 0.5, 1.2, 2.0, 3.0])
def test_a_stop_at_any_moment_of_a_jobs_2_compete_prints_one_line(tmp_path: Path, delay: float, to_group: bool) -> None:
    rc, out = _stopped_compete(tmp_path, delay, to_group)
    how = "interrupted" if to_group else "terminated"
    if rc != 0:  # (a fast machine may have finished)
        assert rc == (130 if to_group else 143), out[-3000:]
        _only_the_commands_line(out, how)


def _ctrl_c_state() -> tuple[bool, object]:
    """This process's SIGINT and a scheduler's SIGUSR2 warning (T35-A03) blocked?, and its SIGTERM handler (run in a pool worker)."""
    return {signal.SIGINT, signal.SIGUSR2} <= signal.pthread_sigmask(signal.SIG_BLOCK, []), signal.getsignal(signal.SIGTERM)


@pytest.mark.slow
@pytest.mark.skipif(not hasattr(signal, "pthread_sigmask"), reason="POSIX signal masks")
def test_a_pool_worker_never_hears_ctrl_c_and_dies_of_sigterm_at_once() -> None:
    from neurohover.procs import stop_pool, worker_pool

    pool = worker_pool(1)
    try:
        assert pool.submit(_ctrl_c_state).result(timeout=120) == (True, signal.SIG_DFL)
    finally:
        stop_pool(pool)
    assert signal.SIGINT not in signal.pthread_sigmask(signal.SIG_BLOCK, [])  # the parent hears it as before


def test_a_worker_of_the_command_is_not_the_command(monkeypatch) -> None:
    """A spawned worker is handed the command's sys.argv: it took the command's SIGTERM handler and excepthook."""
    from neurohover.command import running_as_command

    monkeypatch.setattr(sys, "argv", ["/venv/bin/neurohover", "compete"])
    monkeypatch.setattr(sys, "orig_argv", [sys.executable, "/venv/bin/neurohover", "compete"])
    assert running_as_command()
    monkeypatch.setattr(sys, "orig_argv", [sys.executable, "-c", "from multiprocessing.spawn import spawn_main; spawn_main()", "--multiprocessing-fork"])
    assert not running_as_command()


# ------------------------------------------------------------------------------------------- T26-A08

TINY = ("compete", "--task", "ghh08", "--agent", "baseline", "--runs", "2", "--episodes", "2", "--episode-steps", "20")


def _interrupt_after(monkeypatch, runs: int) -> None:
    """compete's experiment stopped by a Ctrl-C once ``runs`` runs have finished (0: before the first)."""
    import neurohover.experiments as experiments

    real = experiments.reproduce

    def stopping(config, db, executor, **kwargs):
        if runs == 0:
            raise KeyboardInterrupt
        seen = []

        def on_unit(key, result):
            kwargs["on_unit"](key, result)
            seen.append(key)
            if sum(k.startswith("run/") for k in seen) >= runs:
                raise KeyboardInterrupt

        return real(config, db, executor, **(kwargs | {"on_unit": on_unit}))

    monkeypatch.setattr(experiments, "reproduce", stopping)


def test_a_compete_stopped_before_any_run_finished_says_so(tmp_path: Path, cli, monkeypatch) -> None:
    _interrupt_after(monkeypatch, 0)
    rc, _, err = cli(*TINY, "--out", str(tmp_path / "c"))
    assert rc == 130
    assert err.strip().splitlines()[-1] == "neurohover compete: interrupted; no run had finished; run the same command again to start"
    assert not (tmp_path / "c" / "episodes.csv").exists()


@pytest.mark.slow
def test_a_compete_stopped_after_a_run_names_its_episodes(tmp_path: Path, cli, monkeypatch) -> None:
    _interrupt_after(monkeypatch, 1)
    rc, _, err = cli(*TINY, "--out", str(tmp_path / "c"))
    assert rc == 130
    assert err.strip().splitlines()[-1] == (
        f"neurohover compete: interrupted; its 1 finished run is in {tmp_path / 'c'}/episodes.csv and the results store; run the same command again to resume"
    )
    assert len((tmp_path / "c" / "episodes.csv").read_text().splitlines()) == 3  # its header and its two episodes
    monkeypatch.undo()
    rc, _, err = cli(*TINY, "--out", str(tmp_path / "c"))  # the same command resumes
    assert rc == 0 and "were already in" in err, err


# ------------------------------------------------------------------------------------------- T26-A06


def _other_files(folder: Path) -> dict[str, Path]:
    """Other neurohover files and a stranger's, each in a folder of its own under ``folder``, at compete's file names."""
    import numpy as np

    from neurohover import FlightData, baseline_policy, save_policy

    made: dict[str, Path] = {}

    def at(name: str, file: str) -> Path:
        made[name] = folder / name
        made[name].mkdir(parents=True)
        return made[name] / file

    save_policy(baseline_policy(), at("policy", "summary.json"))
    at("model", "summary.json").write_text(json.dumps({"format": "neurohover-model/1", "coefficients": []}))
    flight = FlightData((np.zeros((3, 12)),), (np.zeros((2, 4)),), {"episode_steps": 2}).save(folder / "f.npz")
    flight.rename(at("flight", "episodes.csv"))  # (fly --record writes .npz names only)
    at("export", "episodes.csv").write_text("experiment,scale,key,kind\n")
    at("notes", "episodes.csv").write_text("my own notes\n")
    at("folder", "summary.json").mkdir()
    return made


def test_compete_refuses_to_replace_another_file_at_its_names(tmp_path: Path) -> None:
    from neurohover.compete import compete

    expected = {
        "policy": "summary.json in {} is a policy file: compete would replace it with a competition summary; move it away or give another output directory",
        "model": "summary.json in {} is a model file: compete would replace it with a competition summary",
        "flight": "episodes.csv in {} is flight data (a NumPy archive): compete would replace it with a competition's episodes",
        "export": "episodes.csv in {} is a results export (results --format csv): compete would replace it",
        "notes": "episodes.csv in {} is no file compete wrote: compete would replace it with a competition's episodes",
        "folder": "summary.json in {} is a directory: compete would replace it",
    }
    for name, folder in _other_files(tmp_path).items():
        before = {p.name: p.read_bytes() for p in folder.iterdir() if p.is_file()}
        with pytest.raises(NeurohoverError) as err:
            compete("ghh08", "baseline", runs=1, episodes=2, n_steps=20, out=folder)
        assert str(err.value).startswith(expected[name].format(brief(str(folder)))), str(err.value)
        assert {p.name: p.read_bytes() for p in folder.iterdir() if p.is_file()} == before  # nothing run, nothing written


def test_compete_refuses_another_file_by_exit_2(tmp_path: Path, cli) -> None:
    folder = _other_files(tmp_path)["flight"]
    rc, _, err = cli(*TINY, "--out", str(folder))
    assert rc == 2 and f"episodes.csv in {brief(str(folder))} is flight data (a NumPy archive): compete would replace it" in err, err
    assert not (folder / "results.sqlite").exists()


@pytest.mark.slow
def test_compete_still_replaces_a_competition_an_older_summary_and_empty_files(tmp_path: Path, cli) -> None:
    out = tmp_path / "c"
    assert cli(*TINY, "--out", str(out))[0] == 0
    rc, _, err = cli(*TINY[:4], "incremental", *TINY[5:], "--out", str(out), "--store", str(tmp_path / "s.sqlite"))
    assert rc == 0 and "held the competition of baseline on ghh08" in err, err
    older = tmp_path / "older"
    older.mkdir()
    (older / "summary.json").write_text(json.dumps({"task": "ghh08", "agent": "hybrid"}))  # an older summary: task and agent
    (older / "episodes.csv").write_text("")
    rc, _, err = cli(*TINY, "--out", str(older))
    assert rc == 0 and "held the competition of hybrid on ghh08" in err, err
