"""Bad-input trial 42 (42b), the Gymnasium environments and RL wrappers: T42-B01 (a native vector env of an ``-RL-v0``
id could not be pickled: its transforms were local lambdas), T42-B04 (ScaledObservation / ScaledAction over an
``-RL-v0`` id applied their transform twice), T42-B05 (ScaledAction's task other than the env's family flew that
family's authority) and the trial's borderline case (the README's vector ``TransformReward(envs, crash_aware)`` recipe
over an ``-RL-v0`` id squashed the rewards twice: documented)."""

from __future__ import annotations

import pickle
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

import neurohover  # noqa: F401  (registers the ids)
import neurohover.wrappers
from neurohover.envs import HoverEnv
from neurohover.envs.rl import ScaledAction, ScaledObservation, make_rl_env
from neurohover.errors import NeurohoverError


def test_b01_an_rl_vector_env_pickles_and_flies_the_same_episodes() -> None:
    """T42-B01: pickle.dumps of gym.make_vec("neurohover/GHH08-RL-v0", vectorization_mode="vector_entry_point") was
    "Can't pickle local object 'make_rl_vector_env.<locals>.<lambda>'". Pickled before reset and mid-episode, the copy
    steps to the original's observations and rewards (autoresets and crashes included)."""
    rng = np.random.default_rng(0)
    v = gym.make_vec("neurohover/GHH08-RL-v0", num_envs=2, vectorization_mode="vector_entry_point", episode_steps=10)
    w = pickle.loads(pickle.dumps(v))
    np.testing.assert_array_equal(v.reset(seed=1)[0], w.reset(seed=1)[0])
    for copy in (w, None):
        u = copy if copy is not None else pickle.loads(pickle.dumps(v))
        for step in range(15):
            a = rng.uniform(-0.3, 0.3, (2, 4)).astype(np.float32)
            a[0] = np.nan if step == 12 else a[0]  # a non-finite action is a crash
            got, want = u.step(a), v.step(a)
            assert step != 12 or (got[2][0] and got[1][0] < -5)  # the crash, charged crash-aware for the steps left
            for x, y in zip(got[:4], want[:4]):
                np.testing.assert_array_equal(x, y)
            assert got[0].dtype == np.float32 and got[1].dtype == np.float64


@pytest.mark.parametrize(
    "wrap, name",
    [(ScaledObservation, "ScaledObservation"), (lambda env: ScaledAction(env, "ghh08"), "ScaledAction")],
    ids=["observation", "action"],
)
def test_b04_the_rl_transforms_are_refused_over_an_env_that_carries_them(wrap, name) -> None:
    """T42-B04: over an -RL-v0 id (which carries both transforms) ScaledObservation divided the readings by the crash
    limits again and ScaledAction made controls of controls; so over themselves."""
    carrying = [
        gym.make("neurohover/GHH08-RL-v0", mdp="train:0"),
        make_rl_env(mdp="train:0"),
        wrap(HoverEnv(episode_steps=5)),
        gym.wrappers.RecordEpisodeStatistics(wrap(HoverEnv(episode_steps=5))),
    ]
    for env in carrying:
        with pytest.raises(NeurohoverError, match=rf"is not allowed in {name}: it carries that transform already.*wrap it once"):
            wrap(env)


def test_b04_one_scaled_observation_over_a_plain_id_sees_what_the_rl_id_sees() -> None:
    """The fix refuses only the second transform: wrapped once over the plain short id, the observations are the RL id's."""
    rl = gym.make("neurohover/GHH08-RL-v0", mdp="train:0")
    once = ScaledAction(ScaledObservation(gym.make("neurohover/GHH08-Short-v0", mdp="train:0")), "ghh08")
    np.testing.assert_array_equal(rl.reset(seed=0)[0], once.reset(seed=0)[0])
    a = np.full(4, 0.1, np.float32)
    np.testing.assert_array_equal(rl.step(a)[0], once.step(a)[0])


class _FourControls(gym.Env):
    """An env of no neurohover family: ScaledAction's task is the user's to choose."""

    observation_space = gym.spaces.Box(-1.0, 1.0, (12,))
    action_space = gym.spaces.Box(-1.0, 1.0, (4,))


def test_b05_scaled_action_refuses_a_task_other_than_the_envs_family() -> None:
    """T42-B05: ScaledAction(<a GHH-08 env>, "fghh") flew FGHH's authority (a = 1 gave full aileron) without a word."""
    env = gym.make("neurohover/GHH08-Short-v0", mdp="train:0")
    with pytest.raises(NeurohoverError, match=r"task='fghh' is not allowed: the env flies family 'ghh08'.*give task='ghh08'"):
        ScaledAction(env, "fghh")
    with pytest.raises(NeurohoverError, match=r"task='ghh08' is not allowed: the env flies family 'fghh'"):
        ScaledAction(HoverEnv("fghh", episode_steps=5), "ghh08")
    assert ScaledAction(env, "GHH-08").task == "ghh08"  # the env's own family, in any spelling the package takes
    np.testing.assert_allclose(ScaledAction(env, "ghh08").action(np.ones(4, np.float32)), [0.52, 0.25, 0.05, 0.43], rtol=1e-6)
    assert ScaledAction(_FourControls(), "fghh").action(np.ones(4, np.float32))[0] == pytest.approx(1.02)  # no family: kept


def test_borderline_the_vector_crash_aware_recipe_names_the_rl_ids() -> None:
    """Trial 42's borderline case: TransformReward(<vector env of an -RL-v0 id>, crash_aware) squashed the crash-aware
    rewards again; a bare function has no env to check, so the README and the wrappers' docstring say where it goes."""
    readme = (Path(__file__).resolve().parents[1] / "README.md").read_text()
    recipe = readme[readme.index("`gymnasium.wrappers.vector.TransformReward(envs, neurohover.wrappers.crash_aware)`") :][:300]
    assert "`-RL-v0` id's rewards are crash-aware already" in recipe
    assert "an ``-RL-v0`` id's rewards are crash-aware already" in (neurohover.wrappers.__doc__ or "")
