"""The command line: JSON output, clear errors with exit status 2, and flight-data recording."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import neurohover as nh
from neurohover.cli import main
from neurohover.flightdata import FlightData
from neurohover.policies import prototype, save_policy


def test_fly_json_reports_the_issue_keys(cli) -> None:
    rc, out, _ = cli("fly", "--task", "ghh08", "--mdp", "zero", "--episodes", "3", "--seed", "4", "--json")
    assert rc == 0
    result = json.loads(out)
    for key in ("mean_return", "std_return", "crashes", "episodes", "episodes_per_second"):
        assert key in result
    assert result["episodes"] == 3 and result["crashes"] == 0
    assert -1300 < result["mean_return"] < -700
    assert result["min_return"] <= result["mean_return"] <= result["max_return"]


def test_fly_wind_and_params_set_the_mdp(cli, tmp_path: Path) -> None:
    _, calm, _ = cli("fly", "--task", "ghh08", "--wind", "0,0", "--episodes", "2", "--json")
    _, windy, _ = cli("fly", "--task", "ghh08", "--wind", "4,-4", "--episodes", "2", "--json")
    assert json.loads(windy)["mean_return"] < json.loads(calm)["mean_return"]
    rc, out, _ = cli("fly", "--task", "ghh09", "--params", "0.9,0.5,0.2,0.1,0.8,0.3,0.7,0.6", "--episodes", "2", "--json")
    assert rc == 0 and json.loads(out)["mean_return"] < json.loads(calm)["mean_return"]
    policy_file = save_policy(prototype("mlp", "baseline"), tmp_path / "mlp.json", note="test")
    _, mlp, _ = cli("fly", "--task", "ghh08", "--wind", "0,0", "--episodes", "2", "--json", "--policy", str(policy_file))
    assert json.loads(mlp)["mean_return"] == json.loads(calm)["mean_return"]


def test_fly_record_writes_flight_data(cli, tmp_path: Path) -> None:
    path = tmp_path / "flight.npz"
    rc, _, _ = cli("fly", "--task", "fghh", "--mdp", "train:1", "--episodes", "2", "--record", str(path))
    assert rc == 0
    fd = FlightData.load(path)
    assert fd.n_episodes == 2 and fd.n_transitions == 12000
    assert fd.metadata["task"] == "fghh" and len(fd.metadata["returns"]) == 2
    assert np.all(np.abs(fd.actions[0]) <= 1)


@pytest.mark.parametrize(
    "argv, message",
    [
        (["fly", "--task", "ghh10"], "unknown task 'ghh10': allowed ghh08, ghh09, fghh"),
        (["fly", "--task", "ghh08", "--wind", "6,0"], "must lie in [-5, 5]"),
        (["fly", "--task", "ghh09", "--wind", "1,0"], "--wind U,V sets a GHH-08 MDP"),
        (["fly", "--task", "ghh09", "--params", "0.5,0.5"], "must be 8 numbers"),
        (["fly", "--task", "ghh09", "--params", "0.5,0.5,0.5,0.5,0.5,0.5,0.5,1.5"], "y_center=1.5"),
        (["fly", "--task", "fghh", "--sigma", "-1"], "sigma=-1.0 is out of range"),
        (["fly", "--task", "ghh08", "--mdp", "train:10"], "allowed 0..9"),
        (["fly", "--task", "ghh08", "--mdp", "windy"], "unknown MDP 'windy'"),
        (["fly", "--task", "ghh08", "--episodes", "0"], "--episodes 0 is out of range"),
        (["fly", "--task", "ghh08", "--policy", "missing.json"], "no such policy file (JSON"),
    ],
)
def test_bad_input_exits_2_with_one_clear_message(cli, argv, message: str) -> None:
    rc, out, err = cli(*argv)
    assert rc == 2
    assert message in err
    assert "Traceback" not in err and err.count("\n") == 1


def test_malformed_policy_files_are_refused(cli, tmp_path: Path) -> None:
    cases = {
        "notjson.json": "{not json",
        "nogenome.json": json.dumps({"topology": "mlp"}),
        "short.json": json.dumps({"topology": "mlp", "genome": [0.0] * 40}),
        "strings.json": json.dumps({"topology": "slp", "genome": ["a"] * 40}),
    }
    expected = {
        "notjson.json": "not valid JSON",
        "nogenome.json": "missing key(s) genome",
        "short.json": "mlp genome has 42 genes",
        "strings.json": "list of numbers",
    }
    for name, text in cases.items():
        (tmp_path / name).write_text(text)
        rc, _, err = cli("fly", "--task", "ghh08", "--policy", str(tmp_path / name))
        assert rc == 2 and expected[name] in err, (name, err)


@pytest.mark.slow
def test_every_command_has_help(capsys) -> None:
    from neurohover.cli import build_parser

    commands = build_parser()._subparsers._group_actions[0].choices
    for name in commands:  # in this process: a fresh interpreter per command cost 1 s each
        with pytest.raises(SystemExit) as done:
            main([name, "--help"])
        out = capsys.readouterr().out
        assert done.value.code == 0 and out.startswith(f"usage: neurohover {name}"), name
    # and the entry point itself, once, as a user runs it
    out = subprocess.run([sys.executable, "-m", "neurohover", "evolve", "--help"], capture_output=True, text=True)
    assert out.returncode == 0 and "usage: neurohover evolve" in out.stdout


def test_a_failed_command_leaves_no_empty_output_directory(tmp_path: Path, capsys) -> None:
    from neurohover.cli import main
    from neurohover.experiments import Store

    Store(tmp_path / "empty.sqlite").close()
    out = tmp_path / "new" / "report"
    assert main(["report", "--store", str(tmp_path / "empty.sqlite"), "--out", str(out), "fig7"]) == 2
    err = capsys.readouterr().err
    assert "created directory" not in err and len(err.strip().splitlines()) == 1  # refused before --out is made (sixth trial)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["empty.sqlite"]
    # compete: refused after its --out check (an unknown MDP), so nothing was written there either
    assert main(["compete", "--task", "ghh08", "--agent", "model-free", "--runs", "1", "--episodes", "2", "--mdps", "nope", "--out", str(out)]) == 2
    assert sorted(p.name for p in tmp_path.iterdir()) == ["empty.sqlite"]
    # a directory that was there already stays, empty or not
    (tmp_path / "mine").mkdir()
    assert main(["report", "--store", str(tmp_path / "empty.sqlite"), "--out", str(tmp_path / "mine"), "fig7"]) == 2
    assert (tmp_path / "mine").is_dir()


def test_flight_data_can_be_recorded_in_float32_in_half_the_space(tmp_path: Path, capsys) -> None:
    from neurohover.cli import main
    from neurohover.flightdata import FlightData

    sizes = {}
    for dtype in ("float64", "float32"):
        path = tmp_path / f"{dtype}.npz"
        assert main(["fly", "--task", "ghh08", "--mdp", "train:3", "--episodes", "2", "--record", str(path), "--record-dtype", dtype, "--json"]) == 0
        sizes[dtype] = path.stat().st_size
    capsys.readouterr()
    exact, rounded = FlightData.load(tmp_path / "float64.npz"), FlightData.load(tmp_path / "float32.npz")
    assert sizes["float32"] < 0.6 * sizes["float64"]
    for a, b in zip(exact.observations + exact.actions, rounded.observations + rounded.actions):
        assert b.dtype == np.float64 and np.array_equal(b, a.astype(np.float32).astype(np.float64))
    assert rounded.metadata["returns"] == exact.metadata["returns"]
    with pytest.raises(nh.NeurohoverError, match="flight-data dtype 'float16' is not allowed: use float64 or float32"):
        exact.save(tmp_path / "x.npz", dtype="float16")


@pytest.mark.parametrize(
    "argv",
    [
        ["fly", "--task", "ghh08", "--seed", "1", "--seed", "2"],
        ["fly", "--task", "ghh08", "--mdp", "train:1", "--mdp", "train:2"],
        ["evaluate-agent", "--task", "ghh08", "--obs-delay", "2", "--obs-delay", "3", "--policy", "baseline"],
        ["fly", "--task", "ghh08", "--json", "--json"],  # a flag too (second trial)
    ],
)
def test_a_single_valued_option_given_twice_is_refused(cli, capsys, argv: list[str]) -> None:
    """argparse keeps the last of a repeated option without a word; every command refuses it instead (bad-input trial)."""
    with pytest.raises(SystemExit) as stop:
        cli(*argv)
    err = capsys.readouterr().err
    assert stop.value.code == 2 and "is given more than once: give it once" in err and "Traceback" not in err


@pytest.mark.parametrize(
    "argv",
    [
        ["fly", "--task", "ghh08", "--episodes", "\u0663"],  # Arabic-Indic 3: int() reads it as 3
        ["compete", "--task", "ghh08", "--agent", "baseline", "--runs", "\u0661", "--episodes", "2"],
        ["evolve", "--task", "ghh08", "--out", "x.json", "--checkpoint-every", "\u0661.5"],
        ["fly", "--task", "ghh08", "--wind", "\u0661,2"],  # inside a list, a KEY=VALUE setting or sensor text too (second trial)
        ["fly", "--task", "ghh08", "--obs-noise", "dropout=\u0660.5"],
        ["evolve", "--task", "ghh08", "--out", "x.json", "--resampling", "fixed:\u0661"],
    ],
)
def test_a_number_in_other_scripts_digits_is_refused(cli, capsys, argv: list[str]) -> None:
    """Python's int() and float() read any script's digits; the command line takes ASCII digits only (bad-input trial)."""
    with pytest.raises(SystemExit) as stop:
        cli(*argv)
    err = capsys.readouterr().err
    assert stop.value.code == 2 and "holds digits of another script: give numbers in ASCII digits" in err and "Traceback" not in err


def test_a_repeated_key_of_a_key_value_option_is_refused(cli, tmp_path: Path) -> None:
    rc, _, err = cli("evolve", "--task", "ghh08", "--out", "x.json", "--setting", "pop_size=30", "--setting", "pop_size=40")
    assert rc == 2 and "--setting pop_size=... is given more than once (pop_size=30 and pop_size=40)" in err
    rc, _, err = cli("evolve", "--task", "ghh08", "--out", "x.json", "--plateau-rule", "literal", "--setting", "plateau_rule=no-crash")
    assert rc == 2 and "repeats --plateau-rule" in err
    rc, _, err = cli("reproduce", "fig2", "--store", str(tmp_path / "s.sqlite"), "--set", "runs=2", "--set", "runs=3")
    assert rc == 2 and "--set runs=... is given more than once" in err and not (tmp_path / "s.sqlite").exists()


def test_a_refused_reproduce_leaves_no_store_it_made(cli, tmp_path: Path) -> None:
    store = tmp_path / "new.sqlite"
    rc, _, err = cli("reproduce", "fig2", "--store", str(store), "--only", "nomatch*")
    assert rc == 2 and "matches no unit" in err and not store.exists()


def test_a_config_of_ones_own_may_not_take_a_shipped_experiments_name(cli, tmp_path: Path) -> None:
    from neurohover.experiments.config import shipped_configs

    path = tmp_path / "mine.toml"
    path.write_text(shipped_configs()["fig2"].read_text())
    rc, _, err = cli("reproduce", str(path), "--store", str(tmp_path / "s.sqlite"))
    assert rc == 2 and "name = 'fig2' is a shipped experiment's" in err and not (tmp_path / "s.sqlite").exists()


def test_fly_refuses_empty_list_fields_and_a_record_dtype_without_a_record(cli) -> None:
    for wind in ("1,,1", ",1,1", "1,1,"):
        rc, _, err = cli("fly", "--task", "ghh08", "--episodes", "1", "--wind", wind)
        assert rc == 2 and "none left empty" in err
    rc, _, err = cli("fly", "--task", "ghh08", "--episodes", "1", "--record-dtype", "float32")
    assert rc == 2 and "--record-dtype float32 applies to the flight data --record FILE writes" in err


def test_compete_refuses_bad_options_before_it_makes_its_output_directory(cli, tmp_path: Path) -> None:
    out = tmp_path / "cq"
    for bad in (["--agent", "Baseline"], ["--agent", "baseline", "--drift", "walk=-1"], ["--agent", "continual", "--agent-setting", "cooldown=nan"]):
        rc, _, err = cli("compete", "--task", "ghh08", *bad, "--runs", "1", "--episodes", "2", "--out", str(out))
        assert rc == 2 and "created directory" not in err and not out.exists(), bad


@pytest.mark.slow
def test_the_command_line_loads_matplotlib_and_scipy_stats_only_where_it_draws_or_tests() -> None:
    """Every command imports the parser of every command: with matplotlib (plots) and scipy.stats (races, the report's
    tests) loaded at import, each started `neurohover` paid about a second before doing anything."""
    script = (
        "import sys\n"
        "from neurohover.cli.app import build_parser\n"
        "import neurohover.experiments, neurohover.evolution, neurohover.plots\n"
        "build_parser()\n"
        "print(sorted(m for m in sys.modules if m.split('.')[0] == 'matplotlib' or m.startswith('scipy.stats')))\n"
    )
    run = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, env={**os.environ, "MPLBACKEND": ""})
    assert run.returncode == 0 and run.stdout.strip() == "[]", run.stdout + run.stderr
