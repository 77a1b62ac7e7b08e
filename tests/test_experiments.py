"""Reproduction experiments: configs, unit seeds, the SQLite results store (incl. resume after
SIGKILL and Ctrl-C), results export, and a quick end-to-end subset with the report."""

from __future__ import annotations

import json
import os
import random
import signal
import sqlite3
import subprocess
import time
import warnings
from pathlib import Path

import numpy as np
import pytest
from conftest import finish_run, start_gated_run

from neurohover.cli import main
from neurohover.errors import NeurohoverError
from neurohover.experiments import (
    LocalExecutor,
    Store,
    experiment_names,
    export_results,
    load_config,
    plan,
    reproduce,
    run_unit,
    strip_timing,
    unit_seed,
    write_report,
)
from neurohover.experiments.config import CONFIG_DIR, parse_override
from neurohover.experiments.store import SCHEMA_VERSION

PAPER_EXPERIMENTS = ["fig2", "table4", "fig7", "fig8", "fig11", "fig12", "fig13", "fig15", "fig16"]
ABLATIONS = [
    "ablation-plateau",
    "ablation-hybrid",
    "ablation-fghh",
    "fig15-rules",
    "fig15-champion",
    "fig15-bandits",
    "fig15-uh-cma",
    "topology-ghh08",
    "topology-fghh",
    "fig16-slp-zero",
    "lr-authors-table4",
    "lr-authors-fig8",
    "lr-substeps-table4",
    "lr-substeps-fig8",
    "lr-noise-fig7",
    "lr-noise-fig11",
]
# the harder benchmarks of the paper's Section 7 (docs/benchmarks.md)
BENCHMARKS = ["bench-sensors", "bench-sensors-fallback", "bench-sensor-models", "bench-drift", "bench-drift-armed"]
BEYOND = ["wind-fig7", "wind-fig8", "wind-fig11", "risk-ghh09"]  # what the paper's conclusions predict and it could not run (docs/model.md)

# A small evolution experiment whose units take ~0.3 s each (for the interruption tests).
SLOW_CONFIG = """
name = "slowtest"
title = "interruption test"
kind = "evolution"
[settings]
task = "fghh"
sigma = 0.3
seed = 5
target = "family"
runs = 12
[[settings.variants]]
key = "k1"
label = "k = 1"
[scales.quick]
budget = 3000
n_steps = 200
[scales.paper]
budget = 3000
n_steps = 200
"""


def _write(tmp_path: Path, text: str, name: str = "exp.toml") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


# --------------------------------------------------------------------------------- configs


@pytest.mark.slow
def test_every_experiment_of_the_paper_is_shipped_at_both_scales() -> None:
    assert experiment_names() == PAPER_EXPERIMENTS + ABLATIONS + BENCHMARKS + BEYOND
    for name in PAPER_EXPERIMENTS + ABLATIONS + BENCHMARKS + BEYOND:
        for scale in ("quick", "paper"):
            cfg = load_config(name, scale)
            assert cfg.name == name and cfg.scale == scale and len(cfg.hash) == 16
            assert plan(cfg, {}).units, f"{name} {scale} plans no units"
    assert load_config("table3", "quick").name == "fig2"  # alias


@pytest.mark.parametrize(
    "name, total, check",
    [
        # Figure 2: 4 approaches x 10 training MDPs x 10 runs, plus Table 3 (2 topologies and the shipped set x 10 MDPs).
        ("fig2", 430, lambda s: s["runs"] == 10 and s["n_mdps"] == 10 and s["n_steps"] == 6000 and s["robustness_episodes"] == 10),
        # Table 4: 3 methods + the GLS option x 100 test MDPs, 5 test episodes; + the generic policy.
        (
            "table4",
            401,
            lambda s: (
                s["n_mdps"] == 100
                and s["test_episodes"] == 5
                and s["model_budget"] == 2000
                and s["ec_meno_budget"] == 0
                and s["methods"][2:] == ["lr", "lr-gls"]
            ),
        ),
        # Figure 7: 3 agents x 100 test MDPs x 1000 episodes; + generic and 10 specialised policies.
        ("fig7", 311, lambda s: s["episodes"] == 1000 and all(g["n_mdps"] == 100 for g in s["groups"])),
        # Figure 8: 3 agents x 80 runs (8 per training MDP); + policies and the safety test.
        ("fig8", 252, lambda s: all(g["n_mdps"] * g["runs_per_mdp"] == 80 and g["mdps"] == "train" for g in s["groups"])),
        # Figure 11: 60 + 60 runs on 20 MDPs, 300 hybrid-baseline runs on the 100 test MDPs; + policies.
        ("fig11", 432, lambda s: [g["n_mdps"] * g["runs_per_mdp"] for g in s["groups"]] == [60, 60, 300]),
        ("fig12", 96, lambda s: s["runs"] == 24 and s["sigma"] == 0.2 and s["budget"] == 500000),
        ("fig13", 96, lambda s: s["runs"] == 24 and s["sigma"] == 0.3),
        ("fig15", 120, lambda s: s["runs"] == 24 and s["variants"][0]["resampling"] == "fixed:5"),
        # Figure 16: 2 agents x 3 generics x 100 runs; the zero-setting generics (100) evolved here, the fixed
        # and race ones drawn from Figures 13 and 15's champions (no evolution runs of its own).
        (
            "fig16",
            700,
            lambda s: (
                s["generics_per_agent"] == 100
                and s["generics_from"] == {"fixed": "fig13/k5", "race": "fig15/best-race"}
                and s["episodes"] == 1000
                and s["model_budget"] == 2550
            ),
        ),
    ],
)
def test_paper_scale_follows_the_papers_protocol(name, total, check) -> None:
    cfg = load_config(name, "paper")
    assert plan(cfg, {}).total == total
    assert check(cfg.settings)


def test_unknown_experiment_lists_the_known_ones(cli, tmp_path: Path) -> None:
    with pytest.raises(NeurohoverError) as err:
        load_config("fig99", "quick")
    for name in PAPER_EXPERIMENTS:
        assert name in str(err.value)
    rc, _, stderr = cli("reproduce", "fig99", "--store", str(tmp_path / "s.sqlite"))
    assert rc == 2 and "unknown experiment 'fig99'" in stderr and "fig16" in stderr
    rc, out, _ = cli("reproduce", "--list")
    assert rc == 0 and out.split() == PAPER_EXPERIMENTS + ABLATIONS + BENCHMARKS + BEYOND


@pytest.mark.parametrize(
    "edit, message",
    [
        (lambda t: t.replace('target = "family"', 'target = "family"\nbudgett = 3'), "unknown setting(s) 'budgett'"),
        (lambda t: t.replace("runs = 12", 'runs = "twelve"'), "runs = 'twelve' is not allowed: expected an integer in 1..10000"),
        (lambda t: t.replace("runs = 12\n", ""), "missing required setting 'runs'"),
        (lambda t: t.replace('task = "fghh"', 'task = "ghh08"'), "sigma applies to task 'fghh' only"),
        (lambda t: t.replace('label = "k = 1"', 'label = "k = 1"\nresampling = "race:2"'), "race:DELTA[:RULE] (0 < DELTA < 1"),
        (lambda t: t.replace('kind = "evolution"', 'kind = "magic"'), "kind = 'magic' is not allowed"),
        (lambda t: t.replace("[scales.paper]", "[scales.huge]"), "unknown scale table(s) huge"),
        (lambda t: t + '\n[[settings.variants]]\nkey = "k1"\nlabel = "again"\n', "variant keys must be unique"),
        (lambda t: t.replace("runs = 12", "runs = [1"), "is not valid TOML"),
        # issue 37: a name that escapes the report's folder, an unknown [paper] key, a paper test naming nothing
        (lambda t: t.replace('name = "slowtest"', 'name = "../../escaped"'), "name = '../../escaped' is not allowed"),
        (lambda t: t.replace('name = "slowtest"', 'name = ""'), "name = '' is not allowed"),
        (lambda t: t + '\n[paper]\nnotez = ["x"]\n', "unknown [paper] key(s) 'notez'; allowed: notes"),
        (lambda t: t + '\n[paper]\nttests = [{ a = "k1", b = "k9", p = "0.01" }]\n', "[paper] ttests names 'k9' (b)"),
        (lambda t: t + "\n[paper]\ntable3 = { k9 = { r = 1.0 } }\n", "[paper] table3 names 'k9', which is no group"),  # was never shown
        # second trial: a string of claims was reported letter by letter, a p-value of "banana" printed as the paper's
        (lambda t: t + '\n[paper]\nclaims = "hello"\n', "[paper] claims = 'hello' is not allowed: give a list of strings"),
        # the settings before the [paper] table: an unknown variant resampling is named, not a t test that names nothing
        (lambda t: t.replace('key = "k1"', 'key = "k1"\nresampling = "fixed:0"') + '\n[paper]\nttests = [{ a = "k1", b = "k9", p = "0.01" }]\n', "fixed:K"),
        (lambda t: t + '\n[paper]\nttests = [{ a = "k1", b = "k1", p = "banana" }]\n', "[paper] ttests p = 'banana' is not allowed"),
    ],
)
def test_bad_configs_are_refused_with_a_clear_message(tmp_path: Path, edit, message) -> None:
    path = _write(tmp_path, edit(SLOW_CONFIG))
    with pytest.raises(NeurohoverError) as err:
        load_config(str(path), "quick")
    assert message in str(err.value)


def test_overrides_and_config_hash() -> None:
    assert parse_override("runs=3") == ("runs", 3)
    assert parse_override("policies=evolve") == ("policies", "evolve")
    assert parse_override('policies="shipped"') == ("policies", "shipped")
    with pytest.raises(NeurohoverError, match="KEY=VALUE"):
        parse_override("runs")
    base = load_config("fig12", "quick")
    assert load_config("fig12", "quick").hash == base.hash
    changed = load_config("fig12", "quick", {"runs": 2})
    assert changed.settings["runs"] == 2 and changed.hash != base.hash
    assert load_config("fig12", "paper").hash != base.hash
    with pytest.raises(NeurohoverError, match="unknown setting"):
        load_config("fig12", "quick", {"episodes": 3})


def test_shipped_configs_are_plain_toml_files() -> None:
    import tomllib

    for path in CONFIG_DIR.glob("*.toml"):
        raw = tomllib.loads(path.read_text())
        assert raw["name"] == path.stem and set(raw["scales"]) == {"quick", "paper"} and "paper" in raw


# --------------------------------------------------------------------------------- units and seeds


def test_unit_seeds_come_from_the_key_not_global_state() -> None:
    random.seed(1)
    np.random.seed(1)
    a = unit_seed(7, "fig7", "run/model-free/test3/rep0")
    random.seed(2)
    np.random.seed(2)
    assert unit_seed(7, "fig7", "run/model-free/test3/rep0") == a
    assert unit_seed(7, "fig7", "run/model-free/test4/rep0") != a
    assert unit_seed(8, "fig7", "run/model-free/test3/rep0") != a
    assert unit_seed(7, "fig8", "run/model-free/test3/rep0") != a
    cfg = load_config("fig15", "quick")
    first, second = plan(cfg, {}).units, plan(cfg, {}).units
    assert [u.params for u in first] == [u.params for u in second]
    assert len({u.params["seed"] for u in first}) == len(first)


def test_a_unit_gives_the_same_result_on_one_or_all_threads() -> None:
    cfg = load_config("fig15", "quick", {"budget": 600})
    unit = plan(cfg, {}).units[-1]  # a selection-race run
    a, b = run_unit(unit, threads=1), run_unit(unit.to_dict(), threads=None)
    assert strip_timing(a) == strip_timing(b)
    json.dumps(a, allow_nan=False)


# --------------------------------------------------------------------------------- store


def test_store_semantics(tmp_path: Path) -> None:
    path = tmp_path / "s.sqlite"
    cfg = load_config(str(_write(tmp_path, SLOW_CONFIG)), "quick", {"runs": 2, "budget": 200})
    with Store(path) as store:
        summary = reproduce(cfg, store, LocalExecutor(1), progress=False)
        assert summary.status == "finished" and summary.units_run == 2 and summary.units_total == 2
        assert set(store.results("slowtest", "quick")) == {"evolve/k1/run0", "evolve/k1/run1"}
        # The same config again: nothing to do.
        again = reproduce(cfg, store, LocalExecutor(1), progress=False)
        assert again.units_run == 0 and again.units_before == 2 and again.status == "finished"
        # Another scale of the same experiment lives beside it.
        paper = load_config(str(tmp_path / "exp.toml"), "paper", {"runs": 1, "budget": 200})
        reproduce(paper, store, LocalExecutor(1), progress=False)
        assert {(n, s) for n, s, _, _ in store.experiments()} == {("slowtest", "quick"), ("slowtest", "paper")}
        # A different config under the same name and scale is refused, never mixed ...
        other = load_config(str(tmp_path / "exp.toml"), "quick", {"runs": 3, "budget": 200})
        with pytest.raises(NeurohoverError, match="config hash .* but this config hashes to .*--fresh"):
            reproduce(other, store, LocalExecutor(1), progress=False)
        assert len(store.results("slowtest", "quick")) == 2
        # ... unless the old results are discarded on purpose.
        fresh = reproduce(other, store, LocalExecutor(1), fresh=True, progress=False)
        assert fresh.units_run == 3 and fresh.units_before == 0
        sessions = store.sessions("slowtest", "quick")
        assert sessions[-1]["status"] == "finished" and sessions[-1]["cores"] >= 1 and sessions[-1]["units_run"] == 3


def test_store_refuses_other_schema_versions_and_foreign_files(tmp_path: Path, cli) -> None:
    path = tmp_path / "s.sqlite"
    Store(path).close()
    conn = sqlite3.connect(path)
    conn.execute(f"PRAGMA user_version = {SCHEMA_VERSION + 1}")
    conn.commit()
    conn.close()
    with pytest.raises(NeurohoverError, match=f"schema version {SCHEMA_VERSION + 1}, written by a newer neurohover"):
        Store(path)
    rc, _, stderr = cli("reproduce", "fig15", "--store", str(path))
    assert rc == 2 and "schema version" in stderr
    foreign = tmp_path / "other.sqlite"
    conn = sqlite3.connect(foreign)
    conn.execute("CREATE TABLE t (x)")
    conn.commit()
    conn.close()
    with pytest.raises(NeurohoverError, match="not a neurohover results store"):
        Store(foreign)
    text = tmp_path / "notes.txt"
    text.write_text("hello " * 1000)
    with pytest.raises(NeurohoverError, match="not a neurohover results store"):
        Store(text)


def _finished(path: Path) -> dict[str, float]:
    """key -> finish time of the units in a store another process is writing (empty if not ready)."""
    if not path.exists():
        return {}
    try:
        # Read-write, so that a hot journal left by a killed writer can be rolled back.
        conn = sqlite3.connect(path, timeout=5)
        try:
            return dict(conn.execute("SELECT key, finished FROM units"))
        finally:
            conn.close()
    except sqlite3.OperationalError:
        return {}


def _start(config: Path, store: Path, gates: Path) -> subprocess.Popen:
    return start_gated_run(config, store, gates)


def _open_gates(gates: Path, upto: int) -> None:
    for i in range(upto):
        (gates / str(i)).touch()


def _interrupt_after(proc: subprocess.Popen, store: Path, n: int, sig: int) -> dict[str, float]:
    """Signal ``proc`` once ``n`` units are stored; unit ``n`` waits at its closed gate, so the run is still going."""
    deadline = time.monotonic() + 240  # a safety net against a hung run, not a speed assumption
    while time.monotonic() < deadline and proc.poll() is None and len(_finished(store)) < n:
        time.sleep(0.02)
    assert proc.poll() is None, f"the run ended before it could be interrupted: {proc.communicate()}"
    proc.send_signal(sig)
    finish_run(proc, 120)
    return _finished(store)


@pytest.mark.slow
def test_an_interrupted_run_loses_no_finished_unit_and_resumes(tmp_path: Path) -> None:
    """Ctrl-C, then SIGKILL, then a full run on the same store: nothing finished is lost or redone."""
    config = _write(tmp_path, SLOW_CONFIG)
    store, gates = tmp_path / "s.sqlite", tmp_path / "gates"
    gates.mkdir()
    _open_gates(gates, 2)
    proc = _start(config, store, gates)
    first = _interrupt_after(proc, store, 2, signal.SIGINT)
    assert proc.returncode == 130 and len(first) == 2
    _open_gates(gates, 5)
    proc = _start(config, store, gates)
    second = _interrupt_after(proc, store, 5, signal.SIGKILL)
    assert proc.returncode == -signal.SIGKILL and len(second) == 5
    assert all(second[k] == t for k, t in first.items())
    # Run again with the same store: only the missing units run; finished ones are untouched.
    _open_gates(gates, 12)
    proc = _start(config, store, gates)
    out, err = finish_run(proc, 240)
    assert proc.returncode == 0, err
    assert "ran 7 units, 5 already in the store, 12/12 done" in out
    after = _finished(store)
    assert len(after) == 12 and all(after[k] == t for k, t in second.items())
    with Store(store) as s:
        sessions = s.sessions("slowtest", "quick")
        assert [x["units_run"] for x in sessions] == [2, 3, 7]
        assert [x["status"] for x in sessions] == ["interrupted", "running", "finished"]  # SIGKILL: no goodbye
        assert [s.results("slowtest", "quick")[f"u{i:02d}"]["value"] for i in range(12)] == list(range(12))


@pytest.mark.slow
def test_a_resumed_unit_equals_an_uninterrupted_one(tmp_path: Path) -> None:
    # Each unit is seeded by its key, so a unit run after an interruption gives what it would have.
    cfg = load_config(str(_write(tmp_path, SLOW_CONFIG)), "quick")
    unit = plan(cfg, {}).units[3]
    assert strip_timing(run_unit(unit)) == strip_timing(run_unit(unit))


# --------------------------------------------------------------------------------- end to end


@pytest.fixture(scope="module")
def quick_store(tmp_path_factory) -> Path:
    """A representative quick subset: every unit kind (evolution incl. races, robustness, model
    learning, policy evolution, safety, test runs of every GHH agent) in two worker processes."""
    path = tmp_path_factory.mktemp("quick") / "results.sqlite"
    runs = [  # (one spawned pool of two workers; the rest in this process, which is faster at this size)
        ("fig15", ["--jobs", "2", "--set", "runs=2", "--set", "budget=1500"]),
        ("fig2", ["--set", "n_mdps=1", "--set", "runs=2", "--set", "budget=300"]),
        ("table4", ["--set", "n_mdps=2"]),
        ("fig8", []),
    ]
    for name, extra in runs:
        rc = main(["reproduce", name, "--scale", "quick", "--store", str(path), "--no-progress", *extra])
        assert rc == 0
    return path


@pytest.mark.slow
def test_quick_experiments_end_to_end(quick_store: Path, cli) -> None:
    with Store(quick_store) as store:
        assert {n for n, _, _, _ in store.experiments()} == {"fig2", "table4", "fig8", "fig15"}
        fig8 = store.results("fig8", "quick")
        assert len(fig8) == 18 and len(store.sessions("fig8", "quick")) == 1
        runs = [r for k, r in fig8.items() if k.startswith("run/")]
        assert {r["agent"] for r in runs} == {"model-free", "incremental", "hybrid"}
        assert all(len(r["returns"]) == 15 and r["score"] == pytest.approx(sum(r["returns"])) for r in runs)
        free = [r for k, r in fig8.items() if k.startswith("run/model-free/")]
        assert all(r["policy_changes"][0][1] == "specialised:0" and r["learning_episodes"] <= 9 for r in free)  # own MDP skipped
        assert len(fig8["policy/safety"]["safe"]) == 2
        models = store.results("table4", "quick")
        assert {r["method"] for k, r in models.items() if k.startswith("model/")} == {"lr", "lr-gls", "ec-meno", "ec-mer"}
        robust = {k: r for k, r in store.results("fig2", "quick").items() if k.startswith("robust/")}
        assert sorted(robust) == ["robust/mlp-baseline/train0", "robust/policy-set/train0", "robust/slp-baseline/train0"]
        assert all(len(r["returns"]) == 1 and len(r["returns"][0]) == 3 for r in robust.values())
    rc, out, _ = cli("reproduce", "fig8", "--scale", "quick", "--store", str(quick_store), "--no-progress")
    assert rc == 0 and "ran 0 units, 18 already in the store" in out


@pytest.mark.slow
def test_results_export_csv_and_json(quick_store: Path, cli, tmp_path: Path) -> None:
    rc, out, _ = cli("results", "fig8", "--store", str(quick_store), "--format", "json")
    data = json.loads(out)
    assert rc == 0 and data["experiment"] == "fig8" and data["scale"] == "quick" and len(data["units"]) == 18
    assert data["config"]["settings"]["task"] == "ghh09" and data["sessions"][0]["executor"] == "local"
    with Store(quick_store) as store:
        assert store.sessions("fig15", "quick")[0]["cores"] == 2
    rc, _, _ = cli("results", "fig8", "--store", str(quick_store), "--out", str(tmp_path / "fig8.csv"))
    import csv

    rows = list(csv.DictReader(open(tmp_path / "fig8.csv")))
    assert rc == 0 and len(rows) == 18
    run = next(r for r in rows if r["key"] == "run/hybrid/train0/rep0")
    # One plain value per cell: a list of returns is its count and mean (the JSON export has them all).
    assert not any(v.startswith(("[", "{")) for r in rows for v in r.values())
    returns = next(u for u in data["units"] if u["key"] == "run/hybrid/train0/rep0")["result"]["returns"]
    assert int(run["result.returns.n"]) == len(returns) and float(run["result.returns.mean"]) == pytest.approx(sum(returns) / len(returns))
    assert float(run["result.score"]) == pytest.approx(sum(returns))
    assert run["param.mdp.label"] == "ghh09/train:0" and run["param.policies.safe_indices.0"] != ""
    with Store(quick_store) as store:
        assert export_results(store, "fig15", "csv").count("\n") == 5
    rc, _, err = cli("results", "fig7", "--store", str(quick_store))
    assert rc == 2 and "holds no experiment 'fig7'" in err and "fig8 (quick)" in err
    rc, _, err = cli("results", "fig8", "--store", str(tmp_path / "missing.sqlite"))
    assert rc == 2 and "no such results store" in err


@pytest.mark.slow
def test_report_draws_the_figures_and_compares_with_the_paper(quick_store: Path, tmp_path: Path, cli) -> None:
    out = tmp_path / "report"
    rc, printed, _ = cli("report", "--store", str(quick_store), "--out", str(out))
    assert rc == 0 and "report.md" in printed
    for name in ("fig2", "table4", "fig8", "fig15"):
        png = out / f"{name}-quick.png"
        assert png.is_file() and png.read_bytes()[:4] == b"\x89PNG"
    text = (out / "report.md").read_text()
    for needle in (
        "## Figure 2 and Table 3",
        "### Table 3: robustness",
        "-496.2",
        "-2.508e+06",  # Table 3 beside the paper
        "## Table 4",
        "562.9",
        "-142.2",  # Table 4 beside the paper
        "## Figure 8",
        "5.8e-12",
        "Student's p",
        "Welch's p",
        "runs with a crash",  # t tests, crashes
        "### Winning a competition",
        "P(win), 20 runs",
        "## Figure 15",
        "Scale: **quick**",
        "core(s) (local)",
        "s wall over 1 session(s)",
        "our crash rate",
        "vs paper",
        "### Discussion",
    ):
        assert needle in text, needle
    assert "INCOMPLETE" not in text
    # A hand-written discussion beside the report survives regenerating it.
    (out / "discussion").mkdir()
    (out / "discussion" / "fig8-quick.md").write_text("Our hybrid agent fell back in most episodes.\n")
    assert cli("report", "--store", str(quick_store), "--out", str(out))[0] == 0
    sections = (out / "report.md").read_text().split("\n## ")
    fig8 = next(sec for sec in sections if sec.startswith("Figure 8"))
    assert "### Discussion\n\nOur hybrid agent fell back in most episodes." in fig8
    fig2 = next(sec for sec in sections if sec.startswith("Figure 2"))
    assert "Quick scale only" in fig2 and "fell back" not in fig2
    # One experiment only, and a clear error for an unknown one.
    with Store(quick_store) as store:
        write_report(store, tmp_path / "one", names=["fig15"])
    assert "Figure 2" not in (tmp_path / "one" / "report.md").read_text()
    rc, _, err = cli("report", "fig7", "--store", str(quick_store), "--out", str(tmp_path / "x" / "y"))
    assert rc == 2 and "holds no experiment 'fig7'" in err
    assert "removed" not in err and str(tmp_path / "x") not in err and not (tmp_path / "x").exists()  # none made and removed (sixth trial)


@pytest.mark.slow
def test_the_report_takes_the_papers_table_from_the_shipped_config(quick_store: Path, tmp_path: Path, cli) -> None:
    """Issue 33: a protocol note corrected in the shipped config reaches the report of runs stored before (the [paper]
    table is documentation, outside the config hash), so no note contradicts the stored settings."""
    store = tmp_path / "s.sqlite"
    store.write_bytes(quick_store.read_bytes())
    with sqlite3.connect(store) as db:
        config = json.loads(db.execute("select config from experiments where name = 'fig8' and scale = 'quick'").fetchone()[0])
        config["paper"]["notes"] = ["AN OUTDATED NOTE"]
        db.execute("update experiments set config = ? where name = 'fig8' and scale = 'quick'", (json.dumps(config),))
    rc, _, err = cli("report", "fig8", "--store", str(store), "--out", str(tmp_path / "report"))
    assert rc == 0, err
    text = (tmp_path / "report" / "report.md").read_text()
    assert "AN OUTDATED NOTE" not in text and load_config("fig8", "quick").paper["notes"][0] in text


@pytest.mark.slow
def test_a_report_of_fghh_runs_without_validation_ranks_nothing_and_warns_nothing(tmp_path: Path, cli) -> None:
    # Bug: the ranking took the mean of an empty list of validation scores (numpy's "Mean of empty slice").
    config = tmp_path / "tiny.toml"
    config.write_text(
        'name = "tinyfghh"\ntitle = "t"\nkind = "evolution"\n[settings]\ntask = "fghh"\nsigma = 0.3\nseed = 5\n'
        'target = "family"\nruns = 1\n[[settings.variants]]\nkey = "k1"\nlabel = "k = 1"\n'
        "[scales.quick]\nbudget = 200\nn_steps = 200\n"
    )
    store = tmp_path / "s.sqlite"
    assert cli("reproduce", str(config), "--store", str(store), "--no-progress")[0] == 0
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        rc, _, err = cli("report", "tinyfghh", "--store", str(store), "--out", str(tmp_path / "report"))
    assert rc == 0, err
    assert [str(w.message) for w in caught if issubclass(w.category, RuntimeWarning)] == []
    text = (tmp_path / "report" / "report.md").read_text()
    assert "| k = 1 |" in text and "Ranking by mean validation" not in text


@pytest.mark.slow
def test_failed_units_are_reported_and_not_recorded(tmp_path: Path, monkeypatch) -> None:
    from neurohover.experiments import runner
    from neurohover.experiments.plans import Plan
    from neurohover.experiments.units import Unit

    cfg = load_config(str(_write(tmp_path, SLOW_CONFIG)), "quick")
    units = [Unit("slowtest", "good", "diagnostic", {"value": 1}), Unit("slowtest", "bad", "nonsense", {})]
    monkeypatch.setattr(runner, "plan", lambda config, results, sources=None: Plan(units, 2))
    with Store(tmp_path / "s.sqlite") as store:
        summary = reproduce(cfg, store, LocalExecutor(1), progress=False)
        assert summary.status == "failed" and summary.failed[0][0] == "bad" and "unknown unit kind" in summary.failed[0][1]
        assert set(store.results("slowtest", "quick")) == {"good"}
        assert store.sessions("slowtest", "quick")[-1]["status"] == "failed"
    # A worker process that dies (as if killed) is reported; its unit is not recorded.
    units[1] = Unit("slowtest", "dies", "diagnostic", {"always_exit": True, "sleep": 0})
    executor = LocalExecutor(2)
    try:
        with Store(tmp_path / "s2.sqlite") as store:
            summary = reproduce(cfg, store, executor, progress=False)
            assert summary.status == "failed" and "dies" in {k for k, _ in summary.failed}
            assert "worker process died" in dict(summary.failed)["dies"]
            assert "dies" not in store.results("slowtest", "quick")
    finally:
        executor.close()


@pytest.mark.slow
def test_policies_from_a_policy_set_directory(tmp_path: Path, capsys) -> None:
    from neurohover.policysets import build_policy_set

    sets = tmp_path / "sets"
    build_policy_set("ghh08", out=sets, budget=100, n_steps=100, seed=1)
    store = tmp_path / "s.sqlite"
    argv = ["reproduce", "fig7", "--store", str(store), "--set", f"policies={sets}", "--set", "episodes=12", "--no-progress"]
    assert main(argv) == 0
    assert "ran 9 units, 0 already in the store, 9/9 done" in capsys.readouterr().out  # test runs only
    with Store(store) as s:
        run = next(u for u in s.units("fig7", "quick") if u["key"].startswith("run/model-free/"))
        assert len(run["params"]["policies"]["specialised"]) == 10
    # The policies are part of the config hash: a rebuilt set is never mixed with the old results.
    build_policy_set("ghh08", out=sets, budget=100, n_steps=100, seed=2)
    assert main(argv) == 2
    assert "config hash" in capsys.readouterr().err
    assert main(["reproduce", "fig7", "--store", str(store), "--set", f"policies={tmp_path / 'none'}"]) == 2
    assert "build it with: neurohover build-policies" in capsys.readouterr().err


def test_table3_flies_the_shipped_sets_specialised_policies_as_the_best_champions() -> None:
    """Issue 33: Table 3's figures of the shipped policies come from the store, not from a manifest."""
    from neurohover.policysets import load_policy_set

    cfg = load_config("fig2", "paper")
    units = {u.key: u for u in plan(cfg, {}).units if u.key.startswith("robust/")}
    shipped = load_policy_set("ghh08")
    assert sorted(units) == [f"robust/policy-set/train{i}" for i in range(10)]  # the champions' rows wait for their runs
    for i in range(10):
        p = units[f"robust/policy-set/train{i}"].params
        assert p["own"] == i and p["episodes"] == 10 and len(p["mdps"]) == 10
        assert p["policy"]["genome"] == [float(x) for x in shipped.specialised[i].genome]
    with pytest.raises(NeurohoverError, match="robustness_policies = 'evolve' is not allowed"):
        load_config("fig2", "quick", {"robustness_policies": "evolve"})
    with pytest.raises(NeurohoverError, match="robustness_policies flies a set's specialised policies"):
        load_config("fig15", "quick", {"robustness_policies": "shipped"})


def test_the_commands_are_registered_in_the_cli(capsys) -> None:
    from neurohover import cli

    assert cli.build_parser().parse_args(["reproduce", "--list"]).command == "reproduce"
    assert cli.main(["reproduce", "--list"]) == 0
    assert capsys.readouterr().out.split() == PAPER_EXPERIMENTS + ABLATIONS + BENCHMARKS + BEYOND


@pytest.mark.paper
def test_paper_scale_reproduction() -> None:
    """Every experiment at the paper's scale (days of CPU; resumable): runs only where NEUROHOVER_PAPER_STORE names its
    store, so a `-m paper` run (or one that drops the marker) never starts days of work by accident."""
    store = os.environ.get("NEUROHOVER_PAPER_STORE")
    if not store:
        pytest.skip("days of CPU: set NEUROHOVER_PAPER_STORE=FILE to run every experiment at the paper's scale into FILE")
    jobs = str(os.cpu_count() or 1)
    assert main(["reproduce", "all", "--scale", "paper", "--store", store, "--jobs", jobs]) == 0
    assert main(["report", "--store", store, "--scale", "paper", "--out", str(Path(store).with_suffix("")) + "-report"]) == 0


@pytest.mark.slow
def test_only_runs_the_selected_units_and_a_later_call_finishes_the_rest(tmp_path: Path, capsys) -> None:
    config = _write(tmp_path, SLOW_CONFIG.replace("runs = 12", "runs = 4").replace("budget = 3000", "budget = 200"))
    store = tmp_path / "s.sqlite"
    base = ["reproduce", str(config), "--store", str(store), "--no-progress"]
    assert main([*base, "--only", "evolve/k1/run1", "--only", "**/run3"]) == 0
    assert "selection finished; ran 2 units, 0 already in the store, 2/4 done" in capsys.readouterr().out
    with Store(store) as s:
        first = s.results("slowtest", "quick")
    assert sorted(first) == ["evolve/k1/run1", "evolve/k1/run3"]
    assert main(base) == 0
    assert "finished; ran 2 units, 2 already in the store, 4/4 done" in capsys.readouterr().out
    with Store(store) as s:
        after = s.results("slowtest", "quick")
    assert all(after[k] == v for k, v in first.items())
    # A pattern that matches nothing is a typo, not a silent no-op.
    assert main([*base, "--only", "run/hybrid/*"]) == 2
    assert "--only 'run/hybrid/*' matches no unit; unit keys look like evolve/k1/" in capsys.readouterr().err
    assert main(["reproduce", "all", "--store", str(store), "--only", "run/*"]) == 2
    assert "--only selects units of one experiment: give its NAME instead of 'all'" in capsys.readouterr().err


def test_a_significant_difference_in_the_opposite_direction_does_not_agree_with_the_paper() -> None:
    from neurohover.experiments.report_base import Section

    cfg = load_config("fig8", "quick")
    sec = Section(cfg, {}, None, Path("."))
    rng = np.random.default_rng(0)
    better, worse = list(rng.normal(-100, 5, 20)), list(rng.normal(-200, 5, 20))
    # The paper found hybrid better than model-free (p = 1.4e-14) and incremental better (p = 5.8e-12).
    sec.add_tests({"hybrid": worse, "model-free": better, "incremental": list(rng.normal(-300, 5, 20))}, {}, "final cumulative reward")
    by_pair = {c.split(" (")[0]: c for c in sec.comparisons}
    assert by_pair["hybrid vs model-free"].endswith(": reversed (the paper found hybrid better; ours is worse).")
    assert by_pair["incremental vs model-free"].endswith(": reversed (the paper found incremental better; ours is worse).")
    sec.comparisons.clear()
    sec.add_tests({"hybrid": better, "model-free": worse}, {}, "final cumulative reward")
    assert sec.comparisons[0].endswith(": holds.")


def test_a_verdict_weighs_direction_before_significance() -> None:
    """Figure 11's case: both p-values above 5 % but the effect reversed is not agreement; Figure 2's:
    p = 0.03 in the paper's direction against its p < 0.0026 is weaker, not a hold."""
    from neurohover.experiments.report_base import verdict

    assert verdict("hybrid", -2.0, -1.0, 0.4, "0.2") == "reversed, not significant (the paper found hybrid better; ours is worse)"
    assert verdict("hybrid", -1.0, -2.0, 0.4, "0.2") == "holds (same direction, neither significant)"
    assert verdict("mlp", -1.0, -2.0, 0.03, "< 0.0026") == "same direction, weaker (p >= 0.01 here)"
    assert verdict("mlp", -1.0, -2.0, 0.001, "< 0.0026") == "holds"
    assert verdict("mlp", -1.0, -2.0, 0.2, "1e-5") == "same direction, not significant"
    assert verdict("mlp", -1.0, -2.0, 0.01, "0.3") == "same direction, significant here but not in the paper"
    assert verdict("mlp", -2.0, -1.0, 1e-9, "1e-5") == "reversed (the paper found mlp better; ours is worse)"
    assert verdict("mlp", -1.0, -2.0, 0.01, "none (not in the paper)") is None
    # "not significant" with no number (Figure 2's slp-zero vs slp-baseline, Figure 16's fixed vs zero): no direction to reverse
    assert verdict("slp-zero", -2.0, -1.0, 0.4, "not significant") == "holds (neither significant)"
    assert verdict("slp-zero", -2.0, -1.0, 0.001, "not significant") == "differs: significant here (slp-zero worse), not in the paper"


def test_paired_runs_mostly_equal_are_described_by_the_pairs_that_differ() -> None:
    """risk-ghh09's hybrid-worst: 0 of 60 runs better, median difference 0, Wilcoxon p = 1e-5 was "as good in the median
    pair ... significant", a sentence that says nothing of which way the significant difference goes."""
    from neurohover.experiments.report_base import paired_verdict

    assert paired_verdict(np.r_[np.zeros(58), -3.0, -5.0]) == "equal in 58 of 60 pairs and worse where they differ (0 better, 2 worse"
    assert paired_verdict(np.r_[np.zeros(3), 2.0, -1.0]) == "equal in 3 of 5 pairs and neither better nor worse where they differ (1 better, 1 worse"
    assert paired_verdict(np.array([1.0, 2.0, -1.0])) == "better in the median pair (2 of 3 runs better, median paired difference 1"
    assert paired_verdict(np.array([-1.0, -2.0, 1.0])).startswith("worse in the median pair (1 of 3 runs better")


@pytest.mark.slow
def test_an_interrupt_ends_the_running_worker_processes_at_once() -> None:
    import multiprocessing

    from neurohover.experiments.units import Unit

    executor = LocalExecutor(2)
    units = [Unit("x", "quick", "diagnostic", {"sleep": 0}), Unit("x", "slow", "diagnostic", {"sleep": 120})]

    workers: list = []

    def on_result(unit, result, seconds, worker) -> None:
        workers.extend(multiprocessing.active_children())  # the pool's workers, one still sleeping in the slow unit
        raise KeyboardInterrupt  # as if Ctrl-C arrived once the quick unit is done

    try:
        with pytest.raises(KeyboardInterrupt):
            executor.run(units, on_result, lambda unit, err: None)
    finally:
        executor.close()
    # The 120 s unit was stopped, not waited for: its worker ended by a signal (a worker left to finish
    # its unit and shut down exits with 0).
    assert len(workers) == 2 and all(p.exitcode is not None and p.exitcode < 0 for p in workers), [p.exitcode for p in workers]
    assert not [p for p in multiprocessing.active_children() if p.is_alive()]


@pytest.mark.slow
def test_the_report_opens_with_the_papers_claims_and_conclusions(committed_store: Path, tmp_path: Path) -> None:
    """Issue 33: every claim checked at paper scale, with its verdict; a reversed effect is never counted as holding.
    The hand-written account of the conclusions (issue 32) follows their table."""
    (tmp_path / "discussion").mkdir()
    (tmp_path / "discussion" / "conclusions-paper.md").write_text("**(5)** what the measurements say.\n")
    with Store(committed_store, create=False) as store:
        write_report(store, tmp_path, scale="paper", names=["table4", "fig8", "fig11"])
    text = (tmp_path / "report.md").read_text()
    top = text[text.index("## Claims and conclusions (paper scale)") : text.index("\n## Table 4")]
    assert top.index("### The paper's conclusions") < top.index("### The conclusions, measured\n\n**(5)** what the measurements say.")
    rows = [line.split(" | ") for line in top.splitlines() if line.startswith("| [")]
    fig11 = [r for r in rows if r[0].startswith("| [fig11]") and " vs " in r[1]]
    assert len(fig11) == 2 and all(r[-1].startswith("reversed") for r in fig11)  # the paper's hybrids better; ours worse
    assert any(r[1] == "Table 4, LR: median r_m" and r[2] == "-142.2" for r in rows)
    conclusions = {line.split(" | ")[0][2:]: line.split(" | ") for line in top.splitlines() if line.startswith("| (")}
    models = conclusions["(3)-(4) model-based approaches are feasible, and superior, only with a suitable model representation"]
    assert int(models[3]) >= 2 and "of" in models[2]  # Figure 11's two reversed tests at least


@pytest.mark.parametrize("name", ["fig7", "fig8", "fig11", "bench-drift", "bench-sensors"])
def test_the_run_keys_of_a_test_runs_config_are_its_plans(name: str) -> None:
    """run_keys lists a test-runs experiment's runs before their policies exist (what --only is checked against)."""
    from neurohover.experiments.plans import run_keys

    cfg = load_config(name, "quick", {"policies": "shipped"})
    planned = {u.key for u in plan(cfg, {}, {}).units if u.key.startswith("run/")}
    assert planned and set(run_keys(cfg)) == planned


def test_an_only_that_matches_no_later_unit_is_refused_before_any_unit_runs(tmp_path: Path, capsys) -> None:
    """Second trial: with policies evolved first, `--only nothing` ran and stored the policy units, then refused."""
    store = tmp_path / "s.sqlite"
    assert main(["reproduce", "fig7", "--only", "nothing", "--store", str(store), "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert "--only 'nothing' matches no unit; unit keys look like policy/generic" in err and "run/model-free/test0/rep0" in err
    assert not store.exists()


def test_a_refused_only_leaves_the_store_as_it_was(tmp_path: Path, capsys) -> None:
    """issue 37: `--only nothing` used to record the config first, so a later run with other settings was refused."""
    config = _write(tmp_path, SLOW_CONFIG.replace("runs = 12", "runs = 2").replace("budget = 3000", "budget = 100"))
    store = tmp_path / "s.sqlite"
    base = ["reproduce", str(config), "--store", str(store), "--no-progress"]
    assert main([*base, "--only", "nothing"]) == 2
    assert "--only 'nothing' matches no unit; unit keys look like evolve/k1/run0" in capsys.readouterr().err
    with Store(store) as s:
        assert s.experiments() == []  # nothing recorded
    assert main([*base, "--set", "budget=120", "--only", "evolve/k1/run0"]) == 0  # other settings: not "settings differ"
    with Store(store) as s:
        assert sorted(s.results("slowtest", "quick")) == ["evolve/k1/run0"]
    # Third trial: in a store that already held another experiment, a staged plan's refusal (fig2's robustness units
    # wait for its evolutions) registered fig2 with no unit, which `results fig2` then printed as empty.
    assert main(["reproduce", "fig2", "--store", str(store), "--no-progress", "--only", "zzz"]) == 2
    assert "--only 'zzz' matches no unit" in capsys.readouterr().err
    with Store(store) as s:
        assert [e[0] for e in s.experiments()] == ["slowtest"]


@pytest.mark.slow
def test_an_update_that_forgets_the_policy_source_is_refused(tmp_path) -> None:
    """--update without the run's `--set policies=shipped` would have run every unit again (and dropped the stored
    ones): it is refused with the setting to give, and the store is left as it was."""
    from neurohover.experiments import LocalExecutor, Store, load_config, reproduce

    small = {"episodes": 2, "n_steps": 20}
    with Store(tmp_path / "s.sqlite") as store:
        reproduce(load_config("fig7", "quick", {**small, "policies": "shipped"}), store, LocalExecutor(1), progress=False)
        before = store.units("fig7", "quick")
        with pytest.raises(NeurohoverError, match=r"give --set policies=\"shipped\" as they were run, or --fresh"):
            reproduce(load_config("fig7", "quick", {**small, "n_steps": 30}), store, LocalExecutor(1), progress=False, update=True)
        assert store.units("fig7", "quick") == before
        changed = reproduce(load_config("fig7", "quick", {**small, "n_steps": 30, "policies": "shipped"}), store, LocalExecutor(1), progress=False, update=True)
        assert changed.status == "finished"
