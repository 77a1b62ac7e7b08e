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
