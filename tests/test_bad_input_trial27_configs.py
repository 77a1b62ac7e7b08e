"""The twenty-seventh bad-input trial's findings in experiment configs and the report (T27-A02 to T27-A05): a quick-scale
section's default discussion said "200-step episodes" whatever the config's n_steps (T27-A02); a paper p-value of "< 0.05"
counted as not significant, so the verdict read "significant here but not in the paper" (T27-A03); a [paper] t test of
the same pair in both orders was taken, and the report said the paper found each better than the other (T27-A04); an
unknown key in a [paper] ttests entry was dropped without a word (T27-A05)."""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import tiny_test_runs

from neurohover.errors import NeurohoverError
from neurohover.experiments.config import load_config
from neurohover.experiments.report import _discussion
from neurohover.experiments.report_base import p_significant, verdict

BASE = tiny_test_runs("baseline", "model-free", name="mini")


def _config(tmp_path: Path, text: str, name: str = "c.toml") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def _ttests(*entries: str) -> str:
    return BASE + "[paper]\nttests = [" + ", ".join(entries) + "]\n"


def test_a02_the_quick_discussion_says_the_configs_own_episode_length(tmp_path: Path) -> None:
    cfg = load_config(str(_config(tmp_path, BASE)), "quick")
    assert "with 20-step episodes" in _discussion(cfg, tmp_path) and "200-step" not in _discussion(cfg, tmp_path)
    assert "with 35-step episodes" in _discussion(load_config(str(_config(tmp_path, BASE)), "quick", {"n_steps": 35}), tmp_path)
    assert "with 300-step episodes" in _discussion(load_config("bench-sensor-models", "quick"), tmp_path)
    fig7 = _discussion(load_config("fig7", "quick"), tmp_path)  # the shipped 200-step sections read as before
    assert fig7.startswith("Quick scale only: a check of the whole pipeline with 200-step episodes, few runs and tiny evolution budgets.")


@pytest.mark.parametrize(
    ("text", "significant"),
    [("< 0.05", True), ("<0.05", True), ("< 0.01", True), ("< 0.1", False), ("<= 0.05", False), ("<= 0.049", True), ("0.05", False), ("0.0499", True)],
)
def test_a03_a_paper_p_below_the_level_is_significant(text: str, significant: bool) -> None:
    assert p_significant(text) is significant


def test_a03_the_verdict_of_a_paper_p_under_005_holds() -> None:
    assert verdict("model-free", 2.0, 1.0, 0.0451, "< 0.05") == "holds"
    assert verdict("model-free", 2.0, 1.0, 0.2, "< 0.05") == "same direction, not significant"


@pytest.mark.parametrize("extra", ['pp = "0.01"', "q = 1"])
def test_a05_an_unknown_key_in_a_t_test_is_refused(tmp_path: Path, extra: str) -> None:
    text = _ttests(f'{{ a = "model-free", b = "baseline", p = "0.01", {extra} }}')
    key = extra.split()[0]
    with pytest.raises(NeurohoverError, match=rf"unknown \[paper\] ttests key\(s\) '{key}' in .*; allowed: a, b, p$"):
        load_config(str(_config(tmp_path, text)), "quick")


def test_a04_a_pair_given_twice_is_refused_in_either_order(tmp_path: Path) -> None:
    one = '{ a = "baseline", b = "model-free", p = "< 0.05" }'
    for other in (one, '{ a = "model-free", b = "baseline", p = "< 0.05" }'):
        with pytest.raises(NeurohoverError, match=r"\[paper\] ttests compares '.*' with '.*' twice \(in either order\): give each pair once"):
            load_config(str(_config(tmp_path, _ttests(one, other))), "quick")
    assert len(load_config(str(_config(tmp_path, _ttests(one), "ok.toml")), "quick").paper["ttests"]) == 1
