"""Flight data as transitions, the model's gusts from its residuals, and the noise-free one-step
prediction problem (EC-MENO's objective).

:class:`Transitions` holds every transition k -> k+1 of the flight data with the rotations LR and
the EC methods need; :func:`noise_from_residuals` turns one-step residuals into gust-noise
standard deviations; :class:`OneStepProblem` precomputes the quadratic one-step error of any
one-substep model, and :func:`one_step_error` evaluates it.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import NeurohoverError, brief, finite_real, float64_of, masked_note, refuse_reloaded
from ..flightdata import FlightData, check_flown, crash_flags
from ..sim.constants import GRAVITY, NOISE_DECAY, NOISE_GAIN, NOISE_NAMES, OBS_NAMES, PARAM_NAMES
from ..tasks import MDP
from .model import AXIS_C, AXIS_GAINS, MODEL_DT, LearnedModel, check_vector
from .wind import NO_WIND, WindModel, body_wind

__all__ = ["MIN_TRANSITIONS", "OneStepProblem", "Transitions", "authors_noise", "noise_from_residuals", "one_step_error"]

MIN_TRANSITIONS = 20
_MAX_QUAT_NORM2 = 1.0 + 1e-9
_AXIS_PARAMS = tuple([c, *g] for c, g in zip(AXIS_C, AXIS_GAINS))  # every parameter of each axis


def _rotations(qv: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Body-to-world rotation matrices (N, 3, 3) and qw of quaternion vector parts (N, 3)."""
    qx, qy, qz = qv[:, 0], qv[:, 1], qv[:, 2]
    qw = np.sqrt(np.maximum(0.0, 1.0 - (qx * qx + qy * qy + qz * qz)))
    return _rotation_matrices(qx, qy, qz, qw), qw


def _rotation_matrices(qx, qy, qz, qw) -> np.ndarray:
    xx, yy, zz = qx * qx, qy * qy, qz * qz
    xy, xz, yz = qx * qy, qx * qz, qy * qz
    wx, wy, wz = qw * qx, qw * qy, qw * qz
    r = np.empty((qx.shape[0], 3, 3))
    r[:, 0, 0] = 1.0 - 2.0 * (yy + zz)
    r[:, 0, 1] = 2.0 * (xy - wz)
    r[:, 0, 2] = 2.0 * (xz + wy)
    r[:, 1, 0] = 2.0 * (xy + wz)
    r[:, 1, 1] = 1.0 - 2.0 * (xx + zz)
    r[:, 1, 2] = 2.0 * (yz - wx)
    r[:, 2, 0] = 2.0 * (xz - wy)
    r[:, 2, 1] = 2.0 * (yz + wx)
    r[:, 2, 2] = 1.0 - 2.0 * (xx + yy)
    return r


#: The largest reading of any observed variable flight data may hold: a helicopter crashes long before it moves 1e6 m
#: from its spot or at 1e6 m/s (or rad/s), so a larger one is a damaged reading, not flight (1e300 was taken and called
#: collinear regressors by LR; ninth trial).
MAX_READING = 1e6


def _check_readings(flight_data: FlightData, what: str) -> None:
    """Refuse an observation past :data:`MAX_READING`, naming its episode, step and variable."""
    for e, obs in enumerate(flight_data.observations):
        bad = np.argwhere(np.abs(obs) > MAX_READING)
        if bad.size:
            k, i = (int(x) for x in bad[0])
            raise NeurohoverError(
                f"{what}: episode {e}, step {k} reads {OBS_NAMES[i]} = {obs[k, i]:.6g}, past any flight (at most {MAX_READING:g} in size): "
                "a damaged reading; give flight data as flown"
            )


def _check_quaternions(observations: list[np.ndarray], flown: list[int], metadata: dict, what: str) -> None:
    """Refuse quaternion vector parts longer than 1: LR and the EC methods take ``qw = sqrt(1 - |q vector|^2)`` and the
    body-to-world rotation of each reading, which only a unit quaternion has. Readings through a noisy attitude sensor
    (``--obs-noise attitude=S``) can pass 1 (at S = 0.2 in some hover episodes): kept refused, naming the sensor noise the
    episode's metadata records and what to record instead, where "not helicopter observations" blamed the file (T42-A05)."""
    worst = [float(np.einsum("ij,ij->i", q, q).max(initial=0.0)) for q in (o[:, 9:12].astype(float) for o in observations)]
    if max(worst, default=0.0) <= _MAX_QUAT_NORM2:
        return
    longest = math.sqrt(max(worst))
    tables = metadata.get("mdps")
    tables = tables if isinstance(tables, list) else []
    for i, e in enumerate(flown):
        table = tables[e] if e < len(tables) and isinstance(tables[e], dict) else {}
        sensor = table.get("sensor")
        noise = sensor.get("attitude", 0.0) if isinstance(sensor, dict) else 0.0
        if worst[i] > _MAX_QUAT_NORM2 and finite_real(noise) and noise > 0:
            raise NeurohoverError(
                f"{what}: quaternion vector parts (qx, qy, qz) longer than 1 (max {math.sqrt(worst[i]):.6g} in episode {e}), read through the "
                f"attitude sensor noise {brief(noise)} its metadata records for that episode: a model is fitted from unit quaternions "
                "(qw = sqrt(1 - |q vector|^2)), so record the flight with less attitude noise (e.g. --obs-noise attitude=0.05) or exact sensors"
            )
    raise NeurohoverError(f"{what}: quaternion vector parts (qx, qy, qz) longer than 1 (max {longest:.6g}); not helicopter observations")


class Transitions:
    """All transitions k -> k+1 of the flight data, concatenated over episodes, with rotations.

    Parameters
    ----------
    flight_data : FlightData
        At least ``MIN_TRANSITIONS`` transitions of finite observations with unit quaternions and
        actions in [-1, 1]; anything else is refused with a NeurohoverError naming the episode, step, variable and
        value (:func:`~neurohover.flightdata.check_flown`). One non-finite action is taken: the last of a crashed
        episode (a policy's NaN action, recorded as given, crashes the episode there). Its transition is dropped, not
        learned from: the simulator never flew it (the episode's last observation repeats the one before), and a model
        cannot learn from a NaN action.
    what : str
        What the data are, for error messages.

    Attributes
    ----------
    obs, nxt, act : numpy.ndarray
        Observations at k (N, 12), at k+1 (N, 12) and actions at k (N, 4).
    first : numpy.ndarray of bool
        Whether transition k is the first of its episode.
    step : numpy.ndarray of int64
        The control step of each transition within its episode (0 first): a wind's time.
    R, Rn : numpy.ndarray
        Body-to-world rotations (N, 3, 3) at k and k+1; ``qw`` the scalar part at k.
    V, Vn : numpy.ndarray
        World velocities (N, 3) at k and k+1.
    pair : numpy.ndarray of bool
        Whether transitions k-1 and k lie in one episode (N-1,).
    """

    def __init__(self, flight_data: FlightData, what: str = "flight data") -> None:
        if not isinstance(flight_data, FlightData):
            refuse_reloaded(flight_data, FlightData, what)  # importlib.reload(flightdata): "got FlightData" (T42-B08)
            raise NeurohoverError(f"{what} must be a FlightData, got {type(flight_data).__name__}")
        flight_data.check_again(what)  # metadata edited after making: the learners read crashed and episode_steps (T43-B06)
        episodes, flown = [], []  # flown: each kept episode's index in the flight data
        for e, (o, a, crashed) in enumerate(zip(flight_data.observations, flight_data.actions, crash_flags(flight_data))):
            check_flown(o, a, crashed, f"{what}, episode {e}")  # "holds non-finite observations or actions" named none (T22-02)
            if crashed and a.shape[0] and not np.isfinite(a[-1]).all():
                o, a = o[:-1], a[:-1]  # the simulator never flew it: its next observation repeats the last
            if a.shape[0] > 0:
                episodes.append((o, a))
                flown.append(e)
        n = sum(a.shape[0] for _, a in episodes)
        if n < MIN_TRANSITIONS:
            raise NeurohoverError(f"{what} holds {n} transitions in {flight_data.n_episodes} episodes; learning a model needs at least {MIN_TRANSITIONS}")
        obs = np.concatenate([o[:-1] for o, _ in episodes]).astype(float, copy=False)
        nxt = np.concatenate([o[1:] for o, _ in episodes]).astype(float, copy=False)
        act = np.concatenate([a for _, a in episodes]).astype(float, copy=False)
        _check_readings(flight_data, what)
        _check_quaternions([o for o, _ in episodes], flown, flight_data.metadata, what)
        if np.any(np.abs(act) > 1.0 + 1e-12):
            raise NeurohoverError(
                f"{what}: actions outside [-1, 1] (max |a| {np.abs(act).max():.6g}); flight data hold the clipped actions the simulator applied"
            )
        first = np.zeros(n, dtype=bool)
        first[np.cumsum([0] + [a.shape[0] for _, a in episodes[:-1]])] = True
        self.obs, self.nxt, self.act, self.first = obs, nxt, act, first
        self.step = np.concatenate([np.arange(a.shape[0], dtype=np.int64) for _, a in episodes])
        self.n = n
        self.n_episodes = len(episodes)
        self.R, self.qw = _rotations(obs[:, 9:12])
        self.Rn, _ = _rotations(nxt[:, 9:12])
        # Reconstructed world velocities at k and k+1.
        self.V = np.einsum("nij,nj->ni", self.R, obs[:, 0:3])
        self.Vn = np.einsum("nij,nj->ni", self.Rn, nxt[:, 0:3])
        # Consecutive pairs inside one episode (for AR(1) quasi-differencing).
        self.pair = ~first[1:]

    # LR targets (N, 6): body-frame accelerations minus gravity, and rate accelerations.
    def targets(self) -> np.ndarray:
        acc = (self.Vn - self.V) / MODEL_DT
        acc[:, 2] -= GRAVITY
        y = np.empty((self.n, 6))
        y[:, 0:3] = np.einsum("nji,nj->ni", self.R, acc)  # R_k^T acc: body frame of step k
        y[:, 3:6] = (self.nxt[:, 6:9] - self.obs[:, 6:9]) / MODEL_DT
        return y

    def regressors(self, axis: int, intercept: bool) -> tuple[np.ndarray, tuple[int, ...]]:
        """Design matrix of one axis and the parameter index of each column (-1: intercept)."""
        o, a = self.obs, self.act
        cols: list[np.ndarray]
        if axis == 0:
            cols, idx = [o[:, 0]], [0]
        elif axis == 1:
            cols, idx = [o[:, 1]], [1]
        elif axis == 2:
            cols, idx = [o[:, 2], a[:, 3]], [3, 4]
        else:
            j = axis - 3  # p, q, r with a1, a2, a3
            cols, idx = [o[:, 6 + j], a[:, j]], [AXIS_C[axis], AXIS_GAINS[axis][0]]
        if intercept:
            cols.append(np.ones(self.n))
            idx.append(2 if axis == 1 else -1)
        return np.column_stack(cols), tuple(idx)

    def model_residuals(self, params: np.ndarray) -> np.ndarray:
        """One-step acceleration residuals (n, N, 6) of models ``params`` (n, 11): the model's gusts."""
        p = np.atleast_2d(params)
        y = self.targets()
        o, a = self.obs, self.act
        res = np.empty((p.shape[0], self.n, 6))
        res[:, :, 0] = y[:, 0] - p[:, 0:1] * o[:, 0]
        res[:, :, 1] = y[:, 1] - p[:, 1:2] * o[:, 1] - p[:, 2:3]
        res[:, :, 2] = y[:, 2] - p[:, 3:4] * o[:, 2] - p[:, 4:5] * a[:, 3]
        for j in range(3):
            ci, gi = AXIS_C[3 + j], AXIS_GAINS[3 + j][0]
            res[:, :, 3 + j] = y[:, 3 + j] - p[:, ci : ci + 1] * o[:, 6 + j] - p[:, gi : gi + 1] * a[:, j]
        return res

    def innovations(self, series: np.ndarray) -> np.ndarray:
        """``s_k - 0.8 s_{k-1}`` for consecutive pairs inside an episode (along axis -2)."""
        return (series[..., 1:, :] - NOISE_DECAY * series[..., :-1, :])[..., self.pair, :]


def _checked_residuals(tr: object, residuals: object, batched: bool) -> np.ndarray:
    """``residuals`` as a float array (N, 6), or (..., N, 6) where ``batched``, N being ``tr``'s transitions; else one
    NeurohoverError (None was an AttributeError, 3 numbers an IndexError or einsum's ValueError; fourteenth trial T14-13)."""
    if not isinstance(tr, Transitions):
        raise NeurohoverError(f"tr={brief(tr)} is not allowed: give the Transitions the residuals belong to")
    try:
        arr = np.asarray(residuals)
    except ValueError:  # ragged rows
        arr = np.asarray(None)
    shape = "(..., N, 6)" if batched else "(N, 6)"
    if isinstance(residuals, np.ma.MaskedArray):  # np.asarray drops the mask: the hidden residuals counted in the noise
        raise NeurohoverError(f"residuals of shape {arr.shape} are not allowed{masked_note(residuals)}: give a real array {shape} with N = {tr.n}")
    if arr.dtype.kind not in "iuf" or arr.ndim < 2 or (arr.ndim > 2 and not batched) or arr.shape[-2:] != (tr.n, 6):
        given = f" of shape {arr.shape} and dtype {arr.dtype}" if isinstance(residuals, np.ndarray) else f"={brief(residuals)}"
        raise NeurohoverError(f"residuals{given} is not allowed: give a real array {shape} with N = {tr.n}, the transitions of tr")
    arr = float64_of(arr, copy=False)
    bound = residual_bound(tr.n)
    bad = np.argwhere(~(np.abs(arr) <= bound))  # NaN, +-inf and squares past float64 gave NaN or inf noise (T51-B02)
    if bad.size:
        at = tuple(int(i) for i in bad[0])
        index = ", ".join(str(i) for i in at[:-1])
        raise NeurohoverError(
            f"residuals[{index}, {NOISE_NAMES[at[-1]]}] {brief(float(arr[at]))} is not allowed: give finite numbers in [-{bound:.6g}, {bound:.6g}] "
            f"(the noise estimates are roots of means of their squares over the {tr.n} transitions of tr, which must stay finite)"
        )
    return arr


def residual_bound(n: int) -> float:
    """The largest size of a residual :func:`noise_from_residuals` and :func:`authors_noise` take for ``n`` transitions:
    their squares' mean must stay finite, and the terms squared are at most 1.8 times a residual (an innovation
    ``r_k - 0.8 r_{k-1}``) or 0.1 sqrt(3) times (a world-frame velocity step), so twice the bound, squared and summed
    ``n`` times, stays below a quarter of float64's largest number, rounding and all (T51-B02: 1e200 gave inf with
    NumPy's overflow warning)."""
    return math.sqrt(float(np.finfo(np.float64).max) / n) / 4.0


#: The stationary-rms noise estimate per unit of residual rms, ``sqrt(1 - 0.8**2) / 0.4`` = 1.5 (:func:`noise_from_residuals`):
#: an LR model file's ``stats.noise_std_stationary`` is its ``stats.residual_rms`` times it (T26-B14).
STATIONARY_PER_RMS = math.sqrt(1.0 - NOISE_DECAY**2) / NOISE_GAIN


def noise_from_residuals(tr: Transitions, residuals: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Gust-noise standard deviations of a model from its one-step residuals.

    Parameters
    ----------
    tr : Transitions
        The transitions the residuals belong to.
    residuals : numpy.ndarray
        Acceleration residuals (..., N, 6) (:meth:`Transitions.model_residuals`).

    Returns
    -------
    std, stationary : numpy.ndarray
        (..., 6): the innovation estimate ``rms(r_k - 0.8 r_{k-1}) / 0.4`` (the model's noise) and
        the stationary-rms estimate ``rms(r) * 0.6 / 0.4`` (reported in ``stats``).
    """
    residuals = _checked_residuals(tr, residuals, batched=True)
    innov = tr.innovations(residuals)
    std = np.sqrt(np.mean(innov**2, axis=-2)) / NOISE_GAIN
    stationary = np.sqrt(np.mean(residuals**2, axis=-2)) * STATIONARY_PER_RMS
    return std, stationary


def authors_noise(tr: Transitions, residuals: np.ndarray) -> np.ndarray:
    """The authors' gust-noise estimate (their ``estimate_std``) from one-step acceleration residuals (N, 6).

    They flew the model one step from every observed state and took the rms error of the predicted
    world velocities and rates, over 0.05. A velocity's one-step error is ``0.1 R_k r_k`` (world
    frame) and a rate's ``0.1 r_k``, so the estimate is ``2 rms(R_k r_k)`` and ``2 rms(r_k)``: a
    residual that is pure AR(1) gust noise of std s has rms ``0.4 s / 0.6``, so this reads 4/3 s,
    and any misfit the model leaves (a discarded D_u, a wind) counts in full.
    """
    residuals = _checked_residuals(tr, residuals, batched=False)
    world = np.empty_like(residuals)
    world[:, 0:3] = np.einsum("nij,nj->ni", tr.R, residuals[:, 0:3])
    world[:, 3:6] = residuals[:, 3:6]
    return np.sqrt(np.mean((MODEL_DT * world) ** 2, axis=0)) / (MODEL_DT / 2.0)


def _half_angle_quaternions(rv: np.ndarray) -> np.ndarray:
    """Unit quaternions (N, 4: x, y, z, w) of rotation vectors (N, 3), the kernel's small-angle rule."""
    theta2 = np.einsum("ij,ij->i", rv, rv)
    theta = np.sqrt(theta2)
    small = theta2 < 1e-8
    safe = np.where(small, 1.0, theta)
    k = np.where(small, 0.5, np.sin(0.5 * safe) / safe)
    h = np.empty((rv.shape[0], 4))
    h[:, 0:3] = rv * k[:, None]
    h[:, 3] = np.where(small, np.sqrt(np.maximum(0.0, 1.0 - np.einsum("ij,ij->i", h[:, 0:3], h[:, 0:3]))), np.cos(0.5 * safe))
    return h


class OneStepProblem:
    """Noise-free one-step prediction of the 12-number observation by one-substep models.

    The prediction from observation k (world velocity, position, rates, orientation rebuilt from
    it) with action k follows the kernel's single substep exactly, so it is affine in the 11
    parameters: ``pred_k = base_k + J_k theta``. The mean squared error over transitions,
    ``E(theta) = mean_k |pred_k - obs_{k+1}|^2`` (sum over the 12 entries), is therefore a quadratic
    form precomputed once; evaluating any number of candidate models costs microseconds.

    It is also a sum of six independent per-axis least-squares problems (:meth:`axis_errors`):
    the body force of step k enters the predicted next body velocity through the orthogonal
    ``M_k = R'^T R_k`` (R' the predicted next orientation), so the velocity part of the error is
    ``|M_k^T (pred - obs)|^2``, the squared error of the body velocity change along the u, v and w
    axes *of step k*, each of which depends only on its own parameters (u: C_u; v: C_v, D_v;
    w: C_w, D_w); the rates p, q, r depend only on (C_p, D_p), (C_q, D_q), (C_r, D_r); position
    and orientation do not depend on the parameters at all (:attr:`fixed_error`). Hence
    ``E = fixed_error + sum(axis_errors)``, and the exact minimiser, :meth:`least_squares`, is
    ordinary least squares per axis on the regressors u; v, 1; w, a4; p, a1; q, a2; r, a3 (LR's
    ``"ols"`` with intercepts ``"v"``, up to LR's use of the observed instead of the predicted
    next orientation).
    """

    def __init__(self, flight_data: FlightData) -> None:
        tr = Transitions(flight_data)
        self.transitions = tr
        n = tr.n
        q = np.column_stack([tr.obs[:, 9:12], tr.qw])
        h = _half_angle_quaternions(MODEL_DT * tr.obs[:, 6:9])
        qx, qy, qz, qw = q.T
        hx, hy, hz, hw = h.T
        nq = np.column_stack(
            [
                qw * hx + qx * hw + qy * hz - qz * hy,
                qw * hy - qx * hz + qy * hw + qz * hx,
                qw * hz + qx * hy - qy * hx + qz * hw,
                qw * hw - qx * hx - qy * hy - qz * hz,
            ]
        )
        r_next = _rotation_matrices(nq[:, 0], nq[:, 1], nq[:, 2], nq[:, 3])
        pos = np.einsum("nij,nj->ni", tr.R, tr.obs[:, 3:6]) + MODEL_DT * tr.V
        vel = tr.V.copy()
        vel[:, 2] += MODEL_DT * GRAVITY
        base = np.empty((n, 12))
        base[:, 0:3] = np.einsum("nji,nj->ni", r_next, vel)
        base[:, 3:6] = np.einsum("nji,nj->ni", r_next, pos)
        base[:, 6:9] = tr.obs[:, 6:9]
        base[:, 9:12] = nq[:, 0:3]
        m = np.einsum("nji,njk->nik", r_next, tr.R)  # R'^T R_k: body force of step k in the next body frame
        jac = np.zeros((n, 12, 11))
        o, a = tr.obs, tr.act
        jac[:, 0:3, 0] = MODEL_DT * m[:, :, 0] * o[:, 0:1]
        jac[:, 0:3, 1] = MODEL_DT * m[:, :, 1] * o[:, 1:2]
        jac[:, 0:3, 2] = MODEL_DT * m[:, :, 1]
        jac[:, 0:3, 3] = MODEL_DT * m[:, :, 2] * o[:, 2:3]
        jac[:, 0:3, 4] = MODEL_DT * m[:, :, 2] * a[:, 3:4]
        for j in range(3):
            jac[:, 6 + j, AXIS_C[3 + j]] = MODEL_DT * o[:, 6 + j]
            jac[:, 6 + j, AXIS_GAINS[3 + j][0]] = MODEL_DT * a[:, j]
        r0 = base - tr.nxt
        self.du_jac = MODEL_DT * m[:, :, 0]  # effect of D_u on the next body velocity (N, 3)
        self.dv_jac = MODEL_DT * m[:, :, 1]  # and of a body v acceleration (a wind's)
        self.base, self.jac = base, jac
        self.n = n
        self._h = np.einsum("nij,nik->jk", jac, jac)
        self._b = np.einsum("nij,ni->j", jac, r0)
        self._c = float(np.einsum("ij,ij->", r0, r0))
        # Per-axis constants: velocity residuals in the body frame of step k (M^T r0), rates as they are.
        r0_k = np.einsum("nji,nj->ni", m, r0[:, 0:3])
        self._axis_c = np.concatenate([np.einsum("ni,ni->i", r0_k, r0_k), np.einsum("ni,ni->i", r0[:, 6:9], r0[:, 6:9])])
        #: Mean squared one-step error of position and orientation: no parameter changes it.
        self.fixed_error = max(0.0, (self._c - float(self._axis_c.sum())) / n)

    def axis_errors(self, params) -> np.ndarray:
        """Mean squared one-step error of each axis u, v, w, p, q, r: (11,) -> (6,), (n, 11) -> (n, 6).

        u, v, w: the predicted minus observed next body velocity, expressed in the body frame of
        step k (see the class docstring); p, q, r: the next rates. ``errors(params)`` is
        ``fixed_error + axis_errors(params).sum(-1)``."""
        theta = np.asarray(params, dtype=float)
        if theta.shape[-1:] != (11,) or theta.ndim > 2:
            raise NeurohoverError(f"model parameters must have shape (11,) or (n, 11), got {theta.shape}")
        t2 = np.atleast_2d(theta)
        out = np.empty((t2.shape[0], 6))
        for axis, idx in enumerate(_AXIS_PARAMS):
            t = t2[:, idx]
            out[:, axis] = self._axis_c[axis] + 2.0 * t @ self._b[idx] + np.einsum("ij,jk,ik->i", t, self._h[np.ix_(idx, idx)], t)
        out = np.maximum(out / self.n, 0.0)
        return out[0] if theta.ndim == 1 else out

    def least_squares(self) -> np.ndarray:
        """The closed-form minimiser of :meth:`errors` (11 parameters): least squares per axis.

        Raises NeurohoverError when the flight data do not determine an axis (collinear regressors)."""
        theta = np.zeros(11)
        for axis, idx in enumerate(_AXIS_PARAMS):
            h = self._h[np.ix_(idx, idx)]
            if np.linalg.matrix_rank(h) < len(idx):
                raise NeurohoverError(
                    f"flight data do not determine the {NOISE_NAMES[axis]} axis (regressors "
                    f"{[PARAM_NAMES[i] for i in idx]} are collinear); fly with a policy that varies its actions"
                )
            theta[idx] = np.linalg.solve(h, -self._b[idx])
        return theta

    def regressor_ms(self) -> np.ndarray:
        """Mean square of each parameter's column of the Jacobian (11,): ``E`` rises by
        ``regressor_ms()[i] * d**2`` when parameter i alone moves by d (the diagonal curvature)."""
        return np.diag(self._h) / self.n

    def predict(self, params, d_u: float = 0.0, wind: WindModel = NO_WIND) -> np.ndarray:
        """Predicted next observations (N, 12) of one model's 11 parameters (and its D_u and wind)."""
        theta = np.array(check_vector(params, 11, "model parameters"))
        pred = self.base + self.jac @ theta
        pred[:, 0:3] += d_u * self.du_jac
        if wind.kind != "none":  # the wind's body accelerations C_u wb_u and C_v wb_v
            wb = body_wind(self.transitions, wind)
            pred[:, 0:3] += (theta[0] * wb[:, 0])[:, None] * self.du_jac + (theta[1] * wb[:, 1])[:, None] * self.dv_jac
        return pred

    def errors(self, params) -> np.ndarray | float:
        """Mean squared one-step error of one model (11,) -> float, or of many (n, 11) -> (n,)."""
        theta = np.asarray(params, dtype=float)
        if theta.shape[-1:] != (11,) or theta.ndim > 2:
            raise NeurohoverError(f"model parameters must have shape (11,) or (n, 11), got {theta.shape}")
        t2 = np.atleast_2d(theta)
        e = (self._c + 2.0 * t2 @ self._b + np.einsum("ij,jk,ik->i", t2, self._h, t2)) / self.n
        e = np.maximum(e, 0.0)
        return float(e[0]) if theta.ndim == 1 else e


def _params_of(model) -> np.ndarray:
    if isinstance(model, LearnedModel):
        return np.array(model.params)
    if isinstance(model, MDP):
        if model.substeps != 1 or abs(model.dt - MODEL_DT) > 1e-12 or model.wind_kind != 0:
            raise NeurohoverError("one-step prediction needs a one-substep model MDP without wind (substeps=1, dt=0.1)")
        return np.array(model.params, dtype=float)
    try:  # text or objects were NumPy's "could not convert string to float" (twelfth trial T4)
        return np.asarray(model, dtype=float)
    except (TypeError, ValueError, OverflowError):
        raise NeurohoverError(
            f"model={brief(model)} is not allowed: give a LearnedModel, a one-substep model MDP, 11 parameters or an (n, 11) array of them"
        ) from None


def one_step_error(model, flight_data: FlightData | OneStepProblem):
    """Mean squared noise-free one-step prediction error of the 12-number observation.

    ``model`` is a LearnedModel (with its D_u and wind), a one-substep model MDP without wind, 11
    parameters, or an (n, 11) array of parameter sets (then an array of n errors comes back). The error of a transition is the sum of
    squares over the 12 observation entries; the mean is over all transitions.
    """
    problem = flight_data if isinstance(flight_data, OneStepProblem) else OneStepProblem(flight_data)
    d_u = model.d_u if isinstance(model, (LearnedModel, MDP)) else 0.0
    wind = model.wind if isinstance(model, LearnedModel) else NO_WIND
    if d_u != 0.0 or wind.kind != "none":
        residual = problem.predict(_params_of(model), d_u, wind) - problem.transitions.nxt
        return float(np.einsum("ij,ij->", residual, residual)) / problem.n
    return problem.errors(_params_of(model))
