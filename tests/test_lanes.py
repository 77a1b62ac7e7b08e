"""The SIMD-lanes path (neurohover/sim/lanes.py) flies the same bits as the scalar kernel.

The reference is always the raw scalar ``rollout_batch``, never the dispatch of ``evaluate_jobs``.
The lanes reproduce the FMAs that LLVM forms in the scalar kernel by hand, so these tests are
what catches a numba/LLVM upgrade or a kernel edit that changes the kernel's FMA pattern.
"""

from __future__ import annotations

import numpy as np
import pytest

from neurohover import baseline_policy, evaluate, evaluate_jobs, get_task_family, prototype
from neurohover.evaluate import KernelFlyer, PolicyTable, num_threads
from neurohover.launch import use_lanes as _use_lanes
from neurohover.policies import GENOME_LENGTH
from neurohover.sim.constants import ROW_DT, ROW_SUBSTEPS, ROW_WIND_KIND, SAFEGUARD_LIMITS
from neurohover.sim.jobs import Extras, Flown, Jobs, Parking
from neurohover.sim.kernel import POLICY_SLP, rollout_batch
from neurohover.sim.lanes import LANES, SCALAR_TAIL, fly_lanes, rollout_lanes, rollout_lanes_parked
from neurohover.tasks import Sensor

ZERO_MDP = get_task_family("fghh").zero()
ZERO = ZERO_MDP.row()
COARSE = ZERO.copy()
COARSE[ROW_SUBSTEPS], COARSE[ROW_DT] = 1, 0.1  # one substep of 0.1 s, as a learned model flies
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


def _scalar(table: PolicyTable, row: np.ndarray, seed: int, episodes: np.ndarray, n_steps: int, p=None, m=None):
    """The scalar kernel's rollout_batch, called directly; ``row`` one row or (M, MDP_ROW_LEN) rows, p and m
    the jobs' policy and row indices (default 0)."""
    n = episodes.shape[0]
    zeros = np.zeros(n, dtype=np.int64)
    p = zeros if p is None else p
    m = zeros if m is None else m
    out = Flown.empty(n)
    rollout_batch(Jobs(np.atleast_2d(row), table.kinds, table.genomes, p, m, episodes, np.uint64(seed), n_steps), Extras.none(n, SAFEGUARD_LIMITS), out)
    return tuple(out)


def _lanes(table: PolicyTable, row: np.ndarray, seed: int, episodes: np.ndarray, n_steps: int, threads: int, p=None, m=None):
    n = episodes.shape[0]
    zeros = np.zeros(n, dtype=np.int64)
    rows = np.atleast_2d(row).copy()
    p = zeros if p is None else p
    m = zeros if m is None else m
    out = Flown(np.empty(n), np.empty(n, dtype=np.bool_), np.empty(n, dtype=np.int64), np.full(n, 7, dtype=np.int64))
    with num_threads(threads):
        rollout_lanes(Jobs(rows, table.kinds, table.genomes.copy(), p, m, episodes, np.uint64(seed), n_steps), threads, out)
    return tuple(out)


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
# Sensor models: readings from kernel.sense, scalar per lane (white, correlated, late, and a crashing policy on them).
_SENSED = get_task_family("ghh09").test_mdps()[0]
CASES["white sensors MLP"] = (MLP, _SENSED.with_sensor(Sensor.at_level(1.0)).row())
CASES["correlated late sensors baseline"] = (PolicyTable.from_policies([baseline_policy()]), _SENSED.with_sensor(Sensor.at_level(1.5, 0.9, 2)).row())
CASES["late sensors, crashing MLP"] = (_perturbed(0.06), ZERO_MDP.with_sensor(Sensor(delay=4)).row())


@pytest.mark.parametrize("name", list(CASES))
@pytest.mark.parametrize("threads", [1, 2])
def test_lanes_bit_identical_to_scalar_kernel(name: str, threads: int) -> None:
    table, row = CASES[name]
    episodes = np.arange(3, 3 + 2 * LANES + 3, dtype=np.int64)  # not a multiple of LANES
    ref = _scalar(table, row, 11, episodes, 6000)
    _assert_same(_lanes(table, row, 11, episodes, 6000, threads), ref)


def test_lanes_bit_identical_with_rows_that_sense_and_rows_that_do_not() -> None:
    other = get_task_family("fghh").test_mdps()[3]  # rows alike in substeps and wind, as the lanes need
    rows = np.stack([ZERO, other.with_sensor(Sensor.at_level(1.0, 0.5, 1)).row(), other.row()])
    table = _perturbed(0.06)
    n = 3 * LANES + 2
    episodes = np.arange(n, dtype=np.int64)
    m = np.arange(n, dtype=np.int64) % 3
    _assert_same(_lanes(table, rows, 5, episodes, 1500, 2, m=m), _scalar(table, rows, 5, episodes, 1500, m=m))


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
        n = SCALAR_TAIL + 1  # more lanes in flight than the per-lane tail, so the steps are packed
        stats = np.zeros(2, dtype=np.int64)
        z = np.zeros(n, dtype=np.int64)
        fly_lanes(Jobs(row[None, :], table.kinds, table.genomes, z, z, ep[:n], np.uint64(0), 200), Flown.empty(n), stats)
        assert stats[1] > 0, name  # the large-angle scalar fallback ran


def test_evaluate_jobs_dispatch() -> None:
    n = 2 * LANES + 1
    rows = np.stack([ZERO, ZERO])
    m, fb, rec = np.zeros(n, dtype=np.int64), np.full(n, -1, dtype=np.int64), np.zeros(n, dtype=bool)
    assert _use_lanes("cpu", rows, m, fb, rec)
    assert _use_lanes("cpu", rows, m)
    assert not _use_lanes("cuda", rows, m, fb, rec)
    assert not _use_lanes("cpu", rows, m[: LANES - 1], fb[: LANES - 1], rec[: LANES - 1])
    for arr, value in ((fb, 0), (rec, True)):
        arr[-1] = value
        assert not _use_lanes("cpu", rows, m, fb, rec)
        arr[-1] = np.zeros(1, dtype=arr.dtype)[0] if arr is not fb else -1
    m[-1] = 1
    assert _use_lanes("cpu", rows, m, fb, rec)  # different rows (and policies) are fine
    wind = get_task_family("ghh09").test_mdps()[0].row()
    for other in (COARSE, wind):  # a row with another substep count or with wind: the scalar kernel
        mixed = np.stack([ZERO, other])
        assert not _use_lanes("cpu", mixed, m, fb, rec)
        assert _use_lanes("cpu", mixed, np.zeros(n, dtype=np.int64), fb, rec)  # row 1 unused
        assert _use_lanes("cpu", mixed, np.ones(n, dtype=np.int64), fb, rec)
    # Through evaluate_jobs and evaluate: the same bits as the scalar kernel, safeguard step -1.
    table, row = CASES["crashing MLP"]
    ep = np.arange(n, dtype=np.int64)
    ev = evaluate_jobs(table, row[None, :], np.zeros(n, dtype=np.int64), np.zeros(n, dtype=np.int64), ep, seed=9, n_steps=3000)
    _assert_same((ev.returns, ev.crashed, ev.steps, ev.safeguard_step), _scalar(table, row, 9, ep, 3000))
    ev = evaluate(table, row[None, :], episodes=n, seed=9, n_steps=3000)
    _assert_same((ev.returns.reshape(-1), ev.crashed.reshape(-1), ev.steps.reshape(-1), ev.safeguard_step.reshape(-1)), _scalar(table, row, 9, ep, 3000))


FGHH = [get_task_family("fghh", 0.3).sample(np.random.default_rng(i)).row() for i in range(4)]
GHH08 = [mdp.row() for mdp in get_task_family("ghh08").test_mdps()[:3]]
GHH09 = [mdp.row() for mdp in get_task_family("ghh09").test_mdps()[:3]]
_MIXED = [MLP, _perturbed(0.08), _perturbed(0.5, 3), PolicyTable.from_policies([baseline_policy()]), _spinning(), _non_finite()]
MIXED_POLICIES = PolicyTable(np.concatenate([t.kinds for t in _MIXED]), np.concatenate([t.genomes for t in _MIXED]))  # MLP and SLP genomes
MIXED_ROWS = {"fghh samples": FGHH, "ghh08 winds": GHH08, "ghh09 winds": GHH09, "fghh 1 substep": [np.r_[r[:17], 1, 0.1, r[19:]] for r in FGHH]}


@pytest.mark.parametrize("rows_name", list(MIXED_ROWS))
@pytest.mark.parametrize("n_jobs", [LANES + 3, 4 * LANES + 5])
@pytest.mark.parametrize("threads", [1, 2])
def test_mixed_policies_and_mdps(rows_name: str, n_jobs: int, threads: int) -> None:
    """Each lane its own genome (MLP and SLP, crashing, non-finite, spinning) and its own MDP row."""
    rows = np.stack(MIXED_ROWS[rows_name])
    rng = np.random.default_rng(n_jobs)
    p = rng.integers(0, len(MIXED_POLICIES), n_jobs)
    m = rng.integers(0, rows.shape[0], n_jobs)
    ep = rng.permutation(10_000)[:n_jobs].astype(np.int64)
    ref = _scalar(MIXED_POLICIES, rows, 7, ep, 3000, p, m)
    assert ref[1].any() and not ref[1].all()
    assert n_jobs < 2 * LANES or len(set(ref[2][ref[1]].tolist())) > 1  # episodes end at different steps
    _assert_same(_lanes(MIXED_POLICIES, rows, 7, ep, 3000, threads, p, m), ref)


def test_mixed_rows_really_differ() -> None:
    for name, rows in MIXED_ROWS.items():
        a = np.stack(rows)
        assert (a[:, [0, 1, 3, 5, 7, 9]].std(axis=0) > 0).any() or (a[:, 19:28].std(axis=0) > 0).any(), name
    assert all(r[ROW_WIND_KIND] != 0 for r in GHH08 + GHH09)


def test_rollout_lanes_refuses_rows_it_cannot_pack() -> None:
    ep = np.arange(LANES, dtype=np.int64)
    m = np.arange(LANES, dtype=np.int64) % 2
    for other in (COARSE, GHH09[0]):
        with pytest.raises(ValueError):
            _lanes(MLP, np.stack([ZERO, other]), 0, ep, 10, 1, m=m)


def test_evaluate_jobs_and_kernel_flyer_mixed() -> None:
    """evaluate_jobs and KernelFlyer.fly take the lanes for mixed batches and give the scalar kernel's bits."""
    rows = np.stack(FGHH)
    n = 3 * LANES + 2
    rng = np.random.default_rng(2)
    p = rng.integers(0, len(MIXED_POLICIES), n)
    m = rng.integers(0, rows.shape[0], n)
    ep = np.arange(n, dtype=np.int64)
    ref = _scalar(MIXED_POLICIES, rows, 9, ep, 2000, p, m)
    ev = evaluate_jobs(MIXED_POLICIES, rows, p, m, ep, seed=9, n_steps=2000, threads=2)
    _assert_same((ev.returns, ev.crashed, ev.steps, ev.safeguard_step), ref)
    mlp = np.flatnonzero(MIXED_POLICIES.kinds == MLP.kinds[0])
    sel = np.isin(p, mlp)
    pm = np.searchsorted(mlp, p[sel])
    genomes = MIXED_POLICIES.genomes[mlp][:, : GENOME_LENGTH["mlp"]]
    flyer = KernelFlyer("mlp", 9, 2000)
    with num_threads(2):
        flyer.start()
        ret = flyer.fly(genomes, rows, pm, m[sel], int(sel.sum())).copy()
    ref = _scalar(MIXED_POLICIES, rows, 9, np.arange(int(sel.sum()), dtype=np.int64), 2000, p[sel], m[sel])
    assert np.array_equal(ret.view(np.int64), ref[0].view(np.int64))
    assert np.array_equal(flyer.crashed, ref[1])


def _parked_calls(table, rows, m, episodes, n_steps, threads, plan) -> tuple:
    """Fly the jobs in several calls of rollout_lanes_parked: ``plan`` gives each call's number of required
    jobs, taken from the jobs not over yet (parked first), every other job not over being optional."""
    n = episodes.shape[0]
    r, c, s = np.zeros(n), np.zeros(n, dtype=np.bool_), np.zeros(n, dtype=np.int64)
    parking = Parking.empty(n + 3)
    slot = np.arange(n, dtype=np.int64) + 3  # slots need not be job numbers
    over = np.zeros(n, dtype=bool)
    resumed = 0
    with num_threads(threads):
        for n_req in [*plan, n]:
            waiting = np.flatnonzero(~over)
            if waiting.size == 0:
                break
            waiting = waiting[np.argsort(-parking.steps[slot[waiting]], kind="stable")]  # parked ones required first
            resumed += int((parking.steps[slot[waiting[:n_req]]] > 0).sum())
            jobs = waiting
            out = Flown.empty(jobs.size)
            batch = Jobs(rows, table.kinds, table.genomes, np.zeros(jobs.size, dtype=np.int64), m[jobs], episodes[jobs], np.uint64(5), n_steps)
            rollout_lanes_parked(batch, slot[jobs], min(n_req, jobs.size), threads, parking, out)
            done = out.steps > 0
            assert done[: min(n_req, jobs.size)].all()  # every required job is over
            r[jobs[done]], c[jobs[done]], s[jobs[done]] = out.returns[done], out.crashed[done], out.steps[done]
            over[jobs[done]] = True
    return (r, c, s, np.full(n, -1, dtype=np.int64)), resumed


@pytest.mark.parametrize("threads", [1, 2])
@pytest.mark.parametrize(
    "rows",
    [
        np.stack([m.row() for m in get_task_family("fghh").test_mdps()[:3]]),
        np.stack([m.row() for m in get_task_family("ghh09").test_mdps()[:3]]),
        np.stack([_SENSED.with_sensor(Sensor.at_level(1.5, 0.9, 2)).row(), _SENSED.row()]),
    ],
    ids=["fghh", "ghh09 winds", "sensors"],
)
def test_parked_episodes_resume_to_the_same_bits(rows: np.ndarray, threads: int) -> None:
    """An optional episode in flight when a call's required ones are over is parked and resumed by a
    later call; every job's return, crash flag and steps are the scalar kernel's, bit for bit."""
    table = _perturbed(0.05)  # crashes at various steps
    n = 5 * LANES + 3
    episodes = np.random.default_rng(2).permutation(500)[:n].astype(np.int64)
    m = np.arange(n, dtype=np.int64) % rows.shape[0]
    ref = _scalar(table, rows, 5, episodes, 700, m=m)
    got, resumed = _parked_calls(table, rows, m, episodes, 700, threads, [3, 2 * LANES, 5])
    _assert_same(got, ref)
    # Some episode was parked mid-flight and finished by a later call (on one thread where it stops is fixed;
    # on two it depends on when the other thread's required jobs end).
    assert resumed > 0 or threads > 1


@pytest.mark.parametrize("n_jobs", [2, 5, LANES + 3])
def test_a_few_parked_jobs_on_two_threads_keep_their_bits(n_jobs: int) -> None:
    """Under 2 * LANES jobs a parked call still takes a lane set on every thread (a race's last rounds):
    each thread then flies part of the few jobs, and every result is the scalar kernel's."""
    table = _perturbed(0.05)
    rows = np.stack([m.row() for m in get_task_family("fghh").test_mdps()[:3]])
    episodes = np.arange(n_jobs, dtype=np.int64) * 7 + 1
    m = np.arange(n_jobs, dtype=np.int64) % rows.shape[0]
    got, _ = _parked_calls(table, rows, m, episodes, 700, 2, [1, 2])
    _assert_same(got, _scalar(table, rows, 5, episodes, 700, m=m))


def test_a_parked_call_flies_optional_jobs_only_in_idle_lanes_and_counts_them_not_over() -> None:
    table = _perturbed(0.0)  # the hovering baseline: every episode runs its full length
    n = 3 * LANES
    episodes = np.arange(n, dtype=np.int64)
    parking = Parking.empty(n)
    out = Flown.empty(n)
    with num_threads(1):
        zeros = np.zeros(n, dtype=np.int64)
        rollout_lanes_parked(Jobs(np.atleast_2d(ZERO), table.kinds, table.genomes, zeros, zeros, episodes, np.uint64(1), 300), episodes, LANES, 1, parking, out)
    # The LANES required episodes fill the lanes to their common end: no optional job began.
    assert (out.steps[:LANES] == 300).all() and (out.steps[LANES:] == 0).all() and (parking.steps == 0).all()
