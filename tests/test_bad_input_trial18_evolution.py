"""The eighteenth bad-input trial's findings in the evolution package (T18-5, T18-6): each bad input gives one clear
NeurohoverError naming the value and what is allowed, instead of a silent wrong answer or a message naming nothing;
valid input runs as before."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest

from neurohover.errors import NeurohoverError
from neurohover.evolution.evolve import evolve
from neurohover.evolution.optimisers.cma import CMAES
from neurohover.evolution.optimisers.uh_cma import UHCMAES, UHCMASettings
from neurohover.policies import prototype
from neurohover.tasks import get_task_family

GHH08 = get_task_family("ghh08")


def _raises(fragment: str):
    return pytest.raises(NeurohoverError, match=re.escape(fragment))


# --------------------------------------------------------------------------- T18-5: CMAES state's type


def _cma_state() -> dict:
    opt = CMAES(prototype("slp").genome, popsize=4)
    opt.ask()
    opt.tell(np.zeros(4))
    return opt.state_dict()


@pytest.mark.parametrize(
    ("edit", "fragment"),
    [
        (lambda s: s.update(type="SteadyStateNE"), "state dict is for 'SteadyStateNE', not 'CMAES'"),
        (lambda s: s.update(type=None), "state dict is for None, not 'CMAES'"),
        (lambda s: s.update(type=True), "state dict is for True, not 'CMAES'"),
        (lambda s: s.update(type=[1]), "state dict is for [1], not 'CMAES'"),
        (lambda s: s.update(type=2**64), "state dict is for 18446744073709551616, not 'CMAES'"),
        (lambda s: s.pop("type"), "state dict is for None, not 'CMAES'"),
        (lambda s: s.update(version=2), "unsupported state version 2: allowed 1"),
        (lambda s: s.update(version=True), "unsupported state version True: allowed 1"),
    ],
)
def test_a_cmaes_state_of_another_type_is_refused(edit, fragment: str) -> None:
    """T18-5: CMAES.from_state_dict checked only for unknown entries, so a state whose type was 'SteadyStateNE', None,
    True, [1], 2**64 or missing was taken; now its type (and version) is checked as the other optimisers' are."""
    state = _cma_state()
    assert CMAES.from_state_dict(state).popsize == 4  # the sound state loads
    legacy = {k: v for k, v in state.items() if k != "version"}  # one written before the version entry still loads
    assert isinstance(CMAES.from_state_dict(legacy), CMAES)
    edit(state)
    with _raises(fragment):
        CMAES.from_state_dict(state)


def test_a_uhcmaes_state_keeps_its_type() -> None:
    """T18-5: a UHCMAES state said 'CMAES'; it now says 'UHCMAES' and loads (an older one saying 'CMAES' too), and a
    plain CMAES refuses it by its type."""
    opt = UHCMAES(prototype("slp").genome, UHCMASettings(popsize=4))
    state = opt.state_dict()
    assert state["type"] == "UHCMAES"
    assert isinstance(UHCMAES.from_state_dict(state), UHCMAES)
    assert isinstance(UHCMAES.from_state_dict({**state, "type": "CMAES"}), UHCMAES)
    with _raises("state dict is for 'UHCMAES', not 'CMAES'"):
        CMAES.from_state_dict(state)


# --------------------------------------------------------------------------- T18-6: damaged history rows


@pytest.mark.parametrize(
    ("edit", "fragment"),
    [
        (lambda h: h[0].append(0), "history row 0 (from 0) is [1, "),
        (lambda h: h[0].pop(), "allowed a list of 6 values, generation, evaluations, episodes, generation_episodes, champion_return"),
        (lambda h: h.__setitem__(0, ["a"] * 6), "history row 0 (from 0): generation='a' is not allowed (not a count: allowed an integer >= 0)"),
        (lambda h: h[0].__setitem__(4, "x"), "history row 0 (from 0): champion_return='x' is not allowed (could not convert"),
        (lambda h: h[0].__setitem__(5, -1.0), "history row 0 (from 0): wall_seconds=-1.0 is not allowed (not a number of seconds"),
        (lambda h: h.__setitem__(0, {"a": 1}), "history row 0 (from 0) is {'a': 1}: allowed a list of 6 values"),
    ],
)
def test_a_damaged_history_row_is_named(tiny_checkpoint: Path, tmp_path: Path, edit, fragment: str) -> None:
    """T18-6: a history row of seven values said only 'ValueError: too many values to unpack (expected 6)', and one of
    'a's only 'not a count': neither named the history table, the row or the value; now each does."""
    common = dict(topology="slp", prototype="baseline", seed=3, n_steps=20)
    state = json.loads(tiny_checkpoint.read_text())
    assert state["history"]
    ckpt = tmp_path / "run.ckpt.json"
    ckpt.write_text(json.dumps(state))
    flown = state["counters"]["episodes"]  # resumed with it as the budget, the run stops at once
    assert evolve(GHH08.zero(), budget=flown, checkpoint=ckpt, resume=True, **common).episodes == flown  # the sound checkpoint resumes
    edit(state["history"])
    ckpt.write_text(json.dumps(state))
    with _raises(fragment):
        evolve(GHH08.zero(), budget=flown, checkpoint=ckpt, resume=True, **common)
    with _raises("is a damaged checkpoint: history row 0"):
        evolve(GHH08.zero(), budget=flown, checkpoint=ckpt, resume=True, **common)
