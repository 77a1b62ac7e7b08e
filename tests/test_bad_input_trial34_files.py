"""Bad-input trial 34 (helper A), files: T34-A04 (a compete interrupted in an --out that held an earlier competition
rewrote only episodes.csv: the earlier summary.json and plot stayed, though its note said they are replaced, and plot
--compete refused the folder, blaming the new rows) and T34-A05 (flight data of an older neurohover, naming their policy
but without policy_flown, let learn-model --method ec-mer take another --policy)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from flight_edits import edited_copy
from test_bad_input_trial26_signals import _interrupt_after

from neurohover.errors import NeurohoverError
from neurohover.flightdata import FlightData
from neurohover.models import ec_mer_policy
from neurohover.policies import baseline_policy

# ------------------------------------------------------------------------------------------- T34-A04

TINY = ("compete", "--task", "ghh08", "--agent", "baseline", "--runs", "2", "--episode-steps", "20")


def _finished(cli, out: Path) -> None:
    rc, _, err = cli(*TINY, "--episodes", "2", "--out", str(out))
    assert rc == 0 and (out / "summary.json").is_file() and (out / "cumulative.png").is_file(), err


@pytest.mark.slow
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


@pytest.mark.slow
def test_a_compete_stopped_before_a_run_finished_leaves_the_earlier_competition_whole(tmp_path: Path, cli, monkeypatch) -> None:
    out = tmp_path / "c"
    _finished(cli, out)
    before = {name: (out / name).read_bytes() for name in ("episodes.csv", "summary.json", "cumulative.png")}
    _interrupt_after(monkeypatch, 0)
    rc, _, err = cli(*TINY, "--episodes", "3", "--out", str(out))
    assert rc == 130 and "the folder as it was if none had finished" in err, err
    assert {name: (out / name).read_bytes() for name in before} == before
    assert cli("plot", "--compete", str(out), "--out", str(tmp_path / "p"))[0] == 0


# ------------------------------------------------------------------------------------------- T34-A05


def _older(cli, tmp_path: Path, policy: str = "baseline", named: str | None = None) -> Path:
    """A recording of ``policy`` in the layout of an older neurohover: metadata naming the policy (``named``, else
    ``policy``), without policy_flown."""
    path = tmp_path / "new.npz"
    assert cli("fly", "--task", "ghh08", "--mdp", "train:1", "--episodes", "1", "--policy", policy, "--record", str(path))[0] == 0

    def older(meta: dict) -> None:
        del meta["policy_flown"]
        meta["policy"] = named or policy

    return edited_copy(path, tmp_path / "old.npz", older)


def _near_baseline(tmp_path: Path) -> Path:
    """Another network than the baseline whose actions are the baseline's within the tolerance EC-MER checks."""
    genome = baseline_policy().genome.tolist()
    genome[0] = 1e-9
    path = tmp_path / "near.json"
    path.write_text(json.dumps({"topology": "slp", "genome": genome}))
    return path


@pytest.mark.slow
def test_ec_mer_refuses_another_policy_than_an_older_files_named_one(tmp_path: Path, cli) -> None:
    near = _near_baseline(tmp_path)
    old = _older(cli, tmp_path)
    out = tmp_path / "m.json"
    rc, _, err = cli("learn-model", "--flight-data", str(old), "--method", "ec-mer", "--budget", "2", "--out", str(out), "--policy", str(near))
    assert rc == 2 and not out.exists(), err
    assert f"--policy {str(near)!r} is not the policy that flew flight data {str(old)!r}: their metadata name 'baseline', a different network" in err, err
    assert "record no policy_flown" in err and "leave --policy out" in err and len(err.strip().splitlines()) == 1, err
    data = FlightData.load(old)  # the named policy, given or not, is taken
    assert ec_mer_policy("baseline", data, str(old)) == ec_mer_policy(None, data, str(old)) == baseline_policy()
    new = FlightData.load(tmp_path / "new.npz")  # a current recording: as before
    assert ec_mer_policy("baseline", new, "new.npz") == baseline_policy()


def test_ec_mer_refuses_to_check_against_an_older_files_unreadable_named_policy(tmp_path: Path, cli) -> None:
    gone = "gone-34/p.json"  # no such file here
    old = _older(cli, tmp_path, named=gone)  # flown by the baseline; the named policy file is not here
    with pytest.raises(NeurohoverError) as err:
        ec_mer_policy("baseline", FlightData.load(old), str(old))
    said = str(err.value)
    assert said.startswith(f"--policy 'baseline' cannot be checked against flight data {str(old)!r}: they record no policy_flown"), said
    assert f"the policy their metadata name, {gone!r}, cannot be read here" in said and "record the flight again with fly --record" in said, said
