"""Trial 43, side A (command line): ``compete --task`` refused the spellings of a task family (GHH-08, GHH08, ghh-08,
FGHH) that fly, evolve, evaluate-agent and build-policies take (T43-A01, a false refusal): its experiment name was
built from the text as given."""

from __future__ import annotations

from pathlib import Path

import pytest

from neurohover.cli import main


@pytest.mark.slow
@pytest.mark.parametrize("spelling", ["GHH-08", "GHH08", "ghh-08"])
def test_compete_takes_every_spelling_of_a_task_family_the_other_commands_take(spelling: str, tmp_path: Path, capsys) -> None:
    out = tmp_path / "c"
    argv = ["compete", "--task", spelling, "--agent", "baseline", "--runs", "1", "--episodes", "2", "--episode-steps", "20"]
    assert main([*argv, "--out", str(out)]) == 0, capsys.readouterr().err
    summary = (out / "summary.json").read_text(encoding="utf-8")
    assert '"experiment": "compete-ghh08-baseline"' in summary


def test_a_task_family_no_spelling_names_is_still_refused_by_the_command(tmp_path: Path, capsys) -> None:
    argv = ["compete", "--task", "GHH-10", "--agent", "baseline", "--runs", "1", "--episodes", "2", "--out", str(tmp_path / "c")]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "'GHH-10'" in err and "ghh08" in err
