"""The twenty-third bad-input trial's finding in evolve checkpoints (T23-09): a steady-state checkpoint whose
optimizer_state.tracker.genome is no genome of its population was resumed, and the edited genome written as the run's
champion. With an elite, the population keeps the champion (steady_state.tell: the elite keeps the best rows, ties in
order), so such a checkpoint is refused as damaged, naming the entry. Without an elite, and for the optimisers that keep
no population (CMA-ES) or check their own champion (generational NE: one of its parents), nothing more is required."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from neurohover.errors import NeurohoverError
from neurohover.evolution.evolve import evolve
from neurohover.evolution.steady_state import SteadyStateSettings
from neurohover.tasks import get_task_family

ZERO = get_task_family("ghh08").zero()
#: The run behind the tiny_checkpoint fixture (conftest.py), and the same on the command line.
MDP_RUN = dict(topology="slp", prototype="baseline", seed=3, n_steps=20)
CLI_RUN = ("evolve", "--task", "ghh08", "--mdp", "zero", "--topology", "slp", "--seed-policy", "baseline", "--seed", "3", "--episode-steps", "20")


def _edit_tracker(state: dict, gene: float = 7.0) -> None:
    state["optimizer_state"]["tracker"]["genome"]["data"][0] = gene


def test_a_tracker_genome_outside_the_population_is_refused_on_the_command_line(tiny_checkpoint: Path, tmp_path: Path, cli) -> None:
    """T23-09: tracker.genome.data[0] = 7.0 was resumed (exit 0) and written as the champion; now exit 2, one line."""
    state = json.loads(tiny_checkpoint.read_text())
    _edit_tracker(state)
    (tmp_path / "run.json.checkpoint.json").write_text(json.dumps(state))
    out = tmp_path / "run.json"
    rc, _, err = cli(*CLI_RUN, "--budget", "60", "--out", str(out), "--resume")
    assert rc == 2 and "Traceback" not in err and not out.exists(), err
    best = state["optimizer_state"]["tracker"]["best"]
    text = " ".join(err.split())
    assert (
        f"is a damaged checkpoint: optimizer_state.tracker.genome is not allowed: it is no genome of the population with the champion's return {best!r}" in text
    )
    assert "(gene 0 is 7.0, row " in text and "allowed the population's row of that return (the elite of 49 keeps the champion)" in text


def test_a_sound_multi_generation_checkpoint_resumes_and_its_edited_tracker_is_refused(tmp_path: Path) -> None:
    """T23-09 past the first generation (the champion kept by the elite as the population is bred): the sound
    checkpoint resumes; the tracker genome edited is refused, in the Python API too."""
    settings = SteadyStateSettings(pop_size=6, elite_size=2)
    ckpt = tmp_path / "run.ckpt.json"
    evolve(ZERO, budget=30, checkpoint=ckpt, settings=settings, **MDP_RUN)
    state = json.loads(ckpt.read_text())
    assert state["counters"]["generation"] > 2
    assert evolve(ZERO, budget=34, checkpoint=ckpt, resume=True, settings=settings, **MDP_RUN).episodes == 34  # sound: resumes
    state = json.loads(ckpt.read_text())
    _edit_tracker(state, -3.25)
    ckpt.write_text(json.dumps(state))
    with pytest.raises(NeurohoverError, match=re.escape("is a damaged checkpoint: optimizer_state.tracker.genome is not allowed: it is no genome")):
        evolve(ZERO, budget=40, checkpoint=ckpt, resume=True, settings=settings, **MDP_RUN)


def test_without_an_elite_a_champion_outside_the_population_is_no_contradiction(tmp_path: Path) -> None:
    """T23-09: with elite_size 0 the champion may be bred away, so a checkpoint whose tracker genome is in no row of its
    population is sound: it resumes."""
    settings = SteadyStateSettings(pop_size=4, elite_size=0)
    ckpt = tmp_path / "run.ckpt.json"
    evolve(ZERO, budget=24, checkpoint=ckpt, settings=settings, **MDP_RUN)
    assert evolve(ZERO, budget=28, checkpoint=ckpt, resume=True, settings=settings, **MDP_RUN).episodes == 28
