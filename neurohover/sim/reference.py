"""Plain-Python reference simulator, written to be read next to docs/model.md, Simulator.

It follows the equations literally (quaternion sandwich products, ``math.sin``/``math.cos``) and
takes its gust-noise normals as input, so tests can feed it the same normals as the compiled
kernel (:func:`neurohover.sim.rng.episode_normals`) and compare the two step by step. It is also
the baseline that ``neurohover bench`` measures the kernel against. No episode is flown with it
outside tests and the benchmark; the task families take its :class:`ReferenceMDP` (an MDP's
readable form) and the environments its wind formula for their ``info`` (:func:`competition_time`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from ..errors import NeurohoverError, as_floats, brief, finite_real, whole_number
from .constants import (
    CRASH_STEP_PENALTY,
    EPISODE_STEPS,
    GRAVITY,
    MAX_EPISODE_STEPS,
    MAX_POSITION,
    MAX_RATE,
    MAX_SENSOR_DELAY,
    MAX_VELOCITY,
    MIN_QW,
    WIND_CONSTANT,
    WIND_SINUSOID,
)

__all__ = ["Quat", "ReferenceHelicopter", "ReferenceMDP", "ReferenceSensors", "Vec", "competition_time", "fly_episode", "rotation_vector_quaternion"]

Vec = tuple[float, float, float]
Quat = tuple[float, float, float, float]  # (x, y, z, w)


def _quat_mul(a: Quat, b: Quat) -> Quat:
    """Hamilton product a * b of quaternions stored as (x, y, z, w)."""
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
        aw * bw - ax * bx - ay * by - az * bz,
    )


def _quat_conj(q: Quat) -> Quat:
    return (-q[0], -q[1], -q[2], q[3])


def _rotate(q: Quat, v: Vec) -> Vec:
    """Rotate v by q (body frame to world frame): q v q*."""
    x, y, z, _ = _quat_mul(_quat_mul(q, (v[0], v[1], v[2], 0.0)), _quat_conj(q))
    return (x, y, z)


def _rotate_inverse(q: Quat, v: Vec) -> Vec:
    """Rotate v by the inverse of q (world frame to body frame): q* v q."""
    x, y, z, _ = _quat_mul(_quat_mul(_quat_conj(q), (v[0], v[1], v[2], 0.0)), q)
    return (x, y, z)


def rotation_vector_quaternion(rv: Vec) -> Quat:
    """Unit quaternion of a rotation vector; first-order form below an angle of 1e-4 (docs/model.md, Simulator). Any
    finite rotation vector is one: past 1e150 rad (whose squares would overflow, an OverflowError; T43-B03) its half
    angle is taken from the halved vector, the same rotation."""
    x, y, z = _reals(rv, 3, "rv")
    if max(abs(x), abs(y), abs(z)) < 1e150:
        return _rotation_vector_quaternion((x, y, z))
    half = math.hypot(x / 2, y / 2, z / 2)  # finite: at most sqrt(3) * 0.9e308
    s = math.sin(half)
    return (x / 2 / half * s, y / 2 / half * s, z / 2 / half * s, math.cos(half))


def _rotation_vector_quaternion(rv: Vec) -> Quat:
    """:func:`rotation_vector_quaternion` unchecked, for the substep loop."""
    angle = math.sqrt(rv[0] ** 2 + rv[1] ** 2 + rv[2] ** 2)
    if angle < 1e-4:
        half = (rv[0] / 2, rv[1] / 2, rv[2] / 2)
        return (*half, math.sqrt(1.0 - (half[0] ** 2 + half[1] ** 2 + half[2] ** 2)))
    s = math.sin(angle / 2) / angle
    return (rv[0] * s, rv[1] * s, rv[2] * s, math.cos(angle / 2))


def competition_time(step: int, substep: int) -> float:
    """Time (s) of a substep as the competition software computed it: ``t = 0.1*step + 0.01*substep``
    in floating point, floored to 0.01 s by ``int(t*100)/100.0`` (so some land 0.01 s early)."""
    for name, value in (("step", step), ("substep", substep)):  # -1 was a time of -0.1 s, 'a' a TypeError (thirteenth trial, F6, F7)
        if not whole_number(value) or value < 0:
            raise NeurohoverError(f"{name}={brief(value)} is not allowed: give an integer >= 0 (control steps, substeps)")
    return _competition_time(int(step), int(substep))


def _competition_time(step: int, substep: int) -> float:
    """:func:`competition_time` unchecked, for the substep loop."""
    t = 0.1 * step + 0.01 * substep
    return int(t * 100) / 100.0


@dataclass
class ReferenceMDP:
    """Everything that fixes an MDP, as plain numbers (see :mod:`neurohover.tasks`)."""

    params: Sequence[float]  # C_u, C_v, D_v, C_w, D_w, C_p, D_p, C_q, D_q, C_r, D_r
    noise_std: Sequence[float]  # u, v, w, p, q, r
    wind_kind: int = 0
    wind: Sequence[float] = (0.0,) * 8
    substeps: int = 10
    dt: float = 0.01
    d_u: float = 0.0  # constant u acceleration of a learned model (0 in every true MDP)
    sensor: Sequence[float] = (0.0,) * 7  # noise std of velocity, position, rates, attitude; AR(1) coefficient; delay; dropout

    def __post_init__(self) -> None:
        """Refuse what the simulator cannot fly: 3 params were an unpack ValueError mid-episode, substeps=0 flew no
        physics and returned 0.0 (thirteenth trial, F6, F7). Checked again where it is flown (:func:`_check_mdp`)."""
        _check_mdp(self)

    def wind_at(self, t: float) -> Vec:
        """World-frame wind (m/s) at time t (for GHH-09, t as :func:`competition_time` floors it)."""
        if self.wind_kind == WIND_CONSTANT:
            return (self.wind[0], self.wind[1], 0.0)
        if self.wind_kind == WIND_SINUSOID:
            out = []
            for maxf, freq, phase, center in (self.wind[0:4], self.wind[4:8]):
                amplitude = 5.0 * (maxf - center)
                phi = 2.0 * math.pi * phase if freq != 0.0 else 0.0  # the competition's rule
                out.append(amplitude * math.sin(20.0 * math.pi * freq * t + phi) + 5.0 * center)
            return (out[0], out[1], 0.0)
        return (0.0, 0.0, 0.0)


@dataclass
class ReferenceHelicopter:
    """State of one helicopter in the world frame (north-east-down). Its fields are checked where it is made and at each
    :meth:`step` (wrong action or normals were unpack and index errors, episode_steps=-5 paid a crash a positive
    reward; T43-B02); :func:`fly_episode`, which checks them once, steps it unchecked."""

    mdp: ReferenceMDP
    velocity: Vec = (0.0, 0.0, 0.0)
    position: Vec = (0.0, 0.0, 0.0)
    rates: Vec = (0.0, 0.0, 0.0)
    orientation: Quat = (0.0, 0.0, 0.0, 1.0)
    noise: list[float] = field(default_factory=lambda: [0.0] * 6)
    steps: int = 0
    episode_steps: int = EPISODE_STEPS

    def __post_init__(self) -> None:
        self._check()

    def _check(self) -> None:
        """Refuse a state the simulator cannot step (the fields are the caller's to change between steps)."""
        _check_mdp(self.mdp, "mdp.")
        for name, n in (("velocity", 3), ("position", 3), ("rates", 3), ("orientation", 4)):
            setattr(self, name, _reals(getattr(self, name), n, name))
        self.noise = list(_reals(self.noise, 6, "noise"))
        for name, low in (("episode_steps", 1), ("steps", 0)):
            value, high = getattr(self, name), (MAX_EPISODE_STEPS if name == "episode_steps" else self.episode_steps)
            if not whole_number(value) or not low <= value <= high:
                meaning = "control steps of an episode" if name == "episode_steps" else "control steps flown, at most episode_steps"
                raise NeurohoverError(f"{name}={brief(value)} is not allowed: give an integer in {low}..{high} ({meaning})")
            setattr(self, name, int(value))

    def observation(self) -> list[float]:
        """Body-frame velocity, body-frame position, angular rates, quaternion vector part."""
        q = self.orientation
        return [*_rotate_inverse(q, self.velocity), *_rotate_inverse(q, self.position), *self.rates, *q[:3]]

    def crashed(self) -> bool:
        return (
            any(abs(c) > MAX_VELOCITY for c in self.velocity)
            or any(abs(c) > MAX_POSITION for c in self.position)
            or any(abs(c) > MAX_RATE for c in self.rates)
            or abs(self.orientation[3]) < MIN_QW
        )

    def step(self, action: Sequence[float], normals: Sequence[float]) -> tuple[float, bool]:
        """One 0.1 s control step; returns (reward, crashed). ``action``: 4 real numbers (NaN or inf crashes), ``normals``:
        6 finite standard normals (the gusts' of this step, :func:`neurohover.sim.rng.episode_normals`)."""
        self._check()
        if self.steps >= self.episode_steps:
            raise NeurohoverError(
                f"step {self.steps + 1} is not allowed: the episode of episode_steps={self.episode_steps} is flown (make a new ReferenceHelicopter)"
            )
        if not _n_reals(action, 4):
            raise NeurohoverError(f"action={brief(action)} is not allowed: give 4 real numbers (a sequence or an array)")
        if isinstance(normals, (str, bytes)) or not isinstance(normals, (Sequence, np.ndarray)):
            raise NeurohoverError(f"normals={brief(normals)} is not allowed: give 6 real numbers, all finite (a sequence or an array)")
        return self._step(action, _reals(normals, 6, "normals"))

    def _step(self, action: Sequence[float], normals: Sequence[float]) -> tuple[float, bool]:
        """:meth:`step` unchecked, for :func:`fly_episode`."""
        self.steps += 1
        if not all(math.isfinite(a) for a in action):
            return -CRASH_STEP_PENALTY * (self.episode_steps - self.steps), True
        a1, a2, a3, a4 = (min(1.0, max(-1.0, a)) for a in action)
        std = self.mdp.noise_std
        for i in range(6):
            self.noise[i] = 0.8 * self.noise[i] + 0.2 * normals[i] * std[i] * 2
        c_u, c_v, d_v, c_w, d_w, c_p, d_p, c_q, d_q, c_r, d_r = self.mdp.params
        n_u, n_v, n_w, n_p, n_q, n_r = self.noise
        dt = self.mdp.dt
        for i in range(self.mdp.substeps):
            t = _competition_time(self.steps - 1, i)
            x, y, z = (p + dt * v for p, v in zip(self.position, self.velocity))
            self.position = (x, y, z)
            q = self.orientation
            vb = _rotate_inverse(q, self.velocity)
            wb = _rotate_inverse(q, self.mdp.wind_at(t))
            force = (
                c_u * (vb[0] + wb[0]) + self.mdp.d_u + n_u,
                c_v * (vb[1] + wb[1]) + d_v + n_v,
                c_w * vb[2] + d_w * a4 + n_w,
            )
            fw = _rotate(q, force)
            u, v, w = (vel + dt * f for vel, f in zip(self.velocity, fw))
            self.velocity = (u, v, w + dt * GRAVITY)
            p, q_rate, r = self.rates
            self.orientation = _quat_mul(q, _rotation_vector_quaternion((dt * p, dt * q_rate, dt * r)))
            self.rates = (
                p + dt * (c_p * p + d_p * a1 + n_p),
                q_rate + dt * (c_q * q_rate + d_q * a2 + n_q),
                r + dt * (c_r * r + d_r * a3 + n_r),
            )
        if self.crashed():
            return -CRASH_STEP_PENALTY * (self.episode_steps - self.steps), True
        return -sum(o * o for o in self.observation()), False


@dataclass
class ReferenceSensors:
    """The sensor model of docs/benchmarks.md, literally: noise e_k on each reading, delivered ``delay`` readings late,
    each reading but the reset's lost with probability ``dropout`` (the one delivered last held instead). Its sensor and
    normals are checked where it is made, the reading's row at each :meth:`read` (short normals were an IndexError; T43-B02)."""

    sensor: Sequence[float]
    normals: Sequence[Sequence[float]]  # 12 standard normals per reading, 13 with a dropout (rng.sensor_normals)
    noise: list[float] = field(default_factory=lambda: [0.0] * 12)
    readings: list[list[float]] = field(default_factory=list)
    delivered: list[float] = field(default_factory=list)

    def __post_init__(self) -> None:
        sensor = _reals(self.sensor, 7, "sensor")
        _check_sensor(sensor)
        self.sensor = sensor
        self.normals = _normal_rows("normals", self.normals, 1, _sensor_widths(sensor), every=True)
        self.noise = list(_reals(self.noise, 12, "noise"))
        if not isinstance(self.readings, list) or not all(isinstance(r, list) and len(r) == 12 for r in self.readings):
            raise NeurohoverError(f"readings={brief(self.readings)} is not allowed: give a list of the readings made (lists of 12 numbers), [] at the reset")

    def read(self, observation: Sequence[float]) -> list[float]:
        """The reading the policy gets now, of the true ``observation`` just made (12 real numbers)."""
        k = len(self.readings)
        if k >= len(self.normals):
            raise NeurohoverError(f"reading {k} is not allowed: normals has {len(self.normals)} rows, one per reading (give more rows)")
        if not _n_reals(observation, 12):
            raise NeurohoverError(f"observation={brief(observation)} is not allowed: give 12 real numbers (ReferenceHelicopter.observation())")
        return self._read(observation)

    def _read(self, observation: Sequence[float]) -> list[float]:
        """:meth:`read` unchecked, for :func:`fly_episode`."""
        k = len(self.readings)
        rho, delay, dropout = self.sensor[4], int(self.sensor[5]), self.sensor[6]
        for i in range(12):
            std = self.sensor[i // 3]  # groups of three entries: velocity, position, rates, attitude
            z = self.normals[k][i]
            self.noise[i] = std * z if k == 0 else rho * self.noise[i] + math.sqrt(1.0 - rho * rho) * std * z
        self.readings.append([o + e for o, e in zip(observation, self.noise)])
        lost = dropout > 0 and k > 0 and 0.5 * math.erfc(-self.normals[k][12] / math.sqrt(2.0)) < dropout  # Phi(z) < p
        if not lost:
            self.delivered = self.readings[max(k - delay, 0)]
        return self.delivered


def fly_episode(
    mdp: ReferenceMDP,
    policy: Callable[[list[float]], Sequence[float]],
    normals: Sequence[Sequence[float]],
    n_steps: int = EPISODE_STEPS,
    sensor_normals: Sequence[Sequence[float]] | None = None,
) -> tuple[float, bool, list[list[float]]]:
    """Fly one episode; returns (return, crashed, observations after reset and every step).

    With ``sensor_normals`` (n_steps + 1 rows of 12, or 13 with a dropout: :func:`neurohover.sim.rng.sensor_normals`)
    the policy flies on the readings of ``mdp.sensor``, and those readings are returned (as the
    kernel records them); the reward stays on the true observation.
    """
    normals, sensor_normals = _check_episode(mdp, policy, normals, n_steps, sensor_normals)
    # a copy of its fields, checked as it is made: one the policy changes mid-episode is not flown (T43-B01)
    mdp = ReferenceMDP(tuple(mdp.params), tuple(mdp.noise_std), mdp.wind_kind, tuple(mdp.wind), mdp.substeps, mdp.dt, mdp.d_u, tuple(mdp.sensor))
    heli = ReferenceHelicopter(mdp, episode_steps=n_steps)
    sensors = None if sensor_normals is None else ReferenceSensors(mdp.sensor, sensor_normals)

    def seen(observation: list[float]) -> list[float]:
        return observation if sensors is None else sensors._read(observation)

    observations = [seen(heli.observation())]
    total = 0.0
    for k in range(n_steps):
        reward, crash = heli._step(_action(policy, observations[-1], k), normals[k])
        total += reward
        observations.append(seen(heli.observation()))
        if crash:
            return total, True, observations
    return total, False, observations


def _check_mdp(mdp: object, prefix: str = "") -> None:
    """Refuse ``mdp`` unless it is a :class:`ReferenceMDP` the simulator can fly (``prefix``: how messages name its fields,
    "mdp." where it is flown). A plain dataclass, it may be changed after it is made: substeps=0 flew a perfect 0.0
    return, a NaN dt a NaN one, 3 params were an unpack ValueError (T43-B01); so it is checked again where flown."""
    if not isinstance(mdp, ReferenceMDP):
        raise NeurohoverError(f"mdp={brief(mdp)} is not allowed: give a ReferenceMDP (an MDP's to_reference())")
    _reals(mdp.params, 11, f"{prefix}params")
    _reals(mdp.noise_std, 6, f"{prefix}noise_std", nonnegative=True)  # standard deviations, as the MDP's (fourteenth trial T14-21)
    _reals(mdp.wind, 8, f"{prefix}wind")
    _check_sensor(_reals(mdp.sensor, 7, f"{prefix}sensor"), prefix)
    if mdp.wind_kind not in (0, WIND_CONSTANT, WIND_SINUSOID) or isinstance(mdp.wind_kind, bool):
        raise NeurohoverError(
            f"{prefix}wind_kind={brief(mdp.wind_kind)} is not allowed: give 0 (none), {WIND_CONSTANT} (constant) or {WIND_SINUSOID} (sinusoid)"
        )
    if not whole_number(mdp.substeps) or mdp.substeps < 1:
        raise NeurohoverError(f"{prefix}substeps={brief(mdp.substeps)} is not allowed: give an integer >= 1 (physics substeps of a control step)")
    if not finite_real(mdp.dt) or mdp.dt <= 0:
        raise NeurohoverError(f"{prefix}dt={brief(mdp.dt)} is not allowed: give a finite number > 0 (seconds of a substep)")
    if not finite_real(mdp.d_u):
        raise NeurohoverError(f"{prefix}d_u={brief(mdp.d_u)} is not allowed: give a finite number")


def _reals(values: object, n: int, what: str, nonnegative: bool = False) -> tuple[float, ...]:
    """``values`` as ``n`` finite real numbers (not bools; >= 0 where ``nonnegative``), or a NeurohoverError naming ``what``:
    a NaN flew a NaN return called "not crashed", a negative std flew (fourteenth trial T14-21)."""
    try:
        items: tuple = tuple(values)  # type: ignore[arg-type]
    except TypeError:
        items = ()
    if len(items) != n or not all(finite_real(v) and not (nonnegative and v < 0) for v in items):
        allowed = "finite and >= 0" if nonnegative else "finite"
        raise NeurohoverError(f"{what}={brief(values)} is not allowed: give {n} real numbers, all {allowed}")
    return tuple(float(v) for v in items)


def _check_sensor(sensor: tuple[float, ...], prefix: str = "") -> None:
    """Refuse a sensor the simulator cannot read: a delay of 1.5 steps flew as 1 without a word (fifteenth trial T15-27),
    a correlation of 1 or more took the root of a negative number."""
    if min(sensor[:4]) < 0 or not 0 <= sensor[4] < 1 or not 0 <= sensor[6] < 1:
        raise NeurohoverError(
            f"{prefix}sensor={brief(sensor)} is not allowed: give 4 stds >= 0, a correlation in [0, 1), "
            f"a delay in 0..{MAX_SENSOR_DELAY} and a dropout in [0, 1)"
        )
    if not sensor[5].is_integer() or not 0 <= sensor[5] <= MAX_SENSOR_DELAY:
        raise NeurohoverError(f"{prefix}sensor delay={brief(sensor[5])} is not allowed: give a whole number of control steps in 0..{MAX_SENSOR_DELAY}")


def _check_episode(mdp: object, policy: object, normals: object, n_steps: object, sensor_normals: object) -> tuple[list[list[float]], list[list[float]] | None]:
    """Refuse what :func:`fly_episode` cannot fly, before it flies (short normals were an IndexError mid-episode, n_steps=-1
    returned (0.0, False); thirteenth trial, F6, F7): one vectorised look at each array of normals. Returns the normals
    as Python floats (float32 normals flew in float32; fifteenth trial T15-27)."""
    _check_mdp(mdp, "mdp.")  # a ReferenceMDP changed after it was made (T43-B01)
    assert isinstance(mdp, ReferenceMDP)
    if not callable(policy):
        raise NeurohoverError(f"policy={brief(policy)} is not allowed: give a function of an observation (12 numbers) to 4 actions")
    if not whole_number(n_steps) or not 1 <= int(n_steps) <= MAX_EPISODE_STEPS:
        raise NeurohoverError(f"n_steps={brief(n_steps)} is not allowed: give an integer in 1..{MAX_EPISODE_STEPS}")
    checked = _normal_rows("normals", normals, int(n_steps), (6,))
    if sensor_normals is None:
        return checked, None
    sensor_checked = _normal_rows("sensor_normals", sensor_normals, int(n_steps) + 1, _sensor_widths(mdp.sensor))
    if not any(mdp.sensor):  # they were ignored without a word (fifteenth trial T15-27)
        raise NeurohoverError(f"sensor_normals are not allowed with the exact sensor {brief(tuple(mdp.sensor))}: they apply to a noisy or late sensor only")
    return checked, sensor_checked


def _sensor_widths(sensor: Sequence[float]) -> tuple[int, ...]:
    """The widths a sensor's rows of normals may have: 13 with a dropout (its draw), else 12 (or 13, the 13th unread)."""
    return (13,) if sensor[6] > 0 else (12, 13)


def _normal_rows(name: str, given: object, rows: int, widths: tuple[int, ...], every: bool = False) -> list[list[float]]:
    """The first ``rows`` rows of ``given`` (the argument ``name``; all of them where ``every``) as Python floats, or one
    NeurohoverError: fewer rows,
    another width, a NaN (a NaN gust flew a NaN return called "not crashed", fourteenth trial T14-21), or no real numbers
    (complex ones were flown by their real part with NumPy's ComplexWarning, T43-B14)."""
    want = f"at least {rows} rows of {widths[0]} numbers (neurohover.sim.rng)"
    arr = as_floats(given, name, want)
    if arr.ndim != 2 or arr.shape[0] < rows or arr.shape[1] not in widths:
        raise NeurohoverError(f"{name} of shape {arr.shape} is not allowed: give {want}")
    rows = arr.shape[0] if every else rows
    if not np.isfinite(arr[:rows]).all():
        row, col = (int(i) for i in np.argwhere(~np.isfinite(arr[:rows]))[0])
        raise NeurohoverError(f"{name}[{row}][{col}] = {arr[row, col]} is not allowed: give finite standard normals (neurohover.sim.rng)")
    return arr[:rows].tolist()


def _n_reals(values: object, n: int) -> bool:
    """Whether ``values`` are ``n`` real numbers (NaN and inf floats too: an action of them crashes) in a sequence or an
    array, the one test of an action (n=4) and of an observation read (n=12): a dict {0: .., 3: ..} flew its keys 0, 1,
    2, 3 (T43-B14); np.timedelta64, a numbers.Real, was float()'s TypeError (T17-1); an int past a float's range is none."""
    if isinstance(values, (str, bytes)) or not isinstance(values, (Sequence, np.ndarray)):
        return False
    try:
        return len(values) == n and all(finite_real(v) or isinstance(v, (float, np.floating)) for v in values)
    except TypeError:
        return False


def _action(policy: Callable[[list[float]], Sequence[float]], observation: list[float], k: int) -> Sequence[float]:
    """The policy's action, refused unless it is 4 numbers (3 were an unpack ValueError; thirteenth trial, F6)."""
    action = policy(observation)
    if not _n_reals(action, 4):
        raise NeurohoverError(f"the policy's action at step {k} is {brief(action)}, not allowed: a policy gives 4 numbers (a sequence or an array)")
    return action
