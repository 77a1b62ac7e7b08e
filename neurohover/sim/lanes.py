"""Several episodes per thread in SIMD lanes: the kernel's rollout without recording or safeguard.

Rows with a sensor model fly here too: each lane's readings come from ``kernel.sense``, scalar per
lane, and its policy reads them instead of the packed observation.

:func:`rollout_lanes` flies the jobs of :func:`neurohover.sim.kernel.rollout_batch` when none
records flight data or has a safeguard and their MDP rows share the substep count and whether
there is wind, LANES episodes per thread in lockstep, each lane with its own job's genome and MDP
row, and writes bit-identical returns, crash flags and steps (about 2.2x the scalar kernel's
episodes/s per core, docs/performance.md). :func:`neurohover.evaluate.evaluate_jobs` and
:meth:`neurohover.evaluate.KernelFlyer.fly` choose it for such batches of at least LANES jobs.

How it works
- Lanes in lockstep over control steps, one episode per lane, and a queue: a lane whose episode ends
  takes the next one, so lanes run at different steps. An idle lane flies at rest.
- All lane data live in one flat float64 buffer ``B[row * LANES + lane]`` (state, drive terms, wind,
  observation, reward, crash flag, and the lane's MDP's dynamics coefficients and dt), so LLVM sees constant, non-overlapping offsets and its SLP
  vectorizer packs the fully unrolled ``for lane in range(LANES)`` loops (the substeps, then the
  observation, reward and crash test) into packed instructions on ymm/zmm registers.
- The three Taylor regimes of ``kernel._half_angle_quaternion`` are all computed and chosen by
  selects; a lane at or above SERIES_MAX_ANGLE (or NaN) is counted, and then that control step is
  flown again for every lane, from the saved start, with ``kernel.integrate`` itself (libm sin/cos).
- Bit-identity: the kernel is compiled with fastmath={"contract"}, so which ``a*b + c`` become FMAs
  is decided by LLVM from the operand order of its optimised IR, and the SLP vectorizer reorders
  operands (the same source contracted differently when packed: returns near -1000 differed by up
  to 8e-13). The lane code is therefore compiled without contraction and every FMA that the
  kernel's compiled code forms is written out as ``llvm.fma`` (:func:`fma`), read from the kernel's
  optimised IR. This is the fragile part: a numba/LLVM upgrade or an edit of ``integrate`` or
  ``observe`` can change the kernel's FMA pattern; tests/test_lanes.py pins both paths bit-identical.
- Still scalar per lane: the policy (``exp`` has no bit-identical packed form), the xoshiro256** /
  ziggurat gust noise, the wind's sin, and the bookkeeping.

Measurements (lane counts, per-substep cost, speed-ups): docs/performance.md.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np
from llvmlite import ir
from numba.core import types
from numba.extending import intrinsic

from .constants import GRAVITY, MAX_POSITION, MAX_RATE, MAX_VELOCITY, MIN_QW, SENSOR_SCRATCH, WIND_SINUSOID
from .kernel import (
    SERIES_MAX_ANGLE,
    clip_action,
    competition_time,
    crash_charge,
    integrate,
    observe,
    policy_action,
    rotation_matrix,
    sense,
    unpack_mdp,
    unpack_sensor,
    update_noise,
)
from .rng import next_normal, seed_sensor_stream, seed_stream

LANES = 8  # episodes per thread: 8 doubles fill an AVX-512 register (prototype: 4 lanes 1.94x, 8 2.20x, 16 2.27x)
BIG2 = SERIES_MAX_ANGLE * SERIES_MAX_ANGLE
ROW_OBS = 21  # buffer rows: 0-12 state, 13-18 drive terms, 19-20 wind, 21-32 observation
ROW_REWARD = 33
ROW_CRASH = 34
ROW_BIG = 35  # counts the step's substeps where the lane turned SERIES_MAX_ANGLE or more
ROW_DYN = 36  # rows 36-41 the lane's MDP's c_u, c_v, c_w, c_p, c_q, c_r, row 42 its substep length dt
ROWS = 43
N_PAR = 21  # per-lane scalar parameters (P[lane]): 0-5 noise std, 6-11 d_u d_v d_w d_p d_q d_r, 12-20 wind


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
def _substeps(B, W, n_sub, has_wind):
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
def _observe_lanes(B):
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


@nb.njit(cache=True, inline="always")
def _state(B, lane):
    """The 13 state values of one lane, as the tuple the kernel's functions take."""
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


@nb.njit(cache=True, fastmath={"contract"})
def _reset_lane(B, N, A, lane):
    """A lane at rest at the start of an episode (also what an idle lane flies)."""
    for m in range(ROWS):
        B[m * LANES + lane] = 0.0
    B[12 * LANES + lane] = 1.0
    for m in range(6):
        N[m, lane] = 0.0
    for m in range(4):
        A[m, lane] = 0.0
    o = observe(_state(B, lane))
    for m in range(12):
        B[(ROW_OBS + m) * LANES + lane] = o[m]


@nb.njit(cache=True, fastmath={"contract"})
def _start_lane(B, P, lane, row):
    """Load the MDP row's parameters into a lane that starts an episode: the dynamics the
    substeps read into B's rows 36-42, the noise, drive and wind parameters into P[lane]."""
    dyn, std, n_sub, dt, wind = unpack_mdp(row)
    c_u, c_v, d_v, c_w, d_w, c_p, d_p, c_q, d_q, c_r, d_r, d_u = dyn
    B[(ROW_DYN + 0) * LANES + lane] = c_u
    B[(ROW_DYN + 1) * LANES + lane] = c_v
    B[(ROW_DYN + 2) * LANES + lane] = c_w
    B[(ROW_DYN + 3) * LANES + lane] = c_p
    B[(ROW_DYN + 4) * LANES + lane] = c_q
    B[(ROW_DYN + 5) * LANES + lane] = c_r
    B[(ROW_DYN + 6) * LANES + lane] = dt
    for m in range(6):
        P[lane, m] = std[m]
    P[lane, 6] = d_u
    P[lane, 7] = d_v
    P[lane, 8] = d_w
    P[lane, 9] = d_p
    P[lane, 10] = d_q
    P[lane, 11] = d_r
    wkind, ax, ox, phx, cx, ay, oy, phy, cy = wind
    P[lane, 12] = wkind
    P[lane, 13] = ax
    P[lane, 14] = ox
    P[lane, 15] = phx
    P[lane, 16] = cx
    P[lane, 17] = ay
    P[lane, 18] = oy
    P[lane, 19] = phy
    P[lane, 20] = cy


@nb.njit(cache=True, fastmath={"contract"})
def _start_sensing(seen, srngs, scratch, lane, row, seed, episode) -> bool:
    """Start the sensor model of a lane's new episode (as kernel.fly_job does); whether its row has one."""
    sensor, on = unpack_sensor(row)
    if on:
        seed_sensor_stream(srngs[lane], np.uint64(seed), np.uint64(episode))
        o = sense((0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0), 0, sensor, srngs[lane], scratch[lane])
        for m in range(12):
            seen[lane, m] = o[m]
    return on


@nb.njit(cache=True, fastmath={"contract"})
def _read(B, seen, srngs, scratch, lane, t, row):
    """The sensors' reading ``t`` of the lane's new observation (B's rows 21-32) into ``seen[lane]``."""
    sensor, _ = unpack_sensor(row)
    o = (
        B[(ROW_OBS + 0) * LANES + lane], B[(ROW_OBS + 1) * LANES + lane], B[(ROW_OBS + 2) * LANES + lane],
        B[(ROW_OBS + 3) * LANES + lane], B[(ROW_OBS + 4) * LANES + lane], B[(ROW_OBS + 5) * LANES + lane],
        B[(ROW_OBS + 6) * LANES + lane], B[(ROW_OBS + 7) * LANES + lane], B[(ROW_OBS + 8) * LANES + lane],
        B[(ROW_OBS + 9) * LANES + lane], B[(ROW_OBS + 10) * LANES + lane], B[(ROW_OBS + 11) * LANES + lane],
    )  # fmt: skip
    r = sense(o, t, sensor, srngs[lane], scratch[lane])
    for m in range(12):
        seen[lane, m] = r[m]


@nb.njit(cache=True, fastmath={"contract"})
def fly_lanes(mdp_rows, policy_kinds, genomes, job_policy, job_mdp, episodes, seed, n_steps, out_return, out_crashed, out_steps, stats):
    """Fly jobs j (policy ``job_policy[j]``, MDP row ``job_mdp[j]``, episode index ``episodes[j]``),
    LANES at a time; write each job's return, crash flag and steps (as kernel.fly_job: no
    recording, no safeguard). Every job's MDP row must have the substep count and the wind
    presence (kind 0 or not) of the first job's row.

    A lane whose episode ends takes the next job (a queue), so lanes run at different steps, each
    with its own genome and its own MDP's parameters.
    stats[0] counts control steps, stats[1] those flown by the scalar fallback.
    """
    n_jobs = episodes.shape[0]
    if n_jobs == 0:
        return
    n_sub = int(mdp_rows[job_mdp[0], 17])
    has_wind = int(mdp_rows[job_mdp[0], 19]) != 0
    B = np.zeros(ROWS * LANES)
    B0 = np.zeros(13 * LANES)
    P = np.zeros((LANES, N_PAR))
    N = np.zeros((6, LANES))
    A = np.zeros((4, LANES))
    W = np.zeros((2, n_sub, LANES))
    rngs = np.empty((LANES, 4), dtype=np.uint64)
    # The sensor model (kernel.sense), scalar per lane: what each lane's policy sees, its stream and state.
    seen = np.zeros((LANES, 12))
    srngs = np.empty((LANES, 4), dtype=np.uint64)
    scratch = np.empty((LANES, SENSOR_SCRATCH))
    sensing = np.zeros(LANES, dtype=np.bool_)
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
            _start_lane(B, P, lane, mdp_rows[job_mdp[nxt]])
            sensing[lane] = _start_sensing(seen, srngs, scratch, lane, mdp_rows[job_mdp[nxt]], seed, episodes[nxt])
            nxt += 1
            live += 1
    while live > 0:
        # Control-step part, scalar per lane: policy, clipping, gust noise, drive terms, wind.
        for lane in range(LANES):
            if job[lane] < 0:
                continue
            k = step[lane]
            if sensing[lane]:
                o0, o1, o2, o3, o4, o5 = seen[lane, 0], seen[lane, 1], seen[lane, 2], seen[lane, 3], seen[lane, 4], seen[lane, 5]
                o9, o10, o11 = seen[lane, 9], seen[lane, 10], seen[lane, 11]
            else:
                o0 = B[(ROW_OBS + 0) * LANES + lane]
                o1 = B[(ROW_OBS + 1) * LANES + lane]
                o2 = B[(ROW_OBS + 2) * LANES + lane]
                o3 = B[(ROW_OBS + 3) * LANES + lane]
                o4 = B[(ROW_OBS + 4) * LANES + lane]
                o5 = B[(ROW_OBS + 5) * LANES + lane]
                o9 = B[(ROW_OBS + 9) * LANES + lane]
                o10 = B[(ROW_OBS + 10) * LANES + lane]
                o11 = B[(ROW_OBS + 11) * LANES + lane]
            pol = job_policy[job[lane]]
            a1, a2, a3, a4 = policy_action(policy_kinds[pol], genomes[pol], o0, o1, o2, o3, o4, o5, o9, o10, o11)
            if not (math.isfinite(a1) and math.isfinite(a2) and math.isfinite(a3) and math.isfinite(a4)):
                j = job[lane]
                out_return[j] = total[lane] + crash_charge(n_steps, k + 1)
                out_crashed[j] = True
                out_steps[j] = k + 1
                job[lane] = -2  # over; the lane idles through this step (at rest, dt 0) and is refilled after it
                _reset_lane(B, N, A, lane)
                continue
            a1 = clip_action(a1)
            a2 = clip_action(a2)
            a3 = clip_action(a3)
            a4 = clip_action(a4)
            rng = rngs[lane]
            std = (P[lane, 0], P[lane, 1], P[lane, 2], P[lane, 3], P[lane, 4], P[lane, 5])
            n = (N[0, lane], N[1, lane], N[2, lane], N[3, lane], N[4, lane], N[5, lane])
            n = update_noise(n, std, next_normal(rng), next_normal(rng), next_normal(rng), next_normal(rng), next_normal(rng), next_normal(rng))
            for m in range(6):
                N[m, lane] = n[m]
            A[0, lane] = a1
            A[1, lane] = a2
            A[2, lane] = a3
            A[3, lane] = a4
            B[13 * LANES + lane] = P[lane, 6] + n[0]
            B[14 * LANES + lane] = P[lane, 7] + n[1]
            B[15 * LANES + lane] = P[lane, 8] * a4 + n[2]
            B[16 * LANES + lane] = P[lane, 9] * a1 + n[3]
            B[17 * LANES + lane] = P[lane, 10] * a2 + n[4]
            B[18 * LANES + lane] = P[lane, 11] * a3 + n[5]
            if has_wind:
                wkind = int(P[lane, 12])
                ax, ox, phx, cx = P[lane, 13], P[lane, 14], P[lane, 15], P[lane, 16]
                ay, oy, phy, cy = P[lane, 17], P[lane, 18], P[lane, 19], P[lane, 20]
                for i in range(n_sub):
                    wu = cx
                    wv = cy
                    if wkind == WIND_SINUSOID:
                        t = competition_time(k, i)
                        if ax != 0.0:
                            wu += ax * math.sin(ox * t + phx)
                        if ay != 0.0:
                            wv += ay * math.sin(oy * t + phy)
                    W[0, i, lane] = wu
                    W[1, i, lane] = wv
        stats[0] += 1
        B0[:] = B[: 13 * LANES]
        if not _substeps(B, W, n_sub, has_wind):
            stats[1] += 1
            B[: 13 * LANES] = B0
            for lane in range(LANES):
                if job[lane] < 0:
                    continue  # idle: stays at rest
                dyn, std, n_sub_l, dt, wind = unpack_mdp(mdp_rows[job_mdp[job[lane]]])
                s = integrate(
                    _state(B, lane),
                    (N[0, lane], N[1, lane], N[2, lane], N[3, lane], N[4, lane], N[5, lane]),
                    A[0, lane],
                    A[1, lane],
                    A[2, lane],
                    A[3, lane],
                    step[lane],
                    dyn,
                    n_sub_l,
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
                    out_return[j] = total[lane] + crash_charge(n_steps, t)
                    out_crashed[j] = True
                elif t == n_steps:
                    out_return[j] = total[lane] + B[ROW_REWARD * LANES + lane]
                    out_crashed[j] = False
                else:
                    total[lane] += B[ROW_REWARD * LANES + lane]
                    if sensing[lane]:
                        _read(B, seen, srngs, scratch, lane, t, mdp_rows[job_mdp[j]])
                    continue
                out_steps[j] = t
            _reset_lane(B, N, A, lane)
            total[lane] = 0.0
            step[lane] = 0
            if nxt < n_jobs:
                job[lane] = nxt
                seed_stream(rngs[lane], np.uint64(seed), np.uint64(episodes[nxt]))
                _start_lane(B, P, lane, mdp_rows[job_mdp[nxt]])
                sensing[lane] = _start_sensing(seen, srngs, scratch, lane, mdp_rows[job_mdp[nxt]], seed, episodes[nxt])
                nxt += 1
            else:
                job[lane] = -1
                live -= 1


@nb.njit(cache=True, parallel=True, fastmath={"contract"})
def rollout_lanes(
    mdp_rows, policy_kinds, genomes, job_policy, job_mdp, job_episode, seed, n_steps, n_threads, out_return, out_crashed, out_steps, out_safeguard_step
):
    """Fly the jobs ``(job_policy[j], job_mdp[j], job_episode[j])``, LANES per thread, in parallel.

    The outputs are those of :func:`neurohover.sim.kernel.rollout_batch` for the same jobs with no
    recording and no safeguard, bit for bit. Each lane flies its own job's genome and MDP row;
    all rows used must share the substep count (row[ROW_SUBSTEPS]) and whether there is wind (row[ROW_WIND_KIND] != 0),
    which the packed substep loop takes as constants (ValueError otherwise).

    Parameters
    ----------
    mdp_rows : numpy.ndarray
        ``(M, MDP_ROW_LEN)`` MDP rows.
    policy_kinds : numpy.ndarray of int64
        ``(P,)`` policy kinds (``kernel.POLICY_SLP`` or ``kernel.POLICY_MLP``).
    genomes : numpy.ndarray
        ``(P, 42)`` genomes, padded as in :class:`neurohover.evaluate.PolicyTable`.
    job_policy, job_mdp, job_episode : numpy.ndarray of int64
        Per job, its policy, its MDP row, and the episode index that with ``seed`` fixes its noise.
    seed : numpy.uint64
        Root seed of the noise streams.
    n_steps : int
        Control steps per episode.
    n_threads : int
        Threads to split the jobs over (``numba.get_num_threads()``; a parameter because reading
        it in compiled code would keep this function out of the on-disk cache).
    out_return, out_crashed, out_steps, out_safeguard_step : numpy.ndarray
        Per job: return, crash flag, steps flown, and -1 (no safeguard), written here.
    """
    n_jobs = job_episode.shape[0]
    if n_jobs > 0:
        n_sub = mdp_rows[job_mdp[0], 17]
        windy = mdp_rows[job_mdp[0], 19] != 0.0
        for j in range(n_jobs):
            if mdp_rows[job_mdp[j], 17] != n_sub or (mdp_rows[job_mdp[j], 19] != 0.0) != windy:
                raise ValueError("rollout_lanes: the jobs' MDP rows differ in substep count or wind presence")
    # One contiguous chunk per thread, each with its own lane queue; no chunk smaller than LANES
    # jobs unless the batch is, so lanes stay full.
    n_chunks = max(1, min(n_threads, n_jobs // LANES))
    for c in nb.prange(n_chunks):
        a = c * n_jobs // n_chunks
        b = (c + 1) * n_jobs // n_chunks
        stats = np.zeros(2, dtype=np.int64)
        fly_lanes(
            mdp_rows, policy_kinds, genomes, job_policy[a:b], job_mdp[a:b], job_episode[a:b], seed, n_steps,
            out_return[a:b], out_crashed[a:b], out_steps[a:b], stats,
        )  # fmt: skip
        for j in range(a, b):
            out_safeguard_step[j] = -1
