"""A CleanRL ``ppo_continuous_action.py`` run as a batch policy (``neurohover evaluate-agent --cleanrl RUN``).

CleanRL saves the agent's weights (``runs/RUN/ppo_continuous_action.cleanrl_model`` with ``--save-model``) but not
the running observation statistics of its ``NormalizeObservation`` wrapper, without which the policy cannot be
flown again. Two lines at the end of the script save them beside the model (docs/deep-rl.md, "By id alone")::

    wrapper = envs.envs[0]
    while not hasattr(wrapper, "obs_rms"): wrapper = wrapper.env
    pickle.dump((wrapper.obs_rms.mean, wrapper.obs_rms.var), open(f"runs/{run_name}/obs_rms.pkl", "wb"))

:func:`cleanrl_policy` rebuilds the script's actor (64-64 tanh, the Gaussian's mean) from the weights, normalises
observations with the saved statistics (clipped to +-10, as the script's wrappers do) and returns the mean action.
Needs torch (``pip install torch==2.13.0`` for a CPU build).
"""

from __future__ import annotations

import pickle
from collections.abc import Callable
from pathlib import Path

import numpy as np

from ..errors import NeurohoverError

__all__ = ["cleanrl_policy"]

OBS_CLIP = 10.0  # the script's TransformObservation clip after NormalizeObservation
EPSILON = 1e-8  # NormalizeObservation's


def cleanrl_policy(run: str | Path) -> Callable[[np.ndarray], np.ndarray]:
    """The actor of a CleanRL PPO run folder (``*.cleanrl_model`` and ``obs_rms.pkl``) as a batch function."""
    try:
        import torch
        from torch import nn
    except ModuleNotFoundError:
        raise NeurohoverError("a CleanRL run needs torch: pip install torch==2.13.0 (a CPU build)") from None
    folder = Path(run)
    models = sorted(folder.glob("*.cleanrl_model")) if folder.is_dir() else []
    if len(models) != 1:
        raise NeurohoverError(f"{str(folder)!r} is not a CleanRL run folder: expected one *.cleanrl_model in it (run the script with --save-model)")
    stats = folder / "obs_rms.pkl"
    if not stats.is_file():
        raise NeurohoverError(
            f"{str(folder)!r} has no obs_rms.pkl: CleanRL does not save its observation statistics; save them as "
            "neurohover.integrations.cleanrl's docstring shows (two lines at the end of the script), then train again"
        )
    try:
        state = torch.load(models[0], map_location="cpu")
        with stats.open("rb") as f:
            mean, var = pickle.load(f)
    except (RuntimeError, EOFError, ValueError, pickle.UnpicklingError, OSError) as err:
        first = str(err).strip().splitlines()[0] if str(err).strip() else type(err).__name__
        raise NeurohoverError(f"{str(folder)!r}: its model or obs_rms.pkl cannot be read: {first}") from None
    if not isinstance(state, dict):
        raise NeurohoverError(f"{str(models[0])!r} is not a state dict of ppo_continuous_action.py's Agent")
    weights = {k[len("actor_mean.") :]: v for k, v in state.items() if k.startswith("actor_mean.")}
    if not weights:
        raise NeurohoverError(f"{str(models[0])!r} holds no actor_mean weights: not a ppo_continuous_action.py model")
    n_obs, hidden, n_act = weights["0.weight"].shape[1], weights["0.weight"].shape[0], weights["4.weight"].shape[0]
    actor = nn.Sequential(nn.Linear(n_obs, hidden), nn.Tanh(), nn.Linear(hidden, hidden), nn.Tanh(), nn.Linear(hidden, n_act))
    actor.load_state_dict(weights)
    scale = 1.0 / np.sqrt(np.asarray(var, dtype=np.float64) + EPSILON)

    def act(obs: np.ndarray) -> np.ndarray:
        x = np.clip((np.asarray(obs, dtype=np.float64) - mean) * scale, -OBS_CLIP, OBS_CLIP)
        with torch.no_grad():
            return actor(torch.as_tensor(x, dtype=torch.float32)).numpy()

    return act
