"""Trial 45, side B, a results store and a compete folder edited by hand.

T45-B02: a unit's ``seconds`` of 1e300 was exported (its result's own timing said 0.64 s), and a unit's ``finished`` of
1e12 or 0 and an experiment's ``created`` of -5 were taken: the store's readers refuse seconds over 100 years, seconds
less than the result's own timing (the store times the whole unit, which holds that run), and times outside 2001 to
2106 (the sessions' rule), naming the experiment, the unit and the value.

T45-B09: a compete summary whose ``agent`` and ``experiment`` were both edited (baseline to incremental) was plotted as
the other agent's, and :func:`~neurohover.compete.check_against_store` took it, as its store holds no such experiment;
its store holds the summary's scale (a settings-HASH, which digests the agent and task) under the baseline's
experiment, and the summary is refused naming both."""

from __future__ import annotations

import json
import re
import shutil
from pathlib import Path

import pytest
from store_edits import competed_store, damaged

from neurohover.errors import NeurohoverError

NAME = "compete-ghh08-baseline"


@pytest.fixture(scope="module")
def competed(tmp_path_factory) -> Path:
    """One tiny compete run's folder (``c``) and store (``s.sqlite``)."""
    where = tmp_path_factory.mktemp("t45")
    competed_store(where)
    return where


def export(store: Path) -> str:
    from neurohover.experiments import Store, export_results

    with Store(store, create=False) as held:
        return export_results(held, NAME, "csv")


UNIT = "unit run/baseline/test0/rep0's"
TIMES = r"allowed a time \(seconds since 1970\) from 2001 to 2106"


@pytest.mark.parametrize(
    ("sql", "says"),
    [
        ("UPDATE units SET seconds = 1e300", rf"{UNIT} seconds is damaged \(1e\+300 is more than 3\.15576e\+09 seconds: 100 years at most\)"),
        ("UPDATE units SET seconds = 0", r"unit 'run/baseline/test0/rep0': its seconds 0\.0 are not allowed: the store times the whole unit, .* at least that"),
        ("UPDATE units SET finished = 1e12", rf"{UNIT} finished time 1000000000000\.0 is damaged: {TIMES}"),
        ("UPDATE units SET finished = 0", rf"{UNIT} finished time 0\.0 is damaged: {TIMES}"),
        ("UPDATE experiments SET created = -5", rf"experiment '{NAME}' \('settings-[0-9a-f]+'\)'s created time -5\.0 is not allowed: {TIMES}"),
        ("UPDATE experiments SET created = 1e999", rf"created time inf is not allowed: {TIMES}"),
    ],
)
def test_a_units_seconds_and_the_stores_times_edited_by_hand_are_refused(competed: Path, tmp_path: Path, sql: str, says: str) -> None:
    """T45-B02: each was exported (seconds 1e300 while the unit's own timing said 0.64 s)."""
    store = damaged(competed / "s.sqlite", tmp_path / "s.sqlite", sql)
    with pytest.raises(NeurohoverError, match=rf"results store {re.escape(repr(str(store)))}.*{says}"):
        export(store)


def test_the_store_as_written_exports(competed: Path, tmp_path: Path) -> None:
    """T45-B02: what compete wrote still exports: its seconds hold its result's timing, its times are now."""
    assert export(competed / "s.sqlite").count(NAME) == 1


def test_a_summary_relabelled_to_another_agent_is_refused(competed: Path, tmp_path: Path) -> None:
    """T45-B09: agent and experiment edited together; the store holds its settings-HASH under the baseline's experiment."""
    from neurohover.compete import check_against_store

    folder = tmp_path / "c"
    shutil.copytree(competed / "c", folder)
    summary = json.loads((folder / "summary.json").read_text())
    check_against_store(folder)  # as written
    scale = summary["scale"]
    summary.update(agent="incremental", experiment="compete-ghh08-incremental")
    (folder / "summary.json").write_text(json.dumps(summary))
    says = (
        f"its experiment 'compete-ghh08-incremental' is not the one its store {str(competed / 's.sqlite')!r} holds its scale {scale} under: "
        f"{NAME} (a settings digest names one competition"
    )
    with pytest.raises(NeurohoverError, match=re.escape(says)):
        check_against_store(folder)
