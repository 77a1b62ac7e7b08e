"""The twenty-first bad-input trial's finding in evolve checkpoints (T21-03): counters that no run can have together
(fewer steps than episodes, more evaluations than episodes, more kernel seconds than wall seconds, a history row with
fewer episodes than evaluations) are refused on resume by name, as a damaged checkpoint, instead of being resumed."""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import numpy as np
import pytest

from neurohover.errors import NeurohoverError
from neurohover.evolution.evolve import evolve
from neurohover.flyer import KernelFlyer
from neurohover.policies import prototype
from neurohover.sim.constants import CRASH_STEP_PENALTY
from neurohover.tasks import get_task_family

ZERO = get_task_family("ghh08").zero()
#: The run behind the tiny_checkpoint fixture (conftest.py): steady state on GHH-08's zero MDP, 50 episodes of 20 steps.
MDP_RUN = dict(topology="slp", prototype="baseline", seed=3, n_steps=20)
#: The same run on the command line (resumed from a copy of the fixture's checkpoint).
CLI_RUN = ("evolve", "--task", "ghh08", "--mdp", "zero", "--topology", "slp", "--seed-policy", "baseline", "--seed", "3", "--episode-steps", "20")


def _resume(source: Path, tmp_path: Path, edit) -> None:
    """Resume a copy of checkpoint ``source`` damaged by ``edit`` (with its episodes as the budget: a sound one stops at once)."""
    state = json.loads(source.read_text())
    edit(state)
    ckpt = tmp_path / "run.ckpt.json"
    ckpt.write_text(json.dumps(state))
    evolve(ZERO, budget=max(state["counters"]["episodes"], 1), checkpoint=ckpt, resume=True, **MDP_RUN)


def test_an_episode_that_crashes_on_its_first_step_counts_one_step() -> None:
    """What the refusal rests on: the kernel counts the step an episode crashes on, so every episode has a step or more
    (a NaN genome's first action is not finite: each episode crashes on step 1 and counts 1)."""
    flyer = KernelFlyer("slp", 1, 20)
    genome = np.full_like(prototype("slp", "baseline").genome, np.nan)
    flyer.fly(genome[None, :], ZERO.row()[None, :], None, None, 3)
    assert flyer.crashed.tolist() == [True] * 3 and flyer.job_steps.tolist() == [1, 1, 1]
    assert (flyer.episodes, flyer.steps) == (3, 3)


def test_fewer_steps_than_episodes_is_refused_on_the_command_line(tiny_checkpoint: Path, tmp_path: Path, cli) -> None:
    """T21-03: counters of 40 episodes and 3 steps were resumed (exit 0); each episode flies a step or more, so now the
    checkpoint is refused as damaged, naming both counters, with exit status 2 and no traceback."""
    ckpt = tmp_path / "run.json.checkpoint.json"
    state = json.loads(tiny_checkpoint.read_text())
    state["counters"].update(episodes=40, steps=3)
    state["history"] = []  # (its row's 50 episodes would be past the 40)
    ckpt.write_text(json.dumps(state))
    rc, _, err = cli(*CLI_RUN, "--budget", "60", "--out", str(tmp_path / "run.json"), "--resume")
    assert rc == 2 and "Traceback" not in err and "ValueError" not in err  # (a ValueError's message was prefixed so)
    assert "is a damaged checkpoint: counter 'steps' is 3, below the 40 episodes counted (each has a step or more" in " ".join(err.split())


@pytest.mark.parametrize(
    ("edit", "fragment"),
    [
        (lambda c: c.update(steps=49), "counter 'steps' is 49, below the 50 episodes counted (each has a step or more, a crash on its first too)"),
        (lambda c: c.update(steps=0), "counter 'steps' is 0, below the 50 episodes counted"),
        (lambda c: c.update(evaluations=51), "counter 'episodes' is 50, below the 51 evaluations (each flies an episode or more)"),
        (
            lambda c: c.update(wall_seconds=1.0, kernel_seconds=1.5),
            "counter 'kernel_seconds' is 1.5, more than the run's wall_seconds 1.0 (its kernel time is part",
        ),
    ],
)
def test_counters_no_run_can_have_together_are_refused(tiny_checkpoint: Path, tmp_path: Path, edit, fragment: str) -> None:
    """T21-03: fewer steps than episodes, more evaluations than episodes and more kernel time than wall time were
    resumed; now each is refused as damaged, naming both counters."""
    with pytest.raises(NeurohoverError, match=re.escape(f"is a damaged checkpoint: {fragment}")):
        _resume(tiny_checkpoint, tmp_path, lambda s: edit(s["counters"]))


@pytest.mark.parametrize(
    ("cells", "fragment"),
    [
        ({1: 0}, "history row 0 (from 0): evaluations=0 is not allowed (below its 1 generations: each evaluates a candidate)"),
        ({2: 40, 3: 40}, "history row 0 (from 0): episodes=40 is not allowed (below its 50 evaluations: each flies an episode or more)"),
    ],
)
def test_a_history_row_no_run_can_have_is_refused(tiny_checkpoint: Path, tmp_path: Path, cells: dict, fragment: str) -> None:
    """T21-03: a history row (generation, evaluations, episodes, generation_episodes, ...) holds the counters as they
    were, so the counters' rules hold row by row: the row of 1 generation, 50 evaluations and 50 episodes edited."""

    def edit(state):
        for column, value in cells.items():
            state["history"][0][column] = value

    with pytest.raises(NeurohoverError, match=re.escape(fragment)):
        _resume(tiny_checkpoint, tmp_path, edit)


def test_counters_at_their_bounds_resume(tiny_checkpoint: Path, tmp_path: Path) -> None:
    """Counters every run can have are taken: the fewest steps its population's returns allow (each episode that flew s
    steps charged the worst step for its 20 - s left, T33-B07; one step an episode if each crashed on its first), as many
    episodes as evaluations, the kernel's time all of the wall time."""
    fitness = json.loads(tiny_checkpoint.read_text())["optimizer_state"]["fitness"]["data"]
    fewest = math.ceil(sum(20 + f / CRASH_STEP_PENALTY for f in fitness))
    for counters in ({"steps": fewest}, {"steps": 50 * 20}, {"wall_seconds": 2.0, "kernel_seconds": 2.0}):
        _resume(tiny_checkpoint, tmp_path, lambda s, c=counters: s["counters"].update(c))
