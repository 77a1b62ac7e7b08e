"""The forty-fourth bad-input trial's findings in the evolution helpers and the kernel's fast path (T44-B02, T44-B03,
T44-B04, T44-B09, T44-B10, T44-B21, T44-B22, T44-B23): each bad input gives one NeurohoverError naming the value and
what is allowed, instead of a traceback, a warning or a silent wrong answer; valid input runs as before."""

from __future__ import annotations

import math
import re
import warnings

import numpy as np
import pytest

import neurohover as nh
from neurohover.errors import NeurohoverError
from neurohover.evaluate import PolicyTable, evaluate_jobs, mdp_rows
from neurohover.evolution import seeding
from neurohover.evolution.eonn import EonnSettings, eonn_evolve
from neurohover.evolution.fitness import error_of_fitness, fitness_range, in_fitness_range
from neurohover.evolution.generational import GenerationalSettings
from neurohover.flyer import KernelFlyer

SEED_ALLOWED = "allowed an integer in 0..2**63-1"

#: Each public seeding helper, called with a root seed.
SEEDERS = {
    "optimiser_seed": seeding.optimiser_seed,
    "noise_seed": seeding.noise_seed,
    "mdp_rng": seeding.mdp_rng,
    "validation_seeds": seeding.validation_seeds,
    "reevaluation_seeds": seeding.reevaluation_seeds,
    "child_int": lambda seed: seeding.child_int(seed, 0),
}


# --------------------------------------------------------------------------- T44-B02, T44-B03: the seeding helpers


@pytest.mark.parametrize("bad", [None, [], [1, 2], 1.5, -1, 2**63, "x", True], ids=repr)
@pytest.mark.parametrize("helper", list(SEEDERS))
def test_a_seeding_helper_takes_an_integer_seed_only(helper: str, bad: object) -> None:
    """T44-B02/B03: None (fresh OS entropy: a different "derived" seed every call), [] and lists were taken; 1.5, -1 and
    'x' leaked NumPy's errors. check_seed, the module's own seed check, now checks every seed."""
    with pytest.raises(
        NeurohoverError, match="^" + re.escape(f"seed={nh.errors.brief(bad)} is ") + "(not allowed|out of range): " + re.escape(SEED_ALLOWED) + "$"
    ):
        SEEDERS[helper](bad)


@pytest.mark.parametrize("bad", [None, 1.5, -1, "x"], ids=repr)
def test_child_int_takes_an_integer_key_only(bad: object) -> None:
    with pytest.raises(NeurohoverError, match=r"^key=.* is (not allowed|out of range): allowed an integer in 0\.\.2\*\*63-1$"):
        seeding.child_int(0, bad)


@pytest.mark.parametrize("helper", list(SEEDERS))
def test_a_seeding_helper_takes_numpy_integers_as_the_same_seed(helper: str) -> None:
    for kind in (np.int8, np.int64, np.uint64):
        got, want = SEEDERS[helper](kind(7)), SEEDERS[helper](7)
        if isinstance(want, np.random.Generator):
            got, want = got.random(), want.random()
        assert got == want


def test_the_derived_seeds_are_unchanged() -> None:
    """The checks change nothing a valid seed derives (a run's seeds, hence its results, stay as before)."""
    ss = np.random.SeedSequence(5, spawn_key=(2,))
    assert seeding.noise_seed(5) == int(ss.generate_state(1, np.uint64)[0] >> np.uint64(1))
    assert seeding.mdp_rng(5).random() == np.random.default_rng(np.random.SeedSequence(5, spawn_key=(1,))).random()


# --------------------------------------------------------------------------- T44-B04: the fitness scales


@pytest.mark.parametrize("bad", [-1, 0, 1.5, math.nan, None, "x", True, 10**7 + 1], ids=repr)
def test_fitness_range_takes_a_step_count_only(bad: object) -> None:
    """T44-B04: n_steps=-1 gave bounds for "-1 steps", NaN NaN bounds, None and text a TypeError."""
    with pytest.raises(NeurohoverError, match=r"^n_steps=.* is (not allowed|out of range): allowed an integer in 1\.\.10000000$"):
        fitness_range(bad, "inv-log-error")  # type: ignore[arg-type]


def test_fitness_range_takes_a_numpy_step_count_as_a_python_one() -> None:
    assert fitness_range(np.int16(20), "return") == fitness_range(20, "return")
    assert "its 20 steps" in fitness_range(np.int8(20), "inv-log-error")[2]


@pytest.mark.parametrize("bad", [None, "x", math.nan, math.inf], ids=repr)
def test_in_fitness_range_takes_finite_bounds_only(bad: object) -> None:
    """T44-B04: low=None was a TypeError (NaN bounds held nothing, without a word)."""
    low, high, _ = fitness_range(20, "inv-log-error")
    with pytest.raises(NeurohoverError, match=r"^low=.* is not allowed: allowed a finite number \(a bound of fitness_range\)$"):
        in_fitness_range(0.1, bad, high)  # type: ignore[arg-type]
    with pytest.raises(NeurohoverError, match=r"^high=.* is not allowed: allowed a finite number"):
        in_fitness_range(0.1, low, bad)  # type: ignore[arg-type]


def test_in_fitness_range_refuses_text_values_and_crossed_bounds() -> None:
    with pytest.raises(NeurohoverError, match=r"^values='x' is not allowed: give fitness values"):
        in_fitness_range("x", 0.0, 1.0)  # type: ignore[arg-type]
    with pytest.raises(NeurohoverError, match=r"^low=2\.0 is out of range: allowed a number at most high=1\.0"):
        in_fitness_range(0.5, 2.0, 1.0)
    assert in_fitness_range(np.array([0.5, math.nan, 2.0]), np.float32(0.0), 1).tolist() == [True, False, False]


def test_error_of_fitness_refuses_text() -> None:
    """T44-B04: error_of_fitness('x') was NumPy's ValueError."""
    with pytest.raises(NeurohoverError, match=r"^fitness='x' is not allowed"):
        error_of_fitness("x", "return")  # type: ignore[arg-type]
    assert error_of_fitness(np.array([1.0]), "inv-log-error") == pytest.approx(math.e)


# --------------------------------------------------------------------------- T44-B21, T44-B22, T44-B23: eonn

SMALL = EonnSettings(pop_size=4, keep=3, generations=1, tournament_size=2)


@pytest.mark.parametrize(
    ("args", "message"),
    [
        ((None, "P", SMALL), r"^mdp=None is not allowed: eonn_evolve flies one MDP"),
        (("train:0", "P", SMALL), r"^mdp='train:0' is not allowed: eonn_evolve flies one MDP"),
        (("M", None, SMALL), r"^prototype=None is not allowed: give a Policy"),
        (("M", "baseline", SMALL), r"^prototype='baseline' is not allowed: give a Policy"),
        (("M", "P", 5), r"^settings=5 is not allowed: give an EonnSettings, a dict of its fields or None"),
        (("M", "P", {"pop_size": 4}), r"^bad eonn settings: keep=49 is out of range"),
        (("M", "P", {"popsize": 4}), r"^unknown eonn setting\(s\) 'popsize': allowed pop_size, keep"),
    ],
)
def test_eonn_evolve_checks_its_mdp_prototype_and_settings(args: tuple, message: str) -> None:
    """T44-B21: each was an AttributeError."""
    mdp = nh.get_task_family("ghh08").zero()
    values = {"M": mdp, "P": nh.baseline_policy()}
    mdp_arg, proto, settings = (values.get(a, a) if isinstance(a, str) else a for a in args)
    with pytest.raises(NeurohoverError, match=message):
        eonn_evolve(mdp_arg, proto, settings=settings, n_steps=5)


def test_eonn_evolve_refuses_a_drifting_mdp() -> None:
    from neurohover.tasks import Drift

    mdp = nh.get_task_family("ghh08").zero().with_drift(Drift(0.01, (("D_w", 0.8),)))
    with pytest.raises(NeurohoverError, match="has drifting dynamics"):
        eonn_evolve(mdp, nh.baseline_policy(), settings=SMALL, n_steps=5)


def test_eonn_evolve_takes_a_dict_of_settings_as_the_settings() -> None:
    mdp = nh.get_task_family("ghh08").zero()
    fields = {"pop_size": 4, "keep": 3, "generations": 1, "tournament_size": 2}
    one = eonn_evolve(mdp, nh.baseline_policy(), settings=fields, seed=2, n_steps=5)
    two = eonn_evolve(mdp, nh.baseline_policy(), settings=SMALL, seed=2, n_steps=5)
    assert one == two and one.episodes == 5


@pytest.mark.parametrize("kind", [np.int8, np.int64, np.uint32])
def test_eonn_settings_take_numpy_integers_as_python_ints(kind) -> None:
    """T44-B22: np.int64(50) was refused, where GenerationalSettings takes it."""
    s = EonnSettings(pop_size=kind(6), keep=kind(5), generations=kind(2), tournament_size=kind(3))
    assert s == EonnSettings(pop_size=6, keep=5, generations=2, tournament_size=3)
    assert all(type(getattr(s, name)) is int for name in ("pop_size", "keep", "generations", "tournament_size"))
    assert type(GenerationalSettings(pop_size=kind(60)).pop_size) is int  # the neighbour's behaviour, matched


def test_eonn_settings_store_numpy_floats_as_python_floats_without_a_warning() -> None:
    """T44-B22/B23: np.float32(0.5) was kept as a NumPy scalar, and mutate_std's range check warned "overflow
    encountered in cast" (a traceback under -W error)."""
    names = ("mutate_prob", "mutate_frac", "mutate_std", "mutate_repl", "averaging_prob", "spawn_frac", "spawn_std")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        s = EonnSettings(**{name: np.float32(0.5) for name in names})
    assert all(type(getattr(s, name)) is float and getattr(s, name) == 0.5 for name in names)
    assert "np.float32" not in repr(s)


# --------------------------------------------------------------------------- T44-B09: KernelFlyer.fly


def _flyer_inputs() -> tuple[KernelFlyer, np.ndarray, np.ndarray]:
    genome = nh.prototype("slp", "baseline").genome[None]
    return KernelFlyer("slp", 0, 10), np.vstack([genome, genome]), mdp_rows(nh.get_task_family("ghh08").zero())


@pytest.mark.parametrize("bad", [0, -1, 2**70, 1.5, None, True], ids=repr)
def test_kernel_flyer_takes_a_job_count_in_range_only(bad: object) -> None:
    """T44-B09: 0 was numba's thread-count ValueError, 2**70 NumPy's "maximum allowed dimension exceeded"."""
    flyer, genomes, rows = _flyer_inputs()
    with pytest.raises(NeurohoverError, match=r"^n_jobs=.* is (not allowed|out of range): allowed an integer in 1\.\.100,000,000 \(episodes in one call\)$"):
        flyer.fly(genomes, rows, None, None, bad)  # type: ignore[arg-type]


def test_kernel_flyer_takes_a_small_numpy_job_count() -> None:
    """T44-B09: np.int8(5) was an OverflowError in the index room check."""
    flyer, genomes, rows = _flyer_inputs()
    got = flyer.fly(genomes, rows, None, None, np.int8(5)).copy()
    assert got.shape == (5,) and flyer.episodes == 5 and type(flyer.episodes) is int
    assert np.array_equal(got, KernelFlyer("slp", 0, 10).fly(genomes, rows, None, None, 5))


@pytest.mark.parametrize("where", ["policy_index", "mdp_index"])
def test_kernel_flyer_takes_range_as_its_only_text(where: str) -> None:
    """T44-B09: any text flew as "range" ('SLP' included)."""
    flyer, genomes, rows = _flyer_inputs()
    index = {"policy_index": None, "mdp_index": None, where: "SLP"}
    with pytest.raises(NeurohoverError, match=rf"^{where}='SLP' is not allowed: give None \(0 for every job\), 'range'"):
        flyer.fly(genomes, rows, index["policy_index"], index["mdp_index"], 1)
    assert flyer.fly(genomes, rows, "range", None, 2).shape == (2,)


# --------------------------------------------------------------------------- T44-B10: evaluate_jobs' job count


@pytest.mark.parametrize(("policy_index", "shown"), [(np.array([], dtype=int), "(0,)"), (np.int64(0), "()"), ([], "(0,)")], ids=["empty", "scalar", "list"])
def test_evaluate_jobs_names_policy_index_as_the_job_count(policy_index, shown: str) -> None:
    """T44-B10: an empty or scalar policy_index said "mdp_index has 4 entries but there are 0 jobs", blaming mdp_index."""
    table = PolicyTable.from_policies([nh.baseline_policy()])
    mdps = nh.get_task_family("ghh08").training_mdps()[:1]
    with pytest.raises(NeurohoverError, match=r"^mdp_index has 4 entries but policy_index=.* \(shape " + re.escape(shown) + r"\) sets the job count, "):
        evaluate_jobs(table, mdps, policy_index, np.zeros(4, int), np.arange(4), n_steps=10)
