"""Fixtures the test modules share: the repository's root, the committed results store, the command line in-process."""

from __future__ import annotations

import gzip
import os
import shutil
import signal
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
STORE_GZ = ROOT / "docs" / "reproduction" / "results.sqlite.gz"

# Every process a test starts (scripts, commands, Ray workers) imports this checkout, as the tests do, and so
# shares its compiled-kernel cache: from another directory it found the installed copy and compiled it afresh.
os.environ["PYTHONPATH"] = os.pathsep.join([str(ROOT), *filter(None, [os.environ.get("PYTHONPATH")])])

#: What the ``cli`` fixture returns for one command: exit status, standard output, standard error.
CliRun = Callable[..., tuple[int, str, str]]


def tiny_test_runs(*agents: str, name: str = "tr1", settings: str = "") -> str:
    """A test-runs config (TOML) flying each of ``agents`` on one GHH-08 test MDP, two episodes of 20 steps at the quick
    scale; ``settings``, if given, is every group's own settings table (TOML, e.g. "{ safeguard_after = 20 }")."""
    own = f"settings = {settings}\n" if settings else ""
    groups = "".join(f'[[settings.groups]]\nagent = "{a}"\nmdps = "test"\nn_mdps = 1\n{own}' for a in agents)
    return (
        f'name = "{name}"\ntitle = "tiny"\nkind = "test_runs"\n[settings]\ntask = "ghh08"\nseed = 1\npolicies = "shipped"\n'
        f"{groups}[scales.quick]\nepisodes = 2\nn_steps = 20\n"
    )


def tiny_model_learning(name: str, generic: str) -> str:
    """A model-learning config (TOML) learning LR on one GHH-08 test MDP, 20 steps and budgets of 10 at the quick scale,
    its generic policy ``generic`` ("baseline", or "evolve": its own policy/ units first). It gives only the budgets its
    units use: an EC method's budget, or generic_budget without generic = "evolve", is refused (T60-A02)."""
    generic_budget = "generic_budget = 10\n" if generic == "evolve" else ""
    return (
        f'name = "{name}"\nkind = "model_learning"\n\n[settings]\ntask = "ghh08"\nseed = 1\nmdps = "test"\nmethods = ["lr"]\n'
        f'generic = "{generic}"\npolicy_prototype = "generic"\ntest_episodes = 1\n\n[scales.quick]\nn_mdps = 1\nn_steps = 20\n'
        f"{generic_budget}policy_budget = 10\n"
    )


#: A ``reproduce`` whose plan is twelve diagnostic units (argv: GATES EXPERIMENT reproduce ...): unit i waits
#: until the file GATES/i exists, so a test, not the machine's speed, decides how far the run gets.
GATED_RUN = """
import faulthandler
import signal
import sys

faulthandler.register(signal.SIGUSR1, all_threads=True)  # finish_run asks a run that does not end where it is
# Ctrl-C as in a terminal, however the tests were started: a shell without job control starts a background
# command (`pytest ... &`) with SIGINT ignored, every process below inherits that, and the run would never stop.
signal.signal(signal.SIGINT, signal.default_int_handler)
from neurohover.cli import main
from neurohover.experiments import runner
from neurohover.experiments.plans import Plan
from neurohover.experiments.units import Unit

# Twelve units, unit i held until the test creates gates/i: the test, not the machine's speed, decides
# how far a run gets before it is interrupted.
gates = sys.argv[1]
units = [Unit(sys.argv[2], f"u{i:02d}", "diagnostic", {"value": i, "wait_for": f"{gates}/{i}"}) for i in range(12)]
runner.plan = lambda config, results, sources=None: Plan(units, 12)
sys.exit(main(sys.argv[3:]))
"""


def start_gated_run(config: Path, store: Path, gates: Path, name: str = "slowtest") -> subprocess.Popen:
    """``neurohover reproduce CONFIG --store STORE`` in a process of its own, its units held at ``gates`` (:data:`GATED_RUN`)."""
    argv = [sys.executable, "-c", GATED_RUN, str(gates), name, "reproduce", str(config), "--scale", "quick", "--store", str(store), "--no-progress"]
    # Its own session, so a failed test can end the whole process group.
    return subprocess.Popen(argv, cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True)


@pytest.fixture(scope="session")
def repo_root() -> Path:
    """The checkout the tests run from (README, docs, examples, configs)."""
    return ROOT


@pytest.fixture(scope="session")
def committed_store(tmp_path_factory) -> Path:
    """A private copy of the committed paper-scale results store (skipped where the checkout lacks it)."""
    if not STORE_GZ.is_file():
        pytest.skip("the committed results store is not in this checkout")
    path = tmp_path_factory.mktemp("committed") / "results.sqlite"
    with gzip.open(STORE_GZ) as src, open(path, "wb") as dst:
        shutil.copyfileobj(src, dst)
    return path


@pytest.fixture(scope="session")
def tiny_checkpoint(tmp_path_factory) -> Path:
    """A sound checkpoint of a 5-episode steady-state run on GHH-08's zero MDP (slp from the baseline, seed 3, 20 steps):
    tests read it and damage a copy (they must not write it)."""
    from neurohover.evolution.evolve import evolve
    from neurohover.tasks import get_task_family

    ckpt = tmp_path_factory.mktemp("tiny-checkpoint") / "run.ckpt.json"
    evolve(get_task_family("ghh08").zero(), budget=5, checkpoint=ckpt, topology="slp", prototype="baseline", seed=3, n_steps=20)
    return ckpt


@pytest.fixture
def cli(capsys) -> CliRun:
    """``neurohover ARGS...`` run in this process: returns (exit status, stdout, stderr)."""
    from neurohover.cli import main

    def run(*argv: str) -> tuple[int, str, str]:
        rc = main(list(argv))
        out = capsys.readouterr()
        return rc, out.out, out.err

    return run


def finish_run(proc: subprocess.Popen, timeout: float) -> tuple[str, str]:
    """``proc.communicate()``; a run still going after ``timeout`` seconds (a safety net, not a speed
    assumption) prints its threads' stacks, is killed with its process group, and fails the test with its output."""
    try:
        return proc.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        proc.send_signal(signal.SIGUSR1)
        try:
            out, err = proc.communicate(timeout=5)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            out, err = proc.communicate()
        pytest.fail(f"the run did not end within {timeout:g} s; its stacks and output:\n{out}\n{err}")


def table_sampler(table):
    """A race's ``sample_fn`` over a table of samples: candidate i's t-th episode is ``table[i, t]`` (fixed, as an
    evolution run's is), whatever order the candidates are listed in."""
    import numpy as np

    count = np.zeros(table.shape[0], dtype=int)

    def sample(idx):
        out = np.empty(idx.size)
        for j, i in enumerate(idx):
            out[j] = table[i, count[i]]
            count[i] += 1
        return out

    return sample
