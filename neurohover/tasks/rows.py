"""The checks of a batch of MDPs for the kernel: rows given as an array (``evaluate_jobs``, ``evaluate`` of rows), the
MDP's own checks, but the family's, in a few NumPy operations; and MDPs given in a collection with no order."""

from __future__ import annotations

from collections.abc import Set
from typing import Any

import numpy as np

from ..errors import NeurohoverError, brief
from ..sim.constants import (
    CONTROL_DT,
    MDP_ROW_LEN,
    ROW_D_U,
    ROW_DT,
    ROW_NOISE,
    ROW_PARAMS,
    ROW_SUBSTEPS,
    ROW_WIND,
    ROW_WIND_KIND,
    WIND_CONSTANT,
    WIND_NONE,
    WIND_SINUSOID,
)
from .base import COVER_TOLERANCE, MAX_MAGNITUDE, MAX_SUBSTEPS

#: The kernel-row columns :data:`MAX_MAGNITUDE` bounds: dynamics parameters, noise stds, wind numbers, D_u.
_BOUNDED = np.r_[ROW_PARAMS, ROW_NOISE, ROW_WIND, ROW_D_U]


def check_rows(rows: np.ndarray) -> None:
    """Refuse kernel rows that no MDP has: anything but an (M, MDP_ROW_LEN) array of finite real numbers, substeps not a
    whole number in 1..MAX_SUBSTEPS, dt <= 0, substeps x dt not one control step, a number past MAX_MAGNITUDE, a
    negative noise std or an unknown wind kind (the MDP's own checks but the family's, in a few
    NumPy operations: evaluate() calls it on every array). An all-zero row (substeps 0) flew as a perfect 0.0 (T14-18)."""
    # type and shape first, the cheap tests: a list was a TypeError, a 1-D row an IndexError (T15-4), a mask dropped (T16-9)
    if (
        not isinstance(rows, np.ndarray)
        or isinstance(rows, np.ma.MaskedArray)
        or rows.ndim != 2
        or rows.shape[1] != MDP_ROW_LEN
        or rows.dtype.kind not in "iuf"
    ):
        got = brief(rows) if isinstance(rows, np.ma.MaskedArray) or not isinstance(rows, np.ndarray) else f"shape {rows.shape}, dtype {rows.dtype}"
        raise NeurohoverError(f"MDP rows must be a float array of shape (M, {MDP_ROW_LEN}), rows as MDP.row() gives them; got {got}")
    if not np.isfinite(rows).all():
        i = int(np.flatnonzero(~np.isfinite(rows).all(axis=1))[0])
        raise NeurohoverError(f"MDP rows must be a float array of shape (M, {MDP_ROW_LEN}) of finite numbers; got row {i}: {brief(rows[i].tolist())}")
    sub, dt, kind = rows[:, ROW_SUBSTEPS], rows[:, ROW_DT], rows[:, ROW_WIND_KIND]
    ok = (sub >= 1) & (sub <= MAX_SUBSTEPS) & (sub == np.floor(sub)) & (dt > 0) & (rows[:, ROW_NOISE].min(axis=1) >= 0)
    ok &= (kind == WIND_NONE) | (kind == WIND_CONSTANT) | (kind == WIND_SINUSOID)
    magnitude = np.abs(rows[:, _BOUNDED]).max(axis=1)
    ok &= (magnitude <= MAX_MAGNITUDE) & (np.abs(sub * dt - CONTROL_DT) <= COVER_TOLERANCE)  # as the MDP's own (T27-B05, T27-B06)
    if ok.all():
        return
    i = int(np.flatnonzero(~ok)[0])
    r = rows[i]
    fields_ = (
        ("substeps", r[ROW_SUBSTEPS], 1 <= r[ROW_SUBSTEPS] <= MAX_SUBSTEPS and float(r[ROW_SUBSTEPS]).is_integer(), f"a whole number in 1..{MAX_SUBSTEPS}"),
        ("dt", r[ROW_DT], r[ROW_DT] > 0, "a substep length > 0"),
        ("noise_std", r[ROW_NOISE].tolist(), r[ROW_NOISE].min() >= 0, "stds >= 0"),
        ("wind_kind", r[ROW_WIND_KIND], r[ROW_WIND_KIND] in (WIND_NONE, WIND_CONSTANT, WIND_SINUSOID), "0 (none), 1 (constant) or 2 (sinusoidal)"),
        ("substeps x dt", r[ROW_SUBSTEPS] * r[ROW_DT], abs(r[ROW_SUBSTEPS] * r[ROW_DT] - CONTROL_DT) <= COVER_TOLERANCE, f"one {CONTROL_DT} s control step"),
        ("a parameter, noise std, wind number or D_u of magnitude", magnitude[i], magnitude[i] <= MAX_MAGNITUDE, f"at most {MAX_MAGNITUDE:g}"),
    )
    name, value, _, allowed = next(f for f in fields_ if not f[2])
    shown = value if isinstance(value, list) else float(value)
    raise NeurohoverError(f"MDP row {i} has {name}={shown!r}, which no MDP has: allowed {allowed} (rows as MDP.row() gives them)")


def refuse_unordered_mdps(mdps: Any) -> Any:
    """``mdps``, unless it is a set of MDPs (a frozenset, a dict's keys): a set has no order, so which MDP was in which
    column, and its episodes' gusts (tied to its position), changed with PYTHONHASHSEED from run to run (T32-B02). The
    one check of evaluate's, evaluate_jobs', crash_matrix's and evaluate_callable's MDPs; a set of policies is refused too."""
    if isinstance(mdps, Set):
        raise NeurohoverError(
            f"mdps={brief(mdps)} is not allowed: a {type(mdps).__name__} has no order, and each MDP's results depend on its position;"
            " give an MDP or a list or tuple of MDPs"
        )
    return mdps
