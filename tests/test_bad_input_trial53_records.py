"""Bad-input trial 53, side B (a policy file's record of its run): an mdp beside a task with no target naming the
family was never checked against the task's MDPs, so train:99, banana or '' beside ghh08 loaded (T53-B01; test:10 is
one of ghh08's 100 test MDPs, and loads); a GHH target naming FGHH's breadth, ghh08/G(sigma=0.3), loaded where the
same sigma as the sigma key was refused (T53-B02); the sigma in an FGHH target, fghh/G(sigma=5), -1, nan, abc or '',
was never checked, as the sigma key is, by the FGHH family (T53-B03). What evolve writes still loads."""

from __future__ import annotations

from pathlib import Path

import pytest
from policy_edits import edited, refused

import neurohover as nh
from neurohover.errors import NeurohoverError

PROTO = nh.prototype("slp", "baseline")


def _saved(where: Path, **meta: object) -> Path:
    out = where / "p.json"
    nh.save_policy(PROTO, out, **meta)
    return out


def _refused_both_ways(tmp_path: Path, good: dict, bad: dict, *words: str) -> None:
    """save_policy refuses ``bad`` (``good`` with its changes) naming ``words``, and load_policy a file edited to it."""
    with pytest.raises(NeurohoverError) as err:
        nh.save_policy(PROTO, tmp_path / "bad.json", **{**good, **bad})
    for word in words:
        assert word in str(err.value), err.value
    refused(edited(_saved(tmp_path, **good), tmp_path / "edited.json", **bad), *words)


# --------------------------------------------------------------------------- T53-B01: mdp beside a task, no target


@pytest.mark.parametrize(
    ("task", "mdp", "said"),
    [
        ("ghh08", "train:99", "MDP index 99 in 'train:99' is out of range: allowed 0..9"),
        ("ghh08", "test:100", "allowed 0..99"),
        ("ghh08", "banana", "unknown MDP 'banana'"),
        ("ghh08", "TRAIN:0", "unknown MDP 'TRAIN:0'"),
        ("ghh08", "", "unknown MDP ''"),
        ("ghh09", "train:99", "allowed 0..9"),
        ("fghh", "seeded-test:100", "allowed 0..99"),
    ],
)
def test_t53_b01_an_mdp_its_task_has_not_is_refused(tmp_path: Path, task: str, mdp: str, said: str) -> None:
    _refused_both_ways(tmp_path, {"task": task, "mdp": "G"}, {"mdp": mdp}, f"its mdp {mdp!r} is not allowed beside its task {task!r}", said)


@pytest.mark.parametrize(
    "mdp", ["G", "sample", "zero", "train:0", "train:9", "test:10", "test:99", "seeded-train:3", "seeded-test:5", "wind=1,2", "params=1,2"]
)
def test_t53_b01_every_mdp_evolve_writes_beside_a_task_loads(tmp_path: Path, mdp: str) -> None:
    # test:10 is no bug: ghh08 has 100 test MDPs (test:0..99), as get_task_family('ghh08').mdp('test:10') says
    assert nh.load_policy(_saved(tmp_path, task="ghh08", mdp=mdp)).metadata["mdp"] == mdp


@pytest.mark.parametrize(
    "argv",
    [
        ["--task", "fghh", "--sigma", "0.123456789"],
        ["--task", "fghh", "--sigma", "0.2", "--mdp", "train:3"],
        ["--task", "ghh08", "--mdp", "sample"],
        ["--task", "ghh08", "--wind", "1,2"],
        ["--task", "ghh09", "--mdp", "test:42"],
    ],
)
def test_t53_evolve_s_records_still_load(tmp_path: Path, argv: list[str]) -> None:
    from neurohover.cli import main

    out = tmp_path / "p.json"
    common = ["--topology", "slp", "--seed-policy", "baseline", "--budget", "4", "--episode-steps", "10", "--validation-episodes", "1"]
    assert main(["evolve", *argv, *common, "--seed", "1", "--out", str(out)]) == 0
    meta = nh.load_policy(out).metadata
    if "--sigma" in argv and "--mdp" not in argv:
        assert meta["target"] == "fghh/G(sigma=0.123457)" and meta["mdp"] == "G", meta


# --------------------------------------------------------------------------- T53-B02: a GHH target with a sigma


@pytest.mark.parametrize(("good", "bad"), [({"task": "ghh08", "target": "ghh08/G", "mdp": "G"}, {"target": "ghh08/G(sigma=0.3)"}),
                                          ({"target": "ghh09/G"}, {"target": "ghh09/G(sigma=0.3)"})])  # fmt: skip
def test_t53_b02_a_ghh_family_target_with_a_sigma_is_refused(tmp_path: Path, good: dict, bad: dict) -> None:
    named = bad["target"].partition("/")[0]
    _refused_both_ways(tmp_path, good, bad, f"its target {bad['target']!r} is not allowed: {named}'s MDPs have no breadth (sigma is FGHH's)")


# --------------------------------------------------------------------------- T53-B03: an FGHH target's sigma


@pytest.mark.parametrize(
    ("sigma", "said"),
    [
        ("5", "FGHH sigma=5 is out of range: allowed 0 <= sigma <= 1"),
        ("-1", "FGHH sigma=-1 is out of range"),
        ("nan", "FGHH sigma=nan is out of range"),
        ("inf", "FGHH sigma=inf is out of range"),
        ("1e-300", "too small to change the dynamics"),
        ("abc", "FGHH sigma='abc' is not allowed: give a number"),
        ("", "FGHH sigma='' is not allowed: give a number"),
        ("0.30", "its sigma '0.30' is not written as a run writes it; allowed fghh/G(sigma=0.3)"),
    ],
)
def test_t53_b03_an_fghh_target_s_sigma_is_checked_as_the_sigma_key(tmp_path: Path, sigma: str, said: str) -> None:
    target = f"fghh/G(sigma={sigma})"
    _refused_both_ways(tmp_path, {"task": "fghh", "target": "fghh/G(sigma=0.3)", "mdp": "G"}, {"target": target}, f"its target {target!r} is not allowed", said)


def test_t53_b03_an_fghh_target_s_sigma_agrees_with_the_sigma_key(tmp_path: Path) -> None:
    good = {"task": "fghh", "target": "fghh/G(sigma=0.3)", "mdp": "G", "sigma": 0.3}
    _refused_both_ways(tmp_path, good, {"sigma": 0.2}, "its sigma 0.2 is not allowed beside its target 'fghh/G(sigma=0.3)'")
    _refused_both_ways(tmp_path, good, {"sigma": 5}, "its sigma 5 is not allowed: FGHH sigma=5 is out of range")


@pytest.mark.parametrize("sigma", [0, 1, 0.2, 0.3, 1e-05, 0.123456789, 2.220446049250313e-16])
def test_t53_b03_every_sigma_a_run_writes_reads_back(tmp_path: Path, sigma: float) -> None:
    target = f"fghh/G(sigma={sigma:g})"  # as Run.result writes it
    meta = nh.load_policy(_saved(tmp_path, task="fghh", target=target, mdp="G", sigma=sigma)).metadata
    assert meta["target"] == target
