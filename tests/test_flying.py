"""Flying a Python batch policy: the same episodes as ``neurohover.evaluate`` flies a policy file."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import neurohover as nh
from neurohover.integrations.flying import evaluate_callable

GHH08 = nh.get_task_family("ghh08")


def batch_of(policy: nh.Policy):
    return lambda obs: np.array([policy.act(o) for o in obs])


def test_a_python_policy_meets_the_gusts_evaluate_gives_a_policy_file() -> None:
    mdps = [GHH08.mdp("train:0"), GHH08.mdp("train:7")]
    baseline = nh.baseline_policy()
    flown = evaluate_callable(batch_of(baseline), mdps, episodes=3, seed=5, first_episode=2, n_steps=200, obs_dtype="float64")
    kernel = nh.evaluate(baseline, mdps, episodes=3, seed=5, first_episode=2, n_steps=200)
    assert flown.returns.shape == (2, 3)
    np.testing.assert_allclose(flown.returns, kernel.returns[0], rtol=1e-12)
    np.testing.assert_array_equal(flown.steps, kernel.steps[0])
    assert len(set(flown.returns.ravel().round(6))) == 6  # six different gust streams, not one repeated


def test_a_crashing_policy_stops_counting_at_its_crash() -> None:
    flown = evaluate_callable(lambda obs: np.ones((len(obs), 4)), GHH08.mdp("zero"), episodes=2, n_steps=300)
    assert flown.crashed.all() and (flown.steps < 300).all()
    for e in range(2):  # the one-helicopter environment, on the same gust stream, ends the same way
        env = gym.make("neurohover/GHH08-v0", mdp="zero", episode_steps=300, obs_dtype="float32")
        env.reset(options={"noise": (0, e)})
        total, steps, done = 0.0, 0, False
        while not done:
            _, reward, terminated, truncated, _ = env.step(np.ones(4))
            total, steps, done = total + reward, steps + 1, terminated or truncated
        assert terminated and steps == flown.steps[0, e]
        np.testing.assert_allclose(flown.returns[0, e], total, rtol=1e-12)


def test_on_step_is_called_once_a_control_step_of_the_flight() -> None:
    """evaluate-agent's progress bar counts these: as many as the longest episode's steps."""
    calls = []
    flown = evaluate_callable(lambda obs: np.ones((len(obs), 4)), GHH08.mdp("zero"), episodes=2, n_steps=300, on_step=lambda: calls.append(1))
    assert len(calls) == flown.steps.max() < 300


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"mdps": []}, "non-empty sequence of MDPs"),
        ({"mdps": [GHH08.mdp("zero"), nh.get_task_family("ghh09").mdp("zero")]}, "one task family"),
        ({"episodes": 0}, "episodes=0 is out of range"),
        ({"episodes": 10**6}, "episodes=1000000 is out of range"),
        ({"act": lambda obs: np.zeros(4)}, "act returned actions of shape (4,)"),
    ],
)
def test_bad_input_is_refused_naming_the_value(kwargs: dict, message: str) -> None:
    args = {"act": lambda obs: np.zeros((len(obs), 4)), "mdps": GHH08.mdp("zero"), "episodes": 1, "n_steps": 5, **kwargs}
    act, mdps = args.pop("act"), args.pop("mdps")
    with pytest.raises(nh.NeurohoverError, match=message.replace("(", r"\(").replace(")", r"\)")):
        evaluate_callable(act, mdps, **args)
