"""The twenty-first bad-input trial's findings in results stores: every command refuses a stored unit whose params were
changed, as reproduce did (T21-02). And a budget refused says that 0 is no cap (T21-14). Units stored at a scale of no
config row (orphans) are named as damage, not ignored (T21-15)."""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import CliRun, tiny_test_runs
from store_edits import damaged, dump, error

from neurohover.errors import NeurohoverError
from neurohover.experiments import Store
from neurohover.experiments.export import checked_units

RUN = "run/baseline/test0/rep0"


@pytest.fixture(scope="module")
def tiny(tmp_path_factory) -> tuple[Path, Path]:
    """A config of two agents (tr1: baseline and generic, one 20-step run of 2 episodes each) and a store holding its
    two finished test runs; tests damage copies of the store."""
    from neurohover.cli import main

    where = tmp_path_factory.mktemp("tiny21")
    config = where / "tr1.toml"
    config.write_text(tiny_test_runs("baseline", "generic"))
    assert main(["reproduce", str(config), "--store", str(where / "s.sqlite"), "--no-progress"]) == 0
    return config, where / "s.sqlite"


@pytest.mark.slow
@pytest.mark.parametrize(
    ("edit", "says"),
    [
        ("'$.seed', 12345", "unit.params.seed: the stored 12345, planned "),
        ("'$.episodes', 3", "unit.params.episodes: the stored 3, planned 2"),
    ],
)
def test_every_command_refuses_a_unit_whose_params_were_changed(tiny, tmp_path: Path, cli: CliRun, edit: str, says: str) -> None:
    """T21-02: a finished unit whose stored seed or episode count was edited (its key kept) was refused by reproduce but
    exported by results and reported by report; now the shared check refuses it everywhere, in one message naming the
    store, the experiment, the unit and the setting changed."""
    config, good = tiny
    store = damaged(good, tmp_path / "s.sqlite", f"UPDATE units SET params = json_set(params, {edit}) WHERE key = '{RUN}'")
    before = dump(store)
    message = f"results store {str(store)!r}, experiment tr1 (quick), is damaged: unit '{RUN}' holds other settings than its config plans for it ("
    rc, out, err = cli("results", "tr1", "--store", str(store))
    assert rc == 2 and out == "" and message in err and says in err, err
    line = error(err, "results")
    for argv, command in (
        (("results", "tr1", "--store", str(store), "--format", "json"), "results"),
        (("wins", "tr1", "--store", str(store), "--runs", "1", "--draws", "10"), "wins"),
        (("reproduce", str(config), "--store", str(store), "--no-progress"), "reproduce"),
    ):
        rc, out, err = cli(*argv)
        assert rc == 2 and error(err, command) == line, (argv, err)
    rc, out, err = cli("report", "--store", str(store), "--out", str(tmp_path / "r"))
    assert rc == 2 and f"is not reported: {line}" in err and not (tmp_path / "r").exists(), err
    with Store(store, create=False) as held, pytest.raises(NeurohoverError) as caught:
        checked_units(held, "tr1", "quick")
    assert str(caught.value) == line
    assert dump(store) == before


#: A copy of RUN's row under another name or scale ({name}, {scale}: SQL, a column's name keeps it).
COPY = f"INSERT INTO units SELECT {{name}}, {{scale}}, key, kind, config_hash, params, result, seconds, worker, finished FROM units WHERE key = '{RUN}'"


def test_every_command_names_units_at_a_scale_of_no_config_as_damage(tiny, tmp_path: Path, cli: CliRun) -> None:
    """T21-15: a quick unit copied to scale 'paper', where the store holds no config of tr1, was ignored: results and
    report exported the quick experiment, reproduce ran it (rc 0); now each calls the store damaged, naming the rows."""
    config, good = tiny
    store = damaged(good, tmp_path / "s.sqlite", COPY.format(name="name", scale="'paper'"))
    before = dump(store)
    says = (
        f"results store {str(store)!r}, experiment tr1 (paper), is damaged: it holds 1 finished unit(s) of it but no record of its config, "
        f"so they cannot be checked (the first: unit '{RUN}')"
    )
    for argv, command in (
        (("results", "tr1", "--store", str(store)), "results"),
        (("results", "tr1", "--store", str(store), "--scale", "paper"), "results"),
        (("wins", "tr1", "--store", str(store), "--runs", "1", "--draws", "10"), "wins"),
        (("reproduce", str(config), "--store", str(store), "--no-progress"), "reproduce"),
    ):
        rc, out, err = cli(*argv)
        assert rc == 2 and out == "" and error(err, command).startswith(says), (argv, err)
    rc, out, err = cli("report", "--store", str(store), "--out", str(tmp_path / "r"))
    assert rc == 2 and f"tr1 (quick) is not reported: {says}" in err and not (tmp_path / "r").exists(), err
    assert dump(store) == before


@pytest.mark.slow
def test_report_warns_of_units_of_an_experiment_it_holds_no_config_of(tiny, tmp_path: Path, cli: CliRun) -> None:
    """T21-15: units of an experiment 'ghost' with no config row at all were left out of the report without a word;
    now one warning line names them (the report of the sound experiments written), and asked for alone they are refused."""
    store = damaged(tiny[1], tmp_path / "s.sqlite", COPY.format(name="'ghost'", scale="scale"))
    says = f"ghost (quick) is not reported: results store {str(store)!r}, experiment ghost (quick), is damaged: it holds 1 finished unit(s) of it"
    rc, out, err = cli("report", "--store", str(store), "--out", str(tmp_path / "r"))
    assert rc == 0 and "report written" in out and f"neurohover report: warning: {says}" in err, err
    rc, out, err = cli("report", "ghost", "--store", str(store), "--out", str(tmp_path / "r2"))
    assert rc == 2 and "experiment ghost (quick), is damaged: it holds 1 finished unit(s)" in err and not (tmp_path / "r2").exists(), err
    rc, out, err = cli("results", "ghost", "--store", str(store))
    assert rc == 2 and "experiment ghost (quick), is damaged: it holds 1 finished unit(s)" in err, err
    rc, out, err = cli("results", "tr1", "--store", str(store))  # another experiment's orphans are not this one's damage
    assert rc == 0 and RUN in out, err


@pytest.mark.parametrize(
    ("name", "setting", "says"),
    [
        ("fig2", "budget=-1", "budget = -1 is not allowed: expected an integer in 0..10000000000 (0: no cap, each evolution run stops by"),
        ("table4", "ec_meno_budget=-1", "ec_meno_budget = -1 is not allowed: expected an integer in 0..10000000000 (0: no cap, EC-MENO stops at its plateau)"),
    ],
)
def test_a_refused_budget_says_that_0_is_no_cap(tmp_path: Path, cli: CliRun, name: str, setting: str, says: str) -> None:
    """T21-14: --set budget=-1 (meant as "unlimited") was refused as "expected an integer in 0..10000000000", not told
    that 0 is the way to ask for no cap; a budget that 0 is not allowed for (model_budget) says nothing of it."""
    rc, out, err = cli("reproduce", name, "--set", setting, "--store", str(tmp_path / "s.sqlite"), "--no-progress")
    assert rc == 2 and out == "" and says in err and "Traceback" not in err, err
    rc, _, err = cli("reproduce", "table4", "--set", "model_budget=0", "--store", str(tmp_path / "s.sqlite"), "--no-progress")
    assert rc == 2 and "model_budget = 0 is not allowed: expected an integer in 1..10000000000" in err and "no cap" not in err, err
    assert not (tmp_path / "s.sqlite").exists()


@pytest.mark.paper
def test_the_committed_store_passes_the_shared_check(committed_store: Path) -> None:
    """T21-02: every experiment of the committed paper-scale store (written by earlier versions) passes the shared
    check with its plan check (about half a minute: the paper suite)."""
    with Store(committed_store, create=False) as store:
        for name, scale, _, _ in store.experiments():
            checked_units(store, name, scale)
