"""The SIMD-lanes path (neurohover/sim/lanes.py) flies the same bits as the scalar kernel.

The reference is always the raw scalar ``rollout_batch``, never the dispatch of ``evaluate_jobs``.
The lanes reproduce the FMAs that LLVM forms in the scalar kernel by hand, so these tests are
what catches a numba/LLVM upgrade or a kernel edit that changes the kernel's FMA pattern.
"""

from __future__ import annotations

import numpy as np
import pytest

from neurohover import baseline_policy, evaluate, evaluate_jobs, get_task_family, prototype
from neurohover.evaluate import PolicyTable, _use_lanes, num_threads
from neurohover.sim.constants import SAFEGUARD_LIMITS
from neurohover.sim.kernel import POLICY_SLP, rollout_batch
from neurohover.sim.lanes import LANES, fly_lanes, rollout_lanes

ZERO = get_task_family("fghh").zero().row()
COARSE = ZERO.copy()
COARSE[17], COARSE[18] = 1, 0.1  # one substep of 0.1 s, as a learned model flies
MLP = PolicyTable.from_policies([prototype("mlp", "baseline")])


def _perturbed(scale: float, seed: int = 5) -> PolicyTable:
    return PolicyTable(MLP.kinds.copy(), MLP.genomes + np.random.default_rng(seed).normal(size=MLP.genomes.shape) * scale)


def _non_finite() -> PolicyTable:
    g = MLP.genomes.copy()
    g[0, 11] = np.inf
    return PolicyTable(MLP.kinds.copy(), g)


def _spinning() -> PolicyTable:
    g = np.zeros_like(MLP.genomes)
    g[0, 38], g[0, 36] = 1.0, 0.3  # SLP: constant yaw and roll drive, more than SERIES_MAX_ANGLE a substep
    return PolicyTable(np.array([POLICY_SLP], dtype=np.int64), g)


def _scalar(table: PolicyTable, row: np.ndarray, seed: int, episodes: np.ndarray, n_steps: int):
    """The scalar kernel's rollout_batch, called directly."""
    n = episodes.shape[0]
    zeros = np.zeros(n, dtype=np.int64)
    minus = np.full(n, -1, dtype=np.int64)
    r, c, s, sg = np.empty(n), np.empty(n, dtype=np.bool_), np.empty(n, dtype=np.int64), np.empty(n, dtype=np.int64)
    rollout_batch(
        row[None, :], table.kinds, table.genomes, zeros, zeros, episodes, minus, np.uint64(seed), n_steps, False, SAFEGUARD_LIMITS, minus,
        np.zeros((0, 1, 12)), np.zeros((0, 1, 4)), r, c, s, sg,
    )  # fmt: skip
    return r, c, s, sg


def _lanes(table: PolicyTable, row: np.ndarray, seed: int, episodes: np.ndarray, n_steps: int, threads: int):
    n = episodes.shape[0]
    r, c, s, sg = np.empty(n), np.empty(n, dtype=np.bool_), np.empty(n, dtype=np.int64), np.full(n, 7, dtype=np.int64)
    with num_threads(threads):
        rollout_lanes(row.copy(), table.kinds[0], table.genomes[0].copy(), np.uint64(seed), episodes, n_steps, threads, r, c, s, sg)
    return r, c, s, sg


def _assert_same(a, b) -> None:
    assert np.array_equal(a[0].view(np.int64), b[0].view(np.int64)), np.abs(a[0] - b[0]).max()
    assert np.array_equal(a[1], b[1])
    assert np.array_equal(a[2], b[2])
    assert np.array_equal(a[3], b[3])


CASES = {
    "zero MLP": (MLP, ZERO),
    "zero SLP baseline": (PolicyTable.from_policies([baseline_policy()]), ZERO),
    "crashing MLP": (_perturbed(0.08), ZERO),
    "wild MLP": (PolicyTable(MLP.kinds.copy(), MLP.genomes + np.random.default_rng(3).normal(size=MLP.genomes.shape) * 0.5), ZERO),
    "non-finite action": (_non_finite(), ZERO),
    "1 substep, perturbed MLP": (_perturbed(0.06), COARSE),
    "spinning SLP": (_spinning(), ZERO),
    "spinning SLP, 1 substep": (_spinning(), COARSE),
}
for _fam in ("ghh08", "ghh09"):
    for _m in get_task_family(_fam).test_mdps()[:2]:
        CASES[f"{_m.label} MLP"] = (MLP, _m.row())


@pytest.mark.parametrize("name", list(CASES))
@pytest.mark.parametrize("threads", [1, 2])
def test_lanes_bit_identical_to_scalar_kernel(name: str, threads: int) -> None:
    table, row = CASES[name]
    episodes = np.arange(3, 3 + 2 * LANES + 3, dtype=np.int64)  # not a multiple of LANES
    ref = _scalar(table, row, 11, episodes, 6000)
    _assert_same(_lanes(table, row, 11, episodes, 6000, threads), ref)


@pytest.mark.parametrize("n_jobs", [1, LANES - 1, LANES, LANES + 1, 3 * LANES, 5 * LANES + 3])
@pytest.mark.parametrize("threads", [1, 2])
def test_batch_sizes(n_jobs: int, threads: int) -> None:
    table = _perturbed(0.06)  # crashes at various steps, so the lane queue refills
    episodes = np.random.default_rng(n_jobs).permutation(1000)[:n_jobs].astype(np.int64)
    _assert_same(_lanes(table, ZERO, 4, episodes, 800, threads), _scalar(table, ZERO, 4, episodes, 800))


def test_cases_cover_crashes_non_finite_actions_and_the_fallback() -> None:
    ep = np.arange(2 * LANES, dtype=np.int64)
    for name, crash_steps in (("crashing MLP", None), ("non-finite action", 1)):
        _, c, s, _ = _scalar(*CASES[name], 0, ep, 6000)
        assert c.any(), name
        assert crash_steps is None or (s == crash_steps).all()
    _, c, s, _ = _scalar(*CASES["crashing MLP"], 0, ep, 6000)
    assert len(set(s[c].tolist())) > 1  # lanes end at different steps
    for name in ("spinning SLP, 1 substep",):  # with 10 substeps it crashes on its rate before turning that far
        table, row = CASES[name]
        n = 2
        stats = np.zeros(2, dtype=np.int64)
        fly_lanes(
            row, table.kinds[0], table.genomes[0], np.uint64(0), ep[:n], 200, np.empty(n), np.empty(n, dtype=np.bool_), np.empty(n, dtype=np.int64), stats
        )
        assert stats[1] > 0, name  # the large-angle scalar fallback ran


def test_evaluate_jobs_dispatch() -> None:
    n = 2 * LANES + 1
    p, m, fb, rec = np.zeros(n, dtype=np.int64), np.zeros(n, dtype=np.int64), np.full(n, -1, dtype=np.int64), np.zeros(n, dtype=bool)
    assert _use_lanes("cpu", p, m, fb, rec)
    assert not _use_lanes("cuda", p, m, fb, rec)
    assert not _use_lanes("cpu", p[: LANES - 1], m[: LANES - 1], fb[: LANES - 1], rec[: LANES - 1])
    for arr, value in ((p, 1), (m, 1), (fb, 0), (rec, True)):
        arr[-1] = value
        assert not _use_lanes("cpu", p, m, fb, rec)
        arr[-1] = np.zeros(1, dtype=arr.dtype)[0] if arr is not fb else -1
    # Through evaluate_jobs and evaluate: the same bits as the scalar kernel, safeguard step -1.
    table, row = CASES["crashing MLP"]
    ep = np.arange(n, dtype=np.int64)
    ev = evaluate_jobs(table, row[None, :], np.zeros(n, dtype=np.int64), np.zeros(n, dtype=np.int64), ep, seed=9, n_steps=3000)
    _assert_same((ev.returns, ev.crashed, ev.steps, ev.safeguard_step), _scalar(table, row, 9, ep, 3000))
    ev = evaluate(table, row[None, :], episodes=n, seed=9, n_steps=3000)
    _assert_same((ev.returns.reshape(-1), ev.crashed.reshape(-1), ev.steps.reshape(-1), ev.safeguard_step.reshape(-1)), _scalar(table, row, 9, ep, 3000))
