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

from ..errors import NeurohoverError, brief, finite_real, whole_number
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
    """Unit quaternion of a rotation vector; first-order form below an angle of 1e-4 (docs/model.md, Simulator)."""
    return _rotation_vector_quaternion(_reals(rv, 3, "rv"))  # type: ignore[arg-type]


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
        physics and returned 0.0 (thirteenth trial, F6, F7)."""
        _reals(self.params, 11, "params")
        _reals(self.noise_std, 6, "noise_std", nonnegative=True)  # standard deviations, as the MDP's (fourteenth trial T14-21)
        _reals(self.wind, 8, "wind")
        sensor = _reals(self.sensor, 7, "sensor")
        _check_sensor(sensor)
        if self.wind_kind not in (0, WIND_CONSTANT, WIND_SINUSOID) or isinstance(self.wind_kind, bool):
            raise NeurohoverError(f"wind_kind={brief(self.wind_kind)} is not allowed: give 0 (none), {WIND_CONSTANT} (constant) or {WIND_SINUSOID} (sinusoid)")
        if not whole_number(self.substeps) or self.substeps < 1:
            raise NeurohoverError(f"substeps={brief(self.substeps)} is not allowed: give an integer >= 1 (physics substeps of a control step)")
        if not finite_real(self.dt) or self.dt <= 0:
            raise NeurohoverError(f"dt={brief(self.dt)} is not allowed: give a finite number > 0 (seconds of a substep)")
        if not finite_real(self.d_u):
            raise NeurohoverError(f"d_u={brief(self.d_u)} is not allowed: give a finite number")

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
    """State of one helicopter in the world frame (north-east-down)."""

    mdp: ReferenceMDP
    velocity: Vec = (0.0, 0.0, 0.0)
    position: Vec = (0.0, 0.0, 0.0)
    rates: Vec = (0.0, 0.0, 0.0)
    orientation: Quat = (0.0, 0.0, 0.0, 1.0)
    noise: list[float] = field(default_factory=lambda: [0.0] * 6)
    steps: int = 0
    episode_steps: int = EPISODE_STEPS

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
        """One 0.1 s control step; returns (reward, crashed)."""
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
    each reading but the reset's lost with probability ``dropout`` (the one delivered last held instead)."""

    sensor: Sequence[float]
    normals: Sequence[Sequence[float]]  # 12 standard normals per reading, 13 with a dropout (rng.sensor_normals)
    noise: list[float] = field(default_factory=lambda: [0.0] * 12)
    readings: list[list[float]] = field(default_factory=list)
    delivered: list[float] = field(default_factory=list)

    def read(self, observation: Sequence[float]) -> list[float]:
        """The reading the policy gets now, of the true ``observation`` just made."""
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
    heli = ReferenceHelicopter(mdp, episode_steps=n_steps)
    sensors = None if sensor_normals is None else ReferenceSensors(mdp.sensor, sensor_normals)

    def seen(observation: list[float]) -> list[float]:
        return observation if sensors is None else sensors.read(observation)

    observations = [seen(heli.observation())]
    total = 0.0
    for k in range(n_steps):
        reward, crash = heli.step(_action(policy, observations[-1], k), normals[k])
        total += reward
        observations.append(seen(heli.observation()))
        if crash:
            return total, True, observations
    return total, False, observations


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


def _check_sensor(sensor: tuple[float, ...]) -> None:
    """Refuse a sensor the simulator cannot read: a delay of 1.5 steps flew as 1 without a word (fifteenth trial T15-27),
    a correlation of 1 or more took the root of a negative number."""
    if min(sensor[:4]) < 0 or not 0 <= sensor[4] < 1 or not 0 <= sensor[6] < 1:
        raise NeurohoverError(
            f"sensor={brief(sensor)} is not allowed: give 4 stds >= 0, a correlation in [0, 1), a delay in 0..{MAX_SENSOR_DELAY} and a dropout in [0, 1)"
        )
    if not sensor[5].is_integer() or not 0 <= sensor[5] <= MAX_SENSOR_DELAY:
        raise NeurohoverError(f"sensor delay={brief(sensor[5])} is not allowed: give a whole number of control steps in 0..{MAX_SENSOR_DELAY}")


def _check_episode(mdp: object, policy: object, normals: object, n_steps: object, sensor_normals: object) -> tuple[list[list[float]], list[list[float]] | None]:
    """Refuse what :func:`fly_episode` cannot fly, before it flies (short normals were an IndexError mid-episode, n_steps=-1
    returned (0.0, False); thirteenth trial, F6, F7): one vectorised look at each array of normals. Returns the normals
    as Python floats (float32 normals flew in float32; fifteenth trial T15-27)."""
    if not isinstance(mdp, ReferenceMDP):
        raise NeurohoverError(f"mdp={brief(mdp)} is not allowed: give a ReferenceMDP (an MDP's to_reference())")
    if not callable(policy):
        raise NeurohoverError(f"policy={brief(policy)} is not allowed: give a function of an observation (12 numbers) to 4 actions")
    if not whole_number(n_steps) or not 1 <= int(n_steps) <= MAX_EPISODE_STEPS:
        raise NeurohoverError(f"n_steps={brief(n_steps)} is not allowed: give an integer in 1..{MAX_EPISODE_STEPS}")
    width = 13 if mdp.sensor[6] > 0 else 12
    checked: list[list[list[float]] | None] = [None, None]
    for j, (name, given, rows, widths) in enumerate(
        (("normals", normals, int(n_steps), (6,)), ("sensor_normals", sensor_normals, int(n_steps) + 1, (width, 13)))
    ):
        if name == "sensor_normals" and given is None:
            continue
        want = f"give at least {rows} rows of {widths[0]} numbers (neurohover.sim.rng)"
        try:
            arr = np.asarray(given, dtype=float)
        except (TypeError, ValueError, OverflowError):  # ragged rows, text, 10**400 (an OverflowError)
            raise NeurohoverError(f"{name}={brief(given)} is not allowed: {want}") from None
        if arr.ndim != 2 or arr.shape[0] < rows or arr.shape[1] not in widths:
            raise NeurohoverError(f"{name} of shape {arr.shape} is not allowed: {want}")
        if not np.isfinite(arr[:rows]).all():  # a NaN gust flew a NaN return called "not crashed" (fourteenth trial T14-21)
            row, col = (int(i) for i in np.argwhere(~np.isfinite(arr[:rows]))[0])
            raise NeurohoverError(f"{name}[{row}][{col}] = {arr[row, col]} is not allowed: give finite standard normals (neurohover.sim.rng)")
        checked[j] = arr[:rows].tolist()
    if sensor_normals is not None and not any(mdp.sensor):  # they were ignored without a word (fifteenth trial T15-27)
        raise NeurohoverError(f"sensor_normals are not allowed with the exact sensor {brief(tuple(mdp.sensor))}: they apply to a noisy or late sensor only")
    assert checked[0] is not None
    return checked[0], checked[1]


def _action(policy: Callable[[list[float]], Sequence[float]], observation: list[float], k: int) -> Sequence[float]:
    """The policy's action, refused unless it is 4 numbers (3 were an unpack ValueError; thirteenth trial, F6)."""
    action = policy(observation)
    try:
        # real numbers, NaN too (it crashes): np.timedelta64, a numbers.Real, was float()'s TypeError (T17-1)
        ok = len(action) == 4 and all(finite_real(a) or isinstance(a, (float, np.floating)) for a in action)
    except TypeError:
        ok = False
    if not ok:
        raise NeurohoverError(f"the policy's action at step {k} is {brief(action)}, not allowed: a policy gives 4 numbers")
    return action
