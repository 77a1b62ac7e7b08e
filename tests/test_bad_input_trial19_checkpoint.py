"""The nineteenth bad-input trial's findings in evolve checkpoints (T19-01, T19-08): a damaged checkpoint's counters,
history, MDP stream, champion and config are refused by name on resume, instead of a traceback mid-run or a run that
went on from impossible state; sound checkpoints resume as before."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest

from neurohover.errors import NeurohoverError
from neurohover.evolution.evolve import evolve
from neurohover.evolution.generational import GenerationalSettings
from neurohover.flyer import MAX_EPISODE_INDEX, KernelFlyer
from neurohover.policies import prototype
from neurohover.tasks import get_task_family

GHH08 = get_task_family("ghh08")
#: The run behind the tiny_checkpoint fixture (conftest.py): steady state on GHH-08's zero MDP.
MDP_RUN = dict(topology="slp", prototype="baseline", seed=3, n_steps=20)
#: A tiny generational run on the GHH-08 family (it draws MDPs: its checkpoint has an MDP stream).
FAMILY_RUN = dict(topology="slp", prototype="baseline", seed=3, n_steps=10, settings=GenerationalSettings(pop_size=4, select_size=2))
#: A tiny CMA-ES run on the family (its checkpoint has a champion of its own).
CMA_RUN = dict(topology="slp", prototype="baseline", seed=3, n_steps=10, optimizer="cma", settings={"sigma0": 0.1, "popsize": 4})


def _raises(fragment: str):
    return pytest.raises(NeurohoverError, match=re.escape(fragment))


@pytest.fixture(scope="module")
def family_checkpoint(tmp_path_factory) -> Path:
    """A sound checkpoint of two generations of FAMILY_RUN (tests damage a copy)."""
    ckpt = tmp_path_factory.mktemp("family-checkpoint") / "run.ckpt.json"
    evolve(GHH08, budget=8, checkpoint=ckpt, **FAMILY_RUN)
    return ckpt


@pytest.fixture(scope="module")
def cma_checkpoint(tmp_path_factory) -> Path:
    """A sound checkpoint of two generations of CMA_RUN (tests damage a copy)."""
    ckpt = tmp_path_factory.mktemp("cma-checkpoint") / "run.ckpt.json"
    evolve(GHH08, budget=8, checkpoint=ckpt, **CMA_RUN)
    return ckpt


def _resume_damaged(source: Path, tmp_path: Path, edit, target, run: dict, fragment: str) -> None:
    """The checkpoint ``source`` resumes (with its episodes as the budget: it stops at once); damaged by ``edit``, it is
    refused with a message holding ``fragment``."""
    state = json.loads(source.read_text())
    ckpt = tmp_path / "run.ckpt.json"
    ckpt.write_text(json.dumps(state))
    flown = state["counters"]["episodes"]
    assert evolve(target, budget=flown, checkpoint=ckpt, resume=True, **run).episodes == flown  # the sound checkpoint resumes
    edit(state)
    ckpt.write_text(json.dumps(state))
    with _raises(fragment) as refused:
        evolve(target, budget=flown + 8, checkpoint=ckpt, resume=True, **run)
    assert "Error: " not in str(refused.value), refused.value  # said plainly, not "damaged checkpoint: ValueError: ..."


# --------------------------------------------------------------------------- T19-01: next_index past the kernel's indices

BEYOND = "not a count: allowed an integer in 0..2**62 (half the kernel's episode indices 0..2**63-1"


@pytest.mark.parametrize("value", [2**70, 2**63 - 1, 2**62 + 1])
def test_a_next_index_past_the_kernels_episode_indices_is_refused(tiny_checkpoint: Path, family_checkpoint: Path, tmp_path: Path, value: int) -> None:
    """T19-01: a checkpoint's next_index of 2**70 was an OverflowError in the flyer's np.add mid-run (2**63-1 wrapped to
    negative episode indices on a family); now it is refused as damaged, naming the counter and the allowed range."""

    def edit(s):
        s["counters"]["next_index"] = value

    _resume_damaged(tiny_checkpoint, tmp_path, edit, GHH08.zero(), MDP_RUN, f"counter 'next_index' is {value}, {BEYOND}")
    _resume_damaged(family_checkpoint, tmp_path, edit, GHH08, FAMILY_RUN, f"counter 'next_index' is {value}, {BEYOND}")


def test_a_next_index_at_the_limit_still_flies(tiny_checkpoint: Path, tmp_path: Path) -> None:
    """T19-01: the largest next_index allowed (2**62) leaves room for the resumed run's episodes: it flies on."""
    state = json.loads(tiny_checkpoint.read_text())
    state["counters"]["next_index"] = 2**62
    ckpt = tmp_path / "run.ckpt.json"
    ckpt.write_text(json.dumps(state))
    flown = state["counters"]["episodes"]
    result = evolve(GHH08.zero(), budget=flown + 1, checkpoint=ckpt, resume=True, **MDP_RUN)
    assert result.episodes > flown
    assert json.loads(ckpt.read_text())["counters"]["next_index"] == 2**62 + result.episodes - flown


def test_the_flyer_refuses_episode_indices_past_the_last() -> None:
    """T19-01: a flyer whose next index leaves too few indices refuses the call by name (it was an OverflowError, or
    indices wrapped to negative ones); the last index itself can be flown and reserved."""
    flyer = KernelFlyer("slp", 1, 10)
    genome = prototype("slp").genome[None, :]
    rows = GHH08.zero().row()[None, :]
    flyer.next_index = MAX_EPISODE_INDEX
    assert np.isfinite(flyer.fly(genome, rows, None, None, 1)).all() and flyer.next_index == MAX_EPISODE_INDEX + 1
    for start, call in (
        (MAX_EPISODE_INDEX, lambda: flyer.fly(genome, rows, "range", None, 2)),
        (2**70, lambda: flyer.fly(genome, rows, None, None, 1)),
        (MAX_EPISODE_INDEX, lambda: flyer.reserve(2)),
    ):
        flyer.next_index = start
        with _raises(f"episode indices run out: {2 if start == MAX_EPISODE_INDEX else 1} more episodes from index {start:,} pass"):
            call()
        assert flyer.next_index == start
    flyer.next_index = MAX_EPISODE_INDEX
    assert flyer.reserve(1) == MAX_EPISODE_INDEX


# --------------------------------------------------------------------------- T19-08: history, counters, stream, champion, config


def _history_times_3(s):
    s["history"] = s["history"] * 3


@pytest.mark.parametrize(
    ("edit", "fragment"),
    [
        (_history_times_3, "history row 1 (from 0): generation=1 is not allowed (after row 0's generation 1: generations rise row by row)"),
        (lambda s: s["history"][0].__setitem__(0, 0), "history row 0 (from 0): generation=0 is not allowed (generations start at 1)"),
        (lambda s: s["history"][0].__setitem__(0, 2), "history's last row has generation=2, past the checkpoint's generation counter 1"),
        (lambda s: s["history"][0].__setitem__(2, 10**6), "history's last row has episodes=1,000,000, past the checkpoint's episodes counter 50"),
        (lambda s: s["history"][0].__setitem__(3, 51), "history row 0 (from 0): generation_episodes=51 is not allowed (more than its 50 episodes)"),
    ],
)
def test_a_history_out_of_step_with_the_counters_is_refused(tiny_checkpoint: Path, tmp_path: Path, edit, fragment: str) -> None:
    """T19-08: a checkpoint whose history held its one row three times resumed (exit 0) and wrote three identical rows
    for generation 1 to the history CSV; now a history whose generations do not rise, or that runs past the counters,
    is refused as damaged."""
    _resume_damaged(tiny_checkpoint, tmp_path, edit, GHH08.zero(), MDP_RUN, fragment)


@pytest.mark.parametrize(
    ("edit", "fragment"),
    [
        (lambda s: s["history"].pop(), "history has 1 rows for 2 generations: this run records every generation, one row each"),
        (lambda s: s["history"][1].__setitem__(2, 1), "history row 1 (from 0): episodes=1 is not allowed (below row 0's 4)"),
        (lambda s: s["history"][1].__setitem__(1, 1), "history row 1 (from 0): evaluations=1 is not allowed (below row 0's 4)"),
    ],
)
def test_a_generational_history_has_a_row_per_generation(family_checkpoint: Path, tmp_path: Path, edit, fragment: str) -> None:
    """T19-08: a generational run records every generation, so a history with a row fewer than its generations (or
    one whose counts fall) is refused as damaged."""
    _resume_damaged(family_checkpoint, tmp_path, edit, GHH08, FAMILY_RUN, fragment)


@pytest.mark.parametrize(
    ("counter", "value", "fragment"),
    [
        ("flown", 2**70, f"counter 'flown' is 1180591620717411303424, {BEYOND}"),
        ("generation", 2**70, f"counter 'generation' is 1180591620717411303424, {BEYOND}"),
        ("evaluations", 2**70, f"counter 'evaluations' is 1180591620717411303424, {BEYOND}"),
        ("steps", 2**70, "counter 'steps' is 1,180,591,620,717,411,303,424, more than 50 episodes of 20 steps can have"),
        ("steps", 1001, "counter 'steps' is 1,001, more than 50 episodes of 20 steps can have"),
        ("steps", 1.5, "counter 'steps' is 1.5, not a count"),
        ("flown", 49, "counter 'flown' is 49, below the 50 episodes counted (each was flown)"),
        ("next_index", 49, "counter 'next_index' is 49, below the 50 episodes flown (each flew its own index)"),
        ("evaluations", 0, "counter 'evaluations' is 0, below the 1 generations (each evaluates a candidate)"),
    ],
)
def test_counters_out_of_range_or_out_of_step_are_refused(tiny_checkpoint: Path, tmp_path: Path, counter: str, value, fragment: str) -> None:
    """T19-08: counters flown, steps, generation and evaluations of 2**70 were taken (exit 0); now every counter is
    bounded, and counters that no run can have together (fewer flown than counted, more steps than the episodes
    have) are refused as damaged."""

    def edit(s):
        s["counters"][counter] = value

    _resume_damaged(tiny_checkpoint, tmp_path, edit, GHH08.zero(), MDP_RUN, fragment)


@pytest.mark.parametrize(
    ("edit", "fragment"),
    [
        (lambda m: m["state"].update(state=True), "mdp_stream's state.state=True is not allowed: allowed an integer in 0..2**128-1"),
        (lambda m: m["state"].update(state=1.5), "mdp_stream's state.state=1.5 is not allowed"),
        (lambda m: m["state"].update(state=2**128), "mdp_stream's state.state=3402823669...(39 digits) is not allowed"),
        (lambda m: m["state"].update(inc=True), "mdp_stream's state.inc=True is not allowed"),
        (lambda m: m["state"].update(inc=1.5), "mdp_stream's state.inc=1.5 is not allowed"),
        (lambda m: m["state"].update(inc=2**70), "mdp_stream's state.inc=1180591620717411303424 is not allowed: a PCG64 increment is odd"),
        (lambda m: m.update(has_uint32=-1), "mdp_stream's has_uint32=-1 is not allowed: allowed an integer in 0..1"),
        (lambda m: m.update(has_uint32=1.5), "mdp_stream's has_uint32=1.5 is not allowed: allowed an integer in 0..1"),
        (lambda m: m.update(uinteger=2**32), "mdp_stream's uinteger=4294967296 is not allowed: allowed an integer in 0..2**32-1"),
        (lambda m: m.update(bit_generator="MT19937"), "mdp_stream={'bit_generator': 'MT19937'"),
        (lambda m: m.update(extra=1), "is not allowed: allowed a PCG64 state table (bit_generator, state, has_uint32, uinteger)"),
        (lambda m: m.update(state=[1, 2]), "mdp_stream's state=[1, 2] is not allowed: allowed a table of state and inc"),
    ],
)
def test_a_damaged_mdp_stream_is_refused(family_checkpoint: Path, tmp_path: Path, edit, fragment: str) -> None:
    """T19-08: numpy's bit generator took a stream state or inc of True, 1.5 or 2**70 and a has_uint32 of -1 or 1.5,
    and the run went on drawing other MDPs; now each entry of the PCG64 state is checked before it is set. The message
    says it plainly, not "damaged checkpoint: ValueError: mdp_stream's ..."."""
    _resume_damaged(family_checkpoint, tmp_path, lambda s: edit(s["mdp_stream"]), GHH08, FAMILY_RUN, fragment)


def test_a_champion_return_no_run_can_have_is_refused(tiny_checkpoint: Path, cma_checkpoint: Path, tmp_path: Path) -> None:
    """T19-08: a champion return of 2**70 was taken; a return is minus a sum of squares (<= 0), and a run without a
    champion genome has none (-inf), so either is refused as damaged (its message no longer starts "ValueError: ")."""

    def edit(value):
        return lambda s: s["champion"].update(**{"return": value})

    fragment = "damaged checkpoint: the champion's return is 1180591620717411303424 without a champion genome"
    _resume_damaged(tiny_checkpoint, tmp_path, edit(2**70), GHH08.zero(), MDP_RUN, fragment)
    assert json.loads(cma_checkpoint.read_text())["champion"]["genome"] is not None
    for value in (2**70, 1e-300, "inf"):
        allowed = "'-inf' or a mean return in [-17488.07999, 0] (the worst step, for each of its 10 steps, to none)"  # T27-B03: its n_steps
        fragment = f"damaged checkpoint: the champion's return is {value!r}: allowed {allowed} on the run's fitness scale 'return'"
        _resume_damaged(cma_checkpoint, tmp_path, edit(value), GHH08, CMA_RUN, fragment)


@pytest.mark.parametrize(
    ("edit", "fragment"),
    [
        (lambda c: c["settings"].update(crossover_prob=True), "written by a different run (settings.crossover_prob: the checkpoint's True, given 1.0)"),
        (lambda c: c["settings"].update(elitist=0), "written by a different run (settings.elitist: the checkpoint's 0, given False)"),
        (lambda c: c["prototype"].__setitem__(0, False), "written by a different run (prototype: the checkpoint's [False, "),
    ],
)
def test_a_bool_in_the_config_is_no_number(family_checkpoint: Path, tmp_path: Path, edit, fragment: str) -> None:
    """T19-08: a generational checkpoint whose crossover_prob was true resumed as the run of crossover_prob 1.0 (True == 1
    in Python); the stored config is now compared with the run's type-strictly: a bool is no number."""
    _resume_damaged(family_checkpoint, tmp_path, lambda s: edit(s["config"]), GHH08, FAMILY_RUN, fragment)


def test_a_number_written_as_an_integer_is_the_same_setting(family_checkpoint: Path, tmp_path: Path) -> None:
    """T19-08's strict comparison still takes 1 for 1.0 (a number is a number): the checkpoint resumes."""
    state = json.loads(family_checkpoint.read_text())
    assert state["config"]["settings"]["crossover_prob"] == 1.0
    state["config"]["settings"]["crossover_prob"] = 1
    ckpt = tmp_path / "run.ckpt.json"
    ckpt.write_text(json.dumps(state))
    flown = state["counters"]["episodes"]
    assert evolve(GHH08, budget=flown, checkpoint=ckpt, resume=True, **FAMILY_RUN).episodes == flown


@pytest.mark.parametrize("which", ["steady state", "generational"])
def test_an_optimiser_state_whose_settings_are_not_the_configs_is_refused(which: str, tiny_checkpoint: Path, family_checkpoint: Path, tmp_path: Path) -> None:
    """T19-08 follow-up: resume compared the checkpoint's config with the run's, but the optimiser state carries its own
    copy of the settings, and that copy was flown (crossover_prob 0.9 in it, the default in the config, resumed without a word)."""
    source, target, run = (tiny_checkpoint, GHH08.zero(), MDP_RUN) if which == "steady state" else (family_checkpoint, GHH08, FAMILY_RUN)

    def edit(state: dict) -> None:
        state["optimizer_state"]["settings"]["crossover_prob"] = 0.9

    given = 0.5 if which == "steady state" else 1.0  # each method's default
    _resume_damaged(source, tmp_path, edit, target, run, f"optimizer_state.settings.crossover_prob: the checkpoint's 0.9, given {given}")


# --------------------------------------------------------------------------- T20-01: a NaN champion return in the history


@pytest.mark.parametrize("value", ["nan", "inf"])
def test_a_history_row_with_a_champion_return_no_run_records_is_refused(tiny_checkpoint: Path, family_checkpoint: Path, tmp_path: Path, value: str) -> None:
    """T20-01: a history row's champion return of 'nan' was resumed and written to history.csv as nan; a run records a
    finite return or '-inf' (no champion yet), and anything else is now refused as damage, naming the row."""

    def edit(s):
        s["history"][0][4] = value

    fragment = f"is a damaged checkpoint: history row 0 (from 0): champion_return='{value}' is not allowed ('{value}' is no champion's return"
    _resume_damaged(tiny_checkpoint, tmp_path, edit, GHH08.zero(), MDP_RUN, fragment)
    _resume_damaged(family_checkpoint, tmp_path, edit, GHH08, FAMILY_RUN, fragment)


# --------------------------------------------------------------------------- T20-02: a race delta the resampling has not

#: Tiny generational runs on the family that race their candidates: at a fixed delta and at race:auto's.
RACE_RUN = {**FAMILY_RUN, "resampling": "race:0.1"}
AUTO_RUN = {**FAMILY_RUN, "resampling": "race:auto"}


@pytest.fixture(scope="module")
def race_checkpoints(tmp_path_factory) -> dict[str, Path]:
    """Sound checkpoints of RACE_RUN and AUTO_RUN (tests damage copies)."""
    out = {}
    for name, run in (("race", RACE_RUN), ("auto", AUTO_RUN)):
        out[name] = tmp_path_factory.mktemp(f"{name}-checkpoint") / "run.ckpt.json"
        evolve(GHH08, budget=8, checkpoint=out[name], **run)
    return out


@pytest.mark.parametrize(
    "which, value, fragment",
    [
        ("steady", 0.5, "race_delta is 0.5: allowed null (fixed resampling races no candidates)"),
        ("fixed", 0.5, "race_delta is 0.5: allowed null (fixed resampling races no candidates)"),
        ("race", 0.5, "race_delta is 0.5: allowed 0.1, the delta of race:0.1"),
        ("race", None, "race_delta is None: allowed 0.1, the delta of race:0.1"),
        ("auto", 1.5, "race_delta is 1.5: allowed a confidence level in (0, 1) (race:auto sets one race by race)"),
        ("auto", None, "race_delta is None: allowed a confidence level in (0, 1)"),
    ],
)
def test_a_race_delta_the_resampling_does_not_have_is_refused(
    which: str, value, fragment: str, tiny_checkpoint: Path, family_checkpoint: Path, race_checkpoints: dict[str, Path], tmp_path: Path
) -> None:
    """T20-02: a race_delta of 0.5 in a fixed:1 run's checkpoint was taken and written back beside fixed:1; only a race
    has a delta, a fixed race exactly its own, race:auto one in (0, 1) (the sound ones still resume)."""
    source, target, run = {
        "steady": (tiny_checkpoint, GHH08.zero(), MDP_RUN),
        "fixed": (family_checkpoint, GHH08, FAMILY_RUN),
        "race": (race_checkpoints["race"], GHH08, RACE_RUN),
        "auto": (race_checkpoints["auto"], GHH08, AUTO_RUN),
    }[which]

    def edit(s):
        s["race_delta"] = value

    _resume_damaged(source, tmp_path, edit, target, run, f"is a damaged checkpoint: {fragment}")


# --------------------------------------------------------------------------- T20-03: an optimiser state asked and not told


def _steady_pending(s):
    """The steady-state optimiser's pending batch: the population's first rows, as many as a generation breeds."""
    opt = s["optimizer_state"]
    (n, d), rows = opt["population"]["shape"], opt["settings"]["pop_size"] - opt["settings"]["elite_size"]
    opt["pending"] = {"shape": [rows, d], "data": opt["population"]["data"][: rows * d]}
    assert n >= rows


@pytest.mark.parametrize("which", ["generational", "steady state"])
def test_an_optimiser_state_asked_and_not_told_is_a_damaged_checkpoint(which: str, tiny_checkpoint: Path, family_checkpoint: Path, tmp_path: Path) -> None:
    """T20-03: a checkpoint whose optimiser state was asked and not told (asked=true) failed with the API's "ask() called
    again before tell()", naming no checkpoint; a run checkpoints between generations, so it is now refused as damage."""
    if which == "generational":
        _resume_damaged(
            family_checkpoint,
            tmp_path,
            lambda s: s["optimizer_state"].update(asked=True),
            GHH08,
            FAMILY_RUN,
            "is a damaged checkpoint: optimizer_state's asked=true is not allowed: a run's checkpoint is written between generations (allowed false)",
        )
    else:
        _resume_damaged(
            tiny_checkpoint,
            tmp_path,
            _steady_pending,
            GHH08.zero(),
            MDP_RUN,
            "is a damaged checkpoint: optimizer_state's pending batch is not allowed: a run's checkpoint is written between generations (allowed null)",
        )
