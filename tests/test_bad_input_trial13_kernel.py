"""The thirteenth trial's findings on the kernel's Python entry points (F1, F17, F18: KernelFlyer, launch.Batch and the
launch helpers; F6, F7: neurohover.sim.reference and neurohover.sim.rng): each bad value is one NeurohoverError naming it
and what is allowed, checked before the kernel runs (an out-of-range index read past an array and killed the process)."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest

from neurohover import get_task_family, launch
from neurohover.errors import NeurohoverError
from neurohover.evaluate import evaluate_jobs, mdp_rows
from neurohover.flyer import KernelFlyer
from neurohover.policies import baseline_policy
from neurohover.sim.kernel import GENOME_WIDTH
from neurohover.sim.reference import ReferenceMDP, competition_time, fly_episode, rotation_vector_quaternion
from neurohover.sim.rng import episode_normals, sensor_normals

ROWS = mdp_rows([get_task_family("ghh08").zero()])
GENOMES = baseline_policy().genome[None, :]


def batch(**changed) -> launch.Batch:
    genomes = np.zeros((1, GENOME_WIDTH))
    genomes[0, : GENOMES.shape[1]] = GENOMES
    one = np.zeros(1, dtype=np.int64)
    given = dict(rows=ROWS, kinds=one, genomes=genomes, policy_index=one, mdp_index=one, episode_index=one, seed=0, n_steps=20)
    return launch.Batch(**{**given, **changed})


@pytest.mark.parametrize(
    ("policy_index", "mdp_index", "n_jobs", "message"),
    [
        (np.array([10**6]), None, 1, "policy_index holds 1000000, out of range: allowed 0..0"),
        (np.array([1]), None, 1, "policy_index holds 1, out of range: allowed 0..0"),  # past the genomes given, inside the buffer
        (None, np.array([10**6, 0]), 2, "mdp_index holds 1000000, out of range: allowed 0..0"),
        ("range", None, 2, "policy_index holds 1, out of range: allowed 0..0"),
    ],
)
def test_kernel_flyer_refuses_job_indices_out_of_range(policy_index, mdp_index, n_jobs: int, message: str) -> None:
    """F1: KernelFlyer.fly with a policy or MDP index past the arrays died of SIGSEGV (exit 139, no message)."""
    with pytest.raises(NeurohoverError, match=message):
        KernelFlyer("slp", 0, 20).fly(GENOMES, ROWS, policy_index, mdp_index, n_jobs)


def test_kernel_flyer_refuses_negative_episode_indices_and_job_counts() -> None:
    """F1: an episode index -1 flew (wrapped to 2**64-1), n_jobs=-1 flew all but one of the buffer's jobs."""
    flyer = KernelFlyer("slp", 0, 20)
    with pytest.raises(NeurohoverError, match=r"episode_index holds negative values \(min -1\); allowed >= 0"):
        flyer.fly(GENOMES, ROWS, None, None, 1, np.array([-1]))
    with pytest.raises(NeurohoverError, match=r"n_jobs=-1 is out of range: allowed an integer in 1\.\.100,000,000"):  # 1..: T44-B09
        flyer.fly(GENOMES, ROWS, None, None, -1)
    assert flyer.fly(GENOMES, ROWS, None, None, 1).shape == (1,)  # a good call still flies


@pytest.mark.parametrize(
    ("changed", "message"),
    [
        ({"mdp_index": np.array([10**6])}, "mdp_index holds 1000000, out of range: allowed 0..0"),
        ({"policy_index": np.array([3])}, "policy_index holds 3, out of range: allowed 0..0"),
        ({"kinds": np.array([99])}, r"Batch.kinds holds 99, not a policy kind: allowed 0 \(slp\), 1 \(mlp\)"),
        ({"episode_index": np.array([-1])}, r"episode_index holds negative values \(min -1\); allowed >= 0"),
        ({"n_steps": -5}, "n_steps=-5 is out of range: allowed an integer in 1..10000000"),
        ({"seed": -1}, r"seed=-1 is out of range: allowed an integer in 0..2\*\*63-1"),
    ],
)
def test_batch_refuses_what_the_kernel_would_misread(changed: dict, message: str) -> None:
    """F1: launch.launch(Batch(...)) with an index out of range segfaulted; kind 99 and episode -1 flew, n_steps=-5 returned 0.0."""
    with pytest.raises(NeurohoverError, match=message):
        launch.launch(batch(**changed), launch.Flown.empty(1))


def test_batch_of_good_jobs_still_flies_and_numpy_scalars_are_taken() -> None:
    """F1: the checks refuse only bad values: np.int64 n_steps and np.uint64 seed fly as their ints do."""
    out = launch.Flown.empty(1)
    launch.launch(batch(n_steps=np.int64(20), seed=np.uint64(0)), out)
    assert out.steps[0] == 20


def test_evaluate_jobs_reaches_the_same_one_check() -> None:
    """F1: evaluate_jobs keeps its messages, now from the one check every launch makes (launch.check_job_indices)."""
    mdp = get_task_family("ghh08").zero()
    with pytest.raises(NeurohoverError, match="policy_index holds 5, out of range: allowed 0..0"):
        evaluate_jobs([baseline_policy()], mdp, [5], [0], [0], n_steps=20)
    with pytest.raises(NeurohoverError, match=r"mdp_index holds negative values \(min -1\); allowed >= 0"):
        evaluate_jobs([baseline_policy()], mdp, [0], [-1], [0], n_steps=20)


@pytest.mark.parametrize("n", [-5, 1.5, "a", True])
def test_reserve_refuses_what_is_not_a_count(n) -> None:
    """F17: reserve(-5) set next_index to -5 (indices already flown handed out again), reserve(1.5) made it a float."""
    flyer = KernelFlyer("slp", 0, 20)
    with pytest.raises(NeurohoverError, match=f"n={n!r} is not allowed: give the number of episode indices to reserve, an integer >= 0"):
        flyer.reserve(n)
    assert flyer.next_index == 0
    assert flyer.reserve(np.int64(2)) == 0 and flyer.next_index == 2 and type(flyer.next_index) is int


def test_launch_helpers_refuse_what_is_not_their_arrays() -> None:
    """F18: rows_alike of no rows was an IndexError, of a list a TypeError; use_lanes(m_idx=None) and can_park(None) an
    AttributeError / TypeError; a Batch of lists an AttributeError and of a wrong width a plain ValueError."""
    with pytest.raises(NeurohoverError, match=r"rows=an array of shape \(0, 36\) is not allowed: give a numpy array of MDP rows"):
        launch.rows_alike(np.zeros((0, 36)))
    with pytest.raises(NeurohoverError, match=r"rows=\[\[1.0\]\] is not allowed"):
        launch.rows_alike([[1.0]])  # type: ignore[arg-type]
    with pytest.raises(NeurohoverError, match="m_idx=None is not allowed: give a 1-D numpy array of each job's MDP row"):
        launch.use_lanes("cpu", ROWS, None)  # type: ignore[arg-type]
    with pytest.raises(NeurohoverError, match="rows=None is not allowed"):
        KernelFlyer("slp", 0, 20).can_park(None)  # type: ignore[arg-type]
    with pytest.raises(NeurohoverError, match=r"Batch.rows=\[\[0\]\] is not allowed: give a 2-d float64 numpy array with 36 columns"):
        launch.Batch([[0]], [0], [[0]], [0], [0], [0], 0, 1)  # type: ignore[arg-type]
    with pytest.raises(NeurohoverError, match=r"Batch.rows=a 2-d float64 array of shape \(1, 5\) is not allowed"):
        batch(rows=np.zeros((1, 5)))
    assert launch.rows_alike(ROWS) and KernelFlyer("slp", 0, 20).can_park(ROWS)


MDP = get_task_family("fghh").zero().to_reference()
NORMALS = [[0.0] * 6] * 20


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (
            lambda: fly_episode(MDP, lambda o: [0.0] * 3, NORMALS, 20),
            r"the policy's action at step 0 is \[0.0, 0.0, 0.0\], not allowed: a policy gives 4 numbers",
        ),
        (lambda: fly_episode(MDP, lambda o: [0.0] * 4, [[0.0] * 3] * 20, 20), r"normals of shape \(20, 3\) is not allowed: give at least 20 rows of 6 numbers"),
        (lambda: fly_episode(MDP, lambda o: [0.0] * 4, NORMALS[:5], 20), r"normals of shape \(5, 6\) is not allowed"),
        (
            lambda: fly_episode(MDP, lambda o: [0.0] * 4, NORMALS, 20, [[0.0] * 12] * 5),
            r"sensor_normals of shape \(5, 12\) is not allowed: give at least 21 rows",
        ),
        (lambda: fly_episode(MDP, None, NORMALS, 20), "policy=None is not allowed"),
        (lambda: fly_episode(None, lambda o: [0.0] * 4, NORMALS, 20), "mdp=None is not allowed: give a ReferenceMDP"),
        (lambda: fly_episode(MDP, lambda o: [0.0] * 4, NORMALS, -1), "n_steps=-1 is not allowed: give an integer in 1..10000000"),
        (lambda: ReferenceMDP(params=[0.0] * 3, noise_std=[0] * 6), r"params=\[0.0, 0.0, 0.0\] is not allowed: give 11 real numbers"),
        (lambda: ReferenceMDP(params=MDP.params, noise_std=MDP.noise_std, substeps=0), "substeps=0 is not allowed: give an integer >= 1"),
        (lambda: rotation_vector_quaternion((1,)), r"rv=\(1,\) is not allowed: give 3 real numbers"),
        (lambda: competition_time(-1, 0), r"step=-1 is not allowed: give an integer >= 0"),
        (lambda: competition_time("a", 0), "step='a' is not allowed"),
    ],
)
def test_reference_simulator_refuses_what_it_cannot_fly(call, message: str) -> None:
    """F6, F7: the reference simulator took no checks: 3 actions or params were an unpack ValueError, short normals an
    IndexError mid-episode, n_steps=-1 and substeps=0 flew nothing and returned (0.0, False), competition_time(-1, 0) -0.1."""
    with pytest.raises(NeurohoverError, match=message):
        call()


def test_reference_simulator_takes_numpy_scalars_and_fractions() -> None:
    """F6: the checks refuse only bad values: np.int64 steps and a Fraction in a rotation vector are taken."""
    assert competition_time(np.int64(3), 2) == 0.32
    assert rotation_vector_quaternion((Fraction(1, 10), 0, np.float32(0)))[0] == pytest.approx(0.04997916927067833)
    assert fly_episode(MDP, lambda o: [0.0] * 4, NORMALS, np.int64(2))[0] < 0


@pytest.mark.parametrize(
    ("args", "message"),
    [
        ((0, 0, -1), r"n_steps=-1 is not allowed: give an integer in 1..10,000,001"),
        ((0.5, 0, 2), r"seed=0.5 is not allowed: give an integer in 0..2\*\*63-1"),
        ((2**64, 0, 2), r"seed=18446744073709551616 is not allowed"),
        ((-1, 0, 2), r"seed=-1 is not allowed"),  # wrapped to 2**64-1
        ((0, -1, 2), r"episode=-1 is not allowed"),
    ],
)
def test_episode_normals_refuse_what_has_no_stream(args: tuple, message: str) -> None:
    """F6, F7: a negative count was NumPy's negative dimensions, a float seed numba's typing dump, 2**64 an
    OverflowError, a negative seed wrapped silently."""
    with pytest.raises(NeurohoverError, match=message):
        episode_normals(*args)


def test_sensor_normals_refuse_a_count_or_width_of_nothing() -> None:
    """F6, F7: sensor_normals(0, 0, -2) was NumPy's ValueError, per_reading=0 gave (2, 0) rows of nothing."""
    with pytest.raises(NeurohoverError, match="n_readings=-2 is not allowed"):
        sensor_normals(0, 0, -2)
    with pytest.raises(NeurohoverError, match="per_reading=0 is not allowed: give 12, or 13 where the sensor has a dropout"):
        sensor_normals(0, 0, 2, 0)
    assert sensor_normals(np.uint64(0), np.uint64(0), 2, 13).shape == (2, 13)
    assert (episode_normals(3, 2, 4) == episode_normals(np.uint64(3), np.uint64(2), 4)).all()
