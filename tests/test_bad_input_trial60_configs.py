"""Bad-input trial 60, side A (configs): a model-learning config took settings no unit of it uses (T60-A02):
model_budget and ec_mer_episodes without method 'ec-mer', ec_meno_budget without 'ec-meno', and generic_budget without
generic = "evolve". `reproduce m1.toml --set model_budget=100` on an LR-only config exited 0 with every unit's result the
plain run's, yet the setting changed the config hash: a store made without it refused the command ("settings differ")
and --update ran every unit again. check_used refuses them now, as it does test-runs settings no unit uses (T26-A02)."""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import CliRun, tiny_model_learning

from neurohover.errors import NeurohoverError
from neurohover.experiments.config import load_config, make_config, shipped_configs

#: The trial's m1.toml: LR only, its generic policy the baseline.
M1 = """name = "m1"
title = "m1"
kind = "model_learning"
[settings]
task = "ghh08"
seed = 4
mdps = "test"
methods = ["lr"]
generic = "baseline"
policy_prototype = "generic"
test_episodes = 1
[scales.quick]
n_mdps = 1
n_steps = 50
policy_budget = 60
"""

GENERIC = r"the generic policy an experiment evolves itself \(generic = 'evolve', and this config's generic is 'baseline'\)"


def _config(tmp_path: Path, text: str, name: str = "m1.toml") -> str:
    path = tmp_path / name
    path.write_text(text)
    return str(path)


@pytest.mark.parametrize(
    ("key", "value", "whom"),
    [
        ("model_budget", 100, r"the method 'ec-mer' \(methods = \['lr'\]\)"),
        ("ec_mer_episodes", 3, r"the method 'ec-mer' \(methods = \['lr'\]\)"),
        ("ec_meno_budget", 50, r"the method 'ec-meno' \(methods = \['lr'\]\)"),
        ("generic_budget", 77, GENERIC),
    ],
)
def test_a02_a_setting_no_method_uses_is_refused(tmp_path: Path, key: str, value: int, whom: str) -> None:
    """T60-A02: each was taken with status 0 and written into the hash and the unit params."""
    path = _config(tmp_path, M1)
    message = rf"at scale 'quick': {key} = {value} applies to {whom}; this config has none: leave it out$"
    with pytest.raises(NeurohoverError, match=message):
        load_config(path, "quick", {key: value})
    with pytest.raises(NeurohoverError, match=message):  # given by the config file itself
        load_config(_config(tmp_path, M1 + f"{key} = {value}\n", "own.toml"), "quick")


def test_a02_the_command_line_refuses_it_with_status_2(tmp_path: Path, cli: CliRun) -> None:
    store = tmp_path / "b.sqlite"
    rc, out, err = cli("reproduce", _config(tmp_path, M1), "--store", str(store), "--set", "model_budget=100", "--no-progress")
    assert rc == 2 and "model_budget = 100 applies to the method 'ec-mer'" in err and "Traceback" not in err, (out, err)
    assert not store.exists()  # refused before any store was made
    rc, _, err = cli("reproduce", _config(tmp_path, M1), "--store", str(store), "--set", "ec_meno_budget=50", "--set", "generic_budget=77")
    assert rc == 2 and "ec_meno_budget = 50 applies to the method 'ec-meno'" in err, err


def test_a02_the_default_changes_nothing_and_a_used_setting_stands(tmp_path: Path) -> None:
    path = _config(tmp_path, M1)
    plain = load_config(path, "quick")
    for key, default in (("model_budget", 2000), ("ec_mer_episodes", 1), ("ec_meno_budget", 0), ("generic_budget", 0)):
        assert load_config(path, "quick", {key: default}).hash == plain.hash  # written in anyway: nothing changed
    with pytest.raises(NeurohoverError, match=r"ec_meno_budget = 5 applies to the method 'ec-meno' \(methods = \['ec-mer'\]\)"):
        load_config(path, "quick", {"methods": ["ec-mer"], "ec_meno_budget": 5})
    mer = load_config(path, "quick", {"methods": ["ec-mer"], "model_budget": 100, "ec_mer_episodes": 3})
    assert (mer.settings["model_budget"], mer.settings["ec_mer_episodes"]) == (100, 3)
    assert load_config(path, "quick", {"methods": ["ec-meno", "lr"], "ec_meno_budget": 50}).settings["ec_meno_budget"] == 50
    assert load_config(path, "quick", {"generic": "evolve", "generic_budget": 77}).settings["generic_budget"] == 77
    base = {"task": "ghh08", "seed": 1, "n_mdps": 1, "methods": ["lr"], "generic": "shipped"}
    with pytest.raises(NeurohoverError, match=r"model_budget = 10 applies to the method 'ec-mer'"):  # in Python as well
        make_config("ml60", "model_learning", "quick", {**base, "model_budget": 10})


def test_a02_a_file_s_settings_stand_where_set_switches_their_source(tmp_path: Path) -> None:
    """table4 gives generic_budget and its EC methods' budgets: `--set 'generic="shipped"'` (docs/reproduction) or a subset
    of its methods leaves them standing (one config, each source), but a setting given with the switch is refused."""
    table4 = str(shipped_configs()["table4"])
    assert load_config(table4, "quick", {"generic": "shipped", "methods": ["lr"]}).settings["model_budget"] == 200
    with pytest.raises(NeurohoverError, match=r"model_budget = 5 applies to the method 'ec-mer' \(methods = \['lr'\]\)"):
        load_config(table4, "quick", {"methods": ["lr"], "model_budget": 5})
    with pytest.raises(NeurohoverError, match=r"generic_budget = 50 applies to the generic policy an experiment evolves itself"):
        load_config(table4, "quick", {"generic": "baseline", "generic_budget": 50})
    evolving = _config(tmp_path, M1.replace('generic = "baseline"', 'generic = "evolve"') + "generic_budget = 10\n", "e.toml")
    assert load_config(evolving, "quick", {"generic": "baseline"}).settings["generic_budget"] == 10
    with pytest.raises(NeurohoverError, match=rf"generic_budget = 10 applies to {GENERIC}"):  # the file's own source uses none
        load_config(_config(tmp_path, M1 + "generic_budget = 10\n", "b.toml"), "quick", {"methods": ["ec-mer"]})


def test_a02_the_tiny_fixture_gives_only_what_its_units_use(tmp_path: Path) -> None:
    for generic in ("baseline", "evolve"):
        load_config(_config(tmp_path, tiny_model_learning("ml60", generic), f"{generic}.toml"), "quick")
    text = tiny_model_learning("ml60", "baseline") + "ec_meno_budget = 10\n"
    with pytest.raises(NeurohoverError, match=r"ec_meno_budget = 10 applies to the method 'ec-meno'"):
        load_config(_config(tmp_path, text, "m.toml"), "quick")
