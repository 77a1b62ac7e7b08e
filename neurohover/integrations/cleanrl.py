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
from typing import Any

import numpy as np

from ..errors import NeurohoverError, brief
from ..paths import checked_path
from ..sim.constants import ACTION_DIM, OBS_DIM
from .flying import checked_obs_statistics

__all__ = ["cleanrl_files", "cleanrl_policy"]

OBS_CLIP = 10.0  # the script's TransformObservation clip after NormalizeObservation
EPSILON = 1e-8  # NormalizeObservation's
LAYERS = ("0.weight", "0.bias", "2.weight", "2.bias", "4.weight", "4.bias")  # the actor's Linear layers, between Tanh


#: The globals a pickle of NumPy arrays (or lists) of the statistics names (numpy.core: NumPy 1's numpy._core; _frombuffer:
#: pickle protocol 5): nothing else is looked up. pickle.load took any, and ran what the file said (trial 45's note).
_STATS_GLOBALS = frozenset(
    {
        ("numpy", "dtype"),
        ("numpy", "ndarray"),
        *((f"numpy.{core}.multiarray", name) for core in ("_core", "core") for name in ("_reconstruct", "scalar")),
        *((f"numpy.{core}.numeric", "_frombuffer") for core in ("_core", "core")),
        ("_codecs", "encode"),  # bytes in pickle protocols 0 to 2
    }
)


class _StatsUnpickler(pickle.Unpickler):
    def find_class(self, module: str, name: str):
        """Only NumPy's array, scalar and dtype rebuilders (:data:`_STATS_GLOBALS`)."""
        if (module, name) not in _STATS_GLOBALS:
            raise NeurohoverError(f"its pickle names {brief(f'{module}.{name}')}, which no (mean, var) of arrays holds: allowed NumPy arrays or lists")
        return super().find_class(module, name)


def load_obs_statistics(path: Path) -> Any:
    """What the pickle ``path`` (a run's obs_rms.pkl) holds, unpickled with only NumPy's arrays allowed in it."""
    with path.open("rb") as f:
        return _StatsUnpickler(f).load()


def cleanrl_files(run: str | Path) -> tuple[Path, Path]:
    """The files :func:`cleanrl_policy` reads in the CleanRL run folder ``run``: its ``*.cleanrl_model`` and ``obs_rms.pkl``."""
    folder = checked_path(run, "run", "path of a CleanRL run folder")  # None, 5 were pathlib's TypeError (thirteenth trial, F13)
    models = sorted(folder.glob("*.cleanrl_model")) if folder.is_dir() else []
    if len(models) != 1:
        raise NeurohoverError(f"{str(folder)!r} is not a CleanRL run folder: expected one *.cleanrl_model in it (run the script with --save-model)")
    stats = folder / "obs_rms.pkl"
    if not stats.is_file():
        raise NeurohoverError(
            f"{str(folder)!r} has no obs_rms.pkl: CleanRL does not save its observation statistics; save them as "
            "neurohover.integrations.cleanrl's docstring shows (two lines at the end of the script), then train again"
        )
    return models[0], stats


def _actor_weights(state: Any, model: Path, torch) -> dict[str, Any]:
    """The actor's layers of the state dict ``state``, checked: a missing layer, values that are no tensors, NaN weights
    and an actor of other inputs or outputs were tracebacks or flown as a crashing agent (ninth trial)."""
    if not isinstance(state, dict):
        raise NeurohoverError(f"{str(model)!r} is not a state dict of ppo_continuous_action.py's Agent")
    weights = {k[len("actor_mean.") :]: v for k, v in state.items() if isinstance(k, str) and k.startswith("actor_mean.")}
    if not weights:
        raise NeurohoverError(f"{str(model)!r} holds no actor_mean weights: not a ppo_continuous_action.py model")
    if sorted(weights) != sorted(LAYERS):
        raise NeurohoverError(
            f"{str(model)!r} holds actor_mean layers {', '.join(sorted(weights))}: expected {', '.join(LAYERS)} (ppo_continuous_action.py's actor)"
        )
    for key in LAYERS:
        value = weights[key]
        if not isinstance(value, torch.Tensor) or not value.is_floating_point() or value.dim() != (2 if key.endswith("weight") else 1):
            raise NeurohoverError(f"{str(model)!r}: actor_mean.{key} is {type(value).__name__} {str(value)[:40]!r}, not a tensor of real weights")
        if not torch.isfinite(value).all():
            raise NeurohoverError(f"{str(model)!r}: actor_mean.{key} holds non-finite weights (NaN or inf): the model is damaged")
    n_obs, n_act = weights["0.weight"].shape[1], weights["4.weight"].shape[0]
    if (n_obs, n_act) != (OBS_DIM, ACTION_DIM):
        raise NeurohoverError(f"{str(model)!r}: the model's actor takes {n_obs} inputs and gives {n_act} actions, not {OBS_DIM} and {ACTION_DIM}")
    return weights


def cleanrl_policy(run: str | Path) -> Callable[[np.ndarray], np.ndarray]:
    """The actor of a CleanRL PPO run folder (``*.cleanrl_model`` and ``obs_rms.pkl``) as a batch function."""
    model, stats = cleanrl_files(run)  # the path before the library: a file was "needs torch" (trial 30, borderline)
    try:
        import torch
        from torch import nn
    except ModuleNotFoundError:
        raise NeurohoverError("a CleanRL run needs torch: pip install torch==2.13.0 (a CPU build)") from None
    try:
        state = torch.load(model, map_location="cpu")
        loaded = load_obs_statistics(stats)
    except NeurohoverError as err:
        raise NeurohoverError(f"{str(run)!r}: its obs_rms.pkl cannot be read: {err}") from None
    except Exception as err:  # damaged bytes unpickle into any of a dozen exception types
        first = str(err).strip().splitlines()[0] if str(err).strip() else type(err).__name__
        raise NeurohoverError(f"{str(run)!r}: its model or obs_rms.pkl cannot be read: {first}") from None
    weights = _actor_weights(state, model, torch)
    if not isinstance(loaded, (tuple, list)) or len(loaded) != 2:  # 5 or a dict of two keys was a traceback (ninth trial)
        raise NeurohoverError(f"{str(stats)!r} holds {str(loaded)[:60]}, not (mean, var) arrays of {OBS_DIM}")
    mean, var = checked_obs_statistics(loaded[0], loaded[1], OBS_DIM, repr(str(stats)))
    h1, h2 = weights["0.weight"].shape[0], weights["4.weight"].shape[1]
    actor = nn.Sequential(nn.Linear(OBS_DIM, h1), nn.Tanh(), nn.Linear(h1, h2), nn.Tanh(), nn.Linear(h2, ACTION_DIM))
    try:
        actor.load_state_dict(weights)
    except RuntimeError as err:  # the layers' sizes do not chain
        raise NeurohoverError(f"{str(model)!r}: its actor's layers do not fit together: {str(err).strip().splitlines()[-1].strip()}") from None
    scale = 1.0 / np.sqrt(var + EPSILON)

    def act(obs: np.ndarray) -> np.ndarray:
        x = np.clip((np.asarray(obs, dtype=np.float64) - mean) * scale, -OBS_CLIP, OBS_CLIP)
        with torch.no_grad():
            return actor(torch.as_tensor(x, dtype=torch.float32)).numpy()

    return act
