"""The packed part of the SIMD lanes: one control step's substeps and observation for LANES lanes at once.

All lane data live in one flat float64 buffer ``B[row * LANES + lane]`` (state, drive terms, wind,
observation, reward, crash flag, and the lane's MDP's dynamics coefficients and dt), so LLVM sees
constant, non-overlapping offsets and its SLP vectorizer packs the fully unrolled
``for lane in range(LANES)`` loops into packed instructions on ymm/zmm registers.
:mod:`neurohover.sim.lanes` runs the queue of episodes around it (docs/performance.md).

- The three Taylor regimes of ``kernel._half_angle_quaternion`` are all computed and chosen by
  selects; a lane at or above SERIES_MAX_ANGLE (or NaN) is counted, and then the caller flies that
  control step again for every lane, from the saved start, with ``kernel.integrate`` itself.
- Bit-identity: the kernel is compiled with fastmath={"contract"}, so which ``a*b + c`` become FMAs
  is decided by LLVM from the operand order of its optimised IR, and the SLP vectorizer reorders
  operands (the same source contracted differently when packed: returns near -1000 differed by up
  to 8e-13). This code is therefore compiled without contraction and every FMA that the
  kernel's compiled code forms is written out as ``llvm.fma`` (:func:`fma`), read from the kernel's
  optimised IR. This is the fragile part: a numba/LLVM upgrade or an edit of ``integrate`` or
  ``observe`` can change the kernel's FMA pattern; tests/test_lanes.py pins both paths bit-identical.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from fractions import Fraction
from typing import Any

import numba as nb
from llvmlite import ir
from numba.core import types
from numba.extending import intrinsic

from .constants import GRAVITY, MAX_POSITION, MAX_RATE, MAX_VELOCITY, MIN_QW
from .kernel import SERIES_MAX_ANGLE, rotation_matrix

LANES = 8  # episodes per thread: 8 doubles fill an AVX-512 register (prototype: 4 lanes 1.94x, 8 2.20x, 16 2.27x)
BIG2 = SERIES_MAX_ANGLE * SERIES_MAX_ANGLE
ROW_OBS = 21  # buffer rows: 0-12 state, 13-18 drive terms, 19-20 wind, 21-32 observation
ROW_REWARD = 33
ROW_CRASH = 34
ROW_BIG = 35  # counts the step's substeps where the lane turned SERIES_MAX_ANGLE or more
ROW_DYN = 36  # rows 36-41 the lane's MDP's c_u, c_v, c_w, c_p, c_q, c_r, row 42 its substep length dt
ROWS = 43
N_PAR = 21  # per-lane scalar parameters (P[lane]): 0-5 noise std, 6-11 d_u d_v d_w d_p d_q d_r, 12-20 wind


def or_python(python) -> Callable[[Any], Any]:
    """The decorated intrinsic, or ``python`` where numba leaves the kernels as Python (``NUMBA_DISABLE_JIT=1``) and calls
    it from plain Python: "<intrinsic ...> is not usable in pure-python" ended every evolution (T46-A03)."""

    def choose(compiled):
        return python if getattr(nb.config, "DISABLE_JIT", 0) else compiled  # set from the environment at import

    return choose


def _python_fma(a: float, b: float, c: float) -> float:
    """:func:`fma` in plain Python, rounded once as llvm.fma is (Fraction's exact sum; int / int rounds correctly)."""
    a, b, c = float(a), float(b), float(c)
    if not (math.isfinite(a) and math.isfinite(b) and math.isfinite(c)) or a == 0.0 or b == 0.0:
        return a * b + c  # IEEE's own result: an exact product (a signed zero) or a non-finite operand
    exact = Fraction(a) * Fraction(b) + Fraction(c)
    if exact == 0:
        return 0.0  # an exact zero sum of nonzero terms is +0 when rounding to nearest
    try:
        return float(exact)
    except OverflowError:
        return math.inf if exact > 0 else -math.inf


@or_python(_python_fma)
@intrinsic
def fma(typingctx, a, b, c):
    """``a * b + c`` rounded once: llvm.fma.f64, which SLP packs into vfmadd...pd."""
    sig = types.float64(types.float64, types.float64, types.float64)

    def codegen(context, builder, signature, args):
        d = ir.DoubleType()
        fn = builder.module.declare_intrinsic("llvm.fma", [d], ir.FunctionType(d, [d, d, d]))
        return builder.call(fn, args)

    return sig, codegen


@nb.njit(cache=True, inline="always", fastmath=False)
def _hq_select(rx, ry, rz):
    """kernel._half_angle_quaternion below SERIES_MAX_ANGLE: the three regimes all computed, one chosen
    by selects; each with the operations the kernel's compiled code performs (FMAs explicit)."""
    theta2 = fma(rz, rz, fma(ry, ry, rx * rx))
    h1x = rx * 0.5
    h1y = ry * 0.5
    h1z = rz * 0.5
    w1 = math.sqrt(1.0 - fma(h1z, h1z, fma(h1y, h1y, h1x * h1x)))
    x2 = theta2 * 0.25
    sinc2 = fma(x2, fma(x2, 1.0 / 120, -1.0 / 6), 1.0)
    cos2 = fma(x2, fma(x2, fma(x2, -1.0 / 720, 1.0 / 24), -0.5), 1.0)
    sinc3 = fma(x2, fma(x2, fma(x2, fma(x2, fma(x2, -1.0 / 39916800, 1.0 / 362880), -1.0 / 5040), 1.0 / 120), -1.0 / 6), 1.0)
    cos3 = fma(x2, fma(x2, fma(x2, fma(x2, fma(x2, fma(x2, 1.0 / 479001600, -1.0 / 3628800), 1.0 / 40320), -1.0 / 720), 1.0 / 24), -0.5), 1.0)
    mid = theta2 < 1e-4
    sinc = sinc2 if mid else sinc3
    cs = cos2 if mid else cos3
    k = sinc * 0.5
    small = theta2 < 1e-8
    hx = h1x if small else rx * k
    hy = h1y if small else ry * k
    hz = h1z if small else rz * k
    hw = w1 if small else cs
    return hx, hy, hz, hw, theta2


@nb.njit(cache=True, inline="always", fastmath=False)
def _lane_substep(B, lane, has_wind):
    """One substep of one lane: kernel.integrate's loop body, every FMA the kernel's compiled code
    forms written out (from its optimised LLVM IR and x86's contraction rule), so that a packed
    and a scalar build give the same bits. Lane state B[m * LANES + lane]: rows 0-12 the state,
    13-18 the drive terms (nu, bias_v, bias_w, drive_p, drive_q, drive_r), 19-20 the wind, 36-42
    the lane's own dynamics (c_u, c_v, c_w, c_p, c_q, c_r, dt), so lanes may fly different MDPs."""
    c_u = B[(ROW_DYN + 0) * LANES + lane]
    c_v = B[(ROW_DYN + 1) * LANES + lane]
    c_w = B[(ROW_DYN + 2) * LANES + lane]
    c_p = B[(ROW_DYN + 3) * LANES + lane]
    c_q = B[(ROW_DYN + 4) * LANES + lane]
    c_r = B[(ROW_DYN + 5) * LANES + lane]
    dt = B[(ROW_DYN + 6) * LANES + lane]
    vu = B[0 * LANES + lane]
    vv = B[1 * LANES + lane]
    vw = B[2 * LANES + lane]
    p = B[6 * LANES + lane]
    q = B[7 * LANES + lane]
    r = B[8 * LANES + lane]
    qx = B[9 * LANES + lane]
    qy = B[10 * LANES + lane]
    qz = B[11 * LANES + lane]
    qw = B[12 * LANES + lane]
    B[3 * LANES + lane] = fma(dt, vu, B[3 * LANES + lane])
    B[4 * LANES + lane] = fma(dt, vv, B[4 * LANES + lane])
    B[5 * LANES + lane] = fma(dt, vw, B[5 * LANES + lane])
    r00, r01, r02, r10, r11, r12, r20, r21, r22 = rotation_matrix(qx, qy, qz, qw)  # no FMA there
    bu = fma(r20, vw, fma(r10, vv, r00 * vu))
    bv = fma(r21, vw, fma(r11, vv, r01 * vu))
    bw = fma(r22, vw, fma(r12, vv, r02 * vu))
    if has_wind:
        wu = B[19 * LANES + lane]
        wv = B[20 * LANES + lane]
        bu = bu + fma(r00, wu, r10 * wv)
        bv = bv + fma(r01, wu, r11 * wv)
    fu = fma(c_u, bu, B[13 * LANES + lane])
    fv = fma(c_v, bv, B[14 * LANES + lane])
    fw = fma(c_w, bw, B[15 * LANES + lane])
    B[0 * LANES + lane] = fma(dt, fma(r02, fw, fma(r00, fu, r01 * fv)), vu)
    B[1 * LANES + lane] = fma(dt, fma(r12, fw, fma(r10, fu, r11 * fv)), vv)
    B[2 * LANES + lane] = fma(dt, fma(r22, fw, fma(r20, fu, r21 * fv)) + GRAVITY, vw)
    hx, hy, hz, hw, theta2 = _hq_select(dt * p, dt * q, dt * r)
    B[ROW_BIG * LANES + lane] += 0.0 if theta2 < BIG2 else 1.0  # NaN counts: the scalar code then decides
    B[12 * LANES + lane] = fma(-qz, hz, fma(-qy, hy, fma(qw, hw, -(qx * hx))))
    B[9 * LANES + lane] = fma(-qz, hy, fma(qy, hz, fma(qx, hw, qw * hx)))
    B[10 * LANES + lane] = fma(qz, hx, fma(qy, hw, fma(qw, hy, -(qx * hz))))
    B[11 * LANES + lane] = fma(qz, hw, fma(-qy, hx, fma(qw, hz, qx * hy)))
    B[6 * LANES + lane] = fma(dt, fma(c_p, p, B[16 * LANES + lane]), p)
    B[7 * LANES + lane] = fma(dt, fma(c_q, q, B[17 * LANES + lane]), q)
    B[8 * LANES + lane] = fma(dt, fma(c_r, r, B[18 * LANES + lane]), r)


@nb.njit(cache=True, fastmath=False)
def substeps(B, W, n_sub, has_wind):
    """All substeps of one control step for all lanes of B, in place; the lane loops are the SIMD
    part. Returns False at the first substep where some lane would turn more than
    SERIES_MAX_ANGLE (libm's sin/cos): the caller then restores the step's start and flies it
    with kernel.integrate."""
    for lane in range(LANES):
        B[ROW_BIG * LANES + lane] = 0.0
    for i in range(n_sub):
        if has_wind:
            for lane in range(LANES):
                B[19 * LANES + lane] = W[0, i, lane]
                B[20 * LANES + lane] = W[1, i, lane]
            for lane in range(LANES):
                _lane_substep(B, lane, True)
        else:
            for lane in range(LANES):
                _lane_substep(B, lane, False)
    n_big = 0
    for lane in range(LANES):
        n_big += B[ROW_BIG * LANES + lane] != 0.0
    return n_big == 0


@nb.njit(cache=True, fastmath=False)
def observe_lanes(B):
    """kernel.observe, kernel.reward_of and kernel.crashed of every lane, packed, with the FMAs of the kernel's
    compiled fly_job written out: rows 21-32 the observation, 33 the reward, 34 the crash flag."""
    for lane in range(LANES):
        vu = B[0 * LANES + lane]
        vv = B[1 * LANES + lane]
        vw = B[2 * LANES + lane]
        px = B[3 * LANES + lane]
        py = B[4 * LANES + lane]
        pz = B[5 * LANES + lane]
        p = B[6 * LANES + lane]
        q = B[7 * LANES + lane]
        r = B[8 * LANES + lane]
        qx = B[9 * LANES + lane]
        qy = B[10 * LANES + lane]
        qz = B[11 * LANES + lane]
        qw = B[12 * LANES + lane]
        r00, r01, r02, r10, r11, r12, r20, r21, r22 = rotation_matrix(qx, qy, qz, qw)
        o0 = fma(vw, r20, fma(vv, r10, vu * r00))
        o1 = fma(vw, r21, fma(vu, r01, vv * r11))
        o2 = fma(vw, r22, fma(vu, r02, vv * r12))
        o3 = fma(pz, r20, fma(py, r10, px * r00))
        o4 = fma(pz, r21, fma(px, r01, py * r11))
        o5 = fma(pz, r22, fma(px, r02, py * r12))
        acc = o0 * o0
        acc = fma(o1, o1, acc)
        acc = fma(o2, o2, acc)
        acc = fma(o3, o3, acc)
        acc = fma(o4, o4, acc)
        acc = fma(o5, o5, acc)
        acc = fma(p, p, acc)
        acc = fma(q, q, acc)
        acc = fma(r, r, acc)
        acc = fma(qx, qx, acc)
        acc = fma(qy, qy, acc)
        acc = fma(qz, qz, acc)
        B[(ROW_OBS + 0) * LANES + lane] = o0
        B[(ROW_OBS + 1) * LANES + lane] = o1
        B[(ROW_OBS + 2) * LANES + lane] = o2
        B[(ROW_OBS + 3) * LANES + lane] = o3
        B[(ROW_OBS + 4) * LANES + lane] = o4
        B[(ROW_OBS + 5) * LANES + lane] = o5
        B[(ROW_OBS + 6) * LANES + lane] = p
        B[(ROW_OBS + 7) * LANES + lane] = q
        B[(ROW_OBS + 8) * LANES + lane] = r
        B[(ROW_OBS + 9) * LANES + lane] = qx
        B[(ROW_OBS + 10) * LANES + lane] = qy
        B[(ROW_OBS + 11) * LANES + lane] = qz
        B[ROW_REWARD * LANES + lane] = -acc
        crash = (
            (abs(vu) > MAX_VELOCITY)
            | (abs(vv) > MAX_VELOCITY)
            | (abs(vw) > MAX_VELOCITY)
            | (abs(px) > MAX_POSITION)
            | (abs(py) > MAX_POSITION)
            | (abs(pz) > MAX_POSITION)
            | (abs(p) > MAX_RATE)
            | (abs(q) > MAX_RATE)
            | (abs(r) > MAX_RATE)
            | (abs(qw) < MIN_QW)
        )
        B[ROW_CRASH * LANES + lane] = 1.0 if crash else 0.0
