"""Bad-input trial 34, helper A (the command line): reproduce's refusal of a changed config names the settings that
differ, stored vs given, and says where an older neurohover wrote the store (T34-A02); a paper-scale run whose --set
shrank it is not reported as the paper's protocol nor counted in the paper-scale claims (T34-A01); wins on compete
experiments (one agent each) says what it can compare instead (T34-A03)."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pytest
import store_edits as SE

from neurohover.errors import NeurohoverError
from neurohover.experiments import Store

# T34-A02 ------------------------------------------------------------------------------------------------------------


def _again(store: Store, settings: dict) -> str:
    """The message of a second begin of experiment tr1 with ``settings``."""
    config = dataclasses.replace(SE.tiny_config(), settings=settings)
    with pytest.raises(NeurohoverError) as err:
        store.begin("tr1", "quick", config.hash, config.to_dict())
    return str(err.value)


def test_a_changed_config_is_refused_naming_each_setting_stored_and_given(tmp_path: Path) -> None:
    with Store(tmp_path / "s.sqlite") as store:
        SE.begin(store)
        base = SE.tiny_config().settings
        group = {**base["groups"][0], "n_mdps": 2}
        message = _again(store, {**base, "n_steps": 30, "groups": [group]})
    assert "the settings differ (groups 'baseline'.n_mdps: stored 1, given 2; n_steps: stored 20, given 30), so the results" in message
    assert "restore the old config" in message and "--fresh" in message


def test_a_store_an_older_neurohover_wrote_is_refused_saying_the_new_settings_are_a_newer_neurohovers(tmp_path: Path) -> None:
    """A store written by the 2026-12-03 version lacked settings added since (noise, model_substeps): the refusal named
    two hashes and advised restoring an old config the user never changed."""
    older = SE.tiny_config().settings
    group = {k: v for k, v in older["groups"][0].items() if k != "estimator"}
    config = dataclasses.replace(SE.tiny_config(), settings={**{k: v for k, v in older.items() if k != "safety_episodes"}, "groups": [group]})
    with Store(tmp_path / "s.sqlite") as store:
        store.begin("tr1", "quick", config.hash, config.to_dict())
        message = _again(store, older)
    assert (
        "the settings differ only in ones the stored config lacks, which a newer neurohover added at their defaults "
        "(groups 'baseline'.estimator: stored absent, given 'ols'; safety_episodes: stored absent, given 3); an older neurohover "
        "wrote this store. To go on with it, rerun with --update" in message
    )
    assert "restore the old config" not in message and "or give another --store file" in message


# T34-A01 ------------------------------------------------------------------------------------------------------------


def _shrunk_fig7(n_mdps: int = 2):
    """Figure 7 at paper scale with --set running much less of it: two of its agents on ``n_mdps`` MDPs, 2 episodes of 20 steps."""
    from neurohover.experiments.config import load_config

    groups = [{"agent": agent, "mdps": "test", "n_mdps": n_mdps} for agent in ("model-free", "incremental")]
    overrides = {"policies": "shipped", "episodes": 2, "n_steps": 20, "model_budget": 10, "max_learning_episodes": 1, "groups": groups}
    return load_config("fig7", "paper", overrides)


def test_a_paper_scale_run_shrunk_by_set_is_not_called_the_paper_protocol() -> None:
    from neurohover.experiments.config import load_config
    from neurohover.experiments.report_scale import paper_protocol, scale_note

    note = scale_note(_shrunk_fig7())
    assert note.startswith("not the paper's protocol: --set ran less than fig7 at paper scale as shipped: episodes (2 < 1000), max_learning_episodes")
    assert "n_steps (20 < 6000), group 'model-free' n_mdps (2 < 100)" in note and "left out of the paper-scale claims table" in note
    table4 = load_config("table4", "paper", {"generic_budget": 50, "n_mdps": 1})
    assert "generic_budget (50 < no cap), n_mdps (1 < 100)" in scale_note(table4) and not paper_protocol(table4)
    # more than the paper's, or only where the policies come from: the paper's protocol still
    for overrides in ({}, {"policies": "shipped"}, {"episodes": 2000, "generic_budget": 0, "model_budget": 3000}):
        cfg = load_config("fig7", "paper", overrides)
        assert scale_note(cfg) == "the paper protocol" and paper_protocol(cfg)


@pytest.mark.slow
def test_a_paper_scale_run_shrunk_by_set_stays_out_of_the_paper_scale_claims(tmp_path: Path) -> None:
    """Its t tests were judged in "Claims and conclusions (paper scale)" and counted in the conclusions' tally."""
    from neurohover.experiments import LocalExecutor, reproduce, write_report

    with Store(tmp_path / "s.sqlite") as store:
        reproduce(_shrunk_fig7(), store, LocalExecutor(1), progress=False)
        report = write_report(store, tmp_path / "r").read_text(encoding="utf-8")
    assert "- Scale: **paper** (not the paper's protocol: --set ran less than fig7" in report
    assert "Claims and conclusions" not in report and "### Against the paper" in report


# T34-A03 ------------------------------------------------------------------------------------------------------------


@pytest.mark.slow
def test_wins_on_a_compete_experiment_says_it_holds_one_agent_and_what_wins_compares(tmp_path: Path, cli, capsys) -> None:
    """Every compete experiment holds one agent: wins said only "a competition needs at least two agents, got
    ['baseline']", and its help offered compete runs' scales."""
    store = SE.competed_store(tmp_path)
    rc, _, err = cli("wins", "compete-ghh08-baseline", "--store", str(store))
    assert rc == 2 and SE.error(err, "wins").startswith("experiment 'compete-ghh08-baseline' (settings-"), err
    assert (
        "holds the test runs of one agent (baseline), as every `neurohover compete` experiment does, and a competition needs two or more: "
        "wins compares the groups of one experiment; give a test-runs experiment of two or more groups (none in this store)" in err
    )
    with pytest.raises(SystemExit):
        cli("wins", "--help")
    out = " ".join(capsys.readouterr().out.split())
    assert "settings-HASH" not in out and "a compete experiment holds one agent" in out and "--scale SCALE which scale: quick or paper" in out


@pytest.mark.slow
def test_wins_names_the_experiments_of_the_store_it_can_compare_and_refuses_one_agent_of_several(tmp_path: Path, cli) -> None:
    from conftest import tiny_test_runs

    config = tmp_path / "tr2.toml"
    config.write_text(tiny_test_runs("baseline", "generic", name="tr2"))
    store = SE.competed_store(tmp_path)
    assert cli("reproduce", str(config), "--store", str(store), "--no-progress")[0] == 0
    rc, _, err = cli("wins", "compete-ghh08-baseline", "--store", str(store))
    assert rc == 2 and "give a test-runs experiment of two or more groups (this store's tr2 (quick))" in err, err
    rc, _, err = cli("wins", "tr2", "--store", str(store), "--agents", "generic")
    assert (
        rc == 2 and SE.error(err, "wins") == "--agents 'generic' names one agent: a competition needs two or more; give more of baseline, generic, or --against"
    )
    assert cli("wins", "tr2", "--store", str(store), "--runs", "1")[0] == 0
