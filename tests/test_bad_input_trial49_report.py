"""Bad-input trial 49, helper A (the report): a config of one's own at paper scale is the paper's protocol only where its
settings are a shipped experiment's at paper scale; one that --set shrank below its config's own ``[scales.paper]`` is
noted as a shrunk shipped one is, and one whose config file no longer reads says so (T49-A01); the report's Generated
time carries its UTC offset (trial 49: a bare local time read hours off in another zone)."""

from __future__ import annotations

import re
import time
from pathlib import Path

import pytest

#: A copy of fig2's config as a config of one's own (named mine, fig2's aliases dropped).
TINY = {"n_mdps": 1, "runs": 1, "budget": 10, "n_steps": 20, "validation_episodes": 1, "robustness_episodes": 1}


def _mine(where: Path, **changes: int) -> Path:
    from neurohover.experiments.config import shipped_configs

    text = shipped_configs()["fig2"].read_text(encoding="utf-8")
    text = re.sub(r'(?m)^name = "fig2"', 'name = "mine"', text)
    text = re.sub(r"(?m)^aliases = .*\n", "", text)
    for key, value in changes.items():  # in [scales.paper], the config's own paper scale
        head, paper = text.split("[scales.paper]", 1)
        paper, n = re.subn(rf"(?m)^{key} = .*$", f"{key} = {value}", paper, count=1)
        assert n == 1, key
        text = head + "[scales.paper]" + paper
    path = where / "mine.toml"
    path.write_text(text, encoding="utf-8")
    return path


@pytest.mark.slow
def test_a_config_of_ones_own_shrunk_by_set_is_not_called_the_paper_protocol(tmp_path: Path) -> None:
    from neurohover.experiments.config import load_config
    from neurohover.experiments.report_scale import paper_protocol, scale_note

    cfg = load_config(str(_mine(tmp_path)), "paper", TINY)
    note = scale_note(cfg)
    assert note.startswith("not the paper's protocol: --set ran less than mine at paper scale as its config says (")
    assert "budget (10 < 100000)" in note and "n_steps (20 < 6000)" in note and "runs (1 < 10)" in note
    assert "magnitudes are not comparable with the paper" in note and not paper_protocol(cfg)


def test_a_config_of_ones_own_is_the_paper_protocol_only_at_a_shipped_experiments_paper_scale(tmp_path: Path) -> None:
    from neurohover.experiments.config import load_config
    from neurohover.experiments.report_scale import paper_protocol, scale_note

    same = load_config(str(_mine(tmp_path)), "paper")  # fig2's paper scale under another name
    assert scale_note(same) == "the paper protocol: its settings are the shipped fig2's at paper scale" and paper_protocol(same)
    longer = load_config(str(_mine(tmp_path, n_steps=7000)), "paper")  # its own paper scale, more than fig2's
    note = scale_note(longer)
    assert note.startswith("its config's paper scale, not the paper's protocol: a config of its own, whose settings") and not paper_protocol(longer)
    assert "--set ran less" not in note and "not known" not in note


def test_a_config_of_ones_own_whose_file_is_gone_says_whether_set_ran_less_is_not_known(tmp_path: Path) -> None:
    from neurohover.experiments.config import load_config
    from neurohover.experiments.report_scale import paper_protocol, scale_note

    path = _mine(tmp_path)
    cfg = load_config(str(path), "paper", TINY)
    path.unlink()
    note = scale_note(cfg)
    assert note.startswith("its config's paper scale, not the paper's protocol") and "so whether --set ran less than its paper scale is not known" in note
    assert not paper_protocol(cfg)


@pytest.fixture
def kiritimati(monkeypatch):
    """Local time UTC+14 for the test (time.tzset again after, the zone restored)."""
    monkeypatch.setenv("TZ", "Pacific/Kiritimati")
    time.tzset()
    yield
    monkeypatch.undo()
    time.tzset()


@pytest.mark.slow
def test_the_report_notes_a_shrunk_config_of_ones_own_and_its_time_with_the_utc_offset(tmp_path: Path, kiritimati) -> None:
    from neurohover.experiments import LocalExecutor, Store, reproduce, write_report
    from neurohover.experiments.config import load_config

    with Store(tmp_path / "m.sqlite") as store:
        reproduce(load_config(str(_mine(tmp_path)), "paper", TINY), store, LocalExecutor(1), progress=False)
        report = write_report(store, tmp_path / "rep").read_text(encoding="utf-8")
    assert "- Scale: **paper** (not the paper's protocol: --set ran less than mine at paper scale as its config says (" in report
    assert "(the paper protocol)" not in report
    assert re.search(r"(?m)^Generated \d{4}-\d\d-\d\d \d\d:\d\d:\d\d\+14:00 from the results store ", report)
