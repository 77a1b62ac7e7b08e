"""The fifteenth bad-input trial's findings in neurohover.evolution: each bad argument of an optimiser, an operator, a
fitness transform or evolve() gives one NeurohoverError naming the value and what is allowed, and a state dict with an
entry no state_dict() wrote is refused by name."""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

from neurohover.errors import NeurohoverError
from neurohover.evolution import SteadyStateNE, SteadyStateSettings, evolve, roulette_weights
from neurohover.evolution.common import TellInfo
from neurohover.evolution.generational import GenerationalNE, GenerationalSettings
from neurohover.evolution.operators import crossover, mutate
from neurohover.evolution.optimisers.cma import CMAES
from neurohover.evolution.optimisers.openai_es import OpenAIES, OpenAIESSettings, centred_ranks
from neurohover.evolution.optimisers.uh_cma import UHCMAES, UHCMASettings


@dataclass(frozen=True)
class _Mutation:
    """Settings of an operator made ad hoc (the settings classes check their own fields)."""

    mutate_frac: object = 0.1
    mutate_std: object = 0.8
    mutate_repl: object = 0.25
    averaging_prob: object = 0.5


def _raises(fragment: str):
    return pytest.raises(NeurohoverError, match=re.escape(fragment))


def test_cmaes_popsize_past_the_population_bound_is_refused() -> None:
    """T15-1: CMAES(g, popsize=10**12) ran on in pycma's constructor; settings refused it, the class did not."""
    with _raises("popsize=1000000000000 must be an integer in 2..100,000"):
        CMAES(np.zeros(40), popsize=10**12)
    with _raises("popsize=True must be an integer >= 2"):
        CMAES(np.zeros(40), popsize=True)
    assert CMAES(np.zeros(40), popsize=np.int64(6)).popsize == 6  # a NumPy integer is a number


def test_cmaes_budget_true_is_refused() -> None:
    """T15-21: CMAES(g, budget=True) was taken as a budget of 1."""
    with _raises("budget=True must be an integer >= 1"):
        CMAES(np.zeros(40), budget=True)
    with _raises("budget=0 must be an integer >= 1"):
        UHCMAES(np.zeros(40), UHCMASettings(), budget=0)
    assert CMAES(np.zeros(40), budget=np.int32(5)).budget == 5


def _optimisers():
    g = np.zeros(40)
    return [
        SteadyStateNE(g, SteadyStateSettings(pop_size=4, elite_size=3)),
        GenerationalNE(g, GenerationalSettings(pop_size=4, select_size=2)),
        CMAES(g, popsize=4),
        OpenAIES(g, OpenAIESSettings(popsize=4)),
    ]


@pytest.mark.parametrize("opt", _optimisers(), ids=lambda o: type(o).__name__)
def test_tell_refuses_info_that_is_no_tell_info(opt) -> None:
    """T15-3: o.tell(returns, {"crashed": None}) was "AttributeError: 'dict' object has no attribute 'crashed'"."""
    b = opt.ask()
    with _raises("info={'crashed': None} is not allowed: give a TellInfo (its crashed, selected, episodes) or None"):
        opt.tell(np.zeros(len(b)), {"crashed": None})
    opt.tell(np.zeros(len(b)), TellInfo())  # the batch is still pending: the refused tell changed nothing


@pytest.mark.parametrize(
    "call, fragment",
    [
        (lambda g, rng: mutate(g, 5, _Mutation()), "rng=5 is not allowed: give a numpy.random.Generator"),
        (lambda g, rng: mutate(g, rng, None), "settings=None is not allowed: give settings with mutate_frac, mutate_std and mutate_repl"),
        (lambda g, rng: mutate("abc", rng, _Mutation()), "genome='abc' is not allowed: give a genome: an array of real numbers (real numbers, not text)"),
        (lambda g, rng: mutate(g, rng, _Mutation(), np.ones(3)), "scale has shape (3,): give one number per gene of the genome, shape (40,)"),
        (lambda g, rng: mutate(g, rng, _Mutation(mutate_frac=2.0)), "mutate_frac=2.0 must be a probability in [0, 1]"),
        (lambda g, rng: mutate(g, rng, _Mutation(mutate_repl=np.nan)), "mutate_repl=nan must be a probability in [0, 1]"),
        (lambda g, rng: mutate(g, rng, _Mutation(mutate_std=-1.0)), "mutate_std=-1.0 must be a finite number >= 0"),
        (lambda g, rng: mutate(g, rng, _Mutation(mutate_std="x")), "mutate_std='x' must be a finite number >= 0"),
        (lambda g, rng: crossover(g, np.zeros(39), rng, _Mutation()), "crossover parents must have the same shape, got (40,) and (39,)"),
        (lambda g, rng: crossover(g, g, rng, _Mutation(averaging_prob="x")), "averaging_prob='x' must be a probability in [0, 1]"),
        (lambda g, rng: crossover(g, g, rng, object()), "is not allowed: give settings with averaging_prob"),
        (lambda g, rng: crossover(g, g, None, _Mutation()), "rng=None is not allowed: give a numpy.random.Generator"),
        (lambda g, rng: crossover(g, [True] * 40, rng, _Mutation()), "b=[True, True"),
    ],
)
def test_operators_name_a_bad_argument(call, fragment: str) -> None:
    """T15-7: mutate and crossover (evolution.__all__) raised AttributeError, NumPy's broadcast or conversion error, numba's
    TypingError, or a plain ValueError, and took mutate_frac=2.0 on an ad-hoc settings object."""
    rng = np.random.default_rng(0)
    with _raises(fragment):
        call(np.zeros(40), rng)
    assert rng.random() == np.random.default_rng(0).random()  # refused before any draw


def test_operators_still_take_numbers_of_any_kind() -> None:
    """T15-7: the checks take what worked before (NumPy numbers, lists, -0.0) and give the same genes."""
    g = np.arange(6.0)
    a = mutate(g, np.random.default_rng(1), _Mutation(mutate_frac=1, mutate_std=np.float32(0.5), mutate_repl=np.float64(0.25)))
    b = mutate(list(g), np.random.default_rng(1), _Mutation(mutate_frac=1.0, mutate_std=float(np.float32(0.5)), mutate_repl=0.25), np.ones((6,)))
    assert np.array_equal(a, b)
    assert np.array_equal(mutate(g, np.random.default_rng(1), _Mutation(mutate_std=-0.0)), mutate(g, np.random.default_rng(1), _Mutation(mutate_std=0.0)))
    assert crossover(g.reshape(2, 3), g.reshape(2, 3), np.random.default_rng(1), _Mutation()).shape == (2, 3)


def test_centred_ranks_refuses_returns_that_are_no_1d_numbers() -> None:
    """T15-8: centred_ranks(np.zeros((2, 2))) was NumPy's ValueError, centred_ranks("ab") an AttributeError."""
    with _raises("returns has shape (2, 2): give a 1-D array of 2 or more returns (real numbers)"):
        centred_ranks(np.zeros((2, 2)))
    with _raises("returns='ab' is not allowed: give a 1-D array of 2 or more returns (real numbers, not text)"):
        centred_ranks("ab")
    with _raises("returns has shape (1,)"):
        centred_ranks(np.zeros(1))  # one return has no rank to scale (0 / 0)
    assert centred_ranks([1, 3, 2]).tolist() == [-0.5, 0.5, 0.0]


def test_evolve_resume_takes_only_true_or_false(tmp_path: Path) -> None:
    """T15-16: resume="no" with an existing checkpoint resumed (its truth); resume="yes" without one said "resume=True needs..."."""
    from neurohover.tasks import get_task_family

    mdp = get_task_family("ghh08").mdp("train:0")
    ck = tmp_path / "ck.json"
    ck.write_text("{}")
    with _raises("resume='no' is not allowed: give True (continue from the checkpoint) or False"):
        evolve(mdp, budget=120, n_steps=20, checkpoint=ck, resume="no")
    assert ck.read_text() == "{}"
    with _raises("resume='yes' is not allowed: give True"):
        evolve(mdp, budget=120, n_steps=20, resume="yes")


@pytest.mark.parametrize("opt", _optimisers(), ids=lambda o: type(o).__name__)
def test_from_state_dict_names_an_unknown_entry(opt) -> None:
    """T15-23: from_state_dict({**o.state_dict(), "zzz": 1}) ignored the unknown entry (a missing one was named)."""
    state = opt.state_dict()
    kind = type(opt).__name__
    with _raises(f"{kind} state dict has unknown entries 'zzz': allowed {', '.join(state)}"):
        type(opt).from_state_dict({**state, "zzz": 1})
    type(opt).from_state_dict(state)  # every entry state_dict() writes is known


def test_generational_state_of_before_the_hall_of_fame_still_loads() -> None:
    """T15-23: a checkpoint written before "parents" and "hall_of_fame" existed is no unknown-entry case."""
    opt = _optimisers()[1]
    state = {k: v for k, v in opt.state_dict().items() if k not in ("parents", "hall_of_fame")}
    assert GenerationalNE.from_state_dict(state).generation == 0


def test_roulette_weights_refuses_an_empty_or_2d_array() -> None:
    """T15-24: roulette_weights(np.zeros(0)) returned empty weights, roulette_weights(np.zeros((2, 2))) 2-D ones."""
    with _raises("returns has shape (0,): give a non-empty 1-D array of returns (real numbers)"):
        roulette_weights(np.zeros(0))
    with _raises("returns has shape (2, 2): give a non-empty 1-D array of returns"):
        roulette_weights(np.zeros((2, 2)))
    assert roulette_weights([-10.0]).shape == (1,)
