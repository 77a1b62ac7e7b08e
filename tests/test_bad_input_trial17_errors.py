"""Seventeenth bad-input trial: the shared checks of neurohover.errors (T17-1)."""

from __future__ import annotations

import numpy as np
import pytest

from neurohover.errors import brief, finite_real, whole_number


@pytest.mark.parametrize("value", [np.timedelta64(5, "s"), np.timedelta64(2), np.datetime64("2020-01-01")])
def test_numpy_times_are_no_numbers(value) -> None:
    """T17-1: np.timedelta64 is a np.signedinteger, so it passed as an integer and int() of it raised a TypeError in
    brief, check_seed, require_int and about 85 public functions; selection_race took np.timedelta64(4) as 4."""
    assert not whole_number(value) and not finite_real(value)
    assert brief(value) == repr(value)
    assert whole_number(np.int64(4)) and finite_real(np.float32(2.5)) and finite_real(np.uint8(3))  # NumPy's numbers still are


def test_brief_never_raises() -> None:
    """T17-1: a message must not fail on the value it names: a repr that raises is shown by its type."""

    class Broken:
        def __repr__(self) -> str:
            raise RuntimeError("no repr")

    assert brief(Broken()) == "a Broken"
    assert brief([Broken()]) == "a list"
