"""The twenty-second bad-input trial's findings in stored test runs: a result whose returns are positive (T22-05), whose
derived figures contradict its returns (T22-06), whose crashes are named twice or at steps no episode has (T22-07), that
contradicts its unit's params (T22-08), or whose policy changes, timing or experiment row are out of range (T22-09) was
exported, counted and reported; the shared check (checked_units -> result_from_dict) now refuses each in one message
naming the store, the experiment, the unit, the field, the value and what is allowed."""

from __future__ import annotations

import json
import math
import shutil
import sqlite3
from pathlib import Path
from typing import Any

import pytest
from conftest import CliRun, tiny_test_runs

from neurohover.errors import NeurohoverError
from neurohover.experiments import Store
from neurohover.experiments.export import checked_units

RUN = "run/model-free/test0/rep0"


@pytest.fixture(scope="module")
def tiny(tmp_path_factory) -> Path:
    """A store holding one finished test run of model-free (two 20-step episodes on a GHH-08 test MDP); tests edit
    copies of it."""
    from neurohover.cli import main

    where = tmp_path_factory.mktemp("tiny22")
    config = where / "tr1.toml"
    config.write_text(tiny_test_runs("model-free"))
    assert main(["reproduce", str(config), "--store", str(where / "s.sqlite"), "--no-progress"]) == 0
    return where / "s.sqlite"


def _edited(store: Path, at: Path, **changes: Any) -> Path:
    """A copy of ``store`` at ``at`` whose RUN result has ``changes`` (a callable: of the stored result)."""
    shutil.copyfile(store, at)
    with sqlite3.connect(at) as conn:
        result = json.loads(conn.execute("SELECT result FROM units WHERE key = ?", (RUN,)).fetchone()[0])
        result.update({k: v(result) if callable(v) else v for k, v in changes.items()})
        conn.execute("UPDATE units SET result = ? WHERE key = ?", (json.dumps(result), RUN))
    conn.close()
    return at


def _stored(store: Path) -> dict:
    """RUN's result as ``store`` holds it."""
    with sqlite3.connect(store) as conn:
        result = json.loads(conn.execute("SELECT result FROM units WHERE key = ?", (RUN,)).fetchone()[0])
    conn.close()
    return result


def _refused(store: Path, says: str) -> str:
    """The shared check's message on ``store``, asserted to name the store, the experiment, RUN and ``says``."""
    with Store(store, create=False) as held, pytest.raises(NeurohoverError) as caught:
        checked_units(held, "tr1", "quick")
    message = str(caught.value)
    assert message.startswith(f"results store {str(store)!r}, experiment tr1 (quick), is damaged: unit '{RUN}': ") and says in message, message
    return message


def _refused_by_results(cli: CliRun, store: Path, says: str) -> None:
    """``neurohover results`` refuses ``store`` with exit status 2 and the shared check's message."""
    message = _refused(store, says)
    rc, out, err = cli("results", "tr1", "--store", str(store))
    assert rc == 2 and out == "" and err.strip() == f"neurohover results: error: {message}", err


@pytest.mark.parametrize(
    ("returns", "says"),
    [
        ([5.0, 7.0], "returns[0] = 5.0 is no episode's return: allowed a finite number in [-1.75e+10, 0]"),
        ([-5.0, 1e-3], "returns[1] = 0.001 is no episode's return"),
        ([-5.0, -1e300], "returns[1] = -1e+300 is no episode's return"),
    ],
)
def test_a_run_of_positive_returns_is_refused(tiny: Path, tmp_path: Path, cli: CliRun, returns: list[float], says: str) -> None:
    """T22-05: returns [5, 7, 1] (score 13) were reported as model-free's mean; compete's reader refuses a return > 0
    (every reward is minus a sum of squares), and now the stored run is refused too."""
    store = _edited(tiny, tmp_path / "s.sqlite", returns=returns, score=math.fsum(returns), learning_episodes=0, mean_return_after_learning=sum(returns) / 2)
    _refused_by_results(cli, store, says)


@pytest.mark.parametrize(
    ("changes", "says"),
    [
        ({"mean_return_after_learning": math.nan}, "mean_return_after_learning = nan is not the mean of its returns after its 1 learning episode(s): allowed "),
        ({"mean_return_after_learning": "nan"}, "mean_return_after_learning = 'nan' is not the mean of its returns"),
        ({"mean_return_after_learning": -1e9}, "mean_return_after_learning = -1000000000.0 is not the mean of its returns"),
        ({"learning_episodes": 2}, "learning_episodes = 2 is outside 0..1 (the episode from which its policy no longer changed)"),
    ],
)
def test_a_mean_after_learning_that_contradicts_the_returns_is_refused(tiny: Path, tmp_path: Path, cli: CliRun, changes: dict, says: str) -> None:
    """T22-06: a mean return after learning of NaN (printed as bare NaN by results --format json, shown n/a by report)
    or -1e9, contradicting the returns after the learning episodes, was accepted; now it must be their mean."""
    store = _edited(tiny, tmp_path / "s.sqlite", **changes)
    message = _refused(store, says)
    sound = _stored(tiny)
    assert sound["learning_episodes"] == 1 and sound["mean_return_after_learning"] == sound["returns"][1]  # what the edits contradict
    assert "learning_episodes" in changes or message.endswith(f"allowed {sound['returns'][1]!r}"), message
    rc, out, err = cli("results", "tr1", "--store", str(store), "--format", "json")
    assert rc == 2 and out == "" and err.strip() == f"neurohover results: error: {message}", err


@pytest.mark.parametrize(
    ("changes", "says"),
    [
        (
            {"crash_episodes": [1, 1], "crash_steps": [5, -3]},
            "test run of model-free on ghh08/test:0 is inconsistent: crash_episodes = [1, 1] is not allowed: each episode of 0..1 at most once, in order",
        ),
        ({"crash_episodes": [1, 0], "crash_steps": [5, 6]}, "crash_episodes = [1, 0] is not allowed: each episode of 0..1 at most once, in order"),
        ({"safeguard_episodes": [0, 0]}, "safeguard_episodes = [0, 0] is not allowed: each episode of 0..1 at most once, in order"),
        ({"crash_episodes": [0, 1], "crash_steps": [5, -3]}, "crash_steps[1] = -3 is not allowed: a crash ends its episode at control step 1 or later"),
        ({"crash_episodes": [1], "crash_steps": [0]}, "crash_steps[0] = 0 is not allowed"),
        (
            {"crash_episodes": [1], "crash_steps": [999999]},
            "its result contradicts its params: crash_steps[0] = 999999 is not allowed: its unit's episodes are 20 control steps long: allowed 1..20",
        ),
    ],
)
def test_crashes_named_twice_or_at_steps_no_episode_has_are_refused(tiny: Path, tmp_path: Path, cli: CliRun, changes: dict, says: str) -> None:
    """T22-07: crash_episodes [1, 1] with crash_steps [5, -3] were counted as two crashes of the run, a crash step 999999
    of a 20-step episode accepted; now crash (and safeguard) episodes are each named once, in order, and a crash step is
    one of its unit's episodes' control steps (the kernel counts them from 1; a crash on the last one is one)."""
    _refused_by_results(cli, _edited(tiny, tmp_path / "s.sqlite", **changes), says)


def test_a_crash_on_an_episodes_last_step_is_taken(tiny: Path, tmp_path: Path) -> None:
    """T22-07: the bound is the kernel's: a crash at control step n_steps (20) is one a run records (charged no step
    left, so of any return; a crash at step 1 of these returns is not: T26-B09)."""
    store = _edited(tiny, tmp_path / "s.sqlite", crash_episodes=[0, 1], crash_steps=[20, 20])
    with Store(store, create=False) as held:
        assert checked_units(held, "tr1", "quick")[2][RUN].crash_steps == (20, 20)


@pytest.mark.parametrize(
    ("changes", "says"),
    [
        (  # T25-09: an agent that flies the run's specialised policies ('baseline' is now refused for its policy_changes first)
            {"agent": "model-free-risk"},
            "its result contradicts its params: agent = 'model-free-risk' is not allowed: its unit's params.agent is 'model-free', "
            "and a result must be its unit's",
        ),
        ({"mdp": "ghh09/test:7"}, "mdp = 'ghh09/test:7' is not allowed: its unit's params.mdp.label is 'ghh08/test:0', and a result must be its unit's"),
    ],
)
def test_a_result_that_contradicts_its_units_params_is_refused(tiny: Path, tmp_path: Path, cli: CliRun, changes: dict, says: str) -> None:
    """T22-08: a run whose key and params say model-free on ghh08/test:0 holding agent 'baseline' and mdp 'ghh09/test:7'
    was exported (group model-free, result.agent baseline), counted by wins and reported; now the result must be its unit's."""
    store = _edited(tiny, tmp_path / "s.sqlite", **changes)
    _refused_by_results(cli, store, says)
    rc, out, err = cli("wins", "tr1", "--store", str(store), "--runs", "1", "--draws", "10")
    assert rc == 2 and says in err, err


def test_a_model_result_that_contradicts_its_units_params_is_refused() -> None:
    """T22-08: the same rule for a model unit's method and MDP (checked_units calls it for every unit)."""
    from neurohover.experiments.result_checks import params_problem
    from neurohover.experiments.results import ModelResult, ModelTiming

    model = ModelResult(
        method="lr", mdp="ghh08/test:0", generic_return=-1.0, generic_crashed=False, model_params=(0.0,) * 11, model_noise_std=(0.0,) * 6,
        predicted_return=-1.0,
        test_returns=(-1.0,), test_mean=-1.0, test_crashes=0, policy_episodes=1, timing=ModelTiming(learn_seconds=0.0, evolve_seconds=0.0),
    )  # fmt: skip
    params = {"method": "lr", "mdp": {"label": "ghh08/test:0"}}
    assert params_problem(model, params) == ""
    assert params_problem(model, {**params, "method": "ec-mer"}).startswith("method = 'lr' is not allowed: its unit's params.method is 'ec-mer'")
    assert "mdp = 'ghh08/test:0' is not allowed: its unit's params.mdp.label is 'x'" in params_problem(model, {**params, "mdp": {"label": "x"}})


@pytest.mark.parametrize(
    ("changes", "says"),
    [
        (
            {"policy_changes": [[50, "x"], [-1, ""]]},
            "inconsistent: policy_changes[0] = [50, 'x'] is not allowed: give [episode, policy name], its episodes among 0..1, in order, each once",
        ),
        ({"policy_changes": [[0, "a"], [-1, ""]]}, "policy_changes[1] = [-1, ''] is not allowed"),
        ({"policy_changes": [[0, "a"], [0, "b"]]}, "policy_changes[1] = [0, 'b'] is not allowed"),
        ({"policy_changes": [[0, "a"], [1, ""]]}, "policy_changes[1] = [1, ''] is not allowed"),
        ({"policy_changes": [[0, 3]]}, "policy_changes[0] = [0, 3] is not allowed"),
        ({"policy_changes": ["x"]}, "policy_changes[0] = 'x' is not allowed"),
        ({"timing": {"seconds": -5, "offline_seconds": 0.0}}, "timing.seconds = -5 is not allowed: give a finite number of seconds >= 0"),
        ({"timing": {"seconds": 1.0, "offline_seconds": "x"}}, "timing.offline_seconds = 'x' is not allowed: give a finite number of seconds >= 0"),
    ],
)
def test_policy_changes_outside_the_run_and_negative_seconds_are_refused(tiny: Path, tmp_path: Path, cli: CliRun, changes: dict, says: str) -> None:
    """T22-09: policy_changes [[50, 'x'], [-1, '']] of a run of episodes 0..2 and a timing of -5 seconds were accepted."""
    _refused_by_results(cli, _edited(tiny, tmp_path / "s.sqlite", **changes), says)


def test_an_experiment_created_at_no_number_is_named_as_damage(tiny: Path, tmp_path: Path, cli: CliRun) -> None:
    """T22-09: experiments.created = 'yesterday' (the time that orders a store's experiments) was taken by results,
    wins and report; the store now names it as damage where it reads it, and reproduce --fresh starts the experiment over."""
    store = tmp_path / "s.sqlite"
    shutil.copyfile(tiny, store)
    with sqlite3.connect(store) as conn:
        conn.execute("UPDATE experiments SET created = 'yesterday'")
    conn.close()
    says = (
        f"results store {str(store)!r} is damaged: experiment 'tr1' ('quick')'s created time 'yesterday' is no number: allowed seconds "
        "since 1970 (give another --store file, or reproduce --fresh to start it over)"
    )
    with Store(store, create=False) as held, pytest.raises(NeurohoverError) as caught:
        held.experiments()
    assert str(caught.value) == says
    for argv, command in ((("results", "tr1"), "results"), (("wins", "tr1", "--runs", "1", "--draws", "10"), "wins")):
        rc, out, err = cli(*argv, "--store", str(store))
        assert rc == 2 and out == "" and err.strip() == f"neurohover {command}: error: {says}", err
    rc, out, err = cli("report", "--store", str(store), "--out", str(tmp_path / "r"))
    assert rc == 2 and says in err and not (tmp_path / "r").exists(), err
    config = tmp_path / "tr1.toml"
    config.write_text(tiny_test_runs("model-free"))
    rc, out, err = cli("reproduce", str(config), "--store", str(store), "--no-progress")
    assert rc == 2 and err.strip() == f"neurohover reproduce: error: {says}", err
    with Store(store, create=False) as held:  # begin(fresh=True), as reproduce --fresh calls it: the row is made again
        held.begin("tr1", "quick", held.config_hash("tr1", "quick") or "", held.config("tr1", "quick"), fresh=True)
        assert [n for n, _, _, _ in held.experiments()] == ["tr1"]
