"""Issue 37, the thirteenth fresh trial, F5: neurohover.settingsdoc's public functions refuse what is not a settings
class by name (None and int were AttributeErrors and dataclasses' TypeError; summary(None) was '.')."""

from __future__ import annotations

import pytest

from neurohover import settingsdoc
from neurohover.errors import NeurohoverError
from neurohover.evolution import SteadyStateSettings


@pytest.mark.parametrize("call", [settingsdoc.settings_rows, settingsdoc.documented, settingsdoc.summary, lambda c: settingsdoc.format_settings(c, "t")])
@pytest.mark.parametrize("bad", [None, int, 5, "SteadyStateSettings"])
def test_what_is_no_settings_class_is_refused_by_name(call, bad) -> None:
    with pytest.raises(NeurohoverError, match=r"cls=.* is not allowed: give a settings class \(a dataclass type\)"):
        call(bad)


def test_plain_and_the_title_take_text_and_a_settings_class_is_still_documented() -> None:
    with pytest.raises(NeurohoverError, match="text=None is not allowed: give a docstring's text"):
        settingsdoc.plain(None)
    with pytest.raises(NeurohoverError, match="title=None is not allowed: give text"):
        settingsdoc.format_settings(SteadyStateSettings, None)
    assert settingsdoc.summary(SteadyStateSettings) != "." and settingsdoc.settings_rows(SteadyStateSettings)[0].name
    assert settingsdoc.format_settings(SteadyStateSettings, "steady-state").startswith("steady-state: ")
