"""The compiled simulation kernel: the hover dynamics that everything flies.

Evolution, resampling, selection races, learned models, on-line agents and the Gymnasium
environments all fly helicopters through the functions here: the scalar episode loop, and the
physics that the SIMD lanes (:mod:`.lanes`), the environments' step (:mod:`.step`) and the CUDA
kernel (:mod:`.cuda`) build on, tested bit-identical to it. An MDP is a float64 row (layout in
:mod:`neurohover.sim.constants`) holding dynamics parameters, noise standard deviations, substep
count and length, and the wind model, so a learned model (one 0.1 s substep, no wind) runs in
the same code as the true simulator.

Hot-path choices (the physics is exactly that of docs/model.md, Simulator):
- state lives in scalars, not arrays, so LLVM keeps it in registers;
- orientation uses a rotation matrix built once per substep for the three frame changes;
- the rotation-vector quaternion uses Taylor series of sin(x)/x and cos(x) accurate to double
  precision for the small angles of hovering flight, and libm beyond them;
- gust noise comes from a per-episode xoshiro256** stream through a ziggurat.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from .constants import (
    CRASH_STEP_PENALTY,
    GRAVITY,
    MAX_POSITION,
    MAX_RATE,
    MAX_SENSOR_DELAY,
    MAX_VELOCITY,
    MIN_QW,
    MLP_STEEPNESS,
    NOISE_DECAY,
    NOISE_GAIN,
    ROW_D_U,
    ROW_DT,
    ROW_NOISE_START,
    ROW_PARAMS_START,
    ROW_SENSOR_START,
    ROW_SUBSTEPS,
    ROW_WIND_KIND,
    ROW_WIND_START,
    SAFEGUARD_ARM,
    SENSOR_SCRATCH,
    WIND_CONSTANT,
    WIND_SINUSOID,
)
from .rng import next_normal, seed_sensor_stream, seed_stream

POLICY_SLP = 0
POLICY_MLP = 1
GENOME_WIDTH = 42  # genome rows are padded to the MLP's length
SERIES_MAX_ANGLE = 0.5  # Taylor series below this rotation angle, libm above
SQRT_HALF = math.sqrt(0.5)  # the normal CDF: Phi(z) = erfc(-z sqrt(1/2)) / 2 (a sensor dropout's uniform draw)


@nb.njit(cache=True, inline="always", fastmath={"contract"})
def _sigmoid(s: float) -> float:
    return 1.0 / (1.0 + math.exp(-MLP_STEEPNESS * s))


@nb.njit(cache=True, fastmath={"contract"})
def policy_action(kind, g, u, v, w, x, y, z, qx, qy, qz):
    """Actions (a1..a4) of a generic policy for the 9 inputs it sees (docs/model.md, Policies)."""
    if kind == POLICY_SLP:
        a1 = g[0] * u + g[1] * v + g[2] * w + g[3] * x + g[4] * y + g[5] * z + g[6] * qx + g[7] * qy + g[8] * qz + g[36]
        a2 = g[9] * u + g[10] * v + g[11] * w + g[12] * x + g[13] * y + g[14] * z + g[15] * qx + g[16] * qy + g[17] * qz + g[37]
        a3 = g[18] * u + g[19] * v + g[20] * w + g[21] * x + g[22] * y + g[23] * z + g[24] * qx + g[25] * qy + g[26] * qz + g[38]
        a4 = g[27] * u + g[28] * v + g[29] * w + g[30] * x + g[31] * y + g[32] * z + g[33] * qx + g[34] * qy + g[35] * qz + g[39]
        return a1, a2, a3, a4
    # MLP: biases g[0:15] (hy hx hz L1..L4 S1..S4 a1..a4), then the 27 weights in the order of docs/model.md, Policies.
    hy = _sigmoid(g[0] + g[15] * y)
    hx = _sigmoid(g[1] + g[16] * x)
    hz = _sigmoid(g[2] + g[17] * z)
    l1 = g[3] + g[18] * v + g[19] * y + g[20] * qx + g[21] * hy
    l2 = g[4] + g[22] * u + g[23] * x + g[24] * qy + g[25] * hx
    l3 = g[5] + g[26] * qz
    l4 = g[6] + g[27] * w + g[28] * z + g[29] * hz
    s1 = _sigmoid(g[7] + g[30] * l1)
    s2 = _sigmoid(g[8] + g[31] * l2)
    s3 = _sigmoid(g[9] + g[32] * l3)
    s4 = _sigmoid(g[10] + g[33] * l4)
    a1 = g[11] + g[34] * l1 + g[35] * s1
    a2 = g[12] + g[36] * l2 + g[37] * s2
    a3 = g[13] + g[38] * l3 + g[39] * s3
    a4 = g[14] + g[40] * l4 + g[41] * s4
    return a1, a2, a3, a4


@nb.njit(cache=True, inline="always", fastmath={"contract"})
def clip_action(a: float) -> float:
    return min(1.0, max(-1.0, a))


@nb.njit(cache=True, inline="always", fastmath={"contract"})
def rotation_matrix(qx, qy, qz, qw):
    """Rotation matrix (body to world) of a unit quaternion, row by row."""
    x2 = qx + qx  # doubling is exact, so 2(xy - wz) == x(2y) - w(2z) with fewer operations
    y2 = qy + qy
    z2 = qz + qz
    xx = qx * x2
    yy = qy * y2
    zz = qz * z2
    xy = qx * y2
    xz = qx * z2
    yz = qy * z2
    wx = qw * x2
    wy = qw * y2
    wz = qw * z2
    return (
        1.0 - (yy + zz),
        xy - wz,
        xz + wy,
        xy + wz,
        1.0 - (xx + zz),
        yz - wx,
        xz - wy,
        yz + wx,
        1.0 - (xx + yy),
    )


@nb.njit(cache=True, fastmath={"contract"})
def observe(s):
    """The 12-number observation of state tuple ``s`` (world velocity and position into body frame)."""
    r00, r01, r02, r10, r11, r12, r20, r21, r22 = rotation_matrix(s[9], s[10], s[11], s[12])
    vu, vv, vw, px, py, pz = s[0], s[1], s[2], s[3], s[4], s[5]
    return (
        r00 * vu + r10 * vv + r20 * vw,
        r01 * vu + r11 * vv + r21 * vw,
        r02 * vu + r12 * vv + r22 * vw,
        r00 * px + r10 * py + r20 * pz,
        r01 * px + r11 * py + r21 * pz,
        r02 * px + r12 * py + r22 * pz,
        s[6],
        s[7],
        s[8],
        s[9],
        s[10],
        s[11],
    )


@nb.njit(cache=True, inline="always", fastmath={"contract"})
def crash_charge(n_steps, t) -> float:
    """The reward of a crash at control step ``t`` (1-based) of an ``n_steps`` episode: the worst step for every step left."""
    return -CRASH_STEP_PENALTY * (n_steps - t)


@nb.njit(cache=True, inline="always", fastmath={"contract"})
def reward_of(o) -> float:
    """Minus the sum of squares of the 12 observation entries."""
    acc = 0.0
    for i in range(12):
        acc += o[i] * o[i]
    return -acc


@nb.njit(cache=True, inline="always", fastmath={"contract"})
def crashed(s) -> bool:
    """The crash test (docs/model.md, Simulator) on the world-frame state tuple."""
    return (
        abs(s[0]) > MAX_VELOCITY
        or abs(s[1]) > MAX_VELOCITY
        or abs(s[2]) > MAX_VELOCITY
        or abs(s[3]) > MAX_POSITION
        or abs(s[4]) > MAX_POSITION
        or abs(s[5]) > MAX_POSITION
        or abs(s[6]) > MAX_RATE
        or abs(s[7]) > MAX_RATE
        or abs(s[8]) > MAX_RATE
        or abs(s[12]) < MIN_QW
    )


@nb.njit(cache=True, inline="always", fastmath={"contract"})
def step_outcome(s, o, n_steps, t):
    """The end-of-step rule, once for the compiled code (the lanes keep its packed form): control step ``t``
    (1-based) of an ``n_steps`` episode that left state ``s`` and observation ``o`` earns ``(reward, crashed)``,
    the crash charge if the helicopter crashed, else the observation's reward."""
    if crashed(s):
        return crash_charge(n_steps, t), True
    return reward_of(o), False


@nb.njit(cache=True, inline="always", fastmath={"contract"})
def dangerous(o, limits) -> bool:
    """Safeguard test on observation ``o`` (``limits`` in the layout of constants.SAFEGUARD_LIMITS).

    Kind 0 (``limits[10]``): some velocity, position or rate entry beyond its limit ``limits[0:9]``
    while the helicopter is tilted, qw < ``limits[9]`` (qw from the quaternion's vector part, as
    the authors' code computed it; ``limits[9] = inf``: the box test alone). Kind 1 (the authors'
    FGHH agent): the signed sum of ``o[i] / limits[12 + i]`` over the 12 entries above ``limits[11]``."""
    if limits[10] != 0.0:
        total = 0.0
        for i in range(12):
            total += o[i] / limits[12 + i]
        return total > limits[11]
    for i in range(9):
        if abs(o[i]) > limits[i]:
            qw = math.sqrt(max(0.0, 1.0 - (o[9] * o[9] + o[10] * o[10] + o[11] * o[11])))
            return qw < limits[9]
    return False


@nb.njit(cache=True, inline="always", fastmath={"contract"})
def _half_angle_quaternion(rx, ry, rz):
    """Unit quaternion (x, y, z, w) of rotation vector (rx, ry, rz), the small-angle rule of docs/model.md, Simulator, included."""
    theta2 = rx * rx + ry * ry + rz * rz
    if theta2 < 1e-8:  # angle below 1e-4
        hx = 0.5 * rx
        hy = 0.5 * ry
        hz = 0.5 * rz
        return hx, hy, hz, math.sqrt(1.0 - (hx * hx + hy * hy + hz * hz))
    x2 = 0.25 * theta2  # (theta/2)^2
    if theta2 < 1e-4:  # angle below 0.01 (steady hover): remainders below 1e-17
        sinc = 1.0 + x2 * (-1.0 / 6 + x2 * (1.0 / 120))
        cos = 1.0 + x2 * (-0.5 + x2 * (1.0 / 24 + x2 * (-1.0 / 720)))
        k = 0.5 * sinc
        return k * rx, k * ry, k * rz, cos
    if theta2 < SERIES_MAX_ANGLE * SERIES_MAX_ANGLE:  # remainders below 1e-17
        sinc = 1.0 + x2 * (-1.0 / 6 + x2 * (1.0 / 120 + x2 * (-1.0 / 5040 + x2 * (1.0 / 362880 + x2 * (-1.0 / 39916800)))))
        cos = 1.0 + x2 * (-0.5 + x2 * (1.0 / 24 + x2 * (-1.0 / 720 + x2 * (1.0 / 40320 + x2 * (-1.0 / 3628800 + x2 * (1.0 / 479001600))))))
        k = 0.5 * sinc  # sin(theta/2) / theta
        return k * rx, k * ry, k * rz, cos
    theta = math.sqrt(theta2)
    k = math.sin(0.5 * theta) / theta
    return k * rx, k * ry, k * rz, math.cos(0.5 * theta)


@nb.njit(cache=True, inline="always", fastmath=False)
def _product(a, b):
    """``a * b`` rounded on its own, never fused into an FMA (the CUDA build maps it to ``dmul_rn``)."""
    return a * b


@nb.njit(cache=True, fastmath=False)  # explicit: callees inherit fastmath, and an FMA rounds differently
def competition_time(step, substep):
    """Time (s) of a substep as the competition software computed it: ``int(t*100)/100.0`` with
    ``t = 0.1*step + 0.01*substep`` in floating point (about 4% of substeps land 0.01 s early)."""
    t = _product(0.1, step) + _product(0.01, substep)
    return int(t * 100.0) / 100.0


@nb.njit(cache=True, inline="always", fastmath={"contract"})
def wind_at(wind, step, substep):
    """The world wind ``(u, v)`` (m/s) of substep ``substep`` of control step ``step``: per axis
    ``c + A sin(omega t + phi)`` at the competition's time t (:func:`competition_time`), ``c`` alone for
    a constant wind. ``wind`` is :func:`unpack_mdp`'s tuple; its kind is not 0 (no wind)."""
    kind, ax, ox, phx, cx, ay, oy, phy, cy = wind
    wu = cx
    wv = cy
    if kind == WIND_SINUSOID:
        t = competition_time(step, substep)
        if ax != 0.0:
            wu += ax * math.sin(ox * t + phx)
        if ay != 0.0:
            wv += ay * math.sin(oy * t + phy)
    return wu, wv


@nb.njit(cache=True, fastmath={"contract"})
def unpack_mdp(row):
    """Dynamics, noise, integration and wind settings of an MDP row as a tuple of scalars."""
    # Wind as A*sin(omega*t + phi) + c per world axis; constant wind is A = 0.
    # The row's layout: sim.constants (ROW_*); w: the wind parameters (maxf, freq, phase, center per axis).
    kind, w, s = int(row[ROW_WIND_KIND]), ROW_WIND_START, ROW_NOISE_START
    if kind == WIND_SINUSOID:
        ax = 5.0 * (row[w] - row[w + 3])
        ox = 20.0 * math.pi * row[w + 1]
        phx = 2.0 * math.pi * row[w + 2] if row[w + 1] != 0.0 else 0.0  # the competition: no phase without frequency
        cx = 5.0 * row[w + 3]
        ay = 5.0 * (row[w + 4] - row[w + 7])
        oy = 20.0 * math.pi * row[w + 5]
        phy = 2.0 * math.pi * row[w + 6] if row[w + 5] != 0.0 else 0.0
        cy = 5.0 * row[w + 7]
    elif kind == WIND_CONSTANT:
        ax, ox, phx, cx = 0.0, 0.0, 0.0, row[w]
        ay, oy, phy, cy = 0.0, 0.0, 0.0, row[w + 1]
    else:
        ax, ox, phx, cx, ay, oy, phy, cy = 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    wind = (kind, ax, ox, phx, cx, ay, oy, phy, cy)
    p = ROW_PARAMS_START
    dyn = (row[p], row[p + 1], row[p + 2], row[p + 3], row[p + 4], row[p + 5], row[p + 6], row[p + 7], row[p + 8], row[p + 9], row[p + 10], row[ROW_D_U])
    noise_std = (row[s], row[s + 1], row[s + 2], row[s + 3], row[s + 4], row[s + 5])
    return dyn, noise_std, int(row[ROW_SUBSTEPS]), row[ROW_DT], wind


@nb.njit(cache=True)
def unpack_sensor(row):
    """The sensor model of an MDP row: (velocity, position, rate, attitude std, AR(1) coefficient, delay, dropout), and whether it senses at all."""
    s = ROW_SENSOR_START
    delay = min(max(row[s + 5], 0.0), float(MAX_SENSOR_DELAY))  # clamped: the buffer's size
    sensor = (row[s], row[s + 1], row[s + 2], row[s + 3], row[s + 4], delay, row[s + 6])
    on = row[s] != 0.0 or row[s + 1] != 0.0 or row[s + 2] != 0.0 or row[s + 3] != 0.0 or row[s + 5] != 0.0 or row[s + 6] != 0.0
    return sensor, on


@nb.njit(cache=True, fastmath={"contract"})  # not inlined: it runs only for rows with a sensor model, and compiles once
def sense(o, k, sensor, srng, scratch):
    """What the sensors report at reading ``k`` (0: the reset) of true observation ``o``.

    The reading is ``o`` plus noise e, e_0 = std z and e_k = rho e_(k-1) + sqrt(1 - rho^2) std z
    (stationary std per entry group, 12 normals from the sensor stream ``srng`` per reading),
    delivered ``delay`` readings late (the first reading until then). With a dropout p a 13th normal
    z' per reading loses it when Phi(z') < p (never the reset's): the reading delivered last is held.
    ``scratch`` (SENSOR_SCRATCH floats) holds e, the reading held and the ring buffer of the last delay + 1 readings.
    """
    s_v, s_p, s_r, s_a, rho, d, dropout = sensor
    delay = int(d)
    gain = math.sqrt(1.0 - rho * rho)
    put = 24 + (k % (delay + 1)) * 12
    for i in range(12):
        std = s_v if i < 3 else (s_p if i < 6 else (s_r if i < 9 else s_a))
        z = next_normal(srng)
        e = std * z if k == 0 else rho * scratch[i] + gain * (std * z)
        scratch[i] = e
        scratch[put + i] = o[i] + e
    b = 24 + (max(k - delay, 0) % (delay + 1)) * 12
    if dropout > 0.0:
        lost = 0.5 * math.erfc(-next_normal(srng) * SQRT_HALF) < dropout and k > 0
        if lost:
            b = 12  # the reading held
        else:
            for i in range(12):
                scratch[12 + i] = scratch[b + i]
    return (
        scratch[b], scratch[b + 1], scratch[b + 2], scratch[b + 3], scratch[b + 4], scratch[b + 5],
        scratch[b + 6], scratch[b + 7], scratch[b + 8], scratch[b + 9], scratch[b + 10], scratch[b + 11],
    )  # fmt: skip


@nb.njit(cache=True, inline="always", fastmath={"contract"})
def update_noise(n, std, z0, z1, z2, z3, z4, z5):
    """AR(1) gust noise update, once per control step, fed six standard normals."""
    return (
        NOISE_DECAY * n[0] + NOISE_GAIN * z0 * std[0],
        NOISE_DECAY * n[1] + NOISE_GAIN * z1 * std[1],
        NOISE_DECAY * n[2] + NOISE_GAIN * z2 * std[2],
        NOISE_DECAY * n[3] + NOISE_GAIN * z3 * std[3],
        NOISE_DECAY * n[4] + NOISE_GAIN * z4 * std[4],
        NOISE_DECAY * n[5] + NOISE_GAIN * z5 * std[5],
    )


@nb.njit(cache=True, fastmath={"contract"})
def integrate(s, n, a1, a2, a3, a4, step, dyn, n_sub, dt, wind):
    """Advance state tuple ``s`` through the substeps of control step ``step`` (counting from 0)."""
    c_u, c_v, d_v, c_w, d_w, c_p, d_p, c_q, d_q, c_r, d_r, d_u = dyn
    kind = wind[0]
    vu, vv, vw, px, py, pz, p, q, r, qx, qy, qz, qw = s
    # Action and noise terms are constant over the control step.
    bias_v = d_v + n[1]
    bias_w = d_w * a4 + n[2]
    drive_p = d_p * a1 + n[3]
    drive_q = d_q * a2 + n[4]
    drive_r = d_r * a3 + n[5]
    nu = d_u + n[0]
    for i in range(n_sub):
        px += dt * vu
        py += dt * vv
        pz += dt * vw
        r00, r01, r02, r10, r11, r12, r20, r21, r22 = rotation_matrix(qx, qy, qz, qw)
        bu = r00 * vu + r10 * vv + r20 * vw
        bv = r01 * vu + r11 * vv + r21 * vw
        bw = r02 * vu + r12 * vv + r22 * vw
        if kind != 0:
            wu, wv = wind_at(wind, step, i)
            # The world wind has no vertical component.
            fu = c_u * (bu + (r00 * wu + r10 * wv)) + nu
            fv = c_v * (bv + (r01 * wu + r11 * wv)) + bias_v
        else:
            fu = c_u * bu + nu
            fv = c_v * bv + bias_v
        fw = c_w * bw + bias_w
        vu += dt * (r00 * fu + r01 * fv + r02 * fw)
        vv += dt * (r10 * fu + r11 * fv + r12 * fw)
        vw += dt * (r20 * fu + r21 * fv + r22 * fw + GRAVITY)
        hx, hy, hz, hw = _half_angle_quaternion(dt * p, dt * q, dt * r)
        nqw = qw * hw - qx * hx - qy * hy - qz * hz
        nqx = qw * hx + qx * hw + qy * hz - qz * hy
        nqy = qw * hy - qx * hz + qy * hw + qz * hx
        nqz = qw * hz + qx * hy - qy * hx + qz * hw
        qx, qy, qz, qw = nqx, nqy, nqz, nqw
        p += dt * (c_p * p + drive_p)
        q += dt * (c_q * q + drive_q)
        r += dt * (c_r * r + drive_r)
    return (vu, vv, vw, px, py, pz, p, q, r, qx, qy, qz, qw)


@nb.njit(cache=True, inline="always")
def _record(obs_out, act_out, slot, k, o, a1, a2, a3, a4):
    """Flight data of control step k: the observation the policy saw and the action applied."""
    for i in range(12):
        obs_out[slot, k, i] = o[i]
    act_out[slot, k, 0] = a1
    act_out[slot, k, 1] = a2
    act_out[slot, k, 2] = a3
    act_out[slot, k, 3] = a4


# Not inline="always": numba's parfor pass drops writes through a tuple's arrays in a prange body it inlines
# (numba 0.68); called, the body stays opaque to it (LLVM may still inline it: same arithmetic, same bits).
@nb.njit(cache=True, fastmath={"contract"})
def fly_job(j, rng, srng, scratch, jobs, extras, out):
    """Fly job ``j`` of :func:`rollout_batch` with ``rng`` (4 uint64) as its gust stream's state.

    The whole episode of one job, shared by the CPU kernel (one prange iteration) and the CUDA
    kernel (one thread, :mod:`neurohover.sim.cuda`), so both targets compile this source. ``srng``
    (4 uint64) and ``scratch`` (SENSOR_SCRATCH floats) serve the sensor model when the row has one:
    the policy, the safeguard and the recording see ``seen``; reward and crash test the true state.
    """
    policy_kinds, genomes, n_steps, limits = jobs.kinds, jobs.genomes, jobs.n_steps, extras.limits
    obs_out, act_out = extras.obs_out, extras.act_out
    row = jobs.rows[jobs.mdp[j]]
    seed_stream(rng, np.uint64(jobs.seed), np.uint64(jobs.episode[j]))
    dyn, std, n_sub, dt, wind = unpack_mdp(row)
    sensor, sensing = unpack_sensor(row)
    if sensing:
        seed_sensor_stream(srng, np.uint64(jobs.seed), np.uint64(jobs.episode[j]))
    pol = jobs.policy[j]
    kind = policy_kinds[pol]
    g = genomes[pol]
    fb = extras.fallback[j]
    slot = extras.slots[j]
    safeguard = extras.safeguard
    s = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0)
    n = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    o = observe(s)
    seen = sense(o, 0, sensor, srng, scratch) if sensing else o
    total = 0.0
    crash = False
    sg_step = -1
    t = 0
    for k in range(n_steps):
        if safeguard and fb >= 0 and sg_step < 0 and k >= limits[SAFEGUARD_ARM] and dangerous(seen, limits):
            sg_step = k
            kind = policy_kinds[fb]
            g = genomes[fb]
        a1, a2, a3, a4 = policy_action(kind, g, seen[0], seen[1], seen[2], seen[3], seen[4], seen[5], seen[9], seen[10], seen[11])
        t = k + 1
        if not (math.isfinite(a1) and math.isfinite(a2) and math.isfinite(a3) and math.isfinite(a4)):
            if slot >= 0:
                _record(obs_out, act_out, slot, k, seen, a1, a2, a3, a4)
            crash = True
            total += crash_charge(n_steps, t)
            break
        a1 = clip_action(a1)
        a2 = clip_action(a2)
        a3 = clip_action(a3)
        a4 = clip_action(a4)
        if slot >= 0:
            _record(obs_out, act_out, slot, k, seen, a1, a2, a3, a4)
        n = update_noise(n, std, next_normal(rng), next_normal(rng), next_normal(rng), next_normal(rng), next_normal(rng), next_normal(rng))
        s = integrate(s, n, a1, a2, a3, a4, k, dyn, n_sub, dt, wind)
        o = observe(s)
        if sensing:
            seen = sense(o, t, sensor, srng, scratch)
        else:
            seen = o
        reward, crash = step_outcome(s, o, n_steps, t)
        total += reward
        if crash:
            break
    if slot >= 0:
        for i in range(12):
            obs_out[slot, t, i] = seen[i]
    out.returns[j] = total
    out.crashed[j] = crash
    out.steps[j] = t
    out.safeguard_step[j] = sg_step


@nb.njit(cache=True, parallel=True, fastmath={"contract"})
def rollout_batch(jobs, extras, out):
    """Fly every job (policy, MDP, episode) and write its return, crash flag, steps and safeguard step.

    ``jobs``, ``extras`` and ``out``: a :class:`~neurohover.sim.jobs.Jobs`, :class:`~neurohover.sim.jobs.Extras`
    and :class:`~neurohover.sim.jobs.Flown`. Jobs run in parallel; each draws noise from its own
    (seed, episode) stream, so results do not depend on the thread count. ``extras.slots[j] >= 0``
    records job j's flight data there; ``extras.fallback[j] >= 0`` with ``extras.safeguard`` hands
    control to that policy once the state is dangerous. A non-finite action counts as a crash at that step.
    """
    n_jobs = jobs.policy.shape[0]
    for j in nb.prange(n_jobs):
        rng = np.empty(4, dtype=np.uint64)
        srng = np.empty(4, dtype=np.uint64)
        scratch = np.empty(SENSOR_SCRATCH)
        # int64: the parfor body's index is uint64, its typing pass's int64, and each type compiled fly_job once more
        fly_job(np.int64(j), rng, srng, scratch, jobs, extras, out)
