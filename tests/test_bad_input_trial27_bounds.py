"""Bounds of the twenty-seventh bad-input trial (T27-B03, T27-B10): returns and fitness that no episode of a run's own
length can have are refused (a checkpoint's optimiser fitness, a stored evolve unit's champion and history, an
EpisodeOutcome's and an Evaluation's returns); one twin of the kernel's crash charge and one seconds predicate serve
every reader."""

from __future__ import annotations

import dataclasses
import json
import math
import re
from pathlib import Path

import pytest

from neurohover.errors import NeurohoverError
from neurohover.evolution.evolve import evolve
from neurohover.tasks import get_task_family

#: The run behind the tiny_checkpoint fixture (conftest.py): steady state on GHH-08's zero MDP, 20-step episodes.
MDP_RUN = dict(topology="slp", prototype="baseline", seed=3, n_steps=20)


def _raises(fragment: str):
    return pytest.raises(NeurohoverError, match=re.escape(fragment))


# --------------------------------------------------------------------------- T27-B03: a checkpoint's fitness


@pytest.mark.parametrize(
    ("value", "shown"), [(-1e9, "-1000000000.0"), (-34976.17, "-34976.17"), (5.0, "5.0"), ("inf", "'inf'")], ids=["-1e9", "just-below", "positive", "inf"]
)
def test_a_steady_state_fitness_no_episode_of_the_run_can_have_is_refused(tiny_checkpoint: Path, tmp_path: Path, value, shown) -> None:
    state = json.loads(tiny_checkpoint.read_text())
    data = state["optimizer_state"]["fitness"]["data"]
    assert data[2] != state["optimizer_state"]["tracker"]["best"]  # not the champion's row (the elite's check of it comes first)
    ckpt = tmp_path / "run.ckpt.json"
    data[2] = -34976.1599  # just above the floor of 20 steps, -34976.15997: resumed
    ckpt.write_text(json.dumps(state))
    evolve(get_task_family("ghh08").zero(), budget=50, checkpoint=ckpt, resume=True, **MDP_RUN)
    state["optimizer_state"]["fitness"]["data"][2] = value
    ckpt.write_text(json.dumps(state))
    fragment = f"optimizer_state.fitness data entry 2 is {shown}: not allowed in a run of 20-step episodes"
    if value == "inf" or value == 5.0:  # the optimiser's own checks name them first (+inf is never told; 5.0 is above its champion)
        fragment = "holds +inf" if value == "inf" else "fitness (best 5.0) disagrees with its champion's return"
    with _raises(fragment) as refused:
        evolve(get_task_family("ghh08").zero(), budget=60, checkpoint=ckpt, resume=True, **MDP_RUN)
    if "data entry" in fragment:
        assert "allowed '-inf', 'nan' (an episode that blew up) or a mean return in [-34976.15997, 0]" in str(refused.value)


def test_a_nan_steady_state_fitness_is_resumed_as_evolve_writes_it(tiny_checkpoint: Path, tmp_path: Path) -> None:
    """Not refused (the trial's "evolve never writes NaN there" misreads it): steady state flies raw returns, and an
    episode that blows up (a learned model's MDP of extreme parameters) is told and checkpointed as NaN."""
    state = json.loads(tiny_checkpoint.read_text())
    state["optimizer_state"]["fitness"]["data"][2] = "nan"
    ckpt = tmp_path / "run.ckpt.json"
    ckpt.write_text(json.dumps(state))
    assert evolve(get_task_family("ghh08").zero(), budget=50, checkpoint=ckpt, resume=True, **MDP_RUN).episodes == 50


def test_a_history_fitness_no_episode_of_the_run_can_have_is_refused(tmp_path: Path) -> None:
    """A generational run on inv-log-error (10-step episodes): an error of at most 17488.08, so a fitness of at least
    1/ln(17488.08) = 0.1024; 0.05 in a row before the last is refused by its row."""
    from neurohover.evolution.generational import GenerationalSettings

    run = dict(topology="slp", prototype="baseline", seed=3, n_steps=10, settings=GenerationalSettings(pop_size=4, select_size=2))
    ckpt = tmp_path / "run.ckpt.json"
    evolve(get_task_family("ghh08"), budget=8, checkpoint=ckpt, **run)
    state = json.loads(ckpt.read_text())
    assert len(state["history"]) == 2
    state["history"][0][4] = 0.05
    ckpt.write_text(json.dumps(state))
    fragment = "history's champion_return column row 0 (from 0) is 0.05: not allowed in a run of 10-step episodes on fitness scale 'inv-log-error'"
    with _raises(fragment) as refused:
        evolve(get_task_family("ghh08"), budget=16, checkpoint=ckpt, resume=True, **run)
    assert "allowed '-inf' or a mean 1/ln(error) in [0.1023617, 1000001]" in str(refused.value)


def test_fitness_range_of_each_scale() -> None:
    from neurohover.evolution.fitness import ERROR_FLOOR, episode_fitness, fitness_range
    from neurohover.sim.constants import lowest_return

    for n in (1, 20, 6000):
        low, high, _ = fitness_range(n, "return")
        assert (low, high) == (lowest_return(n), 0.0)
        low, high, _ = fitness_range(n, "inv-log-error")
        worst, best = episode_fitness([lowest_return(n), 0.0], "inv-log-error")
        assert math.isclose(low, worst) and high == best == 1 / math.log(ERROR_FLOOR)


# --------------------------------------------------------------------------- one crash charge, one seconds bound


def test_the_plain_crash_charge_is_the_kernels() -> None:
    from neurohover.sim import kernel
    from neurohover.sim.constants import CRASH_STEP_PENALTY, crash_charge, crash_penalty, crash_return_ceiling

    for n, t in ((1, 1), (20, 1), (20, 10), (20, 20), (6000, 17), (10**7, 3)):
        assert crash_charge(n, t) == kernel.crash_charge(n, t) == crash_penalty(t, n)
        charge = CRASH_STEP_PENALTY * (n - t)
        assert crash_return_ceiling(n, t) == -charge + 1e-9 * charge  # as compete_files and result_checks wrote it
        assert crash_charge(n, t) <= crash_return_ceiling(n, t) <= 0


@pytest.mark.parametrize("value", [0, 0.0, 1.5, 3155760000.0, 3155760000, -1e-9, 3155760000.1, 1e300, math.inf, math.nan, True, "1", None, 10**400])
def test_one_seconds_predicate_serves_every_reader(value) -> None:
    from neurohover.errors import finite_real
    from neurohover.evolution.state_codec import EntryError, read_seconds
    from neurohover.experiments.result_checks import seconds_problem
    from neurohover.policy_records import seconds_problem as record_seconds_problem
    from neurohover.sim.constants import MAX_SECONDS, seconds_allowed

    allowed = finite_real(value) and 0 <= value <= MAX_SECONDS
    assert seconds_allowed(value) is allowed
    assert (record_seconds_problem({"seconds": value}) == "") is allowed
    try:
        assert read_seconds(value) == float(value) and allowed
    except EntryError:
        assert not allowed
    timing = dataclasses.make_dataclass("Timing", [("seconds", object)])(value)  # a record of one field, as a stored timing
    assert (seconds_problem(timing) == "") is allowed
