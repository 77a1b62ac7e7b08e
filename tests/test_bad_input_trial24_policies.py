"""Bad input, trial 24: policy files' names and records (T24-01, T24-02, T24-03).

``neurohover evolve --out`` and ``save_policy`` wrote a policy under any name, overwriting flight data or another run's
checkpoint or history (T24-01); load_policy read a policy file whose record contradicted itself: a validation_return of
5.0, a task other than its target's, mdp_params other than its label's MDP, settings of pop_size 0 (T24-02); and
save_policy wrote a record (seed -1) that load_policy then refused (T24-03). Each is refused by name, before anything is
written or evolved; every file the code writes still loads."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest
from conftest import CliRun

import neurohover as nh
from neurohover.errors import NeurohoverError
from neurohover.manifest import policy_record_problem

#: A short evolve run of ``neurohover evolve`` (its --out comes after).
EVOLVE = ("evolve", "--task", "ghh08", "--budget", "10", "--episode-steps", "20", "--validation-episodes", "1")


@pytest.fixture(scope="module")
def written(tmp_path_factory) -> Path:
    """Evolve outputs the trial-23 test does not write: on train:0 (as the trial wrote it: 50-step episodes, 2 validation
    episodes), on an MDP set by --wind, on a sampled MDP, and over G from a seed policy evolved on train:0 (which no longer
    copies the seed's mdp_params, T25-12)."""
    from neurohover.cli import main

    where = tmp_path_factory.mktemp("written24")
    short = ["--episode-steps", "20", "--validation-episodes", "1"]
    runs = {
        "p": ["--mdp", "train:0", "--budget", "10", "--episode-steps", "50", "--validation-episodes", "2"],
        "wind": ["--wind", "1,2", "--budget", "10", *short],
        "sample": ["--mdp", "sample", "--budget", "10", *short],
        "seeded": ["--mdp", "G", "--budget", "100", "--topology", "mlp", "--seed-policy", str(where / "p.json"), *short],
    }
    for name, extra in runs.items():
        assert main(["evolve", "--task", "ghh08", "--out", str(where / f"{name}.json"), *extra]) == 0, name
    return where


def test_the_files_evolve_writes_still_load(written: Path) -> None:
    for name in ("p", "wind", "sample", "seeded"):
        assert policy_record_problem(nh.load_policy(written / f"{name}.json").metadata) == "", name
    assert "mdp_params" not in nh.load_policy(written / "seeded.json").metadata  # the seed's MDP is not the run's (T25-12)


def test_a_run_over_a_family_records_no_mdp_params(written: Path, tmp_path: Path) -> None:
    """T25-12: a champion over G copied its seed's mdp_params, so the check let them through beside a family target."""
    data = json.loads((written / "seeded.json").read_text())
    data["mdp_params"] = json.loads((written / "p.json").read_text())["mdp_params"]
    (tmp_path / "s.json").write_text(json.dumps(data))
    with pytest.raises(NeurohoverError, match=r"its mdp_params .* is not allowed beside its target 'ghh08/G': a run over a family evolves on no one MDP"):
        nh.load_policy(tmp_path / "s.json")


@pytest.mark.parametrize(
    "out",
    ["f.npz", "q.txt", "p", "p.json.checkpoint.json", "p.json.history.csv", "P.JSON.CHECKPOINT.JSON", "c1/summary.csv"],
)
def test_evolve_refuses_an_out_that_is_no_policy_file_name_before_evolving(tmp_path: Path, monkeypatch, cli: CliRun, out: str) -> None:
    """T24-01: f.npz (flight data) or another run's p.json.checkpoint.json were overwritten by the champion."""
    monkeypatch.chdir(tmp_path)  # names within 60 characters are shown whole
    Path(out).parent.mkdir(exist_ok=True)
    Path(out).write_text("kept")
    rc, stdout, err = cli(*EVOLVE, "--out", out)
    assert rc == 2 and "Traceback" not in err and stdout == "", err
    assert f"neurohover evolve: error: --out {out!r} is not allowed: " in err, err
    if out.lower().endswith(".checkpoint.json"):
        assert "evolve --out FILE writes FILE.checkpoint.json beside FILE as its run's checkpoint" in err, err
    elif out.endswith(".history.csv"):
        assert "evolve --out FILE writes FILE.history.csv beside FILE as its run's history" in err, err
    else:
        assert "a policy file is JSON; give a path ending .json (e.g. " in err, err
    assert Path(out).read_text() == "kept" and sorted(p.name for p in Path(out).parent.iterdir()) == [Path(out).name]  # nothing else written


def test_evolve_still_writes_a_json_name_in_any_case(tmp_path: Path, cli: CliRun) -> None:
    out = tmp_path / "P.JSON"
    assert cli(*EVOLVE, "--out", str(out))[0] == 0 and nh.load_policy(out).topology == "mlp"


def test_save_policy_refuses_a_name_that_is_no_policy_file_name(tmp_path: Path, monkeypatch) -> None:
    """T24-01: save_policy(p, 'sp.txt') was written."""
    monkeypatch.chdir(tmp_path)
    b = nh.baseline_policy()
    for name, says in (
        ("sp.txt", "policy file 'sp.txt' is not allowed: a policy file is JSON; give a path ending .json (e.g. 'sp.json')"),
        ("x.checkpoint.json", "policy file 'x.checkpoint.json' is not allowed: evolve --out FILE writes FILE.checkpoint.json beside FILE"),
        ("h.history.csv", "policy file 'h.history.csv' is not allowed: evolve --out FILE writes FILE.history.csv beside FILE"),
    ):
        with pytest.raises(NeurohoverError) as caught:
            nh.save_policy(b, name)
        assert says in str(caught.value), str(caught.value)
    assert list(tmp_path.iterdir()) == []
    assert nh.load_policy(nh.save_policy(b, "b.Json")) == b


@pytest.mark.parametrize(("changes", "says"), [
    ({"validation_return": 5.0}, "its validation_return 5.0 is not allowed: allowed a mean return in [-1.75e+10, 0]"),
    ({"validation_sd": -1}, "its validation_sd -1 is not allowed: allowed a standard deviation of returns in [0, "),
    ({"validation_episodes": 0}, "its validation_episodes 0 is not allowed: allowed an integer in 1..100,000,000"),
    ({"validation_episodes": 2.5}, "its validation_episodes 2.5 is not allowed: allowed an integer in 1..100,000,000"),
    ({"validation_episodes": 1}, "is not allowed beside its validation_episodes 1: one return has no spread (0)"),
    ({"task": "ghh09"}, "its task 'ghh09' is not allowed beside its target 'ghh08/train:0'"),
    ({"mdp": "train:1"}, "its mdp 'train:1' is not allowed beside its target 'ghh08/train:0': the run was evolved on 'train:0'"),
    ({"mdp": "G"}, "its mdp 'G' is not allowed beside its target 'ghh08/train:0'"),
    ({"target": "ghh08/train:1"}, "its mdp 'train:0' is not allowed beside its target 'ghh08/train:1'"),
    ({"mdp_params": "wind0"}, "is not allowed: MDP 'ghh08/train:0' is not allowed: its wind=(0.0, 0.0) contradict its label: ghh08's train:0 has wind="),
    ({"mdp_params": "label1"}, "is not allowed: MDP 'ghh08/train:1' is not allowed: its wind=(-4.91365, 3.1589050000000003) contradict its label"),
    ({"mdp_params": "custom"}, "its mdp_params label 'ghh08/custom' is not allowed beside its target 'ghh08/train:0'"),
    ({"mdp_params": 5}, "its mdp_params 5 is not allowed: give the MDP the run was evolved on as a table"),
    ({"n_steps": 60}, "its n_steps 60 is not allowed beside its episode_steps 50"),
    ({"champion_fitness_scale": "zzz"}, "its champion_fitness_scale 'zzz' is not allowed: allowed inv-log-error, return"),
    ({"champion_fitness_scale": "inv-log-error"}, "its champion_fitness_scale 'inv-log-error' is not allowed beside its method 'steady-state'"),
    ({"settings": {"pop_size": 0}}, "is not allowed: bad steady-state settings: pop_size=0 must be an integer >= 2"),
    ({"settings": {"zzz": 1}}, "is not allowed: unknown steady-state setting(s) 'zzz': allowed averaging_prob"),
    ({"settings": 3}, "its settings 3 is not allowed: give the optimiser's settings as a table"),
    ({"seconds": -1}, "its seconds -1 is not allowed: allowed a number of seconds >= 0"),
])  # fmt: skip
def test_a_policy_file_whose_record_contradicts_itself_is_refused_by_name(written: Path, tmp_path: Path, changes: dict, says: str) -> None:
    """T24-02: each was read by load_policy and flown by fly --policy."""
    data = json.loads((written / "p.json").read_text())
    edits: dict[str, Any] = {
        "wind0": {**data["mdp_params"], "wind": [0, 0]},
        "label1": {**data["mdp_params"], "label": "ghh08/train:1"},
        "custom": {**data["mdp_params"], "label": "ghh08/custom"},
    }
    changes = {k: (edits.get(v, v) if isinstance(v, str) and k == "mdp_params" else v) for k, v in changes.items()}
    if isinstance(changes.get("settings"), dict):
        changes["settings"] = {**data["settings"], **changes["settings"]}
    path = tmp_path / "p.json"
    path.write_text(json.dumps({**data, **changes}))
    with pytest.raises(NeurohoverError) as caught:
        nh.load_policy(path)
    assert f"policy file {str(path)!r}: " in str(caught.value) and says in str(caught.value), str(caught.value)


def test_fly_refuses_it_with_status_2(written: Path, tmp_path: Path, cli: CliRun) -> None:
    path = tmp_path / "p.json"
    path.write_text(json.dumps({**json.loads((written / "p.json").read_text()), "validation_return": 5.0}))
    rc, _, err = cli("fly", "--task", "ghh08", "--policy", str(path), "--episodes", "1")
    assert rc == 2 and "its validation_return 5.0 is not allowed" in err and "Traceback" not in err, err


@pytest.mark.parametrize(("metadata", "says"), [
    ({"seed": -1}, "its seed -1 is not allowed: allowed an integer in 0..2**63-1"),
    ({"budget": -5}, "its budget -5 is not allowed: allowed an integer in 1..10,000,000,000"),
    ({"validation_return": 5.0}, "its validation_return 5.0 is not allowed"),
])  # fmt: skip
def test_save_policy_refuses_a_record_load_policy_would_refuse(tmp_path: Path, metadata: dict, says: str) -> None:
    """T24-03: save_policy(baseline_policy(), 'sp.json', seed=-1) was written, and load_policy refused it."""
    path = tmp_path / "sp.json"
    with pytest.raises(NeurohoverError) as caught:
        nh.save_policy(nh.baseline_policy(), path, **metadata)
    assert f"policy file {str(path)!r}: {says}" in str(caught.value) and "nothing is written" in str(caught.value)
    assert not path.exists()
    edited = nh.Policy("slp", nh.baseline_policy().genome, metadata)  # the record in the policy's own metadata, too
    with pytest.raises(NeurohoverError, match="load_policy would refuse the file"):
        nh.save_policy(edited, path)
    assert not path.exists()
