"""Bad input, trial 27 (command line): T27-A01, ``evolve --resume`` with another seed policy printed both prototypes cut
at the same place ("[0.0, 0.0, ..." against "[0.0, 0.0, ..."), never the difference. Two long lists that differ are
now named by their first differing entry."""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import CliRun

from neurohover.errors import first_difference


def test_long_lists_are_named_by_their_first_differing_entry() -> None:
    assert first_difference("prototype", [0.0] * 30 + [1.0], [0.0] * 31, "the checkpoint's") == "prototype[30]: the checkpoint's 1.0, given 0.0"
    assert first_difference("x", [1, 2], [1, 3]) == "x: the stored [1, 2], given [1, 3]"  # short: shown whole, as before
    assert first_difference("x", [0.0] * 30, [0.0] * 31).startswith("x: the stored [0.0")  # of other lengths: as before


def test_resuming_from_another_seed_policy_names_the_gene_that_differs(tmp_path: Path, cli: CliRun, monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)
    short = ("--task", "ghh08", "--episode-steps", "20", "--validation-episodes", "1", "--out", "p.json")
    assert cli("evolve", *short, "--budget", "10")[0] == 0
    rc, out, err = cli("evolve", *short, "--budget", "20", "--seed-policy", "zero", "--resume")
    assert (rc, out) == (2, "")
    assert "was written by a different run (prototype[11]: the checkpoint's 0.02, given 0.0)" in err, err


def test_as_authors_takes_its_own_values_beside_it_and_names_a_contradiction(tmp_path: Path, cli: CliRun) -> None:
    """Trial 27 (borderline): ``learn-model --as-authors --d-u discard`` was refused though it agrees with the preset;
    a value that contradicts it is named."""
    base = ("learn-model", "--flight-data", str(tmp_path / "none.npz"), "--method", "lr", "--out", str(tmp_path / "m.json"), "--as-authors")
    rc, _, err = cli(*base, "--d-u", "keep", "--noise-estimate", "rms")
    assert rc == 2 and "--as-authors sets --d-u discard and --noise-estimate rms: --d-u keep contradicts it" in err, err
    rc, _, err = cli(*base, "--d-u", "discard", "--noise-estimate", "rms")  # agrees: it goes on to read the data
    assert rc == 2 and "--as-authors" not in err and "none.npz" in err, err
    assert not (tmp_path / "m.json").exists()


@pytest.mark.slow
def test_a_competition_with_other_settings_into_the_same_folder_says_it_replaces_its_files(tmp_path: Path, cli: CliRun) -> None:
    """Trial 27 (borderline): ``compete --out D`` again with only --seed changed replaced D's files without the note a
    competition of another agent gets."""
    base = ("compete", "--task", "ghh08", "--agent", "baseline", "--runs", "1", "--episodes", "2", "--episode-steps", "20", "--out", str(tmp_path / "d"))
    assert cli(*base)[0] == 0
    rc, _, err = cli(*base, "--seed", "5")
    assert rc == 0 and "held a competition of baseline on ghh08 with other settings ('settings-" in err and "; these are settings-" in err, err
    rc, _, err = cli(*base, "--seed", "5")  # the same again: nothing replaced but its own files
    assert rc == 0 and "note:" not in err, err
