"""The fifteenth bad-input trial's findings in neurohover.envs and neurohover.wrappers: observations of the wrong shape or
type, wrappers of no environment, an unknown or differently spelled task (it flew with full authority), a policy that is
no callable, and a noise stream that is no (seed, episode) pair (a dict was unpacked to its keys)."""

from __future__ import annotations

import numpy as np
import pytest

from neurohover.envs import HoverEnv, HoverVectorEnv, rl
from neurohover.errors import NeurohoverError
from neurohover.wrappers import CrashAwareReward


@pytest.mark.parametrize("obs", [np.zeros(11), "abc", [[0.0] * 12, [0.0]], np.zeros(12, dtype=bool)])
def test_scale_observation_refuses_what_is_no_12_readings(obs) -> None:
    """T15-6: 11 readings were NumPy's broadcast ValueError, "abc" a TypeError."""
    with pytest.raises(NeurohoverError, match=r"is not allowed: observations must be \(\.\.\., 12\) real numbers"):
        rl.scale_observation(obs)


def test_scale_observation_still_takes_readings() -> None:
    """T15-6: the check keeps float32 readings float32 and integers become float64."""
    assert rl.scale_observation(np.ones((2, 12), dtype=np.float32)).dtype == np.float32
    np.testing.assert_allclose(rl.scale_observation(np.ones(12, dtype=int)), 1.0 / rl.OBS_LIMITS)


@pytest.mark.parametrize("wrap", [lambda: CrashAwareReward(None), lambda: rl.ScaledAction(None, "ghh08"), lambda: rl.ScaledObservation(None)])
def test_a_wrapper_of_no_environment_is_refused_by_name(wrap) -> None:
    """T15-11: CrashAwareReward(None) and ScaledAction(None, "ghh08") were Gymnasium's TypeError."""
    with pytest.raises(NeurohoverError, match=r"env=None is not allowed: give a gymnasium Env"):
        wrap()


def test_controls_take_a_task_as_the_package_spells_it() -> None:
    """T15-18: "GHH08" had full authority (the controls differed from "ghh08"'s); task names are case-insensitive."""
    a = np.full(4, 0.5)
    np.testing.assert_array_equal(rl.controls(a, "GHH08"), rl.controls(a, "ghh08"))
    np.testing.assert_array_equal(rl.controls(a, "GHH-09"), rl.controls(a, "ghh09"))
    assert rl.ScaledAction(HoverEnv(episode_steps=5), "GHH08").task == "ghh08"


@pytest.mark.parametrize(
    "call",
    [
        lambda: rl.controls(np.full(4, 0.5), "nope"),
        lambda: rl.controls(np.full(4, 0.5), ["ghh08"]),
        lambda: rl.rl_policy(lambda o: o, "nope"),
        lambda: rl.ScaledAction(HoverEnv(episode_steps=5), "nope"),
    ],
)
def test_an_unknown_task_is_refused_not_flown_with_full_authority(call) -> None:
    """T15-18: an unknown task silently fell back to full authority."""
    with pytest.raises(NeurohoverError, match=r"unknown task .*: allowed ghh08, ghh09, fghh"):
        call()


def test_rl_policy_refuses_an_act_that_is_no_callable() -> None:
    """T15-18: rl_policy(None, "ghh08") was taken and failed only when flown."""
    with pytest.raises(NeurohoverError, match=r"act=None is not allowed: give a callable"):
        rl.rl_policy(None, "ghh08")


@pytest.mark.parametrize("noise", [{1: 0, 2: 0}, "12", (1, 2.0), [1, 2, 3], (True, 1), {1, 2}])
def test_a_noise_stream_that_is_no_pair_of_integers_is_refused(noise) -> None:
    """T15-19: {1: 0, 2: 0} flew stream (1, 2) (unpacked to its keys); "12" said "noise seed='1' is out of range"."""
    env = HoverEnv(episode_steps=5)
    with pytest.raises(NeurohoverError, match=r"noise=.* is not allowed: give a \(seed, episode\) pair of integers"):
        env.reset(options={"noise": noise})
    vector = HoverVectorEnv(num_envs=2, episode_steps=5)
    with pytest.raises(NeurohoverError, match=r"noise.* is not allowed: give a \(seed, episode\) pair of integers"):
        vector.reset(options={"noise": noise})


def test_a_noise_stream_pair_is_still_taken() -> None:
    """T15-19: a tuple, list or array of two (NumPy) integers is a stream; one out of range is named."""
    env = HoverEnv(episode_steps=5)
    for noise in ((1, 2), [1, 2], np.array([1, 2]), (np.int64(1), np.uint8(2))):
        env.reset(options={"noise": noise})
        assert env.noise_stream == (1, 2)
    with pytest.raises(NeurohoverError, match=r"noise episode=-1 is out of range: allowed an integer in 0..2\*\*63-1"):
        env.reset(options={"noise": (1, -1)})
    vector = HoverVectorEnv(num_envs=2, episode_steps=5)
    vector.reset(options={"noise": [[1, 2], [3, 4]]})
    np.testing.assert_array_equal(vector.noise_streams, [[1, 2], [3, 4]])
    with pytest.raises(NeurohoverError, match=r"noise\[1\]=\('3', '4'\) is not allowed"):
        vector.reset(options={"noise": [[1, 2], ["3", "4"]]})
