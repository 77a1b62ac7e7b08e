"""Bad-input trial 55, side A (the command line): ``evolve --out``, ``learn-model --out`` and ``results --out`` replaced
a user's own file (notes in a .json, a .csv of theirs) without a word (T55-A02): refused now as flight data, report.md,
PNGs and checkpoints are, "a file neurohover did not write"; a policy, a model or a results export neurohover wrote is
still replaced (an export is told by its own CSV header or JSON keys, a large JSON export by how it begins). A flag or
switch given a value (``--json=yes``, ``--progress=false``) was argparse's "ignored explicit argument" (T55-A03): it
says now that the option takes no value. A stored test run whose ``agent`` was edited was blamed on its sound
``policy_changes`` (T55-A04): its agent is compared with its unit's params first, by ``results`` and ``Store.put``."""

from __future__ import annotations

import json
import shutil
import sqlite3
from pathlib import Path

import pytest
import store_edits as SE
from conftest import tiny_test_runs

import neurohover as nh
from neurohover import NeurohoverError, filekinds
from neurohover.experiments import Store, Unit
from neurohover.filekinds import held_kind

EVOLVE = ("evolve", "--task", "ghh08", "--budget", "5", "--episode-steps", "20", "--validation-episodes", "1")


@pytest.fixture(scope="module")
def made(tmp_path_factory) -> Path:
    """A folder holding tr1.toml, its store s.sqlite (baseline, one test MDP) and flight data r.npz."""
    from neurohover.cli import main

    where = tmp_path_factory.mktemp("t55a")
    (where / "tr1.toml").write_text(tiny_test_runs("baseline"))
    assert main(["reproduce", str(where / "tr1.toml"), "--store", str(where / "s.sqlite"), "--no-progress"]) == 0
    nh.evaluate(nh.baseline_policy(), nh.get_task_family("ghh08").zero(), n_steps=100, record=True).flight_data.save(where / "r.npz")
    return where


def _argv(command: str, made: Path, out: Path) -> tuple[str, ...]:
    if command == "evolve":
        return (*EVOLVE, "--out", str(out))
    if command == "learn-model":
        return ("learn-model", "--flight-data", str(made / "r.npz"), "--method", "lr", "--out", str(out))
    if command == "evaluate-agent":
        return ("evaluate-agent", "--task", "ghh08", "--policy", "baseline", "--n-mdps", "1", "--episode-steps", "20", "--json", str(out))
    return ("results", "tr1", "--store", str(made / "s.sqlite"), "--out", str(out))


# T55-A02 ------------------------------------------------------------------------------------------------------------


@pytest.mark.parametrize(("command", "name", "text", "kind"), [
    ("evolve", "notes.json", '{"name": "my-notes", "important": [1, 2, 3]}\n', "a policy file"),
    ("evolve", "notes.json", "hello\n", "a policy file"),
    ("learn-model", "u.json", '{"mine": true}\n', "a model file"),
    ("results", "u.csv", "my,own,data\n", "a results export (results --format csv)"),
    ("results", "u.json", '{"name": "my-notes"}\n', "a results export (results --format json)"),
    ("evaluate-agent", "mine.json", "my notes\n", "evaluate-agent rows (--json)"),  # T56-A01, fixed by T55-A02's rule
])  # fmt: skip
def test_a02_a_users_own_file_is_not_replaced(tmp_path: Path, cli, made: Path, monkeypatch, command: str, name: str, text: str, kind: str) -> None:
    monkeypatch.chdir(tmp_path)  # the path as given, short: shown whole
    out = Path(name)
    out.write_text(text)
    rc, _, err = cli(*_argv(command, made, out))
    option = "--json" if command == "evaluate-agent" else "--out"
    assert rc == 2 and f"{option} {name!r} is a file neurohover did not write: give another path (writing {kind} would destroy it)" in err, err
    assert out.read_text() == text
    assert sorted(p.name for p in tmp_path.iterdir()) == [name]  # nor an evolve run's files beside it


@pytest.mark.parametrize(("command", "name"), [("evolve", "p.json"), ("learn-model", "m.json"), ("results", "e.csv"), ("results", "e.json")])
def test_a02_a_file_neurohover_wrote_is_replaced_and_an_empty_one_taken(tmp_path: Path, cli, made: Path, command: str, name: str) -> None:
    out = tmp_path / name
    out.touch()
    for _ in range(2):
        rc, _, err = cli(*_argv(command, made, out))
        assert rc == 0, err
    assert held_kind(out) is not None and out.stat().st_size


def test_a02_a_large_json_export_is_told_apart_by_how_it_begins(tmp_path: Path, cli, made: Path, monkeypatch) -> None:
    out = tmp_path / "e.json"
    assert cli(*_argv("results", made, out))[0] == 0
    monkeypatch.setattr(filekinds, "_KIND_READ_LIMIT", 100)  # as past 64 MiB: not parsed whole
    assert held_kind(out) == "a results export (results --format json)"
    rc, _, err = cli(*_argv("results", made, out))
    assert rc == 0, err
    other = tmp_path / "o.json"
    other.write_text('{"experiment": "x", "notes": "' + "n" * 200 + '"}\n')
    assert held_kind(other) is None


def test_a02_save_policy_refuses_a_users_file_too(tmp_path: Path) -> None:
    out = tmp_path / "notes.json"
    out.write_text('{"mine": true}\n')
    with pytest.raises(NeurohoverError, match="is a file neurohover did not write: give another path"):
        nh.save_policy(nh.baseline_policy(), out)
    assert out.read_text() == '{"mine": true}\n'


# T55-A03 ------------------------------------------------------------------------------------------------------------


@pytest.mark.parametrize(("argv", "message"), [
    (("fly", "--task", "ghh08", "--episodes", "1", "--json=yes"), "--json takes no value, got 'yes': give --json alone, or leave it out"),
    (("evolve", "--task", "ghh08", "--out", "q.json", "--resume=no"), "--resume takes no value, got 'no': give --resume alone, or leave it out"),
    (("reproduce", "t.toml", "--progress=false"), "--progress/--no-progress takes no value, got 'false': give --progress or --no-progress"),
    (("reproduce", "t.toml", "--no-progress=1"), "--progress/--no-progress takes no value, got '1': give --progress or --no-progress"),
])  # fmt: skip
def test_a03_a_flag_given_a_value_says_it_takes_none(cli, capsys, argv: tuple[str, ...], message: str) -> None:
    with pytest.raises(SystemExit) as stop:  # argparse's own refusal, in this process
        cli(*argv)
    rc, err = stop.value.code, capsys.readouterr().err
    assert rc == 2 and f"neurohover {argv[0]}: error: {message} (usage: neurohover {argv[0]} --help)" in err, err
    assert "ignored" not in err


# T55-A04 ------------------------------------------------------------------------------------------------------------


def test_a04_a_test_runs_edited_agent_is_named(tmp_path: Path, cli, made: Path) -> None:
    path = tmp_path / "y.sqlite"
    shutil.copyfile(made / "s.sqlite", path)
    with sqlite3.connect(path) as conn:
        key, text = conn.execute("select key, result from units where kind = 'test_run'").fetchone()
        conn.execute("update units set result = ? where key = ?", (json.dumps({**json.loads(text), "agent": "generic"}), key))
    conn.close()
    rc, _, err = cli("results", "tr1", "--store", str(path))
    line = f"unit {key!r}: its result contradicts its params: agent = 'generic' is not allowed: its unit's params.agent is 'baseline'"
    assert rc == 2 and line in err, err
    assert "policy_changes" not in err


def test_a04_store_put_names_the_agent_too(made: Path, tmp_path: Path) -> None:
    path = tmp_path / "s.sqlite"
    shutil.copyfile(made / "s.sqlite", path)
    with Store(path) as store:
        name, scale, h, _ = store.experiments()[0]
        unit = store.units(name, scale)[0]
        good = store.results(name, scale)[unit["key"]]
        other = Unit(name, unit["key"] + "x", "test_run", unit["params"])
        with pytest.raises(NeurohoverError, match="put: agent = 'generic' is not allowed: its unit's params.agent is 'baseline'"):
            store.put(name, scale, h, other, {**good, "agent": "generic"}, 1.0)
    assert SE.dump(path) == SE.dump(made / "s.sqlite")
