"""The fifteenth bad-input trial's findings in neurohover.models and neurohover.sim.reference (T15-12, T15-17's WindAxis,
T15-27, T15-29's flyable_substeps): each bad value is one NeurohoverError naming it and what is allowed."""

from __future__ import annotations

import re

import numpy as np
import pytest

import neurohover.models as M
import neurohover.sim.reference as reference
from neurohover.errors import NeurohoverError
from neurohover.models.wind import WindAxis
from neurohover.policies import baseline_policy
from neurohover.sim.reference import ReferenceMDP, fly_episode

PARAMS = M.one_substep_params()[0]
NOISE = (0.1,) * 6


def test_reference_rotation_helpers_are_private() -> None:
    """T15-12: quat_mul, quat_conj, rotate and rotate_inverse took 'abcd' or a 2-tuple to a TypeError or ValueError; they
    are the substep loop's internals, now private, and __all__ names the module's checked entry points."""
    for name in ("quat_mul", "quat_conj", "rotate", "rotate_inverse"):
        assert not hasattr(reference, name)
    assert set(reference.__all__) >= {"ReferenceMDP", "fly_episode", "competition_time", "rotation_vector_quaternion"}
    assert all(not name.startswith("_") and hasattr(reference, name) for name in reference.__all__)


@pytest.mark.parametrize("value", [np.float32(1), np.int64(1), np.float64(1.5)])
def test_wind_axis_takes_numpy_reals(value) -> None:
    """T15-17: WindAxis(amplitude=np.float32(1)) and np.int64(1) were refused though they are numbers."""
    axis = WindAxis(amplitude=value, omega=value)
    assert type(axis.amplitude) is float and axis.amplitude == float(value) and type(axis.omega) is float


@pytest.mark.parametrize(("value", "shown"), [(True, "True"), (np.bool_(True), "np.True_"), ("1", "'1'"), (float("nan"), "nan")])
def test_wind_axis_refuses_bools_and_text(value, shown: str) -> None:
    """T15-17: bools stay refused beside NumPy reals."""
    with pytest.raises(NeurohoverError, match=re.escape(f"wind amplitude={shown} must be a finite number")):
        WindAxis(amplitude=value)


@pytest.mark.parametrize(
    ("sensor", "message"),
    [
        ((0, 0, 0, 0, 0, 1.5, 0), "sensor delay=1.5 is not allowed: give a whole number of control steps in 0..10"),
        ((0, 0, 0, 0, 0, 11, 0), "sensor delay=11.0 is not allowed: give a whole number of control steps in 0..10"),
        ((0.1, 0, 0, 0, 1.0, 0, 0), "sensor=(0.1, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0) is not allowed: give 4 stds >= 0, a correlation in [0, 1)"),
        ((0, 0, 0, 0, 0, 0, -0.5), "and a dropout in [0, 1)"),
    ],
)
def test_reference_mdp_refuses_a_sensor_it_cannot_read(sensor, message: str) -> None:
    """T15-27: a delay of 1.5 control steps was flown as 1 without a word; a correlation of 1 took a negative root."""
    with pytest.raises(NeurohoverError, match=re.escape(message)):
        ReferenceMDP(PARAMS, NOISE, sensor=sensor)
    assert ReferenceMDP(PARAMS, NOISE, sensor=(0.1, 0, 0, 0, 0.5, np.int64(2), 0.1)).sensor[5] == 2


def test_fly_episode_computes_float32_normals_in_float64() -> None:
    """T15-27: float32 normals flew the episode in float32 and returned an np.float32."""
    rm = ReferenceMDP(PARAMS, NOISE)
    normals = np.random.default_rng(1).standard_normal((5, 6))
    total32, _, obs32 = fly_episode(rm, baseline_policy().act, normals.astype(np.float32), n_steps=5)
    total64, _, _ = fly_episode(rm, baseline_policy().act, normals.astype(np.float32).astype(np.float64), n_steps=5)
    assert isinstance(total32, float) and total32 == total64  # np.float32 is no float; the policy's np.float64 is
    assert all(isinstance(x, float) for x in obs32[-1])


def test_fly_episode_refuses_sensor_normals_for_an_exact_sensor() -> None:
    """T15-27: sensor normals given for an MDP of exact sensors were ignored without a word."""
    exact = ReferenceMDP(PARAMS, NOISE)
    with pytest.raises(NeurohoverError, match=re.escape("sensor_normals are not allowed with the exact sensor (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)")):
        fly_episode(exact, baseline_policy().act, np.zeros((5, 6)), n_steps=5, sensor_normals=[[0] * 12] * 6)
    late = ReferenceMDP(PARAMS, NOISE, sensor=(0, 0, 0, 0, 0, 1, 0))
    _, _, seen = fly_episode(late, baseline_policy().act, np.zeros((5, 6)), n_steps=5, sensor_normals=[[0] * 12] * 6)
    assert len(seen) == 6


@pytest.mark.parametrize("value", ["x", True, 10.0, 0, 5, None])
def test_flyable_substeps_checks_its_argument(value) -> None:
    """T15-29: LearnedModel.flyable_substeps('x') returned 1; it takes what mdp() takes, 1 or 10."""
    model = M.LearnedModel(PARAMS, NOISE, "lr")
    with pytest.raises(NeurohoverError, match=re.escape(f"substeps={value!r}: allowed 1 or 10")):
        model.flyable_substeps(value)
    assert (model.flyable_substeps(1), model.flyable_substeps(np.int64(10))) == (1, 10)
