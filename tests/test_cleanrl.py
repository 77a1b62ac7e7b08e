"""neurohover.integrations.cleanrl: a CleanRL PPO run folder flown as a batch policy (skipped without torch)."""

from __future__ import annotations

import pickle

import numpy as np
import pytest

torch = pytest.importorskip("torch", reason="torch is not installed (pip install torch==2.13.0)")

from neurohover.errors import NeurohoverError  # noqa: E402
from neurohover.integrations.cleanrl import cleanrl_policy  # noqa: E402


def _run(folder, with_stats: bool = True):
    """A run folder as ppo_continuous_action.py --save-model writes it: its Agent's state dict (critic, actor_mean,
    actor_logstd), and the observation statistics the two documented lines save."""
    nn = torch.nn
    torch.manual_seed(0)
    critic = nn.Sequential(nn.Linear(12, 64), nn.Tanh(), nn.Linear(64, 64), nn.Tanh(), nn.Linear(64, 1))
    actor = nn.Sequential(nn.Linear(12, 64), nn.Tanh(), nn.Linear(64, 64), nn.Tanh(), nn.Linear(64, 4))
    state = {**{f"critic.{k}": v for k, v in critic.state_dict().items()}, **{f"actor_mean.{k}": v for k, v in actor.state_dict().items()}}
    state["actor_logstd"] = torch.zeros(1, 4)
    folder.mkdir()
    torch.save(state, folder / "ppo_continuous_action.cleanrl_model")
    mean, var = np.linspace(-1, 1, 12), np.linspace(0.5, 2, 12)
    if with_stats:
        with open(folder / "obs_rms.pkl", "wb") as f:
            pickle.dump((mean, var), f)
    return actor, mean, var


def test_a_cleanrl_run_flies_its_actors_mean_on_normalised_observations(tmp_path) -> None:
    actor, mean, var = _run(tmp_path / "run")
    act = cleanrl_policy(tmp_path / "run")
    obs = np.random.default_rng(1).normal(scale=30, size=(5, 12)).astype(np.float32)  # some beyond the +-10 clip
    x = np.clip((obs - mean) / np.sqrt(var + 1e-8), -10, 10)
    with torch.no_grad():
        expected = actor(torch.as_tensor(x, dtype=torch.float32)).numpy()
    np.testing.assert_allclose(act(obs), expected, rtol=1e-6)


def test_a_run_without_its_observation_statistics_is_refused_with_the_fix(tmp_path) -> None:
    _run(tmp_path / "run", with_stats=False)
    with pytest.raises(NeurohoverError, match="has no obs_rms.pkl: CleanRL does not save its observation statistics"):
        cleanrl_policy(tmp_path / "run")
    with pytest.raises(NeurohoverError, match="is not a CleanRL run folder"):
        cleanrl_policy(tmp_path / "nothing")
    (tmp_path / "bad").mkdir()
    (tmp_path / "bad" / "x.cleanrl_model").write_text("not torch")
    (tmp_path / "bad" / "obs_rms.pkl").write_text("not a pickle")
    with pytest.raises(NeurohoverError, match="its model or obs_rms.pkl cannot be read"):
        cleanrl_policy(tmp_path / "bad")
