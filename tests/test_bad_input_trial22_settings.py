"""The twenty-second bad-input trial's findings in experiment settings and policy-set manifests: a bad
``generic_resampling`` is named by its key and value with the resampling parser's own message, and ``{}`` is refused
(T22-15). A policy-set manifest whose safe list, crash counts or Table 3 figures contradict its own tables is refused,
and an FGHH manifest's GHH tables (accepted and never read) too (T22-16)."""

from __future__ import annotations

from pathlib import Path

import pytest
from store_edits import edited_policy_set

from neurohover.errors import NeurohoverError


@pytest.mark.parametrize(
    ("table", "message"),
    [
        ({"fixed": "zzz", "race": "race:0.2"}, r"generic_resampling\.fixed: unknown resampling 'zzz': allowed fixed:K"),
        ({"fixed": "fixed:5", "race": "race:2"}, r"generic_resampling\.race: bad resampling 'race:2': DELTA must be a number strictly between 0 and 1"),
        ({"fixed": 5}, r"generic_resampling\.fixed = 5 is not allowed: give a text such as 'fixed:5'"),
        ({"zero": "fixed:1"}, r"generic_resampling has the key 'zero': allowed keys fixed and race"),
        ({}, r"generic_resampling = \{\} is not allowed: give keys fixed and/or race"),
    ],
)
def test_a_bad_generic_resampling_names_its_key_and_value(table: dict, message: str) -> None:
    """T22-15: every bad table read "generic_resampling must be a table with keys fixed and/or race holding fixed:K /
    race:DELTA", naming neither the key nor the value, and {} was taken."""
    from neurohover.experiments.config import load_config

    with pytest.raises(NeurohoverError, match=message):
        load_config("fig16", "quick", {"generic_resampling": table})


def test_a_bad_generic_resampling_on_the_command_line_is_one_line_and_status_2(cli, tmp_path) -> None:
    """T22-15 as found: reproduce --set "generic_resampling={fixed='zzz',race='race:2'}" (refused before any store is
    made)."""
    rc, _, err = cli("reproduce", "fig16", "--scale", "quick", "--store", str(tmp_path / "s.sqlite"), "--set", "generic_resampling={fixed='zzz',race='race:2'}")
    assert rc == 2 and "Traceback" not in err
    assert "generic_resampling.fixed: unknown resampling 'zzz'" in err
    assert not (tmp_path / "s.sqlite").exists()


def test_a_good_generic_resampling_is_kept() -> None:
    from neurohover.experiments.config import load_config

    # generics_from left empty: fig16's own fixed and race generics are drawn from fig13 and fig15, where the table does
    # nothing (refused since T26-A02); the experiment evolves them itself here
    cfg = load_config("fig16", "quick", {"generics_from": {}, "generic_resampling": {"race": "race:0.3"}})
    assert cfg.settings["generic_resampling"] == {"race": "race:0.3"}


def _cell(name: str, i: int, j: int, value):
    return lambda m: m[name][i].__setitem__(j, value)


@pytest.mark.parametrize(
    ("task", "change", "message"),
    [
        (  # as found: policy 6 is listed as safe
            "ghh08",
            _cell("crashes_on_training_mdps", 6, 0, 3),
            r"safe lists specialised policy 6, but crashes_on_training_mdps\[6\]\[0\] = 3: it crashed in 3 episodes on training MDP 0 "
            r"\(3 on the other training MDPs in all\), while policy 0, not listed, crashed in 0 there; safe policies are those that never",
        ),
        (
            "ghh08",
            lambda m: m.__setitem__("safe", [6, 7]),
            r"safe lists specialised policy 7, whose mean return on the other training MDPs is -3313\.48, but not policy 2, which "
            r"crashed there as rarely \(0 episodes\) and returned -828\.70",
        ),
        ("ghh08", _cell("crashes_on_training_mdps", 0, 0, 4), r"crashes_on_training_mdps\[0\]\[0\] = 4 is more than safety_episodes = 3"),
        ("ghh08", _cell("crashes_on_training_mdps", 0, 0, 1), r"table3's crashed_episodes = 0 is not what crashes_on_training_mdps gives \(1\)"),
        ("ghh08", lambda m: m["table3"].__setitem__("r_G", -2001.89), r"table3's r_G = -2001\.89 is not what mean_return_on_training_mdps gives \(-1204\.34\)"),
        ("ghh08", lambda m: m.__setitem__("table3", "x"), r"table3='x' is not allowed: give a table of r and r_G"),
        ("ghh08", lambda m: m.__setitem__("fghh_budget", 10), r"has fghh_budget: they apply to an FGHH set's generics over G; remove them"),
        (
            "fghh",
            lambda m: m.__setitem__("crashes_on_training_mdps", [[3]]),
            r"has crashes_on_training_mdps: they apply to a GHH-08/09 set's specialised policies \(an FGHH set has none\)",
        ),
    ],
)
def test_a_manifest_that_contradicts_itself_is_refused(tmp_path: Path, task: str, change, message: str) -> None:
    """T22-16: a safe policy with crashes on another training MDP (where policies without any were not listed) was flown
    as safe; Table 3's figures and the crash counts were never compared with the tables; an FGHH manifest's GHH tables were
    accepted and ignored."""
    from neurohover.policysets import load_policy_set

    pd = edited_policy_set(tmp_path, task, change)
    with pytest.raises(NeurohoverError, match=message):
        load_policy_set(task, pd)


def test_a_safe_policy_that_crashed_on_the_command_line_is_one_line_and_status_2(cli, tmp_path: Path) -> None:
    """T22-16 as found: compete --agent hybrid --policy-dir with such a set ran (status 0)."""
    pd = edited_policy_set(tmp_path, "ghh08", _cell("crashes_on_training_mdps", 6, 0, 3))
    argv = ["compete", "--task", "ghh08", "--agent", "hybrid", "--runs", "1", "--episodes", "2", "--episode-steps", "20"]
    rc, _, err = cli(*argv, "--policy-dir", str(pd), "--out", str(tmp_path / "X"))
    assert rc == 2 and "Traceback" not in err
    assert "safe lists specialised policy 6, but crashes_on_training_mdps[6][0] = 3" in err


def test_the_shipped_manifests_are_taken_and_safe_lists_in_another_order_are_not(tmp_path: Path) -> None:
    """The rule's checks take what a build writes (its returns rounded to 0.01). The safe policies in another order than
    the tables give were taken here once; the hybrid agents fly safe:0 first, and since T37-B07 they are refused
    (tests/test_bad_input_trial37_files.py: the order the tables cannot tell is taken either way)."""
    from neurohover.policysets import load_policy_set

    for task in ("ghh08", "ghh09", "fghh"):
        load_policy_set(task)
    with pytest.raises(NeurohoverError, match=r"safe=\[2, 6\] is not allowed: the paper's rule on its tables gives \[6, 2\]"):
        load_policy_set("ghh08", edited_policy_set(tmp_path, "ghh08", lambda m: m.__setitem__("safe", [2, 6])))
