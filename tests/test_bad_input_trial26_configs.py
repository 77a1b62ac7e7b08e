"""The twenty-sixth bad-input trial's findings in experiment configs and the report: test-runs settings no unit uses
(model_budget, policy_budget, safety_episodes, ... with no agent that learns models or no policies evolved) were taken,
changing the config hash for nothing (T26-A02); a baseline group's estimator = 'gls' was stored while its sibling model
options were refused (T26-A03); robustness_episodes without a robustness variant did nothing (T26-A04); a [paper] t test
of a group with itself was taken and given a verdict (T26-A05); the report called a compete run at the paper's episodes
a smoke-scale run, and said the quick-scale sentence on pages without a quick-scale section (T26-A07)."""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import tiny_test_runs

from neurohover.compete import competition_config
from neurohover.errors import NeurohoverError
from neurohover.experiments.config import load_config, shipped_configs
from neurohover.experiments.report_scale import QUICK_NOTE, QUICK_SENTENCE, header_note, scale_note


def _config(tmp_path: Path, text: str, name: str = "c.toml") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


BASE = tiny_test_runs("baseline", "model-free", name="mini")


@pytest.mark.parametrize(
    ("key", "value", "whom"),
    [
        ("model_budget", 7, "agents that learn models"),
        ("max_learning_episodes", 3, "agents that learn models"),
        ("predict_episodes", 2, "agents that learn models"),
        ("authors_generations", 3, "model_policy = 'authors'"),
        ("policy_budget", 5, "policies = 'evolve', and this config's policies are 'shipped'"),
        ("safety_episodes", 2, "the safe pair"),
        ("generic_budget", 5, "FGHH generics"),
        ("generics_per_agent", 2, "FGHH generics"),
        ("generic_resampling", {"fixed": "fixed:3"}, "FGHH generics"),
    ],
)
def test_a02_a_setting_no_unit_uses_is_refused(tmp_path: Path, key: str, value: object, whom: str) -> None:
    path = _config(tmp_path, BASE)
    with pytest.raises(NeurohoverError, match=rf"{key} = .* applies to .*{whom}.*; this config has none: leave it out"):
        load_config(str(path), "quick", {key: value})


def test_a02_the_default_changes_nothing_and_a_used_setting_stands(tmp_path: Path) -> None:
    plain = load_config(str(_config(tmp_path, BASE)), "quick")
    assert load_config(str(_config(tmp_path, BASE)), "quick", {"model_budget": 2000}).hash == plain.hash  # written in anyway
    learning = _config(tmp_path, tiny_test_runs("incremental", name="mini"), "i.toml")
    assert load_config(str(learning), "quick", {"model_budget": 7}).settings["model_budget"] == 7
    evolving = _config(tmp_path, BASE.replace('policies = "shipped"', 'policies = "evolve"'), "e.toml")
    assert load_config(str(evolving), "quick", {"policy_budget": 5}).settings["policy_budget"] == 5
    with pytest.raises(NeurohoverError, match="safety_episodes = 2 applies to the safe pair"):  # no agent flies the safe pair
        load_config(str(evolving), "quick", {"safety_episodes": 2})


def test_a02_a_file_s_policy_budget_stands_where_set_switches_the_source(tmp_path: Path) -> None:
    text = BASE.replace('policies = "shipped"\n', 'policies = "evolve"\npolicy_budget = 5\n')
    path = _config(tmp_path, text)
    assert load_config(str(path), "quick", {"policies": "shipped"}).settings["policy_budget"] == 5  # one config, both sources
    with pytest.raises(NeurohoverError, match="policy_budget = 5 applies"):
        load_config(str(_config(tmp_path, text.replace('"evolve"', '"shipped"'), "s.toml")), "quick")
    with pytest.raises(NeurohoverError, match="policy_budget = 7 applies"):  # given with the switch: not the file's
        load_config(str(path), "quick", {"policies": "shipped", "policy_budget": 7})


@pytest.mark.slow
def test_a02_every_shipped_config_loads_at_both_scales() -> None:
    for name in shipped_configs():
        for scale in ("quick", "paper"):
            load_config(name, scale)


def test_a03_a_baseline_group_s_estimator_is_refused_as_its_model_options_are(tmp_path: Path) -> None:
    text = BASE.replace('agent = "baseline"\n', 'agent = "baseline"\nestimator = "gls"\n')
    with pytest.raises(NeurohoverError, match=r"group 'baseline': estimator applies to the agents that learn models \(.*\), not to 'baseline'"):
        load_config(str(_config(tmp_path, text)), "quick")
    ols = load_config(str(_config(tmp_path, BASE.replace('agent = "baseline"\n', 'agent = "baseline"\nestimator = "ols"\n'), "o.toml")), "quick")
    assert ols.hash == load_config(str(_config(tmp_path, BASE, "b.toml")), "quick").hash  # the default: nothing changed
    gls = load_config(str(_config(tmp_path, tiny_test_runs("incremental", name="mini").replace("n_mdps = 1\n", 'n_mdps = 1\nestimator = "gls"\n'))), "quick")
    assert gls.settings["groups"][0]["estimator"] == "gls"


EVOLUTION = """name = "evmini"
kind = "evolution"
[settings]
task = "ghh08"
seed = 3
target = "train"
[[settings.variants]]
key = "slp-baseline"
label = "slp-baseline"
topology = "slp"
[scales.quick]
n_mdps = 1
runs = 1
budget = 60
n_steps = 20
"""


def test_a04_robustness_episodes_without_robustness_variants_is_refused(tmp_path: Path) -> None:
    path = _config(tmp_path, EVOLUTION)
    with pytest.raises(NeurohoverError, match=r"robustness_episodes = 50 applies to Table 3's robustness units \(robustness_variants"):
        load_config(str(path), "quick", {"robustness_episodes": 50})
    assert load_config(str(path), "quick", {"robustness_episodes": 50, "robustness_variants": ["slp-baseline"]}).settings["robustness_episodes"] == 50


def test_a05_a_t_test_of_a_group_with_itself_is_refused(tmp_path: Path) -> None:
    text = BASE + '[paper]\nttests = [{ a = "model-free", b = "model-free", p = "< 0.0002" }]\n'
    with pytest.raises(NeurohoverError, match=r"\[paper\] ttests compares 'model-free' with itself \(a = b\)"):
        load_config(str(_config(tmp_path, text)), "quick")
    load_config(str(_config(tmp_path, text.replace('b = "model-free"', 'b = "baseline"'), "ok.toml")), "quick")


def test_a07_a_compete_scale_is_described_by_its_own_settings() -> None:
    paper = competition_config("ghh08", "incremental", runs=100, episodes=1000, n_steps=6000)
    assert paper.scale.startswith("settings-")
    assert scale_note(paper).startswith("paper-comparable: 1000 episodes of 6000 steps, 100 runs, at least the paper's (fig7 at paper scale")
    fewer = scale_note(competition_config("ghh08", "incremental", runs=40, episodes=1000, n_steps=6000))
    assert "fewer runs (40 < 100)" in fewer and "magnitudes per episode compare" in fewer and "smoke" not in fewer
    short = scale_note(competition_config("ghh08", "incremental", runs=2, episodes=3, n_steps=20))
    assert "fewer episodes (3 < 1000), shorter episodes (20 < 6000 steps), fewer runs (2 < 100)" in short
    assert "magnitudes are not comparable" in short
    assert "fig8 at paper scale" in scale_note(competition_config("ghh09", "hybrid", runs=80, mdps="train", episodes=1000, n_steps=6000))


def test_a07_the_quick_scale_words_only_for_quick_scale(tmp_path: Path) -> None:
    assert scale_note(load_config(str(_config(tmp_path, BASE)), "quick")) == QUICK_NOTE
    assert scale_note(load_config("fig7", "paper")) == "the paper protocol"
    assert header_note({"quick", "paper"}) == f" {QUICK_SENTENCE}"
    assert header_note({"paper", "settings-e256306cea"}) == ""
