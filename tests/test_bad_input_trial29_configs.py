"""Trial 29a's findings on experiment configs, settings hashes and the FGHH policy sets (T29-A02, T29-A05, T29-A07, T29-A08)."""

from __future__ import annotations

import pytest

from neurohover.errors import NeurohoverError
from neurohover.experiments.config import load_config


@pytest.mark.parametrize(
    ("name", "overrides", "named"),
    [
        ("fig7", {"task": "ghh09"}, "changes task from 'ghh08' to 'ghh09'"),
        ("table4", {"task": "ghh09"}, "changes task from 'ghh08' to 'ghh09'"),
        ("fig8", {"task": "ghh08"}, "changes task from 'ghh09' to 'ghh08'"),
        ("fig12", {"sigma": 0.3}, "changes sigma from 0.2 to 0.3"),
        ("fig7", {"groups": [{"agent": "model-free", "mdps": "train", "n_mdps": 2}, {"agent": "incremental", "n_mdps": 2}]}, "the mdps of group 'model-free'"),
    ],
)
def test_a_set_that_changes_what_the_papers_claims_are_about_is_refused(name, overrides, named, cli, tmp_path) -> None:
    """T29-A02: `reproduce fig7 --set task="ghh09"` ran GHH-09 under fig7's GHH-08 title and judged it against the
    paper's GHH-08 t tests ("reversed"); an override of a shipped experiment's conditions is refused by name."""
    with pytest.raises(NeurohoverError, match=f"{named}.*not allowed for the shipped experiment '{name}'.*config of your own: copy "):
        load_config(name, "quick", overrides)
    rc, _, err = cli("reproduce", "fig7", "--store", str(tmp_path / "s.sqlite"), "--set", 'task="ghh09"')
    assert rc == 2 and "changes task from 'ghh08' to 'ghh09'" in err and not (tmp_path / "s.sqlite").exists()


def test_a_set_of_scale_seed_or_policy_source_stays_allowed() -> None:
    """T29-A02: what stays allowed: how much is run (the trial's episodes, n_steps, groups of fewer MDPs), the seed,
    the policy source, and a condition set to the shipped value."""
    groups = [{"agent": a, "mdps": "test", "n_mdps": 2} for a in ("model-free", "model-based", "incremental")]
    small = {"episodes": 3, "n_steps": 20, "max_learning_episodes": 2, "model_budget": 10, "policies": "shipped", "seed": 7, "task": "ghh08"}
    cfg = load_config("fig7", "quick", {**small, "groups": groups})
    assert cfg.settings["task"] == "ghh08" and [g["n_mdps"] for g in cfg.settings["groups"]] == [2, 2, 2]
    assert load_config("fig12", "quick", {"runs": 2, "budget": 40, "sigma": 0.2}).settings["runs"] == 2
    assert load_config("fig16", "quick", {"generics_from": {}}).settings["generics_from"] == {}


def test_a_set_of_another_sigma_names_advice_that_can_be_followed(cli, tmp_path) -> None:
    """T29-A05: compete at an FGHH sigma other than the shipped set's said "build one for this sigma", but nothing builds
    a set for another sigma; it names what does fly there: the set's sigma, an agent of no set, or a config evolving its own."""
    from neurohover.agents.registry import check_agent
    from neurohover.tasks import get_task_family

    with pytest.raises(NeurohoverError, match=r"build-policies builds fghh sets for sigma = 0.3 only: .*\(baseline\).*sigma = 0.2 and policies = \"evolve\""):
        check_agent("authors-fixed", get_task_family("fghh", 0.2))
    rc, _, err = cli("compete", "--task", "fghh", "--agent", "generic", "--runs", "1", "--episodes", "2", "--sigma", "0.2", "--out", str(tmp_path / "g"))
    assert rc == 2 and "build one for this sigma" not in err and 'policies = "evolve"' in err


def test_evaluate_agent_notes_a_generic_of_another_sigma(cli) -> None:
    """T29-A08: evaluate-agent --task fghh --sigma 0.2 flew the shipped sigma-0.3 generic as "generic" without a word,
    where compete refuses that set; the row stays (a reference), with a note naming both sigmas."""
    args = ("evaluate-agent", "--task", "fghh", "--policy", "baseline", "--n-mdps", "1", "--episode-steps", "5")
    rc, out, err = cli(*args, "--sigma", "0.2")
    assert rc == 0 and "generic" in out
    assert "note: the generic row flies the shipped fghh generic, evolved for sigma = 0.3, not 0.2" in err
    rc, _, err = cli(*args)
    assert rc == 0 and "note" not in err


def _competition(**agent_settings):
    from neurohover.compete import competition_config

    return competition_config("ghh08", "hybrid-risk", runs=1, episodes=2, n_steps=20, agent_settings=agent_settings or None)


def test_equal_agent_settings_spelt_otherwise_are_one_competition() -> None:
    """T29-A07: compete's defaults left out, level=1 (kept as an int) and criterion="lcb" (level written in as 1.0) were
    three settings hashes, each flown again; they are one, and level=2 is level=2.0."""
    plain = _competition()
    for spelt in (_competition(level=1), _competition(criterion="lcb"), _competition(level=1.0, trials=2)):
        assert (spelt.scale, spelt.hash) == (plain.scale, plain.hash)
    two = _competition(level=2)
    assert (two.scale, two.hash) == (_competition(level=2.0).scale, _competition(level=2.0).hash) != (plain.scale, plain.hash)


def _tiny(**extra):
    from neurohover.experiments.config import make_config

    settings = {"task": "ghh08", "seed": 1, "policies": "shipped", "episodes": 2, "n_steps": 20, "groups": [{"agent": "baseline", "n_mdps": 1}], **extra}
    return make_config("tiny", "test_runs", "quick", settings)


def test_equal_sensor_and_drift_spelt_otherwise_hash_alike() -> None:
    """T29-A07: sensor={}, drift={} and a sensor's dropout=0 gave another config hash than the same config without them."""
    plain = _tiny().hash
    assert _tiny(sensor={}).hash == _tiny(drift={}).hash == plain
    assert _tiny(groups=[{"agent": "baseline", "n_mdps": 1, "sensor": {}, "drift": {}}]).hash == plain
    half = _tiny(sensor={"level": 0.5}).hash
    assert _tiny(sensor={"level": 0.5, "dropout": 0}).hash == _tiny(sensor={"level": 0.5, "delay": 0}).hash == half != plain
    assert _tiny(sensor={"level": 1}).hash == _tiny(sensor={"level": 1.0}).hash
    walk = _tiny(drift={"walk": 0.01})
    assert walk.hash != plain and _tiny(sensor={"level": 0.5}, groups=[{"agent": "baseline", "n_mdps": 1, "sensor": {"level": 0.5}}]).hash == half


@pytest.mark.parametrize("name", __import__("neurohover.experiments.config", fromlist=["x"]).experiment_names())
def test_the_canonical_spelling_keeps_every_shipped_hash(name, monkeypatch) -> None:
    """T29-A07: the committed store holds every shipped experiment under its config hash: the canonical spelling changes
    none of them, at either scale, with the experiment's policies or the shipped ones."""
    from neurohover.experiments import config

    for scale in ("quick", "paper"):
        now = config.load_config(name, scale)
        with monkeypatch.context() as m:
            m.setattr(config, "canonical_settings", lambda resolved: resolved)
            before = config.load_config(name, scale)
        assert now.hash == before.hash
