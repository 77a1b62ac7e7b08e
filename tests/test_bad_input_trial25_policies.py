"""Bad input, trial 25: policy files' sensor, sigma and run records, and policy sets against their manifests (T25-04,
T25-05, T25-06, T25-07, the policy-file parts of T25-12 and T25-14).

A policy file's ``sensor`` (delay 99, a setting 'bogus', the text 'x') and ``sigma`` (0.7 beside G(sigma=0.3), -3, any on
ghh08) were flown unchecked; its record's fixed:K against its episodes and evaluations, its plateau stop against its
plateau_threshold, its prototype against its seed_policy were not compared; keys no policy file holds (format,
obs_noise), a seed_policy of 5 and a history of 5 or '../../etc/passwd' were taken. A set's FGHH generic recording
G(sigma=0.7) in a set of sigma 0.3, or race resampling as its fixed generic, was flown; a manifest's built 'yesterday',
seed 7 beside policies of a build from 0, and lineage 'independent' beside ancestor.json were shown. Each is refused by
name; every file the code writes still loads."""

from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import Any

import pytest
from conftest import CliRun
from policy_edits import edited, refused

import neurohover as nh
from neurohover.errors import NeurohoverError
from neurohover.manifest import policy_record_problem
from neurohover.policysets import SHIPPED, load_policy_set

SHORT = ("--budget", "10", "--episode-steps", "20", "--validation-episodes", "1")


@pytest.fixture(scope="module")
def written(tmp_path_factory) -> Path:
    """Evolve outputs as the trial wrote them: steady state on ghh08/zero, on ghh08 through a noisy late sensor (which
    records its sensor), over FGHH's G (which records its sigma) and on ghh08 seeded from that (whose record is its own)."""
    from neurohover.cli import main

    where = tmp_path_factory.mktemp("written25")
    runs = {
        "p": [],
        "noisy": ["--obs-noise", "0.3", "--obs-delay", "1"],
        "fghh": ["--task", "fghh", "--mdp", "G", "--setting", "pop_size=5", "--setting", "select_size=2"],
        "seeded": ["--topology", "slp", "--seed-policy", str(where / "fghh.json")],  # its FGHH seed's record not carried
    }
    for name, extra in runs.items():
        task = [] if "--task" in extra else ["--task", "ghh08"]
        assert main(["evolve", *task, *extra, *SHORT, "--out", str(where / f"{name}.json")]) == 0, name
    return where


def test_the_files_evolve_writes_still_load(written: Path) -> None:
    for name in ("p", "noisy", "fghh", "seeded"):
        assert policy_record_problem(nh.load_policy(written / f"{name}.json").metadata) == "", name
    assert nh.load_policy(written / "noisy.json").metadata["sensor"]["delay"] == 1
    assert nh.load_policy(written / "fghh.json").metadata["sigma"] == 0.3


def test_a_seeded_champion_records_its_own_run_not_its_seeds(written: Path, tmp_path: Path) -> None:
    """T25-12's writer bug: a champion copied its seed policy's whole record (its sigma, target, validation figures), so
    a ghh08 run seeded from an FGHH generic said sigma 0.3, and the sigma check had to let seeded files through."""
    seed, seeded = (nh.load_policy(written / f"{n}.json").metadata for n in ("fghh", "seeded"))
    assert "sigma" not in seeded and seeded["target"] == "ghh08/zero" and seeded["seed_policy"] == str(written / "fghh.json")
    assert seeded["prototype"] == seed["prototype"] in ("zero", "baseline")  # where the lineage started is carried on, and only that
    assert seeded.keys() <= nh.load_policy(written / "p.json").metadata.keys() | {"seed_policy"}
    refused(edited(written / "seeded.json", tmp_path / "s.json", sigma=0.3), "its sigma 0.3 is not allowed beside its task 'ghh08'")


@pytest.mark.parametrize(
    ("sensor", "words"),
    [
        ({"delay": 99}, ("its sensor {'delay': 99} is not allowed: sensor delay=99 is out of range", "0..10")),
        ({"bogus": 1}, ("unknown sensor setting(s) 'bogus': allowed level",)),
        ("x", ("its sensor 'x' is not allowed: a sensor must be a table of settings",)),
    ],
)
def test_a_policy_files_sensor_is_read_as_a_sensor(written: Path, tmp_path: Path, sensor: object, words: tuple[str, ...]) -> None:
    """T25-04: sensor delay=99, {'bogus': 1} or 'x' was flown by fly --policy and seeded evolve."""
    refused(edited(written / "noisy.json", tmp_path / "s.json", sensor=sensor), *words)


def test_fly_refuses_a_policy_of_a_bad_sensor(written: Path, tmp_path: Path, cli: CliRun) -> None:
    path = edited(written / "noisy.json", tmp_path / "s.json", sensor={"delay": 99})
    rc, stdout, err = cli("fly", "--task", "ghh08", "--policy", str(path), "--episodes", "1")
    assert rc == 2 and "Traceback" not in err and stdout == "", err
    assert "its sensor {'delay': 99} is not allowed: sensor delay=99 is out of range" in err, err


@pytest.mark.parametrize(
    ("name", "sigma", "words"),
    [
        ("fghh", 0.7, ("its sigma 0.7 is not allowed beside its target 'fghh/G(sigma=0.3)'", "G(sigma=0.3)")),
        ("fghh", -3, ("its sigma -3 is not allowed: FGHH sigma=-3 is out of range: allowed 0 <= sigma <= 1",)),
        ("p", "x", ("its sigma 'x' is not allowed: FGHH sigma='x' is not allowed: give a number 0 <= sigma <= 1",)),  # T26-B17
        ("p", 0.3, ("its sigma 0.3 is not allowed beside its task 'ghh08'", "sigma is FGHH's")),
    ],
)
def test_a_policy_files_sigma_is_checked_by_fghh_and_against_its_task_and_target(
    written: Path, tmp_path: Path, name: str, sigma: object, words: tuple[str, ...]
) -> None:
    """T25-05: sigma 0.7 beside fghh/G(sigma=0.3), -3, or any sigma on ghh08 was flown."""
    refused(edited(written / f"{name}.json", tmp_path / "s.json", sigma=sigma), *words)


def test_a_records_counts_agree_with_its_resampling_and_plateau(written: Path, tmp_path: Path) -> None:
    """T25-06: fixed:3 beside 1 episode per evaluation, evaluations fewer than episodes at fixed:1, and a plateau stop
    before plateau_threshold evaluations were accepted."""
    meta = nh.load_policy(written / "p.json").metadata
    episodes = meta["episodes"]
    assert meta["resampling"] == "fixed:1" and meta["evaluations"] == episodes and meta["settings"]["plateau_threshold"] == 1000
    refused(
        edited(written / "p.json", tmp_path / "a.json", resampling="fixed:3"),
        f"its episodes {episodes} is not allowed beside its evaluations {episodes} and resampling 'fixed:3': each evaluation flies 3 episodes",
    )
    refused(
        edited(written / "p.json", tmp_path / "b.json", evaluations=episodes - 1, generations=1),
        f"its episodes {episodes} is not allowed beside its evaluations {episodes - 1} and resampling 'fixed:1'",
    )
    refused(
        edited(written / "p.json", tmp_path / "c.json", stop_reason="plateau"),
        f"its stop_reason 'plateau' is not allowed beside its evaluations {episodes} and settings' plateau_threshold 1000",
    )


def test_a_records_prototype_agrees_with_its_seed_policy(written: Path, tmp_path: Path) -> None:
    """T25-06: prototype 'zero' beside seed_policy 'baseline' was accepted."""
    assert nh.load_policy(written / "p.json").metadata["seed_policy"] == "baseline"
    refused(edited(written / "p.json", tmp_path / "z.json", prototype="zero"), "its prototype 'zero' is not allowed beside its seed_policy 'baseline'")


@pytest.mark.parametrize(
    ("changes", "words"),
    [
        ({"format": "neurohover-policy/9"}, "its format 'neurohover-policy/9' is not allowed: policy files carry no format tag"),
        ({"obs_noise": "level=0.5"}, "its obs_noise 'level=0.5' is not allowed: a policy file records the sensor its run saw as 'sensor'"),
        ({"seed_policy": 5}, "its seed_policy 5 is not allowed: give what the run was seeded from as text"),
        ({"history": 5}, "its history 5 is not allowed: give the name (no folder) of the run's history file"),
        ({"history": "../../etc/passwd"}, "its history '../../etc/passwd' is not allowed"),
    ],
)
def test_keys_no_policy_file_holds_and_bad_seed_policy_and_history_are_refused(written: Path, tmp_path: Path, changes: dict, words: str) -> None:
    """T25-12 (format, obs_noise: never read, they misled) and T25-14 (seed_policy 5, history 5 or a path) were taken."""
    refused(edited(written / "p.json", tmp_path / "k.json", **changes), words)


def copied_set(tmp_path: Path, task: str) -> Path:
    """A copy of the shipped ``task`` set under ``tmp_path``/sets."""
    shutil.copytree(SHIPPED / task, tmp_path / "sets" / task)
    return tmp_path / "sets" / task


def edit_json(path: Path, **changes: Any) -> None:
    data = json.loads(path.read_text())
    data.update(changes)
    path.write_text(json.dumps(data))


def set_refused(tmp_path: Path, task: str, *words: str) -> None:
    with pytest.raises(NeurohoverError) as err:
        load_policy_set(task, tmp_path / "sets")
    for word in words:
        assert word in str(err.value), str(err.value)


def test_the_shipped_sets_still_load() -> None:
    for task in ("ghh08", "ghh09", "fghh"):
        assert load_policy_set(task).task == task


def test_an_fghh_generics_target_is_compared_with_its_sets_sigma(tmp_path: Path) -> None:
    """T25-07: generic_fixed.json recording fghh/G(sigma=0.7) in a set of sigma 0.3 was flown (only fghh/G compared)."""
    edit_json(copied_set(tmp_path, "fghh") / "generic_fixed.json", target="fghh/G(sigma=0.7)")
    set_refused(tmp_path, "fghh", "generic_fixed.json (the fixed generic policy) records target 'fghh/G(sigma=0.7)', not 'fghh/G(sigma=0.3)'")


def test_an_fghh_generics_resampling_is_its_roles(tmp_path: Path, cli: CliRun) -> None:
    """T25-07: race:0.1 on the fixed generic was flown by compete."""
    edit_json(copied_set(tmp_path, "fghh") / "generic_fixed.json", resampling="race:0.1")
    set_refused(tmp_path, "fghh", "records resampling 'race:0.1', not 'fixed:5'")
    rc, _, err = cli("compete", "--task", "fghh", "--agent", "incremental-fixed", "--runs", "1", "--episodes", "1", "--episode-steps", "5",
                     "--policy-dir", str(tmp_path / "sets"), "--out", str(tmp_path / "c"))  # fmt: skip
    assert rc == 2 and "Traceback" not in err and "records resampling 'race:0.1', not 'fixed:5'" in err, err


def test_a_manifests_seed_is_the_one_its_policies_were_built_from(tmp_path: Path) -> None:
    """T25-14: a manifest seed of 7 beside policies of a build from seed 0 was shown."""
    edit_json(copied_set(tmp_path, "ghh08") / "manifest.json", seed=7)
    set_refused(tmp_path, "ghh08", "generic.json (the generic policy) records seed 2968811710, not ")


def test_a_manifests_built_is_a_build_time(tmp_path: Path) -> None:
    """T25-14: built 'yesterday' was shown as the build's time."""
    edit_json(copied_set(tmp_path, "ghh08") / "manifest.json", built="yesterday")
    set_refused(tmp_path, "ghh08", "its built 'yesterday' is not allowed: give the build's time as YYYY-MM-DD HH:MM:SS")


def test_an_independent_lineage_has_no_ancestor(tmp_path: Path) -> None:
    """T25-14: lineage 'independent' on a chain's set holding ancestor.json was shown."""
    edit_json(copied_set(tmp_path, "ghh08") / "manifest.json", lineage="independent")
    set_refused(tmp_path, "ghh08", "its lineage 'independent' is not allowed beside ancestor.json")
