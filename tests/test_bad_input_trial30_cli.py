"""Bad-input trial 30 (command line): T30-A02 (compete whose runs all failed), T30-A04 (an output name that is a symlink),
T30-A05 (--policy-dir naming a set's own directory), T30-A06 (~ in a config's path settings)."""

from __future__ import annotations

from pathlib import Path

import pytest

from neurohover.errors import NeurohoverError


def _shipped_set_in(parent: Path) -> Path:
    """A copy of the shipped GHH-08 policy set in ``parent``/ghh08 (building one takes many seconds); ``parent``."""
    import shutil

    from neurohover.policysets import policy_dir

    shutil.copytree(policy_dir("ghh08", None), parent / "ghh08")
    return parent


def _failing_units(monkeypatch, fail) -> None:
    from neurohover.experiments import executors

    real = executors.run_unit

    def run_unit(unit, threads=None, device="cpu"):
        if fail(unit["key"]):
            raise RuntimeWarning("overflow encountered in scalar multiply")
        return real(unit, threads, device)

    monkeypatch.setattr(executors, "run_unit", run_unit)


def test_compete_whose_runs_all_failed_says_so_as_reproduce_does_and_summarises_nothing(tmp_path: Path, monkeypatch, cli) -> None:
    _failing_units(monkeypatch, lambda key: key.startswith("run/"))
    out = tmp_path / "g06"
    code, _, err = cli("compete", "--task", "ghh08", "--agent", "baseline", "--runs", "2", "--episodes", "2", "--episode-steps", "20", "--out", str(out))
    assert code == 2 and "Traceback" not in err and "Mean of empty slice" not in err
    assert "failed; ran 0 units" in err and "2 failed, first: run/baseline/test" in err and "RuntimeWarning: overflow" in err
    assert not (out / "episodes.csv").exists() and not (out / "summary.json").exists()  # no header-only episodes.csv


def test_compete_with_a_failed_run_writes_the_finished_ones_and_no_summary(tmp_path: Path, monkeypatch) -> None:
    from neurohover.compete import compete

    _failing_units(monkeypatch, lambda key: key.startswith("run/") and key.endswith("test1/rep0"))
    with pytest.raises(NeurohoverError, match=r"1 failed, first: run/baseline/test1/rep0: RuntimeWarning"):
        compete("ghh08", "baseline", runs=2, episodes=2, n_steps=20, out=tmp_path / "p")
    assert not (tmp_path / "p" / "summary.json").exists()
    assert len((tmp_path / "p" / "episodes.csv").read_text().splitlines()) == 3  # header and the finished run's 2 episodes


def test_summarise_refuses_no_runs_by_name() -> None:
    from neurohover.compete import summarise

    with pytest.raises(NeurohoverError, match="summarise needs at least one test run"):
        summarise([])


def test_results_out_refuses_a_link_to_a_file_of_another_suffix_and_writes_through_one_to_a_csv(tmp_path: Path, cli) -> None:
    """T30-A04: results --out lnk.csv, a link to a TOML config, replaced the config with CSV (the suffix was checked on the
    link's name only). A link to a CSV file is still written through (trial 29)."""
    from conftest import tiny_test_runs

    config, store = tmp_path / "tr1.toml", tmp_path / "tr1.sqlite"
    config.write_text(tiny_test_runs("baseline"))
    assert cli("reproduce", str(config), "--store", str(store), "--no-progress")[0] == 0
    (tmp_path / "cfg2.toml").write_text(config.read_text())
    (tmp_path / "lnk.csv").symlink_to(tmp_path / "cfg2.toml")
    rc, _, err = cli("results", "tr1", "--store", str(store), "--out", str(tmp_path / "lnk.csv"))
    assert rc == 2 and "is a symbolic link to" in err and "cfg2.toml" in err and "give a path ending .csv or .json" in err
    assert (tmp_path / "cfg2.toml").read_text() == config.read_text()
    (tmp_path / "old.csv").write_text("")
    (tmp_path / "ok.csv").symlink_to(tmp_path / "old.csv")
    assert cli("results", "tr1", "--store", str(store), "--out", str(tmp_path / "ok.csv"))[0] == 0
    assert (tmp_path / "old.csv").read_text().startswith("experiment,")


def test_policy_dir_naming_a_sets_own_directory_is_told_to_give_its_parent(tmp_path: Path, cli) -> None:
    """T30-A05: --policy-dir bq0/ghh08 was told to build a set with --out 'bq0/ghh08', which build-policies refuses."""
    from neurohover.policysets import load_policy_set

    _shipped_set_in(tmp_path / "bq0")
    own = tmp_path / "bq0" / "ghh08"
    with pytest.raises(NeurohoverError, match=rf"policy directory '{own}' is itself a ghh08 set: give its parent '{tmp_path / 'bq0'}'"):
        load_policy_set("ghh08", own)
    rc, _, err = cli("compete", "--task", "ghh08", "--agent", "model-free", "--runs", "1", "--episodes", "1", "--episode-steps", "5",
                     "--policy-dir", str(own), "--out", str(tmp_path / "p06"))  # fmt: skip
    assert rc == 2 and "is itself a ghh08 set: give its parent" in err and "build-policies" not in err
    assert load_policy_set("ghh08", tmp_path / "bq0").task == "ghh08"


def test_a_config_policies_path_expands_tilde_as_generics_from_does(tmp_path: Path, monkeypatch) -> None:
    """T30-A06: policies = "~/bq0" was refused as "no such directory" with ~/bq0 holding the set, while generics_from =
    "dir:~/..." expanded ~ (one config, two readings of ~)."""
    from conftest import tiny_test_runs

    from neurohover.experiments.config import load_config

    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    _shipped_set_in(tmp_path / "home" / "bq0")
    text = tiny_test_runs("model-free")
    (tmp_path / "tilde.toml").write_text(text.replace('policies = "shipped"', 'policies = "~/bq0"'))
    (tmp_path / "full.toml").write_text(text.replace('policies = "shipped"', f"policies = {str(tmp_path / 'home' / 'bq0')!r}"))
    tilde, full = load_config(str(tmp_path / "tilde.toml"), "quick"), load_config(str(tmp_path / "full.toml"), "quick")
    assert tilde.external_digest and tilde.external_digest == full.external_digest  # the same set, read through ~
    monkeypatch.setenv("HOME", str(tmp_path))  # ~/bq0 is now missing: refused, as before
    with pytest.raises(NeurohoverError, match=r"policies = '~/bq0' is not allowed: .*no such directory"):
        load_config(str(tmp_path / "tilde.toml"), "quick")


def test_reproduce_all_says_set_applies_to_every_experiment(tmp_path, cli) -> None:
    """Trial 30 (borderline): ``reproduce all --set episodes=2`` was refused as fig2's unknown setting, without saying that
    --set applies to every experiment of 'all'."""
    rc, out, err = cli("reproduce", "all", "--set", "episodes=2", "--store", str(tmp_path / "s.sqlite"))
    assert (rc, out) == (2, "") and "unknown setting(s) 'episodes'" in err, err
    assert err.rstrip().endswith("(--set applies to every experiment of 'all': give one NAME to set what only some have)"), err
    assert not (tmp_path / "s.sqlite").exists()


def test_a_cleanrl_path_is_checked_before_torch(tmp_path, cli) -> None:
    """Trial 30 (borderline): ``--cleanrl FILE`` said "needs torch" (where it is not installed): the path at fault was named
    only once torch was there."""
    (tmp_path / "m.zip").write_bytes(b"PK")
    rc, _, err = cli("evaluate-agent", "--task", "ghh08", "--cleanrl", str(tmp_path / "m.zip"))
    assert rc == 2 and "m.zip" in err and "torch" not in err, err
