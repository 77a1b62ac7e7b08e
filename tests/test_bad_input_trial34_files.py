"""Bad-input trial 34 (helper A), files: T34-A04 (a compete interrupted in an --out that held an earlier competition
rewrote only episodes.csv: the earlier summary.json and plot stayed, though its note said they are replaced, and plot
--compete refused the folder, blaming the new rows) and T34-A05 (flight data of an older neurohover, naming their policy
but without policy_flown, let learn-model --method ec-mer take another --policy)."""

from __future__ import annotations

import json
from pathlib import Path

from test_bad_input_trial26_signals import _interrupt_after

# ------------------------------------------------------------------------------------------- T34-A04

TINY = ("compete", "--task", "ghh08", "--agent", "baseline", "--runs", "2", "--episode-steps", "20")


def _finished(cli, out: Path) -> None:
    rc, _, err = cli(*TINY, "--episodes", "2", "--out", str(out))
    assert rc == 0 and (out / "summary.json").is_file() and (out / "cumulative.png").is_file(), err


def test_an_interrupted_compete_removes_the_earlier_competitions_summary_and_plot(tmp_path: Path, cli, monkeypatch) -> None:
    out = tmp_path / "c"
    _finished(cli, out)
    _interrupt_after(monkeypatch, 1)
    rc, _, err = cli(*TINY, "--episodes", "3", "--out", str(out))  # other settings: the earlier competition's files replaced
    assert rc == 130, err
    assert not (out / "summary.json").exists() and not (out / "cumulative.png").exists()
    assert "its episodes.csv, summary.json and plot are replaced" in err and "leaves only the episodes.csv of its finished runs" in err, err
    assert len((out / "episodes.csv").read_text().splitlines()) == 1 + 3  # its header and its one run's three episodes
    rc, _, err = cli("plot", "--compete", str(out), "--out", str(tmp_path / "p"))
    assert rc == 0, err  # the folder is consistent: plot --compete draws it, labelled by its name
    monkeypatch.undo()
    rc, _, err = cli(*TINY, "--episodes", "3", "--out", str(out))  # the same command resumes and writes them again
    assert rc == 0 and (out / "summary.json").is_file() and (out / "cumulative.png").is_file(), err
    assert json.loads((out / "summary.json").read_text())["runs"] == 2


def test_a_compete_stopped_before_a_run_finished_leaves_the_earlier_competition_whole(tmp_path: Path, cli, monkeypatch) -> None:
    out = tmp_path / "c"
    _finished(cli, out)
    before = {name: (out / name).read_bytes() for name in ("episodes.csv", "summary.json", "cumulative.png")}
    _interrupt_after(monkeypatch, 0)
    rc, _, err = cli(*TINY, "--episodes", "3", "--out", str(out))
    assert rc == 130 and "the folder as it was if none had finished" in err, err
    assert {name: (out / name).read_bytes() for name in before} == before
    assert cli("plot", "--compete", str(out), "--out", str(tmp_path / "p"))[0] == 0
