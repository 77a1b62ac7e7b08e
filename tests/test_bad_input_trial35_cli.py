"""Bad-input trial 35 (the command line): a subnormal CMA-ES sigma0 taken, then pycma's AssertionError (T35-A01); a
baseline-only run refused because a policy set it never flies changed (T35-A02); evolve ended without a word by a batch
scheduler's warning signals and the timers, its half-written checkpoint left beside the output for ever (T35-A03)."""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

import neurohover
from neurohover.experiments import Store


@pytest.mark.parametrize("sigma0", ["1e-320", "5e-324", "1e-101"])
def test_a_step_size_too_small_to_adapt_is_refused_before_flying(cli, tmp_path: Path, sigma0: str) -> None:
    out = tmp_path / "p.json"
    argv = ["evolve", "--task", "ghh08", "--optimizer", "cma", "--setting", f"sigma0={sigma0}", "--budget", "10", "--episode-steps", "20"]
    rc, _, err = cli(*argv, "--out", str(out))
    assert rc == 2 and "must be a finite number >= 1e-100 and <= 1e+100" in err and "Traceback" not in err, err
    assert not out.exists()


BASELINE_ONLY = """name = "mine"
kind = "test_runs"
[settings]
task = "ghh08"
seed = 1
policies = "{policies}"
groups = [{{ agent = "baseline", mdps = "test", n_mdps = 1 }}]
[scales.quick]
episodes = 2
n_steps = 20
"""


def _nudge_unflown_policy(policies: Path) -> None:
    """A set whose specialised_3 changed, as a rebuild changes it: its manifest records the new genome (T36-B05)."""
    from neurohover.manifest import DIGESTS, genome_digest

    path = policies / "ghh08" / "specialised_3.json"
    policy = json.loads(path.read_text())
    policy["genome"][0] += 0.01
    path.write_text(json.dumps(policy))
    manifest = json.loads((policies / "ghh08" / "manifest.json").read_text())
    manifest[DIGESTS]["specialised_3.json"] = genome_digest(neurohover.load_policy(path))
    (policies / "ghh08" / "manifest.json").write_text(json.dumps(manifest))


def test_a_baseline_only_experiment_runs_on_after_a_policy_it_never_flies_changed(cli, tmp_path: Path) -> None:
    policies = tmp_path / "pd2"
    shutil.copytree(Path(neurohover.__file__).parent / "data" / "policies", policies)
    config = tmp_path / "c.toml"
    config.write_text(BASELINE_ONLY.format(policies=policies))
    store = tmp_path / "s.sqlite"
    assert cli("reproduce", str(config), "--store", str(store), "--no-progress")[0] == 0
    with Store(store) as db:
        before = db.results("mine", "quick")
    _nudge_unflown_policy(policies)
    rc, _, err = cli("reproduce", str(config), "--store", str(store), "--no-progress")
    assert rc == 0, err
    with Store(store) as db:
        assert db.results("mine", "quick") == before


@pytest.mark.slow
def test_a_baseline_competition_stored_with_the_sets_digest_is_taken_and_relabelled(cli, tmp_path: Path, monkeypatch) -> None:
    """A folder an older neurohover wrote (its config hashed the shipped set) takes a baseline compete again, runs kept."""
    from neurohover.experiments import external

    argv = ["compete", "--task", "ghh08", "--agent", "baseline", "--runs", "1", "--episodes", "2", "--episode-steps", "20", "--out", str(tmp_path / "c")]
    with monkeypatch.context() as m:  # as neurohover hashed it before T35-A02: every named set
        m.setattr(external, "_flies_set", lambda kind, settings, unregistered=None: True)
        assert cli(*argv)[0] == 0
    with Store(tmp_path / "c" / "results.sqlite") as db:
        ((name, scale, *_),) = db.experiments()
        old_hash, before = db.config_hash(name, scale), db.results(name, scale)
        assert db.config(name, scale)["external_digest"]
    rc, _, err = cli(*argv)
    assert rc == 0 and "hashed an unflown policy set" in err, err
    with Store(tmp_path / "c" / "results.sqlite") as db:
        assert db.results(name, scale) == before and db.config_hash(name, scale) != old_hash
        assert db.config(name, scale)["external_digest"] == ""


def test_the_scheduler_warnings_and_timers_stop_a_command_as_sigterm_does() -> None:
    """SIGUSR2 and SIGXCPU (what SGE's -notify, Slurm's --signal and a CPU-time limit send before their kill) and the
    timer signals stop the command with its line and 128 + the signal; SIGQUIT and SIGTRAP keep their core dumps."""
    from neurohover.errors import Terminated, raise_terminated, stop_signals
    from neurohover.procs import stop_words

    also = {signal.SIGUSR2, signal.SIGXCPU, signal.SIGALRM, signal.SIGVTALRM, signal.SIGPROF}
    assert also <= set(stop_signals()) and not {signal.SIGQUIT, signal.SIGTRAP} & set(stop_signals())
    assert not also & set(stop_signals(command=False))  # a program calling main() keeps its own timers
    for signum in also:
        with pytest.raises(Terminated) as caught:
            raise_terminated(signum, None)
        assert stop_words(caught.value) == ("terminated", 128 + signum)


def assert_evolve_stops_on(tmp_path: Path, signum: int) -> None:
    """A running evolve signalled ``signum`` (once its first checkpoint is written) ends as SIGTERM ends it: its line,
    128 + the signal, its checkpoint, no lock or temporary file (trial 38's real-time signal too)."""
    from test_procs import _end_group, _start

    out = tmp_path / "e.json"
    argv = ["evolve", "--task", "ghh08", "--mdp", "G", "--budget", "1000000", "--episode-steps", "200", "--checkpoint-every", "1"]
    proc = _start(tmp_path, *argv, "--out", str(out))
    try:
        deadline = time.monotonic() + 120  # a safety net: its first generation checkpointed
        while time.monotonic() < deadline and proc.poll() is None and not (tmp_path / "e.json.checkpoint.json").exists():
            time.sleep(0.05)
        os.kill(proc.pid, signum)
        rc = proc.wait(timeout=60)
        err = (tmp_path / "stderr.txt").read_text()
        assert rc == 128 + signum and "Traceback" not in err, err[-2000:]
        assert err.strip().splitlines()[-1].startswith("neurohover evolve: terminated"), err[-2000:]
        left = sorted(p.name for p in tmp_path.iterdir() if p.name not in ("stdout.txt", "stderr.txt"))
        assert left == ["e.json.checkpoint.json"], left  # no lock, no temporary file
    finally:
        _end_group(proc)


@pytest.mark.slow
@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="real processes signalled, found in /proc")
def test_evolve_stopped_by_a_schedulers_sigusr2_saves_its_checkpoint_and_says_so(tmp_path: Path) -> None:
    assert_evolve_stops_on(tmp_path, signal.SIGUSR2)


def _dead_pid() -> int:
    """The pid of a process that has ended (and been reaped)."""
    proc = subprocess.Popen(["true"])
    proc.wait()
    return proc.pid


def test_a_killed_writers_temporary_files_are_removed_by_the_next_run_of_its_output(cli, tmp_path: Path) -> None:
    """A writer stopped at once (SIGKILL, SIGQUIT's core dump) leaves NAME.PID.TID.tmp / .NAME.PID.TID.partial: the
    next run on that output removes those of processes no longer running, not a live one's nor other files."""
    out = tmp_path / "e.json"
    dead = _dead_pid()
    stale = [tmp_path / f"e.json.checkpoint.json.{dead}.{dead}.tmp", tmp_path / f".e.json.{dead}.{dead + 1}.partial"]
    kept = [tmp_path / f"e.json.checkpoint.json.{os.getpid()}.999999.tmp", tmp_path / f"e.json.{dead}.{dead}.tmp.notes", tmp_path / f"f.json.{dead}.1.tmp"]
    for path in stale + kept:
        path.write_text("{")
    rc, _, err = cli("evolve", "--task", "ghh08", "--mdp", "G", "--budget", "10", "--episode-steps", "20", "--out", str(out))
    assert rc == 0, err
    assert not any(path.exists() for path in stale) and all(path.exists() for path in kept)


def test_a_killed_writers_files_beside_an_output_whose_name_starts_with_a_dot_are_removed(tmp_path: Path) -> None:
    """The writer files of an output named '.p.json' start with a dot of the output's own: '.p.json.PID.TID.tmp' was
    taken for a hidden .tmp (none is written) and left for ever."""
    from neurohover.locks import sole_writer

    dead = _dead_pid()
    stale = [tmp_path / f".p.json.{dead}.{dead}.tmp", tmp_path / f"..p.json.{dead}.{dead}.partial"]
    kept = tmp_path / f".p.json.{os.getpid()}.1.tmp"
    for path in [*stale, kept]:
        path.write_text("{")
    with sole_writer(tmp_path / ".p.json", "--out"):
        assert not any(path.exists() for path in stale) and kept.exists()
