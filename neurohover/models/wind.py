"""A learned model's wind: a world-frame wind per horizontal axis, constant or sinusoidal, identified
from flight data (issue 22; docs/model.md, Wind-aware models).

The simulator's wind (SPEC section 2) enters only the u and v body forces,
``f_u = C_u (u + wb_u)`` and ``f_v = C_v (v + wb_v) + D_v``, with ``wb`` the world wind
``W(t) = (W_x(t), W_y(t), 0)`` rotated into the body frame. A wind-blind LR model can only carry
a wind as the constant body accelerations D_u and D_v, which is right for a steady wind near hover
and wrong for GHH-09's sinusoids. :class:`WindModel` gives a learned model the same term, per
world axis ``W(t) = A sin(omega t + phase) + offset``, flown by the kernel as any GHH-09 wind (a
learned model is an MDP row: the wind slots exist).

Identification (:func:`fit_wind`)
---------------------------------
1. Frequency, per axis: the wind-blind fit's u and v residual accelerations, divided by C_u and
   C_v and rotated into the world frame, estimate the wind seen at each control step; averaged
   over the episodes at each step (every episode starts the wind at t = 0), their periodogram's
   peak, refined by least squares on all transitions, is omega.
2. Given the frequencies, the u and v body accelerations are linear in the wind's sine, cosine
   and offset coefficients, fitted by least squares over both axes at once. The drags C_u and C_v
   and D_v are held at the helicopter's defaults and D_u is 0: the data pin down drag times wind
   rather than either (the helicopter's velocity follows the wind; :func:`fit_wind`'s
   ``fit_drags`` measures it), in hover (heading north) a body constant and a world offset push
   the same way, and GHH-08 and GHH-09 vary only the wind.

Aliasing. Flight data are sampled at 10 Hz and the model integrates once per 0.1 s step, while
GHH-09's winds run at up to 10 Hz (omega up to 20 pi rad/s) and act on the simulator's ten 0.01 s
substeps. A step's velocity change averages the wind over its substeps, which scales a sinusoid of
frequency omega by ``sin(0.05 omega) / (10 sin(0.005 omega))`` (0 at 10 Hz) and delays it by
0.045 s; sampled at 10 Hz, omega and ``20 pi - omega`` give the same samples. So what the data
determine, and what a one-substep model should fly, is the *effective* wind: the frequency
folded into [0, 10 pi] rad/s (the Nyquist frequency, 5 Hz), the attenuated amplitude and the
shifted phase (:func:`effective_wind`). The report compares the identified wind with it; the
true frequency is known only up to its alias.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import NeurohoverError, as_floats, brief, check_flag, finite_real, whole_number
from ..sim.constants import CONTROL_DT, SUBSTEP_DT, SUBSTEPS, WIND_CONSTANT, WIND_NONE, WIND_SINUSOID

__all__ = ["DEFAULT_WIND_MODEL", "NO_WIND", "WIND_MODELS", "WindAxis", "WindModel", "body_wind", "effective_wind", "fit_wind", "model_times", "sinusoid_axes"]

WIND_MODELS = ("none", "constant", "sinusoid")
DEFAULT_WIND_MODEL = "none"  # the paper's wind-blind model
_NYQUIST = math.pi / CONTROL_DT  # rad/s: 10 pi, half the 10 Hz sampling rate
MIN_WIND_STEPS = 8  # control steps an episode must span for a sinusoid's frequency


@dataclass(frozen=True)
class WindAxis:
    """One world axis of a wind: ``amplitude * sin(omega * t + phase) + offset`` (m/s, rad/s, rad)."""

    amplitude: float = 0.0
    omega: float = 0.0
    phase: float = 0.0
    offset: float = 0.0

    def __post_init__(self) -> None:
        for name in ("amplitude", "omega", "phase", "offset"):
            value = getattr(self, name)
            if not finite_real(value):  # NumPy reals (np.float32(1)) are numbers too; bools are not (fifteenth trial T15-17)
                raise NeurohoverError(f"wind {name}={brief(value)} must be a finite number")
            object.__setattr__(self, name, float(value))
        if self.omega < 0:
            raise NeurohoverError(f"wind omega={self.omega!r} must be >= 0 (rad/s); a negative frequency is a phase of pi")

    def at(self, t: np.ndarray) -> np.ndarray:
        """The wind (m/s) at times ``t`` (s)."""
        return self.amplitude * np.sin(self.omega * _times(t) + self.phase) + self.offset

    def to_dict(self) -> dict:
        return {"amplitude": self.amplitude, "omega": self.omega, "phase": self.phase, "offset": self.offset}


@dataclass(frozen=True)
class WindModel:
    """A learned model's world-frame wind (x: north-south, y: east-west; none, constant or sinusoid)."""

    kind: str = "none"
    x: WindAxis = WindAxis()
    y: WindAxis = WindAxis()

    def __post_init__(self) -> None:
        if not isinstance(self.kind, str) or self.kind not in WIND_MODELS:  # an array: NumPy's ambiguous truth (T47-B06)
            raise NeurohoverError(f"wind model {brief(self.kind)} is not allowed: choose one of {', '.join(WIND_MODELS)}")
        if not isinstance(self.x, WindAxis) or not isinstance(self.y, WindAxis):
            raise NeurohoverError("a wind model's x and y must be WindAxis values")
        if self.kind != "sinusoid" and any(a.amplitude != 0.0 or a.omega != 0.0 or a.phase != 0.0 for a in (self.x, self.y)):
            raise NeurohoverError(f"a {self.kind!r} wind has offsets only; give kind 'sinusoid' for amplitudes, frequencies and phases")
        if self.kind == "none" and (self.x.offset != 0.0 or self.y.offset != 0.0):
            raise NeurohoverError("wind model 'none' has no offsets")

    def mdp_wind(self) -> tuple[int, tuple[float, ...]]:
        """The MDP's ``wind_kind`` and ``wind`` slots that fly this wind in the kernel."""
        if self.kind == "none":
            return WIND_NONE, ()
        if self.kind == "constant":
            return WIND_CONSTANT, (self.x.offset, self.y.offset)
        slots: list[float] = []
        for a in (self.x, self.y):
            # The competition's parameterisation: A = 5 (maxf - center), omega = 20 pi freq, phase = 2 pi phase, offset = 5 center.
            center = a.offset / 5.0
            slots += [a.amplitude / 5.0 + center, a.omega / (20.0 * math.pi), a.phase / (2.0 * math.pi), center]
        return WIND_SINUSOID, tuple(slots)

    def bound_problem(self, bound: float) -> str:
        """The first field whose MDP wind number (:meth:`mdp_wind`) is past ``bound`` (an MDP's), as '<axis>.<field>=<value>
        is out of range: allowed ...', '' when none is: 1e308 made a model that only :meth:`mdp_wind`'s MDP refused (T47-B08)."""
        k = 1.0 if self.kind == "constant" else 5.0  # a sinusoid's offset and maxf are flown divided by 5
        for name, a in (("x", self.x), ("y", self.y)):
            for field, value, number, allowed in (
                ("offset", a.offset, a.offset / k, f"offset in [-{k * bound:g}, {k * bound:g}]"),
                ("amplitude", a.amplitude, a.amplitude / 5.0 + a.offset / 5.0, f"amplitude + offset in [-{5 * bound:g}, {5 * bound:g}]"),
                ("omega", a.omega, a.omega / (20.0 * math.pi), f"omega in [0, {20 * math.pi * bound:.7g}] rad/s"),
                ("phase", a.phase, a.phase / (2.0 * math.pi), f"phase in [-{2 * math.pi * bound:.7g}, {2 * math.pi * bound:.7g}] rad"),
            ):
                if abs(number) > bound:
                    return f"{name}.{field}={brief(value)} is out of range: allowed {allowed}"
        return ""

    def world(self, t: np.ndarray) -> np.ndarray:
        """The world wind (len(t), 2) at times ``t``."""
        t = _times(t)
        return np.column_stack([self.x.at(t), self.y.at(t)])

    def to_dict(self) -> dict:
        return {"kind": self.kind, "x": self.x.to_dict(), "y": self.y.to_dict()}

    @classmethod
    def from_dict(cls, d: object, source: str = "wind") -> WindModel:
        if not isinstance(d, dict) or "kind" not in d:
            raise NeurohoverError(f"{source} must be a table with kind and, for a wind, x and y ({{amplitude, omega, phase, offset}}), got {d!r:.80}")
        axes = []
        for name in ("x", "y"):
            a = d.get(name, {})
            unknown = set(a) - {"amplitude", "omega", "phase", "offset"} if isinstance(a, dict) else None
            if unknown is None or unknown:
                raise NeurohoverError(f"{source}.{name} must hold amplitude, omega, phase and offset, got {a!r:.80}")
            axes.append(WindAxis(**a))
        return cls(d["kind"], axes[0], axes[1])


NO_WIND = WindModel()


def _times(t: object) -> np.ndarray:
    """Times ``t`` (s) as float64, or one NeurohoverError: text was NumPy's ValueError (T43-B04), NaN a NaN wind."""
    allowed = "times in seconds, finite real numbers (a number or an array)"
    out = as_floats(t, "t", allowed)
    if not np.isfinite(out).all():
        raise NeurohoverError(f"t={brief(t)} is not allowed: give {allowed}")
    return out


def sinusoid_axes(wind: tuple[float, ...]) -> tuple[WindAxis, WindAxis]:
    """The x and y axes of a GHH-09 wind given as its 8 competition parameters (SPEC section 2)."""
    allowed = "8 finite numbers, a GHH-09 wind's maxf, freq, phase and center of x, then of y (an MDP's wind)"
    values = as_floats(wind, "wind", allowed)  # 3 numbers were an unpack ValueError, None a TypeError (T43-B04)
    if values.shape != (8,) or not np.isfinite(values).all():
        raise NeurohoverError(f"wind={brief(wind)} is not allowed: give {allowed}")
    axes = []
    for j in (0, 4):
        maxf, freq, phase, center = values[j : j + 4].tolist()
        axes.append(WindAxis(5.0 * (maxf - center), 20.0 * math.pi * freq, 2.0 * math.pi * phase if freq != 0.0 else 0.0, 5.0 * center))
    return axes[0], axes[1]


def model_times(steps: np.ndarray) -> np.ndarray:
    """Wind times (s) of control steps ``steps`` in a one-substep model, as the kernel computes them
    (the competition's ``int(t*100)/100`` floor of ``t = 0.1 * step``)."""
    try:  # 'a' was NumPy's ValueError, None a NaN time and -1 a time of -0.1 s, without a word (T43-B04)
        given = np.asarray(steps)
    except (TypeError, ValueError):
        given = np.asarray(None)
    if given.dtype.kind not in "iu" or (given < 0).any():
        raise NeurohoverError(f"steps={brief(steps)} is not allowed: give control step numbers, whole and >= 0 (an integer or an array of them)")
    t = 0.1 * given.astype(float)
    return np.trunc(t * 100.0) / 100.0


def effective_wind(axis: WindAxis) -> WindAxis:
    """The wind a one-substep model sampled at 10 Hz sees of the simulator's ``axis`` (module
    docstring, Aliasing): the step average over the ten substeps, then the frequency folded into
    [0, 10 pi] rad/s."""
    if not isinstance(axis, WindAxis):  # None was an AttributeError (fourteenth trial T14-13)
        raise NeurohoverError(f"axis={brief(axis)} is not allowed: give a WindAxis (a WindModel's x or y)")
    w = axis.omega
    if w == 0.0 or axis.amplitude == 0.0:
        return WindAxis(offset=axis.offset + (axis.amplitude * math.sin(axis.phase) if w == 0.0 else 0.0))
    # Mean over substeps i = 0..9 of sin(w (t + 0.01 i) + phase) = gain * sin(w t + phase + 0.045 w).
    half = 0.5 * SUBSTEP_DT * w
    gain = math.sin(SUBSTEPS * half) / (SUBSTEPS * math.sin(half)) if math.sin(half) != 0.0 else 1.0
    amplitude, phase = axis.amplitude * gain, axis.phase + 0.5 * (SUBSTEPS - 1) * SUBSTEP_DT * w
    folded = math.fmod(w, 2.0 * _NYQUIST)
    if folded > _NYQUIST:  # sin((2 Nyquist - w') t_k + p) = sin(w' t_k + pi - p) at every sample t_k = 0.1 k
        folded, phase = 2.0 * _NYQUIST - folded, math.pi - phase
    if amplitude < 0:
        amplitude, phase = -amplitude, phase + math.pi
    return WindAxis(amplitude, folded, math.fmod(phase, 2.0 * math.pi) % (2.0 * math.pi), axis.offset)


# ----------------------------------------------------------------------------- identification


def body_wind(tr, wind: WindModel) -> np.ndarray:
    """The wind (N, 2) along the body u and v axes at each transition of ``tr`` (a Transitions)."""
    from .transitions import Transitions  # here: transitions imports this module

    if not isinstance(tr, Transitions):  # None was an AttributeError (T43-B04), as fit_wind refuses it
        raise NeurohoverError(f"tr={brief(tr)} is not allowed: give the flight data as Transitions (neurohover.models.Transitions)")
    if not isinstance(wind, WindModel):
        raise NeurohoverError(f"wind={brief(wind)} is not allowed: give a WindModel (a learned model's wind)")
    w = wind.world(model_times(tr.step))
    return np.column_stack([tr.R[:, 0, 0] * w[:, 0] + tr.R[:, 1, 0] * w[:, 1], tr.R[:, 0, 1] * w[:, 0] + tr.R[:, 1, 1] * w[:, 1]])


def _basis(t: np.ndarray, omega: float | None) -> np.ndarray:
    """Columns sin, cos, 1 (a sinusoid of ``omega``) or 1 alone (``omega`` None: a constant)."""
    if omega is None:
        return np.ones((t.shape[0], 1))
    return np.column_stack([np.sin(omega * t), np.cos(omega * t), np.ones(t.shape[0])])


def _axis_of(beta: np.ndarray, omega: float | None) -> WindAxis:
    if omega is None:
        return WindAxis(offset=float(beta[0]))
    a, b, c = (float(x) for x in beta)
    return WindAxis(math.hypot(a, b), omega, math.atan2(b, a) % (2.0 * math.pi), c)


def _frequency(series: np.ndarray, t: np.ndarray, step: np.ndarray) -> float:
    """Angular frequency (rad/s, in (0, 10 pi]) of the sinusoid in one axis's wind estimates: the
    periodogram peak of their mean over episodes at each step, refined by least squares on all."""
    counts = np.bincount(step)
    seen = counts > 0
    mean = np.bincount(step, weights=series)[seen] / counts[seen]
    k = np.flatnonzero(seen)
    n = int(k[-1]) + 1
    if k.size < MIN_WIND_STEPS:
        raise NeurohoverError(f"a sinusoidal wind needs flight data over at least {MIN_WIND_STEPS} control steps, got {k.size}")
    grid = np.zeros(n)
    grid[k] = mean - mean.mean()
    pad = 8 * n
    power = np.abs(np.fft.rfft(grid, pad)) ** 2
    power[0] = 0.0
    peak = int(np.argmax(power))
    bin_w = 2.0 * math.pi / (pad * CONTROL_DT)

    def sse(omega: float) -> float:
        x = _basis(t, omega)
        coef, *_ = np.linalg.lstsq(x, series, rcond=None)
        return float(np.sum((series - x @ coef) ** 2))

    from scipy.optimize import minimize_scalar  # SciPy's bounded Brent search

    lo, hi = max(bin_w * (peak - 2), 1e-3), min(bin_w * (peak + 2), _NYQUIST)
    best = minimize_scalar(sse, bounds=(lo, hi), method="bounded", options={"xatol": 1e-7})
    return float(best.x) if sse(best.x) <= sse(bin_w * peak) else float(bin_w * peak)


def fit_wind(tr, kind: str, c_u: float, c_v: float, d_v: float, *, fit_drags: bool = False, iterations: int = 50) -> tuple[WindModel, float, float, dict]:
    """Identify a ``kind`` wind ("constant" or "sinusoid") given the u and v drags (or with them).

    Parameters
    ----------
    tr : Transitions
        The flight data.
    kind : {"constant", "sinusoid"}
    c_u, c_v : float
        The u and v drags of the one-substep model: held (``fit_drags`` False, LR's choice), or
        the starting point of their joint fit.
    d_v : float
        D_v, held (module docstring: in hover it cannot be told from an east-west offset).
    fit_drags : bool
        Fit C_u and C_v with the wind by alternating least squares. Measured on one baseline
        episode of each of GHH-09's first four training MDPs: the product of drag and wind is
        what the data pin down (the helicopter's velocity follows the wind), so the joint fit
        wanders along it (C_u -0.01 to -0.06 against -0.18, wind offsets up to 54 m/s) without
        converging in 50 rounds and explains the data no better; with the drags held at the
        helicopter's defaults (GHH-08 and GHH-09 vary only the wind) the effective wind comes out
        within 2 % in amplitude on every strong axis. Hence False.
    iterations : int
        At most this many rounds of alternating least squares (``fit_drags``).

    Returns
    -------
    wind : WindModel
    c_u, c_v : float
        The drags (held, or refitted).
    stats : dict
        Rounds of alternating least squares run, and the rms of the u and v residual accelerations.
    """
    from .transitions import Transitions  # here: transitions imports this module

    if not isinstance(tr, Transitions):  # None was an AttributeError (fourteenth trial T14-13)
        raise NeurohoverError(f"tr={brief(tr)} is not allowed: give the flight data as Transitions (neurohover.models.Transitions)")
    if kind not in ("constant", "sinusoid"):
        raise NeurohoverError(f"wind model {brief(kind)} cannot be fitted: choose constant or sinusoid")
    for name, value in (("c_u", c_u), ("c_v", c_v), ("d_v", d_v)):
        if not finite_real(value):
            raise NeurohoverError(f"{name}={brief(value)} is not allowed: give a finite number")
    check_flag(fit_drags, "fit_drags", "fit the u and v drags too")  # 'no' was true
    if not whole_number(iterations) or iterations < 1:
        raise NeurohoverError(f"iterations={brief(iterations)} is not allowed: give a whole number >= 1 (rounds of alternating least squares)")
    y = tr.targets()
    yu, yv = y[:, 0], y[:, 1] - d_v
    u, v = tr.obs[:, 0], tr.obs[:, 1]
    r00, r10, r01, r11 = tr.R[:, 0, 0], tr.R[:, 1, 0], tr.R[:, 0, 1], tr.R[:, 1, 1]
    t = model_times(tr.step)
    if abs(c_u) < 1e-6 or abs(c_v) < 1e-6:
        raise NeurohoverError(f"the flight data give drags C_u={c_u:.3g} and C_v={c_v:.3g}; a wind acts through them and cannot be identified")
    omegas: tuple[float | None, float | None] = (None, None)
    if kind == "sinusoid":
        # The wind each step saw, from the wind-blind residuals: solve the body u and v equations for (W_x, W_y).
        m = np.empty((tr.n, 2, 2))
        m[:, 0, 0], m[:, 0, 1], m[:, 1, 0], m[:, 1, 1] = c_u * r00, c_u * r10, c_v * r01, c_v * r11
        w = np.linalg.solve(m, np.column_stack([yu - c_u * u, yv - c_v * v])[:, :, None])[:, :, 0]
        omegas = (_frequency(w[:, 0], t, tr.step), _frequency(w[:, 1], t, tr.step))
    bx, by = _basis(t, omegas[0]), _basis(t, omegas[1])
    nx = bx.shape[1]
    beta = np.zeros(nx + by.shape[1])
    rounds, limit = 0, iterations if fit_drags else 1
    while rounds < limit:
        rounds += 1
        # Drags fixed: the u and v equations are linear in the wind's coefficients.
        design = np.vstack([c_u * np.column_stack([r00[:, None] * bx, r10[:, None] * by]), c_v * np.column_stack([r01[:, None] * bx, r11[:, None] * by])])
        beta_new, *_ = np.linalg.lstsq(design, np.concatenate([yu - c_u * u, yv - c_v * v]), rcond=None)
        if not fit_drags:
            beta = beta_new
            break
        # Wind fixed: each axis is linear in its drag.
        wx, wy = bx @ beta_new[:nx], by @ beta_new[nx:]
        xu, xv = u + r00 * wx + r10 * wy, v + r01 * wx + r11 * wy
        c_u_new, c_v_new = float(xu @ yu / (xu @ xu)), float(xv @ yv / (xv @ xv))
        change = max(abs(c_u_new - c_u), abs(c_v_new - c_v), float(np.max(np.abs(beta_new - beta))))
        beta, c_u, c_v = beta_new, c_u_new, c_v_new
        if change < 1e-10:
            break
    wind = WindModel(kind, _axis_of(beta[:nx], omegas[0]), _axis_of(beta[nx:], omegas[1]))
    wb = body_wind(tr, wind)
    after = float(np.sqrt(np.mean((yu - c_u * (u + wb[:, 0])) ** 2 + (yv - c_v * (v + wb[:, 1])) ** 2) / 2.0))
    return wind, c_u, c_v, {"wind_fit_rounds": rounds, "uv_residual_rms": after}
