"""Items left open by earlier sessions' trials of issue 37, fixed in the twenty-eighth session: an optimiser's
state_dict() that holds itself was followed without end (a RecursionError) by the check that names what strict JSON
cannot write."""

from __future__ import annotations

import pytest

from neurohover import NeurohoverError
from neurohover.evolution.answers import check_state_json


def _holding_itself(where: str) -> dict:
    state: dict = {"mean": [0.0, 1.0], "step": 3}
    if where == "table":
        state["again"] = state
    else:
        inner: list = [1.0]
        inner.append(inner)
        state["history"] = [inner]
    return state


@pytest.mark.parametrize(("where", "entry"), [("table", "['again']"), ("list", "['history'][0][1]")])
def test_a_state_that_holds_itself_is_named_not_followed(where: str, entry: str) -> None:
    with pytest.raises(NeurohoverError, match=r"entry " + entry.replace("[", r"\[").replace("]", r"\]") + r" \(a list or table that holds itself"):
        check_state_json(_holding_itself(where), "mine")


def test_a_state_that_holds_one_list_twice_is_written() -> None:
    shared = [1.0, 2.0]
    check_state_json({"a": shared, "b": shared, "c": [shared, shared]}, "mine")  # the same list twice is no cycle
