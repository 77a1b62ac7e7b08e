"""Generalized helicopter hovering as a Gymnasium environment (one helicopter).

The physics is the compiled kernel's :func:`neurohover.sim.step.step_batch`, called with a
batch of one, so this environment, the vector environment and the batched evaluation fly exactly
the same simulator.

Example
-------
>>> import gymnasium as gym
>>> import neurohover
>>> env = gym.make("neurohover/GHH08-v0", mdp="train:3")
>>> obs, info = env.reset(seed=0)
>>> obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from ..errors import NeurohoverError, brief
from ..sim.constants import (
    ACTION_DIM,
    EPISODE_STEPS,
    MDP_ROW_LEN,
    OBS_DIM,
    PARAM_NAMES,
    STATE_DIM,
)
from ..sim.reference import competition_time
from ..sim.rng import check_seed, seed_stream
from ..sim.step import ENV_NOISE_WIDTH, ENV_RNG_WIDTH, start_readings, step_batch
from ..tasks import MDP, TASK_FAMILIES, TaskFamily, family_class
from ..tasks.drift import Drift, DriftRun
from .arguments import (
    SAMPLE,
    FixedSettings,
    MdpSpec,
    check_action_dtype,
    check_against_id,
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

RENDER_FPS = 10  # control rate (Hz)
RENDER_MODES = ("human", "rgb_array")
TRAIL_STEPS = 100  # positions kept for the rendered track: the last 10 s of flight


#: What ``gymnasium.make`` may pass to :class:`HoverEnv` (its ``max_episode_steps`` is Gymnasium's own).
ENV_KWARGS = ("task", "sigma", "mdp", "episode_steps", "render_mode", "obs_dtype", "action_dtype", "obs_noise", "obs_delay", "drift")


def initial_state() -> np.ndarray:
    """The start state (docs/model.md, Simulator): at rest at the origin, level, facing north."""
    state = np.zeros(STATE_DIM)
    state[12] = 1.0
    return state


def check_render_mode(render_mode: Any) -> str | None:
    """``render_mode`` if it is None or one of :data:`RENDER_MODES`, else a clear error."""
    if render_mode is not None and render_mode not in RENDER_MODES:
        raise NeurohoverError(f"render_mode={render_mode!r} is not supported: use None, {', '.join(map(repr, RENDER_MODES))}")
    return render_mode


def _an_mdp(mdp: Any, where: str) -> MDP:
    """``mdp`` if it is an MDP (None and 'zero' were AttributeErrors in :func:`mdp_info` and :func:`world_wind`; T14-14)."""
    if not isinstance(mdp, MDP):
        raise NeurohoverError(f"{where}: mdp={brief(mdp)} is not allowed: give a neurohover.MDP (e.g. get_task_family('ghh08').mdp('zero'))")
    return mdp


def mdp_info(mdp: MDP) -> dict[str, Any]:
    """The MDP's family, label and parameters, as ``info["mdp_info"]`` carries them.

    ``params`` are the numbers its task family draws (GHH-08: wind_u, wind_v; GHH-09: its 8 wind
    parameters; FGHH: the 11 dynamics parameters), named by ``param_names``. An MDP of no task
    family (a learned model) gives its 11 dynamics parameters and D_u.
    """
    family = _an_mdp(mdp, "mdp_info").family
    cls = family_class(family) if family in TASK_FAMILIES else None  # its entry checked (T43-B10)
    if cls is not None:
        params, names = mdp.row()[cls.row_slice], tuple(cls.param_names)
    else:
        params, names = np.array([*mdp.params, mdp.d_u]), (*PARAM_NAMES, "D_u")
    return {"family": mdp.family, "label": mdp.label, "params": tuple(float(v) for v in params), "param_names": names}


def world_wind(mdp: MDP, steps: int) -> tuple[float, float, float]:
    """World wind (m/s, north-east-down) of ``mdp`` after ``steps`` control steps, as the kernel flies it."""
    return _an_mdp(mdp, "world_wind").to_reference().wind_at(competition_time(steps, 0))


def observation_space(dtype: Any = np.float64) -> spaces.Box:
    return spaces.Box(-np.inf, np.inf, (OBS_DIM,), dtype)


def action_space(dtype: Any = np.float64) -> spaces.Box:
    return spaces.Box(-1.0, 1.0, (ACTION_DIM,), dtype)


class HoverEnv(FixedSettings, gym.Env[np.ndarray, np.ndarray]):
    """Hover an XCell Tempest helicopter at the origin, in an MDP drawn from a task family.

    ## Description

    The generalized helicopter hovering tasks of the 2008 and 2009 Reinforcement Learning
    Competitions and Koppejan & Whiteson (2011): keep a simulated helicopter at its start point
    for 10 minutes of flight at 10 Hz, in an MDP that the agent does not know. The task family
    fixes the distribution G of MDPs: ``ghh08`` (constant wind up to 5 m/s), ``ghh09``
    (sinusoidal winds) or ``fghh`` (every dynamics parameter perturbed, relative std ``sigma``).
    Its arguments are fixed once it is made: setting one (``env.episode_steps = 50``, Gymnasium's
    ``set_wrapper_attr``) is refused, as the steps trust them; make another environment.

    ## Action Space

    ``Box(-1, 1, (4,), float64)`` (``float32`` with ``action_dtype="float32"``); values outside
    [-1, 1] are clipped by the simulator, which flies float64 either way.

    | Num | Action                        | Min | Max |
    |-----|-------------------------------|-----|-----|
    | 0   | aileron (roll, a1)            | -1  | 1   |
    | 1   | elevator (pitch, a2)          | -1  | 1   |
    | 2   | rudder (yaw, a3)              | -1  | 1   |
    | 3   | collective (main thrust, a4)  | -1  | 1   |

    A non-finite action (NaN or infinity) counts as a crash.

    ## Observation Space

    ``Box(-inf, inf, (12,), float64)`` (``float32`` with ``obs_dtype="float32"``); velocities and
    position errors are in the body frame.

    | Num | Observation                           | Unit  |
    |-----|---------------------------------------|-------|
    | 0   | u: forward velocity                   | m/s   |
    | 1   | v: sideways velocity                  | m/s   |
    | 2   | w: downward velocity                  | m/s   |
    | 3   | x: forward position error             | m     |
    | 4   | y: sideways position error            | m     |
    | 5   | z: downward position error            | m     |
    | 6   | p: roll rate                          | rad/s |
    | 7   | q: pitch rate                         | rad/s |
    | 8   | r: yaw rate                           | rad/s |
    | 9   | qx: orientation quaternion, x part    | -     |
    | 10  | qy: orientation quaternion, y part    | -     |
    | 11  | qz: orientation quaternion, z part    | -     |

    ## Rewards

    Minus the sum of squares of the 12 observation entries. The crashing step instead gets
    ``-(3*20^2 + 3*(4*pi)^2 + 3*5^2 + (1 - cos^2(15 deg))) * (episode_steps - t)``, with t the
    control steps taken including the crashing one: the worst possible reward for every step
    that is left (about -1.05e7 for a crash at the start of a 6000-step episode). Rewards are
    Python floats (float64) whatever ``obs_dtype`` is.

    ## Starting State

    At rest at the origin, level and facing north; the observation is all zeros (with noisy
    sensors, their first reading of zeros).

    ## Episode End

    - Termination (crash): any of |u|, |v|, |w| > 5 m/s, |x|, |y|, |z| > 20 m, |p|, |q|, |r| >
      4*pi rad/s, or more than 30 degrees from level (|qw| < cos 15 deg), or a non-finite action.
    - Truncation: ``episode_steps`` control steps flown (6000, i.e. 10 minutes, by default).
      Like Gymnasium's ``TimeLimit``, truncation is reported at the limit even when that last
      step also crashed.

    ## Arguments

    ``gymnasium.make("neurohover/GHH08-v0")``, ``"neurohover/GHH09-v0"`` or
    ``"neurohover/FGHH-v0"`` (which takes ``sigma``, default 0.3; refused beside ``mdp="zero"``, the
    same MDP at every sigma), with the arguments below. Each family also has a variant for deep RL,
    whose id alone sets it up:

    | Id                               | episode_steps, time limit | obs_dtype, action_dtype |
    |----------------------------------|---------------------------|-------------------------|
    | ``neurohover/GHH08-v0`` (...)    | 6000 (the paper's)        | float64                 |
    | ``neurohover/GHH08-Short-v0``    | 1000: a crash is charged  | float32                 |
    | ``neurohover/GHH09-Short-v0``    | the steps left of the     |                         |
    | ``neurohover/FGHH-Short-v0``     | 1000-step episode         |                         |

    and variants with the harder sensors of the paper's Section 7 (:mod:`neurohover.tasks.sensor`;
    docs/benchmarks.md), each family's:

    | Id                                        | obs_noise                       | obs_delay |
    |-------------------------------------------|---------------------------------|-----------|
    | ``neurohover/GHH08-NoisySensors-v0``      | level 1, white                  | 0         |
    | ``neurohover/GHH08-CorrelatedSensors-v0`` | level 1, AR(1) correlation 0.95 | 0         |
    | ``neurohover/GHH08-DelayedSensors-v0``    | exact                           | 2 (0.2 s) |
    | (likewise GHH09-, FGHH-)                  |                                 |           |

    Rewards stay the environment's own; :class:`neurohover.wrappers.CrashAwareReward` is the
    reward transform that learns (docs/deep-rl.md).

    - ``mdp``: ``"sample"`` (default: a fresh MDP drawn from G at each reset), ``"zero"`` (the
      family's mean MDP), ``"train:N"`` / ``"test:N"`` (the family's fixed training and test
      MDPs), or an explicit :class:`neurohover.MDP`.
    - ``episode_steps``: control steps per episode (6000). ``gymnasium.make`` also adds a
      ``TimeLimit`` of the id's episode length; pass ``max_episode_steps`` to ``make`` for longer
      episodes (a longer ``episode_steps`` alone is warned of). ``task`` is the id's: another task
      under one of neurohover's ids is refused (a user's own id takes it, as Gymnasium's make does), and
      so is a kwarg that removes a variant id's defining setting (``obs_noise=0`` under ``-NoisySensors``, white
      noise under ``-CorrelatedSensors``, ``obs_delay=0`` under ``-DelayedSensors``, ``drift=None`` under
      ``-DriftingDynamics``, no change under ``-AbruptChange``); one that keeps it (``obs_delay=3``) is taken.
    - ``obs_dtype``: ``"float64"`` (default) or ``"float32"`` (for deep-RL libraries): the
      observation space's dtype and the returned observations'. The simulation itself always
      runs in float64, so the episodes are the same, observations rounded to float32.
    - ``action_dtype``: ``"float64"`` (default) or ``"float32"``: the action space's dtype.
    - ``render_mode``: ``None`` (default), ``"rgb_array"`` or ``"human"`` (see Rendering).
    - ``obs_noise``: the sensors' noise: ``None`` (exact, default), a level (a number: the profile
      0.1 m/s, 0.1 m, 0.1 rad/s, 0.01 scaled by it), a dict of :class:`neurohover.tasks.sensor.Sensor`
      settings (``velocity``, ``position``, ``rates``, ``attitude``, ``correlation``, ``level``) or
      a ``Sensor``. Observations are then the noisy readings; reward and crash stay on the true
      state. ``obs_delay``: control steps (0..10) the readings arrive late. An explicit MDP (the
      ``mdp`` argument or option) is seen through these sensors, or the id's, as an MDP named by text
      is; one with a sensor of its own flies it under exact sensors, and is refused beside another.
    - ``drift``: drifting dynamics (:mod:`neurohover.tasks.drift`): ``None`` (fixed, default), a
      :class:`neurohover.tasks.Drift`, a dict of its settings (``walk``, ``change``, ``change_at``)
      or the command line's text (``"walk=0.01,D_w=0.8@200-800"``); an explicit MDP with a drift of
      its own drifts so too (beside another ``drift`` it is refused; one without drifts by ``drift``).
      The episodes then make up test runs: ``reset(seed=s)`` (or an ``mdp`` option, or the first
      reset) begins a run, drawing its MDP (``"sample"``) and then its drift's seed from ``np_random``;
      each later ``reset()`` is the run's next episode, on the same MDP with its dynamics drifted to
      that episode. ``info["run_episode"]`` counts the run's episodes
      from 0; ``info["mdp_info"]`` describes the run's MDP as drawn.

    | Id                                        | drift                                          |
    |-------------------------------------------|------------------------------------------------|
    | ``neurohover/GHH08-DriftingDynamics-v0``  | walk 0.01 (about G's breadth after 1000 runs)  |
    | ``neurohover/GHH08-AbruptChange-v0``      | D_w x 0.8 at an episode drawn from 200..800    |
    | (likewise GHH09-, FGHH-)                  |                                                |

    ``reset(seed=..., options=...)`` takes the options ``{"mdp": spec}`` (same values as the
    ``mdp`` argument; it also applies to later episodes) and ``{"noise": (seed, episode)}``
    (fly that gust-noise stream in this episode). A refused reset (a bad seed or option) leaves the
    episode as it was. Gymnasium's passive checker (off for these ids) cannot take one: with
    ``gymnasium.make(..., disable_env_checker=False)`` a refused *first* reset leaves the checker
    without that reset's data, as Gymnasium 1.4 marks its check done before it calls ``reset``, and
    the next ``step()`` is the checker's own TypeError whatever this environment checks first; make
    the environment again after one (T28-B04).

    ## Seeding

    ``reset(seed=s)`` seeds ``np_random``; the episode's MDP (when sampled) and then the seed of
    its gust-noise stream are drawn from it, so an episode is a pure function of ``s`` and the
    actions. The gusts are the kernel's stream ``(noise_stream[0], noise_stream[1])``, the one
    ``neurohover.evaluate_jobs(..., seed=noise_stream[0], episode_index=[noise_stream[1]])``
    flies, so a policy flown here and in a batched evaluation meets the same gusts.

    ## Rendering

    | Mode        | ``render()`` returns                     | Shown                               |
    |-------------|------------------------------------------|-------------------------------------|
    | None        | None (Gymnasium warns)                   | nothing                             |
    | "rgb_array" | (340, 720, 3) uint8 frame                | nothing                             |
    | "human"     | None                                     | a matplotlib window, at 10 fps      |

    A frame shows a top view (east right, north up) and a side view seen from the east (north
    right, altitude up) of the hover target (green cross, the origin), the helicopter rotated by
    its attitude (blue rotor disk, orange nose) and its track over the last 10 s; a compass with
    the MDP's current world wind (full radius 5 m/s), drawn as the way the air moves: the drag acts
    on velocity + W, so a wind parameter W pushes the helicopter along -W, and the arrow is -W;
    and a text line with the MDP label, step and return so far. The views span 5 m either way, widening to 10 m and then to the crash box.
    In ``"human"`` mode ``reset`` and ``step`` show each frame themselves; the window opens at the
    first frame, and without a display the frames are drawn and dropped (with one warning). Both
    modes work with Gymnasium's ``RecordVideo`` (``"rgb_array"``; it needs moviepy). Rendering
    never changes the episode: observations and rewards are the same with or without it.

    ## Info

    | Key         | Value                                                                     |
    |-------------|---------------------------------------------------------------------------|
    | "mdp"       | label of the current MDP (str), e.g. ``"ghh08/test:4"``                   |
    | "crashed"   | whether this step crashed (bool; False after ``reset``)                   |
    | "mdp_info"  | ``{"family": str, "label": str, "params": tuple, "param_names": tuple}``: |
    |             | the numbers that fix the MDP within its family (:func:`mdp_info`)         |

    All three come from ``reset`` and from every ``step``.
    """

    metadata = {"render_modes": list(RENDER_MODES), "render_fps": RENDER_FPS}
    _FIXED = (*ENV_KWARGS, "family")  # fixed once made (FixedSettings; T32-B04)

    def __init__(
        self,
        task: str = "ghh08",
        sigma: float | None = None,
        mdp: MdpSpec = SAMPLE,
        episode_steps: int = EPISODE_STEPS,
        render_mode: str | None = None,
        obs_dtype: Any = "float64",
        action_dtype: Any = "float64",
        obs_noise: Any = None,
        obs_delay: Any = None,
        drift: Any = None,
        **unknown: Any,
    ) -> None:
        check_no_unknown_kwargs(unknown, ENV_KWARGS)
        self.drift = Drift.of(drift)
        self.render_mode = check_render_mode(render_mode)
        self.obs_dtype = check_obs_dtype(obs_dtype)
        self.action_dtype = check_action_dtype(action_dtype)
        self.family: TaskFamily = sensed_family(task, sigma, obs_noise, obs_delay)
        self.episode_steps = check_episode_steps(episode_steps)
        self._spec: MDP | str = self._resolve(mdp)
        refuse_idle_sigma(sigma, mdp)
        self.observation_space = observation_space(self.obs_dtype)
        self.action_space = action_space(self.action_dtype)
        # The kernel steps batches; this environment is a batch of one.
        self._rows = np.zeros((1, MDP_ROW_LEN))
        self._index = np.zeros(1, dtype=np.int64)
        self._state = initial_state()[None, :]
        self._noise = np.zeros((1, ENV_NOISE_WIDTH))  # gust noise, then the sensor's state (one helicopter: always room for it)
        self._rng = np.zeros((1, ENV_RNG_WIDTH), dtype=np.uint64)
        self._steps = np.zeros(1, dtype=np.int64)
        self._action = np.zeros((1, ACTION_DIM))
        self._obs = np.zeros((1, OBS_DIM))
        self._reward = np.zeros(1)
        self._crash = np.zeros(1, dtype=np.bool_)
        self._mdp: MDP | None = None
        self._mdp_info: dict[str, Any] = {}
        self._stream: tuple[int, int] | None = None
        self._run: DriftRun | None = None  # the test run that a drifting environment's episodes make up
        self._run_mdp: MDP | None = None
        self._run_episode = 0
        self._done = True
        # Rendering state: read by render() only, so it cannot change the episode.
        self._return = 0.0
        self._trail: list[np.ndarray] = []
        self._renderer: Any = None
        self._window: Any = None
        self.fix_settings()  # its settings are fixed from here (FixedSettings)

    _env_spec: Any = None

    @property
    def spec(self) -> Any:
        """Gymnasium's ``EnvSpec`` of the environment (None unless made by ``gymnasium.make``)."""
        return self._env_spec

    @spec.setter
    def spec(self, value: Any) -> None:  # gymnasium.make sets it on the env it built: the kwargs it merged are checked here
        check_against_id(value, self.family, self.episode_steps, drift=self.drift)
        self._env_spec = value

    @property
    def mdp(self) -> MDP | None:
        """The MDP of the current episode (None before the first reset)."""
        return self._mdp

    @property
    def drift_run(self) -> DriftRun | None:
        """The current test run of drifting dynamics (its ``seed`` and rows; None without drift)."""
        return self._run

    @property
    def noise_stream(self) -> tuple[int, int] | None:
        """The (seed, episode) gust-noise stream of the current episode."""
        return self._stream

    @property
    def steps(self) -> int:
        """Control steps flown in the current episode."""
        return int(self._steps[0])

    @property
    def episode_return(self) -> float:
        """Sum of the rewards of the current episode so far."""
        return self._return

    def _info(self, crashed: bool) -> dict[str, Any]:
        info = {"mdp": self._mdp_info["label"], "crashed": crashed, "mdp_info": dict(self._mdp_info)}
        if self._run is not None:
            info["run_episode"] = self._run_episode
        return info

    def _resolve(self, mdp: Any) -> MDP | str:
        """The ``mdp`` argument or option resolved (:func:`resolve_mdp`, which puts the environment's sensor on an explicit
        MDP by the rule of drift); an explicit MDP's own drift beside another of the environment's is refused, as a
        sensor is: the environment's won without a word (T26-B03)."""
        spec = resolve_mdp(self.family, mdp)
        if isinstance(spec, MDP) and not (self.drift.none or spec.drift.none or spec.drift == self.drift):
            raise NeurohoverError(
                f"mdp {spec.label or spec.family!r} drifts by its own {spec.drift.to_dict()}, not this environment's drift "
                f"{self.drift.to_dict()}: give the MDP without one (mdp.with_drift(Drift())), or leave drift out and it drifts by its own"
            )
        return spec

    def _drifted(self, spec: MDP | str, new_run: bool) -> tuple[MDP, np.ndarray]:
        """The MDP of this episode of the test run and the (drifted) row it flies: a seeded reset, a new
        ``mdp`` option or the first reset begins a run (its MDP, then its drift seed, drawn here)."""
        if new_run or self._run is None or self._run_mdp is None:
            mdp = self.family.sample(self.np_random) if isinstance(spec, str) else spec
            drift = self.drift if not self.drift.none else mdp.drift
            self._run = DriftRun(drift, mdp.row(), int(self.np_random.integers(2**63 - 1)))
            self._run_mdp, self._run_episode = mdp, 0
        else:
            self._run_episode += 1
        return self._run_mdp, self._run.row(self._run_episode)

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None) -> tuple[np.ndarray, dict[str, Any]]:
        # check_seed: every seed's range, as the vector env says it; Gymnasium's seeding takes a Python int, not np.int64
        super().reset(seed=None if seed is None else check_seed(seed))
        options = check_reset_options(options)
        # Validate every option before touching the episode, so a bad call leaves it as it was.
        spec = self._resolve(options["mdp"]) if "mdp" in options else self._spec
        stream = check_noise_stream(options["noise"]) if "noise" in options else None
        self._spec = spec
        if self.drift.none and (isinstance(spec, str) or spec.drift.none):
            mdp = self.family.sample(self.np_random) if isinstance(spec, str) else spec  # a str spec is SAMPLE
            row = mdp.row()
        else:  # drifting dynamics: the episodes are a test run of one MDP (neurohover.tasks.drift)
            mdp, row = self._drifted(spec, seed is not None or "mdp" in options)
        if stream is None:
            stream = (draw_stream_seed(self.np_random), 0)
        self._mdp = mdp
        self._stream = stream
        self._rows[0] = row
        self._state[0] = initial_state()
        self._noise.fill(0.0)
        seed_stream(self._rng[0], np.uint64(stream[0]), np.uint64(stream[1]))
        start_readings(self._rows, self._index, self._index, np.array([stream], dtype=np.int64), self._rng, self._noise, self._obs)
        self._steps[0] = 0
        self._done = False
        self._mdp_info = mdp_info(mdp)
        self._return = 0.0
        self._trail = [self._state[0, 3:6].copy()]
        if self.render_mode == "human":
            self.render()
        return self._obs[0].astype(self.obs_dtype), self._info(False)

    def step(self, action: np.ndarray) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        if self._done:
            raise NeurohoverError("step() called on a finished episode (or before reset()): call reset() first")
        a = real_values(action, lambda: f"action {brief(action)} is not allowed: give 4 real numbers (aileron, elevator, rudder, collective)")
        if a.shape != (ACTION_DIM,):
            raise NeurohoverError(f"action has shape {a.shape}, expected (4,): aileron, elevator, rudder, collective in [-1, 1]")
        self._action[0] = a
        step_batch(
            self._rows, self._index, self._state, self._noise, self._rng, self._steps, self._action, self.episode_steps, self._obs, self._reward, self._crash
        )
        terminated = bool(self._crash[0])
        truncated = bool(self._steps[0] >= self.episode_steps)
        self._done = terminated or truncated
        reward = float(self._reward[0])
        self._return += reward
        if self.render_mode is not None:
            self._trail.append(self._state[0, 3:6].copy())
            del self._trail[:-TRAIL_STEPS]
            if self.render_mode == "human":
                self.render()
        obs = self._obs[0].astype(self.obs_dtype)  # astype copies: the returned array is the caller's
        return obs, reward, terminated, truncated, self._info(terminated)

    def render(self) -> np.ndarray | None:
        """The current frame (``"rgb_array"``), or show it (``"human"``); see Rendering above.

        Returns
        -------
        numpy.ndarray or None
            An (340, 720, 3) uint8 RGB image in ``"rgb_array"`` mode, else None.
        """
        if self.render_mode is None:
            gym.logger.warn(
                "You are calling render method without specifying any render mode. "
                "You can specify the render_mode at initialization, "
                f'e.g. gym.make("{self.spec.id if self.spec else "neurohover/GHH08-v0"}", render_mode="rgb_array")'
            )
            return None
        frame = self._draw()
        if self.render_mode == "rgb_array":
            return frame
        if self._window is None:
            from .render import HumanWindow

            self._window = HumanWindow(self.metadata["render_fps"])
        self._window.show(frame)
        return None

    def _draw(self) -> np.ndarray:
        if self._renderer is None:
            from .render import HoverRenderer  # matplotlib is loaded only by environments that render

            self._renderer = HoverRenderer()
        steps = self.steps
        if self._mdp is None:  # before the first reset: the start state, no MDP yet
            wind, text = (0.0, 0.0, 0.0), f"{self.family.name}: call reset()"
        else:
            wind = world_wind(self._mdp, steps)
            end = "  CRASHED" if self._crash[0] and self._done else ""
            text = f"{self._mdp.label}   step {steps}/{self.episode_steps}   return {self._return:.6g}{end}"
        trail = np.array(self._trail) if self._trail else None
        return self._renderer.draw(self._state[0], wind, text, trail)

    def __getstate__(self) -> dict[str, Any]:
        """The environment's state for pickle and ``copy.deepcopy``, without its renderer and window: matplotlib's are not
        picklable (its BufferRegion, T36-B02), and they only draw, so the copy makes its own at its next render."""
        state = self.__dict__.copy()
        state["_renderer"] = state["_window"] = None
        return state

    def close(self) -> None:
        """Close the window of ``"human"`` mode and release the renderer (safe to call twice)."""
        if self._window is not None:
            self._window.close()
            self._window = None
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None
        super().close()


__all__ = ["HoverEnv", "MdpSpec", "mdp_info", "world_wind"]
