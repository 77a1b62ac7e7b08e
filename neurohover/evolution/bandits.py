"""Top-mu selection as a multi-armed bandit problem (Section 7's open question; issue 35): LUCB and KL-LUCB.

Selection races (:mod:`neurohover.evolution.races`) decide by Bayesian (Student-t) bounds that assume nothing
about the range of a fitness. The bandit algorithms below identify the mu best of lambda candidates with
probability at least ``1 - delta`` for rewards in [0, 1] (distribution-free), sampling only the two candidates
that are least certain in each round:

- **LUCB1** (Kalyanakrishnan, Tewari, Auer & Stone, ICML 2012): Hoeffding bounds with the exploration rate
  ``beta(u, t) = sqrt(ln(5 n t^4 / (4 delta)) / (2 u))`` for a candidate with ``u`` samples at round ``t``.
- **KL-LUCB** (Kaufmann & Kalyanakrishnan, COLT 2013): Chernoff bounds ``{q : u d(p, q) <= beta(t)}`` with the
  Bernoulli divergence ``d`` and ``beta(t) = ln(k1 n t^alpha / delta)``, ``k1 = 405.5``, ``alpha = 1.1`` (their
  Theorem 3's constants), tighter than Hoeffding's near 0 and 1.

Each round: J = the mu best empirical means; l = the member of J with the lowest lower bound, u = the
non-member with the highest upper bound; stop when u's upper bound is below l's lower bound (epsilon = 0),
otherwise fly l and u one more episode each. As a race does, a candidate flies at most ``t_limit`` episodes; when
both l and u have them, the selection stops on J. The reward is a candidate's episode fitness on FGHH's
``1/ln(error)`` scale, which lies in [0, 1] for any error of at least e (a hovering error is far above): values
above 1 are clipped, NaN and ``-inf`` count as 0; ``+inf`` and an answer of another shape are refused, as in a race.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import NeurohoverError, brief, finite_real
from .common import as_floats
from .races import MAX_RESAMPLING, RaceResult, SampleFn, check_int, check_room, check_sample_fn, draw_samples

__all__ = ["BANDITS", "MAX_BISECTIONS", "kl_bounds", "lucb_radius", "top_mu_bandit"]

#: The bandit selection rules: resampling ``lucb:DELTA`` and ``kl-lucb:DELTA`` (DELTA the error probability).
BANDITS = ("lucb", "kl-lucb")
KL_K1, KL_ALPHA = 405.5, 1.1
#: The most halvings :func:`kl_bounds` takes: 60 reach a float's precision, 1,100 its smallest step (10**13 ran on; T17-4).
MAX_BISECTIONS = 10_000


def lucb_radius(samples: np.ndarray, t: int, n: int, delta: float) -> np.ndarray:
    """LUCB1's confidence radius ``sqrt(ln(5 n t^4 / (4 delta)) / (2 u))`` for candidates with ``samples`` = u episodes each."""
    u = _sample_counts(samples)
    t, n = check_int("t", t, 1), check_int("n", n, 1)  # t=0 was a math domain error (thirteenth trial, F15)
    delta = _check_probability(delta)
    return np.sqrt(math.log(5.0 * n * float(t) ** 4 / (4.0 * delta)) / (2.0 * u))


def _sample_counts(samples: object) -> np.ndarray:
    """Each candidate's number of samples as float64, all >= 1 (0 was a ZeroDivisionError; thirteenth trial, F15)."""
    u = np.atleast_1d(as_floats(samples, "samples", "a 1-D array of sample counts >= 1"))
    if u.ndim != 1 or not np.all(np.isfinite(u) & (u >= 1) & (u == np.floor(u))):  # 1.5 samples was taken (fourteenth trial)
        raise NeurohoverError(f"samples={brief(u.tolist())} is not allowed: give a 1-D array of sample counts >= 1 (whole numbers)")
    return u


def _check_probability(delta: object) -> float:
    """An error probability strictly between 0 and 1 (lucb_radius took 2.0; thirteenth trial, F15)."""
    if not finite_real(delta) or not 0.0 < float(delta) < 1.0:  # type: ignore[arg-type]
        raise NeurohoverError(f"delta={brief(delta)} must be an error probability strictly between 0 and 1 (e.g. 0.1)")
    return float(delta)  # type: ignore[arg-type]


_EPS = 1e-15  # the KL divergence's means are kept this far inside (0, 1)


def kl_bounds(means: np.ndarray, samples: np.ndarray, level: float, iterations: int = 60) -> tuple[np.ndarray, np.ndarray]:
    """The KL confidence bounds ``min / max {q in [0, 1] : u d(p, q) <= level}`` of empirical means ``p`` over ``u``
    samples, by bisection (``iterations`` halvings, 1 to :data:`MAX_BISECTIONS`: within ``2**-iterations``).

    Both bounds of every candidate are bisected in one array (upper bounds first), so that each halving is one
    set of NumPy calls: each element takes the same operations as alone, and so the same bits."""
    p = np.atleast_1d(as_floats(means, "means", "a 1-D array of empirical means"))
    u = _sample_counts(samples)
    # Other lengths were NumPy's broadcast error (thirteenth trial, F15); 1.5 was clipped to 1, its lower bound below it (fourteenth).
    if p.shape != u.shape or not np.all((p >= 0.0) & (p <= 1.0)):
        raise NeurohoverError(
            f"means={brief(p.tolist())} is not allowed: give {u.size} finite mean(s), one per entry of samples, each in [0, 1] (rewards' range)"
        )
    if not finite_real(level) or level < 0:  # a negative level was taken silently
        raise NeurohoverError(f"level={brief(level)} is not allowed: give a finite number >= 0")
    iterations = check_int("iterations", iterations, 1, MAX_BISECTIONS, "halvings")  # -1 was taken silently: no halving at all
    n = p.size
    room = np.tile(float(level) / u, 2)
    up = np.arange(2 * n) < n  # the first half bisects upper bounds, the second lower ones
    lo = np.concatenate([p, np.zeros_like(p)])
    hi = np.concatenate([np.ones_like(p), p])
    pc = np.clip(np.concatenate([p, p]), _EPS, 1 - _EPS)
    pc_rest = 1 - pc
    for _ in range(iterations):
        mid = (lo + hi) / 2
        qc = np.clip(mid, _EPS, 1 - _EPS)
        inside = pc * np.log(pc / qc) + pc_rest * np.log(pc_rest / (1 - qc)) <= room  # the Bernoulli KL divergence d(p, q)
        raise_lo = inside == up  # an upper bound rises while inside, a lower one while outside
        lo, hi = np.where(raise_lo, mid, lo), np.where(raise_lo, hi, mid)
    return hi[n:], lo[:n]


def _rewards(x: np.ndarray) -> np.ndarray:
    """Episode fitness as a reward in [0, 1] (see the module docstring)."""
    r = np.asarray(x, dtype=np.float64)
    return np.clip(np.where(np.isfinite(r), r, 0.0), 0.0, 1.0)


def top_mu_bandit(sample_fn: SampleFn, n_candidates: int, mu: int, delta: float, *, rule: str = "lucb", t_limit: int = 10) -> RaceResult:
    """The ``mu`` best of ``n_candidates`` by LUCB1 (``rule="lucb"``) or KL-LUCB (``"kl-lucb"``) with error
    probability ``delta`` (``n_candidates`` >= 2, as many as fit in half the memory free), each candidate flying at
    most ``t_limit`` episodes (1 to 100,000,
    :data:`~neurohover.evolution.races.MAX_RESAMPLING`); ``sample_fn`` as for
    :func:`~neurohover.evolution.races.selection_race` (a candidate listed twice flies two episodes).

    Returns a :class:`~neurohover.evolution.races.RaceResult`: ``selected`` the mu of best mean when the rule
    stopped (``n_raced`` = mu when its bounds separated them, 0 when the episode limit ended it), ``means``,
    ``n_samples``, the last ``lower`` / ``upper`` bounds, ``rounds`` the rule's rounds.
    """
    n = check_int("n_candidates", n_candidates, 2)
    mu = check_int("mu", mu, 1)
    if mu >= n:
        raise NeurohoverError(f"mu={mu} must be smaller than n_candidates={n}")
    delta = _check_probability(delta)
    if not isinstance(rule, str) or rule not in BANDITS:
        raise NeurohoverError(f"rule={brief(rule)} is not a bandit rule: choose one of {', '.join(BANDITS)}")
    t_limit = check_int("t_limit", t_limit, 1, MAX_RESAMPLING)
    check_room(n, 0)  # per candidate arrays only: a round flies two candidates (10**13 was a MemoryError; T17-3)
    check_sample_fn(sample_fn)  # None was a TypeError (thirteenth trial, F14)
    sums = _rewards(draw_samples(sample_fn, np.arange(n))).copy()  # draw_samples: a race's check of the answer (its shape, +inf)  # every candidate once
    counts = np.ones(n, dtype=np.int64)
    rounds, separated = 0, False
    while True:
        t = int(counts.sum())
        means = sums / counts
        if rule == "lucb":
            radius = lucb_radius(counts, t, n, delta)
            lower, upper = means - radius, means + radius
        else:
            lower, upper = kl_bounds(means, counts, math.log(KL_K1 * n * t**KL_ALPHA / delta))
        order = np.argsort(-means, kind="stable")
        top, rest = order[:mu], order[mu:]
        low = int(top[np.argmin(lower[top])])
        high = int(rest[np.argmax(upper[rest])])
        if upper[high] < lower[low]:
            separated = True
            break
        fly = [i for i in (low, high) if counts[i] < t_limit]
        if not fly:
            break
        rounds += 1
        drawn = _rewards(draw_samples(sample_fn, np.asarray(fly, dtype=np.int64)))
        for i, r in zip(fly, drawn):
            sums[i] += r
            counts[i] += 1
    means = sums / counts
    selected = np.argsort(-means, kind="stable")[:mu]
    spent = int(counts.sum())
    return RaceResult(
        selected=selected.astype(np.int64),
        means=means,
        n_samples=counts,
        lower=lower,
        upper=upper,
        discarded=np.zeros(0, dtype=np.int64),
        n_raced=mu if separated else 0,
        episodes_spent=spent,
        rounds=rounds,
        episodes_flown=spent,
    )
