"""Constants of the XCell Tempest hover model (docs/model.md, Simulator) and the MDP row layout.

An MDP reaches the compiled kernel as one float64 row of ``MDP_ROW_LEN`` numbers, so a batch of
MDPs (task-family MDPs or learned models) is a plain 2-D array.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

# Dynamics parameters in row order (the paper's Table 5 calls them C and D; D_u is 0 in the
# simulator and has its own row slot, ROW_D_U, for learned models).
PARAM_NAMES: tuple[str, ...] = (
    "C_u",
    "C_v",
    "D_v",
    "C_w",
    "D_w",
    "C_p",
    "D_p",
    "C_q",
    "D_q",
    "C_r",
    "D_r",
)
DEFAULT_PARAMS = np.array([-0.18, -0.43, -0.54, -0.49, -42.15, -12.78, 33.04, -10.12, -33.32, -8.16, 70.54])
NOISE_NAMES: tuple[str, ...] = ("u", "v", "w", "p", "q", "r")
DEFAULT_NOISE_STD = np.array([0.1941, 0.2975, 0.6058, 0.1508, 0.2492, 0.0734])

GRAVITY = 9.81
CONTROL_DT = 0.1
SUBSTEPS = 10
SUBSTEP_DT = 0.01
EPISODE_STEPS = 6000
MAX_EPISODE_STEPS = 10**7  # the most control steps of one episode anything accepts (far beyond the paper's 6000)
NOISE_DECAY = 0.8  # AR(1) gust noise: n <- 0.8 n + 0.2 * N(0,1) * std * 2
NOISE_GAIN = 0.2 * 2.0

# Crash test limits (checked after the substeps of a control step).
MAX_VELOCITY = 5.0
MAX_POSITION = 20.0
MAX_RATE = 4.0 * math.pi
MIN_QW = math.cos(math.radians(15.0))  # |qw| below this: more than 30 degrees from level

# Reward of one remaining step at the worst possible state; a crash is charged it for every
# step left in the episode, including the crashing one.
CRASH_STEP_PENALTY = 3 * MAX_POSITION**2 + 3 * MAX_RATE**2 + 3 * MAX_VELOCITY**2 + (1.0 - MIN_QW**2)
# No episode's return is below -WORST_RETURN: a crash charges the worst step for every step left (stored results and
# compete's files are checked against it; every reward is minus a sum of squares, so none is above 0).
WORST_RETURN = CRASH_STEP_PENALTY * MAX_EPISODE_STEPS


def lowest_return(n_steps: int) -> float:
    """The lowest return an episode of ``n_steps`` control steps can have, -CRASH_STEP_PENALTY * n_steps: each step
    flown earns at least the worst step's reward, a crash is charged the worst step for each step left (T27-B03)."""
    return -CRASH_STEP_PENALTY * n_steps


def return_floor(steps: Any, crashed: Any) -> Any:
    """The least return of each episode of ``steps`` control steps flown (the crashing one counted) and ``crashed``
    flags, 1e-9 below for the squares' rounding: ``lowest_return(steps)`` uncrashed, -WORST_RETURN crashed (charged
    the worst step for each step left of a budget of at most MAX_EPISODE_STEPS): what an Evaluation checks its returns
    against, an EpisodeOutcome's rule (agents.protocol._check_return) vectorised (T27-B10)."""
    if isinstance(crashed, bool):  # one episode's (a scalar: no array built)
        return (-WORST_RETURN if crashed else lowest_return(steps)) * (1 + 1e-9)
    return np.where(crashed, -WORST_RETURN, lowest_return(steps)) * (1 + 1e-9)


def crash_charge(n_steps: int, t: int) -> float:
    """The kernel's charge of a crash at control step ``t`` (1-based) of an ``n_steps`` episode, the worst step for every
    step left, -CRASH_STEP_PENALTY * (n_steps - t): the plain twin of ``sim.kernel.crash_charge`` (none for a crash on
    the last step; no checks: :func:`crash_penalty` checks its arguments)."""
    return -CRASH_STEP_PENALTY * (n_steps - t)


def crash_return_ceiling(n_steps: int, t: int) -> float:
    """The largest return an episode that crashes at control step ``t`` of ``n_steps`` can have: it is charged
    :func:`crash_charge` on top of its rewards (each <= 0), so at most that charge, with 1e-9 of it to spare for the
    kernel's rounding. What every reader of recorded crashes checks a return against (compete's episodes.csv, stored
    test runs; T26-B09)."""
    charge = -crash_charge(n_steps, t)
    return -charge + 1e-9 * charge


# The most seconds a run records, 100 years (checkpoints, stored timings, compete summaries): a run's clock at 1e308
# seconds (T19-09) and summary seconds of 1e300 (T24-07) were taken; no run lasts longer.
MAX_SECONDS = 100 * 365.25 * 86400.0


def seconds_allowed(value: object) -> bool:
    """Whether ``value`` is seconds a run may record: a finite real number (not a bool) in [0, :data:`MAX_SECONDS`].
    The one test of it (checkpoints, policy files, models, stored timings, compete summaries); each reader words its
    own message of what the seconds are."""
    from ..errors import finite_real

    return finite_real(value) and 0 <= value <= MAX_SECONDS  # type: ignore[operator]


# Wind models.
WIND_NONE = 0
WIND_CONSTANT = 1  # GHH-08: (wind_u, wind_v) in m/s, world frame
WIND_SINUSOID = 2  # GHH-09: (maxf, freq, phase, center) for x then y, each in [0, 1]

# Layout of an MDP row.
ROW_PARAMS_START = 0  # the 11 dynamics parameters (PARAM_NAMES order)
ROW_PARAMS = slice(ROW_PARAMS_START, ROW_PARAMS_START + 11)
ROW_NOISE_START = 11
ROW_NOISE = slice(ROW_NOISE_START, ROW_NOISE_START + 6)
ROW_SUBSTEPS = 17
ROW_DT = 18
ROW_WIND_KIND = 19
ROW_WIND_START = 20  # (the kernel indexes from it: numba folds module-level ints, not slices)
ROW_WIND = slice(ROW_WIND_START, ROW_WIND_START + 8)
ROW_D_U = 28  # constant u acceleration: 0 in every true MDP; the paper's D_u of a learned model
# The sensor model (docs/benchmarks.md, Sensor noise): what the policy, the safeguard and the flight
# data see is the observation plus noise, read ``delay`` control steps late, each reading lost with
# probability ``dropout`` (the last one delivered held instead); all zero: exact sensors.
ROW_SENSOR_START = 29  # std of the velocity, position, rate and attitude entries; AR(1) coefficient; delay; dropout
ROW_SENSOR = slice(ROW_SENSOR_START, ROW_SENSOR_START + 7)
MDP_ROW_LEN = 36

MAX_SENSOR_DELAY = 10  # control steps (1 s): the kernel's per-episode ring buffer holds MAX_SENSOR_DELAY + 1 readings
SENSOR_SCRATCH = 12 * (MAX_SENSOR_DELAY + 3)  # floats a sensing episode keeps: the noise, the reading held, the ring buffer
SENSOR_GROUPS: tuple[str, ...] = ("velocity", "position", "rates", "attitude")  # 3 observation entries each
#: The smallest noise but 0 (none), float64's epsilon 2**-52: a drift walk's step of one std, exp(walk), is 1.0 below it,
#: and a sensor std below it changes no reading of a size the state has (1e-320 flew exact sensors recorded as noisy; T40-B08, T44-A04).
MIN_NOISE = float(np.finfo(np.float64).eps)

OBS_NAMES: tuple[str, ...] = ("u", "v", "w", "x", "y", "z", "p", "q", "r", "qx", "qy", "qz")
ACTION_NAMES: tuple[str, ...] = ("aileron", "elevator", "rudder", "collective")
OBS_DIM = 12
ACTION_DIM = 4
STATE_DIM = 13  # world velocity (3), world position (3), body rates (3), quaternion (qx, qy, qz, qw)

# Dangerous-state test of the safeguard (docs/model.md, Safeguard). The authors' code fires when
# the helicopter is tilted (qw < 0.99) and any velocity, position or angular-rate entry of the
# observation lies outside [-0.5, 0.5]; the paper's text states the box test alone.
SAFEGUARD_BOX = 0.5
SAFEGUARD_TILT = 0.99
# The authors' FGHH agent's test instead: the sum over the 12 observation entries of entry / limit
# (limits 5 m/s, 20 m, 4 pi rad/s and 1 for the quaternion's vector part) above 0.15.
SAFEGUARD_RATIO_LIMITS = (5.0,) * 3 + (20.0,) * 3 + (4 * math.pi,) * 3 + (1.0,) * 3
SAFEGUARD_RATIO_THRESHOLD = 0.15
# Kernel layout (25 floats): the 9 box limits (u, v, w, x, y, z, p, q, r), the tilt threshold on qw
# (infinity: every attitude counts as tilted, i.e. the paper's box test alone), the test's kind (0:
# box and tilt, 1: sum of ratios), the ratio threshold, the 12 ratio limits, and the control step
# from which the test applies (SAFEGUARD_ARM; 0: from the first, as the authors' agents ran it).
SAFEGUARD_LAYOUT_LEN = 25
SAFEGUARD_ARM = 24
SAFEGUARD_KIND_BOX, SAFEGUARD_KIND_RATIO = 0.0, 1.0
SAFEGUARD_LIMITS = np.array([SAFEGUARD_BOX] * 9 + [SAFEGUARD_TILT, SAFEGUARD_KIND_BOX, SAFEGUARD_RATIO_THRESHOLD, *SAFEGUARD_RATIO_LIMITS, 0.0])


def crash_penalty(steps_taken: int, episode_steps: int = EPISODE_STEPS) -> float:
    """Reward of the crashing control step when ``steps_taken`` steps (including it) were flown, of an episode of
    ``episode_steps`` (a NeurohoverError where they are no whole numbers with 1 <= steps_taken <= episode_steps:
    (10, 5) was a positive "penalty"; thirteenth trial)."""
    from ..errors import NeurohoverError, brief, whole_number

    if not whole_number(episode_steps) or episode_steps < 1:
        raise NeurohoverError(f"episode_steps={brief(episode_steps)} is not allowed: give a whole number of control steps >= 1")
    if not whole_number(steps_taken) or not 1 <= steps_taken <= episode_steps:
        raise NeurohoverError(f"steps_taken={brief(steps_taken)} is not allowed: give a whole number of steps from 1 to episode_steps={episode_steps}")
    return crash_charge(int(episode_steps), int(steps_taken))


#: The MLP's steepened logistic sigma(s) = 1 / (1 + exp(-MLP_STEEPNESS s)) (docs/model.md, Policies).
MLP_STEEPNESS = 4.924273
