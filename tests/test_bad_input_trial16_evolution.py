"""The sixteenth bad-input trial's findings in the evolution package and the NEAT integration (T16-12's NEAT part,
T16-15, T16-16, T16-19 to T16-23): each bad input gives one clear NeurohoverError naming the value and what is
allowed, instead of a traceback, a hang or a silent wrong answer; valid input runs as before."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest

from neurohover.errors import NeurohoverError
from neurohover.evolution import bandits, races
from neurohover.evolution.generational import GenerationalNE, GenerationalSettings
from neurohover.evolution.optimisers.cma import CMAES
from neurohover.evolution.optimisers.openai_es import OpenAIES, OpenAIESSettings
from neurohover.evolution.steady_state import SteadyStateNE, SteadyStateSettings
from neurohover.tasks import get_task_family

PROTO = np.zeros(3)
GHH08 = get_task_family("ghh08")


def _raises(fragment: str):
    return pytest.raises(NeurohoverError, match=re.escape(fragment))


def _optimisers():
    return [
        SteadyStateNE(PROTO, SteadyStateSettings(pop_size=4, elite_size=3)),
        GenerationalNE(PROTO, GenerationalSettings(pop_size=4, select_size=2)),
        CMAES(PROTO, popsize=4),
        OpenAIES(PROTO, OpenAIESSettings(popsize=4)),
    ]


def _told(opt):
    """``opt`` after one generation (its population, parents, champion and tracker filled in)."""
    x = opt.ask()
    opt.tell(-np.arange(1.0, len(x) + 1))
    return opt


def _json_state(opt) -> dict:
    return json.loads(json.dumps(opt.state_dict()))


# --------------------------------------------------------------------------- T16-15: array entries of a state dict


def _bools(a: dict) -> None:
    a["data"] = [True] * len(a["data"])


def _text(a: dict) -> None:
    a["data"][0] = "1.5"


def _one_bool(a: dict) -> None:
    a["data"][-1] = True


DAMAGE = [
    ("SteadyStateNE", lambda s: _bools(s["population"]), "population data entry=True is not allowed"),
    ("SteadyStateNE", lambda s: _one_bool(s["population"]), "(real numbers, not booleans)"),
    ("SteadyStateNE", lambda s: _text(s["fitness"]), "fitness data entry='1.5' is not allowed"),
    ("SteadyStateNE", lambda s: _bools(s["fitness"]), "fitness data entry=True is not allowed"),
    ("SteadyStateNE", lambda s: _bools(s["prototype"]), "prototype data entry=True is not allowed"),
    ("SteadyStateNE", lambda s: s["settings"].update(pop_size=5), "population has 4 genomes where the state's settings make 5"),
    ("SteadyStateNE", lambda s: s["tracker"].update(evaluations=-1), "not a count: allowed an integer >= 0"),
    ("SteadyStateNE", lambda s: _bools(s["tracker"]["genome"]), "tracker genome data entry=True is not allowed"),
    ("SteadyStateNE", lambda s: s["tracker"]["history"][0].__setitem__(0, True), "not a count: allowed an integer >= 0"),
    ("GenerationalNE", lambda s: _bools(s["prototype"]), "prototype data entry=True is not allowed"),
    ("GenerationalNE", lambda s: _text(s["population"]), "population data entry='1.5' is not allowed"),
    ("GenerationalNE", lambda s: _bools(s["champion_genome"]), "champion genome data entry=True is not allowed"),
    ("GenerationalNE", lambda s: _bools(s["parents"]), "parents data entry=True is not allowed"),
    ("GenerationalNE", lambda s: s["settings"].update(pop_size=5, select_size=2), "population has 4 genomes where the state's settings make 5"),
    ("GenerationalNE", lambda s: s["settings"].update(select_size=3), "parents has 2 genomes where the state's settings make 3"),
    ("GenerationalNE", lambda s: s.update(champion_return="1.5"), "could not convert string to float: '1.5'"),
    ("GenerationalNE", lambda s: s["history"][0].__setitem__(1, True), "not a count: allowed an integer >= 0"),
    ("OpenAIES", lambda s: _bools(s["mean"]), "mean data entry=True is not allowed"),
    ("OpenAIES", lambda s: _text(s["adam"][0]), "Adam moment data entry='1.5' is not allowed"),
    ("OpenAIES", lambda s: s["tracker"].update(evaluations=-1), "not a count: allowed an integer >= 0"),
    ("OpenAIES", lambda s: s["tracker"].update(since=9), "since=9 is more than its evaluations (4)"),
]


@pytest.mark.parametrize(("name", "damage", "fragment"), DAMAGE, ids=[f"{n}-{i}" for i, (n, _, _) in enumerate(DAMAGE)])
def test_a_state_dicts_arrays_and_counts_are_checked(name: str, damage, fragment: str) -> None:
    """T16-15: from_state_dict took bools and numeric strings in array entries (every gene True read as 1.0, a fitness
    '1.5' as 1.5), a pop_size that disagreed with the population's rows (the resumed run went on with it) and a
    tracker's evaluations of -1; now each is refused, naming the entry."""
    opt = {type(o).__name__: o for o in _optimisers()}[name]
    state = _json_state(_told(opt))
    cls = type(opt)
    assert np.array_equal(cls.from_state_dict(json.loads(json.dumps(state))).ask(), opt.ask())  # the sound state continues as it was
    damage(state)
    with _raises(fragment):
        cls.from_state_dict(state)


@pytest.mark.parametrize("opt", _optimisers(), ids=lambda o: type(o).__name__)
def test_a_negative_evaluation_count_is_refused_by_every_optimiser(opt) -> None:
    """T16-15: tracker.evaluations = -1 was taken (CMA-ES's pickled tracker included)."""
    _told(opt)
    cls = type(opt)
    cls.from_state_dict(_json_state(opt))
    if isinstance(opt, GenerationalNE):
        opt._evaluations = -1
    else:
        opt._tracker.evaluations = -1
    with _raises("not a count: allowed an integer >= 0"):
        cls.from_state_dict(_json_state(opt))


def test_non_finite_values_of_a_state_still_read_back() -> None:
    """T16-15: the strings enc_float writes for NaN and infinities stay readable ('nan', '-inf')."""
    opt = SteadyStateNE(PROTO, SteadyStateSettings(pop_size=4, elite_size=3))
    x = opt.ask()
    opt.tell(np.array([-1.0, np.nan, -np.inf, -2.0])[: len(x)])
    back = SteadyStateNE.from_state_dict(_json_state(opt))
    assert np.array_equal(back.fitness, opt.fitness, equal_nan=True)


# --------------------------------------------------------------------------- T16-16: a checkpoint's own entries


@pytest.mark.parametrize(
    ("edit", "fragment"),
    [
        (lambda c: c.update(bogus=1), "has unknown entries 'bogus': allowed format, config, budget"),
        (lambda c: c["counters"].update(bogus=1), "the counters table of checkpoint"),
        (lambda c: c["champion"].update(bogus=1), "the champion table of checkpoint"),
        (lambda c: c.update(budget="100"), "budget='100' is not allowed: allowed null or an integer in 1..10,000,000,000"),
        (lambda c: c.update(mdp_stream="x"), "mdp_stream='x' is not allowed: allowed null (a run on one MDP draws no MDPs)"),
        (lambda c: c.update(stop_reason=5), "stop_reason=5 is not allowed: allowed null or one of budget, plateau"),
        (lambda c: c["counters"].update(wall_seconds="1.5"), "counter 'wall_seconds' is '1.5', not a number of seconds >= 0"),
        (lambda c: c["champion"].update(genome=[True] * len(c["optimizer_state"]["prototype"]["data"])), "the champion genome data entry=True is not allowed"),
        (lambda c: c["history"][0].__setitem__(0, True), "not a count: allowed an integer >= 0"),
    ],
)
def test_a_checkpoints_entries_are_checked_on_resume(tiny_checkpoint: Path, tmp_path: Path, edit, fragment: str) -> None:
    """T16-16: evolve(..., resume=True) took a checkpoint with an unknown top-level entry or counter, a budget of '100',
    an mdp_stream of 'x' and a stop_reason of 5; now each is refused by name."""
    from neurohover.evolution.evolve import evolve

    common = dict(topology="slp", prototype="baseline", seed=3, n_steps=20)
    state = json.loads(tiny_checkpoint.read_text())
    ckpt = tmp_path / "run.ckpt.json"
    ckpt.write_text(json.dumps(state))
    flown = state["counters"]["episodes"]  # resumed with it as the budget, the run stops at once
    assert evolve(GHH08.zero(), budget=flown, checkpoint=ckpt, resume=True, **common).episodes == flown  # the sound checkpoint resumes
    edit(state)
    ckpt.write_text(json.dumps(state))
    with _raises(fragment):
        evolve(GHH08.zero(), budget=flown, checkpoint=ckpt, resume=True, **common)


# --------------------------------------------------------------------------- T16-19, T16-20: races' episode caps


def _zeros(i):
    return np.zeros(len(i))


@pytest.mark.parametrize(
    ("call", "fragment"),
    [
        (lambda: races.fixed_resampling(_zeros, 3, 10**13), "k=10000000000000 must be an integer in 1..100,000"),
        (lambda: races.selection_race(_zeros, 6, 2, 0.1, t_limit=10**13), "t_limit=10000000000000 must be an integer in 1..100,000"),
        (lambda: bandits.top_mu_bandit(_zeros, 6, 2, 0.1, t_limit=10**13), "t_limit=10000000000000 must be an integer in 1..100,000"),
    ],
)
def test_races_cap_the_episodes_per_candidate(call, fragment: str) -> None:
    """T16-19, T16-20: fixed_resampling with k=10**13 and a race or bandit with t_limit=10**13 ran on, growing their
    samples until killed; now both are capped at parse_resampling's K (100,000)."""
    with _raises(fragment):
        call()
    assert races.fixed_resampling(_zeros, 3, 2).samples.shape == (3, 2)
    assert races.selection_race(_zeros, 6, 2, 0.1, t_limit=3).n_samples.max() <= 3
    assert bandits.top_mu_bandit(_zeros, 6, 2, 0.1, t_limit=3).n_samples.max() <= 3


# --------------------------------------------------------------------------- T16-21 to T16-23, T16-12: NEAT


@pytest.mark.parametrize("budget", [10**13, 2**64])
def test_evolve_topology_caps_the_budget(budget: int) -> None:
    """T16-21: evolve_topology(..., budget=10**13) ran on without a cap (killed at 90 s); evolve's range applies."""
    from neurohover.integrations.neat import evolve_topology

    with _raises(f"budget={budget!r} is out of range: allowed an integer in 1..10,000,000,000 (episodes)"):
        evolve_topology(GHH08.zero(), budget=budget, n_steps=20)


@pytest.mark.parametrize("mdps", [None, 3, 1.5, True, np.array(3), "ghh08"])
def test_evolve_topology_names_a_target_that_is_no_mdp(mdps) -> None:
    """T16-22: evolve_topology(None, ...) was "TypeError: 'NoneType' object is not iterable" (also 3, 1.5, True, np.array(3))."""
    from neurohover.integrations.neat import NeatSettings, evolve_topology

    with _raises("is not allowed: mdps must be one MDP or a non-empty sequence of MDPs of one task family, or a TaskFamily"):
        evolve_topology(mdps, budget=10, n_steps=20)
    result = evolve_topology([GHH08.zero()], budget=4, n_steps=5, settings=NeatSettings(pop_size=4))
    assert result.episodes == 4


@pytest.mark.parametrize("record", [np.array(3), np.array(3.0)])
def test_network_of_record_names_a_0d_array(record) -> None:
    """T16-23: network_of_record(np.array(3)) was "TypeError: len() of unsized object"."""
    from neurohover.integrations.neat import ACTIVATIONS, network_of_record

    with _raises("is not allowed: give a genome_record (a non-empty list of finite numbers)"):
        network_of_record(record)
    identity = float(ACTIVATIONS.index("identity"))
    outputs = [v for k in range(4) for v in (k, 0.0, 1.0, identity)]  # the four output nodes, no connection
    assert network_of_record(np.array([4.0, *outputs])) is not None  # a 1-D array is a record still


@pytest.mark.parametrize(
    ("field", "value"),
    [("initial", np.array(["a", "b"])), ("fitness", np.array(["a", "b"])), ("start", np.array(["a", "b"])), ("initial", ["x"])],
)
def test_neat_settings_name_a_choice_that_is_no_text(field: str, value) -> None:
    """T16-12: NeatSettings(initial=np.array(['a', 'b'])) was NumPy's "truth value of an array ... is ambiguous"."""
    from neurohover.integrations.neat import NeatSettings

    with _raises(f"{field}="):
        NeatSettings(**{field: value})
    assert NeatSettings(initial="unconnected").initial == "unconnected"
