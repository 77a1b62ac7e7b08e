"""Trial 45 (side A), T45-A03: an experiment config's labelled lists refuse a label twice, as its groups' labels are
refused: an evolution config's variants ("SLP, baseline seed" twice: two report rows, a ranking and a legend that could
not tell them apart), a model-learning config's conditions and fits (the report keyed their rows by label: one hid the
other), and robustness_variants naming a key twice (Table 3's row twice). Every shipped config still loads at both
scales, and a stored config with repeated labels is still read. Also trial 45's observation: compete's command line
names its directory --out where the API (compete(out=...)) says out."""

from __future__ import annotations

import json
import sqlite3
from pathlib import Path

import pytest

from neurohover.errors import NeurohoverError
from neurohover.experiments.config import ExperimentConfig, load_config, load_configs, shipped_configs

EVOLUTION = """name = "evdup"
title = "t"
kind = "evolution"
[settings]
task = "ghh08"
seed = 1
target = "zero"
runs = 1
[[settings.variants]]
key = "a"
label = "SLP, baseline seed"
topology = "slp"
[[settings.variants]]
key = "b"
label = "LABEL"
topology = "mlp"
[scales.quick]
budget = 10
n_steps = 20
"""

MODEL_LEARNING = """name = "mldup"
kind = "model_learning"
[settings]
task = "ghh08"
seed = 1
methods = ["lr"]
generic = "baseline"
test_episodes = 1
[[settings.LIST]]
key = "a"
label = "LABEL"
[[settings.LIST]]
key = "b"
[scales.quick]
n_mdps = 1
n_steps = 20
policy_budget = 10
"""


def _config(tmp_path: Path, text: str):
    path = tmp_path / "c.toml"
    path.write_text(text)
    return load_config(str(path), "quick")


@pytest.mark.parametrize("label", ["SLP, baseline seed", " SLP,  baseline seed "])
def test_an_evolution_config_refuses_two_variants_under_one_label(tmp_path: Path, label: str) -> None:
    with pytest.raises(NeurohoverError, match=r"variant label .* is not allowed on variant 'b': variant 'a' has it; give each variant a label"):
        _config(tmp_path, EVOLUTION.replace("LABEL", label))
    assert [v["label"] for v in _config(tmp_path, EVOLUTION.replace("LABEL", "SLP, zero seed")).settings["variants"]][1] == "SLP, zero seed"


@pytest.mark.parametrize("label", ["   ", " \u3000 "])
def test_a_label_of_spaces_only_is_refused(tmp_path: Path, label: str) -> None:
    """Trial 45's fixer's note: a variant's (or condition's, fit's, group's) label of spaces only was taken, an empty row."""
    with pytest.raises(NeurohoverError, match=r"variants\[1\]: label = .* is not allowed: expected a non-empty string \(not only spaces\)"):
        _config(tmp_path, EVOLUTION.replace("LABEL", label))


@pytest.mark.parametrize(("lst", "what"), [("conditions", "condition"), ("fits", "fit")])
def test_a_model_learning_config_refuses_two_conditions_or_fits_under_one_label(tmp_path: Path, lst: str, what: str) -> None:
    """Condition 'a' labelled 'b', and condition 'b' whose label is its key: the report's rows were keyed by label."""
    text = MODEL_LEARNING.replace("LIST", lst)
    with pytest.raises(NeurohoverError, match=f"{what} label 'b' is not allowed on {what} 'b': {what} 'a' has it"):
        _config(tmp_path, text.replace("LABEL", "b"))
    assert [c["label"] for c in _config(tmp_path, text.replace("LABEL", "A")).settings[lst]] == ["A", "b"]


def test_robustness_variants_refuse_a_key_twice() -> None:
    with pytest.raises(NeurohoverError, match=r"robustness_variants = \['slp-baseline', 'slp-baseline'\] is not allowed: expected a list of distinct"):
        load_config("fig2", "quick", {"robustness_variants": ["slp-baseline", "slp-baseline"]})


@pytest.mark.slow
def test_every_shipped_config_still_loads_at_both_scales(cli) -> None:
    loaded = {(c.name, c.scale) for name in shipped_configs() for scale in ("quick", "paper") for c in load_configs(name, scale)}
    assert {scale for _, scale in loaded} == {"quick", "paper"} and len(loaded) > 50
    rc, out, err = cli("reproduce", "--list")
    assert rc == 0 and "fig2" in out, err


@pytest.mark.slow
def test_the_committed_store_still_reads_and_a_stored_config_with_repeated_labels_too(committed_store: Path, tmp_path: Path, cli) -> None:
    """Stored configs are read as stored (none of the committed store's repeats a label); one that does is still read by
    results and report, its config hash rewritten with its labels."""
    from neurohover.experiments import Store

    with sqlite3.connect(committed_store) as conn:
        for name, scale, text in conn.execute("SELECT name, scale, config FROM experiments").fetchall():
            settings = ExperimentConfig.from_dict(json.loads(text)).settings
            for lst in ("variants", "groups", "conditions", "fits"):
                labels = [item["label"] for item in settings.get(lst, ())]
                assert len(set(labels)) == len(labels), (name, scale, lst)
    conn.close()
    store = tmp_path / "s.sqlite"  # fig2's quick rows alone (a copy of the whole store took a second)
    with Store(store):
        pass
    with sqlite3.connect(store) as conn:
        conn.execute("ATTACH DATABASE ? AS c", (str(committed_store),))
        for table in ("experiments", "units", "sessions"):
            conn.execute(f"INSERT INTO {table} SELECT * FROM c.{table} WHERE name = 'fig2' AND scale = 'quick'")
        (text,) = conn.execute("SELECT config FROM experiments WHERE name = 'fig2' AND scale = 'quick'").fetchone()
        stored = json.loads(text)
        old = stored["hash"]
        for v in stored["settings"]["variants"]:
            v["label"] = "one label"
        stored["hash"] = new = ExperimentConfig.from_dict(stored).hash
        conn.execute("UPDATE experiments SET config = ?, config_hash = ? WHERE name = 'fig2' AND scale = 'quick'", (json.dumps(stored), new))
        for table in ("units", "sessions"):
            conn.execute(f"UPDATE {table} SET config_hash = ? WHERE name = 'fig2' AND scale = 'quick' AND config_hash = ?", (new, old))
    conn.close()
    rc, out, err = cli("results", "fig2", "--scale", "quick", "--store", str(store))
    assert rc == 0 and "robust/slp-baseline/train0" in out, err
    rc, _, err = cli("report", "fig2", "--scale", "quick", "--store", str(store), "--out", str(tmp_path / "r"))
    assert rc == 0, err
    assert "| one label |" in (tmp_path / "r" / "report.md").read_text()


def test_compete_names_a_dangling_link_as_its_out_option(cli, tmp_path: Path, monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)
    Path("d6").symlink_to("nowhere/x")
    Path("f1").write_text("")
    common = ("compete", "--task", "ghh08", "--agent", "baseline", "--runs", "1", "--episodes", "2", "--episode-steps", "20", "--out")
    rc, _, err = cli(*common, "d6")
    assert rc == 2 and "error: --out 'd6' is a symbolic link to 'nowhere/x'" in err, err
    rc, _, err = cli(*common, "f1")
    assert rc == 2 and "error: --out 'f1' is a file; give a directory" in err, err
    Path("it's").symlink_to("nowhere/x")  # repr() in double quotes; a folder in use is named cut by brief() (trial 31's test)
    rc, _, err = cli(*common, "it's")
    assert rc == 2 and 'error: --out "it\'s" is a symbolic link' in err, err


def test_the_compete_api_still_names_its_parameter_out(tmp_path: Path, monkeypatch) -> None:
    from neurohover.compete import compete

    monkeypatch.chdir(tmp_path)
    Path("d6").symlink_to("nowhere/x")
    with pytest.raises(NeurohoverError, match=r"^out 'd6' is a symbolic link"):
        compete("ghh08", "baseline", runs=1, episodes=2, n_steps=20, out="d6")
