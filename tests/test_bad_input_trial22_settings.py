"""The twenty-second bad-input trial's findings in experiment settings and policy-set manifests: a bad
``generic_resampling`` is named by its key and value with the resampling parser's own message, and ``{}`` is refused
(T22-15)."""

from __future__ import annotations

import pytest

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

    cfg = load_config("fig16", "quick", {"generic_resampling": {"race": "race:0.3"}})
    assert cfg.settings["generic_resampling"] == {"race": "race:0.3"}
