"""Bad-input trial 52, side A (the command line): evolve --json and fly --record F --json with standard output closed
exited 0, the JSON asked for lost (T52-A01); a race's delta was recorded by '%g' (race:0.1234567891 as race:0.123457),
and a resume given the recorded label was refused as a damaged checkpoint, a genuinely other delta of that label too
(T52-A02); --setting popsize=none was taken by the neuroevolution's settings but refused by CMA-ES's and UH-CMA-ES's,
whose messages say None is allowed (T52-A03)."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest

from neurohover.evolution import parse_resampling

EVOLVE = ["evolve", "--task", "ghh08", "--episode-steps", "20"]


@pytest.mark.parametrize(
    "argv",
    [[*EVOLVE, "--budget", "10", "--out", "a1.json", "--json"], ["fly", "--task", "ghh08", "--episodes", "1", "--record", "r1.npz", "--json"]],
    ids=["evolve", "fly-record"],
)
def test_a01_a_json_summary_asked_for_with_stdout_closed_is_refused_up_front(cli, monkeypatch, tmp_path: Path, argv: list[str]) -> None:
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(sys, "stdout", None)  # what Python makes of `1>&-`
    rc, _, err = cli(*argv)
    assert rc == 2, err
    assert "standard output is closed: this command prints its results there; run it with standard output open (or leave out --json" in err
    assert not list(tmp_path.iterdir())  # nothing flown, nothing written
    monkeypatch.undo()
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(sys, "stdout", None)
    rc, _, err = cli(*argv[:-1])  # without --json: its files, and its notes nowhere (T28-A01)
    assert rc == 0 and list(tmp_path.iterdir()), err


@pytest.mark.parametrize("text", ["race:0.05", "race:0.1234567891", "bandit:0.1234567891", "race:0.3333333333333333:algorithm1", "fixed:5", "race:auto"])
def test_a02_a_resampling_label_reads_back_as_the_same_resampling(text: str) -> None:
    kind = text.split(":")[0]
    if kind == "bandit":
        from neurohover.evolution.bandits import BANDITS

        text = text.replace("bandit", next(iter(BANDITS)))
    resampling = parse_resampling(text)
    assert parse_resampling(str(resampling)) == resampling
    if text in ("race:0.05", "fixed:5", "race:auto"):
        assert str(resampling) == text  # the labels every record so far holds are unchanged


def test_a02_a_resume_given_the_recorded_resampling_resumes(tmp_path: Path, cli) -> None:
    out = tmp_path / "z1.json"
    rc, _, err = cli(*EVOLVE, "--mdp", "G", "--budget", "10", "--out", str(out), "--resampling", "race:0.1234567891")
    assert rc == 0, err
    recorded = json.loads(out.read_text())["resampling"]
    assert recorded == "race:0.1234567891"
    rc, _, err = cli(*EVOLVE, "--mdp", "G", "--budget", "400", "--out", str(out), "--resampling", recorded, "--resume")
    assert rc == 0 and "damaged" not in err, err


@pytest.mark.parametrize(("optimizer", "setting"), [("cma", "popsize=none"), ("uh-cma", "popsize=None"), ("uh-cma", "reevaluations=NONE")])
def test_a03_setting_none_is_none_for_every_optimiser(tmp_path: Path, cli, optimizer: str, setting: str) -> None:
    out = tmp_path / "w.json"
    rc, _, err = cli(*EVOLVE, "--budget", "10", "--out", str(out), "--optimizer", optimizer, "--setting", setting)
    assert rc == 0, err
    key = setting.split("=")[0]
    assert json.loads(out.read_text())["settings"][key] is None
