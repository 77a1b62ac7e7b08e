"""Bad-input trial 55, side B (misc): T55-B05, T55-B09, T55-B11, T55-B12.

T55-B05: a user family's make() answered an MDP outside the family's param_bounds, which rows() refused.
T55-B09: Store.put took a unit its experiment's config does not plan; every reader then refused the experiment.
T55-B11: the vector env's two seed refusals stated two different ranges for one seed.
T55-B12: integrations.flying.checked_obs_statistics took a masked mean at its hidden values.
"""

from __future__ import annotations

import dataclasses
import re
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest
from store_edits import competed_store

import neurohover as nh
from neurohover.errors import NeurohoverError
from neurohover.sim.constants import DEFAULT_PARAMS, PARAM_NAMES, ROW_PARAMS
from neurohover.tasks import TASK_FAMILIES
from neurohover.tasks.base import MDP, TaskFamily, finite_vector


@pytest.fixture(scope="module")
def heavy():
    """A user family of the 11 dynamics parameters, each within (-100, 100), whose make does not check them."""

    def make(self, params, label=""):
        return MDP("bounded55", params=tuple(finite_vector(params, 11, "heavy params").tolist()), label=label)

    def sample_params(self, rng, n):
        out = np.repeat(DEFAULT_PARAMS[None, :], n, axis=0)
        out[:, 4] *= rng.uniform(0.5, 1.0, n)
        return out

    ns = dict(
        name="bounded55", n_params=11, param_names=PARAM_NAMES, row_slice=ROW_PARAMS, set_code=551, param_bounds=(-100.0, 100.0),
        make=make, zero=lambda self: MDP("bounded55", label="bounded55/zero"), sample_params=sample_params, __module__=__name__,
    )  # fmt: skip
    TASK_FAMILIES["bounded55"] = dataclasses.dataclass(frozen=True)(type("Bounded55", (TaskFamily,), ns))
    yield nh.get_task_family("bounded55")
    del TASK_FAMILIES["bounded55"]


def test_make_refuses_an_answer_outside_the_familys_param_bounds(heavy) -> None:
    """T55-B05: make(p) with D_r = 150 was flown, where rows() of the same p refused it; the bounds' edges are taken."""
    p = DEFAULT_PARAMS.copy()
    p[10] = 150.0
    with pytest.raises(
        NeurohoverError, match=re.escape("is out of range: its D_r=150.0 lies outside the family's param_bounds; each parameter must lie in [-100, 100] (C_u")
    ):
        heavy.make(p)
    p[10] = 100.0
    assert heavy.make(p).params[10] == 100.0
    assert nh.get_task_family("ghh08").make([5.0, -5.0]).wind == (5.0, -5.0)
    assert nh.get_task_family("ghh09").make([0.0] * 4 + [1.0] * 4).wind[-1] == 1.0


@pytest.fixture(scope="module")
def compete_store(tmp_path_factory) -> Path:
    return competed_store(tmp_path_factory.mktemp("t55"))


@pytest.mark.parametrize(
    "key, problem",
    [
        ("zzz", "its key is of no shape a test_runs experiment plans: its unit keys are policy/<name> or run/<group>/<mdps><i>/rep<r>"),
        ("run/baseline/test99/rep0", "its key names MDP test99, but its params fly the MDP labelled 'ghh08/test:0'"),
        ("run/bo9/test0/rep0", "its key names group 'bo9', but its params' group is 'baseline'"),
        ("run/baseline/test0/rep1", "its config plans no such test run (no such group, MDP or repetition)"),
        ("policy/x", "its key names a policy unit, whose kind is 'evolve' or 'safety', not 'test_run'"),
    ],
)
def test_put_refuses_a_unit_the_config_does_not_plan(compete_store: Path, tmp_path: Path, key: str, problem: str) -> None:
    """T55-B09: such a unit was stored (put returned True), and export_results, results and report then refused the whole
    experiment as damaged; now put refuses it, by key, and the experiment still exports."""
    from neurohover.experiments import Store, Unit, export_results

    store = Store(compete_store)
    try:
        (name, scale, config_hash, _) = store.experiments()[0]
        u0 = store.units(name, scale)[0]
        with pytest.raises(NeurohoverError, match=re.escape(f"put: unit {key!r} is not allowed: {problem}; give a unit of the plan of {name} ({scale})")):
            store.put(name, scale, config_hash, Unit(name, key, "test_run", u0["params"]), u0["result"], 1.0)
        assert [u["key"] for u in store.units(name, scale)] == [u0["key"]]
        assert store.put(name, scale, config_hash, Unit(name, u0["key"], "test_run", u0["params"]), u0["result"], 1.0) is False
        assert export_results(store, name).count("\n") == 2
    finally:
        store.close()


def test_the_vector_envs_seed_refusals_state_one_range() -> None:
    """T55-B11: the not-allowed refusal offered 0..2**63-1, which the out-of-range one refused for 3 sub-environments."""
    vec = gym.make_vec("neurohover/GHH08-v0", num_envs=3, vectorization_mode="vector_entry_point", episode_steps=20)
    with pytest.raises(NeurohoverError, match=re.escape("seed=1.5 is not allowed: give None, an integer in 0..2**63-3, or a list of 3 integers in 0..2**63-1")):
        vec.reset(seed=1.5)
    with pytest.raises(NeurohoverError, match=re.escape("is out of range: allowed an integer in 0..2**63-3")):
        vec.reset(seed=2**63 - 1)


def test_checked_obs_statistics_refuses_a_masked_array() -> None:
    """T55-B12: a masked mean was taken at its hidden values."""
    from neurohover.integrations.flying import checked_obs_statistics

    masked = np.ma.masked_array(np.full(12, 7.0), mask=True)
    for mean, var, name in ((masked, np.ones(12), "mean"), (np.zeros(12), masked, "var")):
        with pytest.raises(NeurohoverError, match=re.escape(f"v.pkl holds a {name} that is not an array of 12 real numbers (a masked array: give")):
            checked_obs_statistics(mean, var, 12, "v.pkl")
