"""Bad-input trial 54, side B (files and helpers): crash_aware took a positive reward as its absolute value (+5 squashed
as -5, +2000 charged as a crash; T54-B07): neurohover's rewards are at most 0, so a positive one is refused by name.
load_policy(Path("baseline")) was the built-in baseline, not the file at that path, and `fly --policy baseline` flew the
built-in beside a file 'baseline' without a word (T54-B09): a path is read as a file, and the command line says which
one it flies."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import neurohover as nh
from neurohover import NeurohoverError
from neurohover.wrappers import crash_aware


@pytest.mark.parametrize("reward", [5.0, 2000.0, 1e-300, np.array([-1.0, 0.5]), [[-2.0], [3.0]]])
def test_b07_a_positive_reward_is_refused_not_squashed_as_its_size(reward) -> None:
    with pytest.raises(NeurohoverError, match=r"is not allowed: give rewards <= 0, as neurohover's are"):
        crash_aware(reward)


def test_b07_rewards_at_most_zero_are_squashed_as_before() -> None:
    assert crash_aware(-0.0) == 0.0 and crash_aware(0) == 0.0 and crash_aware(-3) == pytest.approx(-np.log(4.0))
    assert crash_aware(np.array([-1.0, -5.0])) == pytest.approx(-np.log1p([1.0, 5.0]))


def test_b09_a_path_named_baseline_is_read_as_the_file(tmp_path: Path, monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)
    nh.save_policy(nh.prototype("mlp", "zero"), "p.json")
    Path("baseline").write_bytes(Path("p.json").read_bytes())
    assert nh.load_policy(Path("baseline")).topology == "mlp" and nh.load_policy("./baseline").topology == "mlp"
    assert nh.load_policy("baseline") == nh.baseline_policy()  # the text is the built-in's name (README)


@pytest.mark.parametrize(
    ("argv", "option", "name"),
    [
        (("fly", "--task", "ghh08", "--episodes", "1", "--policy", "baseline"), "--policy", "baseline"),
        (("evaluate-agent", "--task", "ghh08", "--policy", "baseline", "--n-mdps", "1", "--episode-steps", "20"), "--policy", "baseline"),
        (("evolve", "--task", "ghh08", "--seed-policy", "zero", "--budget", "1", "--episode-steps", "5", "--out", "e.json"), "--seed-policy", "zero"),
    ],
)
def test_b09_a_policy_name_beside_a_file_of_that_name_is_said(tmp_path: Path, monkeypatch, cli, argv, option: str, name: str) -> None:
    monkeypatch.chdir(tmp_path)
    rc, _, err = cli(*argv)
    assert rc == 0 and "note: " + option not in err, err  # no such file here: nothing to say
    Path("e.json").unlink(missing_ok=True)
    nh.save_policy(nh.prototype("mlp", "zero"), "p.json")
    Path("p.json").rename(name)
    rc, _, err = cli(*argv)
    said = f"neurohover: note: {option} {name} is the built-in {name} policy, not the file '{name}' here (give {option} ./{name} for the file)"
    assert rc == 0 and said in err, err
