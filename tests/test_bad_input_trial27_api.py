"""Twenty-seventh bad-input trial, the API: T27-B08 (a NaN genome in a PolicyTable flies as a crash: documented, pinned
here), T27-B10 (an EpisodeOutcome with a positive return, a return below its steps' worst or a safeguard step past the
episode) and T27-B13 (mutate and crossover took NaN genomes and a negative scale)."""

from __future__ import annotations

import numpy as np
import pytest

import neurohover as nh
from neurohover.agents.protocol import EpisodeOutcome
from neurohover.errors import NeurohoverError
from neurohover.evolution.operators import crossover, mutate
from neurohover.evolution.steady_state import SteadyStateSettings
from neurohover.sim.constants import CRASH_STEP_PENALTY, WORST_RETURN


def test_a_nan_genome_in_a_policy_table_flies_as_a_crash() -> None:
    """T27-B08 is no bug: PolicyTable and from_genomes document that a non-finite genome is flown and crashes at once
    (an optimiser's diverged sample is scored, not a stopped run), where a Policy (a file's) refuses it. A table's
    padding past an SLP's 40 genes stays zero (T33-B10: anything else is an MLP row declared an SLP)."""
    mdp = nh.get_task_family("ghh08").mdp("train:0")
    padded = np.pad(np.full((1, 40), np.nan), ((0, 0), (0, 2)))  # an SLP row of a table MLPs share
    for table in (nh.PolicyTable.from_genomes(np.full((1, 40), np.nan), "slp"), nh.PolicyTable(np.array([0]), padded)):
        ev = nh.evaluate(table, mdp, n_steps=20)
        assert ev.returns.ravel().tolist() == pytest.approx([-CRASH_STEP_PENALTY * 19])  # a crash at step 1 of 20
        assert ev.crashed.ravel().tolist() == [True] and ev.steps.ravel().tolist() == [1]
    with pytest.raises(NeurohoverError, match="must hold finite numbers"):
        nh.Policy("slp", np.full(40, np.nan))


def _outcome(**change: object) -> EpisodeOutcome:
    fields: dict = {"episode": 0, "ret": -5.0, "crashed": False, "steps": 20, "safeguard_step": -1, "flight_data": None}
    return EpisodeOutcome(**{**fields, **change})


@pytest.mark.parametrize(
    ("change", "match"),
    [
        ({"ret": 5.0}, r"ret=5.0 is out of range: allowed -34976.\d+..0 for 20 steps that did not crash"),
        ({"ret": -1e30}, r"ret=-1e\+30 is out of range: allowed -34976.\d+..0 for 20 steps"),
        ({"ret": -1e30, "crashed": True}, r"ret=-1e\+30 is out of range: allowed -1.7488\d+e\+10..0 for an episode that crashed"),
        ({"safeguard_step": 99}, r"safeguard_step=99 of a 20-step episode is out of range: allowed -1 \(never\) or 0..steps-1"),
        ({"safeguard_step": 20}, r"safeguard_step=20 of a 20-step"),
    ],
    ids=["positive", "below-steps-worst", "below-worst-return", "safeguard-past", "safeguard-at-end"],
)
def test_an_episode_outcome_out_of_its_episode_is_refused(change: dict, match: str) -> None:
    """T27-B10: every reward is minus a sum of squares, at worst CRASH_STEP_PENALTY for a step within the crash limits; a
    crash is charged that for each step left of a budget of at most MAX_EPISODE_STEPS."""
    with pytest.raises(NeurohoverError, match=match):
        _outcome(**change)


def test_an_episode_outcome_at_its_bounds_is_taken() -> None:
    """The bounds themselves, and a crash's charge for the steps left of a longer budget, are an episode's."""
    assert _outcome(ret=0.0).ret == 0.0
    assert _outcome(ret=-CRASH_STEP_PENALTY * 20).steps == 20
    assert _outcome(ret=-CRASH_STEP_PENALTY * 19, crashed=True, steps=1).crashed  # a crash at step 1 of 20
    assert _outcome(ret=-WORST_RETURN, crashed=True, steps=1).crashed
    assert _outcome(safeguard_step=19).safeguard_step == 19


SETTINGS = SteadyStateSettings()


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda rng: mutate(np.full(40, np.nan), rng, SETTINGS), r"genome=.* is not allowed: a genome must hold finite numbers; genes \[0, 1,"),
        (lambda rng: mutate(np.r_[np.zeros(39), np.inf], rng, SETTINGS), r"genome=.* finite numbers; genes \[39\] are not"),
        (lambda rng: mutate(np.zeros(40), rng, SETTINGS, scale=-np.ones(40)), r"scale=.* is not allowed: give one finite number >= 0 per gene"),
        (lambda rng: mutate(np.zeros(40), rng, SETTINGS, scale=np.full(40, np.nan)), r"scale=.* give one finite number >= 0"),
        (lambda rng: crossover(np.full(40, np.nan), np.zeros(40), rng, SETTINGS), r"a=.* is not allowed: a genome must hold finite numbers"),
        (lambda rng: crossover(np.zeros(40), np.r_[np.nan, np.zeros(39)], rng, SETTINGS), r"b=.* finite numbers; genes \[0\] are not"),
    ],
    ids=["mutate-nan", "mutate-inf", "scale-negative", "scale-nan", "crossover-a", "crossover-b"],
)
def test_operators_refuse_non_finite_genomes(call, match: str) -> None:
    """T27-B13: NaN parents gave NaN children and a negative scale was taken, where Policy, SteadyStateNE and CMAES refuse."""
    with pytest.raises(NeurohoverError, match=match):
        call(np.random.default_rng(0))


def test_operators_take_finite_genomes_and_a_zero_scale() -> None:
    rng = np.random.default_rng(0)
    assert set(mutate(np.ones(40), rng, SETTINGS, scale=np.zeros(40)).tolist()) <= {0.0, 1.0}  # a zero scale: delta 0
    assert np.isfinite(crossover(np.ones(40), np.zeros(40), rng, SETTINGS)).all()
