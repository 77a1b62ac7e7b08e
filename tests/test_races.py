"""Selection races and fixed resampling (neurohover.evolution.races), checked against a frozen reference copy."""

from __future__ import annotations

import dataclasses
import math
import warnings

import numpy as np
import pytest
from scipy import stats

from neurohover.evolution import (
    bayes_mean_bounds,
    fixed_resampling,
    selection_race,
)

# --------------------------------------------------------------------------- races


def noisy_sampler(means: np.ndarray, sd: float, seed: int):
    rng = np.random.default_rng(seed)
    calls = []

    def sample(idx: np.ndarray) -> np.ndarray:
        calls.append(idx.size)
        return means[idx] + rng.normal(0.0, sd, idx.size)

    return sample, calls


def test_bayes_mean_bounds_edge_cases() -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert bayes_mean_bounds(np.array([3.0]), 0.9) == (-math.inf, math.inf)
        assert bayes_mean_bounds(np.array([2.0, 2.0, 2.0]), 0.9) == (2.0, 2.0)
        assert bayes_mean_bounds(np.array([-np.inf, 1.0]), 0.9) == (-math.inf, -math.inf)
        lo, hi = bayes_mean_bounds(np.array([1.0, 2.0]), 0.9)
        assert math.isfinite(lo) and lo < 1.5 < hi
        x = np.random.default_rng(0).normal(5.0, 2.0, 7)
        expected = stats.t.interval(0.8, 6, loc=x.mean(), scale=stats.sem(x))
        assert bayes_mean_bounds(x, 0.8) == pytest.approx(expected)
        assert bayes_mean_bounds(x, 0.95)[0] < bayes_mean_bounds(x, 0.5)[0]


@pytest.mark.parametrize("n", [2, 3, 5, 10, 37, 1000, 1001, 1500])
@pytest.mark.parametrize("delta", [0.1, 0.5, 0.9, 0.99])
def test_bayes_mean_bounds_match_scipy_bayes_mvs(n: int, delta: float) -> None:
    x = np.random.default_rng(n).normal(-3e4, 5e3, n)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # n=2: infinite statistic
        expected = stats.bayes_mvs(x, alpha=delta)[0].minmax
    assert bayes_mean_bounds(x, delta) == pytest.approx(expected, rel=1e-12, abs=1e-9)


def test_race_selects_top_mu_and_saves_episodes() -> None:
    means = -10.0 * np.arange(20)[::-1]  # candidate 19 best
    sample, calls = noisy_sampler(means, 1.0, seed=0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        race = selection_race(sample, 20, 5, delta=0.9, t_limit=10)
    assert sorted(race.selected.tolist()) == [15, 16, 17, 18, 19]
    assert race.n_raced == 5
    fixed = fixed_resampling(noisy_sampler(means, 1.0, seed=0)[0], 20, k=10)
    assert fixed.episodes_spent == 200 and fixed.samples.shape == (20, 10)
    assert race.episodes_spent < fixed.episodes_spent / 2
    assert race.episodes_spent == race.n_samples.sum() == sum(calls)
    assert race.rounds == len(calls) + 1 and race.n_samples.max() <= 10  # rounds 1 and 2 fly in one call
    assert calls[0] == 40  # every candidate twice
    assert np.all(race.lower <= race.means) and np.all(race.means <= race.upper)
    assert np.all(np.abs(race.means - means) < 4.0)


def test_race_decision_rule_thresholds() -> None:
    # Scripted returns, delta=0.5 (t quantile 1.0 at 1 dof). After round 2:
    # c0 = [10, 12] -> bounds [10, 12]; c1 = [11.5, 11.5] -> point 11.5, inside
    # c0's bounds; c2, c3 = [0, 0] -> point 0. With lambda=4, mu=1 nobody beats
    # lambda-mu=3 others yet, while c2 and c3 lie below >= mu=1 others: discarded.
    # Round 3: c0 = [10, 12, 11] -> 11 +- 0.47, so c1 (11.5) now beats all 3
    # and c0 lies below c1.
    script = {0: [10.0, 12.0, 11.0], 1: [11.5, 11.5, 11.5], 2: [0.0, 0.0, 0.0], 3: [0.0, 0.0, 0.0]}
    calls = {i: 0 for i in script}

    def sample(idx):
        out = []
        for i in idx:
            out.append(script[int(i)][calls[int(i)]])
            calls[int(i)] += 1
        return np.array(out)

    race = selection_race(sample, 4, 1, delta=0.5, t_limit=10)
    assert race.rounds == 3 and race.n_raced == 1
    assert race.selected.tolist() == [1]
    assert race.discarded.tolist() == [2, 3, 0]  # c0 (upper 11.47 < 11.5) goes in round 3
    assert race.n_samples.tolist() == [3, 3, 2, 2]
    assert race.lower[0] == pytest.approx(11.0 - stats.t.ppf(0.75, 2) * math.sqrt(1 / 3))


def test_race_indistinguishable_candidates_run_to_limit() -> None:
    sample, _ = noisy_sampler(np.zeros(12), 1.0, seed=1)
    race = selection_race(sample, 12, 4, delta=0.99, t_limit=6)
    assert len(set(race.selected.tolist())) == 4
    assert race.rounds == 6 and race.episodes_spent <= 12 * 6
    # The fill step takes the best means among the undecided ones.
    undecided = race.n_samples == 6
    filled = race.selected[race.n_raced :]
    assert np.all(undecided[filled])
    others = np.setdiff1d(np.flatnonzero(undecided), race.selected)
    assert race.means[filled].min() >= race.means[others].max()


def test_race_single_sample_and_zero_variance() -> None:
    means = np.arange(8, dtype=float)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        one = selection_race(lambda i: means[i], 8, 3, delta=0.9, t_limit=1)
        assert one.rounds == 1 and one.episodes_spent == 8 and one.n_raced == 0
        assert sorted(one.selected.tolist()) == [5, 6, 7]
        exact = selection_race(lambda i: means[i], 8, 3, delta=0.9, t_limit=10)
        assert exact.rounds == 2 and exact.episodes_spent == 16 and exact.n_raced == 3
        assert sorted(exact.selected.tolist()) == [5, 6, 7]
        ties = selection_race(lambda i: np.full(i.size, -4.0), 8, 3, delta=0.9, t_limit=4)
        assert ties.rounds == 4 and ties.n_raced == 0 and len(set(ties.selected.tolist())) == 3


def test_race_nan_returns_are_worst() -> None:
    means = np.arange(10, dtype=float)

    def sample(idx):
        out = means[idx] + np.random.default_rng(int(idx.sum())).normal(0, 0.1, idx.size)
        out[idx == 9] = np.nan  # the nominally best candidate crashes the simulator
        return out

    race = selection_race(sample, 10, 3, delta=0.9)
    assert 9 not in race.selected and sorted(race.selected.tolist()) == [6, 7, 8]
    assert race.means[9] == -math.inf


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"delta": 0.0}, r"delta=0.0 must be a confidence level strictly between 0 and 1"),
        ({"delta": 1.0}, r"delta=1.0 must be"),
        ({"mu": 0}, r"mu=0 must be an integer >= 1"),
        ({"mu": 6}, r"mu=6 must be smaller than n_candidates=6"),
        ({"t_limit": 0}, r"t_limit=0 must be an integer >= 1"),
        ({"n_candidates": 1, "mu": 1}, r"n_candidates=1 must be an integer >= 2"),
    ],
)
def test_race_validation(kwargs, message) -> None:
    args = {"n_candidates": 6, "mu": 2, "delta": 0.9, "t_limit": 3} | kwargs
    with pytest.raises(ValueError, match=message):
        selection_race(lambda i: np.zeros(i.size), **args)


def test_resampling_validation_and_shape_check() -> None:
    with pytest.raises(ValueError, match=r"k=0 must be an integer >= 1"):
        fixed_resampling(lambda i: np.zeros(i.size), 5, 0)
    with pytest.raises(ValueError, match="sample_fn returned shape"):
        fixed_resampling(lambda i: np.zeros(3), 5, 2)
    res = fixed_resampling(lambda i: i.astype(float), 4, 3)
    assert np.array_equal(res.means, [0.0, 1.0, 2.0, 3.0]) and res.episodes_spent == 12


# ------------------------------------------------- selection_race regression (reference copy)
# A frozen copy of the original per-candidate implementation of ``selection_race``
# (one ``bayes_mean_bounds`` and one mean per candidate per round). The vectorised
# implementation in neurohover.evolution.races must reproduce it exactly: same
# selection (and order), same calls to ``sample_fn``, same means / bounds / counts.


def _ref_draw(sample_fn, indices: np.ndarray) -> np.ndarray:
    out = np.asarray(sample_fn(indices.copy()), dtype=np.float64)
    if out.shape != indices.shape:
        raise ValueError(f"sample_fn returned shape {out.shape} for {indices.size} candidates; expected {indices.shape}")
    if np.any(out == np.inf):
        raise ValueError("sample_fn returned +inf; returns must be finite, NaN or -inf")
    return np.where(np.isnan(out), -np.inf, out)


def _ref_mean(samples: np.ndarray) -> float:
    return -math.inf if np.any(np.isneginf(samples)) else float(np.mean(samples))


def _ref_bounds(samples: np.ndarray, delta: float) -> tuple[float, float]:
    x = np.asarray(samples, dtype=np.float64).ravel()
    n = x.size
    if np.any(np.isneginf(x)):
        return -math.inf, -math.inf
    if n == 1:
        return -math.inf, math.inf
    if np.all(x == x[0]):
        m = float(x[0])
        return m, m
    xbar = float(x.mean())
    var = float(x.var())
    scale = math.sqrt(var / n) if n > 1000 else math.sqrt(var / (n - 1))
    q_lo, q_hi = (1.0 - delta) / 2.0, (1.0 + delta) / 2.0
    if n > 1000:
        q_lo, q_hi = float(stats.norm.ppf(q_lo)), float(stats.norm.ppf(q_hi))
    else:
        q_lo, q_hi = float(stats.t.ppf(q_lo, n - 1)), float(stats.t.ppf(q_hi, n - 1))
    return q_lo * scale + xbar, q_hi * scale + xbar


def _ref_best_first(means: np.ndarray, idx: np.ndarray) -> np.ndarray:
    return np.argsort(-means[idx], kind="stable")


def _reference_selection_race(sample_fn, n: int, mu: int, delta: float, t_limit: int = 10) -> dict:
    samples: list[list[float]] = [[] for _ in range(n)]
    lower = np.full(n, -np.inf)
    upper = np.full(n, np.inf)
    means = np.full(n, np.nan)
    undecided = np.ones(n, dtype=bool)
    discarded = np.zeros(n, dtype=bool)
    selected: list[int] = []
    discard_order: list[int] = []
    rounds = 0
    while True:
        active = np.flatnonzero(undecided)
        for i, r in zip(active, _ref_draw(sample_fn, active)):
            samples[i].append(float(r))
            arr = np.asarray(samples[i])
            means[i] = _ref_mean(arr)
            lower[i], upper[i] = _ref_bounds(arr, delta)
        rounds += 1
        n_beaten = (upper[None, :] < lower[active, None]).sum(axis=1)
        n_beating = (lower[None, :] > upper[active, None]).sum(axis=1)
        newly_sel = active[n_beaten >= n - mu]
        newly_dis = active[n_beating >= mu]
        room = mu - len(selected)
        if newly_sel.size > room:
            newly_sel = newly_sel[_ref_best_first(means, newly_sel)][:room]
        selected.extend(int(i) for i in newly_sel[_ref_best_first(means, newly_sel)])
        undecided[newly_sel] = False
        undecided[newly_dis] = False
        discarded[newly_dis] = True
        discard_order.extend(int(i) for i in newly_dis)
        if len(selected) >= mu or not undecided.any():
            break
        if len(selected) + int(undecided.sum()) <= mu:
            break
        if rounds >= t_limit:
            break
    n_raced = len(selected)
    for pool in (np.flatnonzero(undecided), np.flatnonzero(discarded)):
        need = mu - len(selected)
        if need <= 0:
            break
        selected.extend(int(i) for i in pool[_ref_best_first(means, pool)][:need])
    n_samples = np.array([len(s) for s in samples], dtype=np.int64)
    return {
        "selected": np.asarray(selected, dtype=np.int64),
        "means": means,
        "n_samples": n_samples,
        "lower": lower,
        "upper": upper,
        "discarded": np.asarray([i for i in discard_order if i not in selected], dtype=np.int64),
        "n_raced": n_raced,
        "episodes_spent": int(n_samples.sum()),
        "rounds": rounds,
    }


def _race_case(seed: int):
    """A random race problem: (n, mu, delta, t_limit, table of returns per candidate and sample)."""
    rng = np.random.default_rng(seed)
    n = int(rng.integers(5, 61))
    mu = int(rng.integers(1, n))
    delta = float(rng.uniform(0.05, 0.95))
    t_limit = int(rng.integers(2, 11)) if seed % 11 else int(rng.integers(1, 4))
    kind = seed % 7
    scale = float(10.0 ** rng.uniform(-2, 4))
    true = rng.normal(0.0, scale, n) - (3e4 if seed % 2 else 0.0)
    noise = float(10.0 ** rng.uniform(-3, 0.5)) * scale
    table = true[:, None] + rng.normal(0.0, noise, (n, t_limit))
    if kind == 1:  # heavy ties: few distinct values
        table = rng.integers(0, 3, (n, t_limit)).astype(float) + rng.integers(0, 2, (n, 1))
    elif kind == 2:  # some constant candidates
        const = rng.random(n) < 0.5
        table[const] = true[const, None]
    elif kind == 3:  # NaN and -inf returns
        table[rng.random((n, t_limit)) < 0.05] = np.nan
        table[rng.random((n, t_limit)) < 0.03] = -np.inf
    elif kind == 4:  # all identical
        table[:] = -4.0
    elif kind == 5:  # rounded returns (ties between candidates and samples), some crashes
        table = np.round(table / noise)
        table[rng.random((n, t_limit)) < 0.02] = np.nan
    elif kind == 6:  # huge dynamic range, sums where order matters
        table = rng.choice([1e16, 1.0, -1e16, 0.1, 3.0, -2.5e-3], (n, t_limit)) + true[:, None] * 1e-3
    return n, mu, delta, t_limit, table


def _table_sampler(table: np.ndarray):
    count = np.zeros(table.shape[0], dtype=np.int64)
    calls: list[np.ndarray] = []

    def sample(idx: np.ndarray) -> np.ndarray:
        calls.append(idx.copy())
        out = np.empty(idx.size)
        for q, i in enumerate(idx):  # a candidate listed twice flies its next two samples, in list order
            out[q] = table[i, count[i]]
            count[i] += 1
        idx[:] = -1  # a sample_fn scribbling on its argument must not matter
        return out

    return sample, calls


def _assert_race_equal(new, ref: dict) -> None:
    for key in ("selected", "n_samples", "discarded"):
        got = getattr(new, key)
        assert got.dtype == ref[key].dtype and np.array_equal(got, ref[key]), key
    for key in ("n_raced", "episodes_spent", "rounds"):
        assert getattr(new, key) == ref[key], key
    for key in ("means", "lower", "upper"):
        np.testing.assert_allclose(getattr(new, key), ref[key], rtol=1e-12, atol=0, err_msg=key)


@pytest.mark.parametrize("seed", range(400))
def test_selection_race_matches_reference_implementation(seed: int) -> None:
    n, mu, delta, t_limit, table = _race_case(seed)
    ref_sample, ref_calls = _table_sampler(table)
    with warnings.catch_warnings(record=True) as ref_warnings:
        warnings.simplefilter("always")
        ref = _reference_selection_race(ref_sample, n, mu, delta, t_limit)
    new_sample, new_calls = _table_sampler(table)
    with warnings.catch_warnings(record=True) as new_warnings:
        warnings.simplefilter("always")
        new = selection_race(new_sample, n, mu, delta, t_limit)
    _assert_race_equal(new, ref)
    if t_limit >= 2:  # rounds 1 and 2 in one call: the reference's first two calls, one after the other
        ref_calls = [np.concatenate(ref_calls[:2]), *ref_calls[2:]]
    assert len(new_calls) == len(ref_calls)
    for a, b in zip(new_calls, ref_calls):
        assert a.dtype == b.dtype and np.array_equal(a, b)
    if not ref_warnings:
        assert not new_warnings


@pytest.mark.parametrize("seed", range(40))
def test_selection_race_matches_reference_with_stream_sampler(seed: int) -> None:
    """Returns drawn from one RNG stream in call order (as the evolve loop does)."""
    rng = np.random.default_rng(seed)
    n = int(rng.integers(5, 61))
    mu, delta, t_limit = int(rng.integers(1, n)), float(rng.uniform(0.05, 0.95)), int(rng.integers(2, 11))
    true = rng.normal(0.0, 1.0, n)

    def make():
        stream = np.random.default_rng(seed + 1000)
        return lambda idx: true[idx] + stream.normal(0.0, 2.0, idx.size)

    ref = _reference_selection_race(make(), n, mu, delta, t_limit)
    _assert_race_equal(selection_race(make(), n, mu, delta, t_limit), ref)


@pytest.mark.slow
def test_selection_race_matches_reference_beyond_1000_samples() -> None:
    """Indistinguishable candidates raced past n = 1000 (normal-approximation bounds)."""
    rng = np.random.default_rng(5)
    table = rng.normal(0.0, 1.0, (3, 1003))
    ref = _reference_selection_race(_table_sampler(table)[0], 3, 1, 0.999999, 1003)
    new = selection_race(_table_sampler(table)[0], 3, 1, 0.999999, 1003)
    assert ref["rounds"] > 1000
    _assert_race_equal(new, ref)


def test_selection_race_bad_returns_raise_like_reference() -> None:
    for bad in (lambda i: np.zeros(i.size + 1), lambda i: np.where(i == 3, np.inf, 0.0)):
        for impl in (_reference_selection_race, selection_race):
            with pytest.raises(ValueError, match="sample_fn returned"):
                impl(bad, 6, 2, 0.9, 3)


@pytest.mark.parametrize("seed", range(0, 400, 7))
def test_a_races_look_ahead_changes_no_result(seed: int) -> None:
    """With every candidate's t-th sample fixed (the table), look-ahead batches fly more samples
    per call but the race uses exactly the samples it used without them."""
    n, mu, delta, t_limit, table = _race_case(seed)
    plain_sample, plain_calls = _table_sampler(table)
    plain = selection_race(plain_sample, n, mu, delta, t_limit)
    for batch in (7, 64, 10_000):
        sample, calls = _table_sampler(table)
        ahead = selection_race(sample, n, mu, delta, t_limit, batch=batch)
        _assert_race_equal(ahead, dataclasses.asdict(plain))
        assert len(calls) <= len(plain_calls)
        if batch == 10_000:  # every sample up to t_limit in the first call
            assert len(calls) == 1
        assert ahead.episodes_flown == sum(c.size for c in calls) >= ahead.episodes_spent
    assert plain.episodes_flown == plain.episodes_spent


# ------------------------------------------------- the compiled round, to the bits


def test_the_compiled_sum_is_numpys_to_the_bits() -> None:
    from neurohover.evolution.races import _pairwise_sum

    rng = np.random.default_rng(0)
    for n in [*range(1, 40), 127, 128, 129, 255, 300, 1003]:
        x = rng.normal(0, 1, n) * 10.0 ** rng.integers(-8, 9, n)  # sums where the order matters
        assert _pairwise_sum(x, n) == x.sum(), n


@pytest.mark.parametrize("k", [1, 2, 3, 7, 8, 9, 10, 17, 1001])
def test_a_compiled_round_gives_bayes_mean_bounds_and_the_decisions_to_the_bits(k: int) -> None:
    """Each undecided candidate's mean and bounds are ``_mean`` and :func:`bayes_mean_bounds` of its row, bit for
    bit (crashes, constant rows, wide ranges among them), and the selections and discards are those counted on
    everyone's bounds as the race defines them."""
    from neurohover.evolution.races import _race_round, _standard_quantiles

    rng = np.random.default_rng(k)
    n, mu, delta = 40, 15, 0.7
    samples = rng.normal(-1000.0, 50.0, (n, k + 2)) * 10.0 ** rng.integers(-3, 4, (n, 1))
    samples[rng.random(n) < 0.2, rng.integers(0, k)] = -np.inf
    samples[:3, :] = samples[:3, :1]  # constant rows
    active = np.flatnonzero(rng.random(n) < 0.7).astype(np.int64)
    crashed = np.zeros(n, dtype=bool)
    means, lower, upper = np.full(n, np.nan), rng.normal(-1000, 50, n), rng.normal(-900, 50, n)  # the others' bounds
    sel, dis = np.zeros(n, dtype=bool), np.zeros(n, dtype=bool)
    q_lo, q_hi = _standard_quantiles(k, delta) if k > 1 else (math.nan, math.nan)
    _race_round(samples, active, 0, k, q_lo, q_hi, n - mu, mu, crashed, means, lower, upper, sel, dis)
    for i in active:
        row = samples[i, :k]
        assert crashed[i] == bool(np.isneginf(row).any())
        want_mean = -math.inf if crashed[i] else float(np.mean(row))
        assert np.float64(means[i]).tobytes() == np.float64(want_mean).tobytes()
        lo, hi = bayes_mean_bounds(row, delta)
        assert (np.float64(lower[i]).tobytes(), np.float64(upper[i]).tobytes()) == (np.float64(lo).tobytes(), np.float64(hi).tobytes())
    np.testing.assert_array_equal(sel[: active.size], (upper[None, :] < lower[active, None]).sum(axis=1) >= n - mu)
    np.testing.assert_array_equal(dis[: active.size], (lower[None, :] > upper[active, None]).sum(axis=1) >= mu)
