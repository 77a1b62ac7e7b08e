"""Fitness estimation under noise: fixed resampling and selection races (docs/model.md, Fitness under noise).

Both functions are driven by a caller-supplied ``sample_fn(indices) -> returns``
that flies every listed candidate for ONE more episode, each on a fresh MDP
drawn from the task family, and returns one return per index (same order; a
candidate listed twice flies two episodes, numbered in list order).
Returns are maximised (in the helicopter domain they are negative).

Recording the cost per generation
---------------------------------
Both results carry ``episodes_spent``; pass it to ``GenerationalNE.tell(means,
TellInfo(episodes=result.episodes_spent))`` (a race: also ``selected=result.selected``) so that
the optimiser's per-generation history records how many episodes were flown.

Selection races
---------------
:func:`selection_race` implements the prose of Sect. 5.2 by default (Algorithm 1 with the paper's
two changes; ``t_limit = t_min = t_max``, so no adaptation of ``t_limit``). Candidates are kept in
selected / discarded / undecided pools. Every round recomputes an undecided candidate's bounds FROM
SCRATCH from all its samples (so a bound may loosen again; the mean always lies inside; all undecided
candidates have the same number of samples, so one compiled call gives exactly the values of the
per-candidate call). Then, with ``lambda = n_candidates``:

- an undecided candidate whose lower bound exceeds the upper bounds of at least ``lambda - mu``
  others is selected;
- one whose upper bound is below the lower bounds of at least ``mu`` others is discarded.

"Others" means all other candidates whatever their pool, at their current bounds (decided candidates
keep their last bounds). Both conditions cannot hold at once. The race stops when ``mu`` are selected,
when every undecided candidate has ``t_limit`` samples, or when selected + undecided ``<= mu`` (the
fill step would pick them all). If one round selects more candidates than places remain, the ones
with the highest means are taken. Bounds with a single sample are ``(-inf, inf)``; zero-variance
samples give ``(mean, mean)``; NaN returns count as ``-inf`` and give ``(-inf, -inf)``.

``rule="algorithm1"`` is the printed Algorithm 1 (lines 18-26), one undecided candidate after another
in index order: selected when its lower bound exceeds the upper bounds of at least
``lambda - mu - |D|`` undecided ones, discarded when its upper bound is below the lower bounds of at
least ``mu - |S|`` undecided ones, ``S``, ``D`` and the undecided set changing at once; it stops when
``mu`` are selected or at ``t_limit`` (no early stop) and may select more than ``mu`` in its last round
(``over_selected``). ``rule="authors"`` is the same loop as their FGHH code ran it, which passes over
the candidate after each decision in a round.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from dataclasses import dataclass

import numba
import numpy as np

from ..errors import NeurohoverError, brief, check_arity, finite_real, real_number, whole_number
from ..flightmeta import compared_by_value
from ..procs import half_free_memory
from .common import as_floats

__all__ = [
    "RACE_RULES",
    "SampleFn",
    "RaceResult",
    "ResamplingResult",
    "bayes_mean_bounds",
    "fixed_resampling",
    "selection_race",
]

SampleFn = Callable[[np.ndarray], np.ndarray]

#: How a race decides (:func:`selection_race`): ``"prose"`` the paper's text (every other candidate, at its last
#: bounds; all of a round's decisions at once); ``"algorithm1"`` the printed Algorithm 1 (the undecided ones only,
#: the thresholds lowered by the decided counts, one candidate after another); ``"authors"`` their FGHH code's loop,
#: Algorithm 1 in a Python ``for`` over a list it removes from, so the candidate after each decision is passed over.
RACE_RULES = ("prose", "algorithm1", "authors")


@compared_by_value  # == by value: arrays whole (T46-B08)
@dataclass(frozen=True, eq=False)
class ResamplingResult:
    """Outcome of :func:`fixed_resampling`.

    Attributes
    ----------
    samples : np.ndarray
        ``(n_candidates, k)`` returns, column ``j`` from the ``j``-th call of ``sample_fn``.
    means : np.ndarray
        ``(n_candidates,)`` fitness estimates (NaN samples count as ``-inf``).
    episodes_spent : int
        ``n_candidates * k``.
    """

    samples: np.ndarray
    means: np.ndarray
    episodes_spent: int


@compared_by_value
@dataclass(frozen=True, eq=False)
class RaceResult:
    """Outcome of :func:`selection_race`.

    Attributes
    ----------
    selected : np.ndarray
        ``mu`` distinct candidate indices: first those the race selected (in
        the order they were selected; ties within a round by mean), then the
        places filled by best mean.
    means : np.ndarray
        ``(n_candidates,)`` mean return of each candidate over its samples.
    n_samples : np.ndarray
        ``(n_candidates,)`` number of episodes each candidate was flown.
    lower, upper : np.ndarray
        ``(n_candidates,)`` last confidence bounds of each candidate's mean.
    discarded : np.ndarray
        Indices the race discarded, in the order they were discarded.
    n_raced : int
        How many of ``selected`` were selected by the race itself (the rest
        were filled by best mean).
    episodes_spent : int
        Total episodes flown (``n_samples.sum()``).
    rounds : int
        Rounds raced (the most samples of a candidate); the first call of ``sample_fn`` flies
        rounds 1 and 2 when ``t_limit >= 2``.
    episodes_flown : int
        Samples drawn in all: ``episodes_spent`` plus look-ahead samples the race never used.
    over_selected : int
        Candidates the rule selected beyond ``mu`` (``"algorithm1"`` and ``"authors"`` may; the ``mu``
        of best mean among those selected are kept).
    """

    selected: np.ndarray
    means: np.ndarray
    n_samples: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    discarded: np.ndarray
    n_raced: int
    episodes_spent: int
    rounds: int
    episodes_flown: int = 0
    over_selected: int = 0


#: The most episodes a candidate flies in one estimate: fixed resampling's K (``fixed:K``) and a race's or bandit's
#: ``t_limit`` (k=10**13 built sample arrays until killed, t_limit=10**13 raced tied candidates on; sixteenth trial).
MAX_RESAMPLING = 100_000


def check_int(name: str, value: object, minimum: int, maximum: int | None = None, unit: str = "episodes per candidate") -> int:
    if not whole_number(value) or value < minimum:
        raise NeurohoverError(f"{name}={brief(value)} must be an integer >= {minimum}")
    if maximum is not None and value > maximum:
        raise NeurohoverError(f"{name}={brief(value)} must be an integer in {minimum}..{maximum:,} ({unit})")
    return int(value)


#: Bytes a race, a bandit or fixed resampling holds per candidate (bounds, means, flags, indices) and per episode
#: sample (the samples, a grown copy, a call's indices and returns), for :func:`check_room`.
_CANDIDATE_BYTES, _SAMPLE_BYTES = 256, 32


def check_room(n: int, episodes: int) -> None:
    """Refuse ``n`` candidates of at most ``episodes`` kept samples each (0: none kept) whose arrays would not fit in half
    the memory free now (10**13 candidates were a MemoryError of 72.8 TiB, 2**63 an empty result of 2**64 episodes; T17-3)."""
    room = half_free_memory()
    most = room // (_CANDIDATE_BYTES + _SAMPLE_BYTES * episodes)
    if n > most:
        each = f" of up to {episodes:,} episodes each" if episodes else ""
        raise NeurohoverError(
            f"n_candidates={brief(n)} is too many: at most {most:,} candidates{each} fit in half the memory free now ({room / 2**30:.1f} GiB); "
            "give fewer candidates"
        )


def _check_delta(delta: object) -> float:
    level = "a confidence level strictly between 0 and 1 (e.g. 0.9 for 90% confidence bounds)"
    if not real_number(delta):  # '0.5', Decimal, a 0-d array, True were called out of range (T35-B10)
        raise NeurohoverError(f"delta={brief(delta)} is not a number: allowed {level}")
    if not (finite_real(delta) and 0.0 < float(delta) < 1.0):  # finite_real: float(10**400) overflowed
        raise NeurohoverError(f"delta={brief(delta)} must be {level}")
    return float(delta)


def check_sample_fn(sample_fn: object) -> None:
    """Refuse a ``sample_fn`` that cannot be called before anything is flown (None was a TypeError mid-run; thirteenth trial, F14)."""
    if not callable(sample_fn):
        raise NeurohoverError(f"sample_fn={brief(sample_fn)} is not allowed: give a function of an array of candidate indices returning one return per index")
    # a wrong arity was a raw TypeError at its first call (T40-B02)
    check_arity("sample_fn", sample_fn, 1, "it is called as sample_fn(indices)", "a function of an array of candidate indices returning one return per index")


def draw_samples(sample_fn: SampleFn, indices: np.ndarray) -> np.ndarray:
    """Call ``sample_fn`` and check its answer (races and bandits alike); NaN returns become ``-inf`` (worst)."""
    out = as_floats(sample_fn(indices.copy()), "sample_fn's returns", f"{indices.size} numbers, one per candidate")
    if out.shape != indices.shape:
        raise NeurohoverError(f"sample_fn returned shape {out.shape} for {indices.size} candidates; expected {indices.shape}")
    if np.any(out == np.inf):
        raise NeurohoverError("sample_fn returned +inf; returns must be finite, NaN or -inf")
    return np.where(np.isnan(out), -np.inf, out)


def _mean(samples: np.ndarray) -> float:
    """One candidate's mean return, as a race's (:func:`_race_round`): returns past 2**500 in size in units of a power of
    two, so that finite returns of 1e308 average to 1e308, not +inf after an overflow warning (T40-B03, as T35-B04's bounds)."""
    if np.any(np.isneginf(samples)):
        return -math.inf
    largest = float(np.max(np.abs(samples)))
    if largest == 0.0 or _SMALL <= largest <= _LARGE:  # most returns: no call of the compiled scale (its first loads numba)
        return float(np.mean(samples))
    p = int(_scale_exponent(samples, samples.size))
    if p == 0:
        return float(np.mean(samples))
    return float(np.mean(samples * math.ldexp(1.0, -p))) * math.ldexp(1.0, p)


@functools.lru_cache(maxsize=4096)
def _standard_quantiles(n: int, delta: float) -> tuple[float, float]:
    """Quantiles at (1 -/+ delta)/2 of the standardised posterior of the mean (as in SciPy)."""
    from scipy import stats  # half a second to import: only a race needs it, not every command line

    q_lo, q_hi = (1.0 - delta) / 2.0, (1.0 + delta) / 2.0
    if n > 1000:  # scipy.stats.mvsdist switches to a normal approximation here
        return float(stats.norm.ppf(q_lo)), float(stats.norm.ppf(q_hi))
    return float(stats.t.ppf(q_lo, n - 1)), float(stats.t.ppf(q_hi, n - 1))


def bayes_mean_bounds(samples: np.ndarray, delta: float) -> tuple[float, float]:
    """Bayesian confidence bounds of the mean of ``samples`` at level ``delta``.

    The bounds are those of ``scipy.stats.bayes_mvs(samples, alpha=delta)[0].minmax``,
    which the paper used: the equal-tailed ``delta`` interval of the posterior
    of the mean under the Jeffreys prior, a Student-t with ``n - 1`` degrees of
    freedom around the sample mean with scale ``sqrt(var / (n - 1))`` (SciPy's
    normal approximation for ``n > 1000``). They are evaluated here in that
    closed form with cached quantiles, because ``bayes_mvs`` also builds the
    variance and standard-deviation posteriors and costs ~3 ms per call, about
    as much as flying an episode when a race updates hundreds of bounds per
    generation; the tests check agreement with ``bayes_mvs``.

    Cases where ``bayes_mvs`` fails or degenerates are handled explicitly:

    - one sample: ``(-inf, +inf)`` (``bayes_mvs`` raises; nothing is known
      about the spread);
    - zero variance (all samples equal): ``(mean, mean)`` (``bayes_mvs`` gives NaN);
    - any ``-inf`` sample (the races map NaN to ``-inf``): ``(-inf, -inf)``;
    - returns past 2**500 or below 2**-400 in size, whose squares overflow or
      underflow (``bayes_mvs`` gives ``(-inf, inf)``, or zero width): computed
      in units of a power of two, so the bounds stay finite and correct.

    Parameters
    ----------
    samples : np.ndarray
        1-D array of at least one return, no NaN and no ``+inf``.
    delta : float
        Confidence level in (0, 1): probability mass inside the interval.

    Returns
    -------
    tuple of float
        ``(lower, upper)``.
    """
    delta = _check_delta(delta)  # 1.5 gave (nan, nan) silently (thirteenth trial, F15)
    x = as_floats(samples, "samples", "an array of returns")
    if x.ndim != 1:  # a 2-D array was flattened and taken as one candidate's returns (fourteenth trial)
        raise NeurohoverError(f"samples of shape {x.shape} is not allowed: give a 1-D array of returns, one candidate's")
    n = x.size
    if n == 0:
        raise NeurohoverError("bayes_mean_bounds needs at least one sample")
    if np.any(np.isnan(x) | (x == np.inf)):  # NaN gave (nan, nan) silently; -inf is a crash (the races map NaN to it)
        raise NeurohoverError(f"samples={brief(x.tolist())} is not allowed: give finite returns or -inf, no NaN and no +inf")
    if np.any(np.isneginf(x)):
        return -math.inf, -math.inf
    if n == 1:
        return -math.inf, math.inf
    if np.all(x == x[0]):
        m = float(x[0])
        return m, m
    p = int(_scale_exponent(x, n))  # returns whose squares overflow or underflow: in units of 2**p (T35-B04)
    if p:
        x = x * math.ldexp(1.0, -p)
    up = math.ldexp(1.0, p)
    xbar = float(x.mean())
    var = float(x.var())
    scale = math.sqrt(var / n) if n > 1000 else math.sqrt(var / (n - 1))
    q_lo, q_hi = _standard_quantiles(n, delta)
    return (q_lo * scale + xbar) * up, (q_hi * scale + xbar) * up


def fixed_resampling(sample_fn: SampleFn, n_candidates: int, k: int) -> ResamplingResult:
    """Estimate every candidate's fitness as its mean return over ``k`` episodes.

    ``sample_fn`` is called ``k`` times with all indices ``0..n_candidates-1``.

    Parameters
    ----------
    sample_fn : callable
        ``sample_fn(indices) -> returns``, one fresh episode per index.
    n_candidates : int
        Number of candidates (>= 1; their samples must fit in half the memory free).
    k : int
        Episodes per candidate (1 to :data:`MAX_RESAMPLING`, 100,000).

    Returns
    -------
    ResamplingResult
    """
    check_sample_fn(sample_fn)
    n = check_int("n_candidates", n_candidates, 1)
    k = check_int("k", k, 1, MAX_RESAMPLING)
    check_room(n, k)
    idx = np.arange(n)
    samples = np.stack([draw_samples(sample_fn, idx) for _ in range(k)], axis=1)
    means = np.array([_mean(row) for row in samples])
    return ResamplingResult(samples=samples, means=means, episodes_spent=n * k)


def selection_race(
    sample_fn: SampleFn,
    n_candidates: int,
    mu: int,
    delta: float,
    t_limit: int = 10,
    batch: int = 0,
    rule: str = "prose",
) -> RaceResult:
    """Pick ``mu`` of ``n_candidates`` noisy candidates with a selection race (the module's "Selection races").

    Round 1 flies every candidate once (in the same call of ``sample_fn`` as round 2, since one sample
    decides nothing); each later round flies every undecided candidate one more episode, recomputes
    its bounds from all its samples (:func:`bayes_mean_bounds`), and selects or discards by ``rule``.
    Remaining places are filled with the undecided candidates of best mean (then the discarded ones).

    Parameters
    ----------
    sample_fn : callable
        ``sample_fn(indices) -> returns``: flies each listed candidate one more
        episode on a fresh MDP and returns one return per index.
    n_candidates : int
        Population size ``lambda`` (>= 2; ``t_limit`` samples of each must fit in half the memory free).
    mu : int
        Number to select, ``1 <= mu < n_candidates``.
    delta : float
        Confidence level of the bounds, in (0, 1) exclusive; larger is more
        cautious (wider bounds, more episodes).
    t_limit : int, default 10
        Maximum episodes per candidate (1 to :data:`MAX_RESAMPLING`, 100,000).
    rule : {"prose", "algorithm1", "authors"}, default "prose"
        The paper's prose, the printed Algorithm 1, or its loop as the authors' code ran it (module docstring).
    batch : int, default 0
        Look-ahead for speed: when a call of ``sample_fn`` is due, each undecided candidate is
        listed for its next ``ceil(batch / undecided)`` samples at once (at most up to
        ``t_limit``; at least the one the round needs), and later rounds use them before calling
        again. Samples of a candidate decided before it reaches them are never used. With a
        ``sample_fn`` whose t-th sample of a candidate is fixed (as an evolution run's is) the
        result does not depend on ``batch``; ``episodes_flown`` counts what it flew in all.

    Returns
    -------
    RaceResult
    """
    n, mu, delta, t_limit, batch = _race_arguments(sample_fn, n_candidates, mu, delta, t_limit, batch, rule)

    # Samples in one (n, capacity) array: in round r every undecided candidate has r samples (columns 0..r-1 of
    # its row); _race_round sums them in NumPy's order, so means and bounds are those of bayes_mean_bounds.
    samples = np.empty((n, min(t_limit, 16)))
    n_samples = np.zeros(n, dtype=np.int64)
    crashed = np.zeros(n, dtype=bool)  # some sample is -inf (or was NaN)
    lower, upper = np.full(n, -np.inf), np.full(n, np.inf)
    means = np.full(n, np.nan)
    undecided = np.ones(n, dtype=bool)
    discarded = np.zeros(n, dtype=bool)
    selected: list[int] = []
    discard_order: list[int] = []
    rounds = episodes_flown = 0
    need_select, need_discard = n - mu, mu
    sel, dis = np.zeros(n, dtype=np.bool_), np.zeros(n, dtype=np.bool_)  # per undecided candidate of a round: selected, discarded

    flown = 0  # samples drawn so far by every undecided candidate (they stay in lockstep)
    while True:
        active = np.flatnonzero(undecided)
        if flown == rounds:  # a call is due: this round's samples, and any look-ahead
            samples, ahead = _fly_ahead(sample_fn, samples, active, rounds, batch, t_limit)
            flown += ahead
            episodes_flown += ahead * active.size
        first_new = rounds
        rounds += 2 if rounds == 0 and t_limit >= 2 else 1
        n_samples[active] = rounds
        q_lo, q_hi = _standard_quantiles(rounds, delta) if rounds > 1 else (math.nan, math.nan)
        # This round's bounds, then the decisions on them, all undecided candidates at once.
        _race_round(samples, active, first_new, rounds, q_lo, q_hi, need_select, need_discard, crashed, means, lower, upper, sel, dis)
        if rule != "prose":  # Algorithm 1's decisions, one candidate after another (the bounds are this round's)
            newly_sel, newly_dis = _sequential_decisions(active, lower, upper, n - mu, mu, len(selected), int(discarded.sum()), rule == "authors")
        else:  # the prose's, all at once; a round that selects more than the places left takes the best means
            newly_sel, newly_dis = active[sel[: active.size]], active[dis[: active.size]]
            if newly_sel.size > mu - len(selected):
                newly_sel = newly_sel[_best_first(means, newly_sel)][: mu - len(selected)]
            newly_sel = newly_sel[_best_first(means, newly_sel)]
        selected.extend(newly_sel.tolist())  # Algorithm 1's kept beyond mu for now: the best mu are taken below
        undecided[newly_sel] = False
        undecided[newly_dis] = False
        discarded[newly_dis] = True
        discard_order.extend(newly_dis.tolist())
        n_undecided = int(np.count_nonzero(undecided))
        # mu selected; nothing undecided; (the prose) the undecided certain to fill the places; or t_limit reached
        if len(selected) >= mu or n_undecided == 0 or (rule == "prose" and len(selected) + n_undecided <= mu) or rounds >= t_limit:
            break

    selected, n_raced, over_selected = _filled(selected, undecided, discarded, means, mu)
    chosen = set(selected)
    discards = np.asarray([i for i in discard_order if i not in chosen], dtype=np.int64)
    picked = np.asarray(selected, dtype=np.int64)
    spent = int(n_samples.sum())
    return RaceResult(picked, means, n_samples, lower, upper, discards, n_raced, spent, rounds, episodes_flown=episodes_flown, over_selected=over_selected)


def _race_arguments(sample_fn, n_candidates, mu, delta, t_limit, batch, rule) -> tuple[int, int, float, int, int]:
    """:func:`selection_race`'s arguments checked (NeurohoverError naming the bad one)."""
    check_sample_fn(sample_fn)
    n = check_int("n_candidates", n_candidates, 2)
    mu = check_int("mu", mu, 1)
    if mu >= n:
        raise NeurohoverError(f"mu={mu} must be smaller than n_candidates={n}")
    if not isinstance(rule, str) or rule not in RACE_RULES:
        raise NeurohoverError(f"rule={brief(rule)} is not a race rule: choose one of {', '.join(RACE_RULES)}")
    t_limit = check_int("t_limit", t_limit, 1, MAX_RESAMPLING)
    check_room(n, t_limit)
    return n, mu, _check_delta(delta), t_limit, check_int("batch", batch, 0)


def _fly_ahead(sample_fn: SampleFn, samples: np.ndarray, active: np.ndarray, rounds: int, batch: int, t_limit: int) -> tuple[np.ndarray, int]:
    """Fly this round's samples of the undecided ``active`` and any look-ahead (``batch``) into ``samples``
    (grown when it lacks the columns); returns the samples array and how many rounds were flown.

    Round 1 can decide nothing (one sample: bounds (-inf, inf), or (-inf, -inf) for a crash, which no
    lower bound of -inf exceeds), so its call flies round 2 too.
    """
    ahead = max(2 if rounds == 0 else 1, -(-batch // active.size))
    ahead = min(ahead, t_limit - rounds)
    draws = draw_samples(sample_fn, np.tile(active, ahead))  # listed in round order
    if rounds + ahead > samples.shape[1]:
        grown = np.empty((samples.shape[0], min(t_limit, max(2 * samples.shape[1], rounds + ahead))))
        grown[:, : samples.shape[1]] = samples
        samples = grown
    samples[active, rounds : rounds + ahead] = draws.reshape(ahead, active.size).T
    return samples, ahead


def _filled(selected: list[int], undecided: np.ndarray, discarded: np.ndarray, means: np.ndarray, mu: int) -> tuple[list[int], int, int]:
    """The race's ``mu`` picks: the best ``mu`` of those selected (a last round of Algorithm 1 may select more),
    then the undecided of best mean, then (only if those run out) the discarded; with how many were raced
    in and how many were selected beyond ``mu``."""
    over_selected = max(0, len(selected) - mu)
    if over_selected:
        picked = np.asarray(selected)
        selected = picked[_best_first(means, picked)][:mu].tolist()
    n_raced = len(selected)
    for pool in (np.flatnonzero(undecided), np.flatnonzero(discarded)):
        need = mu - len(selected)
        if need <= 0:
            break
        selected.extend(pool[_best_first(means, pool)][:need].tolist())
    return selected, n_raced, over_selected


def _sequential_decisions(
    active: np.ndarray, lower: np.ndarray, upper: np.ndarray, n_select: int, mu: int, n_selected: int, n_discarded: int, skip: bool
) -> tuple[np.ndarray, np.ndarray]:
    """One round of Algorithm 1's lines 18-26 over the undecided ``active`` (in index order): who is selected and
    who discarded, in the order decided. ``n_select`` is lambda - mu; ``skip``: the authors' loop, whose
    ``for i, x in enumerate(U)`` with ``U.pop(i)`` passes over the candidate after each decision."""
    pool = active.tolist()
    chosen: list[int] = []
    dropped: list[int] = []
    i = 0
    while i < len(pool):
        x = pool[i]
        others_lower = lower[pool]
        others_upper = upper[pool]
        if np.count_nonzero(lower[x] > others_upper) >= n_select - (n_discarded + len(dropped)):
            chosen.append(pool.pop(i))
        elif np.count_nonzero(upper[x] < others_lower) >= mu - (n_selected + len(chosen)):
            dropped.append(pool.pop(i))
        else:
            i += 1
            continue
        i += skip  # the element now at i took the decided one's place: their loop moves on past it
    return np.asarray(chosen, dtype=np.int64), np.asarray(dropped, dtype=np.int64)


@numba.njit(cache=True, error_model="numpy")
def _pairwise_sum(x, n):
    """NumPy's sum of ``x[:n]`` (its pairwise summation: blocks of 8 in 8 partial sums), to the same bits."""
    if n < 8:
        total = -0.0
        for i in range(n):
            total += x[i]
        return total
    if n <= 128:
        r = x[:8].copy()
        i = 8
        while i < n - n % 8:
            for j in range(8):
                r[j] += x[i + j]
            i += 8
        total = ((r[0] + r[1]) + (r[2] + r[3])) + ((r[4] + r[5]) + (r[6] + r[7]))
        while i < n:
            total += x[i]
            i += 1
        return total
    half = n // 2
    half -= half % 8
    return _pairwise_sum(x, half) + _pairwise_sum(x[half:], n - half)


@numba.njit(cache=True, error_model="numpy")
def _scale_exponent(x, n):
    """0 where the returns ``x[:n]`` have a mean and variance a float holds to full precision, else the even ``p``
    that brings the largest near 1: the bounds are then those of ``x / 2**p`` times ``2**p``, exact powers of two.
    Returns past 2**500 (~3e150) overflowed the squared deviations to (-inf, inf); below 2**-400 (~4e-121) they
    underflowed, and denormal returns gave zero-width bounds (T35-B04)."""
    largest = 0.0
    for t in range(n):
        a = abs(x[t])
        if a > largest:
            largest = a
    if largest == 0.0 or _SMALL <= largest <= _LARGE:
        return 0
    p = min(max(math.frexp(largest)[1], -1000), 1000)  # 2**-p and 2**p both floats; denormals come to ~2**-62 at most
    return p - p % 2


_LARGE, _SMALL = 2.0**500, 2.0**-400


@numba.njit(cache=True, error_model="numpy")
def _race_round(samples, active, first_new, k, q_lo, q_hi, need_select, need_discard, crashed, means, lower, upper, sel, dis):
    """One round of :func:`selection_race` for its undecided candidates ``active`` (each with ``k`` samples in
    its row of ``samples``, ``first_new ..`` new this round): update ``crashed``, write ``means`` and the
    bounds, :func:`bayes_mean_bounds` to the bits (NumPy's summation order: ``_pairwise_sum``), then flag in
    ``sel`` / ``dis`` (per position in ``active``) those this round selects and discards, on everyone's
    current bounds. ``q_lo`` / ``q_hi``: the standardised quantiles for ``k`` samples."""
    for i in active:
        for t in range(first_new, k):
            if samples[i, t] == -np.inf:
                crashed[i] = True
    squares = np.empty(k)
    scaled = np.empty(k)
    for i in active:
        row = samples[i]
        if crashed[i]:
            means[i] = lower[i] = upper[i] = -np.inf
            continue
        p = _scale_exponent(row, k)
        if p != 0:  # returns whose squares overflow or underflow: those of row / 2**p, times 2**p (T35-B04)
            down = math.ldexp(1.0, -p)
            for t in range(k):
                scaled[t] = row[t] * down
            row = scaled
        up = math.ldexp(1.0, p)  # 1.0 (p = 0): the same bits as unscaled
        mean = _pairwise_sum(row, k) / k
        means[i] = mean * up
        if k == 1:
            lower[i], upper[i] = -np.inf, np.inf
            continue
        constant = True
        for t in range(1, k):
            if row[t] != row[0]:
                constant = False
                break
        if constant:
            lower[i] = upper[i] = samples[i, 0]
            continue
        for t in range(k):
            d = row[t] - mean
            squares[t] = d * d
        var = _pairwise_sum(squares, k) / k
        scale = np.sqrt(var / k) if k > 1000 else np.sqrt(var / (k - 1))
        lower[i] = (q_lo * scale + mean) * up
        upper[i] = (q_hi * scale + mean) * up
    for q in range(active.shape[0]):
        i = active[q]
        beaten = 0
        beating = 0
        for j in range(means.shape[0]):
            beaten += upper[j] < lower[i]
            beating += lower[j] > upper[i]
        sel[q] = beaten >= need_select
        dis[q] = beating >= need_discard


def _best_first(means: np.ndarray, idx: np.ndarray) -> np.ndarray:
    """Order (positions into ``idx``) by descending mean, stable on ties."""
    return np.argsort(-means[idx], kind="stable")
