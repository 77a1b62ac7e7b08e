"""The seventeenth bad-input trial's findings in the evolution package and the NEAT integration (T17-1's evolution
part, T17-2, T17-3, T17-4, T17-6, T17-9): each bad input gives one clear NeurohoverError naming the value and what is
allowed, instead of a traceback, a hang or a silent wrong answer; valid input runs as before."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from neurohover.errors import NeurohoverError, brief
from neurohover.evolution import Resampling, bandits, races
from neurohover.evolution.config import check_budget, parse_resampling
from neurohover.evolution.evolve import evolve
from neurohover.evolution.fitness import episode_fitness, error_of_fitness
from neurohover.evolution.optimisers.cma import CMAES, CMASettings
from neurohover.evolution.optimisers.uh_cma import UHCMASettings
from neurohover.evolution.seeding import check_seed
from neurohover.integrations.neat import evolve_topology
from neurohover.tasks import get_task_family

FGHH = get_task_family("fghh")


def _raises(fragment: str):
    return pytest.raises(NeurohoverError, match=re.escape(fragment))


def _zeros(indices: np.ndarray) -> np.ndarray:
    return np.zeros(len(indices))


# --------------------------------------------------------------------------- T17-1: np.timedelta64 as a number


@pytest.mark.parametrize("span", [np.timedelta64(4), np.timedelta64(5, "s")], ids=["generic", "seconds"])
@pytest.mark.parametrize(
    "call, fragment",
    [
        (lambda v: check_seed(v), "seed=np.timedelta64("),
        (lambda v: CMAES(np.zeros(3), seed=v), "seed=np.timedelta64("),
        (lambda v: CMASettings(popsize=v), "CMA-ES popsize=np.timedelta64("),
        (lambda v: UHCMASettings(reevaluations=v), "UH-CMA-ES reevaluations=np.timedelta64("),
        (lambda v: check_budget(v), "budget=np.timedelta64("),
        (lambda v: evolve(FGHH.zero(), budget=10, n_steps=v), "n_steps=np.timedelta64("),
        (lambda v: evolve_topology(FGHH.zero(), budget=40, seed=v), "seed=np.timedelta64("),
        (lambda v: episode_fitness(np.array([v]), "return"), "real numbers, not time spans"),
    ],
)
def test_time_spans_are_no_numbers(call, fragment: str, span) -> None:
    """T17-1: np.timedelta64 is a np.signedinteger, so the `isinstance(x, (int, np.integer))` checks passed it: a seed
    of np.timedelta64(4) was taken as 4 (a unit's one was int()'s TypeError), and episode_fitness read time spans as
    returns. Every integer check now goes through errors.whole_number, every array of returns through as_floats."""
    with _raises(fragment):
        call(span)
    assert check_seed(np.int64(4)) == 4 and CMASettings(popsize=np.int64(6)).popsize == 6 and check_budget(np.uint8(9)) == 9
    assert episode_fitness(np.array([-2.0]), "return").tolist() == [-2.0]


# --------------------------------------------------------------------------- T17-2: Resampling checks its fields


@pytest.mark.parametrize(
    "fields, fragment",
    [
        ({"kind": "fixed", "k": -5}, "Resampling k=-5 is not allowed: give fixed resampling's K, an integer in 1..100,000"),
        ({"kind": "fixed", "k": 100_001}, "Resampling k=100001 is not allowed"),
        ({"kind": "nope"}, "Resampling kind='nope' is not allowed: allowed fixed, race, lucb, kl-lucb"),
        ({"kind": "fixed", "k": np.timedelta64(2)}, "Resampling k=np.timedelta64(2) is not allowed"),
        ({"kind": "fixed", "k": "5"}, "Resampling k='5' is not allowed"),
        ({"kind": "fixed", "k": True}, "Resampling k=True is not allowed"),
        ({"kind": "fixed", "k": 2, "auto": "no"}, "Resampling auto='no' is not allowed: give True"),
        ({"kind": "fixed", "k": 2, "delta": 0.5}, "Resampling delta=0.5 is not allowed: fixed resampling has none"),
        ({"kind": "race", "delta": 1.5}, "Resampling delta=1.5 is not allowed: give a number strictly between 0 and 1"),
        ({"kind": "race", "delta": None}, "Resampling delta=None is not allowed"),
        ({"kind": "race", "delta": 0.5, "k": 3}, "Resampling k=3 is not allowed: give 1 (kind='race' uses no K)"),
        ({"kind": "race", "delta": 0.5, "k": 11, "auto": True}, "Resampling k=11 is not allowed: give race:auto's K, an integer in 1..10"),
        ({"kind": "race", "delta": 0.5, "rule": "x"}, "Resampling rule='x' is not allowed"),
        ({"kind": "lucb", "delta": 0.1, "rule": "authors"}, "Resampling rule='authors' is not allowed"),
        ({"kind": "lucb", "delta": 0.1, "auto": True}, "Resampling auto=True is for kind='race'"),
    ],
)
def test_resampling_checks_its_fields(fields: dict, fragment: str) -> None:
    """T17-2: Resampling checked nothing: k=-5 was NumPy's "negative dimensions are not allowed" mid-run, kind='nope' a
    TypeError in str(), k=np.timedelta64(2) "Can't hash generic timedelta64", k='5' a message of '5555...', k=True and
    auto='no' were taken. It now applies parse_resampling's rules (one check for both)."""
    with _raises(fragment):
        Resampling(**fields)
    assert str(Resampling("fixed", np.int64(3))) == "fixed:3" and type(Resampling("fixed", np.int64(3)).k) is int
    assert str(Resampling("race", delta=np.float32(0.5), rule="authors")) == "race:0.5:authors"
    assert Resampling("race", 5, 0.5, auto=True) == parse_resampling("race:auto") and parse_resampling("kl-lucb:0.1") == Resampling("kl-lucb", delta=0.1)
    with _raises("bad resampling 'fixed:0': K must be an integer in 1..100,000"):
        parse_resampling("fixed:0")


@pytest.mark.parametrize("spec", ["race:" + "9" * 5000, "x" * 5000, "race:0.5:" + "q" * 5000, "\u0661" * 5000])
def test_resampling_refusal_shortens_a_long_spec(spec: str) -> None:
    """A 5,000-character resampling spec was echoed whole (twice for a bad rule): now shortened as every echoed value is
    (errors.brief), with its length named."""
    with pytest.raises(NeurohoverError) as refused:
        parse_resampling(spec)
    assert len(str(refused.value)) < 700 and "(5,0" in str(refused.value)


# --------------------------------------------------------------------------- T17-3, T17-4: caps on sizes and halvings


@pytest.mark.parametrize("n", [10**13, 2**62, 2**63, np.uint64(2**64 - 1)], ids=["1e13", "2^62", "2^63", "uint64-max"])
@pytest.mark.parametrize(
    "call",
    [
        lambda n: races.fixed_resampling(_zeros, n, 2),
        lambda n: races.selection_race(_zeros, n, 2, 0.1),
        lambda n: bandits.top_mu_bandit(_zeros, n, 2, 0.1),
    ],
    ids=["fixed", "race", "bandit"],
)
def test_races_cap_the_candidates_by_memory(call, n) -> None:
    """T17-3: no cap on n_candidates: 10**13 was a MemoryError of 72.8 TiB, 2**62 NumPy's "array is too big",
    np.uint64(2**64-1) "Maximum allowed size exceeded", and 2**63 silently an empty result of 2**64 episodes. The
    candidates' arrays must now fit in half the memory free, and the message says how many do."""
    with _raises(f"n_candidates={int(n)} is too many: at most"):
        call(n)
    assert races.fixed_resampling(_zeros, 3, 2).episodes_spent == 6
    assert len(races.selection_race(_zeros, 6, 2, 0.1, t_limit=3).selected) == 2
    assert len(bandits.top_mu_bandit(_zeros, 6, 2, 0.1, t_limit=3).selected) == 2


@pytest.mark.parametrize("iterations", [10**13, 2**63, np.uint64(2**64 - 1), 10_001])
def test_kl_bounds_caps_its_halvings(iterations) -> None:
    """T17-4: kl_bounds(..., iterations=10**13) ran without end (so did 2**63 and np.uint64(2**64-1)); the halvings
    are now capped at MAX_BISECTIONS (10,000), named in the message."""
    with _raises(f"iterations={brief(iterations)} must be an integer in 1..10,000 (halvings)"):
        bandits.kl_bounds(np.array([0.5]), np.array([3]), 0.1, iterations=iterations)
    lower, upper = bandits.kl_bounds(np.array([0.5]), np.array([3]), 0.1, iterations=bandits.MAX_BISECTIONS)
    assert 0.0 <= lower[0] < 0.5 < upper[0] <= 1.0


# --------------------------------------------------------------------------- T17-6: a scale that is no text


@pytest.mark.parametrize("scale", [np.ma.masked, np.array("return"), b"return", None], ids=["masked", "0-d array", "bytes", "None"])
def test_fitness_scale_must_be_text(scale) -> None:
    """T17-6: episode_fitness(returns, np.ma.masked) returned the inv-log-error result as though that scale were named:
    a comparison with np.ma.masked is masked, so neither `== "return"` nor `!= "inv-log-error"` held. A scale that is
    no text is now refused, by error_of_fitness too (which read any scale but "return" as inv-log-error)."""
    with _raises("unknown fitness scale"):
        episode_fitness(np.array([-1.0]), scale)
    with _raises("unknown fitness scale"):
        error_of_fitness(0.2, scale)
    with _raises("unknown fitness scale 'log'"):
        error_of_fitness(0.2, "log")
    assert episode_fitness(np.array([-100.0]), "inv-log-error")[0] == pytest.approx(1 / np.log(100.0))
    assert error_of_fitness(episode_fitness(np.array([-100.0]), "inv-log-error"), "inv-log-error")[0] == pytest.approx(100.0)


# --------------------------------------------------------------------------- T17-9: intervals without their partner


@pytest.mark.parametrize(
    "kwargs, fragment",
    [
        ({"checkpoint_every_s": 5}, "checkpoint_every_s=5 needs checkpoint= (the file it writes)"),
        ({"progress_every_s": 5}, "progress_every_s=5 needs progress= (the callable it paces)"),
        ({"checkpoint_every_s": True, "checkpoint": "x.json"}, "checkpoint_every_s=True must be a number > 0 (seconds)"),
        ({"progress_every_s": True, "progress": print}, "progress_every_s=True is not a number"),  # a type, not a range (T33-B16)
    ],
)
def test_intervals_need_their_partner(kwargs: dict, fragment: str, tmp_path: Path, monkeypatch) -> None:
    """T17-9: checkpoint_every_s without checkpoint=, and progress_every_s without progress=, were ignored without a
    word, and checkpoint_every_s=True was taken as 1 second. Their defaults are now None (the usual 60 s and 0.2 s), so
    one given alone is refused, as a bool is."""
    monkeypatch.chdir(tmp_path)
    with _raises(fragment):
        evolve(FGHH.zero(), budget=10, n_steps=5, **kwargs)
    seen: list = []
    result = evolve(FGHH.zero(), budget=10, n_steps=5, checkpoint=tmp_path / "c.json", checkpoint_every_s=5, progress=seen.append, progress_every_s=0)
    assert result.episodes >= 10 and seen and (tmp_path / "c.json").is_file()
