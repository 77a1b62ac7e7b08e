"""The Gymnasium environments' kernel: many helicopters advanced by one control step each.

:func:`step_batch` (CPU) and :mod:`.cuda`'s step kernel run :func:`step_one`, built from the
physics of :mod:`.kernel`, so an environment's episode is the episode :func:`.kernel.fly_job`
flies with the same (seed, episode) stream (tests/test_envs.py). A helicopter's state lives in
the caller's arrays; rows with a sensor model need the wider ones (:data:`ENV_NOISE_WIDTH`,
:data:`ENV_RNG_WIDTH`), and :func:`start_readings` gives a new episode's first reading.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from .constants import SENSOR_SCRATCH
from .kernel import clip_action, crash_charge, integrate, observe, sense, step_outcome, unpack_mdp, unpack_sensor, update_noise
from .rng import next_normal, seed_sensor_stream

ENV_NOISE_WIDTH = 6 + SENSOR_SCRATCH  # per-helicopter floats when it senses: gust noise, then the sensor's
ENV_RNG_WIDTH = 8  # and uint64 words: the gust stream, then the sensor stream


@nb.njit(cache=True, inline="always")
def _state(states, i):
    """Helicopter ``i``'s state row as the kernel's state tuple."""
    r = states[i]
    return (r[0], r[1], r[2], r[3], r[4], r[5], r[6], r[7], r[8], r[9], r[10], r[11], r[12])


@nb.njit(cache=True, inline="always")
def _sensor_of(row, noise, rngs):
    """The row's sensor model, and whether it senses here: the caller's arrays must have room for it (an env sizes them so)."""
    sensor, on = unpack_sensor(row)
    return sensor, on and noise.shape[1] >= ENV_NOISE_WIDTH and rngs.shape[1] >= ENV_RNG_WIDTH


@nb.njit(cache=True, inline="always", fastmath={"contract"})
def step_one(i, mdp_rows, env_mdp, states, noise, rngs, steps, actions, n_steps, obs_out, rew_out, crash_out):
    """Advance helicopter ``i`` of :func:`step_batch` by one control step (its arguments, plus ``i``).

    Shared by the CPU kernel (one loop iteration) and the CUDA kernel (one thread,
    :mod:`neurohover.sim.cuda`), so both targets compile this source.
    """
    k = steps[i]
    t = k + 1
    steps[i] = t
    sensor, sensing = _sensor_of(mdp_rows[env_mdp[i]], noise, rngs)
    a1, a2, a3, a4 = actions[i, 0], actions[i, 1], actions[i, 2], actions[i, 3]
    if not (math.isfinite(a1) and math.isfinite(a2) and math.isfinite(a3) and math.isfinite(a4)):
        o = observe(_state(states, i))
        if sensing:
            o = sense(o, t, sensor, rngs[i, 4:], noise[i, 6:])
        for m in range(12):
            obs_out[i, m] = o[m]
        rew_out[i] = crash_charge(n_steps, t)
        crash_out[i] = True
        return
    dyn, std, n_sub, dt, wind = unpack_mdp(mdp_rows[env_mdp[i]])
    rng = rngs[i]
    n = (noise[i, 0], noise[i, 1], noise[i, 2], noise[i, 3], noise[i, 4], noise[i, 5])
    n = update_noise(n, std, next_normal(rng), next_normal(rng), next_normal(rng), next_normal(rng), next_normal(rng), next_normal(rng))
    s = _state(states, i)
    s = integrate(s, n, clip_action(a1), clip_action(a2), clip_action(a3), clip_action(a4), k, dyn, n_sub, dt, wind)
    for m in range(13):
        states[i, m] = s[m]
    for m in range(6):
        noise[i, m] = n[m]
    o = observe(s)
    seen = sense(o, t, sensor, rngs[i, 4:], noise[i, 6:]) if sensing else o
    for m in range(12):
        obs_out[i, m] = seen[m]
    rew_out[i], crash_out[i] = step_outcome(s, o, n_steps, t)


@nb.njit(cache=True, fastmath={"contract"})
def step_batch(mdp_rows, env_mdp, states, noise, rngs, steps, actions, n_steps, obs_out, rew_out, crash_out):
    """Advance many helicopters by one control step each (the vector environment's kernel).

    ``states`` (N, 13), ``noise`` (N, 6), ``rngs`` (N, 4) and ``steps`` (N,) are updated in place.
    A non-finite action is a crash charged the full penalty. The body is :func:`step_one`. Rows
    with a sensor model need ``noise`` (N, ENV_NOISE_WIDTH) and ``rngs`` (N, ENV_RNG_WIDTH): the
    gust state, then the sensor's (:func:`start_readings` starts it); ``obs_out`` gets the readings.
    """
    for i in range(states.shape[0]):
        step_one(i, mdp_rows, env_mdp, states, noise, rngs, steps, actions, n_steps, obs_out, rew_out, crash_out)


@nb.njit(cache=True)
def start_readings(mdp_rows, env_mdp, idx, streams, rngs, noise, obs_out):
    """The first reading of each new episode ``idx`` of :func:`step_batch`: zeros, or the sensors' reading of them.

    ``streams`` (N, 2) holds each episode's (seed, episode); a sensing row's sensor stream is
    seeded from it (as :func:`fly_job` seeds it) into ``rngs[i, 4:]`` and its noise kept in ``noise[i, 6:]``.
    """
    zero = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    for i in idx:
        sensor, sensing = _sensor_of(mdp_rows[env_mdp[i]], noise, rngs)
        seen = zero
        if sensing:
            srng = rngs[i, 4:]
            seed_sensor_stream(srng, np.uint64(streams[i, 0]), np.uint64(streams[i, 1]))
            seen = sense(zero, 0, sensor, srng, noise[i, 6:])
        for m in range(12):
            obs_out[i, m] = seen[m]
