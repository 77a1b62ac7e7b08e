"""The nineteenth bad-input trial's findings in the optimisers' state dicts (T19-02, T19-03, T19-08, T19-09, T19-10):
a damaged entry of a GenerationalNE, SteadyStateNE, OpenAIES or CMA-ES state is refused on loading by a
NeurohoverError naming it, instead of a traceback at the first ask()/tell() or a run that went on from an impossible
state; a generation's episodes are bounded; sound states load and continue as before."""

from __future__ import annotations

import copy
import json
import re
from pathlib import Path

import numpy as np
import pytest

from neurohover.errors import NeurohoverError
from neurohover.evolution import common
from neurohover.evolution.common import TellInfo
from neurohover.evolution.config import MAX_BUDGET
from neurohover.evolution.evolve import evolve
from neurohover.evolution.generational import GenerationalNE, GenerationalSettings
from neurohover.evolution.optimisers.cma import CMAES
from neurohover.evolution.optimisers.openai_es import OpenAIES, OpenAIESSettings
from neurohover.evolution.optimisers.uh_cma import UHCMAES, UHCMASettings
from neurohover.evolution.steady_state import SteadyStateNE, SteadyStateSettings
from neurohover.tasks import get_task_family

GHH08 = get_task_family("ghh08")
NAN_GENES = {"shape": [4], "data": ["nan", 0.0, 0.0, 0.0]}


def _raises(fragment: str):
    return pytest.raises(NeurohoverError, match=re.escape(fragment))


def _generational() -> dict:
    """Two generations of a tiny GenerationalNE: champions -1.0, then -2.0 (select_size 2, so both in the hall)."""
    opt = GenerationalNE(np.zeros(4), GenerationalSettings(pop_size=6, select_size=2, generations=5), seed=1)
    for k in range(2):
        opt.ask()
        opt.tell(-np.arange(6.0) - 1.0 - k)
    return opt.state_dict()


def _steady_state(elite: int = 4) -> dict:
    """Three generations of a tiny SteadyStateNE, its best return -0.5 told in the first."""
    opt = SteadyStateNE(np.zeros(4), SteadyStateSettings(pop_size=6, elite_size=elite), seed=1)
    for k in range(3):
        n = len(opt.ask())
        opt.tell(-np.arange(n, dtype=float) - 1.0 + (0.5 if k == 0 else 0.0))
    return opt.state_dict()


def _openai_es() -> dict:
    """Two generations of a tiny OpenAIES (popsize 4)."""
    opt = OpenAIES(np.zeros(4), OpenAIESSettings(popsize=4), seed=1)
    for _ in range(2):
        opt.ask()
        opt.tell(-np.arange(4.0) - 1.0)
    return opt.state_dict()


def _check_refused(cls, make, edit, fragment: str) -> None:
    state = make()
    restored = cls.from_state_dict(copy.deepcopy(state))  # the sound state loads and goes on
    batch = restored.ask()
    restored.tell(-np.arange(len(batch), dtype=float) - 3.0)
    edit(state)
    with _raises(fragment):
        cls.from_state_dict(state)


# --------------------------------------------------------------------------- T19-02: GenerationalNE's entries


@pytest.mark.parametrize(
    ("edit", "fragment"),
    [
        (lambda s: s.update(population=None), "'population' entry None is damaged (no population"),
        (lambda s: s.update(population="x"), "'population' entry 'x' is damaged"),
        (lambda s: s.update(population=NAN_GENES), "population has shape (4,), expected (n, 4)"),
        (lambda s: s["population"]["data"].__setitem__(0, "nan"), "population holds a gene that is not a finite number"),
        (lambda s: s.update(champion_genome=None), "champion (return -2.0, genome none) is not its last generation's"),
        (lambda s: s.update(champion_genome=NAN_GENES), "champion genome holds a gene that is not a finite number"),
        (lambda s: s["hall_of_fame"][0].__setitem__(1, None), "'hall_of_fame' entry"),
        (lambda s: s["hall_of_fame"][0].__setitem__(1, NAN_GENES), "hall of fame genome holds a gene that is not a finite number"),
        (lambda s: s.update(parents=NAN_GENES), "parents has shape (4,), expected (n, 4)"),
        (lambda s: s.update(asked="true"), "'asked' entry 'true' is damaged (not a flag"),
        (lambda s: s.update(rng=None), "rng=None is not allowed: allowed a PCG64 state table"),
    ],
)
def test_a_generational_states_entries_are_checked_on_loading(edit, fragment: str) -> None:
    """T19-02: a GenerationalNE state whose population was None loaded, and its first ask() was an AttributeError
    ('NoneType' has no attribute 'copy'); now every entry is read back strictly: None, text, a wrong shape or a NaN gene
    is refused by name."""
    _check_refused(GenerationalNE, _generational, edit, fragment)


# --------------------------------------------------------------------------- T19-09: GenerationalNE's progress


@pytest.mark.parametrize(
    ("edit", "fragment"),
    [
        (lambda s: s.update(history={}), "'history' entry {} is damaged (a table, not a list"),
        (lambda s: s.update(history=s["history"][:1]), "has 1 history rows for generation=2: one row per generation"),
        (lambda s: s.update(history=[]), "has 0 history rows for generation=2"),
        (lambda s: s.update(generation=3), "has 2 history rows for generation=3"),
        (lambda s: s.update(generation=2**70), "'generation' entry 1180591620717411303424 is damaged (a count past"),
        (lambda s: s.update(evaluations=13), "has evaluations=13 where its history's episodes add up to 12"),
        (lambda s: s["history"][1].__setitem__(0, 5), "history row 2 says generation 5, evaluations 12: expected generation 2"),
        (lambda s: s["history"][1].__setitem__(2, 10**11), "episodes=100000000000 is more than a generation may cost (10,000,000,000)"),
        (lambda s: s["history"][1].__setitem__(2, 10**30), "a count past 9223372036854775807"),
        (lambda s: s["history"][1].__setitem__(3, "nan"), "'nan' is no champion's return: allowed a finite number or '-inf'"),
        (lambda s: s.update(hall_of_fame=s["hall_of_fame"] * 3), "hall_of_fame returns [-1.0, -2.0, -1.0, -2.0, -1.0, -2.0] are not allowed"),
        (lambda s: s["hall_of_fame"].reverse(), "hall_of_fame returns [-2.0, -1.0] are not allowed"),
        (lambda s: s["hall_of_fame"][0].__setitem__(0, -0.5), "hall_of_fame returns [-0.5, -2.0] are not allowed"),
        (lambda s: s["hall_of_fame"][0].__setitem__(0, "nan"), "'nan' is no champion's return"),
        (lambda s: s["hall_of_fame"][0].__setitem__(0, float("nan")), "nan is no champion's return"),
        (lambda s: s.update(hall_of_fame={}), "'hall_of_fame' entry {} is damaged (a table, not a list"),
        (lambda s: s.update(champion_return="nan"), "'champion_return' entry 'nan' is damaged ('nan' is no champion's return"),
        (lambda s: s.update(champion_return=-1.0), "champion (return -1.0, genome given) is not its last generation's: return -2.0"),
        (lambda s: s.update(wall_seconds=1e308), "'wall_seconds' entry 1e+308 is damaged (more seconds than 100 years"),
        (lambda s: s["history"][0].__setitem__(4, 1e308), "more seconds than 100 years"),
        (lambda s: s.update(settings={}), "settings lack pop_size, select_size, generations"),
    ],
)
def test_a_generational_states_history_counts_and_champions_must_agree(edit, fragment: str) -> None:
    """T19-09 (and T19-08's generation of 2**70): GenerationalNE.from_state_dict took a history of {} or of fewer rows
    than its generations, a hall of fame longer than select_size, 'nan' returns and 1e308 seconds; a run resumed from
    generation 2**70 stopped at once 'by generations'. Now the history, counts, champion and hall of fame must agree as
    tell() makes them."""
    _check_refused(GenerationalNE, _generational, edit, fragment)


def test_a_generational_state_from_before_the_hall_of_fame_still_loads() -> None:
    """Checkpoints written before 2026-12-04 have no parents and no hall of fame: they still load (the checks above
    allow their absence), and one resumed from them saves an empty hall beside its generations, which loads too."""
    state = _generational()
    del state["parents"], state["hall_of_fame"]
    opt = GenerationalNE.from_state_dict(state)
    again = GenerationalNE.from_state_dict(opt.state_dict())
    assert again.generation == 2 and again.hall_of_fame is None


# --------------------------------------------------------------------------- T19-09, T19-08: SteadyStateNE


def _set_history_return(value):
    return lambda s: s["tracker"]["history"][0].__setitem__(1, value)


@pytest.mark.parametrize(
    ("edit", "fragment"),
    [
        (_set_history_return(float("nan")), "history record [1, nan, ...] is not allowed"),
        (_set_history_return("nan"), "history record [1, nan, ...] is not allowed"),
        (_set_history_return("-inf"), "history record [1, -inf, ...] is not allowed"),
        (_set_history_return(-1.0), "the last history record [1, -1.0, ...] is not the champion's: best=-0.5"),
        (lambda s: s["tracker"]["history"][0].__setitem__(0, 99), "history record [99, -0.5, ...] is not allowed"),
        (lambda s: s["tracker"]["history"].append([2, -0.75, 0.0]), "history record [2, -0.75, ...] is not allowed"),
        (lambda s: s["tracker"].update(history={}), "history={} is not allowed"),
        (lambda s: s["tracker"].update(history=[]), "a champion without a history record"),
        (lambda s: s["tracker"].update(since=0), "best=-0.5 found at evaluation 10 (evaluations - since)"),
        (lambda s: s["tracker"].update(best=-1.0), "is not the champion's: best=-1.0"),
        (lambda s: s["fitness"].update(data=["nan"] * 6), "fitness (best -inf) disagrees with its champion's return -0.5"),
        (lambda s: s["fitness"]["data"].__setitem__(0, -0.25), "fitness (best -0.25) disagrees with its champion's return -0.5"),
        (lambda s: s.update(generation=2**70), "'generation' entry 1180591620717411303424 is damaged (a count past"),
        (lambda s: s.update(generation=4), "has generation=4, tracker evaluations=10"),
        (lambda s: s["tracker"].update(evaluations=11, since=10), "has generation=3, tracker evaluations=11"),
        (lambda s: s.update(population=None, fitness=None), "has generation=3, tracker evaluations=10 and no population"),
        (lambda s: s.update(wall_seconds=1e308), "'wall_seconds' entry 1e+308 is damaged (more seconds than 100 years"),
        (lambda s: s["tracker"]["history"][0].__setitem__(2, 1e308), "more seconds than 100 years"),
        (lambda s: s.update(settings={}), "settings lack pop_size, elite_size"),
    ],
)
def test_a_steady_state_states_tracker_fitness_and_counts_must_agree(edit, fragment: str) -> None:
    """T19-09, T19-08: SteadyStateNE.from_state_dict took tracker history rows with NaN, 'nan' or out-of-order returns,
    a best of -1 that disagreed with the fitness array, an all-NaN fitness beside a finite champion, 1e308 seconds and a
    generation of 2**70; now the tracker's history, best and counts must agree with the population as tell() makes them."""
    _check_refused(SteadyStateNE, _steady_state, edit, fragment)


def test_a_steady_state_without_elite_or_champion_still_loads() -> None:
    """Without an elite the population is the last batch, whose best may be below the champion's; with no finite
    return yet an all-NaN fitness is the true state: both load."""
    state = _steady_state(elite=0)
    assert SteadyStateNE.from_state_dict(state).champion_return == -0.5
    opt = SteadyStateNE(np.zeros(4), SteadyStateSettings(pop_size=6, elite_size=4), seed=1)
    opt.ask()
    opt.tell(np.full(6, np.nan))
    assert SteadyStateNE.from_state_dict(opt.state_dict()).champion_genome is None


# --------------------------------------------------------------------------- T19-03: OpenAI-ES and CMA-ES


@pytest.mark.parametrize(
    ("edit", "fragment"),
    [
        (lambda s: s["adam"].__setitem__(0, None), "OpenAIES state dict's 'adam' entry [None, "),
        (lambda s: s["adam"].__setitem__(1, None), "is damaged (no Adam moment"),
        (lambda s: s["adam"].append(s["adam"][0]), "not Adam's two moments"),
        (lambda s: s.update(adam={}), "not Adam's two moments"),
        (lambda s: s["adam"][1]["data"].__setitem__(0, -1.0), "Adam's second moment holds a negative number"),
        (lambda s: s["adam"][0]["data"].__setitem__(0, "nan"), "Adam moment holds a gene that is not a finite number"),
        (lambda s: s.update(mean=None), "'mean' entry None is damaged (no mean"),
        (lambda s: s.update(generation=5), "has generation=5 and tracker evaluations=8"),
        (lambda s: s.update(generation=2**70), "a count past"),
        (lambda s: s.update(settings={}), "settings lack popsize, sigma, learning_rate"),
        (lambda s: s["tracker"]["history"][0].__setitem__(1, "nan"), "history record [1, nan, ...] is not allowed"),
        (lambda s: s.update(wall_seconds=1e308), "more seconds than 100 years"),
    ],
)
def test_an_openai_es_states_entries_are_checked_on_loading(edit, fragment: str) -> None:
    """T19-03: an OpenAIES state whose Adam moment was None loaded, and the first tell() was a TypeError in the Adam
    step; now the moments (two finite arrays, the second >= 0), the settings (every field), the generation (against
    the evaluations told) and the tracker are checked on loading."""
    _check_refused(OpenAIES, _openai_es, edit, fragment)


def test_a_cma_states_tracker_is_checked_on_loading() -> None:
    """T19-03: a pickled CMA-ES state's champion tracking is read back as the others' are: a champion without its
    history record, or one whose history disagrees with its best, is refused."""
    opt = CMAES(np.zeros(4), popsize=4, seed=1)
    opt.ask()
    opt.tell(-np.arange(4.0) - 1.0)
    assert CMAES.from_state_dict(opt.state_dict()).champion_return == -1.0
    opt._tracker.history = []
    with _raises("a champion without a history record"):
        CMAES.from_state_dict(opt.state_dict())


@pytest.mark.parametrize(
    ("name", "value", "fragment"),
    [
        ("_rng", None, "its generator None or clock"),
        ("_clock", None, "or clock None is of the wrong kind"),
        ("budget", -1, "its budget=-1 is not allowed"),
        ("budget", True, "its budget=True is not allowed"),
        ("_pending", "x", "its pending batch 'x' is not allowed"),
        ("_pending", np.full((4, 4), np.nan), "pending genomes holds a gene that is not a finite number"),
        ("_pending", np.zeros((4, 3)), "pending genomes has shape (4, 3), expected (n, 4)"),
    ],
)
@pytest.mark.parametrize("cls", [CMAES, UHCMAES])
def test_a_cma_states_pickled_parts_are_checked_on_loading(cls, name: str, value, fragment: str) -> None:
    """T19-03: a CMA-ES (or UH-CMA-ES) state whose pickled generator or clock was None, or whose pending batch was
    text, loaded and failed at the first ask() or tell() with a traceback; a budget of -1 or True was taken. Now the
    optimiser's own parts are checked on loading."""
    opt = CMAES(np.zeros(4), popsize=4, seed=1) if cls is CMAES else UHCMAES(np.zeros(4), UHCMASettings(popsize=4), seed=1)
    opt.ask()
    assert isinstance(cls.from_state_dict(opt.state_dict()), cls)  # the sound state (between ask and tell) loads
    setattr(opt, name, value)
    with _raises(fragment):
        cls.from_state_dict(opt.state_dict())


# --------------------------------------------------------------------------- T19-10: a generation's episodes


@pytest.mark.parametrize("episodes", [10**30, MAX_BUDGET + 1, -1, True, 2.0, "3"])
def test_a_generations_episodes_are_bounded(episodes) -> None:
    """T19-10: TellInfo(episodes=10**30) was taken and a GenerationalNE's evaluations became 1e30; now TellInfo and
    GenerationalNE.tell(episodes=...) take an integer in 0..MAX_EPISODES (a run's largest budget)."""
    assert common.MAX_EPISODES == MAX_BUDGET
    assert TellInfo(episodes=np.int64(MAX_BUDGET)).episodes == MAX_BUDGET
    with _raises(f"episodes={episodes!r}"[:12]):
        TellInfo(episodes=episodes)
    opt = GenerationalNE(np.zeros(4), GenerationalSettings(pop_size=6, select_size=2), seed=1)
    opt.ask()
    with _raises("allowed an integer in 0..10,000,000,000"):
        opt.tell(-np.arange(6.0), episodes=episodes)
    opt.tell(-np.arange(6.0), TellInfo(episodes=7))
    assert opt.evaluations == 7


# --------------------------------------------------------------------------- T19-08: through evolve --resume


@pytest.mark.parametrize("name", ["crossover_prob", "averaging_prob", "mutate_prob", "mutate_frac", "mutate_repl", "init_mutate_frac"])
@pytest.mark.parametrize("cls", [GenerationalSettings, SteadyStateSettings])
def test_a_probability_setting_refuses_a_bool(cls, name: str) -> None:
    """T19-08: a generational checkpoint's crossover_prob of true resumed (run.py compared it as 1.0): the settings
    classes refuse True as a probability, as the CLI does."""
    with _raises(f"{name}=True must be a probability in [0, 1]"):
        cls(**{name: True})


def _resume(tmp_path: Path, state: dict, target, **run) -> None:
    ckpt = tmp_path / "damaged.ckpt.json"
    ckpt.write_text(json.dumps(state))
    evolve(target, budget=state["counters"]["episodes"] + 4, checkpoint=ckpt, resume=True, **run)


def test_a_resumed_generational_state_of_generation_2_to_the_70_is_refused(tmp_path: Path) -> None:
    """T19-08: a generational checkpoint whose optimizer_state said generation 2**70 resumed and stopped at once
    'by generations'; now the optimiser's state is refused by name."""
    run = dict(topology="slp", prototype="baseline", seed=3, n_steps=10, settings=GenerationalSettings(pop_size=4, select_size=2))
    ckpt = tmp_path / "run.ckpt.json"
    evolve(GHH08, budget=8, checkpoint=ckpt, **run)
    state = json.loads(ckpt.read_text())
    state["optimizer_state"]["generation"] = 2**70
    with _raises("cannot restore the optimiser (GenerationalNE state dict's 'generation' entry 1180591620717411303424 is damaged"):
        _resume(tmp_path, state, GHH08, **run)


def test_a_resumed_steady_state_of_nan_fitness_is_refused(tiny_checkpoint: Path, tmp_path: Path) -> None:
    """T19-08: a steady-state checkpoint whose optimizer_state fitness was all NaN beside a finite champion resumed;
    now it is refused by name."""
    state = json.loads(tiny_checkpoint.read_text())
    fitness = state["optimizer_state"]["fitness"]
    fitness["data"] = ["nan"] * len(fitness["data"])
    with _raises("cannot restore the optimiser (SteadyStateNE state dict's fitness (best -inf) disagrees with its champion's return"):
        _resume(tmp_path, state, GHH08.zero(), topology="slp", prototype="baseline", seed=3, n_steps=20)
