"""Bad-input trial 34 (the Python API), the agents, the results store and the kernel's threading layer: T34-B06 (a final
Choice that asks to record: the flight data were never delivered), T34-B07 (a Choice's dangerous rule without a
fallback was ignored), T34-B14 (a Store dropped without close() kept its writer lock, and its own process was then told
that "another run" held it) and T34-B13 (multiprocessing's fork after a flight hung in libgomp)."""

from __future__ import annotations

import pytest

import neurohover as nh
from neurohover.agents import Choice


def test_final_choice_that_records_is_refused():
    """T34-B06: a final choice flies the rest of the run in one batch, without update; its recording was never seen."""
    with pytest.raises(nh.NeurohoverError, match=r"final=True with record=True is not allowed: .*update never sees"):
        Choice(nh.baseline_policy(), "baseline", final=True, record=True)
    assert Choice(nh.baseline_policy(), "baseline", final=True).final  # each alone is taken
    assert Choice(nh.baseline_policy(), "baseline", record=True).record


def test_dangerous_rule_without_fallback_is_refused():
    """T34-B07: without a fallback the safeguard acts on nothing (as evaluate_jobs refuses its limits alone, T28-B16)."""
    b = nh.baseline_policy()
    with pytest.raises(nh.NeurohoverError, match=r"Choice dangerous=DangerousState\(.* is not allowed without a fallback"):
        Choice(b, "x", dangerous=nh.DangerousState(box=0.001, tilt=0.001))
    assert Choice(b, "x", dangerous=nh.DangerousState()).fallback is None  # the default rule, named or not, is taken
    assert Choice(b, "x", fallback=b, dangerous=nh.DangerousState(box=0.001, tilt=0.001)).fallback is b


def test_continual_agent_without_safeguard_flies():
    """T34-B07: the continual agent with its safeguard off (or flying the generic) chose its own rule without a fallback."""
    from neurohover.agents.continual import ContinualAgent, ContinualSettings

    agent = ContinualAgent(nh.baseline_policy(), settings=ContinualSettings(safeguard_after=5))  # flying the generic: no fallback
    assert agent.choose(0).fallback is None


@pytest.mark.slow
def test_store_dropped_unclosed_lets_go_of_its_lock(tmp_path):
    """T34-B14: a Store dropped without close() kept its writer lock, and the next Store of the same process was told
    that "another run (pid <its own pid>)" wrote it, for as long as the process lived (a notebook cell run twice)."""
    import gc

    from neurohover.experiments.store import Store

    path = tmp_path / "s.sqlite"
    for _ in range(3):  # a loop of Store(path) + lock() without close: the second pass failed
        s = Store(path)
        s.lock()
        del s
    s = Store(path)
    s.lock()
    s = None  # rebinding drops it at once
    t = Store(path)
    t.lock()
    del t
    gc.collect()
    assert not (tmp_path / "s.sqlite.lock").exists()  # released as close() does
    with Store(path) as u:
        u.lock()


def test_store_held_by_this_process_is_named_so(tmp_path):
    """T34-B14: a lock another open Store of this very process holds is not "another run": waiting never ends it."""
    import os

    from neurohover.experiments.store import Store

    path = tmp_path / "s.sqlite"
    with Store(path) as first:
        first.lock()
        with pytest.raises(nh.NeurohoverError, match=rf"another open Store of this process \(pid {os.getpid()} .*close\(\) that Store first"):
            Store(path).lock()
    with Store(path) as again:  # closed: free again
        again.lock()


def test_forked_copy_of_a_store_leaves_the_lock_alone(tmp_path):
    """T34-B14: the collector's release acts only in the process that took the lock, not in a child forked from it."""
    import os

    from neurohover.experiments.store_checks import let_go
    from neurohover.locks import WriterLock

    lock = WriterLock(tmp_path / "x.lock")
    assert lock.acquire(lambda who: who)
    let_go(lock, -1, os.getpid() + 1)  # as in a forked child
    assert lock.held and lock.path.exists()
    let_go(lock, -1, os.getpid())
    assert not lock.held and not lock.path.exists()


_FORK_SCRIPT = """
import os, sys
import neurohover as nh
from neurohover.errors import NeurohoverError

def fly():
    fam = nh.get_task_family("ghh08")
    nh.evaluate(nh.baseline_policy(), fam.mdp("train:0"), episodes=1, n_steps=20, seed=1)

def in_child():
    pid = os.fork()
    if pid == 0:
        try:
            fly()
        except NeurohoverError as err:
            print("refused:", err, flush=True)
            os._exit(7)
        os._exit(0)
    return os.waitstatus_to_exitcode(os.waitpid(pid, 0)[1])

print("before", in_child(), flush=True)  # forked before any flight: the child starts its own threads
fly()
print("after", in_child(), flush=True)
"""


@pytest.mark.slow
def test_a_child_forked_after_a_flight_is_refused_not_killed():
    """T34-B13: a process forked after its parent flew on numba's GNU OpenMP threads was killed at its first flight
    ("Terminating: fork() called from a process already using GNU OpenMP"), and a fork Pool respawned it forever; it is
    now refused with the remedies named. The child of a parent that never flew flies."""
    import os
    import subprocess
    import sys

    env = {**os.environ, "NUMBA_THREADING_LAYER": "omp"}
    done = subprocess.run([sys.executable, "-c", _FORK_SCRIPT], env=env, capture_output=True, text=True, timeout=60)
    if "threading layer numba cannot load here" in done.stderr:
        pytest.skip("no OpenMP threading layer here")
    assert done.returncode == 0, done.stderr[-2000:]
    lines = done.stdout.splitlines()
    assert "before 0" in lines and "after 7" in lines, done.stdout + done.stderr[-2000:]
    refusal = next(line for line in lines if line.startswith("refused:"))
    assert "numba's OpenMP threads do not survive fork" in refusal and "get_context('spawn')" in refusal and "NUMBA_THREADING_LAYER=workqueue" in refusal
    assert "Terminating" not in done.stderr
