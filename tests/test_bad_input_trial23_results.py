"""The twenty-third bad-input trial's findings in stored evolution runs, robustness units and baseline test runs: a hand
edit that contradicts the run itself or its unit's params (a champion its history contradicts, stop_reason 'bogus',
episodes past the budget, a history out of order, validations of another count; positive robustness returns, more
crashes than episodes: T23-08; a baseline run with safeguard episodes, offline seconds beyond the run's: T23-14) was
exported and reported; the shared check (checked_units -> result_from_dict, params_problem) now refuses each in one
message naming the store, the experiment, the unit, the field, the value and what is allowed."""

from __future__ import annotations

import json
import shutil
import sqlite3
from pathlib import Path
from typing import Any

import pytest
from conftest import CliRun, tiny_test_runs
from store_edits import refused_by_every_command

from neurohover.errors import NeurohoverError
from neurohover.experiments import Store
from neurohover.experiments.export import checked_units
from neurohover.experiments.result_checks import params_problem
from neurohover.experiments.results import result_from_dict

EVOLVE = "evolve/slp-zero/train0/run0"
ROBUST = "robust/mlp-baseline/train0"
RUN = "run/baseline/test0/rep0"

#: A tiny fig2: steady-state SLP (zero seed) and MLP (baseline seed) runs on one GHH-08 training MDP, 60 episodes of 20
#: steps, 2 validation episodes, and Table 3's robustness unit of the MLP champion (2 episodes).
EV1 = """
name = "ev1"
title = "tiny"
kind = "evolution"
[settings]
task = "ghh08"
seed = 3
target = "train"
robustness_variants = ["mlp-baseline"]
[[settings.variants]]
key = "slp-zero"
label = "SLP, zero seed"
topology = "slp"
prototype = "zero"
[[settings.variants]]
key = "mlp-baseline"
label = "MLP, baseline seed"
topology = "mlp"
prototype = "baseline"
[scales.quick]
n_mdps = 1
runs = 1
budget = 60
n_steps = 20
validation_episodes = 2
robustness_episodes = 2
"""


def _reproduced(where: Path, text: str) -> tuple[Path, Path]:
    from neurohover.cli import main

    config = where / "c.toml"
    config.write_text(text)
    assert main(["reproduce", str(config), "--store", str(where / "s.sqlite"), "--no-progress"]) == 0
    return config, where / "s.sqlite"


@pytest.fixture(scope="module")
def ev1(tmp_path_factory) -> tuple[Path, Path]:
    """EV1's config and a store of its three finished units; tests edit copies of the store."""
    return _reproduced(tmp_path_factory.mktemp("ev1"), EV1)


@pytest.fixture(scope="module")
def tr1(tmp_path_factory) -> tuple[Path, Path]:
    """A config of one baseline test run (two 20-step episodes) and a store of it."""
    return _reproduced(tmp_path_factory.mktemp("tr23"), tiny_test_runs("baseline"))


def _stored(store: Path, key: str) -> dict:
    with sqlite3.connect(store) as conn:
        result = json.loads(conn.execute("SELECT result FROM units WHERE key = ?", (key,)).fetchone()[0])
    conn.close()
    return result


def _edited(store: Path, at: Path, key: str, **changes: Any) -> Path:
    """A copy of ``store`` at ``at`` whose unit ``key`` has ``changes`` in its result (a callable: of the stored result)."""
    shutil.copyfile(store, at)
    result = _stored(store, key)
    result.update({k: v(result) if callable(v) else v for k, v in changes.items()})
    with sqlite3.connect(at) as conn:
        conn.execute("UPDATE units SET result = ? WHERE key = ?", (json.dumps(result), key))
    conn.close()
    return at


def _refused(store: Path, name: str, key: str, says: str) -> str:
    """The shared check's message on ``store``, asserted to name the store, the experiment, the unit and ``says``."""
    with Store(store, create=False) as held, pytest.raises(NeurohoverError) as caught:
        checked_units(held, name, "quick")
    message = str(caught.value)
    assert message.startswith(f"results store {str(store)!r}, experiment {name} (quick), is damaged: unit '{key}': ") and says in message, message
    return message


def _history(*last: Any) -> Any:
    """A change of the history's last entry to ``last``."""
    return lambda r: [*r["history"][:-1], list(last)]


@pytest.mark.parametrize(
    ("changes", "says"),
    [
        (
            {"stop_reason": "bogus"},
            "evolution run is inconsistent: stop_reason = 'bogus' is not allowed: allowed one of budget, plateau, generations, cma-stop, optimiser-stop",
        ),
        ({"champion_return": -1.0}, "champion_return = -1.0 is not allowed: its history ends at "),
        (
            {"champion_return": 5.0},
            "champion_return = 5.0 is not allowed: on raw returns (no fitness scale) it is a mean return: allowed a number in [-1.75e+10, 0]",
        ),
        ({"fitness": "bogus"}, "fitness = 'bogus' is not allowed: allowed one of inv-log-error, return, or none (raw returns)"),
        ({"champion_crashed": "yes"}, "champion_crashed = 'yes' is not allowed: allowed true, false or none (not recorded)"),
        ({"generations": 0}, "generations = 0 is not allowed: a run stops at a generation boundary, after one generation at least"),
        (
            {"generations": 61},
            (
                "generations = 61 is not allowed: a run stops at a generation boundary, after one generation "
                "at least, each flying an episode at least, and it flew 60 episodes: allowed 1..60"
            ),
        ),
        ({"evaluations": 1000000}, "evaluations = 1000000 is not allowed: each of its 11 generations evaluates a candidate at least"),
        ({"history": lambda r: r["history"][::-1]}, "history[1] = [50, "),
        (
            {"history": _history(70, -1.0)},
            "history[1] = [70, -1.0] is not allowed: give [episodes, champion fitness], its episodes increasing within 1..60 (the run's episodes)",
        ),
        ({"history": _history(55, -1.0)}, "history[1] = [55, -1.0] is not allowed: a run's history ends at its last generation, at its 60 episodes"),
        ({"history": []}, "its history is empty"),
        ({"validation": [5.0, -1.0]}, "validation[0] = 5.0 is no episode's return"),
        ({"validation_crashed": [True]}, "validation_crashed = [True] is not allowed: give one true or false for each of its 2 validation episodes"),
    ],
)
def test_an_evolution_run_that_contradicts_itself_is_refused(ev1, tmp_path: Path, changes: dict, says: str) -> None:
    """T23-08: each hand edit of a stored evolution run was exported and reported as it was; now the run must fit
    together (the history's last entry is its champion's fitness at its last generation, at its episodes)."""
    _refused(_edited(ev1[1], tmp_path / "s.sqlite", EVOLVE, **changes), "ev1", EVOLVE, says)


@pytest.mark.parametrize(
    ("changes", "says"),
    [
        (
            {"champion": lambda r: {**r["champion"], "topology": "mlp"}},
            "its result contradicts its params: champion.topology = 'mlp' is not allowed: its unit's params.topology is 'slp'",
        ),
        ({"champion": lambda r: {**r["champion"], "genome": r["champion"]["genome"][:39]}}, "is not allowed: a slp genome is 40 finite numbers"),
        ({"validation": [-1.0]}, "validation = [-1.0] is not allowed: its unit's params.validation_episodes is 2: allowed 2 returns"),
        (
            {"stop_reason": "plateau"},
            (
                "episodes = 60 is not allowed: it stopped by 'plateau' before its unit's budget "
                "of 60 episodes (a run at or past it stops by 'budget'): allowed fewer than 60"
            ),
        ),
        (
            {"evaluations": 50},
            "episodes = 60 is not allowed: its unit's resampling is fixed:1, 1 episode(s) an evaluation, and it made 50 evaluations: allowed 50",
        ),
        (
            {"episodes": 100, "evaluations": 100, "generations": 95, "history": _history(100, -1.0), "champion_return": -1.0},
            "episodes = 100 is not allowed: it stopped by its unit's budget of 60 episodes, at the first generation boundary at or past it, its last "
            "generation flying at most 6 (fixed:1, 100 evaluations in 95 generations): allowed 60..65",
        ),
        (
            {"episodes": 50, "evaluations": 50, "history": [[50, -1.0]], "champion_return": -1.0},
            "episodes = 50 is not allowed: it stopped by its unit's budget of 60 episodes",
        ),
    ],
)
def test_an_evolution_run_that_contradicts_its_units_params_is_refused(ev1, tmp_path: Path, cli: CliRun, changes: dict, says: str) -> None:
    """T23-08: a champion of another topology or genome length, a validation of another count, episodes beyond (or
    short of) the budget it stopped by were exported; now they must fit the unit's params."""
    store = _edited(ev1[1], tmp_path / "s.sqlite", EVOLVE, **changes)
    message = _refused(store, "ev1", EVOLVE, says)
    rc, out, err = cli("results", "ev1", "--store", str(store))
    assert rc == 2 and out == "" and err.strip() == f"neurohover results: error: {message}", err


@pytest.mark.parametrize(
    ("changes", "says"),
    [
        (
            {"returns": [[5.0, -1.0]]},
            "robustness result is inconsistent: returns[0][0] = 5.0 is no episode's return: allowed a number in [-1.75e+10, 0] or nan",
        ),
        ({"crashes": [3]}, "crashes[0] = 3 is not allowed: its MDP's row holds 2 episodes: allowed 0..2"),
        ({"crashes": [0, 0]}, "crashes = [0, 0] is not allowed: give one crash count for each of its 1 MDPs' rows of returns"),
        ({"own": 1}, "own = 1 is not allowed: it holds 1 MDPs' rows: allowed 0..0"),
        (
            {"returns": [[-1.0, -2.0, -3.0]]},
            "its result contradicts its params: returns[0] = [-1.0, -2.0, -3.0] is not allowed: its unit's params.episodes is 2: allowed 2 returns",
        ),
        (
            {"returns": [[-1.0, -2.0], [-1.0, -2.0]], "crashes": [0, 0]},
            "returns = [[-1.0, -2.0], [-1.0, -2.0]] is not allowed: its unit flies 1 MDPs (params.mdps)",
        ),
    ],
)
def test_a_robustness_result_that_contradicts_itself_or_its_params_is_refused(ev1, tmp_path: Path, changes: dict, says: str) -> None:
    """T23-08: positive returns, more crashes than episodes and rows of other lengths than params.episodes were reported
    in Table 3; now a robustness result must fit together and fit its unit's params."""
    _refused(_edited(ev1[1], tmp_path / "s.sqlite", ROBUST, **changes), "ev1", ROBUST, says)


def test_results_report_and_reproduce_update_refuse_a_damaged_evolution_run(ev1, tmp_path: Path, cli: CliRun) -> None:
    """T23-08: every command that reads the store refuses the damaged run, in one message, and leaves the store as it was."""
    config, good = ev1
    store = _edited(good, tmp_path / "s.sqlite", EVOLVE, stop_reason="bogus")
    line = _refused(store, "ev1", EVOLVE, "stop_reason = 'bogus' is not allowed")
    refused_by_every_command(cli, config, store, "ev1", line, tmp_path / "r")


def test_a_crashed_champion_of_any_return_is_taken(ev1, tmp_path: Path) -> None:
    """T23-08: champion_crashed is not checked against the returns: a crash at an episode's last control step is charged
    nothing (crash_charge(n, n) = 0), so a crashed champion may have any return (only what is proven is refused)."""
    store = _edited(ev1[1], tmp_path / "s.sqlite", EVOLVE, champion_crashed=True, validation_crashed=[True, False])
    with Store(store, create=False) as held:
        assert checked_units(held, "ev1", "quick")[2][EVOLVE].champion_crashed is True


@pytest.mark.parametrize(
    ("changes", "says"),
    [
        (
            {"safeguard_episodes": [0]},
            "test run of baseline on ghh08/test:0 is inconsistent: safeguard_episodes = [0] is not allowed: "
            "agent baseline flies under no safeguard: allowed []",
        ),
        (
            {"timing": lambda r: {"seconds": 1.0, "offline_seconds": 2.5}},
            "timing.offline_seconds = 2.5 is not allowed: it is part of the run's timing.seconds 1.0: allowed at most that",
        ),
    ],
)
def test_a_baseline_run_with_safeguard_episodes_or_offline_time_beyond_its_own_is_refused(tr1, tmp_path: Path, cli: CliRun, changes: dict, says: str) -> None:
    """T23-14: a stored baseline run with safeguard episodes (the baseline has no safeguard) and a run whose offline
    seconds exceed its seconds were exported; now each is refused."""
    store = _edited(tr1[1], tmp_path / "s.sqlite", RUN, **changes)
    message = _refused(store, "tr1", RUN, says)
    rc, out, err = cli("results", "tr1", "--store", str(store))
    assert rc == 2 and out == "" and err.strip() == f"neurohover results: error: {message}", err


@pytest.mark.paper  # about 10 s over the whole store: run with the store's other checks when it is committed (-m paper)
def test_every_stored_evolution_and_robustness_result_of_the_committed_store_is_taken(committed_store: Path) -> None:
    """T23-08: the checks refuse only what is contradictory: every evolve, robustness and test-run unit of the
    committed paper store (all its experiments, both scales) passes them."""
    checked = 0
    with sqlite3.connect(committed_store) as conn:
        rows = conn.execute("SELECT key, kind, params, result FROM units WHERE kind IN ('evolve', 'robustness', 'test_run')").fetchall()
    conn.close()
    for key, kind, params, result in rows:
        assert params_problem(result_from_dict(kind, json.loads(result), key), json.loads(params)) == "", key
        checked += 1
    assert checked > 1000


def test_any_agent_without_a_safeguard_is_refused_safeguard_episodes(tmp_path: Path) -> None:
    """T23-14: not only the baseline: a generic run (no safeguard either; compete_labels.NO_SAFEGUARD, as plot --compete
    reads rows) stored with safeguard episodes is refused; a hybrid run's are its own (checked elsewhere)."""
    config, store = _reproduced(tmp_path, tiny_test_runs("generic"))
    edited = _edited(store, tmp_path / "e.sqlite", "run/generic/test0/rep0", safeguard_episodes=[1])
    _refused(edited, "tr1", "run/generic/test0/rep0", "safeguard_episodes = [1] is not allowed: agent generic flies under no safeguard")
