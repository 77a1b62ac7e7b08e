"""Per-episode random streams for the compiled kernel.

Each episode draws its gust noise from its own xoshiro256** stream whose 256-bit state is
derived from ``(seed, episode index)`` by SplitMix64. A result therefore never depends on
batch size, batch order or thread count. Standard normal variates come from a 256-layer
ziggurat (Marsaglia & Tsang 2000, in Doornik's 2005 form), which is several times cheaper
than Box-Muller; the gust noise needs 6 draws per control step, 36,000 per episode.
"""

from __future__ import annotations

import functools
import math

import numba as nb
import numpy as np

from ..errors import NeurohoverError, brief, whole_in, whole_number

_U64 = np.uint64
_GOLDEN = _U64(0x9E3779B97F4A7C15)
_MIX1 = _U64(0xBF58476D1CE4E5B9)
_MIX2 = _U64(0x94D049BB133111EB)
_EPISODE_KEY = _U64(0xD1B54A32D192ED03)  # odd constant that separates episode indices from seeds
SENSOR_STREAM_KEY = _U64(0x2545F4914F6CDD1D)  # xored into the seed: an episode's sensor noise has a stream of its own
_TWO_POW_M53 = 1.0 / 9007199254740992.0
#: The largest root seed of the streams (seeds are integers in ``0..MAX_SEED``).
MAX_SEED = 2**63 - 1


def _wrapping(**options):
    """``nb.njit(**options)``; where numba leaves the function as Python (``NUMBA_DISABLE_JIT=1``), the function under
    ``np.errstate(over="ignore")``: its uint64 sums and products wrap on purpose, as they do silently in compiled code, and
    NumPy's scalars warned "overflow encountered" (a traceback under PYTHONWARNINGS=error; T31-A06)."""

    def decorate(fn):
        compiled = nb.njit(**options)(fn)
        if compiled is not fn:  # compiled: the machine code is unchanged
            return compiled

        @functools.wraps(fn)
        def wrapping(*args):
            with np.errstate(over="ignore"):
                return fn(*args)

        return wrapping

    return decorate


def check_seed(seed) -> int:
    """``seed`` as an int; NeurohoverError unless it is an integer in ``0..2**63-1`` (not a bool)."""
    return whole_in(seed, "seed", 0, MAX_SEED, "2**63-1")  # np.timedelta64(4) was taken as 4 (T17-1); 1.5 "out of range" (T22-14)


@_wrapping(cache=True, inline="always")
def splitmix64(x: np.uint64) -> np.uint64:
    """SplitMix64 finaliser of ``x + golden``: a 64-bit hash used to expand seeds."""
    z = x + _GOLDEN
    z = (z ^ (z >> _U64(30))) * _MIX1
    z = (z ^ (z >> _U64(27))) * _MIX2
    return z ^ (z >> _U64(31))


@nb.njit(cache=True, inline="always")
def _rotl(x: np.uint64, k: int) -> np.uint64:
    return (x << _U64(k)) | (x >> _U64(64 - k))


@_wrapping(cache=True)
def seed_stream(state: np.ndarray, seed: np.uint64, episode: np.uint64) -> None:
    """Fill ``state`` (4 uint64) with the xoshiro256** state of episode ``episode`` of ``seed``."""
    x = splitmix64(splitmix64(seed) ^ (episode * _EPISODE_KEY))
    for i in range(4):
        x = splitmix64(x)
        state[i] = x


@_wrapping(cache=True, inline="always")
def next_u64(state: np.ndarray) -> np.uint64:
    """Next 64 random bits of a xoshiro256** stream (Blackman & Vigna 2018)."""
    s0 = state[0]
    s1 = state[1]
    s2 = state[2]
    s3 = state[3]
    result = _rotl(s1 * _U64(5), 7) * _U64(9)
    t = s1 << _U64(17)
    s2 ^= s0
    s3 ^= s1
    s1 ^= s2
    s0 ^= s3
    s2 ^= t
    s3 = _rotl(s3, 45)
    state[0] = s0
    state[1] = s1
    state[2] = s2
    state[3] = s3
    return result


@nb.njit(cache=True, inline="always")
def next_uniform(state: np.ndarray) -> float:
    """Uniform double in [0, 1) with 53 random bits."""
    return float(next_u64(state) >> _U64(11)) * _TWO_POW_M53


def _ziggurat_tables(layers: int = 256) -> tuple[np.ndarray, np.ndarray]:
    """Layer edges x[0..layers] and densities f(x) of the normal ziggurat (Doornik's ZIGNOR)."""
    r = 3.6541528853610088  # rightmost edge for 256 layers
    v = 0.00492867323399  # area of each layer
    x = np.empty(layers + 1)
    f = lambda t: math.exp(-0.5 * t * t)  # noqa: E731
    x[0] = v / f(r)
    x[1] = r
    for i in range(2, layers):
        x[i] = math.sqrt(-2.0 * math.log(v / x[i - 1] + f(x[i - 1])))
    x[layers] = 0.0
    return x, np.exp(-0.5 * x * x)


ZIG_X, ZIG_F = _ziggurat_tables()
ZIG_R = 3.6541528853610088


@nb.njit(cache=True)
def _normal_slow(state: np.ndarray, i: int, u: float) -> float:
    """Rejection part of the ziggurat: the tail (layer 0) or a wedge; retries until accepted."""
    while True:
        if i == 0:
            # Marsaglia's tail method for |z| > R.
            while True:
                a = -math.log(1.0 - next_uniform(state)) / ZIG_R
                b = -math.log(1.0 - next_uniform(state))
                if b + b > a * a:
                    break
            return -(ZIG_R + a) if u < 0.0 else ZIG_R + a
        z = u * ZIG_X[i]
        if ZIG_F[i + 1] + next_uniform(state) * (ZIG_F[i] - ZIG_F[i + 1]) < math.exp(-0.5 * z * z):
            return z
        bits = next_u64(state)
        i = int(bits & np.uint64(0xFF))
        u = 2.0 * (float(bits >> np.uint64(11)) * _TWO_POW_M53) - 1.0
        if abs(u * ZIG_X[i]) < ZIG_X[i + 1]:
            return u * ZIG_X[i]


@nb.njit(cache=True, inline="always")
def next_normal(state: np.ndarray) -> float:
    """Standard normal variate: one 64-bit draw on the fast path (about 99% of calls)."""
    bits = next_u64(state)
    i = int(bits & np.uint64(0xFF))
    u = 2.0 * (float(bits >> np.uint64(11)) * _TWO_POW_M53) - 1.0
    z = u * ZIG_X[i]
    if abs(z) < ZIG_X[i + 1]:
        return z
    return _normal_slow(state, i, u)


#: The most rows of normals one call draws (the longest episode anything accepts, with its reset's reading).
MAX_COUNT = 10**7 + 1


def _check_stream(seed, episode, count, what: str) -> tuple[np.uint64, np.uint64, int]:
    """Refuse a seed, an episode index or a count the streams have no meaning for (a negative seed wrapped, 0.5 was numba's
    typing dump, 2**64 an OverflowError, a count -1 NumPy's negative dimensions; thirteenth trial, F6 and F7)."""
    for name, value, low, top in (("seed", seed, 0, MAX_SEED), ("episode", episode, 0, MAX_SEED), (what, count, 1, MAX_COUNT)):
        if not whole_number(value) or not low <= int(value) <= top:
            shown = "2**63-1" if top == MAX_SEED else f"{top:,}"
            raise NeurohoverError(f"{name}={brief(value)} is not allowed: give an integer in {low}..{shown}")
    return np.uint64(seed), np.uint64(episode), int(count)


def episode_normals(seed: int | np.uint64, episode: int | np.uint64, n_steps: int) -> np.ndarray:
    """The (n_steps, 6) standard normals that episode ``episode`` of ``seed`` feeds the gust noise (checked, then :func:`_episode_normals`)."""
    return _episode_normals(*_check_stream(seed, episode, n_steps, "n_steps"))


@nb.njit(cache=True)
def _episode_normals(seed: np.uint64, episode: np.uint64, n_steps: int) -> np.ndarray:
    """The (n_steps, 6) standard normals that episode ``episode`` of ``seed`` feeds the gust noise."""
    state = np.empty(4, dtype=np.uint64)
    seed_stream(state, seed, episode)
    out = np.empty((n_steps, 6))
    for k in range(n_steps):
        for j in range(6):
            out[k, j] = next_normal(state)
    return out


@nb.njit(cache=True)
def seed_sensor_stream(state: np.ndarray, seed: np.uint64, episode: np.uint64) -> None:
    """Fill ``state`` with episode ``episode``'s sensor-noise stream: the gust stream of seed ``seed ^ SENSOR_STREAM_KEY``."""
    seed_stream(state, np.uint64(seed) ^ SENSOR_STREAM_KEY, np.uint64(episode))


def sensor_normals(seed: int | np.uint64, episode: int | np.uint64, n_readings: int, per_reading: int = 12) -> np.ndarray:
    """The (n_readings, per_reading) standard normals that episode ``episode`` of ``seed`` feeds the sensor model
    (checked, then :func:`_sensor_normals`): ``per_reading`` 12, or 13 with a dropout."""
    checked = _check_stream(seed, episode, n_readings, "n_readings")
    if isinstance(per_reading, bool) or per_reading not in (12, 13):  # 0 gave rows of nothing (thirteenth trial, F7)
        raise NeurohoverError(f"per_reading={brief(per_reading)} is not allowed: give 12, or 13 where the sensor has a dropout")
    return _sensor_normals(*checked, int(per_reading))


@nb.njit(cache=True)
def _sensor_normals(seed: np.uint64, episode: np.uint64, n_readings: int, per_reading: int = 12) -> np.ndarray:
    """The (n_readings, per_reading) standard normals that episode ``episode`` of ``seed`` feeds the sensor model.

    One row per reading: the reset's, then one after every control step, from
    :func:`seed_sensor_stream`'s stream, so sensor noise never shifts the gusts: 12 for the noise,
    and a 13th (``per_reading=13``) that decides a dropout, where the sensor has one.
    """
    state = np.empty(4, dtype=np.uint64)
    seed_sensor_stream(state, seed, episode)
    out = np.empty((n_readings, per_reading))
    for k in range(n_readings):
        for j in range(per_reading):
            out[k, j] = next_normal(state)
    return out
