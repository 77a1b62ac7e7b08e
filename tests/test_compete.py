"""compete is an inline experiment: same planner, units, seeds and store as reproduce."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import pytest

from neurohover.compete import compete, competition_config
from neurohover.errors import NeurohoverError
from neurohover.experiments import Store, plan, unit_seed
from neurohover.experiments.config import make_config
from neurohover.tasks import MDP


def test_sampled_mdps_are_those_of_the_same_group_in_any_experiment_with_that_seed() -> None:
    cfg = competition_config("ghh09", "baseline", runs=3, episodes=2, mdps="sample", seed=17, n_steps=50)
    twin = make_config("my-experiment", "test_runs", "quick", {**cfg.settings})
    ours, theirs = plan(cfg, {}).units, plan(twin, {}).units
    assert [u.params["mdp"] for u in ours] == [u.params["mdp"] for u in theirs]
    assert [MDP.from_dict(u.params["mdp"]).label for u in ours] == [f"ghh09/sample:{i}" for i in range(3)]
    # Unit seeds derive from (seed, experiment name, unit key): documented, and different per experiment.
    assert [u.params["seed"] for u in ours] == [unit_seed(17, cfg.name, u.key) for u in ours]
    assert [u.params["seed"] for u in ours] != [u.params["seed"] for u in theirs]


@pytest.mark.slow
def test_a_competition_resumes_from_its_store_and_flies_nothing_twice(tmp_path: Path) -> None:
    flown: list[str] = []
    first, runs = compete("ghh08", "baseline", runs=3, episodes=4, n_steps=80, out=tmp_path / "a", on_result=lambda key, result: flown.append(key))
    assert len(flown) == 3 and (tmp_path / "a" / "results.sqlite").is_file()
    again, runs_again = compete("ghh08", "baseline", runs=3, episodes=4, n_steps=80, out=tmp_path / "a", on_result=lambda key, result: flown.append(key))
    assert len(flown) == 3 and again["mean_cumulative_return"] == first["mean_cumulative_return"]
    assert runs_again == runs
    # Other settings in the same store are another experiment scale: kept apart, nothing refused.
    longer, _ = compete("ghh08", "baseline", runs=3, episodes=5, n_steps=80, out=tmp_path / "a")
    assert longer["episodes"] == 5 and len(flown) == 3
    with Store(tmp_path / "a" / "results.sqlite", create=False) as store:
        assert sorted(n for n, *_ in store.experiments()) == ["compete-ghh08-baseline"] * 2


@pytest.mark.slow
def test_episode_rows_carry_steps_and_policies(tmp_path: Path) -> None:
    summary, runs = compete("ghh08", "baseline", runs=2, episodes=3, n_steps=60, out=tmp_path / "b")
    rows = list(csv.DictReader(open(tmp_path / "b" / "episodes.csv")))
    assert len(rows) == 6 and {r["policy"] for r in rows} == {"baseline"} and {r["steps"] for r in rows} == {"60"}
    assert [float(r["return"]) for r in rows[:3]] == [float(x) for x in runs[0].returns]
    assert summary["crash_rate_runs"] == 0.0


def test_runs_beyond_the_set_must_fill_it_evenly() -> None:
    assert competition_config("ghh08", "baseline", runs=200, episodes=1).settings["groups"][0]["runs_per_mdp"] == 2
    with pytest.raises(NeurohoverError, match="runs=150 on the 100 test MDPs of ghh08"):
        competition_config("ghh08", "baseline", runs=150, episodes=1)
    with pytest.raises(NeurohoverError, match="unknown --mdps 'all'"):
        competition_config("ghh08", "baseline", runs=1, episodes=1, mdps="all")


def test_a_crashing_run_records_its_crash_step() -> None:
    from neurohover.compete_folder import episode_rows
    from neurohover.experiments.results import TestRunResult, TestRunTiming

    result = TestRunResult(
        agent="x",
        mdp="m",
        score=-3.0,
        returns=(-1.0, -2.0),
        crash_episodes=(1,),
        safeguard_episodes=(0,),
        policy_changes=((0, "a"), (1, "b")),
        learning_episodes=1,
        mean_return_after_learning=-2.0,
        crash_steps=(17,),
        timing=TestRunTiming(seconds=0.0, offline_seconds=0.0),
    )
    assert episode_rows(4, result, 100) == [[4, "m", 0, "-1.0", 0, 100, "a", 1], [4, "m", 1, "-2.0", 1, 17, "b", 0]]


@pytest.mark.slow
def test_compete_says_when_it_reuses_stored_runs(tmp_path: Path, capsys) -> None:
    from neurohover.cli import main

    args = ["compete", "--task", "ghh08", "--agent", "baseline", "--runs", "2", "--episodes", "3", "--out", str(tmp_path / "c")]
    assert main(args) == 0
    assert "reused" not in capsys.readouterr().err
    assert main(args) == 0
    assert "2 of 2 units (runs and the policies they fly) were already in" in capsys.readouterr().err


@pytest.mark.slow
def test_an_agents_own_settings_reach_its_runs_and_are_checked(cli, tmp_path) -> None:
    from neurohover.compete import competition_config

    plain = competition_config("ghh08", "hybrid-risk", runs=1, episodes=3)
    config = competition_config("ghh08", "hybrid-risk", runs=1, episodes=3, agent_settings={"criterion": "worst"})
    assert config.scale != plain.scale and config.settings["groups"][0]["settings"]["criterion"] == "worst"
    assert "settings" not in plain.settings["groups"][0]  # without them, older competitions' digests stay as they were
    rc, out, err = cli(
        "compete", "--task", "ghh08", "--agent", "hybrid-risk", "--agent-setting", 'criterion="lcb"', "--agent-setting", "level=3",
        "--runs", "1", "--episodes", "4", "--episode-steps", "100", "--out", str(tmp_path / "a"),
    )  # fmt: skip
    assert rc == 0, err
    summary = json.loads((tmp_path / "a" / "summary.json").read_text())
    with Store(tmp_path / "a" / "results.sqlite", create=False) as store:
        (unit,) = [u for u in store.units(summary["experiment"], summary["scale"]) if u["key"].startswith("run/")]
    assert {k: unit["params"]["agent_settings"][k] for k in ("criterion", "level")} == {"criterion": "lcb", "level": 3}
    rc, _, err = cli("compete", "--task", "ghh08", "--agent", "baseline", "--agent-setting", "level=3", "--runs", "1", "--out", str(tmp_path / "b"))
    assert rc == 2 and "agent 'baseline' takes no settings table of its own; agents that do:" in err and "continual" in err
    rc, _, err = cli("compete", "--task", "ghh08", "--agent", "continual", "--agent-setting", "cooldwn=3", "--runs", "1", "--out", str(tmp_path / "c"))
    assert rc == 2 and "unknown ContinualSettings setting(s) 'cooldwn'" in err
    # Fifth trial: a setting the agent would ignore was accepted without a word.
    for agent, given, why in (
        ("hybrid-risk", ["trials=3"], "trials applies to model-free-risk only, not to hybrid-risk"),
        ("model-free-risk", ['criterion="mean"', "level=2"], "level applies to criterion lcb only, not to criterion 'mean'"),
    ):
        settings = [a for g in given for a in ("--agent-setting", g)]
        rc, _, err = cli("compete", "--task", "ghh08", "--agent", agent, *settings, "--runs", "1", "--out", str(tmp_path / "d"))
        assert rc == 2 and f"agent {agent!r}: {why}" in err, err
