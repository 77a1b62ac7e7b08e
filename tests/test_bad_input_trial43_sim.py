"""The forty-third bad-input trial's findings in the public low-level helpers (side B: T43-B01, T43-B02, T43-B03, T43-B04,
T43-B05, T43-B08, T43-B09, T43-B14): neurohover.sim.reference, neurohover.models.wind, format_parameter_table, Drift and
HoverRenderer. Each bad value is one NeurohoverError naming it and what is allowed."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

import neurohover.models.wind as W
from neurohover.errors import NeurohoverError
from neurohover.sim.constants import CRASH_STEP_PENALTY
from neurohover.sim.reference import ReferenceHelicopter, ReferenceSensors, fly_episode, rotation_vector_quaternion
from neurohover.tasks import get_task_family

NORMALS = np.zeros((5, 6))


def _reference():
    return get_task_family("ghh08").mdp("train:0").to_reference()


def _hover(observation):
    return (0.0, 0.0, 0.0, 0.0)


@pytest.mark.parametrize(
    ("field", "value", "message"),
    [
        ("substeps", 0, "mdp.substeps=0 is not allowed: give an integer >= 1"),
        ("dt", math.nan, "mdp.dt=nan is not allowed: give a finite number > 0"),
        ("params", (1.0, 2.0, 3.0), r"mdp.params=\(1.0, 2.0, 3.0\) is not allowed: give 11 real numbers, all finite"),
        ("sensor", (0.0,) * 6 + (2.0,), r"mdp.sensor=.* is not allowed: give 4 stds >= 0"),
    ],
)
def test_a_reference_mdp_changed_after_it_was_made_is_checked_where_flown(field: str, value: object, message: str) -> None:
    """T43-B01: substeps=0 set after to_reference() flew a perfect 0.0 return, dt=nan a NaN one, 3 params an unpack error."""
    ref = _reference()
    setattr(ref, field, value)
    with pytest.raises(NeurohoverError, match=message):
        fly_episode(ref, _hover, NORMALS, n_steps=5)
    with pytest.raises(NeurohoverError, match=message):
        ReferenceHelicopter(ref)


def test_a_reference_mdp_changed_by_the_policy_mid_episode_is_not_flown() -> None:
    """T43-B01: the episode flies the MDP as it was checked, not one the policy changes as it flies."""
    ref = _reference()
    want = fly_episode(ref, _hover, NORMALS, n_steps=5)[:2]

    def meddling(observation):
        ref.substeps = 0
        return (0.0, 0.0, 0.0, 0.0)

    assert fly_episode(ref, meddling, NORMALS, n_steps=5)[:2] == want
    with pytest.raises(NeurohoverError, match="mdp.substeps=0 is not allowed"):  # changed now: refused at the next flight
        fly_episode(ref, _hover, NORMALS, n_steps=5)


def _read_twice(sensors: ReferenceSensors) -> None:
    sensors.read([0.0] * 12)
    sensors.read([0.0] * 12)


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda ref: ReferenceHelicopter(ref).step((0.0, 0.0, 0.0), (0.0,) * 6), r"action=\(0.0, 0.0, 0.0\) is not allowed: give 4 real numbers"),
        (lambda ref: ReferenceHelicopter(ref).step({0: 0.0, 1: 0.0, 2: 0.0, 3: 0.0}, (0.0,) * 6), r"action=\{0: 0.0.* is not allowed: give 4 real numbers"),
        (lambda ref: ReferenceHelicopter("x"), "mdp='x' is not allowed: give a ReferenceMDP"),
        (lambda ref: ReferenceHelicopter(ref).step((0.0,) * 4, (0.0,) * 2), r"normals=\(0.0, 0.0\) is not allowed: give 6 real numbers, all finite"),
        (lambda ref: ReferenceHelicopter(ref).step((0.0,) * 4, (math.nan,) * 6), r"normals=\(nan, .* is not allowed: give 6 real numbers, all finite"),
        (lambda ref: ReferenceHelicopter(ref, velocity=(0.0, "a", 0.0)), r"velocity=\(0.0, 'a', 0.0\) is not allowed: give 3 real numbers"),
        (lambda ref: ReferenceHelicopter(ref, episode_steps=-5), r"episode_steps=-5 is not allowed: give an integer in 1..\d+"),
        (lambda ref: ReferenceHelicopter(ref, episode_steps=5, steps=9), r"steps=9 is not allowed: give an integer in 0..5"),
        (lambda ref: ReferenceSensors((0.1,) * 4 + (0, 0, 0), [[0] * 3]), r"normals of shape \(1, 3\) is not allowed: give at least 1 rows of 12"),
        (lambda ref: ReferenceSensors((0.1,) * 4 + (0, 0, 0.5), [[0] * 12]), r"normals of shape \(1, 12\) is not allowed: give at least 1 rows of 13"),
        (lambda ref: ReferenceSensors((0.1,) * 3, [[0] * 12]), r"sensor=\(0.1, 0.1, 0.1\) is not allowed: give 7 real numbers"),
        (lambda ref: ReferenceSensors((0.1,) * 4 + (0, 0, 0), [[0] * 12]).read([0.0] * 3), r"observation=\[0.0, 0.0, 0.0\] is not allowed: give 12 real"),
        (lambda ref: _read_twice(ReferenceSensors((0.1,) * 4 + (0, 0, 0), [[0] * 12])), "reading 1 is not allowed: normals has 1 rows"),
    ],
)
def test_the_reference_helicopter_and_sensors_check_their_arguments(call, message: str) -> None:
    """T43-B02: they checked nothing: unpack, attribute and index errors."""
    with pytest.raises(NeurohoverError, match=message):
        call(_reference())


def test_a_reference_helicopter_pays_no_reward_for_a_crash_past_its_episode() -> None:
    """T43-B02: episode_steps=-5 paid a crash (a NaN action) a positive reward; a step past the episode is refused."""
    heli = ReferenceHelicopter(_reference(), episode_steps=3)
    assert heli.step((0.0, 0.0, 0.0, math.nan), (0.0,) * 6) == (-CRASH_STEP_PENALTY * 2, True)
    heli.step((0.0,) * 4, (0.0,) * 6)
    heli.step((0.0,) * 4, (0.0,) * 6)
    with pytest.raises(NeurohoverError, match="step 4 is not allowed: the episode of episode_steps=3 is flown"):
        heli.step((0.0,) * 4, (0.0,) * 6)
    # stepped by hand, it flies as fly_episode does
    ref = _reference()
    total, crashed, _ = fly_episode(ref, _hover, NORMALS, n_steps=5)
    heli = ReferenceHelicopter(ref, episode_steps=5)
    assert sum(heli.step(_hover(None), row)[0] for row in NORMALS.tolist()) == total and not crashed


@pytest.mark.parametrize("rv", [(1e200, 0.0, 0.0), (1e308, 1e308, 0.0), (-1.7e308, 1.7e308, 1.7e308), (3e150, -2e150, 1.0)])
def test_a_huge_rotation_vector_is_a_unit_quaternion(rv: tuple[float, float, float]) -> None:
    """T43-B03: 1e200 passed the "3 real numbers, all finite" check and was an OverflowError; it is a rotation too."""
    q = rotation_vector_quaternion(rv)
    assert all(math.isfinite(c) for c in q) and math.fsum(c * c for c in q) == pytest.approx(1.0)
    axis = np.array(rv) / max(map(abs, rv))
    vector = np.array(q[:3])
    assert np.allclose(np.cross(vector, axis), 0.0, atol=1e-12)  # about the vector's own axis


def test_a_moderate_rotation_vector_is_unchanged() -> None:
    """T43-B03: below 1e150 rad the formula is the one the substep loop uses."""
    assert rotation_vector_quaternion((1e-3, 0.0, 0.0)) == pytest.approx((0.0004999999791666669, 0.0, 0.0, 0.9999998750000026), abs=0)
    angle = 1e100
    q = rotation_vector_quaternion((angle, 0.0, 0.0))
    assert q == (math.sin(angle / 2), 0.0, 0.0, math.cos(angle / 2))


def test_fly_episode_refuses_a_dict_action_and_complex_normals() -> None:
    """T43-B14: a dict {0: .., 3: ..} flew its keys 0, 1, 2, 3; complex normals flew their real part with a ComplexWarning."""
    ref = _reference()
    with pytest.raises(NeurohoverError, match=r"the policy's action at step 0 is \{0: 0.0, .*, not allowed: a policy gives 4 numbers"):
        fly_episode(ref, lambda o: {0: 0.0, 1: 0.0, 2: 0.0, 3: 0.23}, NORMALS, n_steps=5)
    with pytest.raises(NeurohoverError, match=r"the policy's action at step 0 is \{0.0, 1.0, 2.0, 3.0\}, not allowed"):
        fly_episode(ref, lambda o: {0.0, 1.0, 2.0, 3.0}, NORMALS, n_steps=5)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(
            NeurohoverError, match=r"normals=array\(\[\[0.\+1.j.* is not allowed: give at least 5 rows of 6 numbers .*\(real numbers, not complex numbers\)"
        ):
            fly_episode(ref, _hover, NORMALS + 1j, n_steps=5)
        with pytest.raises(NeurohoverError, match=r"sensor_normals=.* is not allowed: give at least 6 rows of 12 numbers .*not complex numbers"):
            ref.sensor = (0.1, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
            fly_episode(ref, _hover, NORMALS, n_steps=5, sensor_normals=np.zeros((6, 12)) + 1j)
    # sequences and arrays of 4 real numbers fly alike
    ref = _reference()
    assert fly_episode(ref, lambda o: np.zeros(4), NORMALS, n_steps=5)[:2] == fly_episode(ref, lambda o: [0, 0, 0, 0], NORMALS, n_steps=5)[:2]


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda: W.sinusoid_axes((1.0, 0.1, 0.2)), r"wind=\(1.0, 0.1, 0.2\) is not allowed: give 8 finite numbers, a GHH-09 wind's"),
        (lambda: W.sinusoid_axes(None), r"wind=None is not allowed: give 8 finite numbers"),
        (lambda: W.sinusoid_axes([math.nan] * 8), r"wind=\[nan, .* is not allowed: give 8 finite numbers"),
        (lambda: W.model_times("a"), r"steps='a' is not allowed: give control step numbers, whole and >= 0"),
        (lambda: W.model_times(None), r"steps=None is not allowed: give control step numbers"),
        (lambda: W.model_times([-1]), r"steps=\[-1\] is not allowed: give control step numbers, whole and >= 0"),
        (lambda: W.model_times([1.5]), r"steps=\[1.5\] is not allowed: give control step numbers, whole"),
        (lambda: W.WindModel().world("x"), r"t='x' is not allowed: give times in seconds, finite real numbers"),
        (lambda: W.WindAxis(1, 1, 0, 0).at("abc"), r"t='abc' is not allowed: give times in seconds, finite real numbers"),
        (lambda: W.WindAxis(1, 1, 0, 0).at([math.nan]), r"t=\[nan\] is not allowed: give times in seconds, finite real numbers"),
        (lambda: W.body_wind(None, W.WindModel()), r"tr=None is not allowed: give the flight data as Transitions"),
    ],
)
def test_the_wind_helpers_check_their_input(call, message: str) -> None:
    """T43-B04: the public helpers of neurohover.models.wind leaked ValueError, TypeError and AttributeError; model_times(None)
    was NaN and model_times([-1]) a time of -0.1 s without a word. fit_wind, in the same module, refused such input."""
    with pytest.raises(NeurohoverError, match=message):
        call()


def test_the_wind_helpers_take_what_they_took() -> None:
    """T43-B04: numbers, arrays and an MDP's wind as before."""
    assert W.model_times(5) == 0.5 and W.model_times(np.arange(3)).tolist() == [0.0, 0.1, 0.2] and W.model_times([np.int32(2)]).tolist() == [0.2]
    axis = W.WindAxis(2.0, 3.0, 0.5, 1.0)
    assert axis.at(0.25) == 2.0 * math.sin(0.75 + 0.5) + 1.0 and axis.at(np.zeros((2, 3))).shape == (2, 3)
    assert W.WindModel("sinusoid", axis, axis).world([0.0, 0.1]).shape == (2, 2)
    mdp = get_task_family("ghh09").mdp("train:0")
    assert W.sinusoid_axes(mdp.wind) == W.sinusoid_axes(list(mdp.wind))


def test_format_parameter_table_names_a_none_row() -> None:
    """T43-B05: None, the bad-row search's own "no bad row" answer, passed the check and was an AttributeError."""
    from neurohover.models import ParamRow, format_parameter_table

    row = ParamRow("C_u", -0.18, -0.18, 0.0)
    with pytest.raises(NeurohoverError, match="row None is not allowed: give the ParamRow rows that parameter_table returns"):
        format_parameter_table([row, None])
    assert "C_u" in format_parameter_table([row])


@pytest.mark.parametrize(
    "make", [lambda: iter([("C_u", 2.0)]), lambda: (p for p in [("C_u", 2.0)]), lambda: map(tuple, [("C_u", 2.0)]), lambda: zip(["C_u"], [2.0])]
)
def test_a_drift_change_given_as_an_iterator_is_refused(make) -> None:
    """T43-B08: an iterator was "has no len()", a TypeError; it is refused as change_at and walk refuse a generator."""
    from neurohover.tasks.drift import Drift

    with pytest.raises(
        NeurohoverError,
        match=r"drift change=<.*> is not allowed: give parameter factors as a table or a list of \(name, factor\) pairs, not a one-shot iterator",
    ):
        Drift(change=make())
    assert Drift(change=[("C_u", 2.0)]) == Drift(change={"C_u": 2.0})


def test_a_closed_renderer_draws_on_a_new_figure() -> None:
    """T43-B09: draw after close() was an AttributeError ('NoneType' object has no attribute 'dpi'); it draws again, as an
    environment's render() after close() does."""
    from neurohover.envs.render import HoverRenderer

    renderer = HoverRenderer(64, 48)
    state = [0.0] * 12 + [1.0]
    before = renderer.draw(state, [1.0, 0.0, 0.0], "x")
    renderer.close()
    renderer.close()
    with pytest.raises(NeurohoverError, match="draw state"):  # checked as before
        renderer.draw([0.0] * 3, [1.0, 0.0, 0.0], "x")
    after = renderer.draw(state, [1.0, 0.0, 0.0], "x")
    assert after.shape == (48, 64, 3) and (after == before).all()
    renderer.close()
