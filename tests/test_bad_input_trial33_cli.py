"""Bad-input trial 33 (the command line): a config file named .TOML (T33-A01), and a path to a config of another
suffix taken for an experiment name (T33-A02)."""

from __future__ import annotations

from pathlib import Path

from conftest import tiny_test_runs

from neurohover.experiments import Store


def test_a_config_file_named_in_upper_case_is_read(cli, tmp_path: Path) -> None:
    config = tmp_path / "mine.TOML"
    config.write_text(tiny_test_runs("baseline", name="mine"))
    rc, out, err = cli("reproduce", str(config), "--store", str(tmp_path / "s.sqlite"), "--no-progress")
    assert rc == 0, err
    with Store(tmp_path / "s.sqlite") as store:
        assert [e[0] for e in store.experiments()] == ["mine"]


def test_a_path_to_a_config_of_another_suffix_is_named_as_a_file_not_an_unknown_experiment(cli, tmp_path: Path, monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)
    Path("noext").write_text(tiny_test_runs("baseline", name="mine"))
    for given in ("noext", "./noext", str(tmp_path / "noext"), "sub/none"):
        rc, _, err = cli("reproduce", given, "--store", "s.sqlite")
        why = f"config file {given!r} is not allowed: a config file's name ends .toml; give a path ending .toml, or an experiment name"
        assert rc == 2 and why in err and "Traceback" not in err, err
    rc, _, err = cli("reproduce", "nothing", "--store", "s.sqlite")  # no file, no slash: a name, as before
    assert rc == 2 and "unknown experiment 'nothing': known experiments are fig2" in err, err
    assert not Path("s.sqlite").exists()
