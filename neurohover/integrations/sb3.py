"""Stable-Baselines3 over the native vector environment: every helicopter in one kernel call.

SB3 (and RL Zoo) step a ``VecEnv``; their own ``DummyVecEnv`` steps one Python environment after
another. :class:`SB3VecEnv` is an SB3 ``VecEnv`` over :class:`neurohover.envs.HoverVectorEnv`, so
a step of 1024 helicopters is one kernel call. SB3's conventions are kept: a finished episode
resets at once, its last observation in ``infos[i]["terminal_observation"]`` and
``infos[i]["TimeLimit.truncated"]`` set when the time limit (not a crash) ended it::

    from stable_baselines3 import PPO
    from stable_baselines3.common.vec_env import VecMonitor
    from neurohover.integrations.sb3 import SB3VecEnv

    env = VecMonitor(SB3VecEnv("neurohover/GHH08-Short-v0", num_envs=64))
    PPO("MlpPolicy", env).learn(10_000)

Needs ``stable-baselines3`` (``pip install 'neurohover[examples]'``).
"""

from __future__ import annotations

import importlib
import pickle
import zipfile
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any, cast

import gymnasium as gym
import numpy as np

from ..envs.arguments import check_noise_stream, check_reset_options, real_values
from ..envs.vector import HoverVectorEnv
from ..errors import NeurohoverError, brief, check_flag, finite_real
from ..paths import checked_path
from ..sim.constants import ACTION_DIM
from ..sim.rng import MAX_SEED
from . import SB3_ALGORITHMS
from .flying import checked_obs_statistics
from .sb3_files import check_algo, rl_zoo_files, sb3_model_file

try:
    from stable_baselines3.common.vec_env.base_vec_env import VecEnv
except ModuleNotFoundError as missing:  # the optional extra
    raise NeurohoverError(f"neurohover.integrations.sb3 needs {missing.name}: pip install 'neurohover[examples]'") from None

__all__ = ["RecurrentPolicy", "SB3VecEnv", "UnknownAttributeError", "rl_zoo_files", "rl_zoo_policy", "sb3_policy"]


class UnknownAttributeError(NeurohoverError, AttributeError):
    """:meth:`SB3VecEnv.get_attr` of a name the environment lacks: an AttributeError too, which SB3 catches (has_attr)."""


#: Attributes of the native vector env that hold one entry per helicopter: get_attr gives helicopter i entry i.
_PER_HELICOPTER = ("mdps", "mdp_specs", "noise_streams", "steps")
#: Spaces the native vector env holds batched: get_attr gives each helicopter its own (SB3's DummyVecEnv does).
_SINGLE_SPACES = {"observation_space": "single_observation_space", "action_space": "single_action_space"}


class SB3VecEnv(VecEnv):
    """An SB3 ``VecEnv`` of ``num_envs`` helicopters of a registered id (``gym.make_vec`` keyword
    arguments, e.g. ``mdp="train:3"``, pass through to :class:`~neurohover.envs.HoverVectorEnv`).

    :meth:`seed` and ``set_options`` apply to the next :meth:`reset` only, as in SB3's own vector environments;
    options are each helicopter's, as ``HoverEnv.reset`` takes them: ``{"mdp": spec}`` (kept for later episodes)
    and ``{"noise": (seed, episode)}`` (that very gust stream, given to every helicopter a dict is given to)."""

    def __init__(self, env_id: str, num_envs: int, **kwargs: Any) -> None:
        if env_id not in gym.registry or not str(gym.registry[env_id].entry_point).startswith("neurohover."):
            raise NeurohoverError(f"env_id={env_id!r} is not a neurohover environment: use one of the neurohover/* ids")
        self.venv = gym.make_vec(env_id, num_envs=num_envs, vectorization_mode="vector_entry_point", **kwargs)
        self.native = cast(HoverVectorEnv, self.venv.unwrapped)
        super().__init__(num_envs, self.native.single_observation_space, self.native.single_action_space)
        self._actions: np.ndarray | None = None
        self._seed: int | None = None
        self._reset_with: dict[str, Any] = {}  # the native reset options of set_options, checked

    def reset(self) -> np.ndarray:
        obs, info = self.venv.reset(seed=self._seed, options=self._reset_with or None)
        self._seed, self._reset_with = None, {}
        self._reset_options()  # SB3's: options apply to one reset
        self.reset_infos = [{"mdp": info["mdp"][i]} for i in range(self.num_envs)]
        return obs

    def set_options(self, options: list[dict] | dict | None = None) -> None:
        """The options of the next :meth:`reset` (a dict for every helicopter, or a list of one per helicopter),
        checked now: they were ignored, bad ones too (SB3's VecEnv keeps them for a reset this one replaces; ninth trial)."""
        if options is None:
            options = {}
        if isinstance(options, dict):
            options = [options] * self.num_envs
        if not isinstance(options, (list, tuple)) or len(options) != self.num_envs:
            raise NeurohoverError(f"options={options!r:.80} is not allowed: give None, a dict, or a list of {self.num_envs} dicts (one per helicopter)")
        per_env = [check_reset_options(o) for o in options]  # unknown keys and non-dicts refused, naming them
        native: dict[str, Any] = {}
        if any("mdp" in o for o in per_env):  # a helicopter given none keeps its own
            native["mdp"] = self.native.resolve_mdps([o.get("mdp", spec) for o, spec in zip(per_env, self.native.mdp_specs, strict=True)])
        given = [i for i, o in enumerate(per_env) if "noise" in o]
        if given and len(given) != self.num_envs:
            raise NeurohoverError(f"options give noise to helicopter(s) {given} only: give it to all {self.num_envs} or to none")
        if given:
            native["noise"] = [check_noise_stream(o["noise"], f"options[{i}] noise") for i, o in enumerate(per_env)]
        self._options = [dict(o) for o in per_env]
        self._reset_with = native

    def step_async(self, actions: np.ndarray) -> None:
        a = real_values(actions, f"actions must be a ({self.num_envs}, {ACTION_DIM}) array of real numbers, got {actions!r:.80}")
        if a.shape != (self.num_envs, ACTION_DIM):  # a (4, 2) or (8,) array was reshaped and flown (ninth trial)
            raise NeurohoverError(f"actions have shape {a.shape}, expected ({self.num_envs}, {ACTION_DIM}): one row per helicopter")
        self._actions = a

    def step_wait(self):
        if self._actions is None:  # a bare AssertionError before (ninth trial)
            raise NeurohoverError("step_wait() without a pending step_async(actions): call step_async first, or step(actions)")
        actions, self._actions = self._actions, None
        obs, rewards, terminated, truncated, info = self.venv.step(actions)
        done = terminated | truncated
        infos: list[dict[str, Any]] = [{"crashed": bool(terminated[i])} for i in range(self.num_envs)]
        if done.any():
            for i in np.flatnonzero(done).tolist():
                infos[i]["terminal_observation"] = obs[i].copy()
                infos[i]["TimeLimit.truncated"] = bool(truncated[i] and not terminated[i])
            fresh, _ = self.venv.reset(options={"reset_mask": done})  # SB3 resets at once (Gymnasium: at the next step)
            obs = np.where(done[:, None], fresh, obs)
        return obs, rewards.astype(np.float32), done, infos

    def close(self) -> None:
        self.venv.close()

    def seed(self, seed: int | None = None) -> Sequence[None | int]:
        """The seed of the next :meth:`reset` (sub-environment i: ``seed + i``, as Gymnasium's vector envs)."""
        n = self.num_envs
        if seed is not None and (isinstance(seed, (bool, np.bool_)) or not isinstance(seed, (int, np.integer)) or not 0 <= seed <= MAX_SEED + 1 - n):
            # 'a' was kept and failed every later reset; -1 was refused only there (ninth trial)
            raise NeurohoverError(f"seed={seed!r:.40} is not allowed: give None or an integer in 0..2**63-{n} (helicopter i gets seed + i)")
        self._seed = None if seed is None else int(seed)
        return [None if seed is None else int(seed) + i for i in range(n)]

    def get_attr(self, attr_name: str, indices=None) -> list[Any]:
        """One value per helicopter of ``indices``, read from the native vector environment: its per-helicopter attributes
        (``mdps``, ``mdp_specs``, ``noise_streams``, ``steps``) give each helicopter its own entry, ``observation_space``
        and ``action_space`` each helicopter's own space, and its other attributes (``render_mode``, ``family``,
        ``episode_steps``, ...) the same value for each. A name it lacks raises :class:`UnknownAttributeError`."""
        chosen = self._indices(indices)
        native = self.native
        if not isinstance(attr_name, str) or not hasattr(native, _SINGLE_SPACES.get(attr_name, attr_name)):
            # a bare AttributeError naming HoverVectorEnv, which the user never made (tenth trial)
            public = sorted(n for n in dir(native) if not n.startswith("_") and not callable(getattr(type(native), n, None)))
            raise UnknownAttributeError(
                f"get_attr({attr_name!r:.60}): the helicopters' vector environment has no such attribute; "
                f"per helicopter: {', '.join(_PER_HELICOPTER)}; shared: {', '.join(n for n in public if n not in _PER_HELICOPTER)}"
            )
        value = getattr(native, _SINGLE_SPACES.get(attr_name, attr_name))
        if attr_name in _PER_HELICOPTER:  # each helicopter's own entry, as DummyVecEnv reads each env (tenth trial)
            return [value[i] for i in chosen]
        return [value] * len(chosen)

    def set_attr(self, attr_name: str, value: Any, indices=None) -> None:
        raise NeurohoverError(f"set_attr({attr_name!r}) is not supported: the helicopters share one native vector environment")

    def env_method(self, method_name: str, *method_args, indices=None, **method_kwargs) -> list[Any]:
        raise NeurohoverError(f"env_method({method_name!r}) is not supported: the helicopters share one native vector environment")

    def env_is_wrapped(self, wrapper_class, indices=None) -> list[bool]:
        """False for each helicopter of ``indices``: no Gymnasium wrapper sits between them and SB3."""
        return [False] * len(self._indices(indices))

    def get_images(self) -> Sequence[np.ndarray | None]:
        # SB3's contract is a NotImplementedError, but an empty one did not say why or what to do (tenth trial)
        raise NotImplementedError(
            "SB3VecEnv draws no images (its helicopters fly in one kernel call, render_mode=None): to watch one, "
            "make a single environment with gymnasium.make(env_id, render_mode='rgb_array') and call its render()"
        )

    def _indices(self, indices) -> list[int]:
        """SB3's ``indices`` (None: every helicopter; an int; or an iterable of ints), each in 0..num_envs-1: 5 of 2 and
        'abc' gave lists of 1 and 3 values (tenth trial)."""
        n = self.num_envs
        allowed = f"give None, an int or an iterable of ints in 0..{n - 1} (the helicopters)"
        if indices is None:
            return list(range(n))
        chosen: list[Any] | None = None
        if isinstance(indices, (int, np.integer)):
            chosen = [indices]
        elif not isinstance(indices, (str, bytes, dict)):
            try:
                chosen = list(indices)
            except TypeError:  # not iterable: a float, a 0-d array
                pass
        if chosen is None:
            raise NeurohoverError(f"indices={indices!r:.60} is not allowed: {allowed}")
        bad = [i for i in chosen if isinstance(i, (bool, np.bool_)) or not isinstance(i, (int, np.integer)) or not 0 <= i < n]
        if bad:
            raise NeurohoverError(f"indices={indices!r:.60} is not allowed ({bad[0]!r:.30} is no helicopter): {allowed}")
        return [int(i) for i in chosen]


def _algorithm(algo: str):
    package, name = SB3_ALGORITHMS[check_algo(algo)]
    try:
        return getattr(importlib.import_module(package), name)
    except ModuleNotFoundError:
        raise NeurohoverError(f"algo={algo!r} needs {package}: pip install {package.replace('_', '-')}") from None


def _load(algorithm, path: Path):
    """A saved model (its file checked by :func:`~.sb3_files.sb3_model_file`), or one clear error naming the file
    (another algorithm's, damaged)."""
    try:
        return algorithm.load(path, device="cpu")
    except (zipfile.BadZipFile, KeyError, ValueError, RuntimeError, EOFError, AttributeError, TypeError, pickle.UnpicklingError) as err:
        raise NeurohoverError(f"{str(path)!r} cannot be loaded as a {algorithm.__name__} model: {err}") from None
    except AssertionError:  # another zip (a flight-data .npz): SB3 asserts that it found its data (fourth trial)
        raise NeurohoverError(f"{str(path)!r} is a zip file but not a Stable-Baselines3 model (no model data in it)") from None


class RecurrentPolicy:
    """A recurrent model (sb3-contrib's ``RecurrentPPO``) as an *indexed* batch function ``act(observations, episodes)``:
    each episode keeps its own hidden state from its first step (:func:`neurohover.integrations.flying.evaluate_callable`
    calls it with the indices of the episodes still flying). One object flies one flight: its episodes' states live in it."""

    indexed = True

    def __init__(self, model, deterministic: bool = True, prepare: Callable[[np.ndarray], np.ndarray] | None = None) -> None:
        if not hasattr(getattr(model, "policy", None), "lstm_hidden_state_shape") or not callable(getattr(model, "predict", None)):
            # None was an AttributeError at the first step (thirteenth trial, F13)
            raise NeurohoverError(f"model={brief(model)} is not allowed: give a recurrent Stable-Baselines3 model (sb3-contrib's RecurrentPPO)")
        if prepare is not None and not callable(prepare):
            raise NeurohoverError(f"prepare={brief(prepare)} is not allowed: give a function of the observations, or None")
        self.model, self.deterministic, self.prepare = model, deterministic, prepare
        self.state: tuple[np.ndarray, ...] | None = None
        self.started: np.ndarray | None = None

    def __call__(self, obs: np.ndarray, episodes: np.ndarray) -> np.ndarray:
        episodes = np.asarray(episodes)
        if self.state is None or self.started is None or int(episodes.max()) >= self.started.size:  # the first step of a flight
            layers, _, hidden = self.model.policy.lstm_hidden_state_shape  # the actor's (h, c), one column per episode
            n = int(episodes.max()) + 1
            self.state = (np.zeros((layers, n, hidden), dtype=np.float32), np.zeros((layers, n, hidden), dtype=np.float32))
            self.started = np.zeros(n, dtype=bool)
        x = self.prepare(obs) if self.prepare is not None else obs
        state = tuple(s[:, episodes] for s in self.state)
        actions, new = self.model.predict(x, state=state, episode_start=~self.started[episodes], deterministic=self.deterministic)
        for s, n_ in zip(self.state, new, strict=True):
            s[:, episodes] = n_
        self.started[episodes] = True
        return actions


def _policy_of(model, deterministic: bool, prepare: Callable[[np.ndarray], np.ndarray] | None = None):
    """A loaded model as a batch function (indexed for a recurrent one), observations first through ``prepare``."""
    if hasattr(model.policy, "lstm_hidden_state_shape"):
        return RecurrentPolicy(model, deterministic, prepare)
    if prepare is None:
        return lambda obs: model.predict(obs, deterministic=deterministic)[0]
    return lambda obs: model.predict(prepare(obs), deterministic=deterministic)[0]


def sb3_policy(model_zip: str | Path, *, algo: str = "ppo", deterministic: bool = True) -> Callable[[np.ndarray], np.ndarray]:
    """A saved Stable-Baselines3 model (``MODEL.zip``) as a batch function (observations as it was trained on them:
    wrap it yourself if it learned behind a normaliser), ready for :func:`neurohover.integrations.flying.evaluate_callable`."""
    check_flag(deterministic, "deterministic", "the Gaussian's mean")  # 'no' was true
    path = checked_path(model_zip, "model_zip", "MODEL.zip file path")  # None, 5, b'x.zip' were pathlib's TypeError (thirteenth trial, F13)
    check_algo(algo)  # the arguments in order: algo=['ppo'] beside an empty file was named by the file (T38-A05's order)
    sb3_model_file(path)  # before the algorithm's import
    return _policy_of(_load(_algorithm(algo), path), deterministic)


def _vecnormalize(path: Path, n_obs: int):
    """The frozen VecNormalize statistics pickled in ``path``, checked: a damaged file, another object, or statistics of
    another shape, non-finite or negative variances, were tracebacks or flown as a crashing agent (ninth trial)."""
    from stable_baselines3.common.vec_env import VecNormalize

    try:
        with path.open("rb") as f:
            stats = pickle.load(f)  # a VecNormalize without its environment: normalize_obs needs only its statistics
    except Exception as err:  # damaged bytes unpickle into any of a dozen exception types
        raise NeurohoverError(f"{str(path)!r} cannot be read as VecNormalize statistics ({type(err).__name__}: {str(err)[:80]})") from None
    if not isinstance(stats, VecNormalize):
        raise NeurohoverError(f"{str(path)!r} cannot be read as VecNormalize statistics (it holds {type(stats).__name__} {str(stats)[:60]!r})")
    if getattr(stats, "norm_obs", None) is not False:
        rms = getattr(stats, "obs_rms", None)
        checked_obs_statistics(getattr(rms, "mean", None), getattr(rms, "var", None), n_obs, f"{str(path)!r} (its obs_rms)")
        for name, allowed, ok in (("clip_obs", "> 0", lambda v: v > 0), ("epsilon", ">= 0", lambda v: v >= 0)):
            value = getattr(stats, name, None)
            if not finite_real(value) or not ok(value):
                raise NeurohoverError(
                    f"{str(path)!r} cannot be read as VecNormalize statistics (its {name} is {value!r:.40}: expected a finite number {allowed})"
                )
    stats.training = False
    return stats


def rl_zoo_policy(run: str | Path, *, algo: str = "ppo", deterministic: bool = True) -> Callable[[np.ndarray], np.ndarray]:
    """The trained policy of an RL Zoo run folder (``logs/ppo/neurohover-GHH08-Short-v0_1``), as a batch function.

    It loads the folder's final model (``ENV.zip``, or ``best_model.zip`` when there is no final
    one) and its observation statistics (``ENV/vecnormalize.pkl``, frozen), and maps a batch of
    observations to the model's actions (the Gaussian's mean when ``deterministic``), ready for
    :func:`neurohover.integrations.flying.evaluate_callable`.
    """
    check_flag(deterministic, "deterministic", "the Gaussian's mean")  # 'no' was true
    model_zip, stats_file = rl_zoo_files(run, algo)
    sb3_model_file(model_zip)  # before the algorithm's import
    model = _load(_algorithm(algo), model_zip)
    stats = None if stats_file is None else _vecnormalize(stats_file, int(np.prod(model.observation_space.shape)))
    return _policy_of(model, deterministic, None if stats is None else stats.normalize_obs)
