"""The fourteenth bad-input trial's findings in the evolution package (T14-3, T14-6, T14-7, T14-8, T14-9 and the
evolution part of T14-21): each bad input gives one clear NeurohoverError naming the value and what is allowed,
instead of a traceback or a silent wrong answer; valid input runs as before."""

from __future__ import annotations

import decimal
import fractions
import json
from pathlib import Path

import numpy as np
import pytest

from neurohover.errors import NeurohoverError
from neurohover.evolution import bandits, races
from neurohover.evolution.eonn import EonnSettings
from neurohover.evolution.generational import GenerationalNE, GenerationalSettings
from neurohover.evolution.optimisers.cma import CMAES, CMASettings
from neurohover.evolution.optimisers.openai_es import OpenAIES, OpenAIESSettings
from neurohover.evolution.optimisers.uh_cma import UHCMAES, UHCMASettings
from neurohover.evolution.steady_state import SteadyStateNE, SteadyStateSettings

PROTO = np.zeros(3)

#: Each optimiser as the Python API builds it, small.
OPTIMISERS = {
    "SteadyStateNE": lambda **kw: SteadyStateNE(PROTO, kw.pop("settings", SteadyStateSettings(pop_size=4, elite_size=3)), **kw),
    "GenerationalNE": lambda **kw: GenerationalNE(PROTO, kw.pop("settings", GenerationalSettings(pop_size=4, select_size=2)), **kw),
    "CMAES": lambda **kw: CMAES(PROTO, popsize=4, **kw),
    "OpenAIES": lambda **kw: OpenAIES(PROTO, kw.pop("settings", OpenAIESSettings(popsize=4)), **kw),
}


def _ask_tell(opt) -> None:
    x = opt.ask()
    opt.tell(-np.ones(len(x)))


# --------------------------------------------------------------------------- T14-3: a spread of -0.0


@pytest.mark.parametrize(
    ("make", "fields"),
    [
        (lambda: SteadyStateSettings(pop_size=4, elite_size=3, mutate_std=-0.0), ("mutate_std",)),
        (lambda: SteadyStateSettings(pop_size=4, elite_size=3, init_mutate_std=-0.0), ("init_mutate_std",)),
        (lambda: GenerationalSettings(pop_size=4, select_size=2, mutate_std=-0.0), ("mutate_std",)),
        (lambda: GenerationalSettings(pop_size=4, select_size=2, init_mutate_std=-0.0), ("init_mutate_std",)),
        (lambda: EonnSettings(mutate_std=-0.0, spawn_std=-0.0), ("mutate_std", "spawn_std")),
        (lambda: OpenAIESSettings(l2=-0.0), ("l2",)),
        (lambda: UHCMASettings(epsilon=-0.0), ("epsilon",)),
    ],
)
def test_a_spread_of_minus_zero_is_taken_as_zero(make, fields) -> None:
    """T14-3: mutate_std=-0.0 (init_mutate_std, eonn's spawn_std) was accepted, then NumPy's "scale < 0" at the first
    mutation; the one spread check now stores 0.0, and the optimiser runs."""
    settings = make()
    for name in fields:
        value = getattr(settings, name)
        assert value == 0.0 and not np.signbit(value), (name, value)
    if isinstance(settings, SteadyStateSettings):
        opt = SteadyStateNE(PROTO, settings)
        _ask_tell(opt)
        _ask_tell(opt)
    elif isinstance(settings, GenerationalSettings):
        _ask_tell(GenerationalNE(PROTO, settings))


def test_evolve_on_the_command_line_takes_a_mutation_spread_of_minus_zero(tmp_path: Path, capsys) -> None:
    """T14-3: `evolve --setting mutate_std=-0.0` was a ValueError traceback (scale < 0) in the first population."""
    from neurohover.cli import main

    out = tmp_path / "e.json"
    assert main(["evolve", "--task", "ghh08", "--budget", "5", "--episode-steps", "20", "--out", str(out), "--setting", "mutate_std=-0.0"]) == 0
    assert "Traceback" not in capsys.readouterr().err and out.exists()


# --------------------------------------------------------------------------- T14-6: returns that are not real numbers

BAD_RETURNS = {
    "dates": (lambda n: np.array(["2020-01-01"] * n, "datetime64[D]"), "dates"),
    "numeric text": (lambda n: ["-1"] * n, "text"),
    "None": (lambda n: [None] * n, "Python objects"),
    "bools": (lambda n: np.ones(n, bool), "booleans"),
    "Decimal": (lambda n: [decimal.Decimal(-1)] * n, "Python objects"),
    "Fraction": (lambda n: [fractions.Fraction(-1, 2)] * n, "Python objects"),
    "complex": (lambda n: -np.ones(n, complex), "complex numbers"),
    "masked": (lambda n: np.ma.masked_array(-np.ones(n), mask=[True] + [False] * (n - 1)), "a masked array"),
}


@pytest.mark.parametrize("kind", BAD_RETURNS)
@pytest.mark.parametrize("name", OPTIMISERS)
def test_tell_takes_real_numbers_only(name: str, kind: str) -> None:
    """T14-6: tell() took dates (2020-01-01 became a champion return 18262.0), numeric text, None (as NaN), bools,
    Decimal, Fraction, complex numbers (the imaginary part dropped with a warning) and masked arrays (the mask
    ignored); the one shared check refuses them by name and nothing is told."""
    opt = OPTIMISERS[name]()
    x = opt.ask()
    make, what = BAD_RETURNS[kind]
    what_name = "fitness_estimates" if name == "GenerationalNE" else "fitness"
    with pytest.raises(NeurohoverError, match=rf"{what_name}=.* is not allowed: give {len(x)} returns, one per asked genome \(real numbers, not {what}\)"):
        opt.tell(make(len(x)))
    opt.tell(list(range(-len(x), 0)))  # still pending, and Python ints are real numbers


@pytest.mark.parametrize(
    ("prototype", "what"),
    [(["1", "2", "3"], "text"), (np.ones(3, bool), "booleans"), (np.ones(3, complex), "complex numbers"), ([1.0, None, 2.0], "Python objects")],
)
@pytest.mark.parametrize("name", ["SteadyStateNE", "GenerationalNE", "CMAES", "OpenAIES"])
def test_a_prototype_of_text_bools_or_complex_numbers_is_refused(name: str, prototype, what: str) -> None:
    """T14-6: a prototype of '1' strings, bools or complex numbers was taken as numbers."""
    make = {"SteadyStateNE": SteadyStateNE, "GenerationalNE": GenerationalNE, "CMAES": CMAES, "OpenAIES": OpenAIES}[name]
    with pytest.raises(NeurohoverError, match=rf"prototype=.* is not allowed: give a non-empty 1-D genome of finite numbers \(real numbers, not {what}\)"):
        make(prototype)


def test_races_take_real_numbers_only() -> None:
    """T14-6: fixed_resampling took dates from sample_fn, selection_race numeric text ('a' was refused, '1' not)."""
    with pytest.raises(NeurohoverError, match=r"sample_fn's returns=.* is not allowed: give 4 numbers, one per candidate \(real numbers, not dates\)"):
        races.fixed_resampling(lambda i: np.array(["2020-01-01"] * len(i), "datetime64[D]"), 4, 1)
    with pytest.raises(
        NeurohoverError, match=r"sample_fn's returns=\['1', '1', '1', '1'\] is not allowed: give 4 numbers, one per candidate \(real numbers, not text\)"
    ):
        races.selection_race(lambda i: ["1"] * len(i), 4, 1, 0.9, t_limit=1)
    result = races.fixed_resampling(lambda i: np.asarray(i, dtype=np.float32) - 4, 4, 2)  # float32 and ints: real numbers
    assert result.means.tolist() == [-4.0, -3.0, -2.0, -1.0]


def test_real_returns_of_any_numeric_dtype_still_tell_the_same() -> None:
    """T14-6: the check refuses by dtype kind only: ints, float32 and a list of NumPy scalars tell as float64 did."""
    told = []
    for values in ([-3, -1, -2, -4], np.array([-3, -1, -2, -4], np.float32), [np.float64(-3), np.int64(-1), -2.0, np.int8(-4)]):
        opt = SteadyStateNE(PROTO, SteadyStateSettings(pop_size=4, elite_size=3), seed=1)
        opt.ask()
        opt.tell(values)
        told.append((opt.fitness.tolist(), opt.champion_return, opt.ask().tobytes()))
    assert told[0] == told[1] == told[2] and told[0][1] == -1.0


# --------------------------------------------------------------------------- T14-7: seeds

BAD_SEEDS = [(-1, "-1"), (1.5, "1.5"), ("1", "'1'"), (np.int8(-1), r"np\.int8\(-1\)"), (True, "True"), (2**70, str(2**70)), ([1, 2], r"\[1, 2\]")]


@pytest.mark.parametrize(("seed", "shown"), BAD_SEEDS)
@pytest.mark.parametrize("name", [*OPTIMISERS, "UHCMAES"])
def test_an_optimiser_takes_a_seed_in_0_to_2_63_only(name: str, seed, shown: str) -> None:
    """T14-7: seed=-1, 1.5, '1' and np.int8(-1) were NumPy's "expected non-negative integer" / "SeedSequence expects
    int"; True, 2**70 and [1, 2] were taken. The seed check every command uses now refuses them."""
    make = (lambda **kw: UHCMAES(PROTO, UHCMASettings(popsize=4), **kw)) if name == "UHCMAES" else OPTIMISERS[name]
    why = "is out of range" if isinstance(seed, (int, np.integer)) and not isinstance(seed, bool) else "is not allowed"  # T22-14
    with pytest.raises(NeurohoverError, match=rf"seed={shown} {why}: allowed an integer in 0\.\.2\*\*63-1"):
        make(seed=seed)


def test_eonn_evolve_takes_a_seed_in_0_to_2_63_only() -> None:
    """T14-7: eonn_evolve's seed went to NumPy unchecked, as the optimisers' did."""
    from neurohover import prototype
    from neurohover.evolution.eonn import eonn_evolve
    from neurohover.tasks import get_task_family

    with pytest.raises(NeurohoverError, match=r"seed=-1 is out of range: allowed an integer in 0\.\.2\*\*63-1"):
        eonn_evolve(
            get_task_family("ghh08").zero(), prototype("slp"), settings=EonnSettings(pop_size=2, keep=1, generations=1, tournament_size=1), seed=-1, n_steps=5
        )


@pytest.mark.parametrize("name", OPTIMISERS)
def test_a_numpy_integer_seed_is_the_same_seed(name: str) -> None:
    """T14-7: the check returns a Python int: np.int64(7) still seeds exactly as 7."""
    assert np.array_equal(OPTIMISERS[name](seed=np.int64(7)).ask(), OPTIMISERS[name](seed=7).ask())


# --------------------------------------------------------------------------- T14-8: settings of another class


@pytest.mark.parametrize(
    ("make", "shown", "wanted"),
    [
        (lambda: OpenAIES(PROTO, settings={"popsize": 4}), r"\{'popsize': 4\}", "OpenAIESSettings"),
        (lambda: OpenAIES(PROTO, settings=SteadyStateSettings()), r"SteadyStateSettings\(pop_size=50", "OpenAIESSettings"),
        (lambda: SteadyStateNE(PROTO, settings=OpenAIESSettings()), r"OpenAIESSettings\(popsize=20", "SteadyStateSettings"),
        (lambda: GenerationalNE(PROTO, settings={}), r"\{\}", "GenerationalSettings"),
        (lambda: UHCMAES(PROTO, CMASettings()), r"CMASettings\(sigma0=0\.02", "UHCMASettings"),
    ],
)
def test_settings_of_another_class_are_refused_at_construction(make, shown: str, wanted: str) -> None:
    """T14-8: another optimiser's settings, or a dict, were an AttributeError at construction or at the first ask()."""
    with pytest.raises(NeurohoverError, match=rf"settings={shown}.* is not allowed: give a {wanted} \(or None for its defaults\)"):
        make()


# --------------------------------------------------------------------------- T14-9: damaged state dicts


def _state(name: str) -> dict:
    opt = OPTIMISERS[name]()
    _ask_tell(opt)
    return json.loads(json.dumps(opt.state_dict()))


@pytest.mark.parametrize(
    ("name", "key", "why"),
    [
        ("SteadyStateNE", "generation", "not a count: allowed an integer >= 0"),
        ("SteadyStateNE", "settings", "TypeError: 'str' object is not a mapping"),
        ("SteadyStateNE", "population", "TypeError: string indices must be integers"),
        ("SteadyStateNE", "tracker", "TypeError: string indices must be integers"),
        ("SteadyStateNE", "wall_seconds", "not a number of seconds: allowed a finite number >= 0"),
        ("GenerationalNE", "generation", "not a count: allowed an integer >= 0"),
        ("GenerationalNE", "evaluations", "not a count: allowed an integer >= 0"),
        ("GenerationalNE", "asked", "not a flag: allowed true or false"),
        ("GenerationalNE", "history", "ValueError: not enough values to unpack"),
        ("GenerationalNE", "champion_return", "could not convert string to float: 'x'"),
        ("OpenAIES", "generation", "not a count: allowed an integer >= 0"),
        ("OpenAIES", "adam", "TypeError: string indices must be integers"),
        ("OpenAIES", "tracker", "TypeError: string indices must be integers"),
        ("OpenAIES", "wall_seconds", "not a number of seconds"),
    ],
)
def test_a_damaged_entry_of_a_state_dict_is_named(name: str, key: str, why: str) -> None:
    """T14-9: an entry of a state dict set to 'x' was a bare ValueError, TypeError or KeyError from inside
    from_state_dict; now one NeurohoverError names the entry, what is wrong with it and what is allowed."""
    cls = type(OPTIMISERS[name]())
    state = _state(name)
    with pytest.raises(
        NeurohoverError, match=rf"{name} state dict's '{key}' entry 'x' is damaged \({why}.*\): give a dict that {name}\.state_dict\(\) returned"
    ):
        cls.from_state_dict({**state, key: "x"})
    del state[key]
    with pytest.raises(NeurohoverError, match=rf"{name} state dict has no '{key}' entry: give a dict that {name}\.state_dict\(\) returned"):
        cls.from_state_dict(state)


@pytest.mark.parametrize("name", ["SteadyStateNE", "GenerationalNE", "OpenAIES"])
def test_a_state_version_of_true_is_not_version_1(name: str) -> None:
    """T14-9: version=True compared equal to 1 and was taken."""
    cls = type(OPTIMISERS[name]())
    with pytest.raises(NeurohoverError, match=r"unsupported state version True: allowed 1"):
        cls.from_state_dict({**_state(name), "version": True})


@pytest.mark.parametrize(
    ("state", "fragment"),
    [
        ({"type": "CMAES"}, r"CMAES state dict has no 'pickle' entry: give a dict that CMAES\.state_dict\(\) returned"),
        ({"type": "CMAES", "pickle": "x"}, r"CMAES state dict's 'pickle' entry 'x' is damaged \(not base64 text: allowed the text state_dict\(\) wrote\)"),
        ({"type": "CMAES", "pickle": "AAAA"}, r"CMAES state dict's 'pickle' entry 'AAAA' is damaged \(UnpicklingError: "),
        ({"type": "CMAES", "pickle": 5}, r"CMAES state dict's 'pickle' entry 5 is damaged \(TypeError: "),
        ("x", r"state dict is a str, not a dict"),
    ],
)
def test_a_damaged_cma_es_state_is_named(state, fragment: str) -> None:
    """T14-9: CMAES.from_state_dict({}) was a KeyError, {'pickle': 'x'} a binascii.Error."""
    with pytest.raises(NeurohoverError, match=fragment):
        CMAES.from_state_dict(state)


def test_a_cma_es_state_still_continues_as_it_would_have() -> None:
    """T14-9: the checks leave a sound state's round trip as it was."""
    a = CMAES(PROTO, popsize=4, seed=3)
    _ask_tell(a)
    b = CMAES.from_state_dict(json.loads(json.dumps(a.state_dict())))
    assert np.array_equal(a.ask(), b.ask())


def test_a_damaged_optimiser_state_in_a_checkpoint_is_named_on_resume(tmp_path: Path) -> None:
    """T14-9: the resume's message carries the optimiser's, naming the entry (the CLI prints it, status 2)."""
    from neurohover.evolution.evolve import evolve
    from neurohover.tasks import get_task_family

    GHH08 = get_task_family("ghh08")
    ckpt = tmp_path / "run.ckpt.json"
    common = dict(topology="slp", prototype="baseline", seed=3, n_steps=20)
    evolve(GHH08, budget=5, checkpoint=ckpt, **common)
    state = json.loads(ckpt.read_text())
    state["optimizer_state"]["generation"] = "x"
    ckpt.write_text(json.dumps(state))
    with pytest.raises(NeurohoverError, match=r"cannot restore the optimiser \(GenerationalNE state dict's 'generation' entry 'x' is damaged \(not a count"):
        evolve(GHH08, budget=120, checkpoint=ckpt, resume=True, **common)


# --------------------------------------------------------------------------- T14-21: bounds


@pytest.mark.parametrize(
    ("samples", "fragment"),
    [
        (np.zeros((2, 2)), r"samples of shape \(2, 2\) is not allowed: give a 1-D array of returns, one candidate's"),
        (np.array([True, False, True]), r"samples=array\(\[ True, False, True\]\) is not allowed: give an array of returns \(real numbers, not booleans\)"),
    ],
)
def test_bayes_mean_bounds_takes_one_candidates_real_returns(samples, fragment: str) -> None:
    """T14-21: a 2-D array was flattened into one candidate's returns, and bools were taken as 0 and 1."""
    with pytest.raises(NeurohoverError, match=fragment):
        races.bayes_mean_bounds(samples, 0.5)


@pytest.mark.parametrize("mean", [1.5, -0.5])
def test_kl_bounds_takes_means_in_the_rewards_range(mean: float) -> None:
    """T14-21: a mean of 1.5 was clipped to 1 and given a lower bound 0.37 below it; the means are of rewards in [0, 1]."""
    with pytest.raises(NeurohoverError, match=rf"means=\[{mean}\] is not allowed: give 1 finite mean\(s\), one per entry of samples, each in \[0, 1\]"):
        bandits.kl_bounds(np.array([mean]), np.array([1]), level=1.0)
    lower, upper = bandits.kl_bounds(np.array([0.0, 1.0]), np.array([1, 2]), level=1.0)  # the ends of the range are taken
    assert lower[0] == 0.0 and upper[1] == 1.0


def test_lucb_radius_takes_whole_sample_counts() -> None:
    """T14-21: a fractional sample count (1.5) was taken."""
    with pytest.raises(NeurohoverError, match=r"samples=\[1\.5\] is not allowed: give a 1-D array of sample counts >= 1 \(whole numbers\)"):
        bandits.lucb_radius(np.array([1.5]), 1, 2, 0.1)
    with pytest.raises(NeurohoverError, match=r"samples=.* is not allowed: give a 1-D array of sample counts >= 1 \(real numbers, not booleans\)"):
        bandits.lucb_radius(np.array([True]), 1, 2, 0.1)
    assert bandits.lucb_radius(np.array([1.0, 2.0]), 1, 2, 0.1).shape == (2,)
