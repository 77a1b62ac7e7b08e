"""Bad-input trial 55, side A (signals): SIGTERM, SIGHUP and SIGUSR1 sent to a running ``neurohover evolve`` ended it
mid-generation, saying "the last periodic checkpoint (if any) is X" where there was none: the run's episodes were lost,
where Ctrl-C at the same moment saved its checkpoint (T55-A01). A stop signal now waits for the generation boundary as
the first Ctrl-C does: the checkpoint is saved and said, status 128 + the signal, and the same command resumes it."""

from __future__ import annotations

import json
import math
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from conftest import ROOT, finish_run

from neurohover.errors import Terminated, raise_terminated
from neurohover.evolution.evolve import EvolutionInterrupted, evolve
from neurohover.evolution.run import InterruptFlag
from neurohover.procs import stop_words
from neurohover.tasks import get_task_family

POSIX = hasattr(signal, "SIGHUP") and hasattr(signal, "SIGUSR1")


@pytest.fixture
def command_handlers():
    """SIGTERM, SIGHUP and SIGUSR1 handled as the command handles them (:func:`~neurohover.errors.raise_terminated`)
    while the test runs; the test process's own handlers put back after."""
    taken = [signal.SIGTERM, signal.SIGHUP, signal.SIGUSR1]
    previous = {signum: signal.signal(signum, raise_terminated) for signum in taken}
    try:
        yield
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler)


@pytest.mark.skipif(not POSIX, reason="SIGHUP and SIGUSR1")
def test_a_stop_signal_waits_for_the_generation_boundary_and_a_second_one_stops_at_once(command_handlers) -> None:
    """The first stop signal only sets the flag (as the first Ctrl-C); a second one raises at once, as its own signal,
    so that a save it lands in is cut before its rename (the earlier checkpoint stands); the handlers are put back."""
    with pytest.raises(Terminated) as caught:
        with InterruptFlag() as flag:
            signal.raise_signal(signal.SIGHUP)
            assert flag.set and flag.signum == signal.SIGHUP
            assert stop_words(flag.stop()) == ("terminated", 129)
            signal.raise_signal(signal.SIGUSR1)
    assert stop_words(caught.value) == ("terminated", 128 + signal.SIGUSR1)
    assert all(signal.getsignal(s) is raise_terminated for s in (signal.SIGTERM, signal.SIGHUP, signal.SIGUSR1))
    with pytest.raises(Terminated) as caught:  # the last generation was checked: the stop still reaches the caller
        with InterruptFlag():
            signal.raise_signal(signal.SIGTERM)
    assert stop_words(caught.value) == ("terminated", 143)


@pytest.mark.skipif(not POSIX, reason="SIGHUP")
def test_a_programs_own_stop_signal_handler_is_left_alone(command_handlers) -> None:
    heard: list[int] = []

    def own(signum, frame) -> None:
        heard.append(signum)

    signal.signal(signal.SIGHUP, own)
    with InterruptFlag() as flag:
        assert signal.getsignal(signal.SIGHUP) is own
        signal.raise_signal(signal.SIGHUP)
    assert heard == [signal.SIGHUP] and not flag.set


def test_sigterm_mid_run_saves_the_checkpoint_as_ctrl_c_does_and_the_run_resumes(command_handlers, tmp_path: Path) -> None:
    """A SIGTERM during the run (here from its progress call) saves the checkpoint at the next generation boundary; the
    stop says "terminated", 143; resumed, the run continues from the saved counters."""
    ckpt = tmp_path / "run.ckpt.json"
    common = dict(topology="slp", prototype="baseline", seed=3, n_steps=20, checkpoint=ckpt, checkpoint_every_s=math.inf)  # no periodic one

    def progress(info) -> None:
        if info.generation == 2:
            signal.raise_signal(signal.SIGTERM)

    family = get_task_family("ghh08")
    with pytest.raises(EvolutionInterrupted) as caught:
        evolve(family, budget=100_000, progress=progress, progress_every_s=0, **common)
    stop = caught.value
    assert stop.checkpoint == ckpt and stop_words(stop) == ("terminated", 143), str(stop)
    saved = json.loads(ckpt.read_text())["counters"]
    assert saved["generation"] == 3 and saved["episodes"] == stop.episodes > 0
    result = evolve(family, budget=stop.episodes + 1, resume=True, **common)
    assert result.episodes > stop.episodes and result.generations > saved["generation"]


def test_a_second_sigterm_during_the_stops_save_leaves_the_last_checkpoint_whole(command_handlers, tmp_path: Path, monkeypatch) -> None:
    """A second SIGTERM landing while the first one's checkpoint is written (here inside its fsync) stops at once: the
    file written before stands byte for byte, no temporary file is left, and the run resumes from it."""
    from neurohover.evolution import records

    ckpt = tmp_path / "run.ckpt.json"
    common = dict(topology="slp", prototype="baseline", seed=3, n_steps=20, checkpoint=ckpt, checkpoint_every_s=math.inf)
    family = get_task_family("ghh08")
    evolve(family, budget=300, **common)
    before = ckpt.read_bytes()
    sync = os.fsync

    def second_signal_mid_write(fd: int) -> None:
        signal.raise_signal(signal.SIGTERM)  # the flag is set: this one raises here, before the rename
        sync(fd)

    def progress(info) -> None:
        signal.raise_signal(signal.SIGTERM)
        monkeypatch.setattr(records.os, "fsync", second_signal_mid_write)

    with pytest.raises(Terminated) as caught:
        evolve(family, budget=100_000, resume=True, progress=progress, progress_every_s=0, **common)
    monkeypatch.undo()
    assert stop_words(caught.value) == ("terminated", 143)
    assert ckpt.read_bytes() == before and sorted(p.name for p in tmp_path.iterdir()) == [ckpt.name]
    assert evolve(family, budget=600, resume=True, **common).episodes >= 600


def test_a_second_stop_mid_generation_names_no_checkpoint_that_is_not_there(tmp_path: Path, capsys) -> None:
    """The command's line after a second signal mid-generation: no checkpoint named where none was saved; the one a
    run wrote (or resumed from) named with --resume."""
    from neurohover.cli.learning import _evolve_stopped, _modified

    ckpt = tmp_path / "e.json.checkpoint.json"
    try:
        raise Terminated("signal 1", signum=signal.SIGHUP if POSIX else 15)
    except Terminated:
        try:
            raise EvolutionInterrupted(None, 50) from None
        except EvolutionInterrupted as err:
            stopped = err
    status = _evolve_stopped(stopped, ckpt, _modified(ckpt), False)
    assert status == (129 if POSIX else 143)
    assert capsys.readouterr().err.strip() == "neurohover evolve: terminated mid-generation; no checkpoint of this run was saved"
    ckpt.write_text("{}")
    _evolve_stopped(stopped, ckpt, _modified(ckpt), True)
    assert f"terminated mid-generation; its last checkpoint is {ckpt} (run the same command with --resume" in capsys.readouterr().err


@pytest.mark.slow
@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="a real process signalled")
def test_sigterm_to_a_running_evolve_command_saves_its_checkpoint_and_the_same_command_resumes(cli, tmp_path: Path) -> None:
    """T55-A01 as reported: `neurohover evolve` sent SIGTERM once flying (its first periodic checkpoint written) ends at
    the next generation with its checkpoint saved and said, status 143, and --resume continues that run."""
    out = tmp_path / "e.json"
    ckpt = tmp_path / "e.json.checkpoint.json"
    argv = ["evolve", "--task", "ghh08", "--mdp", "G", "--episode-steps", "10", "--validation-episodes", "1", "--out", str(out)]
    proc = subprocess.Popen(
        [sys.executable, "-m", "neurohover", *argv, "--budget", "1000000", "--checkpoint-every", "0.05"],
        cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True,
    )  # fmt: skip
    deadline = time.monotonic() + 60  # a safety net, not a speed assumption: the run is flying once it checkpointed
    while not ckpt.exists() and proc.poll() is None and time.monotonic() < deadline:
        time.sleep(0.02)
    if proc.poll() is None:
        os.kill(proc.pid, signal.SIGTERM)
    _, err = finish_run(proc, 60)
    assert proc.returncode == 143 and "Traceback" not in err, err[-2000:]
    last = err.strip().splitlines()[-1]
    assert last.startswith("neurohover evolve: terminated after ") and last.endswith(
        f"episodes; checkpoint saved to {ckpt} (run the same command with --resume to continue)"
    ), last
    episodes = int(last.split(" after ")[1].split()[0])
    assert json.loads(ckpt.read_text())["counters"]["episodes"] == episodes > 0
    rc, _, err = cli(*argv, "--resume", "--budget", str(episodes + 1))
    assert rc == 0 and out.is_file(), err
    assert json.loads(ckpt.read_text())["counters"]["episodes"] > episodes
