"""The twenty-fourth bad-input trial's findings in compete summaries and stored results that contradict themselves:
a summary.json whose offline seconds exceed its seconds, or are above 0 for an agent that does no work between episodes,
or whose seconds are 1e300, was plotted (T24-07); a stored evolution run whose kernel seconds exceed its seconds, or
whose champion's fitness falls in a run whose champion is the best fitness ever told, was exported and reported
(T24-09). Each is refused in one message naming the file or unit, the field, the value and what is allowed."""

from __future__ import annotations

import json
import re
import shutil
import sqlite3
from pathlib import Path
from typing import Any

import pytest
from conftest import CliRun, tiny_test_runs
from store_edits import refused_by_every_command
from test_bad_input_trial23_results import EV1, _edited, _refused, _reproduced

from neurohover.compete_files import MAX_SECONDS, read_compete_dir
from neurohover.compete_labels import NO_OFFLINE
from neurohover.errors import NeurohoverError
from neurohover.experiments.result_checks import _history_fall_problem, params_problem
from neurohover.experiments.results import result_from_dict

EVOLVE = "evolve/slp-zero/train0/run0"
RUN = "run/baseline/test0/rep0"


@pytest.fixture(scope="module")
def ev1(tmp_path_factory) -> tuple[Path, Path]:
    """EV1's config (two steady-state runs on one GHH-08 training MDP) and a store of its finished units."""
    return _reproduced(tmp_path_factory.mktemp("ev24"), EV1)


@pytest.fixture(scope="module")
def tr1(tmp_path_factory) -> tuple[Path, Path]:
    """A config of one baseline test run (two 20-step episodes) and a store of it."""
    return _reproduced(tmp_path_factory.mktemp("tr24"), tiny_test_runs("baseline"))


@pytest.fixture(scope="module")
def real(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """A baseline competition as the finding's (2 runs, 2 episodes of 50 steps) and a learning agent's (incremental)."""
    from neurohover.compete import compete

    root = tmp_path_factory.mktemp("real24")
    compete("ghh08", "baseline", out=root / "baseline", runs=2, episodes=2, n_steps=50)
    compete("ghh08", "incremental", out=root / "incremental", runs=2, episodes=3, n_steps=40)
    return {name: root / name for name in ("baseline", "incremental")}


def _copy(real: dict[str, Path], folder: Path, name: str, **edits: object) -> Path:
    """The real competition ``name`` in ``folder``, its summary's keys set as ``edits``."""
    folder.mkdir()
    shutil.copy(real[name] / "episodes.csv", folder / "episodes.csv")
    summary = json.loads((real[name] / "summary.json").read_text())
    (folder / "summary.json").write_text(json.dumps(summary | edits, indent=1))
    return folder


def _summary_refused(folder: Path, message: str, cli: CliRun, tmp_path: Path) -> None:
    """``folder`` refused by read_compete_dir and by ``neurohover plot --compete`` (status 2, no traceback, no file)."""
    with pytest.raises(NeurohoverError, match=rf"^--compete '{re.escape(str(folder))}/summary.json': {re.escape(message)}"):
        read_compete_dir(folder)
    rc, out, err = cli("plot", "--compete", str(folder), "--out", str(tmp_path / "plots"))
    assert rc == 2 and "Traceback" not in err and message in err and out == "", err
    assert not (tmp_path / "plots" / "compete.png").exists()


SUMMARY_CASES = [
    (
        "baseline",
        {"mean_offline_seconds_per_run": 5.0, "mean_seconds_per_run": 0.14},
        "its mean_offline_seconds_per_run 5.0 is not allowed: the agent's work between episodes is part of the run's "
        "mean_seconds_per_run 0.14: allowed at most that",
    ),
    (
        "baseline",
        {"mean_offline_seconds_per_run": 0.01, "mean_seconds_per_run": 0.14},
        "its mean_offline_seconds_per_run 0.01 is not allowed: agent baseline does no work between episodes "
        "(its first choice holds for the whole run): allowed 0",
    ),
    (
        "incremental",
        {"mean_offline_seconds_per_run": 2.0, "mean_seconds_per_run": 1.0},
        "its mean_offline_seconds_per_run 2.0 is not allowed: the agent's work between episodes is part of the run's mean_seconds_per_run 1.0",
    ),
    (
        "baseline",
        {"mean_seconds_per_run": 1e300},
        "its mean_seconds_per_run 1e+300 is not allowed: at most 3.15576e+09 seconds (100 years: no run lasts longer)",
    ),
    ("incremental", {"mean_offline_seconds_per_run": 1e10}, "its mean_offline_seconds_per_run 10000000000.0 is not allowed: at most 3.15576e+09 seconds"),
]


@pytest.mark.slow
@pytest.mark.parametrize(("name", "edits", "message"), SUMMARY_CASES, ids=[f"{n}-{i}" for i, (n, _, _) in enumerate(SUMMARY_CASES)])
def test_a_summary_whose_seconds_contradict_it_is_refused(real: dict[str, Path], cli: CliRun, tmp_path: Path, name: str, edits: dict, message: str) -> None:
    """T24-07: offline seconds 5.0 of a 0.14-second baseline run, any offline seconds of the baseline (it learns
    nothing between episodes), offline seconds beyond a learning agent's seconds, and seconds of 1e300 were plotted."""
    _summary_refused(_copy(real, tmp_path / "c", name, **edits), message, cli, tmp_path)


@pytest.mark.slow
def test_what_compete_writes_of_its_seconds_is_read(real: dict[str, Path], tmp_path: Path) -> None:
    """T24-07: a baseline competition writes offline seconds 0.0 exactly, a learning agent's more (within its
    seconds), and both are read; a learning agent's offline seconds within its seconds are its own."""
    baseline = json.loads((real["baseline"] / "summary.json").read_text())
    learning = json.loads((real["incremental"] / "summary.json").read_text())
    assert baseline["mean_offline_seconds_per_run"] == 0.0 and 0 < learning["mean_offline_seconds_per_run"] <= learning["mean_seconds_per_run"]
    for name in real:
        read_compete_dir(real[name])
    read_compete_dir(_copy(real, tmp_path / "c", "incremental", mean_offline_seconds_per_run=0.5, mean_seconds_per_run=1.0))


def test_the_agents_without_offline_work_never_have_their_update_called() -> None:
    """T24-07: each agent of NO_OFFLINE (offline seconds 0 in every run and summary) makes its first choice final, so
    run_test never calls its update; MAX_SECONDS is the checkpoints' bound (one constant, sim.constants)."""
    from neurohover.agents.registry import AGENTS
    from neurohover.agents.spec import AgentOptions, AgentPolicies
    from neurohover.evolution.state_codec import MAX_SECONDS as CHECKPOINT_MAX_SECONDS
    from neurohover.policies import baseline_policy

    assert MAX_SECONDS == CHECKPOINT_MAX_SECONDS and NO_OFFLINE <= set(AGENTS)
    for name in NO_OFFLINE:
        agent = AGENTS[name].build(AgentPolicies(generic=baseline_policy()), AgentOptions())
        assert agent.choose(0).final, name


@pytest.mark.slow
def test_a_stored_baseline_run_with_offline_seconds_is_refused(tr1, tmp_path: Path, cli: CliRun) -> None:
    """T24-07: a stored baseline run with offline seconds within its seconds was taken (compete would write them in a
    summary that plot --compete refuses); the store now refuses it as plot refuses the summary."""
    store = _edited(tr1[1], tmp_path / "s.sqlite", RUN, timing={"seconds": 1.0, "offline_seconds": 0.5})
    says = "timing.offline_seconds = 0.5 is not allowed: agent baseline does no work between episodes (its first choice holds for the whole run): allowed 0"
    message = _refused(store, "tr1", RUN, says)
    rc, out, err = cli("results", "tr1", "--store", str(store))
    assert rc == 2 and out == "" and err.strip() == f"neurohover results: error: {message}", err


def _raised_first(r: dict[str, Any]) -> list[list[Any]]:
    """The stored history with its first record raised above the last (a champion's fitness that falls)."""
    history = [list(h) for h in r["history"]]
    history[0][1] = -1.0
    return history


@pytest.mark.slow
@pytest.mark.parametrize(
    ("changes", "says"),
    [
        (
            {"timing": lambda r: {"seconds": 1.81, "kernel_seconds": 99.0}},
            "evolution run is inconsistent: timing.kernel_seconds = 99.0 is not allowed: it is part of the run's timing.seconds 1.81: allowed at most that",
        ),
        (
            {"timing": lambda r: {"seconds": 1e300, "kernel_seconds": 0.5}},
            "timing.seconds = 1e+300 is not allowed: at most 3.15576e+09 seconds (100 years: no run lasts longer)",
        ),
        (
            {"history": _raised_first},
            "its result contradicts its params: history[1] = [60, -299.4",
        ),
    ],
    ids=["kernel-seconds", "seconds", "history"],
)
def test_an_evolution_run_that_contradicts_itself_is_refused_by_every_command(ev1, tmp_path: Path, cli: CliRun, changes: dict, says: str) -> None:
    """T24-09: kernel seconds 99.0 of a 1.81-second run, and a champion's fitness that falls in a steady-state run on one
    MDP (its champion is the best fitness ever told: [[50, -1.0], [60, -299.4]]), were exported, reported and taken by
    reproduce --update; each command now refuses them in one message and leaves the store as it was."""
    config, good = ev1
    store = _edited(good, tmp_path / "s.sqlite", EVOLVE, **changes)
    line = _refused(store, "ev1", EVOLVE, says)
    refused_by_every_command(cli, config, store, "ev1", line, tmp_path / "r")


@pytest.mark.slow
def test_the_falling_history_message_names_the_records(ev1, tmp_path: Path) -> None:
    """T24-09: the message names the record that falls, the earlier record's fitness and what is allowed."""
    store = _edited(ev1[1], tmp_path / "s.sqlite", EVOLVE, history=_raised_first)
    message = _refused(store, "ev1", EVOLVE, "history[1] = [60, -299.")
    assert message.endswith(
        "is not allowed: its unit evolves on one MDP (params.target.kind 'mdp'), where the champion is the best fitness ever told, "
        "and an earlier record reached -1.0: allowed at least that"
    ), message


@pytest.mark.slow
def test_a_falling_history_is_taken_where_the_champion_is_each_generations_best(ev1) -> None:
    """T24-09: only what is proven is refused: on a family (generational NE, races, CMA-ES, OpenAI-ES, uh-cma: the best
    estimate of the last generation) and for NEAT (each generation's best) a champion's fitness may fall."""
    with sqlite3.connect(ev1[1]) as conn:
        params, result = conn.execute("SELECT params, result FROM units WHERE key = ?", (EVOLVE,)).fetchone()
    conn.close()
    stored = json.loads(result)
    run = result_from_dict("evolve", stored | {"history": _raised_first(stored)}, EVOLVE)
    on_mdp = json.loads(params)
    assert params_problem(run, on_mdp).startswith("history[1] = [60, -299.")
    on_family = on_mdp | {"target": {"kind": "family", "task": "fghh", "sigma": 0.3}}
    assert params_problem(run, on_family) == ""
    assert _history_fall_problem(run, on_mdp | {"topology": "neat"}) == ""
