"""The twenty-fifth bad-input trial's findings in compete rows and stored results an agent never writes: a policy that
a multi-policy agent never flies in a compete episodes.csv (authors-zero's 'specialised:1', model-free's 'model:1' or
'specialised:99') was plotted (T25-08), and in a stored test run's policy_changes was exported, reported and copied
into episodes.csv (T25-09); a stored model unit with 3 model parameters, a generic return of 5.0 or negative noise
standard deviations was exported and reported (T25-10). Each is refused in one message naming the file or unit, the
field, the value and what is allowed."""

from __future__ import annotations

import csv
import json
import re
import sqlite3
from pathlib import Path

import pytest
from conftest import CliRun, tiny_model_learning, tiny_test_runs
from store_edits import refused_by_every_command
from test_bad_input_trial23_results import _edited, _refused, _reproduced

from neurohover.compete_files import read_compete_dir
from neurohover.compete_labels import ONE_POLICY, POLICY_LABELS, policy_label_problem
from neurohover.errors import NeurohoverError

RUN = "run/model-free/test0/rep0"


@pytest.fixture(scope="module")
def mf(tmp_path_factory) -> tuple[Path, Path]:
    """A config of one model-free test run (two 20-step episodes on a GHH-08 test MDP) and a store of it."""
    return _reproduced(tmp_path_factory.mktemp("mf25"), tiny_test_runs("model-free", name="mf1"))


@pytest.fixture(scope="module")
def ml(tmp_path_factory) -> tuple[Path, Path]:
    """A config of one LR model unit (baseline generic, 20 steps, budgets of 10) and a store of it."""
    return _reproduced(tmp_path_factory.mktemp("ml25"), tiny_model_learning("ml1", "baseline"))


@pytest.fixture(scope="module")
def competition(tmp_path_factory) -> Path:
    """A model-free competition on GHH-08: 1 run of 2 episodes of 20 steps (specialised:0, then specialised:1)."""
    from neurohover.compete import compete

    out = tmp_path_factory.mktemp("c25") / "c"
    compete("ghh08", "model-free", out=out, runs=1, episodes=2, n_steps=20)
    return out


def test_the_policy_table_is_the_agents() -> None:
    """T25-08: POLICY_LABELS (this layer may not import the agents) holds every agent but the one-policy ones, and the
    numbers their labels take: the task's specialised policies, hybrid's N_EVOLVED, the authors' evolutions; the
    model-free agent labels each of its policies within it."""
    from neurohover.agents.fghh_code import CodeAgentSettings
    from neurohover.agents.hybrid import N_EVOLVED
    from neurohover.agents.model_free import ModelFreeAgent
    from neurohover.agents.registry import AGENTS
    from neurohover.policies import baseline_policy
    from neurohover.tasks import get_task_family

    assert set(POLICY_LABELS) | set(ONE_POLICY) == set(AGENTS) and not set(POLICY_LABELS) & set(ONE_POLICY)
    for task in ("ghh08", "ghh09"):
        assert POLICY_LABELS["model-free"]["specialised"] == (0, len(get_task_family(task).training_mdps()) - 1)
    assert POLICY_LABELS["hybrid-risk"]["model"] == (0, N_EVOLVED - 1)
    assert POLICY_LABELS["authors-race"]["model"] == (1, CodeAgentSettings().evolutions)
    agent = ModelFreeAgent([baseline_policy()] * 10)
    for episode in range(12):
        assert policy_label_problem("model-free", agent.choose(episode).label) == ""


@pytest.mark.parametrize(
    ("agent", "label", "says"),
    [
        ("authors-zero", "specialised:1", "policy 'specialised:1' is not allowed: agent authors-zero flies generic, model:1..3"),
        ("authors-zero", "model:7", "policy 'model:7' is not allowed: agent authors-zero flies generic, model:1..3"),
        ("model-free", "model:1", "policy 'model:1' is not allowed: agent model-free flies specialised:0..9"),
        ("model-based", "model:2", "policy 'model:2' is not allowed: agent model-based flies generic, model:1"),
        ("incremental", "model:0", "policy 'model:0' is not allowed: agent incremental flies generic, model:N (N >= 1)"),
        ("hybrid", "generic", "policy 'generic' is not allowed: agent hybrid flies safe:0..1, model:0..2, replacement:N (N >= 1)"),
        ("continual", "model:01", "policy 'model:01' is not allowed: agent continual flies generic, model:N (N >= 1)"),
        ("generic", "model:0", "policy 'model:0' is not allowed: agent generic flies 'generic' only"),
    ],
)
def test_a_policy_the_agent_never_flies_is_named(agent: str, label: str, says: str) -> None:
    """T25-08, T25-09: the one check of a policy label, by agent, naming what the agent flies."""
    assert policy_label_problem(agent, label) == says


@pytest.mark.parametrize("label", ["generic", "model:3", "model:291", "replacement:95", "safe:1", "specialised:9"])
def test_the_policies_the_agents_fly_are_taken(label: str) -> None:
    """T25-08: labels the committed store's runs hold are taken for their agents; an agent not in the table (a
    hand-written one) is not checked."""
    agents = {"generic": "continual", "model:3": "authors-zero", "model:291": "continual", "replacement:95": "hybrid", "safe:1": "hybrid-risk"}
    assert policy_label_problem(agents.get(label, "model-free-risk"), label) == ""
    assert policy_label_problem("my-agent", "anything") == ""


@pytest.mark.parametrize(("label", "allowed"), [("model:1", "specialised:0..9"), ("specialised:99", "specialised:0..9")])
def test_an_episodes_row_of_a_policy_the_agent_never_flies_is_refused(competition: Path, cli: CliRun, tmp_path: Path, label: str, allowed: str) -> None:
    """T25-08: model-free's 'specialised:1' edited to 'model:1' or 'specialised:99' in episodes.csv was plotted."""
    folder = tmp_path / "c"
    folder.mkdir()
    (folder / "summary.json").write_text((competition / "summary.json").read_text())
    with open(competition / "episodes.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert [r["policy"] for r in rows] == ["specialised:0", "specialised:1"]
    rows[1]["policy"] = label
    with open(folder / "episodes.csv", "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    message = f"--compete '{folder}/episodes.csv', line 3: policy '{label}' is not allowed: agent model-free flies {allowed}"
    with pytest.raises(NeurohoverError, match=f"^{re.escape(message)}$"):
        read_compete_dir(folder)
    rc, out, err = cli("plot", "--compete", str(folder), "--out", str(tmp_path / "plots"))
    assert rc == 2 and "Traceback" not in err and message in err and out == "", err
    read_compete_dir(competition)


def test_a_stored_run_of_a_policy_the_agent_never_flies_is_refused_by_every_command(mf, cli: CliRun, tmp_path: Path) -> None:
    """T25-09: a stored model-free run whose policy_changes name 'model:1' was exported, reported and copied into
    episodes.csv; every command now refuses it, naming the unit and the change, and leaves the store as it was."""
    config, good = mf
    with sqlite3.connect(good) as conn:
        (stored,) = conn.execute("SELECT result FROM units WHERE key = ?", (RUN,)).fetchone()
    conn.close()
    assert json.loads(stored)["policy_changes"] == [[0, "specialised:0"], [1, "specialised:1"]]
    store = _edited(good, tmp_path / "s.sqlite", RUN, policy_changes=[[0, "specialised:0"], [1, "model:1"]])
    says = "policy_changes[1]: policy 'model:1' is not allowed: agent model-free flies specialised:0..9"
    line = _refused(store, "mf1", RUN, says)
    refused_by_every_command(cli, config, store, "mf1", line, tmp_path / "r")


@pytest.mark.parametrize(
    ("changes", "says"),
    [
        ({"model_params": [1.0] * 3}, "model_params = [1.0, 1.0, 1.0] is not allowed: a learned model has 11 of them: allowed 11 numbers"),
        ({"model_noise_std": [1.0] * 7}, "model_noise_std = [1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0] is not allowed: a learned model has 6 of them"),
        ({"model_noise_std": [-1.0] * 6}, "model_noise_std[0] = -1.0 is not allowed: a standard deviation: allowed a finite number >= 0"),
        (
            {"generic_return": 5.0},
            "generic_return = 5.0 is no episode's return: allowed a number in [-1.75e+10, 0] or nan (every reward is minus a sum of squares)",
        ),
    ],
    ids=["params", "noise-count", "noise-negative", "generic-return"],
)
def test_a_stored_model_unit_that_contradicts_itself_is_refused_by_every_command(ml, cli: CliRun, tmp_path: Path, changes: dict, says: str) -> None:
    """T25-10: a stored model unit with 3 model parameters (11 are learned), noise sds of -1.0 or a generic return of
    5.0 was exported and reported; every command now refuses it, naming the unit and the field."""
    config, good = ml
    with sqlite3.connect(good) as conn:
        (key,) = conn.execute("SELECT key FROM units WHERE kind = 'model'").fetchone()
    conn.close()
    store = _edited(good, tmp_path / "s.sqlite", key, **changes)
    line = _refused(store, "ml1", key, f"model result is inconsistent: {says}")
    refused_by_every_command(cli, config, store, "ml1", line, tmp_path / "r")
