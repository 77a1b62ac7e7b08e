"""Typed unit results (neurohover/experiments/results.py): every result of the committed results
store reads back and writes out exactly as stored, timing takes no part in ==, bad dicts are
refused, and the one parser of unit keys."""

from __future__ import annotations

import json
import re
import shutil
import sqlite3
from pathlib import Path

import pytest

from neurohover.errors import NeurohoverError
from neurohover.experiments import load_config, plan, run_unit, strip_timing
from neurohover.experiments.results import (
    RESULT_TYPES,
    EvolveResult,
    RobustnessResult,
    StoredPolicy,
    TestRunResult,
    UnitKey,
    result_from_dict,
)
from neurohover.experiments.store import _dumps


def _stored(path: Path, *where: str):
    with sqlite3.connect(path) as conn:
        return conn.execute("SELECT name, scale, key, kind, result FROM units" + (" WHERE " + where[0] if where else ""), where[1:]).fetchall()


def _round_trip(rows) -> set[str]:
    """Each stored result read as its type and written out again, to the same dict and the same text; the kinds seen."""
    kinds = set()
    for name, scale, key, kind, text in rows:
        d = json.loads(text)
        result = result_from_dict(kind, d, key)
        assert isinstance(result, RESULT_TYPES[kind])
        assert result.to_dict() == d, (name, scale, key)
        assert _dumps(result.to_dict()) == text, (name, scale, key)  # same keys in the same order: stored identically
        kinds.add(kind)
    return kinds


@pytest.mark.slow
def test_stored_results_of_every_experiment_and_kind_round_trip_exactly(committed_store: Path) -> None:
    """The first 10 units (by key) of every experiment, scale and kind; the whole store, which grows with every paper-scale
    run, is the paper-marked test below (python3 -m pytest -m paper)."""
    with sqlite3.connect(committed_store) as conn:
        rows = conn.execute(
            "SELECT name, scale, key, kind, result FROM (SELECT *, row_number() OVER (PARTITION BY name, scale, kind ORDER BY key) AS n "
            "FROM units) WHERE n <= 10"
        ).fetchall()
        experiments = conn.execute("SELECT COUNT(DISTINCT name || '/' || scale) FROM units").fetchone()[0]
    assert _round_trip(rows) == set(RESULT_TYPES) - {"diagnostic"}
    assert len({(name, scale) for name, scale, *_ in rows}) == experiments > 50


@pytest.mark.paper
def test_every_stored_result_round_trips_exactly(committed_store: Path) -> None:
    rows = _stored(committed_store)
    assert _round_trip(rows) == set(RESULT_TYPES) - {"diagnostic"} and len(rows) > 1000


def test_units_store_their_typed_result(committed_store: Path) -> None:
    """A unit returns its typed result's to_dict(): it reads back into the same result."""
    stored = {k: json.loads(t) for _, _, k, _, t in _stored(committed_store, "name = ? AND scale = ?", "fig2", "quick")}
    unit = next(u for u in plan(load_config("fig2", "quick"), stored).units if u.kind == "robustness")
    result = run_unit(unit)
    assert list(result) == ["returns", "crashes", "own"]
    assert RobustnessResult.from_dict(result).to_dict() == result
    d = run_unit({"experiment": "x", "key": "k", "kind": "diagnostic", "params": {"value": [1, {"a": 2}], "seed": 3}})
    assert d == {"value": [1, {"a": 2}], "seed": 3} and result_from_dict("diagnostic", d).to_dict() == d


def _evolve_dict(**changes) -> dict:
    d = {
        "champion": {"topology": "slp", "genome": [0.5, -1.0]},
        "champion_return": -12.5,
        "episodes": 40,
        "evaluations": 40,
        "generations": 4,
        "stop_reason": "budget",
        "champion_crashed": False,
        "history": [[1, "-inf"], [40, -12.5]],
        "validation": [-13.0, "nan"],
        "timing": {"seconds": 1.25, "kernel_seconds": 0.5},
    }
    d.update(changes)
    return {k: v for k, v in d.items() if v is not None}


def test_timing_takes_no_part_in_equality() -> None:
    a = EvolveResult.from_dict(_evolve_dict())
    assert a == EvolveResult.from_dict(_evolve_dict(timing={"seconds": 9.0, "kernel_seconds": 8.0}))
    assert a != EvolveResult.from_dict(_evolve_dict(champion_return=-12.0, history=[[1, "-inf"], [40, -12.0]]))  # its history ends at it (T23-08)
    assert a.champion == StoredPolicy("slp", (0.5, -1.0)) and a.history == ((1, "-inf"), (40, -12.5))
    assert a.final_score != a.final_score  # nan in the validation returns stays nan
    # keys that older stores lack stay absent
    old = _evolve_dict(champion_crashed=None, validation=None)
    r = EvolveResult.from_dict(old)
    assert r.champion_crashed is None and r.validation is None and r.to_dict() == old and r.final_score == -12.5


def test_bad_result_dicts_are_refused() -> None:
    with pytest.raises(NeurohoverError, match="missing key.*stop_reason"):
        EvolveResult.from_dict({k: v for k, v in _evolve_dict().items() if k != "stop_reason"})
    with pytest.raises(NeurohoverError, match="unknown key.*surprise"):
        EvolveResult.from_dict(_evolve_dict(surprise=1))
    with pytest.raises(NeurohoverError, match="timing: expected a JSON object"):
        EvolveResult.from_dict(_evolve_dict(timing=[1.0, 2.0]))
    with pytest.raises(NeurohoverError, match="unknown unit kind 'nope'"):
        result_from_dict("nope", {})
    with pytest.raises(NeurohoverError, match="must be a TestRunTiming"):
        TestRunResult(
            agent="a",
            mdp="m",
            score=0.0,
            returns=[],
            crash_episodes=[],
            safeguard_episodes=[],
            policy_changes=[],
            learning_episodes=0,
            mean_return_after_learning=0.0,
            timing={"seconds": 1.0, "offline_seconds": 0.0},
        )


@pytest.mark.parametrize(
    "key, parts",
    [
        ("evolve/mlp-baseline/train3/run7", ("evolve", "mlp-baseline", "train3", 7)),
        ("evolve/race0.2/run0", ("evolve", "race0.2", None, 0)),
        ("robust/slp-zero/train9", ("robust", "slp-zero", "train9", None)),
        ("policy/generic", ("policy", "generic", None, None)),
        ("policy/generic-race1", ("policy", "generic-race1", None, None)),
        ("model/lr-gls/test12", ("model", "lr-gls", "test12", None)),
        ("run/hybrid-baseline/sample4/rep2", ("run", "hybrid-baseline", "sample4", 2)),
        ("run/a/b/train0/rep1", ("run", "a/b", "train0", 1)),  # a group label with a slash
        ("good", ("", "", None, None)),
    ],
)
def test_unit_keys_parse(key: str, parts: tuple) -> None:
    k = UnitKey.parse(key)
    assert (k.stage, k.group, k.mdp, k.rep) == parts and k.key == key
    assert k.mdp_index == (None if k.mdp is None else int(k.mdp.lstrip("abcdefghijklmnopqrstuvwxyz")))


def test_the_mdp_index_is_the_number_in_the_mdp_part() -> None:
    assert UnitKey.parse("model/lr-gls/test12").mdp_index == 12
    assert UnitKey.parse("run/a/b/train0/rep1").mdp_index == 0
    assert UnitKey.parse("policy/generic-race1").mdp_index is None


@pytest.mark.slow
def test_export_and_report_read_typed_results(committed_store: Path, tmp_path: Path) -> None:
    """The CSV gains the key's parts from UnitKey; a result the types refuse is named in the report, in its experiment's place."""
    import csv
    import io

    from neurohover.experiments import Store, export_results, write_report

    with Store(committed_store, create=False) as store:
        rows = list(csv.DictReader(io.StringIO(export_results(store, "fig8", "csv", "quick"))))
    run = next(r for r in rows if r["key"] == "run/hybrid/train0/rep0")
    assert (run["group"], run["mdp"], run["rep"]) == ("hybrid", "train0", "0")
    assert int(run["result.returns.n"]) > 0 and float(run["result.timing.seconds"]) > 0
    generic = next(r for r in rows if r["key"] == "policy/generic")
    assert generic["result.champion.topology"] == "mlp" and int(generic["result.champion.genome.n"]) == 42
    broken = shutil.copy(committed_store, tmp_path / "broken.sqlite")  # the module's store stays intact
    with sqlite3.connect(broken) as conn:
        conn.execute("UPDATE units SET result = ? WHERE name = 'fig15' AND scale = 'quick' AND key = 'evolve/k5/run0'", (json.dumps({"champion_return": 1.0}),))
    with Store(broken, create=False) as store:
        report = write_report(store, tmp_path / "report", scale="quick", names=["fig15"]).read_text()
    assert re.search(r"Not reported: the store's copy is damaged\.\*\* .*evolve/k5/run0.*missing key", report)


@pytest.mark.slow
def test_unit_keys_are_made_and_parsed_by_one_scheme() -> None:
    from neurohover.experiments.config import load_config, shipped_configs
    from neurohover.experiments.plans import plan
    from neurohover.experiments.results import UnitKey

    for name in shipped_configs():
        for unit in plan(load_config(name, "paper"), {}).units:
            k = UnitKey.parse(unit.key)
            assert k.stage and UnitKey.make(k.stage, k.group, k.mdp, k.rep) == unit.key
    assert UnitKey.make("run", "hybrid", "train3", 2) == "run/hybrid/train3/rep2"
    with pytest.raises(ValueError, match="do not fit the key scheme"):
        UnitKey.make("robust", "k5", "test3")  # robustness units fly training MDPs only
    with pytest.raises(ValueError, match="unknown unit stage 'evolved'"):
        UnitKey.make("evolved", "k5")


#: Stored units that run again in seconds, each finished before a feature that must leave results as they were:
#: test runs (model-free, incremental, hybrid with its safeguard), an LR model, a GHH-08 robustness test, a
#: fixed-resampling and two race evolutions, and the authors' FGHH agent. Exact sensors, no drift and races
#: that park their episodes (all later) give the stored bits.
REPLAYED = [
    ("fig7", "paper", "run/incremental/test99/rep0"),
    ("fig8", "paper", "run/model-free/train6/rep1"),
    ("fig2", "quick", "robust/mlp-baseline/train0"),
    ("fig15", "quick", "evolve/k5/run2"),
    ("fig15", "quick", "evolve/race0.5/run1"),
    ("fig15", "quick", "evolve/race0.5/run2"),
    ("fig16", "quick", "run/authors-race/test1/rep0"),
]


# Result fields added after units were stored (a stored unit lacks them; run again, it has them)
RECORDED_SINCE = {"test_w_sd"}


#: Replayed with ``-m paper`` only: a hybrid run and a Table 4 model, about 8 s of the default suite's 4 minutes.
REPLAYED_SLOW = [
    ("fig11", "paper", "run/hybrid/test1/rep0"),
    ("table4", "paper", "model/lr/test67"),
]


@pytest.mark.slow
def test_stored_units_run_again_to_their_stored_results(committed_store: Path) -> None:
    replay(committed_store, REPLAYED)


@pytest.mark.paper
def test_slower_stored_units_run_again_to_their_stored_results(committed_store: Path) -> None:
    replay(committed_store, REPLAYED_SLOW)


def replay(committed_store: Path, units: list[tuple[str, str, str]]) -> None:
    """Each stored unit of ``units`` run again: its result equals the stored one (timings aside)."""
    with sqlite3.connect(committed_store) as conn:
        for name, scale, key in units:
            row = conn.execute("SELECT kind, params, result FROM units WHERE name = ? AND scale = ? AND key = ?", (name, scale, key)).fetchone()
            assert row is not None, (name, scale, key)
            kind, params, stored = row
            unit = {"experiment": name, "key": key, "kind": kind, "params": json.loads(params)}
            again, before = strip_timing(run_unit(unit, threads=2)), strip_timing(json.loads(stored))
            assert set(again) - set(before) <= RECORDED_SINCE, (name, scale, key)  # a unit now records more, never less
            assert {k: again[k] for k in before} == before, (name, scale, key)


def test_a_crash_rate_is_never_shown_as_zero_when_an_episode_crashed() -> None:
    from neurohover.experiments.report_testruns import crash_rate

    assert [crash_rate(c, 20_000) for c in (0, 1, 30, 200, 10_687, 20_000)] == ["0%", "0.005%", "0.15%", "1%", "53%", "100%"]


@pytest.mark.slow
def test_runs_paired_with_their_own_copies_are_called_the_same_runs(committed_store: Path, tmp_path: Path) -> None:
    """wind-fig8's wind-blind groups are Figure 8's runs again: the report said "as good in the median pair (0 of 80
    runs better, ..., Wilcoxon p = 1, not significant)", a test where there is nothing to test."""
    from neurohover.experiments import Store, write_report

    with Store(committed_store, create=False) as store:
        report = write_report(store, tmp_path / "report", scale="paper", names=["wind-fig8"]).read_text()
    assert "model-free/wind-blind vs fig8's model-free on the same seeds: the same runs, all 80 pairs equal" in report
    assert "| model-free/wind-blind | fig8/model-free | 80 |" in report and "none: all 80 equal" in report
    assert re.search(r"incremental/wind-aware vs fig8's incremental on the same seeds: (better|worse) in the median pair", report)
