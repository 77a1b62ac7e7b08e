"""The eleventh fresh trial's settings findings: each bad setting gives one clear message (exit 2 / NeurohoverError)
naming it and what is allowed, before anything is flown; and EC-MER refuses a --policy that never flew the data."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from neurohover.errors import NeurohoverError

HUGE_INT = 10**400
SHOWN = r"1000000000\.\.\.\(401 digits\)"  # 10**400 as the messages show it


def _evolve(tmp_path: Path, *extra: str) -> list[str]:
    return ["evolve", "--task", "ghh08", "--episode-steps", "20", "--validation-episodes", "1", "--out", str(tmp_path / "p.json"), *extra]


@pytest.mark.parametrize("optimizer", ["cma", "uh-cma"])
def test_a_step_size_past_its_bound_is_refused_up_front(optimizer: str, tmp_path: Path, cli) -> None:
    """T1: sigma0=1e308 was pycma's AssertionError mid-run; settings cma documented sigma0 only as "> 0"."""
    rc, _, err = cli(*_evolve(tmp_path, "--optimizer", optimizer, "--budget", "20", "--setting", "sigma0=1e308"))
    assert rc == 2 and "Traceback" not in err, err
    assert "CMA-ES sigma0=1e+308 must be a finite number >= 1e-100 and <= 1e+100 (a larger one overflows the genes)" in err, err
    assert not (tmp_path / "p.json").exists()
    rc, out, _ = cli("settings", optimizer)
    assert rc == 0 and "The initial step size (>= 1e-100 and <= 1e100" in out, out


def test_more_reevaluations_than_a_generation_holds_are_refused(tmp_path: Path, cli) -> None:
    """T2: uh-cma reevaluations=50 was an IndexError in pycma's noise handler; "None or an integer >= 1" said nothing more."""
    from neurohover.evolution.optimisers.uh_cma import UHCMAES, UHCMASettings

    rc, _, err = cli(*_evolve(tmp_path, "--optimizer", "uh-cma", "--budget", "60", "--setting", "reevaluations=50"))
    assert rc == 2 and "Traceback" not in err, err
    assert "UH-CMA-ES reevaluations=50 must be at most popsize=15 (pycma's 4 + 3 ln D for D=42 genes)" in err, err
    with pytest.raises(NeurohoverError, match=r"reevaluations=11 must be at most popsize=10: it re-evaluates solutions of one generation"):
        UHCMASettings(popsize=10, reevaluations=11)
    with pytest.raises(NeurohoverError, match=r"reevaluations=10 must be at most popsize=9 \(pycma's 4 \+ 3 ln D for D=6 genes\)"):
        UHCMAES(np.ones(6), UHCMASettings(reevaluations=10))
    assert UHCMAES(np.ones(6), UHCMASettings(reevaluations=9)).popsize == 9  # every solution of a generation: allowed


def test_an_agents_settings_of_the_wrong_type_are_refused_when_made() -> None:
    """T6: HybridSettings and CodeAgentSettings took dangerous='x' (an AttributeError mid-run), CodeAgentSettings any
    estimator, wind_model, d_u or noise (refused, if at all, only when the run learned its model)."""
    from neurohover.agents.fghh_code import CodeAgentSettings
    from neurohover.agents.hybrid import HybridSettings

    for cls in (HybridSettings, CodeAgentSettings):
        with pytest.raises(NeurohoverError, match=r"dangerous='x' is not allowed: give a DangerousState \(neurohover.evaluate.DangerousState\)"):
            cls(dangerous="x")
    for name, allowed in (("estimator", "ols, gls"), ("wind_model", "none, constant, sinusoid"), ("d_u", "keep, discard"), ("noise", "innovations, rms")):
        for value in ("x", 5):
            with pytest.raises(NeurohoverError, match=f"{name}={value!r} is not allowed: choose one of {allowed}$"):
                CodeAgentSettings(**{name: value})


def test_a_bool_is_not_a_number_of_model_substeps() -> None:
    """S6: CodeAgentSettings(model_substeps=True) was taken as 1 (True == 1), though evolutions=True was refused."""
    from neurohover.agents.fghh_code import CodeAgentSettings

    with pytest.raises(NeurohoverError, match=r"model_substeps=True: allowed 1 or 10"):
        CodeAgentSettings(model_substeps=True)
    assert CodeAgentSettings(model_substeps=10).model_substeps == 10


def _settings(name: str) -> type:
    from neurohover.cli.settings import settings_classes

    return settings_classes()[name]


@pytest.mark.parametrize(
    ("name", "values", "message"),
    [
        ("cma", {"sigma0": -1}, r"CMA-ES sigma0=-1 must be a finite number >= 1e-100 and <= 1e\+100"),
        ("cma", {"popsize": HUGE_INT}, f"CMA-ES popsize={SHOWN} must be None or an integer in 2..100,000"),
        ("uh-cma", {"epsilon": -1}, r"UH-CMA-ES epsilon=-1 must be a finite number >= 0"),
        ("uh-cma", {"popsize": 1}, r"CMA-ES popsize=1 must be None or an integer in 2..100,000"),
        ("uh-cma", {"min_evaluations": 0}, r"UH-CMA-ES min_evaluations=0 and max_evaluations=20 must be integers with 1 <= min <= max"),
        ("uh-cma", {"reevaluations": 0}, r"UH-CMA-ES reevaluations=0 must be None or an integer >= 1"),
        (
            "incremental",
            {"max_learning_episodes": 0},
            r"max_learning_episodes=0 is out of range: allowed an integer in 1..2\*\*63-1",
        ),  # whole_in's range (T24-11)
        ("steady-state", {"mutate_prob": HUGE_INT}, f"mutate_prob={SHOWN} must be a probability in \\[0, 1\\]"),
        ("generational", {"crossover_prob": HUGE_INT}, f"crossover_prob={SHOWN} must be a probability in \\[0, 1\\]"),
        ("generational", {"init_mutate_frac": HUGE_INT}, f"init_mutate_frac={SHOWN} must be a probability"),
        ("steady-state", {"pop_size": HUGE_INT}, f"pop_size={SHOWN} must be an integer in 2..100,000"),
        ("eonn", {"mutate_std": HUGE_INT}, f"mutate_std={SHOWN} is out of range: allowed a number in \\[0, 1e\\+100\\]"),
        ("eonn", {"spawn_std": HUGE_INT}, f"spawn_std={SHOWN} is out of range: allowed a number in \\[0, 1e\\+100\\]"),
        ("eonn", {"mutate_frac": HUGE_INT}, f"mutate_frac={SHOWN} is out of range: allowed a probability in \\[0, 1\\]"),
        ("authors-fghh", {"fired_error": HUGE_INT}, f"fired_error={SHOWN} is out of range: allowed a finite number >= 0"),
        ("neat", {"activations": 5}, r"activations=5: allowed a non-empty tuple of distinct names from identity, tanh"),
        ("neat", {"activations": None}, r"activations=None: allowed a non-empty tuple"),
    ],
)
def test_settings_classes_refuse_with_a_neurohover_error_naming_the_value(name: str, values: dict, message: str) -> None:
    """T7: CMASettings, the UH-CMA-ES and incremental settings raised plain ValueErrors, *_prob=10**400 OverflowError,
    eonn's spreads and fired_error=10**400 NumPy's TypeError, NeatSettings(activations=5) "'int' object is not iterable";
    and 10**400 was echoed whole (a 400-character line)."""
    with pytest.raises(NeurohoverError, match=message) as caught:
        _settings(name)(**values)
    assert len(str(caught.value)) < 200, caught.value


def test_a_config_neat_table_with_activations_of_a_number_names_them(tmp_path: Path) -> None:
    """U4: neat = { activations = 5 } said only "neat: 'int' object is not iterable"."""
    from neurohover.experiments.config import load_config

    path = tmp_path / "neat1.toml"
    path.write_text(
        'name = "neat1"\ntitle = "t"\nkind = "evolution"\n[settings]\ntask = "ghh08"\nseed = 1\ntarget = "train"\n'
        '[[settings.variants]]\nkey = "neat"\nlabel = "x"\ntopology = "neat"\nneat = { activations = 5 }\n'
        "[scales.quick]\nbudget = 600\nruns = 1\n[scales.paper]\nbudget = 600\nruns = 1\n"
    )
    with pytest.raises(NeurohoverError, match=r"activations=5: allowed a non-empty tuple of distinct names from identity, tanh, sigmoid"):
        load_config(str(path), "quick")


@pytest.mark.parametrize(
    "call",
    [
        "selection_race(f, 5, 2, 2.0)|delta=2.0 must be a confidence level strictly between 0 and 1",
        f"selection_race(f, 5, 2, 10**400)|delta={SHOWN} must be a confidence level",
        "selection_race(f, 5, 5, 0.5)|mu=5 must be smaller than n_candidates=5",
        "selection_race(f, 5, 2, 0.5, rule='x')|rule='x' is not a race rule: choose one of prose, algorithm1, authors",
        "selection_race(f, 5, 2, 0.5, rule=['x'])|rule=\\['x'\\] is not a race rule",
        "fixed_resampling(f, 5, -1)|k=-1 must be an integer >= 1",
        "fixed_resampling(lambda i: np.zeros(1), 5, 2)|sample_fn returned shape \\(1,\\) for 5 candidates; expected \\(5,\\)",
        "fixed_resampling(lambda i: ['a'] * len(i), 5, 2)|sample_fn's returns=\\['a', .* is not allowed: give 5 numbers, one per candidate",
        "SteadyStateNE('abc')|prototype='abc' is not allowed: give a non-empty 1-D genome of finite numbers",
        "roulette_weights('abc')|returns='abc' is not allowed: give an array of returns \\(numbers\\)",
    ],
)
def test_the_evolution_functions_refuse_with_a_neurohover_error(call: str) -> None:
    """T8: selection_race and fixed_resampling (README-documented) raised plain ValueErrors, SteadyStateNE("abc") and
    roulette_weights("abc") NumPy's "could not convert string to float"."""
    from neurohover.evolution import SteadyStateNE, fixed_resampling, roulette_weights, selection_race

    code, message = call.split("|")
    scope = {"np": np, "f": lambda i: np.zeros(len(i)), "selection_race": selection_race, "fixed_resampling": fixed_resampling}
    scope.update(SteadyStateNE=SteadyStateNE, roulette_weights=roulette_weights)
    with pytest.raises(NeurohoverError, match=message):
        eval(code, scope)


def test_ask_and_tell_out_of_order_or_with_text_say_what_to_do() -> None:
    """T8: tell() before ask() and ask() twice were bare RuntimeErrors (missed by except NeurohoverError), tell() of
    strings NumPy's "could not convert"."""
    import neurohover as nh
    from neurohover.evolution import GenerationalNE, SteadyStateNE
    from neurohover.evolution.optimisers.cma import CMAES

    genome = nh.prototype("slp", "baseline").genome
    for make in (SteadyStateNE, GenerationalNE, CMAES):
        with pytest.raises(NeurohoverError, match=r"tell\(\) called without a pending ask\(\): call ask\(\) first, then tell\(\) one return per genome"):
            make(genome).tell(np.zeros(3))
    for make, what in ((SteadyStateNE, "batch"), (GenerationalNE, "population")):
        opt = make(genome)
        asked = opt.ask()
        with pytest.raises(NeurohoverError, match=f"ask\\(\\) called again before tell\\(\\) of the previous {what}: tell\\(\\) its returns first"):
            opt.ask()
        with pytest.raises(NeurohoverError, match=f"fitness.*=\\['a', .* is not allowed: give {len(asked)} returns, one per asked genome"):
            opt.tell(["a"] * len(asked))
        with pytest.raises(RuntimeError):  # still the RuntimeError it was, for callers that catch that
            opt.ask()


@pytest.mark.parametrize(
    ("optimizer", "setting", "message"),
    [
        ("openai-es", "sigma=1e308", r"sigma=1e\+308 must be a finite number >= 1e-100 and <= 1e\+100 \(a larger one overflows the genes\)"),
        ("openai-es", "learning_rate=1e308", r"learning_rate=1e\+308 must be a finite number >= 1e-100 and <= 1e\+100"),
        ("ne", "mutate_std=1e308", r"mutate_std=1e\+308 must be a finite number >= 0 and <= 1e\+100 \(a larger one overflows the genes\)"),
    ],
)
def test_a_spread_that_overflows_the_genes_is_refused_up_front(optimizer: str, setting: str, message: str, tmp_path: Path, cli) -> None:
    """U5: openai-es sigma=1e308 and generational mutate_std=1e308 (documented "> 0" and "finite, >= 0") ended, after
    flying, in "a mlp genome must hold finite numbers; genes [...] are not", naming no setting."""
    import re

    extra = ["--mdp", "G", "--setting", "generations=2", "--setting", "pop_size=4", "--setting", "select_size=2"] if optimizer == "ne" else ["--budget", "20"]
    rc, _, err = cli(*_evolve(tmp_path, "--optimizer", optimizer, "--setting", setting, *extra))  # "ne" over G: generational
    assert rc == 2 and re.search(message, err) and "genome must hold" not in err, err
    rc, out, _ = cli("settings", "openai-es" if optimizer == "openai-es" else "generational")
    assert "<= 1e100" in out or "0 to 1e100" in out, out


@pytest.mark.slow
def test_ec_mer_refuses_a_policy_other_than_the_one_that_flew_the_data(tmp_path: Path, cli) -> None:
    """S2: learn-model --method ec-mer --policy FILE fitted the closed loop of FILE, a policy that never flew the data
    (their metadata record the baseline), without a word."""
    data, other = tmp_path / "fd.npz", tmp_path / "pol.json"
    assert cli("fly", "--task", "ghh08", "--episodes", "1", "--record", str(data))[0] == 0
    other.write_text(json.dumps({"topology": "slp", "genome": [0.01] * 40}))
    argv = ["learn-model", "--flight-data", str(data), "--method", "ec-mer", "--budget", "2"]
    rc, _, err = cli(*argv, "--out", str(tmp_path / "m1.json"), "--policy", str(other))
    assert rc == 2 and not (tmp_path / "m1.json").exists(), err
    assert f"--policy '{other}' is not the policy that flew flight data '{data}' (they record 'baseline', a different network)" in err, err
    assert "leave --policy out to use the recorded one" in err, err
    rc, out, err = cli(*argv, "--out", str(tmp_path / "m2.json"), "--policy", "baseline")  # the recorded one, given: fine
    assert rc == 0 and "ec-mer model written to" in out, err
