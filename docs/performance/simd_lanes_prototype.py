"""Several episodes per thread in SIMD lanes: a prototype of the kernel's hot loop (issue 12, point 1).

Measured on this project's 2-vCPU AMD EPYC (Zen 4, AVX2 + AVX-512) development VM, 2026-11-27,
one thread, 128 full 6000-step episodes of the baseline-equivalent MLP in the zero setting, best of 5,
the kernel's own fly_job (K, 766-771 episodes/s, as evaluate(threads=1): 766) and the lanes (L)
alternated in one process (``--lanes N --episodes 128``):

    lanes   L episodes/s   K episodes/s   L / K
      4        1,486           768        1.94x   (ymm: AVX2 width)
      8        1,695           771        2.20x   (zmm: LLVM packs 8 doubles in AVX-512 registers)
     16        1,741           766        2.27x

Per episode (8 lanes; 1 and 10 substeps compared): a substep costs 3.6 ns instead of 14.1 ns, the rest of
a control step (policy, noise, bookkeeping) about 0.39 ms instead of 0.46 ms; 0.61 ms against 1.30 ms.
Returns, crash flags and step counts are bit-identical to ``neurohover.evaluate.evaluate`` (threads=1) for
64 episodes x 2 seeds of each case that ``--verify`` flies: the zero setting (MLP and SLP baseline), two
GHH-08 (constant wind) and two GHH-09 (sinusoidal wind) test MDPs, crashing policies (a non-finite action
at step 1, crashes at steps 2 to 608), one-substep-of-0.1-s rows (model-like) and a spinning policy that
turns more than SERIES_MAX_ANGLE in a substep (the scalar fallback below), with 4, 8 and 16 lanes.

How it works
- Lanes in lockstep over control steps, one episode per lane, and a queue: a lane whose episode ends takes
  the next one, so lanes run at different steps. An idle lane flies at rest.
- All lane data live in one flat float64 buffer ``B[row * LANES + lane]`` (state, drive terms, wind,
  observation, reward, crash flag), so LLVM sees constant, non-overlapping offsets and its SLP vectorizer
  packs the fully unrolled ``for lane in range(LANES)`` loops (the ten substeps, then the observation,
  reward and crash test) into vmulpd/vfmadd...pd/vsqrtpd on ymm/zmm registers (``--asm`` counts them).
- The three Taylor regimes of ``K._half_angle_quaternion`` are all computed and chosen by selects; a lane
  at or above SERIES_MAX_ANGLE (or NaN) is counted in the vector loop, and then that control step is
  flown again for every lane, from the saved start, with ``K.integrate`` itself (libm sin/cos).
- Bit-identity: the kernel is compiled with fastmath={"contract"}, so which ``a*b + c`` become FMAs is
  decided by LLVM's x86 instruction selection from the order of the operands in its optimized IR, and the
  SLP vectorizer reorders operands, so the same source contracted differently when packed (returns near -1000
  differed by up to 8e-13 after 6000 steps). Here the lane code is compiled without contraction and every FMA that the
  kernel's compiled code forms is written out as ``llvm.fma`` (``fma`` below), read from the kernel's
  optimized IR (``integrate.inspect_llvm()``; fly_job for the observation and the reward): an add whose
  first operand is a single-use product is fused with that product, otherwise with the second one; products
  with several uses (the rotation matrix, 0.5 * rx, ...) are never fused.
- Still scalar per lane: the policy (``exp`` has no bit-identical packed form), the xoshiro256** /
  ziggurat gust noise, the wind's sin, and the bookkeeping.

Integrated since as neurohover/sim/lanes.py (rollout_lanes; evaluate_jobs takes it for batches of one policy on
one MDP row without recording or safeguard; tests/test_lanes.py). What integration was planned to take: this in
kernel.py as a second path of rollout_batch (jobs grouped by MDP and policy,
LANES jobs per prange iteration), recording and the safeguard per lane, a test that pins the two paths
bit-identical (as here) on every MDP kind, and a guard for the fragile part: the FMA pattern of the
scalar kernel is LLVM's choice, so a numba/LLVM upgrade or an edit of integrate/observe can change it.
The clean fix is to write the FMAs out in the scalar kernel too (same ``fma`` intrinsic, contraction off),
which changes no result today and makes both paths exact by construction; the CUDA build has ``fma``.

Run: python3 docs/performance/simd_lanes_prototype.py [--lanes 8] [--verify] [--asm] [--episodes 64]
"""

import argparse
import math
import os
import re
import sys
import time
from collections import Counter

import numba as nb
import numpy as np
from llvmlite import ir
from numba.core import types
from numba.extending import intrinsic

from neurohover.evaluate import PolicyTable, evaluate
from neurohover.policies import baseline_policy, prototype
from neurohover.sim import kernel as K
from neurohover.sim.constants import CRASH_STEP_PENALTY, GRAVITY, MAX_POSITION, MAX_RATE, MAX_VELOCITY, MIN_QW, WIND_SINUSOID
from neurohover.sim.rng import next_normal, seed_stream
from neurohover.tasks import get_task_family

LANES = int(os.environ.get("NEUROHOVER_LANES", "8"))  # a compile-time constant; --lanes re-runs with it set
BIG2 = K.SERIES_MAX_ANGLE * K.SERIES_MAX_ANGLE
ROW_OBS = 21  # buffer rows: 0-12 state, 13-18 drive terms, 19-20 wind, 21-32 observation
ROW_REWARD = 33
ROW_CRASH = 34
ROW_BIG = 35  # counts the step's substeps where the lane turned SERIES_MAX_ANGLE or more
ROWS = 36


@intrinsic
def fma(typingctx, a, b, c):
    """``a * b + c`` rounded once: llvm.fma.f64, which SLP packs into vfmadd...pd."""
    sig = types.float64(types.float64, types.float64, types.float64)

    def codegen(context, builder, signature, args):
        d = ir.DoubleType()
        fn = builder.module.declare_intrinsic("llvm.fma", [d], ir.FunctionType(d, [d, d, d]))
        return builder.call(fn, args)

    return sig, codegen


@nb.njit(inline="always", fastmath=False)
def _hq_select(rx, ry, rz):
    """K._half_angle_quaternion below SERIES_MAX_ANGLE: the three regimes all computed, one chosen
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


@nb.njit(inline="always", fastmath=False)
def _lane_substep(B, lane, dyn, dt, has_wind):
    """One substep of one lane: K.integrate's loop body, every FMA the kernel's compiled code
    forms written out (from its optimised LLVM IR and x86's contraction rule), so that a packed
    and a scalar build give the same bits. Lane state B[m * LANES + lane]: rows 0-12 the state,
    13-18 the drive terms (nu, bias_v, bias_w, drive_p, drive_q, drive_r), 19-20 the wind."""
    c_u, c_v, d_v, c_w, d_w, c_p, d_p, c_q, d_q, c_r, d_r, d_u = dyn
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
    r00, r01, r02, r10, r11, r12, r20, r21, r22 = K._rotation(qx, qy, qz, qw)  # no FMA there
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


@nb.njit(fastmath=False)
def _substeps(B, W, n_sub, dyn, dt, has_wind):
    """All substeps of one control step for all lanes of B, in place; the lane loops are the SIMD
    part. Returns False at the first substep where some lane would turn more than
    SERIES_MAX_ANGLE (libm's sin/cos): the caller then restores the step's start and flies it
    with K.integrate."""
    for lane in range(LANES):
        B[ROW_BIG * LANES + lane] = 0.0
    for i in range(n_sub):
        if has_wind:
            for lane in range(LANES):
                B[19 * LANES + lane] = W[0, i, lane]
                B[20 * LANES + lane] = W[1, i, lane]
            for lane in range(LANES):
                _lane_substep(B, lane, dyn, dt, True)
        else:
            for lane in range(LANES):
                _lane_substep(B, lane, dyn, dt, False)
    n_big = 0
    for lane in range(LANES):
        n_big += B[ROW_BIG * LANES + lane] != 0.0
    return n_big == 0


@nb.njit(fastmath=False)
def _observe_lanes(B):
    """K.observe, K.reward_of and K.crashed of every lane, packed, with the FMAs of the kernel's
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
        r00, r01, r02, r10, r11, r12, r20, r21, r22 = K._rotation(qx, qy, qz, qw)
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


@nb.njit(inline="always")
def _state(B, lane):
    return (
        B[0 * LANES + lane],
        B[1 * LANES + lane],
        B[2 * LANES + lane],
        B[3 * LANES + lane],
        B[4 * LANES + lane],
        B[5 * LANES + lane],
        B[6 * LANES + lane],
        B[7 * LANES + lane],
        B[8 * LANES + lane],
        B[9 * LANES + lane],
        B[10 * LANES + lane],
        B[11 * LANES + lane],
        B[12 * LANES + lane],
    )


@nb.njit(fastmath={"contract"})
def _reset_lane(B, N, A, lane):
    """A lane at rest at the start of an episode (also what an idle lane flies)."""
    for m in range(ROWS):
        B[m * LANES + lane] = 0.0
    B[12 * LANES + lane] = 1.0
    for m in range(6):
        N[m, lane] = 0.0
    for m in range(4):
        A[m, lane] = 0.0
    o = K.observe(_state(B, lane))
    for m in range(12):
        B[(ROW_OBS + m) * LANES + lane] = o[m]


@nb.njit(fastmath={"contract"})
def fly_lanes(row, kind, g, seed, episodes, n_steps, out_return, out_crashed, out_steps, stats):
    """Fly episode indices ``episodes`` of policy (kind, g) on MDP ``row``, LANES at a time;
    write each episode's return, crash flag and steps (as K.fly_job: no recording, no safeguard).

    A lane whose episode ends takes the next one (a queue), so lanes run at different steps.
    stats[0] counts control steps, stats[1] those flown by the scalar fallback.
    """
    dyn, std, n_sub, dt, wind = K.unpack_mdp(row)
    c_u, c_v, d_v, c_w, d_w, c_p, d_p, c_q, d_q, c_r, d_r, d_u = dyn
    wkind, ax, ox, phx, cx, ay, oy, phy, cy = wind
    has_wind = wkind != 0
    n_jobs = episodes.shape[0]
    B = np.zeros(ROWS * LANES)
    B0 = np.zeros(13 * LANES)
    N = np.zeros((6, LANES))
    A = np.zeros((4, LANES))
    W = np.zeros((2, n_sub, LANES))
    rngs = np.empty((LANES, 4), dtype=np.uint64)
    job = np.full(LANES, -1, dtype=np.int64)
    step = np.zeros(LANES, dtype=np.int64)
    total = np.zeros(LANES)
    nxt = 0
    live = 0
    for lane in range(LANES):
        _reset_lane(B, N, A, lane)
        if nxt < n_jobs:
            job[lane] = nxt
            seed_stream(rngs[lane], np.uint64(seed), np.uint64(episodes[nxt]))
            nxt += 1
            live += 1
    while live > 0:
        # Control-step part, scalar per lane: policy, clipping, gust noise, drive terms, wind.
        for lane in range(LANES):
            if job[lane] < 0:
                continue
            k = step[lane]
            o0 = B[(ROW_OBS + 0) * LANES + lane]
            o1 = B[(ROW_OBS + 1) * LANES + lane]
            o2 = B[(ROW_OBS + 2) * LANES + lane]
            o3 = B[(ROW_OBS + 3) * LANES + lane]
            o4 = B[(ROW_OBS + 4) * LANES + lane]
            o5 = B[(ROW_OBS + 5) * LANES + lane]
            o9 = B[(ROW_OBS + 9) * LANES + lane]
            o10 = B[(ROW_OBS + 10) * LANES + lane]
            o11 = B[(ROW_OBS + 11) * LANES + lane]
            a1, a2, a3, a4 = K.policy_action(kind, g, o0, o1, o2, o3, o4, o5, o9, o10, o11)
            if not (math.isfinite(a1) and math.isfinite(a2) and math.isfinite(a3) and math.isfinite(a4)):
                j = job[lane]
                out_return[j] = total[lane] + -CRASH_STEP_PENALTY * (n_steps - (k + 1))
                out_crashed[j] = True
                out_steps[j] = k + 1
                job[lane] = -2  # over; the lane idles through this step and is refilled after it
                _reset_lane(B, N, A, lane)
                continue
            a1 = K._clip(a1)
            a2 = K._clip(a2)
            a3 = K._clip(a3)
            a4 = K._clip(a4)
            rng = rngs[lane]
            n = (N[0, lane], N[1, lane], N[2, lane], N[3, lane], N[4, lane], N[5, lane])
            n = K.update_noise(n, std, next_normal(rng), next_normal(rng), next_normal(rng), next_normal(rng), next_normal(rng), next_normal(rng))
            for m in range(6):
                N[m, lane] = n[m]
            A[0, lane] = a1
            A[1, lane] = a2
            A[2, lane] = a3
            A[3, lane] = a4
            B[13 * LANES + lane] = d_u + n[0]
            B[14 * LANES + lane] = d_v + n[1]
            B[15 * LANES + lane] = d_w * a4 + n[2]
            B[16 * LANES + lane] = d_p * a1 + n[3]
            B[17 * LANES + lane] = d_q * a2 + n[4]
            B[18 * LANES + lane] = d_r * a3 + n[5]
            if has_wind:
                for i in range(n_sub):
                    wu = cx
                    wv = cy
                    if wkind == WIND_SINUSOID:
                        t = K.competition_time(k, i)
                        if ax != 0.0:
                            wu += ax * math.sin(ox * t + phx)
                        if ay != 0.0:
                            wv += ay * math.sin(oy * t + phy)
                    W[0, i, lane] = wu
                    W[1, i, lane] = wv
        stats[0] += 1
        B0[:] = B[: 13 * LANES]
        if not _substeps(B, W, n_sub, dyn, dt, has_wind):
            stats[1] += 1
            B[: 13 * LANES] = B0
            for lane in range(LANES):
                s = K.integrate(
                    _state(B, lane),
                    (N[0, lane], N[1, lane], N[2, lane], N[3, lane], N[4, lane], N[5, lane]),
                    A[0, lane],
                    A[1, lane],
                    A[2, lane],
                    A[3, lane],
                    step[lane],
                    dyn,
                    n_sub,
                    dt,
                    wind,
                )
                for m in range(13):
                    B[m * LANES + lane] = s[m]
        _observe_lanes(B)
        # Bookkeeping, scalar per lane: return, end of episode, refill.
        for lane in range(LANES):
            j = job[lane]
            if j == -1:
                continue
            if j >= 0:
                t = step[lane] + 1
                step[lane] = t
                if B[ROW_CRASH * LANES + lane] != 0.0:
                    out_return[j] = total[lane] + -CRASH_STEP_PENALTY * (n_steps - t)
                    out_crashed[j] = True
                elif t == n_steps:
                    out_return[j] = total[lane] + B[ROW_REWARD * LANES + lane]
                    out_crashed[j] = False
                else:
                    total[lane] += B[ROW_REWARD * LANES + lane]
                    continue
                out_steps[j] = t
            _reset_lane(B, N, A, lane)
            total[lane] = 0.0
            step[lane] = 0
            if nxt < n_jobs:
                job[lane] = nxt
                seed_stream(rngs[lane], np.uint64(seed), np.uint64(episodes[nxt]))
                nxt += 1
            else:
                job[lane] = -1
                live -= 1


@nb.njit(fastmath={"contract"})
def fly_scalar(row, kind, g, seed, episodes, n_steps, out_return, out_crashed, out_steps):
    """The kernel's own fly_job, one episode after another on this thread (rollout_batch without prange)."""
    n = episodes.shape[0]
    mdp_rows = row.reshape((1, row.shape[0]))
    kinds = np.array([kind], dtype=np.int64)
    genomes = g.reshape((1, g.shape[0]))
    zeros = np.zeros(n, dtype=np.int64)
    fb = np.full(n, -1, dtype=np.int64)
    rec = np.full(n, -1, dtype=np.int64)
    limits = np.zeros(10)
    obs = np.zeros((1, 1, 12))
    act = np.zeros((1, 1, 4))
    sg = np.zeros(n, dtype=np.int64)
    rng = np.empty(4, dtype=np.uint64)
    for j in range(n):
        K.fly_job(
            j, rng, mdp_rows, kinds, genomes, zeros, zeros, episodes, fb, seed, n_steps, False, limits, rec, obs, act, out_return, out_crashed, out_steps, sg
        )


def _fly(f, row, kind, g, seed, episodes, n_steps=6000):
    r = np.zeros(episodes.shape[0])
    c = np.zeros(episodes.shape[0], dtype=np.bool_)
    s = np.zeros(episodes.shape[0], dtype=np.int64)
    stats = np.zeros(2, dtype=np.int64)
    if f is fly_lanes:
        f(row, kind, g, seed, episodes, n_steps, r, c, s, stats)
    else:
        f(row, kind, g, seed, episodes, n_steps, r, c, s)
    return r, c, s, stats


def verify(n_eps):
    """Bit-identity of returns, crash flags and steps with neurohover.evaluate.evaluate (one thread)."""
    mlp = prototype("mlp", "baseline")
    t = PolicyTable.from_policies([mlp])
    zero = get_task_family("fghh").zero().row()
    coarse = zero.copy()
    coarse[17], coarse[18] = 1, 0.1  # one substep of 0.1 s, as a learned model flies
    cases = [("zero setting, MLP", t, zero), ("zero setting, SLP baseline", PolicyTable.from_policies([baseline_policy()]), zero)]
    for fam in ("ghh08", "ghh09"):
        for m in get_task_family(fam).test_mdps()[:2]:
            cases.append((f"{m.label}, MLP", t, m.row()))
    rng = np.random.default_rng(3)
    cases.append(("zero setting, MLP genome + N(0, 0.5)", PolicyTable(t.kinds.copy(), t.genomes + rng.normal(size=t.genomes.shape) * 0.5), zero))
    for sc in (0.02, 0.06, 0.08, 0.1):
        g = t.genomes + np.random.default_rng(5).normal(size=t.genomes.shape) * sc
        cases.append((f"zero setting, MLP genome + N(0, {sc})", PolicyTable(t.kinds.copy(), g), zero))
        cases.append((f"1 substep of 0.1 s, MLP genome + N(0, {sc})", PolicyTable(t.kinds.copy(), g), coarse))
    g = t.genomes.copy()
    g[0, 11] = np.inf
    cases.append(("zero setting, non-finite action", PolicyTable(t.kinds.copy(), g), zero))
    spin = np.zeros_like(t.genomes)
    spin[0, 38], spin[0, 36] = 1.0, 0.3  # SLP: constant yaw and roll drive
    for r, label in ((zero, "zero setting"), (coarse, "1 substep of 0.1 s")):
        cases.append((f"{label}, spinning SLP", PolicyTable(np.zeros(1, dtype=t.kinds.dtype), spin), r))
    ok_all = True
    for name, table, row in cases:
        for seed in (0, 12345):
            ev = evaluate(table, row[None, :], episodes=n_eps, seed=seed, threads=1)
            r, c, s, st = _fly(fly_lanes, row, int(table.kinds[0]), table.genomes[0], seed, np.arange(n_eps, dtype=np.int64))
            ok = (
                np.array_equal(r.view(np.int64), np.asarray(ev.returns).reshape(-1).view(np.int64))
                and np.array_equal(c, np.asarray(ev.crashed).reshape(-1))
                and np.array_equal(s, np.asarray(ev.steps).reshape(-1))
            )
            ok_all &= ok
            fallback = f"scalar-fallback steps {st[1]}/{st[0]}"
            print(f"  {name:45s} seed {seed:5d}: crashed {c.sum():3d}/{n_eps}, steps {s.min()}-{s.max()}, {fallback}, bit-identical {ok}")
    print(f"LANES={LANES}: " + ("all bit-identical" if ok_all else "MISMATCH"))
    return ok_all


def asm_counts():
    """Packed and scalar arithmetic instructions in the lane loops' machine code."""
    for f in (_substeps, _observe_lanes):
        asm = f.inspect_asm(f.signatures[0])
        found = re.findall(r"^\s+(v\w+)\s+[^\n]*?%([xyz])mm", asm, re.M)
        ops = Counter(o + " " + r + "mm" for o, r in found if re.search(r"mul|add|sub|fma|fnm|fms|sqrt|cmp", o))
        packed = sum(v for k, v in ops.items() if "pd " in k)
        scalar = sum(v for k, v in ops.items() if "sd " in k)
        print(f"  {f.__name__}: {packed} packed, {scalar} scalar arithmetic instructions; " + ", ".join(f"{k} {v}" for k, v in ops.most_common(8)))


def bench(n_eps, repeats):
    """Episodes/s of the kernel's fly_job and of the lanes, alternated, best of ``repeats``."""
    t = PolicyTable.from_policies([prototype("mlp", "baseline")])
    row = get_task_family("fghh").zero().row()
    kind, g = int(t.kinds[0]), t.genomes[0]
    eps = np.arange(n_eps, dtype=np.int64)
    res = {"kernel fly_job": [], f"{LANES} lanes": []}
    for _ in range(repeats):
        for name, f in (("kernel fly_job", fly_scalar), (f"{LANES} lanes", fly_lanes)):
            t0 = time.perf_counter()
            _fly(f, row, kind, g, 0, eps)
            res[name].append(n_eps / (time.perf_counter() - t0))
    for name, v in res.items():
        print(f"  {name:15s} {max(v):6.0f} episodes/s (best of {repeats}: " + " ".join(f"{x:.0f}" for x in v) + ")")
    print(f"  ratio {max(res[f'{LANES} lanes']) / max(res['kernel fly_job']):.2f}x")


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--lanes", type=int, default=None, help="lanes per thread (default 8; env NEUROHOVER_LANES)")
    ap.add_argument("--episodes", type=int, default=64)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--verify", action="store_true", help="check bit-identity with neurohover.evaluate.evaluate")
    ap.add_argument("--asm", action="store_true", help="count packed instructions in the lane loops")
    args = ap.parse_args()
    if args.lanes is not None and args.lanes != LANES:
        os.environ["NEUROHOVER_LANES"] = str(args.lanes)
        os.execv(sys.executable, [sys.executable, *sys.argv])
    nb.set_num_threads(1)
    if args.verify:
        verify(args.episodes)
    table = PolicyTable.from_policies([prototype("mlp", "baseline")])
    for f in (fly_lanes, fly_scalar):  # compile before timing, with bench's argument types
        _fly(f, get_task_family("fghh").zero().row(), int(table.kinds[0]), table.genomes[0], 0, np.arange(2, dtype=np.int64), 10)
    if args.asm:
        asm_counts()
    bench(args.episodes, args.repeats)
