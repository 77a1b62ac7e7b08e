"""Issue 37, the thirteenth fresh trial, F5 (and the minor crash_penalty, F8 threads): neurohover.settingsdoc's public functions refuse what is not a settings
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


def test_crash_penalty_takes_whole_steps_within_the_episode() -> None:
    """Thirteenth trial (minor): crash_penalty(10, 5) was a positive "penalty", 'a' a TypeError."""
    import numpy as np

    from neurohover.sim.constants import CRASH_STEP_PENALTY, crash_penalty

    assert crash_penalty(np.int64(4), 5) == -CRASH_STEP_PENALTY and crash_penalty(5, 5) == 0
    for steps, length, bad in ((10, 5, "steps_taken=10"), (0, 5, "steps_taken=0"), ("a", 5, "steps_taken='a'"), (1, 0, "episode_steps=0")):
        with pytest.raises(NeurohoverError, match=rf"{bad} is not allowed"):
            crash_penalty(steps, length)


def test_threads_of_numpy_integer_types_are_taken() -> None:
    """Thirteenth trial F8: num_threads(np.int64(1)) was 'out of range 1..N'; text is now named by its type."""
    import numpy as np

    from neurohover.launch import num_threads

    with num_threads(np.int64(1)):
        pass
    with pytest.raises(NeurohoverError, match=r"threads='1' is not allowed: give an integer in 1\.\."):
        with num_threads("1"):
            pass
