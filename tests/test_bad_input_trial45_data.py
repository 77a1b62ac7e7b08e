"""Bad-input trial 45, side B: data and extension points. A task name that is no text in ``family_for`` (T45-B04);
``check_vector``'s ``nonnegative`` and ``finite_vector``'s ``length`` unchecked (T45-B05); flight data whose arrays were
replaced after making (T45-B06) or edited in place (T45-B07); ``CrashAwareReward`` over an env that is no HoverEnv
(T45-B10)."""

from __future__ import annotations

import re

import gymnasium as gym
import numpy as np
import pytest

import neurohover  # noqa: F401  (registers the neurohover/ ids)
from neurohover.envs.rl import ScaledAction, ScaledObservation
from neurohover.errors import NeurohoverError
from neurohover.flightdata import FlightData
from neurohover.models import Transitions, check_vector, learn_lr, observed_return
from neurohover.tasks import family_for, finite_vector, get_task_family, set_name
from neurohover.wrappers import CrashAwareReward


def _flight(steps: int = 60, episodes: int = 2) -> FlightData:
    """Flight data of full (uncrashed) episodes, small readings that vary (LR needs regressors that are not constant)."""
    rng = np.random.default_rng(0)
    obs = tuple(rng.normal(0.0, 0.01, (steps + 1, 12)) for _ in range(episodes))
    act = tuple(rng.uniform(-0.1, 0.1, (steps, 4)) for _ in range(episodes))
    return FlightData(obs, act, {"episode_steps": steps, "crashed": [False] * episodes})


@pytest.mark.parametrize("name", [[], {}, np.array(["ghh08"])])
def test_b04_family_for_refuses_an_unhashable_name_as_get_task_family_does(name) -> None:
    """T45-B04: family_for([], None) was a TypeError (unhashable type), where get_task_family refuses the name."""
    with pytest.raises(NeurohoverError) as said:
        get_task_family(name)
    with pytest.raises(NeurohoverError, match=re.escape(str(said.value))):
        family_for(name, None)
    assert str(said.value).startswith("unknown task ") and "allowed ghh08, ghh09, fghh" in str(said.value)
    assert set_name(name, None, "test") == "test"  # spec as given where the task is none a family takes (was a TypeError)
    assert family_for("GHH-08", 0.2).name == "ghh08" and family_for("fghh", 0.2).sigma == 0.2  # what it took still taken


@pytest.mark.parametrize("flag", [np.array([True, False]), "x", float("nan"), {}, None, 1])
def test_b05_check_vector_refuses_a_nonnegative_that_is_no_flag(flag) -> None:
    """T45-B05: nonnegative=<array of two> was NumPy's "truth value is ambiguous"; 'x', nan and {} were taken as flags."""
    with pytest.raises(NeurohoverError, match=r"^nonnegative=.* is not allowed: give True \(refuse negative numbers\) or False$"):
        check_vector([1.0, 2.0], 2, "v", nonnegative=flag)
    assert check_vector([1.0, -2.0], 2, "v", nonnegative=np.False_) == (1.0, -2.0)
    with pytest.raises(NeurohoverError, match=r"v must be >= 0"):
        check_vector([1.0, -2.0], 2, "v", nonnegative=np.True_)


@pytest.mark.parametrize("length", [np.array([2, 2]), "2", 2.0, -1, True, None])
def test_b05_finite_vector_refuses_a_length_that_is_no_count(length) -> None:
    """T45-B05: finite_vector(..., length=<array>) was NumPy's "truth value is ambiguous"; refused as check_vector refuses
    it, by the one check (a length of 0 is finite_vector's: an MDP without wind holds no wind numbers)."""
    message = r"^length=.* is not allowed: give a whole number >= {} \(how many numbers v holds\)$"
    with pytest.raises(NeurohoverError, match=message.format(0)):
        finite_vector([1.0, 2.0], length, "v")
    with pytest.raises(NeurohoverError, match=message.format(1)):
        check_vector([1.0, 2.0], length, "v")
    assert finite_vector([1.0, 2.0], np.int8(2), "v").tolist() == [1.0, 2.0] and finite_vector([], 0, "v").size == 0


def test_b06_every_reader_refuses_flight_data_whose_arrays_were_replaced() -> None:
    """T45-B06: observations replaced with object.__setattr__ (10 readings for 60 actions): learn_lr was NumPy's broadcast
    error, observed_return a wrong number, Transitions and check_again took them, save wrote them."""
    data = _flight()
    assert np.isfinite(observed_return(data, 0)) and learn_lr(data) is not None
    object.__setattr__(data, "observations", (data.observations[0][:10],) + data.observations[1:])
    said = re.escape("flight data, episode 0: observations must be (T+1, 12) and actions (T, 4), got (10, 12) and (60, 4)")
    for read in (data.check_again, lambda: observed_return(data, 0), lambda: Transitions(data), lambda: learn_lr(data)):
        with pytest.raises(NeurohoverError, match=said):
            read()
    object.__setattr__(data, "actions", list(data.actions))
    with pytest.raises(NeurohoverError, match=r"flight data: its actions \[.* are not allowed: give a tuple of arrays, one per episode"):
        data.check_again()


def test_b06_save_refuses_flight_data_whose_arrays_were_replaced(tmp_path) -> None:
    """T45-B06: save wrote arrays that no longer pair up (load then called the file truncated)."""
    data = _flight()
    object.__setattr__(data, "actions", (data.actions[0][:5],) + data.actions[1:])
    with pytest.raises(NeurohoverError, match=re.escape("episode 0: observations must be (T+1, 12) and actions (T, 4), got (61, 12) and (5, 4)")):
        data.save(tmp_path / "f.npz")
    assert not (tmp_path / "f.npz").exists()


def test_b07_flight_data_arrays_are_read_only_and_the_callers_stay_writeable(tmp_path) -> None:
    """T45-B07: fd.observations[0][5, 0] = inf made observed_return -inf and passed check_again; an action of 5.0 was
    saved and loaded back. The arrays flight data hold are read-only; the caller's own arrays are copied, not frozen."""
    given_obs, given_act = np.full((6, 12), 0.01), np.zeros((5, 4))
    data = FlightData((given_obs,), (given_act,), {"episode_steps": 5, "crashed": [False]})
    before = observed_return(data, 0)
    for array in (*data.observations, *data.actions):
        assert not array.flags.writeable
        with pytest.raises(ValueError, match="read-only"):
            array[0, 0] = np.inf
    given_obs[1, 0] = np.inf  # the caller's array is theirs: writeable, and not the flight data's
    assert observed_return(data, 0) == before and np.isfinite(data.observations[0]).all()
    loaded = FlightData.load(data.save(tmp_path / "f.npz"))
    assert loaded == data and not any(a.flags.writeable for a in (*loaded.observations, *loaded.actions))
    joined = loaded + data
    assert joined.n_episodes == 2 and not any(a.flags.writeable for a in (*joined.observations, *joined.actions))
    assert joined.observations[0] is loaded.observations[0]  # read-only arrays are shared, not copied again


def test_b07_observed_return_refuses_a_reading_no_flight_gives() -> None:
    """T45-B07: observed_return made an infinite reading a return of -inf; it reads the episode as Transitions does."""
    obs = np.full((6, 12), 0.01)
    obs[5, 0] = np.inf
    data = FlightData((obs,), (np.zeros((5, 4)),), {"episode_steps": 5, "crashed": [False]})
    with pytest.raises(NeurohoverError, match=r"flight data, episode 0: step 5 reads u = inf: no flight records a NaN or infinite observation"):
        observed_return(data, 0)


def test_b10_crash_aware_reward_refuses_an_env_that_is_no_hover_env() -> None:
    """T45-B10: CrashAwareReward(gym.make("CartPole-v1")) was taken, CartPole's +1 for staying upright made -0.69."""
    said = r"^env=.*CartPole.* is not allowed: it flies a CartPoleEnv, not a neurohover HoverEnv, .*; give a neurohover env \(gymnasium.make"
    with pytest.raises(NeurohoverError, match=said):
        CrashAwareReward(gym.make("CartPole-v1"))


@pytest.mark.parametrize(("wrap", "env_id"), [(lambda e: ScaledObservation(e), "CartPole-v1"), (lambda e: ScaledAction(e, "ghh08"), "Pendulum-v1")])
def test_the_rl_transforms_refuse_an_env_that_is_no_hover_env(wrap, env_id: str) -> None:
    """After T45-B10: ScaledObservation took CartPole and ScaledAction Pendulum (their first reset or step was refused);
    both now refuse an env of other shapes at construction (an env of a helicopter's shapes stays the user's: T42-B05)."""
    with pytest.raises(NeurohoverError, match=r"space is a Box of shape \((4|1),\), and this transform takes .* \((12|4),\)\)"):
        wrap(gym.make(env_id))
    assert wrap(gym.make("neurohover/GHH08-Short-v0")).reset(seed=0)[0].shape == (12,)
    stacked = ScaledObservation(gym.wrappers.FrameStackObservation(gym.make("neurohover/GHH08-Short-v0"), 3))  # rows of 12
    assert stacked.reset(seed=0)[0].shape == (3, 12)
    env = CrashAwareReward(gym.wrappers.RecordEpisodeStatistics(gym.make("neurohover/GHH08-Short-v0")))
    env.reset(seed=0)
    assert env.step(np.zeros(4, dtype=np.float32))[1] < 0.0
