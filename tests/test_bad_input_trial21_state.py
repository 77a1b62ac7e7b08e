"""Bad input of the twenty-first trial: the ask/tell optimisers' TellInfo and saved states (T21-10, T21-11, T21-13)."""

from __future__ import annotations

import copy
import re

import numpy as np
import pytest

from neurohover.errors import NeurohoverError
from neurohover.evolution.common import TellInfo
from neurohover.evolution.generational import GenerationalNE, GenerationalSettings
from neurohover.evolution.optimisers import OPTIMISERS
from neurohover.evolution.steady_state import SteadyStateNE, SteadyStateSettings


def _asked(name: str):
    """An optimiser of 4 genomes a generation whose batch is asked (one of ``generational``, ``steady``, ``openai-es``)."""
    if name == "generational":
        opt = GenerationalNE(np.zeros(3), GenerationalSettings(pop_size=4, select_size=2))
    elif name == "steady":
        opt = SteadyStateNE(np.zeros(3), SteadyStateSettings(pop_size=4, elite_size=3))
    else:
        spec = OPTIMISERS[name]
        opt = spec.make(np.zeros(3), spec.settings(popsize=4), 0)
    assert len(opt.ask()) == 4
    return opt


@pytest.mark.parametrize("name", ["generational", "steady", "openai-es"])
@pytest.mark.parametrize(
    ("info", "message"),
    [
        (TellInfo(crashed=np.array([True])), "TellInfo crashed must be 4 booleans, one per asked genome; got 1 flag: array([ True])"),
        (TellInfo(crashed=[False] * 5), "TellInfo crashed must be 4 booleans, one per asked genome; got 5 flags: [False, False"),
        (TellInfo(crashed=np.ones((4, 1), bool)), "TellInfo crashed must be 4 booleans, one per asked genome; got shape (4, 1)"),
        (TellInfo(crashed=np.array([5, 0, 0, 0])), "TellInfo crashed must be 4 booleans, one per asked genome; got int64 values: array([5, 0, 0, 0])"),
        (
            TellInfo(selected=np.array([-1, 0])),
            "TellInfo selected must be distinct integer indices in 0..3 of the 4 asked genomes (1 to 4 of them); got index -1",
        ),
        (
            TellInfo(selected=np.array([0, 4])),
            "TellInfo selected must be distinct integer indices in 0..3 of the 4 asked genomes (1 to 4 of them); got index 4",
        ),
        (
            TellInfo(selected=[0, 1, 2, 3, 0]),
            "TellInfo selected must be distinct integer indices in 0..3 of the 4 asked genomes (1 to 4 of them); got 5 indices",
        ),
        (
            TellInfo(selected=np.array([2, 2])),
            "TellInfo selected must be distinct integer indices in 0..3 of the 4 asked genomes (1 to 4 of them); got index 2 twice",
        ),
        (
            TellInfo(selected=np.array([0.0, 1.0])),
            "TellInfo selected must be distinct integer indices in 0..3 of the 4 asked genomes (1 to 4 of them); got float64 values",
        ),
    ],
)
def test_a_tell_info_that_does_not_fit_the_asked_batch_is_refused_by_name(name: str, info: TellInfo, message: str) -> None:
    """T21-10: crash flags of the wrong length and selected indices out of range were taken by the tell() of each
    optimiser that does not read them (and integer flags of 5 by steady state's); every tell now checks both fields
    against the genomes asked, in TellInfo.check, and the refused tell leaves the batch pending."""
    opt = _asked(name)
    with pytest.raises(NeurohoverError, match=re.escape(message)):
        opt.tell(-np.arange(1.0, 5.0), info)
    opt.tell(-np.arange(1.0, 5.0), TellInfo(crashed=np.array([True, False, False, True]), selected=[1, 0]))


def test_a_generational_tell_names_a_selection_of_another_size() -> None:
    """T21-10: the generational optimiser's own check (select_size indices) names the size given."""
    opt = _asked("generational")
    with pytest.raises(NeurohoverError, match=re.escape("selected must be 2 (select_size) distinct integer indices in 0..3; got 3: array([0, 1, 2])")):
        opt.tell(-np.arange(1.0, 5.0), selected=np.array([0, 1, 2]))


def _generational_state() -> dict:
    """The state of a GenerationalNE (4 genomes of 3 genes, 2 parents) after two generations."""
    opt = GenerationalNE(np.zeros(3), GenerationalSettings(pop_size=4, select_size=2))
    for k in range(2):
        opt.ask()
        opt.tell(-np.arange(1.0, 5.0) - k)
    return opt.state_dict()


def _steady_state() -> dict:
    """The state of a SteadyStateNE (4 genomes of 3 genes) after its first generation."""
    opt = SteadyStateNE(np.zeros(3), SteadyStateSettings(pop_size=4, elite_size=3))
    opt.ask()
    opt.tell(-np.arange(1.0, 5.0))
    return opt.state_dict()


@pytest.mark.parametrize(
    ("make", "damage", "message"),
    [
        (
            _generational_state,
            lambda s: s["population"]["data"].__setitem__(7, "nan"),
            "population holds a gene that is not a finite number: data entry 7 (genome 2, gene 1) is nan",
        ),
        (
            _generational_state,
            lambda s: s["population"]["data"].__setitem__(2, float("inf")),
            "population holds a gene that is not a finite number: data entry 2 (genome 0, gene 2) is inf",
        ),
        (
            _generational_state,
            lambda s: s["champion_genome"]["data"].__setitem__(1, "-inf"),
            "champion genome holds a gene that is not a finite number: gene 1 is -inf",
        ),
        (
            _generational_state,
            lambda s: s["population"]["data"].__setitem__(5, "NaN"),
            "population data entry='NaN' is not allowed: give real numbers or 'nan', 'inf', '-inf' as state_dict() wrote them (real numbers, not text);"
            " it is data entry 5 of 12",
        ),
        (
            _generational_state,
            lambda s: s["parents"]["data"].__setitem__(4, None),
            "parents data entry=None is not allowed: give real numbers or 'nan', 'inf', '-inf' as state_dict() wrote them"
            " (real numbers, not Python objects); it is data entry 4 of 6",
        ),
        (
            _steady_state,
            lambda s: s["tracker"]["genome"]["data"].__setitem__(2, "nan"),
            "tracker genome holds a gene that is not a finite number: gene 2 is nan",
        ),
        (
            _steady_state,
            lambda s: s["population"]["data"].__setitem__(slice(3, 5), ["inf", "nan"]),
            "population holds a gene that is not a finite number: data entry 3 (genome 1, gene 0) is inf, and 1 more",
        ),
    ],
)
def test_a_state_gene_that_is_no_finite_number_is_named_by_its_place_and_value(make, damage, message: str) -> None:
    """T21-13: a genome of a state holding 'nan', 'inf' or a JSON NaN was refused as "holds a gene that is not a finite
    number" without saying which of its genes; now the message names the data entry (genome and gene) and its value,
    and a data entry that is no number at all ('NaN', None) names its place among the data too."""
    state = make()
    damage(state)
    cls = GenerationalNE if state["type"] == "GenerationalNE" else SteadyStateNE
    with pytest.raises(NeurohoverError, match=re.escape(message)):
        cls.from_state_dict(state)


@pytest.mark.parametrize(
    ("damage", "message"),
    [
        (
            lambda s: s.update(hall_of_fame=[]),
            "GenerationalNE state dict's hall_of_fame is [] at generation=2 beside its parents and a champion (return -2.0): every tell() keeps both",
        ),
        (
            lambda s: s.update(parents=None),
            "GenerationalNE state dict's parents are null at generation=2 beside its hall_of_fame and a champion (return -2.0): every tell() keeps both",
        ),
        (
            lambda s: s.update(hall_of_fame=s["hall_of_fame"][:1]),
            "hall_of_fame returns [-1.0] leave out its champion's return -2.0: every generation's champion enters the hall, unless select_size (2)",
        ),
        (
            lambda s: s["parents"]["data"].__setitem__(0, s["parents"]["data"][0] + 1.0) or s["parents"]["data"].__setitem__(3, s["parents"]["data"][3] + 1.0),
            "GenerationalNE state dict's champion genome is none of its 2 parents: the champion is its generation's best parent",
        ),
    ],
)
def test_a_generational_states_champion_parents_and_hall_of_fame_must_agree(damage, message: str) -> None:
    """T21-11: a GenerationalNE state past its first generation with "hall_of_fame": [] beside its champion was taken
    (and so were null parents, a hall of fame without the last champion and a champion none of the parents); now the
    champion must be one of the parents and in the hall (unless select_size better ones are), as tell() keeps them."""
    state = _generational_state()
    GenerationalNE.from_state_dict(copy.deepcopy(state))  # the sound state loads
    damage(state)
    with pytest.raises(NeurohoverError, match=re.escape(message)):
        GenerationalNE.from_state_dict(state)


def test_a_generational_state_without_parents_and_hall_of_fame_still_loads() -> None:
    """T21-11: a checkpoint of before 2026-12-04 has neither, and one saved after resuming it before a generation was
    told holds them as null and []: both still load, and the next tell() fills them in."""
    state = _generational_state()
    del state["parents"], state["hall_of_fame"]
    resumed = GenerationalNE.from_state_dict(state)
    again = GenerationalNE.from_state_dict(resumed.state_dict())
    assert (again.parents, again.hall_of_fame) == (None, None)
    again.ask()
    again.tell(-np.arange(1.0, 5.0))
    assert GenerationalNE.from_state_dict(again.state_dict()).hall_of_fame.shape == (1, 3)
