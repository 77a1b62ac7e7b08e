"""Several episodes per thread in SIMD lanes: the kernel's rollout without recording or safeguard.

Rows with a sensor model fly here too: each lane's readings come from ``kernel.sense``, scalar per
lane, and its policy reads them instead of the packed observation.

:func:`rollout_lanes` flies the jobs of :func:`neurohover.sim.kernel.rollout_batch` when none
records flight data or has a safeguard and their MDP rows share the substep count and whether
there is wind, LANES episodes per thread in lockstep, each lane with its own job's genome and MDP
row, and writes bit-identical returns, crash flags and steps (about 2.2x the scalar kernel's
episodes/s per core, docs/performance.md). :func:`neurohover.launch.launch` chooses it for such batches of at least LANES jobs
(:func:`neurohover.evaluate.evaluate_jobs` and the evolution's :class:`neurohover.flyer.KernelFlyer`
fly through it).
:func:`rollout_lanes_parked` is the same with optional jobs and parking: a selection race's later
samples fill the lanes its round leaves idle, and an episode in flight when the round's samples are
over is kept and resumed by a later call (docs/performance.md, Selection races).

How it works
- Lanes in lockstep over control steps, one episode per lane, and a queue: a lane whose episode ends
  takes the next one, so lanes run at different steps. An idle lane flies at rest.
- The substeps, then the observation, reward and crash test, run packed for all lanes at once
  (:mod:`neurohover.sim.packed`, which says how they stay bit-identical to the scalar kernel); a
  control step in which some lane turns more than SERIES_MAX_ANGLE is flown again for every lane,
  from the saved start, with ``kernel.integrate`` itself (libm sin/cos). The tail of a queue, where
  at most ``SCALAR_TAIL`` lanes are left in flight, runs that way too (cheaper than a packed step).
- Still scalar per lane: the policy (``exp`` has no bit-identical packed form), the xoshiro256** /
  ziggurat gust noise, the wind's sin, and the bookkeeping.

Measurements (lane counts, per-substep cost, speed-ups): docs/performance.md.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np
from numba.core import cgutils, types
from numba.extending import intrinsic

from .constants import ROW_SUBSTEPS, ROW_WIND_KIND, SENSOR_SCRATCH
from .jobs import PARK_F, PARK_U, Parking
from .kernel import (
    clip_action,
    crash_charge,
    integrate,
    observe,
    policy_action,
    sense,
    unpack_mdp,
    unpack_sensor,
    update_noise,
    wind_at,
)
from .packed import LANES, N_PAR, ROW_CRASH, ROW_DYN, ROW_OBS, ROW_REWARD, ROWS, observe_lanes, or_python, substeps
from .rng import next_normal, seed_sensor_stream, seed_stream

#: At most this many lanes in flight (the queue empty), a control step's substeps run per lane with ``kernel.integrate``
#: (the same bits): one packed step costs about as much as 2-3 scalar ones (docs/performance.md, Selection races).
SCALAR_TAIL = 2

__all__ = ["LANES", "SCALAR_TAIL", "PARK_F", "PARK_U", "fly_lanes", "fly_queue", "fly_shared", "park_lane", "rollout_lanes", "rollout_lanes_parked"]


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


def _python_fetch_add(counter, delta):
    """``_fetch_add`` where numba leaves the kernels as Python (``NUMBA_DISABLE_JIT=1``): its prange loops run serially
    there, so a plain read, add and write is the atomic add (an intrinsic has no pure-Python form; T46-A03)."""
    before = counter[0]
    counter[0] = before + delta
    return before


def _python_fence() -> None:
    """``_fence`` where numba leaves the kernels as Python: one thread, nothing to order."""


@or_python(_python_fetch_add)
@intrinsic
def _fetch_add(typingctx, counter, delta):
    """Atomically add ``delta`` to ``counter[0]`` (an int64 array) and return its value before: a queue
    that several threads take jobs from, one index each."""
    sig = types.int64(counter, types.int64)

    def codegen(context, builder, signature, args):
        ary = context.make_array(signature.args[0])(context, builder, args[0])
        ptr = cgutils.get_item_pointer(context, builder, signature.args[0], ary, [context.get_constant(types.intp, 0)])
        return builder.atomic_rmw("add", ptr, args[1], "seq_cst")

    return sig, codegen


@or_python(_python_fence)
@intrinsic
def _fence(typingctx):
    """A sequentially consistent fence: the loads after it are not hoisted above it (another thread's counts)."""
    sig = types.void()

    def codegen(context, builder, signature, args):
        builder.fence("seq_cst")

    return sig, codegen


@nb.njit(cache=True)
def _take(counter) -> int:
    """The next job index of a shared queue (one per call, every thread taking from it)."""
    return _fetch_add(counter, 1)  # an intrinsic: numba supplies typingctx


@nb.njit(cache=True)
def _required_over(left) -> bool:
    """Whether a call's required jobs are all over (``left[0]``: those not over, counted down by every thread)."""
    _fence()  # an intrinsic: numba supplies typingctx
    return left[0] == 0


@nb.njit(cache=True, fastmath={"contract"})
def park_lane(B, N, rngs, seen, srngs, scratch, step, total, sensing, lane, slot, parking) -> None:
    """Keep a lane's episode, between two control steps, in ``slot`` of ``parking``: everything its
    next step reads (the drive terms, wind and packed rows are rewritten each step; P from the row)."""
    park_f, park_u = parking.floats, parking.streams
    for m in range(13):
        park_f[slot, m] = B[m * LANES + lane]
    for m in range(12):
        park_f[slot, 13 + m] = B[(ROW_OBS + m) * LANES + lane]
    for m in range(6):
        park_f[slot, 25 + m] = N[m, lane]
    park_f[slot, 31] = total[lane]
    for m in range(4):
        park_u[slot, m] = rngs[lane, m]
    if sensing[lane]:
        for m in range(12):
            park_f[slot, 32 + m] = seen[lane, m]
        for m in range(SENSOR_SCRATCH):
            park_f[slot, 44 + m] = scratch[lane, m]
        for m in range(4):
            park_u[slot, 4 + m] = srngs[lane, m]
    parking.steps[slot] = step[lane]


@nb.njit(cache=True, fastmath={"contract"})
def _begin(B, P, N, rngs, seen, srngs, scratch, step, total, lane, row, seed, episode, job_slot, q, parking) -> bool:
    """Start job ``q``'s episode in a lane at rest: from its first step, or where it was parked. Returns whether it senses."""
    _start_lane(B, P, lane, row)
    park_f, park_u, park_step = parking
    s = job_slot[q] if park_step.shape[0] > 0 else -1
    if s < 0 or park_step[s] == 0:
        seed_stream(rngs[lane], np.uint64(seed), np.uint64(episode))
        step[lane] = 0
        total[lane] = 0.0
        return _start_sensing(seen, srngs, scratch, lane, row, seed, episode)
    for m in range(13):
        B[m * LANES + lane] = park_f[s, m]
    for m in range(12):
        B[(ROW_OBS + m) * LANES + lane] = park_f[s, 13 + m]
    for m in range(6):
        N[m, lane] = park_f[s, 25 + m]
    total[lane] = park_f[s, 31]
    step[lane] = park_step[s]
    for m in range(4):
        rngs[lane, m] = park_u[s, m]
    _, on = unpack_sensor(row)
    if on:
        for m in range(12):
            seen[lane, m] = park_f[s, 32 + m]
        for m in range(SENSOR_SCRATCH):
            scratch[lane, m] = park_f[s, 44 + m]
        for m in range(4):
            srngs[lane, m] = park_u[s, 4 + m]
    return on


@nb.njit(cache=True, inline="always")
def _lane_buffers(n_sub):
    """A thread's lanes: the packed state B (and B0, a control step's start), per-lane MDP parameters P, gust
    noise N, actions A, substep winds W, gust streams; the sensor model's readings, streams, state and flags;
    each lane's job (-1: idle), step and return so far."""
    return (
        np.zeros(ROWS * LANES),
        np.zeros(13 * LANES),
        np.zeros((LANES, N_PAR)),
        np.zeros((6, LANES)),
        np.zeros((4, LANES)),
        np.zeros((2, n_sub, LANES)),
        np.empty((LANES, 4), dtype=np.uint64),
        np.zeros((LANES, 12)),
        np.empty((LANES, 4), dtype=np.uint64),
        np.empty((LANES, SENSOR_SCRATCH)),
        np.zeros(LANES, dtype=np.bool_),
        np.full(LANES, -1, dtype=np.int64),
        np.zeros(LANES, dtype=np.int64),
        np.zeros(LANES),
    )


@nb.njit(cache=True, fastmath={"contract"}, inline="always")
def _refill(B, P, N, A, rngs, seen, srngs, scratch, sensing, job, step, total, lane, nxt, queue, jobs, job_slot, parking):
    """Lane ``lane`` reset and given the queue's next job while one is left (else idle: job -1); the last job index
    this thread took."""
    _reset_lane(B, N, A, lane)
    total[lane] = 0.0
    step[lane] = 0
    n_jobs = jobs.episode.shape[0]
    if nxt < n_jobs:
        nxt = _take(queue)
    if nxt < n_jobs:
        job[lane] = nxt
        sensing[lane] = _begin(
            B, P, N, rngs, seen, srngs, scratch, step, total, lane, jobs.rows[jobs.mdp[nxt]], jobs.seed, jobs.episode[nxt], job_slot, nxt, parking
        )  # fmt: skip
    else:
        job[lane] = -1
    return nxt


@nb.njit(cache=True, fastmath={"contract"}, inline="always")
def _integrate_each(B, N, A, job, step, mdp_rows, job_mdp) -> None:
    """A control step's substeps per lane with ``kernel.integrate`` (libm sin/cos): the large-angle fallback and
    the queue's tail. Idle lanes stay at rest."""
    for lane in range(LANES):
        if job[lane] < 0:
            continue
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


@nb.njit(cache=True)
def _over(j, n_required, left, parking, job_slot):
    """Job ``j``'s episode is over in a parking call: one required job fewer to wait for, and its slot begins afresh."""
    if j < n_required:
        _fetch_add(left, -1)
    parking.steps[job_slot[j]] = 0


@nb.njit(cache=True)
def _end_job(out, j, ret, crashed, steps, parks, n_required, left, parking, job_slot) -> None:
    """Job ``j``'s episode is over (once per episode, so not inlined): its return, crash flag and steps written."""
    out.returns[j] = ret
    out.crashed[j] = crashed
    out.steps[j] = steps
    if parks:
        _over(j, n_required, left, parking, job_slot)


@nb.njit(cache=True, fastmath={"contract"})
def _fill_lanes(B, P, N, A, rngs, seen, srngs, scratch, sensing, job, step, total, queue, jobs, job_slot, parking):
    """Every lane given a job while the queue has one: the last job index this thread took and the lanes in flight."""
    nxt = -1
    live = 0
    for lane in range(LANES):
        nxt = _refill(B, P, N, A, rngs, seen, srngs, scratch, sensing, job, step, total, lane, nxt, queue, jobs, job_slot, parking)
        if job[lane] >= 0:
            live += 1
    return nxt, live


@nb.njit(cache=True, fastmath={"contract"})
def _park_lanes(B, N, rngs, seen, srngs, scratch, step, total, sensing, job, job_slot, parking) -> None:
    """Every episode in flight parked (the call's required jobs are over)."""
    for lane in range(LANES):
        if job[lane] >= 0:
            park_lane(B, N, rngs, seen, srngs, scratch, step, total, sensing, lane, job_slot[job[lane]], parking)


@nb.njit(cache=True, fastmath={"contract"})
def fly_queue(jobs, out, stats, n_required, job_slot, parking, left, queue):
    """Fly the :class:`~neurohover.sim.jobs.Jobs` ``jobs``, LANES at a time; write each job's return,
    crash flag and steps into the :class:`~neurohover.sim.jobs.Flown` ``out`` (as kernel.fly_job: no
    recording, no safeguard). Every job's MDP row must have the substep count and the wind
    presence (kind 0 or not) of the first job's row.

    A lane whose episode ends takes the next job, so lanes run at different steps, each with its own
    genome and its own MDP's parameters. The jobs are taken in order from ``queue[0]`` (the next
    index), which every thread of a call shares: a thread whose jobs end early takes more, and none
    idles while a job is left (results do not depend on which thread flies a job).
    stats[0] counts control steps, stats[1] those flown again by the large-angle fallback. Once the queue is
    empty and at most SCALAR_TAIL lanes fly, their substeps run per lane with ``kernel.integrate``.

    Parking (``parking`` has slots): jobs ``n_required`` and later are optional. Job j's episode
    is kept in slot ``job_slot[j]`` of ``parking`` (:func:`park_lane`): one
    whose ``parking.steps`` is above 0 resumes there. ``left[0]`` counts the call's required jobs not
    yet over (every thread counts it down); once it is 0, the episodes still in flight are parked and
    the call returns (an optional job not over keeps ``out_steps`` 0).
    """
    mdp_rows, job_mdp, n_steps = jobs.rows, jobs.mdp, jobs.n_steps
    n_jobs = jobs.episode.shape[0]
    if n_jobs == 0:
        return
    n_sub = int(mdp_rows[job_mdp[0], ROW_SUBSTEPS])
    has_wind = int(mdp_rows[job_mdp[0], ROW_WIND_KIND]) != 0
    B, B0, P, N, A, W, rngs, seen, srngs, scratch, sensing, job, step, total = _lane_buffers(n_sub)
    nxt, live = _fill_lanes(B, P, N, A, rngs, seen, srngs, scratch, sensing, job, step, total, queue, jobs, job_slot, parking)
    parks = parking.steps.shape[0] > 0
    while live > 0:
        # (a thread whose last job was required below the last one holds required jobs only: it flies on)
        if parks and nxt >= n_required - 1 and _required_over(left):
            _park_lanes(B, N, rngs, seen, srngs, scratch, step, total, sensing, job, job_slot, parking)
            break
        # Control-step part, scalar per lane: policy, clipping, gust noise, drive terms, wind.
        for lane in range(LANES):
            if job[lane] < 0:
                continue
            k = step[lane]
            if sensing[lane]:
                o0, o1, o2, o3, o4, o5 = seen[lane, 0], seen[lane, 1], seen[lane, 2], seen[lane, 3], seen[lane, 4], seen[lane, 5]
                o9, o10, o11 = seen[lane, 9], seen[lane, 10], seen[lane, 11]
            else:
                o0, o1, o2 = B[(ROW_OBS + 0) * LANES + lane], B[(ROW_OBS + 1) * LANES + lane], B[(ROW_OBS + 2) * LANES + lane]
                o3, o4, o5 = B[(ROW_OBS + 3) * LANES + lane], B[(ROW_OBS + 4) * LANES + lane], B[(ROW_OBS + 5) * LANES + lane]
                o9, o10, o11 = B[(ROW_OBS + 9) * LANES + lane], B[(ROW_OBS + 10) * LANES + lane], B[(ROW_OBS + 11) * LANES + lane]
            pol = jobs.policy[job[lane]]
            a1, a2, a3, a4 = policy_action(jobs.kinds[pol], jobs.genomes[pol], o0, o1, o2, o3, o4, o5, o9, o10, o11)
            if not (math.isfinite(a1) and math.isfinite(a2) and math.isfinite(a3) and math.isfinite(a4)):
                _end_job(out, job[lane], total[lane] + crash_charge(n_steps, k + 1), True, k + 1, parks, n_required, left, parking, job_slot)
                job[lane] = -2  # over; the lane idles through this step (at rest, dt 0) and is refilled after it
                _reset_lane(B, N, A, lane)
                continue
            a1, a2, a3, a4 = clip_action(a1), clip_action(a2), clip_action(a3), clip_action(a4)
            rng = rngs[lane]
            std = (P[lane, 0], P[lane, 1], P[lane, 2], P[lane, 3], P[lane, 4], P[lane, 5])
            n = (N[0, lane], N[1, lane], N[2, lane], N[3, lane], N[4, lane], N[5, lane])
            n = update_noise(n, std, next_normal(rng), next_normal(rng), next_normal(rng), next_normal(rng), next_normal(rng), next_normal(rng))
            for m in range(6):
                N[m, lane] = n[m]
            A[0, lane], A[1, lane], A[2, lane], A[3, lane] = a1, a2, a3, a4
            B[13 * LANES + lane], B[14 * LANES + lane] = P[lane, 6] + n[0], P[lane, 7] + n[1]
            B[15 * LANES + lane], B[16 * LANES + lane] = P[lane, 8] * a4 + n[2], P[lane, 9] * a1 + n[3]
            B[17 * LANES + lane], B[18 * LANES + lane] = P[lane, 10] * a2 + n[4], P[lane, 11] * a3 + n[5]
            if has_wind:
                wind = (int(P[lane, 12]), P[lane, 13], P[lane, 14], P[lane, 15], P[lane, 16], P[lane, 17], P[lane, 18], P[lane, 19], P[lane, 20])
                for i in range(n_sub):
                    W[0, i, lane], W[1, i, lane] = wind_at(wind, k, i)
        stats[0] += 1
        packed = live > SCALAR_TAIL
        if packed:
            for i in range(13 * LANES):  # a loop, not B0[:] = B[...]: numba's slice copy compiles a formatted error message (seconds)
                B0[i] = B[i]
        if not (packed and substeps(B, W, n_sub, has_wind)):
            if packed:
                stats[1] += 1
                for i in range(13 * LANES):
                    B[i] = B0[i]
            _integrate_each(B, N, A, job, step, mdp_rows, job_mdp)
        observe_lanes(B)
        # Bookkeeping, scalar per lane: return, end of episode, refill.
        for lane in range(LANES):
            j = job[lane]
            if j == -1:
                continue
            if j >= 0:
                t = step[lane] + 1
                step[lane] = t
                if B[ROW_CRASH * LANES + lane] != 0.0:
                    _end_job(out, j, total[lane] + crash_charge(n_steps, t), True, t, parks, n_required, left, parking, job_slot)
                elif t == n_steps:
                    _end_job(out, j, total[lane] + B[ROW_REWARD * LANES + lane], False, t, parks, n_required, left, parking, job_slot)
                else:
                    total[lane] += B[ROW_REWARD * LANES + lane]
                    if sensing[lane]:
                        _read(B, seen, srngs, scratch, lane, t, mdp_rows[job_mdp[j]])
                    continue
            nxt = _refill(B, P, N, A, rngs, seen, srngs, scratch, sensing, job, step, total, lane, nxt, queue, jobs, job_slot, parking)
            if job[lane] < 0:
                live -= 1


@nb.njit(cache=True, fastmath={"contract"})
def fly_lanes(jobs, out, stats):
    """:func:`fly_queue` without parking: every job is flown to its end."""
    queue = np.zeros(1, dtype=np.int64)
    fly_shared(jobs, out, stats, queue)


@nb.njit(cache=True, fastmath={"contract"})
def fly_shared(jobs, out, stats, queue):
    """:func:`fly_lanes` taking its jobs from ``queue`` (shared with the call's other threads)."""
    none = np.zeros(0, dtype=np.int64)
    nowhere = Parking(np.zeros((0, PARK_F)), np.zeros((0, PARK_U), dtype=np.uint64), none)
    fly_queue(jobs, out, stats, jobs.episode.shape[0], none, nowhere, np.zeros(1, dtype=np.int64), queue)


@nb.njit(cache=True, parallel=True, fastmath={"contract"})
def rollout_lanes(jobs, n_threads, out):
    """Fly the :class:`~neurohover.sim.jobs.Jobs` ``jobs``, LANES per thread, in parallel, into ``out``
    (a :class:`~neurohover.sim.jobs.Flown`).

    The outputs are those of :func:`neurohover.sim.kernel.rollout_batch` for the same jobs with no
    recording and no safeguard, bit for bit. Each lane flies its own job's genome and MDP row;
    all rows used must share the substep count (row[ROW_SUBSTEPS]) and whether there is wind (row[ROW_WIND_KIND] != 0),
    which the packed substep loop takes as constants (ValueError otherwise). ``n_threads``: threads
    to split the jobs over (``numba.get_num_threads()``; a parameter because reading it in compiled
    code would keep this function out of the on-disk cache).
    """
    mdp_rows, job_mdp = jobs.rows, jobs.mdp
    n_jobs = jobs.episode.shape[0]
    if n_jobs > 0:
        n_sub = mdp_rows[job_mdp[0], ROW_SUBSTEPS]
        windy = mdp_rows[job_mdp[0], ROW_WIND_KIND] != 0.0
        for j in range(n_jobs):
            if mdp_rows[job_mdp[j], ROW_SUBSTEPS] != n_sub or (mdp_rows[job_mdp[j], ROW_WIND_KIND] != 0.0) != windy:
                raise ValueError("rollout_lanes: the jobs' MDP rows differ in substep count or wind presence")
    # One lane set per thread, all taking jobs from one shared queue (a thread whose episodes end early
    # takes more); no thread with fewer than LANES jobs on average unless the batch is, so lanes stay full.
    n_chunks = max(1, min(n_threads, n_jobs // LANES))
    queue = np.zeros(1, dtype=np.int64)
    for _ in nb.prange(n_chunks):  # one lane set per thread
        stats = np.zeros(2, dtype=np.int64)
        fly_shared(jobs, out, stats, queue)
    for j in range(n_jobs):
        out.safeguard_step[j] = -1


@nb.njit(cache=True, parallel=True, fastmath={"contract"})
def rollout_lanes_parked(jobs, job_slot, n_required, n_threads, parking, out):
    """:func:`rollout_lanes` with optional jobs and parking: fly jobs ``0 .. n_required - 1`` to their end,
    and jobs ``n_required ..`` only in lanes the required ones leave idle.

    The call returns once every required job is over; an optional episode then in flight is parked in
    its slot ``job_slot[j]`` of ``parking`` (a :class:`~neurohover.sim.jobs.Parking`: ``steps`` its
    steps flown, 0 for an episode not begun), and a later call that lists
    the same slot resumes it there, so an episode's return is the same bits however many calls it
    took. Every thread takes jobs in order from one shared queue, required ones first: a thread with
    no required job left flies optional ones until every required one is over. ``out.steps[j]`` is 0 for an
    optional job not over (parked, or not begun); otherwise the outputs are :func:`rollout_lanes`'s
    (``out.safeguard_step`` is not written).
    The rows must be alike in substeps and wind, as there (not checked here: one race's rows are).
    """
    n_jobs = jobs.episode.shape[0]
    for j in range(n_jobs):
        out.steps[j] = 0
    # Every thread takes a lane set even for fewer than 2 * LANES jobs (unlike rollout_lanes): a race's last
    # rounds list a few required jobs, and two threads with half-full lanes end them sooner than one thread.
    n_chunks = max(1, min(n_threads, n_jobs))
    left = np.full(1, n_required, dtype=np.int64)  # set before any thread starts
    queue = np.zeros(1, dtype=np.int64)
    for _ in nb.prange(n_chunks):  # one lane set per thread
        stats = np.zeros(2, dtype=np.int64)
        fly_queue(jobs, out, stats, n_required, job_slot, parking, left, queue)
