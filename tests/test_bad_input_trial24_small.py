"""Bad input, trial 24, small findings: the RL ids flew an infinite action as full control where the plain ids crash
(T24-10); evaluate called a non-integer episodes "out of range" (T24-11); evolve's refusals all start "neurohover evolve:"
(T24-12, pinned: the trial's own output had the prefix)."""

from __future__ import annotations

import re

import gymnasium as gym
import numpy as np
import pytest

import neurohover as nh
from neurohover.envs import rl
from neurohover.errors import NeurohoverError, brief
from neurohover.evaluate import evaluate

NON_FINITE = [np.inf, -np.inf, np.nan]


@pytest.mark.parametrize("bad", NON_FINITE, ids=["inf", "-inf", "nan"])
def test_a_non_finite_action_crashes_on_the_rl_ids_as_on_the_plain_ids(bad: float) -> None:
    """T24-10: GHH08-RL-v0 clipped +-inf to full control and flew on (crashed False) where GHH08-v0 crashes."""
    for env_id in ("neurohover/GHH08-v0", "neurohover/GHH08-RL-v0"):
        env = gym.make(env_id, episode_steps=20)
        env.reset(seed=1)
        _, _, terminated, truncated, info = env.step(np.array([bad, 0, 0, 0], dtype=np.float32))
        assert terminated and not truncated and info["crashed"], (env_id, bad)
        vec = gym.make_vec(env_id, num_envs=3, vectorization_mode="vector_entry_point", episode_steps=20)
        vec.reset(seed=1)
        actions = np.zeros((3, 4), dtype=np.float32)
        actions[0, 0] = bad
        actions[1, 3] = bad
        _, _, terminated, _, info = vec.step(actions)
        np.testing.assert_array_equal(terminated, [True, True, False], err_msg=f"{env_id} {bad}")
        np.testing.assert_array_equal(info["crashed"], [True, True, False])


def test_controls_of_a_non_finite_action_are_not_finite_and_finite_ones_still_clip() -> None:
    """T24-10: controls() made +inf the authority's control; a finite action past +-1 is still clipped."""
    a = np.array([[np.inf, 0, 0, 0], [0, -np.inf, 0, 0], [0, 0, np.nan, 0], [5.0, -5.0, 0.5, 0]])
    c = rl.controls(a, "ghh08")
    assert not np.isfinite(c[0, 0]) and not np.isfinite(c[1, 1]) and not np.isfinite(c[2, 2])
    assert np.isfinite(c[:3][np.eye(3, 4) == 0]).all()  # the other controls of those rows as usual
    np.testing.assert_allclose(c[3], rl.controls(np.array([1.0, -1.0, 0.5, 0]), "ghh08"))


@pytest.mark.parametrize("bad", [1.5, True, np.float64(2.0), "2", np.timedelta64(4)], ids=repr)
def test_evaluate_calls_a_non_integer_episodes_not_allowed(bad: object) -> None:
    """T24-11: episodes=1.5 (or True) said "is out of range: allowed an integer >= 1", where n_steps=10.0 "is not allowed"."""
    mdp = nh.get_task_family("ghh08").mdp("test:0")
    allowed = "allowed an integer in 1..100,000,000 (policies x MDPs x episodes in one call)"
    with pytest.raises(NeurohoverError, match="^" + re.escape(f"episodes={brief(bad)} is not allowed: {allowed}") + "$"):
        evaluate(nh.baseline_policy(), mdp, episodes=bad, n_steps=10)


@pytest.mark.parametrize("bad", [0, -1, 10**13], ids=repr)
def test_evaluate_calls_an_integer_episodes_past_the_range_out_of_range(bad: int) -> None:
    """T24-11: an integer outside 1..MAX_EPISODES_PER_CALL is "out of range", with the range."""
    mdp = nh.get_task_family("ghh08").mdp("test:0")
    allowed = "allowed an integer in 1..100,000,000 (policies x MDPs x episodes in one call)"
    with pytest.raises(NeurohoverError, match="^" + re.escape(f"episodes={bad} is out of range: {allowed}") + "$"):
        evaluate(nh.baseline_policy(), mdp, episodes=bad, n_steps=10)
    assert evaluate(nh.baseline_policy(), mdp, episodes=np.int64(2), n_steps=10).returns.shape == (1, 1, 2)


EVOLVE = ["evolve", "--task", "ghh08", "--mdp", "G", "--budget", "10", "--episode-steps", "20"]


@pytest.mark.parametrize(
    ("extra", "words"),
    [
        (["--resampling", "race:1"], "bad resampling 'race:1': DELTA must be a number strictly between 0 and 1"),  # the finding's run
        (["--resampling", "fixed:0"], "bad resampling 'fixed:0'"),
        (["--setting", "zzz=1"], "zzz"),
        (["--preset", "zzz"], "argument --preset: invalid choice: 'zzz'"),
        (["--checkpoint-every", "1e400"], "argument --checkpoint-every:"),  # options.real, an argparse type function
        (["--threads", "1_0"], "argument --threads:"),  # options.integer
        (["--plateau-rule", "zzz"], "zzz"),  # a settings-dataclass option (options._converter)
    ],
)
def test_every_evolve_refusal_starts_with_the_command(extra: list[str], words: str, capsys, tmp_path) -> None:
    """T24-12: the finding quoted `evolve: error: bad resampling ...`; the trial's own output (and every option parsed
    by a type function, a choice or the command's own check) says `neurohover evolve: error:`, in one line."""
    from neurohover.cli import main

    try:
        rc = main([*EVOLVE, "--out", str(tmp_path / "q.json"), *extra])
    except SystemExit as done:  # argparse's refusals exit from inside main
        rc = done.code
    out, err = capsys.readouterr()
    assert rc == 2 and out == "", (rc, out, err)
    assert err.startswith("neurohover evolve: error: ") and words in err and len(err.splitlines()) == 1, err
    assert not (tmp_path / "q.json").exists()
