"""Known answers for the random streams: xoshiro256**, SplitMix64 and the ziggurat normal sampler.

The expected values are the published outputs of the reference C implementations (Blackman &
Vigna, prng.di.unimi.it) where they exist, and otherwise an independent plain-Python
implementation written here from the papers (Marsaglia & Tsang 2000; Doornik 2005).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import stats

from neurohover.sim.rng import ZIG_F, ZIG_R, ZIG_X, episode_normals, next_normal, next_u64, seed_stream, splitmix64

MASK = (1 << 64) - 1
GOLDEN = 0x9E3779B97F4A7C15


def _rotl(x: int, k: int) -> int:
    return ((x << k) | (x >> (64 - k))) & MASK


def _xoshiro_next(s: list[int]) -> int:
    """xoshiro256** 1.0, transcribed from the reference C code into plain Python integers."""
    result = (_rotl((s[1] * 5) & MASK, 7) * 9) & MASK
    t = (s[1] << 17) & MASK
    s[2] ^= s[0]
    s[3] ^= s[1]
    s[1] ^= s[2]
    s[0] ^= s[3]
    s[2] ^= t
    s[3] = _rotl(s[3], 45)
    return result


def _splitmix_next(state: int) -> tuple[int, int]:
    """splitmix64.c's next(): advance the state by the golden gamma, return the mixed value."""
    state = (state + GOLDEN) & MASK
    z = state
    z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & MASK
    z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & MASK
    return state, z ^ (z >> 31)


def test_xoshiro256starstar_matches_the_published_reference_outputs() -> None:
    # First outputs of the reference implementation from the state {1, 2, 3, 4}.
    published = [
        11520,
        0,
        1509978240,
        1215971899390074240,
        1216172134540287360,
        607988272756665600,
        16172922978634559625,
        8476171486693032832,
        10595114339597558777,
        2904607092377533576,
    ]
    state = np.array([1, 2, 3, 4], dtype=np.uint64)
    ours = [int(next_u64(state)) for _ in range(len(published))]
    assert ours == published
    ref = [1, 2, 3, 4]
    assert [_xoshiro_next(ref) for _ in range(len(published))] == published


def test_xoshiro256starstar_agrees_with_plain_python_over_a_long_stream() -> None:
    state = np.array([0x0123456789ABCDEF, 0xFEDCBA9876543210, 0xDEADBEEFCAFEBABE, 0x0F1E2D3C4B5A6978], dtype=np.uint64)
    ref = [int(x) for x in state]
    assert [int(next_u64(state)) for _ in range(2000)] == [_xoshiro_next(ref) for _ in range(2000)]


def test_splitmix64_matches_the_published_reference_outputs() -> None:
    # splitmix64.c seeded with 1234567 (the values the Rust and Java ports test against).
    published = [6457827717110365317, 3203168211198807973, 9817491932198370423, 4593380528125082431, 16408922859458223821]
    state = 1234567
    ref = []
    for _ in published:
        state, z = _splitmix_next(state)
        ref.append(z)
    assert ref == published
    # Our splitmix64(x) is the mix of x + gamma, i.e. next() from state x without keeping the state.
    ours = [int(splitmix64(np.uint64((1234567 + k * GOLDEN) & MASK))) for k in range(len(published))]
    assert ours == published


def test_episode_streams_are_seeded_as_documented() -> None:
    seed, episode = 20110401, 7
    state = np.empty(4, dtype=np.uint64)
    seed_stream(state, np.uint64(seed), np.uint64(episode))
    x = int(splitmix64(np.uint64(int(splitmix64(np.uint64(seed))) ^ ((episode * 0xD1B54A32D192ED03) & MASK))))
    expected = []
    for _ in range(4):
        x = int(splitmix64(np.uint64(x)))
        expected.append(x)
    assert [int(v) for v in state] == expected


def _ziggurat_tables() -> tuple[list[float], list[float]]:
    """Doornik's ZIGNOR tables for 256 layers, computed afresh in plain Python."""
    r, v = 3.6541528853610088, 0.00492867323399
    x = [0.0] * 257
    x[0] = v / math.exp(-0.5 * r * r)
    x[1] = r
    for i in range(2, 256):
        x[i] = math.sqrt(-2.0 * math.log(v / x[i - 1] + math.exp(-0.5 * x[i - 1] * x[i - 1])))
    return x, [float(np.exp(-0.5 * t * t)) for t in x]  # numpy's exp, as the package's table (libm may differ by an ulp)


def _normal(s: list[int], x: list[float], f: list[float]) -> float:
    """One standard normal by Doornik's ZIGNOR, from the low 8 bits (layer) and top 53 bits (u) of one draw."""

    def uniform() -> float:
        return (_xoshiro_next(s) >> 11) * 2.0**-53

    bits = _xoshiro_next(s)
    i, u = bits & 0xFF, 2.0 * ((bits >> 11) * 2.0**-53) - 1.0
    while True:
        if abs(u * x[i]) < x[i + 1]:
            return u * x[i]
        if i == 0:
            while True:
                a = -math.log(1.0 - uniform()) / ZIG_R
                b = -math.log(1.0 - uniform())
                if b + b > a * a:
                    return -(ZIG_R + a) if u < 0.0 else ZIG_R + a
        z = u * x[i]
        if f[i + 1] + uniform() * (f[i] - f[i + 1]) < math.exp(-0.5 * z * z):
            return z
        bits = _xoshiro_next(s)
        i, u = bits & 0xFF, 2.0 * ((bits >> 11) * 2.0**-53) - 1.0


def test_ziggurat_tables_and_normals_match_an_independent_implementation() -> None:
    x, f = _ziggurat_tables()
    np.testing.assert_array_equal(ZIG_X[:256], np.array(x[:256]))
    np.testing.assert_array_equal(ZIG_F, np.array(f))
    state = np.array([5, 6, 7, 8], dtype=np.uint64)
    ref = [5, 6, 7, 8]
    n = 20000  # long enough to pass through the tail and the wedges many times
    ours = np.array([next_normal(state) for _ in range(n)])
    theirs = np.array([_normal(ref, x, f) for _ in range(n)])
    np.testing.assert_array_equal(ours, theirs)
    assert np.sum(np.abs(ours) > ZIG_R) > 0  # the tail was exercised


@pytest.mark.parametrize("episode", [0, 1, 123456789])
def test_episode_normals_are_standard_normal(episode: int) -> None:
    z = episode_normals(np.uint64(42), np.uint64(episode), 20000).ravel()  # 120,000 draws
    assert stats.kstest(z, "norm").pvalue > 1e-3
    assert abs(z.mean()) < 0.02 and abs(z.std() - 1.0) < 0.02
