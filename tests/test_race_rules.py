"""The race rules of issue 32: the printed Algorithm 1 and the authors' FGHH loop, against plain references written
from their texts (objects in Python lists, bounds from scipy's bayes_mvs), on tables of samples where a candidate's
t-th episode is fixed (as an evolution run's is)."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import table_sampler
from scipy import stats

from neurohover.errors import NeurohoverError
from neurohover.evolution import selection_race
from neurohover.evolution.config import parse_resampling
from neurohover.experiments import Store, reproduce, write_report
from neurohover.experiments.config import load_config, make_config
from neurohover.experiments.executors import make_executor
from neurohover.experiments.plans import plan

LAMBDA, MU, T_LIMIT = 50, 20, 10


class _Candidate:
    def __init__(self, index: int, row: np.ndarray) -> None:
        self.index, self.row, self.evals = index, row, []

    def fly(self) -> None:
        self.evals.append(float(self.row[len(self.evals)]))

    def bounds(self, delta: float) -> None:
        self.mean = float(np.mean(self.evals))
        if np.all(np.asarray(self.evals) == self.evals[0]):
            self.lb = self.ub = self.mean
        else:
            self.lb, self.ub = stats.bayes_mvs(self.evals, alpha=delta)[0].minmax


def reference_race(table: np.ndarray, mu: int, delta: float, skip: bool) -> tuple[list[int], int, int]:
    """Algorithm 1 (lines 1-27, 34-39) as printed, its loop in the authors' Python when ``skip``:
    ``for i, x in enumerate(U): ... U.pop(i)``. Returns (selected before capping, episodes, rounds)."""
    pool = [_Candidate(i, row) for i, row in enumerate(table)]
    n = len(pool)
    undecided, chosen, dropped = list(pool), [], []
    for x in undecided:
        x.fly()
    t, episodes = 1, n
    while t < T_LIMIT and len(chosen) < mu:
        t += 1
        for x in undecided:
            x.fly()
            x.bounds(delta)
        episodes += len(undecided)
        if skip:
            for i, x in enumerate(undecided):  # as the authors wrote it: pop while enumerating
                if sum(x.lb > y.ub for y in undecided) >= n - mu - len(dropped):
                    chosen.append(undecided.pop(i))
                elif sum(x.ub < y.lb for y in undecided) >= mu - len(chosen):
                    dropped.append(undecided.pop(i))
        else:
            for x in list(undecided):  # every undecided candidate once, the sets changing as it goes
                if sum(x.lb > y.ub for y in undecided) >= n - mu - len(dropped):
                    chosen.append(x)
                    undecided.remove(x)
                elif sum(x.ub < y.lb for y in undecided) >= mu - len(chosen):
                    dropped.append(x)
                    undecided.remove(x)
        if not undecided:
            break
    return [x.index for x in chosen], episodes, t


def _table(seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return rng.normal(0.0, 1.0, LAMBDA)[:, None] + rng.normal(0.0, 1.5, (LAMBDA, T_LIMIT))


@pytest.mark.slow
@pytest.mark.parametrize("rule", ["algorithm1", "authors"])
@pytest.mark.parametrize("seed", range(6))
def test_a_rule_matches_its_reference(rule: str, seed: int) -> None:
    table = _table(seed)
    picked, episodes, rounds = reference_race(table, MU, 0.5, skip=rule == "authors")
    race = selection_race(table_sampler(table), LAMBDA, MU, 0.5, t_limit=T_LIMIT, rule=rule)
    assert race.episodes_spent == episodes and race.rounds == rounds
    assert race.over_selected == max(0, len(picked) - MU)
    raced = sorted(picked, key=lambda i: -race.means[i])[:MU]  # the mu best of those selected
    assert set(race.selected[: race.n_raced].tolist()) == set(raced)
    assert len(set(race.selected.tolist())) == MU


@pytest.mark.slow
def test_the_rules_decide_differently_and_the_look_ahead_changes_nothing() -> None:
    """On 100 random races (candidates' spread 1, episodes' 0.3) Algorithm 1 spends other episodes than the prose
    rule in some, and the authors' loop picks other parents than Algorithm 1 in many."""
    differs = {"algorithm1": 0, "authors": 0}
    for seed in range(100):
        rng = np.random.default_rng(seed)
        table = rng.normal(0.0, 1.0, LAMBDA)[:, None] + rng.normal(0.0, 0.3, (LAMBDA, T_LIMIT))
        prose = selection_race(table_sampler(table), LAMBDA, MU, 0.5, t_limit=T_LIMIT)
        alg1 = selection_race(table_sampler(table), LAMBDA, MU, 0.5, t_limit=T_LIMIT, rule="algorithm1")
        authors = selection_race(table_sampler(table), LAMBDA, MU, 0.5, t_limit=T_LIMIT, rule="authors")
        ahead = selection_race(table_sampler(table), LAMBDA, MU, 0.5, t_limit=T_LIMIT, rule="authors", batch=200)
        assert ahead.selected.tolist() == authors.selected.tolist() and ahead.episodes_spent == authors.episodes_spent
        differs["algorithm1"] += alg1.episodes_spent != prose.episodes_spent
        differs["authors"] += set(authors.selected) != set(alg1.selected)
    assert 0 < differs["algorithm1"] < 20 and differs["authors"] > 10


def test_race_rules_are_named_in_the_resampling_spec() -> None:
    assert str(parse_resampling("race:0.5")) == "race:0.5"  # the prose rule: specs (and config hashes) as before
    spec = parse_resampling("race:0.5:algorithm1")
    assert (spec.kind, spec.delta, spec.rule, str(spec)) == ("race", 0.5, "algorithm1", "race:0.5:algorithm1")
    assert parse_resampling("race:0.2:authors").rule == "authors"
    with pytest.raises(NeurohoverError, match="'fastest' is not a race rule: allowed prose, algorithm1, authors"):
        parse_resampling("race:0.5:fastest")
    with pytest.raises(ValueError, match="rule='x' is not a race rule"):
        selection_race(table_sampler(_table(0)), LAMBDA, MU, 0.5, rule="x")


def test_fig15_rules_runs_take_the_seeds_and_validation_of_figure_15s_races() -> None:
    rules = {u.key: u.params for u in plan(load_config("fig15-rules", "paper"), {}).units}
    fig15 = {u.key: u.params for u in plan(load_config("fig15", "paper"), {}).units}
    assert len(rules) == 4 * 24
    for rule in ("alg1", "authors"):
        for delta in ("0.2", "0.5"):
            mine, theirs = rules[f"evolve/race{delta}-{rule}/run7"], fig15[f"evolve/race{delta}/run7"]
            assert mine["seed"] == theirs["seed"] and mine["validation_seed"] == theirs["validation_seed"]
            assert mine["resampling"] == f"race:{delta}:{'algorithm1' if rule == 'alg1' else 'authors'}"
    base = {"task": "fghh", "seed": 1, "target": "family", "runs": 1, "variants": [{"key": "a", "label": "a", "paired_with": "k5"}]}
    with pytest.raises(NeurohoverError, match="set paired_with: give the experiment's seeds_of too"):
        make_config("x", "evolution", "quick", base)
    with pytest.raises(NeurohoverError, match=r"seeds_of = .* is not allowed: expected a table \{experiment = NAME, seed = ITS ROOT SEED\}"):
        make_config("x", "evolution", "quick", {**base, "seeds_of": {"experiment": "fig15"}})


@pytest.mark.slow
def test_the_report_pairs_each_rules_run_with_figure_15s(tmp_path) -> None:
    small = {"runs": 2, "budget": 400, "n_steps": 50, "validation_episodes": 4}
    with Store(tmp_path / "s.sqlite") as store:
        executor = make_executor("local", jobs=1)
        try:
            for name in ("fig15", "fig15-rules"):
                reproduce(load_config(name, "quick", small), store, executor, progress=False)
        finally:
            executor.close()
        write_report(store, tmp_path / "out", names=["fig15-rules"])
    text = (tmp_path / "out" / "report.md").read_text()
    block = text[text.index("### Paired with fig15") :]
    rows = [line for line in block.splitlines() if line.startswith("| races")]
    assert len(rows) == 2 and all("| fig15/race0.5 | 2 |" in r for r in rows)
    assert "vs fig15's fixed, k = 5 (mean validation 1/ln(error), Welch)" in text
