"""What trial 58's fix of ``unknown_keys`` (T58-B01..B03) left in five checks that joined unknown keys by hand: a task
family table, a [paper] table, its ttests entries and its numbers, and a config's top-level keys named the key ''
as nothing ("unknown key(s) ; allowed ..."). Each now names it as its repr, ``''``. And trial 59 side A's note: a drift text's
unknown key was not told that walk is allowed."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from neurohover.errors import NeurohoverError
from neurohover.experiments.config import load_config
from neurohover.experiments.paper_checks import check_paper_table
from neurohover.tasks import family_from_dict


def _refused_with(fragment: str):
    return pytest.raises(NeurohoverError, match=re.escape(fragment))


def test_a_task_family_tables_empty_key_is_named() -> None:
    with _refused_with("unknown key(s) ''; allowed family"):
        family_from_dict({"family": "ghh08", "": 1})


def test_a_paper_tables_empty_key_is_named() -> None:
    with _refused_with("unknown [paper] key(s) ''; allowed"):
        check_paper_table({"notes": [], "": 1}, "config 'x'")


def test_a_paper_t_tests_empty_key_is_named() -> None:
    with _refused_with("unknown [paper] ttests key(s) '' in"):
        check_paper_table({"ttests": [{"a": "x", "b": "y", "p": "0.01", "": 1}]}, "config 'x'")


def test_a_paper_numbers_empty_key_is_named() -> None:
    with _refused_with("unknown number(s) ''"):
        check_paper_table({"groups": {"baseline": {"mean": -1.0, "": 2.0}}}, "config 'x'")


def test_a_configs_empty_top_level_key_is_named(tmp_path: Path) -> None:
    shipped = (Path(__file__).parents[1] / "neurohover" / "experiments" / "configs" / "fig2.toml").read_text()
    config = tmp_path / "mine.toml"
    config.write_text('"" = 1\n' + shipped)
    with _refused_with("unknown top-level key(s) ''; allowed"):
        load_config(str(config), "quick")


def test_a_drift_text_of_an_unknown_key_names_walk_among_what_is_allowed() -> None:
    """Trial 59, side A: '--drift WALK=0.01' was told only the dynamics parameters, as if walk were not allowed."""
    from neurohover.tasks.drift import Drift

    with _refused_with("drift 'WALK=0.01': 'WALK' is not walk and not a dynamics parameter; allowed walk=STD and C_u, C_v"):
        Drift.parse("WALK=0.01")


def test_a_drift_walk_in_runs_of_one_episode_is_refused(tmp_path: Path) -> None:
    """T61-A01: walk=0.5 with one episode a run was stored as drifting and flew fixed dynamics (episode 0 flies the MDP
    as given); a walk in runs of two episodes is taken."""
    from neurohover.compete import compete
    from neurohover.tasks.drift import Drift

    walk = Drift.parse("walk=0.5")
    with _refused_with("drift walk=0.5 drifts nothing in a test run of 1 episode"):
        walk.check_run(1)
    walk.check_run(2)
    with _refused_with("drifts nothing in a test run of 1 episode"):
        compete("ghh08", "baseline", runs=1, episodes=1, n_steps=20, out=tmp_path / "c", drift=walk)
    assert not (tmp_path / "c").exists() or not any((tmp_path / "c").iterdir())
