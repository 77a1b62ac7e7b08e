"""Bad-input trial 56, side A (the command line): ``compete --runs N`` after ``--runs M`` flew every run again without a
word, the run count being part of the competition's settings digest (T56-A02): it says so on stderr now before flying,
with the stored runs' count and how to reuse them (stores keep their digests). A refused config change of a list of
entries of another length (groups) showed two identical cut-off lists (T56-A03): entries are compared one by one now,
one a list lacks shown stored or given absent. A key given twice in a TOML config was tomllib's "Cannot overwrite a
value" (T56-A04): the key is named, with its table and lines."""

from __future__ import annotations

import json

import pytest

from neurohover import NeurohoverError
from neurohover.compete import compete
from neurohover.experiments.config import load_config, make_config
from neurohover.experiments.config_changes import config_changes


@pytest.mark.slow
def test_compete_notes_runs_stored_under_another_run_count(tmp_path, capsys) -> None:
    """T56-A02: the same competition with another --runs is said to fly its runs anew, naming the stored count."""
    compete("ghh08", "baseline", runs=1, episodes=1, n_steps=20, out=tmp_path / "c")
    capsys.readouterr()
    compete("ghh08", "baseline", runs=2, episodes=1, n_steps=20, out=tmp_path / "c")
    err = capsys.readouterr().err
    assert "holds this competition with 1 runs (settings-" in err
    assert "they are not reused, as the run count is part of a competition's settings digest; its 2 runs are flown anew" in err
    assert "To reuse them, give --runs 1" in err
    compete("ghh08", "baseline", runs=2, episodes=1, n_steps=20, out=tmp_path / "c")  # its own runs resumed: no note
    assert "not reused" not in capsys.readouterr().err


def _groups(*groups: dict) -> dict:
    settings = {"task": "ghh08", "seed": 1, "policies": "shipped", "episodes": 2, "n_steps": 50, "groups": list(groups)}
    return make_config("mytest", "test_runs", "quick", settings).to_dict()


def test_changed_group_list_of_another_length_shows_the_entries_that_differ() -> None:
    """T56-A03: one group stored, two given: the first's n_mdps and the added group are named, not two cut-off lists."""
    base, generic = {"agent": "baseline", "mdps": "test", "runs_per_mdp": 1}, {"agent": "generic", "mdps": "test", "n_mdps": 2, "runs_per_mdp": 1}
    what, _ = config_changes(json.dumps(_groups(base | {"n_mdps": 1})), _groups(base | {"n_mdps": 2}, generic))
    assert "groups 'baseline'.n_mdps: stored 1, given 2; groups 'generic': stored absent, given {'agent': 'generic'" in what
    what, _ = config_changes(json.dumps(_groups(base | {"n_mdps": 2}, generic)), _groups(base | {"n_mdps": 2}))
    assert what.startswith("the settings differ (groups 'generic': stored {'agent': 'generic'") and "given absent)" in what


TOML = 'name = "mytest"\nkind = "test_runs"\n\n[settings]\ntask = "ghh08"\nseed = 1\nseed = 2\n'


@pytest.mark.parametrize(
    ("text", "said"),
    [
        (TOML, "key 'seed' is given twice in [settings] (lines 6 and 7): give each key once"),
        (TOML.rstrip("\n"), "key 'seed' is given twice in [settings] (lines 6 and 7)"),  # tomllib: "at end of document"
        (TOML.replace("seed = 1", "seed.x = 1"), "key 'seed' is given twice in [settings] (line 7; a line above gives it, or a table it names, a value)"),
    ],
)
def test_toml_key_given_twice_is_named(tmp_path, text: str, said: str) -> None:
    """T56-A04: the key, its table and lines, not tomllib's "Cannot overwrite a value (at line 7, column 9)"."""
    path = tmp_path / "b4.toml"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(NeurohoverError, match="is not valid TOML: " + said.replace("(", r"\(").replace(")", r"\)").replace("[", r"\[").replace("]", r"\]")):
        load_config(str(path), "quick")
