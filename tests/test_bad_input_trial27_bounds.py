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


# --------------------------------------------------------------------------- T27-B03: a stored evolve unit


def _stored_evolve_unit(store: Path, fitness: str | None, n_steps: int) -> tuple[str, dict, dict]:
    """The key, result and params of the committed store's first evolve unit on ``fitness`` with ``n_steps``-step episodes
    and validation episodes."""
    import sqlite3

    with sqlite3.connect(store) as conn:
        rows = conn.execute("SELECT key, params, result FROM units WHERE kind = 'evolve'").fetchall()
    conn.close()
    for key, params, result in rows:
        p, r = json.loads(params), json.loads(result)
        if p.get("n_steps") == n_steps and r.get("fitness") == fitness and r.get("validation"):
            return key, r, p
    raise AssertionError(f"no evolve unit on {fitness} with {n_steps} steps")


@pytest.mark.parametrize(
    ("fitness", "edit", "says"),
    [
        (
            "return",
            {"champion": -1e9},
            "champion_return = -1000000000.0 is not allowed: its unit's episodes are 200 control steps long: allowed a mean return in [-349761.5997, 0]",
        ),
        (None, {"champion": -349762.0}, "champion_return = -349762.0 is not allowed: its unit's episodes are 200 control steps long"),
        (
            "inv-log-error",
            {"champion": 0.05},
            "champion_return = 0.05 is not allowed: its unit's episodes are 200 control steps long: allowed a mean 1/ln(error) in [0.07833917, 1000001]",
        ),
        (
            "return",
            {"validation": -1e9},
            "validation[0] = -1000000000.0 is not allowed: its unit's episodes are 200 control steps long: allowed at least -349761.5997",
        ),
    ],
    ids=["return", "raw", "inv-log-error", "validation"],
)
def test_a_stored_evolve_unit_beyond_its_own_episode_length_is_refused(committed_store: Path, fitness, edit: dict, says: str) -> None:
    from neurohover.experiments.result_checks import params_problem
    from neurohover.experiments.results import result_from_dict

    key, result, params = _stored_evolve_unit(committed_store, fitness, 200)
    assert params_problem(result_from_dict("evolve", result, key), params) == ""
    if "champion" in edit:  # the champion's fitness is its history's last (the run's other checks), so both move
        result["champion_return"] = result["history"][-1][1] = edit["champion"]
    else:
        result["validation"][0] = edit["validation"]
    assert params_problem(result_from_dict("evolve", result, key), params).startswith(says)


# --------------------------------------------------------------------------- T27-B10: EpisodeOutcome's steps, Evaluation's returns


@pytest.mark.parametrize(("steps", "says"), [(0, "steps=0 is out of range"), (10**7 + 1, "steps=10000001 is out of range")])
def test_an_episode_outcome_of_no_steps_or_past_the_longest_episode_is_refused(steps: int, says: str) -> None:
    from neurohover.agents.protocol import EpisodeOutcome

    with _raises(f"EpisodeOutcome {says}: allowed an integer in 1..10000000"):
        EpisodeOutcome(episode=0, ret=0.0, crashed=True, steps=steps, safeguard_step=-1, flight_data=None)
    assert EpisodeOutcome(episode=0, ret=-1.0, crashed=False, steps=10**7, safeguard_step=-1, flight_data=None).steps == 10**7


@pytest.mark.parametrize(
    ("ret", "crashed", "says"),
    [
        (5.0, False, "Evaluation returns holds 5.0 for a 20-step episode that did not crash: allowed -34976.15997..0"),
        (-1e9, False, "Evaluation returns holds -1000000000.0 for a 20-step episode that did not crash: allowed -34976.15997..0"),
        (-1e30, True, "Evaluation returns holds -1e+30 for an episode that crashed: allowed -1.748807999e+10..0"),
        (-math.inf, True, "Evaluation returns holds -inf for an episode that crashed"),
        (math.inf, False, "Evaluation returns holds inf for a 20-step episode"),
    ],
)
def test_an_evaluation_of_returns_no_episode_can_have_is_refused(ret: float, crashed: bool, says: str) -> None:
    import numpy as np

    from neurohover.evaluate import Evaluation

    def made(value: float, flag: bool) -> Evaluation:
        returns = np.array([[-3.0, value]])
        return Evaluation(returns, np.array([[False, flag]]), np.array([[20, 20]]), np.full((1, 2), -1), None, 0.0)

    assert made(-34976.0, False).returns[0, 1] == -34976.0 and made(-1e9, True).crashed[0, 1]  # a crash: up to -WORST_RETURN
    assert np.isnan(made(math.nan, True).returns[0, 1])  # a blow-up is not judged here (T27-B06)
    with _raises(says):
        made(ret, crashed)


def test_every_evaluate_return_passes() -> None:
    import neurohover as nh

    family = get_task_family("ghh08")
    ev = nh.evaluate("baseline", [family.zero(), family.make([4.9, -3.0])], episodes=3, n_steps=30)
    assert ev.returns.size == 6 and (ev.returns <= 0).all()
