"""Bad-input trial 54, side A (experiments): a model-learning experiment's authors_generations was taken where no fit
has model_policy = 'authors', so no unit read it, yet it changed the config hash and the store refused the same command
without it (T54-A01); the config checks read the task registry's flags unchecked, so a sigma refusal listed a
run-time family whose has_sigma was the text 'no', and an entry that is no class was an AttributeError (T54-B11)."""

from __future__ import annotations

from pathlib import Path

import pytest

from neurohover.errors import NeurohoverError
from neurohover.experiments.config import load_config, make_config, shipped_configs
from neurohover.tasks import FGHH, TASK_FAMILIES

# --------------------------------------------------------------------------- T54-A01: authors_generations unused

SMALL = {"n_mdps": 1, "n_steps": 50, "methods": ["lr"], "generic": "baseline", "policy_budget": 20, "test_episodes": 1}


def test_authors_generations_without_an_authors_fit_is_refused() -> None:
    """T54-A01: `reproduce table4 --set authors_generations=5` ran (rc 0) and stored a hash of its own."""
    table4 = str(shipped_configs()["table4"])
    message = r"at scale 'quick': authors_generations = 5 applies to the fits with model_policy = 'authors'; this config has none: leave it out$"
    with pytest.raises(NeurohoverError, match=message):
        load_config(table4, "quick", {**SMALL, "authors_generations": 5})
    assert "authors_generations" not in load_config(table4, "quick", SMALL).settings


def test_a_config_file_s_authors_generations_without_an_authors_fit_is_refused(tmp_path: Path) -> None:
    """T54-A01: a copy of table4.toml with methods = ["ec-meno"] and authors_generations = 7 ran with rc 0; so did fits
    that evolve all their policies our way."""
    text = shipped_configs()["table4"].read_text().partition("[paper]")[0]  # its claims name the other methods
    text = text.replace('methods = ["ec-mer", "ec-meno", "lr", "lr-gls"]', 'methods = ["ec-meno"]\nauthors_generations = 7')
    path = tmp_path / "t4.toml"
    path.write_text(text)
    with pytest.raises(NeurohoverError, match=r"authors_generations = 7 applies to the fits with model_policy = 'authors'; this config has none"):
        load_config(str(path), "quick")
    ours = {"methods": ["lr"], "fits": [{"key": "a", "model_policy": "ours"}], "authors_generations": 7}
    with pytest.raises(NeurohoverError, match=r"authors_generations = 7 applies to the fits with model_policy = 'authors'"):
        make_config("ours54", "model_learning", "quick", {"task": "ghh08", "seed": 1, "n_mdps": 1, **ours})


def test_authors_generations_stands_where_a_fit_evolves_the_authors_way() -> None:
    path = str(shipped_configs()["lr-authors-table4"])
    for scale, generations in (("quick", 5), ("paper", 500)):
        assert load_config(path, scale).settings["authors_generations"] == generations
    assert load_config(path, "quick", {"authors_generations": 4}).settings["authors_generations"] == 4
    theirs = {"methods": ["lr"], "fits": [{"key": "a", "model_policy": "authors"}], "authors_generations": 7}
    assert make_config("theirs54", "model_learning", "quick", {"task": "ghh08", "seed": 1, "n_mdps": 1, **theirs}).settings["authors_generations"] == 7


# --------------------------------------------------------------------------- the registry's flags, read checked


class Textual54(FGHH):
    """A run-time family whose has_sigma is the text 'no' (truthy), refused by the registry's entry check."""

    name = "textual54"
    has_sigma = "no"  # type: ignore[assignment]


@pytest.mark.parametrize("entry", [Textual54, 5], ids=["flag-as-text", "no-class"])
def test_the_sigma_refusal_lists_only_the_registry_s_good_entries(monkeypatch, entry) -> None:
    """A has_sigma 'no' was listed among the families with a sigma ("sigma applies to task 'fghh', 'textual54' only");
    an entry 5 was "AttributeError: 'int' object has no attribute 'has_sigma'"."""
    monkeypatch.setitem(TASK_FAMILIES, "textual54", entry)
    settings = {"task": "ghh08", "sigma": 0.3, "seed": 1, "n_mdps": 1, "methods": ["lr"]}
    with pytest.raises(NeurohoverError, match=r"^experiment 'x': sigma applies to task 'fghh' only, not 'ghh08'$"):
        make_config("x", "model_learning", "quick", settings)
    with pytest.raises(NeurohoverError, match=r"task = 'textual54' is not allowed"):
        make_config("x", "model_learning", "quick", {**settings, "task": "textual54"})
