"""Many helicopters in one Gymnasium vector environment, stepped by one kernel call.

``HoverVectorEnv`` is what ``gymnasium.make_vec("neurohover/GHH08-v0", num_envs=N,
vectorization_mode="vector_entry_point")`` builds. Every ``step`` advances all N helicopters
through a single call of the kernel's step (:func:`neurohover.launch.stepper` chooses the CPU's
:func:`neurohover.sim.step.step_batch` or the CUDA build); Python only touches the
sub-environments that reset.

Example
-------
>>> import gymnasium as gym
>>> import numpy as np
>>> import neurohover
>>> envs = gym.make_vec("neurohover/GHH09-v0", num_envs=1024, vectorization_mode="vector_entry_point")
>>> obs, info = envs.reset(seed=0)
>>> obs, rewards, terminated, truncated, info = envs.step(np.zeros((1024, 4)))
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numba as nb
import numpy as np
from gymnasium import logger
from gymnasium.utils import seeding
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from ..errors import NeurohoverError, brief, whole_number
from ..launch import check_device, stepper
from ..sim.constants import ACTION_DIM, EPISODE_STEPS, MDP_ROW_LEN, OBS_DIM
from ..sim.rng import MAX_SEED, seed_stream
from ..sim.step import ENV_NOISE_WIDTH, ENV_RNG_WIDTH, start_readings
from ..tasks import MDP, TaskFamily, refuse_drift
from .arguments import (
    MDP_OPTIONS,
    SAMPLE,
    FixedSettings,
    MdpSpec,
    check_action_dtype,
    check_against_id,
    check_count,
    check_episode_steps,
    check_no_unknown_kwargs,
    check_noise_stream,
    check_obs_dtype,
    check_reset_options,
    draw_stream_seed,
    real_values,
    refuse_idle_sigma,
    resolve_mdp,
    sensed_family,
)
from .hover import RENDER_FPS, action_space, initial_state, mdp_info, observation_space

MAX_NUM_ENVS = 10**7
#: What ``gymnasium.make_vec`` may pass to :class:`HoverVectorEnv`.
VECTOR_ENV_KWARGS = (
    "num_envs", "task", "sigma", "mdp", "episode_steps", "max_episode_steps", "render_mode", "obs_dtype", "device", "action_dtype", "obs_noise", "obs_delay",
    "autoreset_mode",
)  # fmt: skip


@nb.njit(cache=True)
def _seed_streams(rngs: np.ndarray, idx: np.ndarray, streams: np.ndarray) -> None:
    """Seed the noise streams of sub-environments ``idx`` from their (seed, episode) rows."""
    for i in idx:
        seed_stream(rngs[i], np.uint64(streams[i, 0]), np.uint64(streams[i, 1]))


def _next_step_only(mode: Any) -> AutoresetMode:
    """The vector env's autoreset mode: NEXT_STEP, the one it resets in; given as such it was refused as an unknown
    argument, and another mode was refused without naming the one it takes (T38-B01)."""
    try:
        taken = AutoresetMode.NEXT_STEP if mode is None else AutoresetMode(mode)
    except (ValueError, TypeError):
        taken = None
    if taken is not AutoresetMode.NEXT_STEP:
        raise NeurohoverError(f"autoreset_mode={brief(mode)} is not supported: this vector env resets in AutoresetMode.NEXT_STEP ('NextStep') only")
    return taken


def _listed(mdp: Any) -> Any:
    """An ``mdp`` setting given as a plain 1-D NumPy array (of names, say) as the list it holds, as a list is taken: it
    was refused as no name (T47-B14); anything else as it is."""
    if isinstance(mdp, np.ndarray) and not isinstance(mdp, np.ma.MaskedArray) and mdp.ndim == 1:
        return mdp.tolist()
    return mdp


class HoverVectorEnv(FixedSettings, VectorEnv):
    """``num_envs`` independent hovering helicopters (see :class:`neurohover.envs.hover.HoverEnv`).

    Observations are float64 arrays of shape (num_envs, 12) (float32 with
    ``obs_dtype="float32"``), actions (num_envs, 4); rewards (float64),
    terminations and truncations are (num_envs,) arrays. Sub-environments reset automatically
    in Gymnasium's ``NEXT_STEP`` mode: the step after sub-environment i terminated or was
    truncated ignores its action and returns its new episode's first observation (all zeros; with noisy sensors their reading),
    reward 0 and ``terminated = truncated = False``. The arguments are fixed once it is made: setting one
    (``envs.episode_steps = 50``, ``set_wrapper_attr``) is refused; make another environment.

    Parameters
    ----------
    num_envs : int
        Number of helicopters.
    task : {"ghh08", "ghh09", "fghh"}
        Task family.
    sigma : float, optional
        FGHH only: relative standard deviation of the dynamics parameters (default 0.3); refused when every
        sub-environment's ``mdp`` is ``"zero"`` (the same MDP at every sigma).
    mdp : str, MDP or sequence of them
        ``"sample"`` (default: each sub-environment draws its own fresh MDP from G at every
        reset), ``"zero"``, ``"train:N"``, ``"test:N"`` or an :class:`~neurohover.MDP`, for all
        sub-environments, or a sequence of ``num_envs`` of these (a list, a tuple or a 1-D array), one per
        sub-environment. An explicit MDP is seen through the sensors of ``obs_noise`` / ``obs_delay`` (or the
        id's), as one named by text is; one with a sensor of its own flies it under exact sensors, and is refused
        beside another.
    episode_steps : int
        Control steps per episode (6000); the crash penalty counts the steps left to it.
    max_episode_steps : int, optional
        Truncate earlier than ``episode_steps`` (``make_vec`` passes the registered limit).
    obs_dtype : {"float64", "float32"}
        dtype of the observation space and the returned observations (the simulation runs in
        float64 either way).
    render_mode : None
        No rendering (render a single :class:`~neurohover.envs.hover.HoverEnv` instead).
    device : {"cpu", "cuda"}
        Where the helicopters fly (docs/gpu.md). ``"cuda"``: one CUDA thread per helicopter; the
        states, gust noise, noise-stream states and step counters stay on the GPU between steps,
        and each step copies the actions in and the observations, rewards and crash flags out
        (resets copy the reset sub-environments' rows in). ``"cuda"`` where no GPU is usable
        raises :class:`~neurohover.NeurohoverError`.
    action_dtype : {"float64", "float32"}
        dtype of the action space (the simulation runs in float64 either way).
    autoreset_mode : AutoresetMode, optional
        ``AutoresetMode.NEXT_STEP`` (or its value ``"NextStep"``), the one mode it resets in, as its metadata says;
        None: that one. Another mode is refused by name.

    Notes
    -----
    Seeding follows ``SyncVectorEnv``: ``reset(seed=s)`` gives sub-environment i its own
    generator seeded with ``s + i`` (a list of seeds gives one each). Each reset of a
    sub-environment, automatic or not, draws from its generator the MDP (when sampled) and then
    its gust-noise stream seed, exactly as ``HoverEnv`` does, so sub-environment i flies the same
    episodes, bit for bit, as ``HoverEnv`` after ``reset(seed=s + i)`` and then plain
    ``reset()`` calls, given the same actions.

    ``reset`` options: ``"mdp"`` (as the ``mdp`` argument; kept for later episodes: with ``reset_mask``, a
    sub-environment not reset now keeps flying its episode and takes its entry at its next reset, automatic or not),
    ``"noise"`` (this reset only: one ``(seed, episode)`` pair, which gives sub-environment i the
    stream ``(seed, episode + i)`` like ``neurohover.evaluate_jobs`` with consecutive episode
    indices, or a sequence of ``num_envs`` pairs) and ``"reset_mask"`` (a (num_envs,) bool array:
    reset only those sub-environments; the others keep flying).

    Info: ``"crashed"`` every step; ``"mdp"`` (MDP labels) and ``"mdp_info"`` (family, label and
    parameters, as :func:`neurohover.envs.hover.mdp_info` gives them) for the sub-environments
    that reset, each with Gymnasium's ``"_key"`` mask. ``"mdp_info"`` is laid out as
    ``SyncVectorEnv`` lays out the single environment's: a dict of (num_envs,) object arrays
    ``"family"``, ``"label"``, ``"params"`` (tuples), ``"param_names"`` (tuples), each with its
    mask. The current MDPs are ``mdps``.
    """

    metadata = {"render_modes": [], "render_fps": RENDER_FPS, "autoreset_mode": AutoresetMode.NEXT_STEP}
    _FIXED = (*VECTOR_ENV_KWARGS, "family")  # fixed once made (FixedSettings; T32-B04)

    def __init__(
        self,
        num_envs: int = 1,
        task: str = "ghh08",
        sigma: float | None = None,
        mdp: MdpSpec | Sequence[MdpSpec] = SAMPLE,
        episode_steps: int = EPISODE_STEPS,
        max_episode_steps: int | None = None,
        render_mode: str | None = None,
        obs_dtype: Any = "float64",
        device: str = "cpu",
        action_dtype: Any = "float64",
        obs_noise: Any = None,
        obs_delay: Any = None,
        autoreset_mode: Any = None,
        **unknown: Any,
    ) -> None:
        check_no_unknown_kwargs(unknown, VECTOR_ENV_KWARGS)
        self.autoreset_mode = _next_step_only(autoreset_mode)
        check_device(device)
        check_count(num_envs, "num_envs", MAX_NUM_ENVS)  # 8.0 was called out of range (T22-14)
        if render_mode is not None:
            raise NeurohoverError(f"render_mode={render_mode!r} is not supported: this environment has no rendering (use None)")
        n = int(num_envs)
        self.num_envs = n
        self.obs_dtype = check_obs_dtype(obs_dtype)
        self.family: TaskFamily = sensed_family(task, sigma, obs_noise, obs_delay)
        self.episode_steps = check_episode_steps(episode_steps)
        self.max_episode_steps = self.episode_steps if max_episode_steps is None else check_episode_steps(max_episode_steps, "max_episode_steps")
        self._limit = min(self.episode_steps, self.max_episode_steps)
        self._specs: list[MDP | str] = self.resolve_mdps(mdp)
        refuse_idle_sigma(sigma, _listed(mdp))
        self.render_mode = None
        self.single_observation_space = observation_space(self.obs_dtype)
        self.single_action_space = action_space(check_action_dtype(action_dtype))
        self.observation_space = batch_space(self.single_observation_space, n)
        self.action_space = batch_space(self.single_action_space, n)

        self._rows = np.zeros((n, MDP_ROW_LEN))
        self._index = np.arange(n, dtype=np.int64)  # sub-environment i flies MDP row i
        self._state = np.tile(initial_state(), (n, 1))
        self._noise = np.zeros((n, 6))  # widened (_make_room_for_sensors) once an MDP with a sensor model is flown
        self._rng = np.zeros((n, 4), dtype=np.uint64)
        self._steps = np.zeros(n, dtype=np.int64)
        self._obs = np.zeros((n, OBS_DIM))  # the current observation of every sub-environment
        self._reward = np.zeros(n)
        self._crash = np.zeros(n, dtype=np.bool_)
        self._actions = np.zeros((n, ACTION_DIM))
        self._streams = np.zeros((n, 2), dtype=np.int64)
        self._gens: list[np.random.Generator | None] = [None] * n
        self._mdps: list[MDP | None] = [None] * n
        self._draws: list[np.ndarray | None] = [None] * n  # raw draw of each sampled MDP
        self._sample_template, self._sample_slice = self.family.row_template(), self.family.row_slice
        self._sample_label = f"{self.family.name}/sample"
        self._sample_names = tuple(self.family.param_names)
        self._autoreset = np.zeros(n, dtype=np.bool_)
        self._any_autoreset = False
        self._ready = False
        self._all = np.ones(n, dtype=np.bool_)
        self._all.setflags(write=False)
        self.device = device
        self._make_room_for_sensors(self._specs, made=False)
        # On the GPU the host's _state, _noise and _rng rows are written only by resets (and then
        # copied in); the device holds the flying values. _steps is mirrored on the host.
        self._stepper = stepper(device, self._rows, self._index, self._state, self._noise, self._rng, self._steps)
        self.fix_settings()  # its settings are fixed from here (FixedSettings)

    # -- read-only views -------------------------------------------------------------------

    _env_spec: Any = None

    @property
    def spec(self) -> Any:
        """Gymnasium's ``EnvSpec`` of the environment (None unless made by ``gymnasium.make_vec``)."""
        return self._env_spec

    @spec.setter
    def spec(self, value: Any) -> None:  # make_vec sets it on the env it built: the kwargs it merged are checked here
        check_against_id(value, self.family, self.episode_steps, self.max_episode_steps)
        self._env_spec = value

    @property
    def mdps(self) -> list[MDP | None]:
        """The MDP each sub-environment flies in its current episode (None before reset)."""
        for i, d in enumerate(self._draws):
            if d is not None and self._mdps[i] is None:
                self._mdps[i] = self.family.make(d, label=self._sample_label)
        return list(self._mdps)

    @property
    def noise_streams(self) -> np.ndarray:
        """(num_envs, 2) array: the (seed, episode) gust-noise stream of each current episode."""
        return self._streams.copy()

    @property
    def steps(self) -> np.ndarray:
        """Control steps flown by each sub-environment in its current episode."""
        return self._steps.copy()

    def _senses(self, specs: Sequence[MDP | str]) -> bool:
        return any(not (self.family.sensor if isinstance(spec, str) else spec.sensor).exact for spec in specs)  # a str spec is SAMPLE

    def _make_room_for_sensors(self, specs: Sequence[MDP | str], made: bool = True) -> None:
        """Widen the per-helicopter noise and stream state for sensor models (kept narrow, and fast, without them);
        ``made``: the stepper exists (and then steps the widened arrays)."""
        if self._noise.shape[1] >= ENV_NOISE_WIDTH or not self._senses(specs):
            return
        if made and self.device == "cuda":
            raise NeurohoverError(
                "this vector environment on device='cuda' was made without a sensor model and cannot fly one now: "
                "make it with obs_noise/obs_delay, or with the sensing MDPs as its mdp argument"
            )
        n = self.num_envs
        noise, rng = np.zeros((n, ENV_NOISE_WIDTH)), np.zeros((n, ENV_RNG_WIDTH), dtype=np.uint64)
        noise[:, :6], rng[:, :4] = self._noise, self._rng
        self._noise, self._rng = noise, rng
        if made:
            self._stepper = stepper(self.device, self._rows, self._index, self._state, self._noise, self._rng, self._steps)

    # -- argument checks -------------------------------------------------------------------

    @property
    def mdp_specs(self) -> tuple[MDP | str, ...]:
        """Each helicopter's MDP setting as its next reset reads it: an MDP, or ``"sample"`` (a fresh draw each episode)."""
        return tuple(self._specs)

    def resolve_mdps(self, value: Any) -> list[MDP | str]:
        """The ``mdp`` option of :meth:`reset` (one MDP, a name, or one per helicopter) as one setting per helicopter,
        checked: a name the family does not know, a wrong count or a drifting MDP raise NeurohoverError."""
        cache: dict[str, MDP] = {}
        value = _listed(value)
        if isinstance(value, (str, MDP)):
            specs = [resolve_mdp(self.family, value, cache)] * self.num_envs
        elif isinstance(value, (list, tuple)):
            if len(value) != self.num_envs:
                raise NeurohoverError(f"mdp has {len(value)} entries but there are num_envs={self.num_envs} sub-environments")
            specs = [resolve_mdp(self.family, v, cache) for v in value]
        else:  # the per-helicopter form named too (T47-B14)
            raise NeurohoverError(
                f"mdp={brief(value)} is not allowed: use one of {', '.join(MDP_OPTIONS)} or an MDP instance, "
                f"or a sequence of num_envs={self.num_envs} of these (a list or a 1-D array), one per sub-environment"
            )
        for spec in specs:
            if isinstance(spec, MDP):
                refuse_drift(spec, "the vector environment (one episode per sub-environment, no runs)")
        return specs

    def _check_seeds(self, seed: Any) -> list[int | None]:
        n = self.num_envs
        if seed is None:
            return [None] * n
        if whole_number(seed):  # np.timedelta64, a NumPy integer, was int()'s TypeError (T17-1)
            if not 0 <= seed <= MAX_SEED + 1 - n:  # every seed's range (the last helicopter's seed + n - 1 too)
                raise NeurohoverError(f"seed={brief(seed)} is out of range: allowed an integer in 0..2**63-{n}")
            return [int(seed) + i for i in range(n)]
        if (  # an array: 1-D and plain (a 0-d one was len()'s TypeError, T16-5; a masked one's mask would be dropped)
            (isinstance(seed, (list, tuple)) or (isinstance(seed, np.ndarray) and not isinstance(seed, np.ma.MaskedArray) and seed.ndim == 1))
            and len(seed) == n
            and all(s is None or (whole_number(s) and 0 <= s <= MAX_SEED) for s in seed)
        ):
            return [None if s is None else int(s) for s in seed]
        raise NeurohoverError(  # one seed's range as the refusal above states it: seed + i seeds sub-environment i (T55-B11)
            f"seed={brief(seed)} is not allowed: give None, an integer in 0..2**63-{n}, or a list of {n} integers in 0..2**63-1 (or None)"
        )

    def _check_streams(self, value: Any) -> list[tuple[int, int]]:
        n = self.num_envs
        if isinstance(value, np.ma.MaskedArray):  # its masked entries would be read at their hidden values (T16-9)
            raise NeurohoverError(f"noise={brief(value)} is not allowed: give a (seed, episode) pair or {n} of them, not a masked array")
        try:
            per_env = np.ndim(value) == 2
        except ValueError:  # ragged nesting
            per_env = False
        if per_env:
            if len(value) != n:
                raise NeurohoverError(f"noise has {len(value)} (seed, episode) pairs but there are num_envs={n} sub-environments")
            return [check_noise_stream(tuple(v), f"noise[{i}]") for i, v in enumerate(value)]
        seed, episode = check_noise_stream(value)
        if episode + n - 1 > 2**63 - 1:
            raise NeurohoverError(f"noise episode {episode} + {n - 1} sub-environments exceeds 2**63-1")
        return [(seed, episode + i) for i in range(n)]

    def _check_mask(self, mask: Any) -> np.ndarray:
        # a masked array's masked entries were reset at their hidden values (sixteenth trial T16-9)
        if (
            not isinstance(mask, np.ndarray)
            or isinstance(mask, np.ma.MaskedArray)
            or mask.dtype != np.bool_
            or mask.shape != (self.num_envs,)
            or not mask.any()
        ):
            raise NeurohoverError(
                f"reset_mask must be a bool numpy array of shape ({self.num_envs},) with at least one True (not a masked array), got {brief(mask)}"
            )
        return mask.copy()

    def _coerce_actions(self, actions: Any) -> np.ndarray:
        a = real_values(actions, lambda: f"actions must be a ({self.num_envs}, 4) array of real numbers, got {brief(actions)}")
        if a.shape != (self.num_envs, ACTION_DIM):
            raise NeurohoverError(f"actions have shape {a.shape}, expected ({self.num_envs}, 4): aileron, elevator, rudder, collective per helicopter")
        np.copyto(self._actions, a)
        return self._actions

    # -- episodes --------------------------------------------------------------------------

    def _reset_envs(self, idx: np.ndarray, streams: list[tuple[int, int]] | None) -> None:
        """Start new episodes in sub-environments ``idx`` (their generators already exist)."""
        sample_params = self.family.sample_params
        template, where = self._sample_template, self._sample_slice
        seeds = []
        for i in idx.tolist():
            gen = self._gens[i]
            spec = self._specs[i]
            if isinstance(spec, str):  # SAMPLE: "is SAMPLE" failed on an unpickled copy, whose string is equal but another (T32-B19)
                # The same draws as family.sample(gen), but building the MDP object is ~8x dearer
                # than the draw itself, so it is built only when someone asks (``mdps``).
                d = sample_params(gen, 1)[0]
                row = self._rows[i]
                row[:] = template
                row[where] = d
                self._draws[i] = d
                self._mdps[i] = None
            elif spec is not self._mdps[i]:
                self._rows[i] = spec.row()
                self._draws[i] = None
                self._mdps[i] = spec
            if streams is None:
                seeds.append(draw_stream_seed(gen))
        if streams is None:
            self._streams[idx, 0] = seeds
            self._streams[idx, 1] = 0
        else:
            self._streams[idx] = [streams[i] for i in idx.tolist()]
        _seed_streams(self._rng, idx, self._streams)
        self._state[idx] = initial_state()
        self._noise[idx] = 0.0
        self._steps[idx] = 0
        # The first readings: all zeros (the start state observes so), or what the sensors make of them.
        start_readings(self._rows, self._index, idx, self._streams, self._rng, self._noise, self._obs)
        self._stepper.set_rows(idx, self._rows[idx], self._state[idx], self._noise[idx], self._rng[idx], self._steps[idx])

    def _labels(self, idx: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        labels = np.full(self.num_envs, None, dtype=object)
        mask = np.zeros(self.num_envs, dtype=np.bool_)
        for i in idx.tolist():
            labels[i] = self._sample_label if self._draws[i] is not None else self._mdps[i].label
        mask[idx] = True
        return labels, mask

    def _mdp_infos(self, idx: np.ndarray, mask: np.ndarray) -> dict[str, np.ndarray]:
        """``info["mdp_info"]`` of sub-environments ``idx`` (``mask``: their bool mask)."""
        n = self.num_envs
        family, label, params, names = (np.full(n, None, dtype=object) for _ in range(4))
        # Sampled MDPs (the common case, hundreds per step under a crashing policy) column by column.
        sampled = [i for i in idx.tolist() if self._draws[i] is not None]
        if sampled:
            family[sampled], label[sampled] = self.family.name, self._sample_label
            for i in sampled:  # one at a time: a list of equal-length tuples would be read as a 2-D array
                params[i], names[i] = tuple(self._draws[i].tolist()), self._sample_names
        for i in idx.tolist():
            if self._draws[i] is None:
                item = mdp_info(self._mdps[i])
                family[i], label[i], params[i], names[i] = item["family"], item["label"], item["params"], item["param_names"]
        return {
            "family": family,
            "_family": mask.copy(),
            "label": label,
            "_label": mask.copy(),
            "params": params,
            "_params": mask.copy(),
            "param_names": names,
            "_param_names": mask.copy(),
        }

    def reset(self, *, seed: int | Sequence[int | None] | None = None, options: dict[str, Any] | None = None) -> tuple[np.ndarray, dict[str, Any]]:
        options = check_reset_options(options, extra=("reset_mask",))
        # Validate everything before changing anything, so a bad call leaves the env as it was.
        seeds = self._check_seeds(seed)
        mask = self._check_mask(options["reset_mask"]) if "reset_mask" in options else self._all
        specs = self.resolve_mdps(options["mdp"]) if "mdp" in options else self._specs
        streams = self._check_streams(options["noise"]) if "noise" in options else None
        if not self._ready and not mask.all():
            raise NeurohoverError("the first reset() must reset every sub-environment: leave out reset_mask")
        self._make_room_for_sensors(specs)
        if whole_number(seed):
            super().reset(seed=int(seed))
        idx = np.flatnonzero(mask)
        for i in idx.tolist():
            if seeds[i] is not None or self._gens[i] is None:
                self._gens[i], _ = seeding.np_random(seeds[i])
        if "mdp" in options:  # every entry: those of sub-environments masked out were dropped (T14-15)
            self._specs = list(specs)
        self._reset_envs(idx, streams)
        self._autoreset[idx] = False
        self._any_autoreset = bool(self._autoreset.any())
        self._ready = True
        labels, label_mask = self._labels(idx)
        info = {
            "mdp": labels,
            "_mdp": label_mask,
            "crashed": np.zeros(self.num_envs, dtype=np.bool_),
            "_crashed": label_mask.copy(),
            "mdp_info": self._mdp_infos(idx, label_mask),
            "_mdp_info": label_mask.copy(),
        }
        return self._obs.astype(self.obs_dtype), info

    def render(self) -> None:
        """No frame: this environment has no rendering (``render_mode`` is None), so, as :class:`HoverEnv` without a render
        mode does, it warns and returns None (Gymnasium's NotImplementedError before; T14-14)."""
        logger.warn(
            "HoverVectorEnv has no rendering (its render_mode is None): render a single environment instead, "
            'e.g. gym.make("neurohover/GHH08-v0", render_mode="rgb_array")'
        )

    def step(self, actions: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        if not self._ready:
            raise NeurohoverError("step() called before reset(): call reset() first")
        a = actions
        if not (type(a) is np.ndarray and a.dtype == np.float64 and a.shape == self._actions.shape and a.flags.c_contiguous):
            a = self._coerce_actions(actions)
        self._stepper.step(a, self.episode_steps, self._obs, self._reward, self._crash)
        rewards = self._reward.copy()
        terminated = self._crash.copy()
        truncated = self._steps >= self._limit
        info: dict[str, Any] = {}
        if self._any_autoreset:
            # NEXT_STEP autoreset: the kernel also stepped these sub-environments (one batched
            # call is cheaper than masking), and that step is now discarded.
            idx = np.flatnonzero(self._autoreset)
            self._reset_envs(idx, None)
            rewards[idx] = 0.0
            terminated[idx] = False
            truncated[idx] = False
            info["mdp"], info["_mdp"] = self._labels(idx)
            info["mdp_info"], info["_mdp_info"] = self._mdp_infos(idx, info["_mdp"]), info["_mdp"].copy()
        info["crashed"] = terminated.copy()
        info["_crashed"] = np.ones(self.num_envs, dtype=np.bool_)
        np.logical_or(terminated, truncated, out=self._autoreset)
        self._any_autoreset = bool(self._autoreset.any())
        return self._obs.astype(self.obs_dtype), rewards, terminated, truncated, info


__all__ = ["HoverVectorEnv"]
