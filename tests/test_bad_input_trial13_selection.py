"""The thirteenth trial's findings on selection and report helpers (F14, F15, F20, F21): each bad input gives one clear
NeurohoverError naming the value and what is allowed, instead of a traceback or a silent wrong answer."""

from __future__ import annotations

from pathlib import Path

import pytest

from neurohover.errors import NeurohoverError


@pytest.mark.parametrize("names", [[], ()])
def test_write_report_refuses_an_empty_list_of_names(names, tmp_path: Path) -> None:
    """F21: names=[] was read as None and wrote a report of every experiment in the store; None still means all."""
    from neurohover.experiments.report import write_report
    from neurohover.experiments.store import Store

    store = Store(tmp_path / "r.sqlite")
    with pytest.raises(NeurohoverError, match=r"names=(\[\]|\(\)) is not allowed: give one or more experiment names, or None for all"):
        write_report(store, tmp_path / "out", names=names)
    assert not (tmp_path / "out").exists()
    with pytest.raises(NeurohoverError, match="holds no experiment"):  # None: all of them (here none), not refused
        write_report(store, tmp_path / "out", names=None)
