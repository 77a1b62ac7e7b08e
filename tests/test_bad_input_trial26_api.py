"""Twenty-sixth bad-input trial, the API: T26-B01 (a None policy in PolicyTable.from_policies), T26-B02 (an Evaluation
built by hand checked nothing), T26-B03 (an explicit MDP dropped the environment's sensor), T26-B16 (get_task_family's
sigma past a float's range) and T26-B17 (non-numbers called out of range, fallback_index's unnamed entry)."""

from __future__ import annotations

import re

import gymnasium as gym
import numpy as np
import pytest

import neurohover as nh
from neurohover.envs import HoverEnv, HoverVectorEnv
from neurohover.errors import NeurohoverError


def test_a_none_policy_is_refused_by_name() -> None:
    """T26-B01: None was the 'nothing found' default of the check, then an AttributeError ('topology')."""
    for policies in ([None], [nh.baseline_policy(), None]):
        with pytest.raises(NeurohoverError, match=re.escape("policy None is not a Policy: load one with neurohover.load_policy")):
            nh.PolicyTable.from_policies(policies)


def _evaluation(**changed) -> nh.Evaluation:
    fields = {
        "returns": np.zeros(2),
        "crashed": np.zeros(2, dtype=bool),
        "steps": np.full(2, 5),
        "safeguard_step": np.full(2, -1),
        "flight_data": None,
        "seconds": 0.5,
    }
    return nh.Evaluation(**(fields | changed))


@pytest.mark.parametrize(
    ("changed", "message"),
    [
        ({"returns": "a"}, "Evaluation returns='a' is not allowed: give a NumPy array of real numbers, one per episode"),
        ({"returns": [1.0, 2.0]}, "Evaluation returns=[1.0, 2.0] is not allowed: give a NumPy array"),
        ({"crashed": np.zeros(3, dtype=bool)}, "Evaluation crashed has shape (3,), returns (2,): give one entry per episode in each"),
        ({"crashed": np.zeros(2)}, "Evaluation crashed=array([0., 0.]) is not allowed: give a NumPy array of True/False flags"),
        ({"steps": np.zeros(2)}, "Evaluation steps=array([0., 0.]) is not allowed: give a NumPy array of integers"),
        ({"steps": np.zeros(2, dtype=int)}, "Evaluation steps holds 0: allowed 1..10,000,000"),
        ({"safeguard_step": np.array([5, -1])}, "Evaluation safeguard_step 5 of a 5-step episode is not allowed: give -1 (never) or 0..steps-1"),
        ({"flight_data": "x"}, "Evaluation flight_data='x' is not allowed: give FlightData or None"),
        ({"seconds": float("nan")}, "Evaluation seconds=nan is not allowed: give a finite number >= 0 (wall time)"),
        ({"seconds": "1"}, "Evaluation seconds='1' is not allowed"),
    ],
)
def test_an_evaluation_built_by_hand_is_checked(changed: dict, message: str) -> None:
    """T26-B02: text returns were an AttributeError at .episodes, arrays of other shapes NumPy's ValueError in reshape(),
    flight_data='x' and seconds=nan were taken."""
    with pytest.raises(NeurohoverError, match=re.escape(message)):
        _evaluation(**changed)


def test_evaluations_that_evaluate_builds_still_pass() -> None:
    mdps = nh.get_task_family("ghh08").training_mdps()[:2]
    ev = nh.evaluate(nh.baseline_policy(), mdps, episodes=2, n_steps=20, record=True)
    assert ev.returns.shape == (1, 2, 2) and ev.reshape((4,)).episodes == 4 and ev.reshape((4,)) == ev.reshape((4,))
    assert _evaluation(seconds=1).seconds == 1.0 and isinstance(_evaluation(seconds=1).seconds, float)


def _sensor(env) -> nh.Sensor:
    env.reset(seed=0)
    return env.unwrapped.mdp.sensor


def test_an_explicit_mdp_flies_under_the_environments_sensor() -> None:
    """T26-B03: an MDP object flew exact sensors under the -NoisySensors ids, obs_noise and obs_delay, where the same MDP
    named by text flew the environment's."""
    mdp = nh.get_task_family("ghh08").mdp("train:0")
    for env_id in ("NoisySensors", "DelayedSensors", "CorrelatedSensors"):
        named = _sensor(gym.make(f"neurohover/GHH08-{env_id}-v0", mdp="train:0", episode_steps=20, max_episode_steps=20))
        assert not named.exact
        assert _sensor(gym.make(f"neurohover/GHH08-{env_id}-v0", mdp=mdp, episode_steps=20, max_episode_steps=20)) == named
    assert _sensor(HoverEnv(mdp=mdp, obs_delay=3, episode_steps=20)) == nh.Sensor(delay=3)
    assert _sensor(HoverEnv(mdp=mdp, obs_noise=0.5, episode_steps=20)) == nh.Sensor.at_level(0.5)
    env = HoverEnv(obs_noise=0.5, episode_steps=20)
    env.reset(seed=0, options={"mdp": mdp})
    assert env.mdp.sensor == nh.Sensor.at_level(0.5)
    vec = gym.make_vec("neurohover/GHH08-v0", num_envs=2, vectorization_mode="vector_entry_point", mdp=mdp, obs_delay=2, episode_steps=20)
    vec.reset(seed=0)
    assert [m.sensor for m in vec.unwrapped.mdps] == [nh.Sensor(delay=2)] * 2
    vec = HoverVectorEnv(num_envs=2, obs_noise=1.0, episode_steps=20)
    vec.reset(seed=0, options={"mdp": [mdp, "train:1"]})
    assert [m.sensor for m in vec.mdps] == [nh.Sensor.at_level(1.0)] * 2


def test_an_explicit_mdps_own_sensor_flies_alone_and_is_refused_beside_another() -> None:
    """T26-B03: by the rule of an explicit MDP's drift, its own sensor flies where the environment's is exact (or the same)."""
    mdp = nh.get_task_family("ghh08").mdp("train:0")
    own = mdp.with_sensor(nh.Sensor.at_level(2.0, delay=1))
    assert _sensor(HoverEnv(mdp=own, episode_steps=20)) == own.sensor
    assert _sensor(HoverEnv(mdp=own, obs_noise=2.0, obs_delay=1, episode_steps=20)) == own.sensor
    message = (
        "mdp 'ghh08/train:0' carries its own sensor Sensor(velocity=0.2, position=0.2, rates=0.2, attitude=0.02, delay=1), "
        "not this environment's Sensor(velocity=0.1, position=0.1, rates=0.1, attitude=0.01) (its obs_noise, obs_delay or id)"
    )
    with pytest.raises(NeurohoverError, match=re.escape(message)):
        gym.make("neurohover/GHH08-NoisySensors-v0", mdp=own)
    with pytest.raises(NeurohoverError, match=re.escape(message)):
        HoverVectorEnv(num_envs=2, obs_noise=1.0, mdp=own)
    env = HoverEnv(obs_noise=1.0, episode_steps=20)
    with pytest.raises(NeurohoverError, match=re.escape(message)):
        env.reset(seed=0, options={"mdp": own})


def test_an_explicit_mdps_own_drift_beside_another_is_refused() -> None:
    """T26-B03's rule for drift: the environment's drift won over an MDP's own without a word."""
    mdp = nh.get_task_family("ghh08").mdp("train:0")
    with pytest.raises(NeurohoverError, match=re.escape("mdp 'ghh08/train:0' drifts by its own {'walk': 0.2")):
        HoverEnv(mdp=mdp.with_drift(nh.Drift(0.2)), drift={"walk": 0.01}, episode_steps=20)
    env = HoverEnv(drift={"walk": 0.01}, episode_steps=20)
    with pytest.raises(NeurohoverError, match="not this environment's drift"):
        env.reset(seed=0, options={"mdp": mdp.with_drift(nh.Drift(0.2))})
    same = HoverEnv(mdp=mdp.with_drift(nh.Drift(0.01)), drift={"walk": 0.01}, episode_steps=20)
    same.reset(seed=0)
    assert same.drift_run is not None and same.drift_run.drift == nh.Drift(0.01)


def test_get_task_family_checks_sigma_as_fghh_does() -> None:
    """T26-B16: 10**400 was cut to 40 digits (reading as 10**39) and the range 0..1 was not named."""
    message = "FGHH sigma=1000000000...(401 digits) is out of range: allowed 0 <= sigma <= 1"
    for make in (lambda: nh.get_task_family("fghh", sigma=10**400), lambda: nh.FGHH(sigma=10**400)):
        with pytest.raises(NeurohoverError, match=re.escape(message)):
            make()
    assert nh.get_task_family("fghh", sigma=np.float32(0.25)).sigma == 0.25


@pytest.mark.parametrize(
    ("make", "message"),
    [
        (lambda: nh.Sensor.at_level("1"), "sensor noise level='1' is not allowed: give a number in 0..1000"),
        (lambda: nh.Sensor.at_level(None), "sensor noise level=None is not allowed: give a number in 0..1000"),
        (lambda: nh.Sensor.at_level(-1), "sensor noise level=-1 is out of range: allowed a number in 0..1000"),
        (lambda: nh.DangerousState(box="1"), "safeguard box='1' is not allowed: give a number > 0"),
        (lambda: nh.DangerousState(tilt=None), "safeguard tilt=None is not allowed: give a number with 0 < tilt <= 1"),
        (lambda: nh.DangerousState(box=-1), "safeguard box=-1 is out of range: allowed a finite number > 0"),
        (lambda: nh.FGHH(sigma="x"), "FGHH sigma='x' is not allowed: give a number 0 <= sigma <= 1"),
        (lambda: nh.get_task_family("fghh", sigma="x"), "FGHH sigma='x' is not allowed: give a number 0 <= sigma <= 1"),
        (lambda: nh.Drift(change=(("D_w", 0.8),), change_at=(1.5, 3)), "drift change_at=(1.5, 3) is not allowed: give two episode numbers lo, hi, whole"),
    ],
)
def test_a_non_number_is_not_called_out_of_range(make, message: str) -> None:
    """T26-B17: '1', None and 'x' were "out of range", as was the episode 1.5."""
    with pytest.raises(NeurohoverError, match=re.escape(message)):
        make()


@pytest.mark.parametrize(
    ("fallback", "message"),
    [
        ([5], "fallback_index entry 0 is 5, out of range: allowed -1 (none) or 0..0"),
        ([0, 0], "fallback_index has 2 entries but there are 1 jobs: give one per job, each in -1..0"),
        (np.array([2**64 - 1], dtype=np.uint64), "fallback_index entry 0 is 18446744073709551615, out of range"),  # wrapped to -1
    ],
)
def test_fallback_index_names_its_bad_entry_and_length(fallback, message: str) -> None:
    """T26-B17: "fallback_index must have 1 entries in -1..0" named neither the 5 nor the length 2."""
    mdp = nh.get_task_family("ghh08").mdp("train:0")
    with pytest.raises(NeurohoverError, match=re.escape(message)):
        nh.evaluate_jobs([nh.baseline_policy()], [mdp], [0], [0], [0], fallback_index=fallback, n_steps=5)
