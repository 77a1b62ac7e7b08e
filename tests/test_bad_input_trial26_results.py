"""The twenty-sixth bad-input trial's findings in stored results, checkpoints, compete output and flight data: a stored
steady-state run whose generations its evaluations contradict was exported and reported (T26-B04); a checkpoint whose
counters.generation contradicts its optimiser's was resumed and its count written (T26-B05); a crash charged less than
the simulator charges it (T26-B09: refused where the crash step is known; a crash on the last step is charged nothing,
so the trial's own cases are sound); a compete run on another run's MDP was plotted (T26-B10); an exact recording
flagged uncrashed with a reading past a crash bound was learned from (T26-B11); a store missing the evolution run a
robustness unit was made from was told as holding a unit the config does not plan (T26-B15)."""

from __future__ import annotations

import json
import shutil
import sqlite3
from pathlib import Path

import numpy as np
import pytest
from conftest import CliRun
from store_edits import damaged, refused_by_every_command
from test_bad_input_trial23_results import EV1, _edited, _refused, _reproduced, _stored

from neurohover.compete_files import read_compete_dir
from neurohover.errors import NeurohoverError
from neurohover.evolution.steady_state import steady_state_evaluations
from neurohover.experiments import Store
from neurohover.experiments.export import checked_units
from neurohover.experiments.result_checks import params_problem
from neurohover.experiments.results import TestRunResult
from neurohover.flightdata import FlightData
from neurohover.sim.constants import CRASH_STEP_PENALTY
from neurohover.sim.kernel import crash_charge

EVOLVE = "evolve/slp-zero/train0/run0"
ROBUST = "robust/mlp-baseline/train0"


@pytest.fixture(scope="module")
def ev1(tmp_path_factory) -> tuple[Path, Path]:
    """EV1's config (trial 23: steady-state SLP and MLP runs of 60 episodes, a robustness unit) and a store of it."""
    return _reproduced(tmp_path_factory.mktemp("ev26"), EV1)


# --------------------------------------------------------------------------- T26-B04: generations against evaluations


def test_the_steady_state_rule_is_one() -> None:
    """T26-B04: pop_size 50, elite 49: generation 1 is 50 evaluations, 11 is 60; no generation is none."""
    assert [steady_state_evaluations(g, 50, 49) for g in (0, 1, 11)] == [0, 50, 60]
    assert steady_state_evaluations(3, 6, 2) == 6 + 2 * 4


@pytest.mark.slow
def test_a_stored_steady_state_run_of_generations_its_evaluations_contradict_is_refused(ev1: tuple[Path, Path], tmp_path: Path, cli: CliRun) -> None:
    """T26-B04: generations 40 beside 60 evaluations of pop_size 50, elite 49 (generation 11) was exported and reported."""
    config, store = ev1
    stored = _stored(store, EVOLVE)
    assert (stored["evaluations"], stored["generations"]) == (60, 11)
    at = _edited(store, tmp_path / "g.sqlite", EVOLVE, generations=40)
    says = (
        "generations = 40 is not allowed: its unit evolves by steady state (pop_size 50, elite_size 49: its first generation evaluates 50 "
        "candidates, each later one 1), and its 60 evaluations are generation 11: allowed 11"
    )
    line = _refused(at, "ev1", EVOLVE, says)
    refused_by_every_command(cli, config, at, "ev1", line, tmp_path / "report")


@pytest.mark.slow
def test_a_steady_state_run_under_other_optimiser_settings_is_checked_by_them(ev1: tuple[Path, Path]) -> None:
    """T26-B04: the rule takes the unit's own pop_size and elite_size; a run of another optimiser is not checked by it."""
    from neurohover.experiments.results import EvolveResult

    with sqlite3.connect(ev1[1]) as conn:
        params = json.loads(conn.execute("SELECT params FROM units WHERE key = ?", (EVOLVE,)).fetchone()[0])
    conn.close()
    edits = {"generations": 3, "evaluations": 14, "episodes": 14, "history": [[14, -1.0]], "champion_return": -1.0}
    run = EvolveResult.from_dict({**_stored(ev1[1], EVOLVE), **edits}, EVOLVE)
    small = {**params, "optimiser": {"pop_size": 6, "elite_size": 2}, "budget": 14}
    assert "generations" not in params_problem(run, small) and "evaluations = 14" not in params_problem(run, small)
    problem = params_problem(run, {**params, "budget": 14})
    assert problem.startswith("evaluations = 14 is not allowed: its unit evolves by steady state (pop_size 50, elite_size 49")
    assert problem.endswith("and its 3 generations are 52 evaluations: allowed 52")
    assert params_problem(run, {**params, "optimiser": {"name": "cma"}, "budget": 14}) == ""


# --------------------------------------------------------------------------- T26-B05: a checkpoint's generation

CLI_RUN = ("evolve", "--task", "ghh08", "--mdp", "zero", "--topology", "slp", "--seed-policy", "baseline", "--seed", "3", "--episode-steps", "20")


@pytest.mark.parametrize(
    ("counter", "value", "says"),
    [
        ("generation", 5, "counter 'generation' is 5, but optimizer_state.generation is 1: the optimiser is told once a generation of the run (allowed 1)"),
        (
            "evaluations",
            49,
            "counter 'evaluations' is 49, but its 1 steady-state generations are 50 evaluations (pop_size 50, then 1 a generation): allowed 50",
        ),
    ],
)
def test_a_checkpoint_whose_counters_contradict_its_optimiser_is_refused(
    tiny_checkpoint: Path, tmp_path: Path, cli: CliRun, counter: str, value: int, says: str
) -> None:
    """T26-B05: counters.generation 5 beside an optimiser at generation 1 was resumed and written as 15 generations."""
    state = json.loads(tiny_checkpoint.read_text())
    assert (state["counters"]["generation"], state["optimizer_state"]["generation"], state["counters"]["evaluations"]) == (1, 1, 50)
    state["counters"][counter] = value
    (tmp_path / "run.json.checkpoint.json").write_text(json.dumps(state))
    out = tmp_path / "run.json"
    rc, _, err = cli(*CLI_RUN, "--budget", "60", "--out", str(out), "--resume")
    assert rc == 2 and "Traceback" not in err and not out.exists(), err
    assert f"is a damaged checkpoint: {says}; resume from an undamaged copy" in " ".join(err.split()), err


def test_a_sound_checkpoint_resumes_to_its_own_count(tiny_checkpoint: Path, tmp_path: Path, cli: CliRun) -> None:
    """T26-B05: the unedited checkpoint resumes; 60 episodes of pop_size 50, elite 49 are 11 generations."""
    shutil.copyfile(tiny_checkpoint, tmp_path / "run.json.checkpoint.json")
    out = tmp_path / "run.json"
    rc, _, err = cli(*CLI_RUN, "--budget", "60", "--out", str(out), "--resume")
    assert rc == 0, err
    assert json.loads(out.read_text())["generations"] == 11


# --------------------------------------------------------------------------- T26-B09: a crash's charge


def test_a_crash_on_the_last_step_is_charged_nothing() -> None:
    """T26-B09, verified: the kernel charges the worst step for each step left after the crashing one, none on the last;
    so a crashed episode of any return <= 0 is sound where its crash step is not known."""
    assert crash_charge(20, 20) == 0.0 and crash_charge(20, 10) == -10 * CRASH_STEP_PENALTY


@pytest.mark.slow
def test_the_trials_crashed_results_are_sound_without_their_crash_steps(ev1: tuple[Path, Path], tmp_path: Path) -> None:
    """T26-B09 (1), (2): champion_crashed true beside a champion return of -58.4 (the mean of K episodes, any of which
    may crash on its last step) and a robustness crash beside a return of -64.7 are read as stored."""
    at = _edited(ev1[1], tmp_path / "c.sqlite", EVOLVE, champion_crashed=True)
    at = _edited(at, tmp_path / "c2.sqlite", ROBUST, crashes=lambda r: [1] * len(r["crashes"]))
    with Store(at, create=False) as held:
        _, _, results = checked_units(held, "ev1", "quick")
    assert results[EVOLVE].champion_crashed is True and list(results[ROBUST].crashes) == [1]  # type: ignore[union-attr]


def test_a_stored_crash_charged_less_than_its_step_gives_is_refused() -> None:
    """T26-B09 where the step is known: a run's crash at step 10 of 20 returning -6.1 (charged 10 worst steps: at most
    -17488) is refused; the same crash on step 20 is sound."""
    stored = {
        "agent": "baseline", "mdp": "ghh08/test:0", "score": -6.1, "returns": [-6.1], "crash_episodes": [0], "safeguard_episodes": [],
        "policy_changes": [[0, "baseline"]], "learning_episodes": 0, "mean_return_after_learning": -6.1, "crash_steps": [10],
        "timing": {"seconds": 0.1, "offline_seconds": 0.0},
    }  # fmt: skip
    params = {"agent": "baseline", "n_steps": 20}
    problem = params_problem(TestRunResult.from_dict(stored, "run/baseline/test0/rep0"), params)
    assert problem == (
        "returns[0] = -6.1 is not allowed: episode 0 crashed at step 10 of its 20, and a crash is charged 1748.81 for each step left: "
        "allowed at most -17488.07999"
    )
    assert params_problem(TestRunResult.from_dict({**stored, "crash_steps": [20]}, "run/baseline/test0/rep0"), params) == ""


@pytest.fixture(scope="module")
def competition(tmp_path_factory) -> Path:
    """An incremental competition on GHH-08's test MDPs: 2 runs of 3 episodes of 20 steps (the trial's c2)."""
    from neurohover.compete import compete

    out = tmp_path_factory.mktemp("c26") / "c2"
    compete("ghh08", "incremental", out=out, runs=2, episodes=3, n_steps=20)
    return out


def _rows_edited(competition: Path, at: Path, old: str, new: str, summary: bool = True) -> Path:
    at.mkdir()
    text = (competition / "episodes.csv").read_text()
    assert old in text
    (at / "episodes.csv").write_text(text.replace(old, new))
    if summary:
        shutil.copyfile(competition / "summary.json", at / "summary.json")
    return at


@pytest.mark.slow
def test_a_compete_crash_charged_less_than_its_step_gives_is_refused(competition: Path, tmp_path: Path, cli: CliRun) -> None:
    """T26-B09 (3): the trial's row (crashed 1, return -6.1, step 20 of 20) is sound; at step 10 it is refused, without
    a summary too (the file's longest episode bounds the episodes' length)."""
    first = (competition / "episodes.csv").read_text().splitlines()[1]
    run, mdp, episode, ret, crashed, steps, rest = first.split(",", 6)
    assert (crashed, steps) == ("0", "20")
    last_step = _rows_edited(competition, tmp_path / "last", first, ",".join([run, mdp, episode, ret, "1", "20", rest]), summary=False)
    assert read_compete_dir(last_step).crashes == 1
    mid = _rows_edited(competition, tmp_path / "mid", first, ",".join([run, mdp, episode, ret, "1", "10", rest]), summary=False)
    rc, _, err = cli("plot", "--compete", str(mid), "--out", str(tmp_path / "pl"))
    assert rc == 2 and not (tmp_path / "pl").exists(), err
    assert f"line 2: return {float(ret)!r} is not allowed: the episode crashed at step 10 of its 20, and a crash is charged 1748.81 for each step left" in err


# --------------------------------------------------------------------------- T26-B10: a run's MDP


@pytest.mark.slow
def test_a_compete_run_on_another_runs_mdp_is_refused(competition: Path, tmp_path: Path, cli: CliRun) -> None:
    """T26-B10: run 1 of 2 on test:0 (compete flies it on test:1) was plotted; refused with the summary and without."""
    assert read_compete_dir(competition).returns.shape == (2, 3)
    for summary in (True, False):
        at = _rows_edited(competition, tmp_path / f"c10-{summary}", "\n1,ghh08/test:1,", "\n1,ghh08/test:0,", summary=summary)
        rc, _, err = cli("plot", "--compete", str(at), "--out", str(at / "pl"))
        assert rc == 2 and not (at / "pl").exists(), err
        assert (
            "line 5: mdp 'ghh08/test:0' is not allowed: compete flies its test MDPs in turn, run i on test:i, so run 1 of its 2 runs flies ghh08/test:1"
        ) in err


# --------------------------------------------------------------------------- T26-B11: readings past a crash bound


@pytest.fixture(scope="module")
def flights(tmp_path_factory) -> dict[str, Path]:
    """fly --record's files: the trial's (train:1, 2 episodes), one that crashes (the zero policy), a noisy sensor's."""
    from neurohover.cli import main

    folder = tmp_path_factory.mktemp("flights26")
    (folder / "zero.json").write_text(json.dumps({"topology": "slp", "genome": [0.0] * 40}))
    runs = {
        "f": ["--mdp", "train:1", "--episodes", "2"],
        "fall": ["--mdp", "train:1", "--episodes", "1", "--policy", str(folder / "zero.json")],
        "noisy": ["--mdp", "train:1", "--episodes", "1", "--obs-noise", "0.5"],
    }
    paths = {}
    for name, argv in runs.items():
        paths[name] = folder / f"{name}.npz"
        assert main(["fly", "--task", "ghh08", *argv, "--threads", "1", "--record", str(paths[name])]) == 0
    return paths


def _observation_edited(flight: Path, at: Path, row: int, column: int, value: float) -> Path:
    """``flight`` with one reading set and its returns and policy_flown removed (they would name the edit otherwise)."""
    with np.load(flight) as z:
        arrays = {k: z[k] for k in z.files}
    metadata = json.loads(str(arrays["metadata"]))
    metadata.pop("returns"), metadata.pop("policy_flown")
    arrays["observations"] = arrays["observations"].copy()
    arrays["observations"][row, column] = value
    np.savez_compressed(at, **{**arrays, "metadata": np.array(json.dumps(metadata))})
    return at


@pytest.mark.slow
def test_an_uncrashed_episode_past_a_crash_bound_is_refused(flights: dict[str, Path], tmp_path: Path, cli: CliRun) -> None:
    """T26-B11: x 50 m (no world component is past 20 m, so no body-frame reading past 34.6 m) at step 100 of an episode
    flagged uncrashed was loaded and learned from."""
    at = _observation_edited(flights["f"], tmp_path / "x.npz", 100, 3, 50.0)
    says = "its metadata crashed=[False, False] is not allowed: episode 0 is flagged uncrashed, yet after step 100 its distance is 50."
    with pytest.raises(NeurohoverError, match="past the crash bound 34.64 m") as err:
        FlightData.load(at)
    assert says in str(err.value)
    rc, _, stderr = cli("learn-model", "--flight-data", str(at), "--method", "lr", "--out", str(tmp_path / "m.json"))
    assert rc == 2 and says in stderr and not (tmp_path / "m.json").exists(), stderr


@pytest.mark.slow
@pytest.mark.parametrize(("column", "value", "says"), [(6, 13.0, "its rate is 13, past the crash bound 12.57 rad/s"), (9, 0.5, "its tilt is 60")])
def test_each_crash_bound_is_read(flights: dict[str, Path], tmp_path: Path, column: int, value: float, says: str) -> None:
    """T26-B11: the rates' bound and the tilt's (a quaternion's vector part of 0.5 is 60 degrees off level)."""
    with pytest.raises(NeurohoverError, match=f"after step 7 {says}"):
        FlightData.load(_observation_edited(flights["f"], tmp_path / "x.npz", 7, column, value))


@pytest.mark.slow
def test_a_crashed_episodes_readings_before_its_last_are_within_the_bounds(flights: dict[str, Path], tmp_path: Path) -> None:
    """T26-B11: a crash's last reading is past a bound (sound), a reading before it is refused."""
    crashed = FlightData.load(flights["fall"])
    assert crashed.metadata["crashed"] == [True] and crashed.observations[0].shape[0] > 3
    with pytest.raises(NeurohoverError, match=r"episode 0's observations are not allowed: after step 2 its speed is 9\.\d+, past the crash bound 8\.66 m/s"):
        FlightData.load(_observation_edited(flights["fall"], tmp_path / "c.npz", 2, 0, 9.0))


@pytest.mark.slow
def test_a_noisy_sensors_readings_are_not_held_to_the_bounds(flights: dict[str, Path], tmp_path: Path) -> None:
    """T26-B11: only exact readings are the state; a noisy sensor's may lie past a bound."""
    assert FlightData.load(_observation_edited(flights["noisy"], tmp_path / "n.npz", 100, 3, 50.0)).observations[0][100, 3] == 50.0


# --------------------------------------------------------------------------- T26-B15: a missing source unit


@pytest.mark.slow
@pytest.mark.parametrize("sql", ["DELETE FROM units WHERE key = '{key}'", "UPDATE units SET name = 'fig7' WHERE key = '{key}'"])
def test_a_unit_whose_source_is_missing_is_named_so(ev1: tuple[Path, Path], tmp_path: Path, cli: CliRun, sql: str) -> None:
    """T26-B15: the robustness unit's evolution run deleted (or moved to another experiment) was told as a unit the
    config does not plan; the refusal now names the missing unit it is made from."""
    config, store = ev1
    source = "evolve/mlp-baseline/train0/run0"
    at = damaged(store, tmp_path / "s.sqlite", sql.format(key=source))
    with Store(at, create=False) as held, pytest.raises(NeurohoverError) as err:
        checked_units(held, "ev1", "quick")
    line = str(err.value)
    assert line == (
        f"results store {str(at)!r}, experiment ev1 (quick), is damaged: it holds unit {ROBUST!r}, made from unit {source!r}, which it does not hold: "
        "the config plans the one once the other is stored; the unit it is made from was removed or moved (reproduce --fresh starts it over)"
    )
    if sql.startswith("DELETE"):
        refused_by_every_command(cli, config, at, "ev1", line, tmp_path / "report")
