"""Kernel fidelity: the compiled kernel agrees with the plain-Python reference, step by step."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import stats

from neurohover import (
    MDP,
    DangerousState,
    NeurohoverError,
    Policy,
    PolicyTable,
    Safeguard,
    baseline_policy,
    evaluate,
    evaluate_jobs,
    get_task_family,
    prototype,
)
from neurohover.sim.constants import CRASH_STEP_PENALTY, EPISODE_STEPS, MAX_RATE, MAX_VELOCITY, MDP_ROW_LEN, MIN_QW
from neurohover.sim.reference import fly_episode
from neurohover.sim.rng import episode_normals

SEED = 7


def _mlp_policy(rng_seed: int = 0) -> Policy:
    # A perturbed baseline-equivalent MLP exercises every weight while staying airborne.
    rng = np.random.default_rng(rng_seed)
    g = prototype("mlp", "baseline").genome + rng.normal(0, 0.01, 42)
    return Policy("mlp", g)


def _learned_model_mdp() -> MDP:
    rng = np.random.default_rng(3)
    params = get_task_family("fghh").zero().params
    return MDP("model", params=tuple(np.array(params) * rng.uniform(0.9, 1.1, 11)), substeps=1, dt=0.1, label="model", d_u=0.3)


CASES = {
    "ghh08": get_task_family("ghh08").training_mdps()[0],
    "ghh09": get_task_family("ghh09").training_mdps()[0],
    "fghh": get_task_family("fghh", 0.3).training_mdps()[0],
    "zero": get_task_family("ghh08").zero(),
    "model": _learned_model_mdp(),
}


@pytest.mark.parametrize("case", sorted(CASES))
@pytest.mark.parametrize("policy", [baseline_policy(), _mlp_policy()], ids=["baseline", "mlp"])
def test_kernel_matches_reference_step_by_step(case: str, policy: Policy) -> None:
    mdp = CASES[case]
    n_steps, episode = 400, 11
    ev = evaluate_jobs([policy], mdp, [0], [0], [episode], seed=SEED, record=[True], n_steps=n_steps)
    normals = episode_normals(np.uint64(SEED), np.uint64(episode), n_steps)
    ref_return, ref_crash, ref_obs = fly_episode(mdp.to_reference(), policy.act, normals.tolist(), n_steps)
    kernel_obs = ev.flight_data.observations[0]
    assert kernel_obs.shape == (len(ref_obs), 12)
    np.testing.assert_allclose(kernel_obs, np.array(ref_obs), rtol=1e-7, atol=1e-9)
    assert ev.crashed[0] == ref_crash
    assert ev.returns[0] == pytest.approx(ref_return, rel=1e-8)
    # The policy saw exactly those observations and applied these (clipped) actions.
    acts = ev.flight_data.actions[0]
    expected = np.clip([policy.act(o) for o in ref_obs[:-1]], -1, 1)
    np.testing.assert_allclose(acts, expected, rtol=1e-7, atol=1e-9)


def test_wind_actually_differs_between_families() -> None:
    # Guards against a kernel that ignores wind: the same noise gives different flights.
    fam08, fam09 = get_task_family("ghh08"), get_task_family("ghh09")
    mdps = [fam08.zero(), fam08.make([4.0, -3.0]), fam09.make([0.9, 0.5, 0.2, 0.1, 0.8, 0.3, 0.7, 0.6])]
    ev = evaluate(baseline_policy(), mdps, episodes=1, seed=SEED, n_steps=500)
    r = ev.returns.ravel()
    assert len(set(r.tolist())) == 3
    assert r[0] > r[1] and r[0] > r[2]  # wind makes hovering harder for the baseline


def test_baseline_flies_zero_setting_near_minus_1000() -> None:
    ev = evaluate(baseline_policy(), get_task_family("ghh08").zero(), episodes=16, seed=SEED)
    assert not ev.crashed.any()
    assert (ev.steps == EPISODE_STEPS).all()
    assert -1150 < ev.returns.mean() < -850


def test_mlp_baseline_seed_acts_exactly_like_baseline() -> None:
    mdp = get_task_family("ghh08").training_mdps()[2]
    ev = evaluate([baseline_policy(), prototype("mlp", "baseline")], mdp, episodes=3, seed=SEED)
    np.testing.assert_array_equal(ev.returns[0], ev.returns[1])


def test_crash_penalty_and_episode_length() -> None:
    # The zero policy gives no collective: the helicopter falls past 5 m/s within a second.
    climber = prototype("slp", "zero")
    ev = evaluate(climber, get_task_family("fghh").zero(), episodes=1, seed=SEED)
    t = int(ev.steps[0, 0, 0])
    assert ev.crashed[0, 0, 0] and 1 < t < 200
    normals = episode_normals(np.uint64(SEED), np.uint64(0), EPISODE_STEPS)
    ref_return, ref_crash, ref_obs = fly_episode(get_task_family("fghh").zero().to_reference(), climber.act, normals.tolist())
    assert ref_crash and len(ref_obs) == t + 1
    # The crashing step is charged the worst reward for every remaining step, itself included.
    penalty = -CRASH_STEP_PENALTY * (EPISODE_STEPS - t)
    rewards_before = ev.returns[0, 0, 0] - penalty
    assert rewards_before < 0 and rewards_before > -CRASH_STEP_PENALTY * t
    assert ev.returns[0, 0, 0] == pytest.approx(ref_return, rel=1e-9)
    assert CRASH_STEP_PENALTY == pytest.approx(3 * 400 + 3 * (4 * math.pi) ** 2 + 3 * 25 + (1 - math.cos(math.radians(15)) ** 2))
    assert CRASH_STEP_PENALTY * (EPISODE_STEPS - 1) == pytest.approx(1.049e7, rel=1e-3)


def test_non_finite_action_is_a_crash_with_full_penalty() -> None:
    table = PolicyTable.from_policies([prototype("mlp", "baseline")])  # a table: a Policy's genes are bounded (T30-B01)
    g = table.genomes.copy()
    g[0, 3] = 1.7e308  # bias of L1
    g[0, 15 + 6] = 1.7e308  # hy -> L1: the sum overflows to inf, and so does a1
    ev = evaluate(PolicyTable(table.kinds, g), get_task_family("ghh08").zero(), episodes=2, seed=SEED, record=True)
    assert ev.crashed.all() and (ev.steps == 1).all()
    np.testing.assert_array_equal(ev.returns.ravel(), -CRASH_STEP_PENALTY * (EPISODE_STEPS - 1))
    assert not np.isfinite(ev.flight_data.actions[0][0, 0])


def test_results_do_not_depend_on_threads_batch_size_or_order() -> None:
    fam = get_task_family("ghh09")
    mdps = fam.training_mdps()[:4]
    pols = [baseline_policy(), _mlp_policy(1)]
    rng = np.random.default_rng(0)
    n = 24
    p_idx, m_idx, e_idx = rng.integers(0, 2, n), rng.integers(0, 4, n), rng.integers(0, 1000, n)
    a = evaluate_jobs(pols, mdps, p_idx, m_idx, e_idx, seed=SEED, n_steps=600, threads=1)
    b = evaluate_jobs(pols, mdps, p_idx, m_idx, e_idx, seed=SEED, n_steps=600, threads=2)
    perm = rng.permutation(n)
    c = evaluate_jobs(pols, mdps, p_idx[perm], m_idx[perm], e_idx[perm], seed=SEED, n_steps=600)
    single = evaluate_jobs(pols, mdps, p_idx[:1], m_idx[:1], e_idx[:1], seed=SEED, n_steps=600)
    np.testing.assert_array_equal(a.returns, b.returns)
    np.testing.assert_array_equal(a.returns[perm], c.returns)
    assert single.returns[0] == a.returns[0]
    other_seed = evaluate_jobs(pols, mdps, p_idx, m_idx, e_idx, seed=SEED + 1, n_steps=600)
    assert not np.array_equal(other_seed.returns, a.returns)


def test_episode_streams_are_standard_normal_and_independent() -> None:
    z = episode_normals(np.uint64(1), np.uint64(0), 50_000).ravel()
    assert stats.kstest(z, "norm").pvalue > 1e-3
    assert abs(z.mean()) < 0.01 and abs(z.std() - 1) < 0.01
    tail = np.mean(np.abs(z) > 3.6541528853610088)  # the ziggurat's tail region is exercised
    assert tail == pytest.approx(2 * stats.norm.sf(3.6541528853610088), rel=0.5)
    a = episode_normals(np.uint64(1), np.uint64(1), 5000).ravel()
    b = episode_normals(np.uint64(2), np.uint64(0), 5000).ravel()
    assert abs(np.corrcoef(z[:30000], a)[0, 1]) < 0.03
    assert abs(np.corrcoef(a, b)[0, 1]) < 0.05


def test_safeguard_hands_over_to_fallback() -> None:
    g = np.zeros(40)
    g[36] = 0.6  # constant aileron: rolls until the state is dangerous
    roller = Policy("slp", g)
    mdp = get_task_family("ghh08").zero()
    alone = evaluate(roller, mdp, episodes=3, seed=SEED)
    assert alone.crashed.all() and (alone.safeguard_step == -1).all()
    paper = Safeguard(baseline_policy(), DangerousState("paper"))  # the box test alone
    guarded = evaluate(roller, mdp, episodes=3, seed=SEED, safeguard=paper, record=True)
    assert (guarded.safeguard_step > 0).all() and not guarded.crashed.any()
    assert (guarded.steps == EPISODE_STEPS).all()
    # From the hand-over on, the fallback's actions are applied.
    fd = guarded.flight_data
    k = int(guarded.safeguard_step[0, 0, 0])
    obs, acts = fd.observations[0], fd.actions[0]
    assert np.max(np.abs(obs[k, :9])) > 0.5 and np.max(np.abs(obs[k - 1, :9])) <= 0.5
    np.testing.assert_allclose(acts[k : k + 50], np.clip([baseline_policy().act(o) for o in obs[k : k + 50]], -1, 1), rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(acts[:k, 0], 0.6)


def test_crash_limits_are_spec_values() -> None:
    assert MAX_VELOCITY == 5.0 and MAX_RATE == pytest.approx(4 * math.pi) and MIN_QW == pytest.approx(math.cos(math.radians(15)))


@pytest.mark.parametrize(
    "call, message",
    [
        (lambda: evaluate_jobs([baseline_policy()], get_task_family("ghh08").zero(), [1], [0], [0]), "policy_index holds 1"),
        (lambda: evaluate_jobs([baseline_policy()], get_task_family("ghh08").zero(), [0], [0, 0], [0]), "mdp_index has 2 entries"),
        (lambda: evaluate(baseline_policy(), get_task_family("ghh08").zero(), episodes=0), "episodes=0"),
        (lambda: evaluate(baseline_policy(), get_task_family("ghh08").zero(), seed=-1), "seed=-1"),
        (lambda: evaluate(baseline_policy(), np.zeros((1, 5))), f"shape (M, {MDP_ROW_LEN})"),
        (lambda: evaluate(baseline_policy(), get_task_family("ghh08").zero(), threads=999), "threads=999"),
        (lambda: Policy("mlp", np.zeros(40)), "mlp genome has 42 genes"),
        (lambda: Policy("rnn", np.zeros(40)), "unknown policy topology 'rnn'"),
        (lambda: Policy("slp", [np.nan] * 40), "finite"),
    ],
)
def test_bad_input_gets_clear_messages(call, message: str) -> None:
    with pytest.raises(NeurohoverError, match=message.replace("(", r"\(").replace(")", r"\)")):
        call()


def test_memory_is_proportional_to_the_batch_not_the_episode_length() -> None:
    import tracemalloc

    policy = baseline_policy()
    mdp = get_task_family("ghh08").zero()
    evaluate_jobs([policy], mdp, [0], [0], [0], seed=1, n_steps=2)  # load the kernel first
    n = 100_000
    zeros = np.zeros(n, dtype=np.int64)
    tracemalloc.start()
    ev = evaluate_jobs([policy], mdp, zeros, zeros, np.arange(n), seed=1, n_steps=3)
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    assert ev.returns.shape == (n,)
    # A few job-sized arrays (8 bytes per job each), nothing per step: a per-step array of the
    # 12-number observation alone would need 100,000 x 4 x 12 x 8 bytes = 38 MB.
    assert peak < 120 * n
