"""The fourteenth bad-input trial's findings in neurohover.models, neurohover.netfile, neurohover.sim.reference and
neurohover.procs (T14-12, T14-13, T14-20, T14-21): each bad value is one NeurohoverError naming it and what is allowed."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import neurohover.models as M
from neurohover import procs
from neurohover.errors import NeurohoverError
from neurohover.flightdata import FlightData
from neurohover.netfile import policy_from_net, policy_to_net
from neurohover.policies import baseline_policy
from neurohover.sim.reference import ReferenceMDP, fly_episode, rotation_vector_quaternion
from neurohover.tasks import get_task_family

PARAMS = M.one_substep_params()[0]
NOISE = [0.1] * 6


@pytest.mark.parametrize(
    ("stats", "message"),
    [
        ({"a": object()}, r"model stats entry 'a' = <object object at .*> is not allowed: give strict JSON values, numbers finite \(Object of type object"),
        ({"n": 3, "a": math.nan}, r"model stats entry 'a' = nan is not allowed: give strict JSON values, numbers finite"),
        ({"a": [1, {"b": math.inf}]}, r"model stats entry 'a' = \[1, \{'b': inf\}\] is not allowed"),
        ({"a": 10**400}, r"model stats entry 'a' = 1000000000...\(401 digits\) is not allowed"),  # load() would refuse it
    ],
)
def test_learned_model_refuses_stats_it_cannot_save(stats: dict, message: str, tmp_path) -> None:
    """T14-12: stats={'a': object()} or {'a': nan} were taken, and save() raised json's TypeError or ValueError."""
    with pytest.raises(NeurohoverError, match=message):
        M.LearnedModel(PARAMS, NOISE, "lr", stats=stats)
    model = M.LearnedModel(PARAMS, NOISE, "lr", stats={"n": 3, "e": [0.5, None, "x"]})
    assert M.LearnedModel.load(model.save(tmp_path / "m.json")).stats == model.stats
    with pytest.raises(NeurohoverError, match=r"m2.json.*: model stats entry 'a' = nan is not allowed"):
        (tmp_path / "m2.json").write_text(json.dumps({**model.to_dict(), "stats": {"a": math.nan}}))
        M.LearnedModel.load(tmp_path / "m2.json")


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda: M.check_vector([10**400, 1], 2, "x"), r"x must be 2 finite numbers, got \[1000000"),
        (lambda: M.check_vector(["1", "2"], 2, "x"), r"x must be 2 numbers, got \['1', '2'\]"),
        (lambda: M.check_vector([True, 1], 2, "x"), r"x must be 2 numbers, got \[True, 1\]"),
        (lambda: M.check_vector([1, 2], "2", "x"), r"length='2' is not allowed: give a whole number >= 1 \(how many numbers x holds\)"),
        (lambda: M.check_vector([0.0] * 10**5, 11, "x"), r"x must be 11 numbers, got 100000: \[0\.0, 0\.0, .*\.\.\.$"),  # shortened
        (
            lambda: M.equivalent_params([0.0] * 11, dt="0.01"),
            r"substeps=10 x dt='0.01' is not allowed: give a whole number of substeps >= 1 and a finite step > 0 \(s\) covering 0.1 s",
        ),
        (lambda: M.one_substep_params([0.0] * 11, dt="0.01"), r"substeps=10 x dt='0.01' is not allowed"),
        (lambda: M.one_substep_params(substeps=True, dt=0.1), r"substeps=True x dt=0.1 is not allowed"),
        (lambda: M.equivalent_params([0.0] * 11, [-1] * 6), r"noise std must be >= 0, got \[-1.0, -1.0"),
        (lambda: M.one_substep_params(noise_std=[-1] * 6), r"noise std must be >= 0, got \[-1.0, -1.0"),
        (lambda: M.effective_wind(None), r"axis=None is not allowed: give a WindAxis \(a WindModel's x or y\)"),
        (lambda: M.fit_wind(None, "constant", 0, 0, 0), r"tr=None is not allowed: give the flight data as Transitions"),
        (lambda: M.LearnedModel(PARAMS, NOISE, "lr", seconds=True), r"seconds=True must be a finite number in \[0, "),
    ],
)
def test_model_helpers_name_bad_values(call, message: str) -> None:
    """T14-13: 10**400 was an OverflowError, text and bools were taken as numbers, a length '2' said "must be 2 numbers,
    got 2", dt='0.01' a TypeError, negative stds taken, effective_wind(None) and fit_wind(None, ...) AttributeErrors."""
    with pytest.raises(NeurohoverError, match=message):
        call()


def test_noise_estimates_refuse_residuals_of_another_shape() -> None:
    """T14-13: residuals of shape (3,) were an IndexError, (2, 2) einsum's ValueError, tr=None an AttributeError."""
    tr = M.Transitions(FlightData((np.zeros((21, 12)),), (np.zeros((20, 4)),)))
    given = "is not allowed: give a real array"
    with pytest.raises(NeurohoverError, match=rf"residuals of shape \(3,\) and dtype float64 {given} \(\.\.\., N, 6\) with N = 20"):
        M.noise_from_residuals(tr, np.zeros(3))
    with pytest.raises(NeurohoverError, match=rf"residuals of shape \(2, 2\) and dtype float64 {given} \(N, 6\) with N = 20"):
        M.authors_noise(tr, np.zeros((2, 2)))
    with pytest.raises(NeurohoverError, match=r"tr=None is not allowed: give the Transitions the residuals belong to"):
        M.authors_noise(None, np.zeros((20, 6)))  # type: ignore[arg-type]
    assert M.noise_from_residuals(tr, np.zeros((3, 20, 6)))[0].shape == (3, 6)
    assert M.authors_noise(tr, np.zeros((20, 6))).shape == (6,)


@pytest.mark.parametrize(
    ("old", "new", "message"),
    [
        ("s 12 16 +0", "s 12 16 1_0", r"weight '1_0' is not allowed: give a decimal number in ASCII digits \(like \+0.0367 or -1.5e-3; no '_'\)"),
        ("s 12 16 +0", "s 12 16 0x1", r"weight '0x1' is not allowed: give a decimal number in ASCII digits"),
        ("n 1 0 0", "n 1_0 0 0", r"node id '1_0' is not allowed: give an integer in ASCII digits \(no '_'\)"),
    ],
)
def test_net_files_take_plain_numbers_only(old: str, new: str, message: str) -> None:
    """T14-20: Python's float() and int() read '1_0' as 10: the weight became 10.0 without a word."""
    text = policy_to_net(baseline_policy())
    assert old in text
    with pytest.raises(NeurohoverError, match=r"network file, line \d+: " + message):
        policy_from_net(text.replace(old, new, 1))
    assert policy_from_net(text.replace("s 12 16 +0", "s 12 16 -.5e-1", 1)).genome.tolist().count(-0.05) == 1


REFERENCE = get_task_family("fghh").zero().to_reference()
NORMALS = [[0.0] * 6] * 20


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (
            lambda: fly_episode(REFERENCE, lambda o: [0.0] * 4, [[math.nan] * 6] * 20, 20),
            r"normals\[0\]\[0\] = nan is not allowed: give finite standard normals",
        ),
        (lambda: fly_episode(REFERENCE, lambda o: [0.0] * 4, [[10**400] * 6] * 20, 20), r"normals=\[\[1000000.* is not allowed: give at least 20 rows of 6"),
        (
            lambda: fly_episode(REFERENCE, lambda o: [0.0] * 4, NORMALS, 20, [[0.0] * 12] * 20 + [[math.inf] * 12]),
            r"sensor_normals\[20\]\[0\] = inf is not allowed: give finite standard normals",
        ),
        (
            lambda: ReferenceMDP(params=REFERENCE.params, noise_std=[-1] * 6),
            r"noise_std=\[-1, -1, -1, -1, -1, -1\] is not allowed: give 6 real numbers, all finite and >= 0",
        ),
        (
            lambda: ReferenceMDP(params=REFERENCE.params, noise_std=REFERENCE.noise_std, wind_kind=1, wind=[math.nan] * 8),
            r"wind=\[nan, .*\] is not allowed: give 8 real numbers, all finite",
        ),
        (lambda: rotation_vector_quaternion((math.nan, 0, 0)), r"rv=\(nan, 0, 0\) is not allowed: give 3 real numbers, all finite"),
    ],
)
def test_reference_simulator_refuses_non_finite_numbers(call, message: str) -> None:
    """T14-21: a NaN gust normal flew a NaN return called "not crashed", a negative noise std was taken, a NaN rotation
    vector gave a NaN quaternion (10**400 normals were an OverflowError)."""
    with pytest.raises(NeurohoverError, match=message):
        call()


def test_worker_pool_is_bounded_by_the_cores() -> None:
    """T14-21: worker_pool(10**6) made a pool of a million workers (started as work arrived)."""
    expected = rf"jobs=1000000 is not allowed: give at most {procs.max_jobs()} worker processes \(the cores this process may use\)"
    with pytest.raises(NeurohoverError, match=expected):
        procs.worker_pool(10**6)
