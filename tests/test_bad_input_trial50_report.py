"""Bad-input trial 50, the report: under a TZ whose UTC offset is 24 hours or more (glibc takes TZ='UTC-25'), the
Generated line was datetime's ValueError after every figure was drawn (T50-A01); a figure name blocked by a user's
file (a policy file at fig7-quick.png) was said as "the store's copy is damaged", and with every experiment blocked,
"every experiment asked for is damaged", which could send a user to reproduce --fresh (T50-A04): the report now stops
at the blocked output, naming it, writes no report.md and calls nothing damaged."""

from __future__ import annotations

import re
import time
from pathlib import Path

import pytest
from test_bad_input_trial7 import tiny_store  # noqa: F401  (tiny_store: the fixture)


@pytest.fixture(params=["UTC-25", "XXX-99:99", "XXX+24", "XXX-24:00:01"])
def far_zone(request, monkeypatch):
    """A TZ that glibc accepts with an offset of a day or more (time.tzset again after, the zone restored)."""
    monkeypatch.setenv("TZ", request.param)
    time.tzset()
    yield request.param
    monkeypatch.undo()
    time.tzset()


@pytest.mark.slow
def test_a01_the_report_is_written_under_an_offset_of_a_day_or_more(tiny_store: Path, tmp_path: Path, cli, far_zone: str) -> None:  # noqa: F811
    rc, _, err = cli("report", "--store", str(tiny_store), "--out", str(tmp_path / "rep"))
    assert rc == 0, err
    stamp = re.search(r"(?m)^Generated (\S+ \S+) from the results store ", (tmp_path / "rep" / "report.md").read_text(encoding="utf-8"))
    offset = time.localtime().tm_gmtoff
    hours, rest = divmod(abs(offset), 3600)
    assert abs(offset) >= 24 * 3600 and stamp is not None
    assert stamp[1].endswith(f"{'-' if offset < 0 else '+'}{hours:02d}:{rest // 60:02d}" + (f":{rest % 60:02d}" if rest % 60 else ""))


@pytest.mark.slow
def test_a04_a_blocked_figure_is_named_and_nothing_is_called_damaged(tiny_store: Path, tmp_path: Path, cli) -> None:  # noqa: F811
    rc, _, err = cli("report", "--store", str(tiny_store), "--out", str(tmp_path / "first"))
    figures = sorted(p.name for p in (tmp_path / "first").glob("*.png"))
    assert rc == 0 and figures, err
    out = tmp_path / "rep"
    out.mkdir()
    (out / figures[0]).write_text('{"format": "neurohover-policy/1"}\n', encoding="utf-8")  # a user's file at the figure's name
    rc, _, err = cli("report", "--store", str(tiny_store), "--out", str(out))
    assert rc == 2 and f"{figures[0]!s}" in err and "it would be replaced with a PNG image" in err, err
    assert "damaged" not in err and not (out / "report.md").exists()
