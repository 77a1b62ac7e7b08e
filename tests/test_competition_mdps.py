"""The competitions' MDP sets and the competition software's wind clock (docs/model.md, Task families)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from neurohover import NeurohoverError, baseline_policy, evaluate_jobs, get_task_family
from neurohover.sim.kernel import competition_time
from neurohover.sim.reference import competition_time as reference_time
from neurohover.sim.reference import fly_episode
from neurohover.sim.rng import episode_normals
from neurohover.tasks import COMPETITION_MDPS_FILE


def _file() -> dict:
    return json.loads(COMPETITION_MDPS_FILE.read_text())


@pytest.mark.parametrize("task", ["ghh08", "ghh09", "fghh"])
def test_train_and_test_sets_are_the_competition_mdps(task: str) -> None:
    family = get_task_family(task)
    rows = _file()[task]
    scale = 5.0 if task == "ghh08" else 1.0  # GHH-08's file lists the wind as values in [-1, 1]
    for kind, mdps in (("train", family.training_mdps()), ("test", family.test_mdps())):
        assert len(mdps) == len(rows[kind]) == (10 if kind == "train" else 100)
        for i, mdp in enumerate(mdps):
            got = mdp.params if task == "fghh" else mdp.wind
            np.testing.assert_allclose(got, np.array(rows[kind][i]) * scale, rtol=0, atol=1e-12)
            assert mdp.label == f"{task}/{kind}:{i}"
            assert family.mdp(f"{kind}:{i}") == mdp


def test_shipped_file_holds_the_authors_values() -> None:
    # A few values as the authors' mdp.py lists them (0-based), so an edited file cannot pass.
    rows = _file()
    assert rows["ghh08"]["train"][0] == [-0.98273, 0.631781]
    assert rows["ghh09"]["train"][1][:2] == [0.720038, 0.635304]
    assert rows["fghh"]["train"][0][4] == -44.18
    assert get_task_family("ghh08").training_mdps()[0].wind == pytest.approx((-4.91365, 3.158905))


def test_seeded_sets_stay_available_under_their_own_name() -> None:
    family = get_task_family("ghh09")
    seeded = family.seeded_training_mdps()
    assert len(seeded) == 10 and len(family.seeded_test_mdps()) == 100
    assert family.mdp("seeded-train:9") == seeded[9] and seeded[9].label == "ghh09/seeded-train:9"
    assert seeded[0] != family.training_mdps()[0]
    assert family.seeded_training_mdps() == seeded  # fixed, not redrawn


def test_fghh_at_another_sigma_uses_its_seeded_sets() -> None:
    family = get_task_family("fghh", 0.2)
    assert not family.has_competition_sets and get_task_family("fghh", 0.3).has_competition_sets
    assert family.training_mdps() == family.seeded_training_mdps()
    assert family.mdp("test:5") == family.seeded_test_mdps()[5]
    # the sigma-0.2 draws are narrower than the competition's sigma-0.3 rows
    spread = lambda mdps: np.std([m.params for m in mdps], axis=0) / np.abs(mdps[0].params).clip(1e-9)  # noqa: E731
    assert np.median(spread(family.test_mdps())) < np.median(spread(get_task_family("fghh").test_mdps()))


@pytest.mark.parametrize(
    ("spec", "message"),
    [
        ("seeded-train:10", r"out of range: allowed 0\.\.9"),
        ("seeded-test:100", r"out of range: allowed 0\.\.99"),
        ("seeded:1", "seeded-train:N"),
        ("competition:0", "seeded-train:N"),
    ],
)
def test_bad_mdp_names_are_refused(spec: str, message: str) -> None:
    with pytest.raises(NeurohoverError, match=message):
        get_task_family("ghh08").mdp(spec)


def test_wind_clock_is_floored_exactly_as_the_competition_software() -> None:
    early = 0
    for k in range(6000):
        for i in range(10):
            t = 0.1 * k + 0.01 * i
            want = int(t * 100) / 100.0
            assert competition_time(k, i) == want == reference_time(k, i)
            early += want < (10 * k + i) / 100.0 - 1e-9
    assert 0.02 < early / 60000 < 0.06  # about 4% of substeps land 0.01 s early


def test_no_phase_without_frequency() -> None:
    # freq = 0: the wind is the centre value whatever the phase (the competition sets phi = 0).
    family = get_task_family("ghh09")
    with_phase = family.make([0.9, 0.0, 0.3, 0.2, 0.1, 0.0, 0.8, 0.6])
    without = family.make([0.9, 0.0, 0.0, 0.2, 0.1, 0.0, 0.0, 0.6])
    other = family.make([0.9, 0.0, 0.3, 0.2, 0.1, 0.0, 0.8, 0.7])
    ev = evaluate_jobs([baseline_policy()], [with_phase, without, other], [0, 0, 0], [0, 1, 2], [5, 5, 5], seed=3, n_steps=300)
    assert ev.returns[0] == ev.returns[1] != ev.returns[2]  # same gusts: only the wind could differ
    assert with_phase.to_reference().wind_at(0.0) == pytest.approx((0.2 * 5, 0.6 * 5, 0.0))


def test_kernel_matches_reference_on_a_fast_competition_wind() -> None:
    # A fast wind makes the 0.01 s floor visible: kernel and reference must floor the same way.
    mdp = get_task_family("ghh09").make([0.9, 1.0, 0.3, 0.2, 0.1, 0.9, 0.8, 0.6])
    n_steps, episode, seed = 300, 4, 11
    ev = evaluate_jobs([baseline_policy()], mdp, [0], [0], [episode], seed=seed, record=[True], n_steps=n_steps)
    normals = episode_normals(np.uint64(seed), np.uint64(episode), n_steps)
    ref_return, _, ref_obs = fly_episode(mdp.to_reference(), baseline_policy().act, normals.tolist(), n_steps)
    np.testing.assert_allclose(ev.flight_data.observations[0], np.array(ref_obs), rtol=1e-7, atol=1e-9)
    assert ev.returns[0] == pytest.approx(ref_return, rel=1e-8)
