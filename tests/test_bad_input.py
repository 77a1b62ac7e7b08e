"""Bad paths and option conflicts: one clear message, exit status 2, before any long computation."""

from __future__ import annotations

import contextlib
import json
import os
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest
from bad_input import CASES, run_case, setup

from neurohover import NeurohoverError, get_task_family
from neurohover.cli import main
from neurohover.flightdata import FlightData


@pytest.fixture(scope="module")
def workdir(tmp_path_factory) -> Path:
    return setup(tmp_path_factory.mktemp("bad-input"))


@pytest.mark.slow
@pytest.mark.parametrize("args, expected", CASES, ids=[" ".join(a[:1] + a[-2:]) for a, _ in CASES])
def test_each_case_is_refused_with_one_clear_line(args, expected, workdir: Path, capsys, monkeypatch) -> None:
    monkeypatch.chdir(workdir)
    before = sorted(p.name for p in workdir.iterdir())
    rc = main(list(args))  # an uncaught exception (a traceback) fails the test here
    err = capsys.readouterr().err
    assert rc == 2
    assert len(err.strip().splitlines()) == 1 and expected in err, err
    assert sorted(p.name for p in workdir.iterdir()) == before  # nothing written, no stray directories


@pytest.mark.slow
def test_the_script_runs_a_case_in_a_fresh_process(workdir: Path) -> None:
    # evolve with an unwritable --out and a budget of 1e9 episodes: refused before evolving (which would
    # take days: the timeout is only a net against that), with no progress line or compile note.
    proc = run_case(["evolve", "--task", "ghh08", "--budget", "1000000000", "--out", "adir"], workdir, timeout=600)
    assert proc.stdout == ""
    assert proc.returncode == 2 and "Traceback" not in proc.stderr
    assert proc.stderr.strip() == "neurohover evolve: error: --out 'adir' is a directory; give a file path"


def test_missing_parent_directories_are_created_and_announced(tmp_path: Path, capsys) -> None:
    target = tmp_path / "new" / "deeper" / "flight.npz"
    rc = main(["fly", "--task", "ghh08", "--episodes", "2", "--record", str(target), "--json"])
    out, err = capsys.readouterr()
    assert rc == 0 and target.is_file()
    assert f"created directory {str(tmp_path / 'new')!r} and 1 below it" in err
    assert json.loads(out)["flight_data"] == str(target)


def test_an_existing_output_file_survives_the_check(tmp_path: Path) -> None:
    from neurohover.paths import output_file

    path = tmp_path / "keep.txt"
    path.write_text("results\n")
    mtime = os.stat(path).st_mtime_ns
    assert output_file(path, "--out") == path
    assert path.read_text() == "results\n" and os.stat(path).st_mtime_ns == mtime
    output_file(tmp_path / "fresh.txt", "--out")
    assert not (tmp_path / "fresh.txt").exists()  # the probe leaves nothing behind


@pytest.mark.skipif(os.geteuid() == 0, reason="root may write anywhere; /proc covers unwritable places above")
def test_an_unwritable_directory_is_refused(tmp_path: Path, capsys) -> None:
    locked = tmp_path / "locked"
    locked.mkdir(mode=0o500)
    assert main(["fly", "--task", "ghh08", "--episodes", "1", "--record", str(locked / "x.npz")]) == 2
    assert "cannot create a file in" in capsys.readouterr().err


def test_recorded_flight_data_are_compressed(tmp_path: Path, capsys) -> None:
    path = tmp_path / "f.npz"
    assert main(["fly", "--task", "ghh08", "--episodes", "2", "--record", str(path), "--json"]) == 0
    with zipfile.ZipFile(path) as z:
        assert {i.compress_type for i in z.infolist()} == {zipfile.ZIP_DEFLATED}
        raw = sum(i.file_size for i in z.infolist())
    assert path.stat().st_size < raw  # float64 noise compresses little, but it does compress
    assert FlightData.load(path).n_transitions == 12000


def test_fly_progress_is_quiet_with_json_and_chunking_changes_no_result(tmp_path: Path, capsys, monkeypatch) -> None:
    from neurohover.cli import flying

    assert main(["fly", "--task", "ghh08", "--mdp", "train:1", "--episodes", "7", "--json"]) == 0
    whole = capsys.readouterr()
    assert whole.err == ""
    monkeypatch.setattr(flying, "FLY_CHUNK", 3)  # three kernel calls of 3, 3 and 1 episodes
    monkeypatch.setattr(sys.stderr, "isatty", lambda: True, raising=False)
    assert main(["fly", "--task", "ghh08", "--mdp", "train:1", "--episodes", "7"]) == 0
    chunked = capsys.readouterr()
    assert "7/7" in chunked.err  # the progress bar ran to the end
    mean = float(next(line for line in chunked.out.splitlines() if "mean_return" in line).split(":")[1])
    np.testing.assert_allclose(mean, json.loads(whole.out)["mean_return"], rtol=1e-6)
    # --json flies in chunks too: a Ctrl-C is heard between them (one call of every episode ignored it; third trial)
    evaluate_module = sys.modules["neurohover.evaluate"]  # the package's name `evaluate` is the function
    calls = []
    real = evaluate_module.evaluate_jobs
    monkeypatch.setattr(evaluate_module, "evaluate_jobs", lambda *a, **k: calls.append(1) or real(*a, **k))
    assert main(["fly", "--task", "ghh08", "--mdp", "train:1", "--episodes", "7", "--json"]) == 0
    assert len(calls) == 3 and json.loads(capsys.readouterr().out)["mean_return"] == json.loads(whole.out)["mean_return"]


def test_version_names_the_installed_package(capsys) -> None:
    from importlib.metadata import version

    with pytest.raises(SystemExit) as stop:
        main(["--version"])
    assert stop.value.code == 0
    assert capsys.readouterr().out.strip() == f"neurohover {version('neurohover')}"


def test_version_with_other_arguments_is_refused(capsys) -> None:
    with pytest.raises(SystemExit) as stop:
        main(["--version", "extra"])  # argparse printed the version and dropped 'extra' (second trial)
    assert stop.value.code == 2
    captured = capsys.readouterr()
    assert captured.out == "" and "--version takes no other arguments, got 'extra'" in captured.err


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["fly", "--task", "ghh08", "--bogus"], "unrecognized arguments: --bogus"),
        (["fly", "--episodes", "\u0661"], "argument '\u0661' holds digits of another script"),
    ],
)
def test_a_commands_parse_errors_name_the_command(capsys, args: list[str], message: str) -> None:
    with pytest.raises(SystemExit) as stop:
        main(args)  # said "neurohover: error:" without the command (third trial)
    assert stop.value.code == 2 and f"neurohover fly: error: {message}" in capsys.readouterr().err


def test_demo_refuses_zero_episodes_before_its_table(capsys) -> None:
    assert main(["demo", "--episodes", "0"]) == 2
    assert capsys.readouterr().out == ""  # the header was printed before the refusal (second trial)


@pytest.mark.slow
def test_the_script_prints_one_line_per_case() -> None:
    # One case in a fresh process (the script runs all of them by hand; each case runs in-process above).
    script = str(Path(__file__).with_name("bad_input.py"))
    proc = subprocess.run([sys.executable, script, "--every", str(len(CASES))], capture_output=True, text=True, timeout=900)
    lines = proc.stdout.strip().splitlines()
    assert proc.returncode == 0, proc.stdout + proc.stderr
    n = len(CASES[:: len(CASES)])
    assert len(lines) == n + 1 and all(line.startswith("ok ") for line in lines[:-1])
    assert lines[-1] == f"{n} of {n} cases refused cleanly"


@pytest.mark.skipif(not Path("/dev/full").exists(), reason="no /dev/full on this system")
@pytest.mark.parametrize(
    "args",
    [
        ["fly", "--task", "ghh08", "--episodes", "1", "--record", "/dev/full"],
        ["learn-model", "--flight-data", "fd.npz", "--method", "lr", "--out", "/dev/full"],
    ],
)
def test_a_device_is_refused_as_an_output_file(args, workdir: Path, capsys, monkeypatch) -> None:
    """issue 37: writing to /dev/full was an OSError traceback, to /dev/null a struct.error, and a checkpoint written by
    replacing its file turned the device node into a regular file (second trial). A full disk: the RLIMIT test below."""
    monkeypatch.chdir(workdir)
    assert main(list(args)) == 2
    err = capsys.readouterr().err
    assert err.strip().splitlines()[-1].endswith("'/dev/full' is not a regular file (a device, pipe or socket); give a file path"), err
    assert Path("/dev/full").is_char_device()


def test_an_evolution_checkpoint_is_never_written_over_a_device_or_an_empty_path(tmp_path: Path) -> None:
    from neurohover.evolution.evolve import evolve

    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    zero = get_task_family("ghh08").zero()
    for bad, message in ((fifo, "is not a regular file"), ("", "checkpoint is empty; give a file path"), (tmp_path, "is a directory")):
        with pytest.raises(NeurohoverError, match=message):
            evolve(zero, budget=5, n_steps=10, checkpoint=bad)
    assert fifo.is_fifo()


@pytest.mark.slow
def test_a_write_cut_short_leaves_no_partial_file(tmp_path: Path) -> None:
    """A file-size limit (RLIMIT_FSIZE) makes the flight data's write fail halfway, as a full disk would."""
    script = (
        "import resource, signal, sys\n"
        "signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # the write then fails with EFBIG instead of killing the process\n"
        "resource.setrlimit(resource.RLIMIT_FSIZE, (20000, 20000))\n"
        "from neurohover.cli import main\n"
        "sys.exit(main(['fly', '--task', 'ghh08', '--episodes', '4', '--record', 'big.npz', '--json']))\n"
    )
    proc = subprocess.run([sys.executable, "-c", script], cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 2, proc.stderr[-2000:]
    assert "Traceback" not in proc.stderr and "'big.npz': cannot write it (File too large); no partial file is left" in proc.stderr
    assert not (tmp_path / "big.npz").exists()


@pytest.mark.parametrize(
    ("broken", "expected"), [("specialised_0.json", "is not valid JSON: Expecting value: line 2"), ("manifest.json", "cannot be read as JSON")]
)
def test_a_malformed_file_in_a_policy_directory_is_named(broken: str, expected: str, tmp_path: Path, capsys) -> None:
    """issue 37: a malformed manifest was a JSONDecodeError traceback; every file is named with its path."""
    import shutil

    from neurohover.policysets import policy_dir

    shutil.copytree(policy_dir("ghh08"), tmp_path / "pd" / "ghh08")
    (tmp_path / "pd" / "ghh08" / broken).write_text('{"topology": "mlp", "genome": [1,\n')
    args = ["compete", "--task", "ghh08", "--agent", "model-free", "--runs", "1", "--episodes", "2"]
    assert main([*args, "--policy-dir", str(tmp_path / "pd"), "--out", str(tmp_path / "q")]) == 2
    err = capsys.readouterr().err
    assert f"'{tmp_path / 'pd' / 'ghh08' / broken}'" in err and expected in err, err


def test_a_file_given_as_a_policy_directory_is_named(tmp_path: Path) -> None:
    """Sixth trial: a file given as the policy directory was told "manifest.json missing; build it" inside the file."""
    from neurohover.policysets import load_policy_set

    (tmp_path / "base.json").write_text("{}")
    with pytest.raises(NeurohoverError, match="base.json' is not a directory: give the directory that holds ghh08/"):
        load_policy_set("ghh08", tmp_path / "base.json")


def test_another_tasks_policy_set_under_a_tasks_name_is_refused(tmp_path: Path) -> None:
    """A GHH-09 set copied in as ghh08/ was flown on GHH-08 without a word (second trial)."""
    import shutil

    from neurohover.policysets import load_policy_set, policy_dir

    shutil.copytree(policy_dir("ghh09"), tmp_path / "ghh08")
    with pytest.raises(NeurohoverError, match="manifest .* is of task 'ghh09', not 'ghh08'"):
        load_policy_set("ghh08", tmp_path)


@pytest.mark.parametrize(
    ("task", "key", "value"),
    [("ghh08", "safe", bad) for bad in ("x", [99, 100], [1.0], [6, 6])] + [("ghh08", "sigma", "x")] + [
        ("ghh08", "n_steps", "x"), ("ghh08", "seed", -1), ("ghh08", "budget", 1.5), ("ghh08", "lineage", 5), ("ghh08", "lineage", "other"),
        ("fghh", "seconds", float("nan")), ("fghh", "sigma", float("inf")), ("fghh", "fghh_budget", True), ("fghh", "built", 5),
    ],
)  # fmt: skip
def test_a_policy_set_manifest_with_bad_entries_is_refused(task: str, key: str, value, tmp_path: Path) -> None:
    """Fifth trial: a manifest's safe entry "x" or [99, 100] was a TypeError or IndexError when the hybrid agent was made;
    its descriptive fields (n_steps "x", a lineage 5) were taken and shown as given."""
    import shutil

    from neurohover.policysets import load_policy_set, policy_dir

    shutil.copytree(policy_dir(task), tmp_path / task)
    manifest = json.loads((tmp_path / task / "manifest.json").read_text())
    (tmp_path / task / "manifest.json").write_text(json.dumps({**manifest, key: value}))
    with pytest.raises(NeurohoverError, match=f"manifest .*: {key}=.* is not allowed"):
        load_policy_set(task, tmp_path)


def test_a_repeated_sensor_key_and_a_damaged_store_are_one_clear_line(tmp_path: Path, capsys) -> None:
    """issue 37: a repeated --obs-noise (or key) kept the last silently; a store damaged mid-file was a sqlite3 traceback."""
    assert main(["fly", "--task", "ghh08", "--episodes", "1", "--obs-noise", "velocity=0.1", "--obs-noise", "velocity=0.2"]) == 2
    assert "--obs-noise is given 2 times" in capsys.readouterr().err
    assert main(["fly", "--task", "ghh08", "--episodes", "1", "--obs-noise", "velocity=0.1,velocity=0.2"]) == 2
    assert "sensor setting 'velocity' is given twice" in capsys.readouterr().err
    from neurohover.experiments import LocalExecutor, Store, load_config, reproduce

    good = tmp_path / "s.sqlite"
    with Store(good) as store:
        reproduce(load_config("fig2", "quick", {"runs": 1, "budget": 40, "n_steps": 20}), store, LocalExecutor(1), progress=False)
    data = good.read_bytes()
    damaged = tmp_path / "d.sqlite"
    damaged.write_bytes(data[: len(data) // 2] + b"\x00garbage" * 512 + data[len(data) // 2 + 4096 :])
    rc = main(["report", "--store", str(damaged), "--out", str(tmp_path / "r")])  # its only experiment damaged: nothing to report (T19-07)
    err = capsys.readouterr().err
    assert rc == 2 and "nothing could be reported" in err and f"results store {str(damaged)!r} is damaged" in err
    for argv in (["results", "fig2"], ["wins", "fig2"]):
        rc = main([*argv, "--store", str(damaged)])
        err = capsys.readouterr().err
        assert rc == 2 and "Traceback" not in err and "cannot be read" in err and str(damaged) in err and len(err) < 400, err


@pytest.mark.slow
def test_a_damaged_row_is_named_and_the_rest_of_the_store_reported(tmp_path: Path, capsys) -> None:
    """issue 37: a unit or config whose stored JSON is damaged was a JSONDecodeError traceback; now the command
    names the row, and the report reports every other experiment, the damaged one in its place."""
    import sqlite3

    from neurohover.experiments import LocalExecutor, Store, load_config, reproduce, write_report

    path = tmp_path / "s.sqlite"
    with Store(path) as store:
        for name in ("fig2", "ablation-plateau"):
            cfg = load_config(name, "quick", {"runs": 1, "budget": 40, "n_steps": 20})
            reproduce(cfg, store, LocalExecutor(1), progress=False)
    with sqlite3.connect(path) as conn:
        conn.execute("UPDATE units SET result = '{cut' WHERE name = 'fig2' AND key = (SELECT min(key) FROM units WHERE name = 'fig2')")
    assert main(["results", "fig2", "--store", str(path), "--scale", "quick"]) == 2
    err = capsys.readouterr().err
    assert "experiment fig2 (quick), unit" in err and "is damaged (not JSON" in err and "Traceback" not in err
    with Store(path, create=False) as store:
        report = write_report(store, tmp_path / "rep").read_text()
        # Fifth trial: reproduce counted the damaged unit as finished ("9/9 done", exit 0) and never ran it again.
        cfg = load_config("fig2", "quick", {"runs": 1, "budget": 40, "n_steps": 20})
        with pytest.raises(NeurohoverError, match="experiment fig2 \\(quick\\), unit .*'s result is damaged \\(not JSON"):
            reproduce(cfg, store, LocalExecutor(1), progress=False)
    assert "Not reported: the store's copy is damaged." in report and "## Ablation" in report
    with sqlite3.connect(path) as conn:
        conn.execute("UPDATE units SET result = '[1, 2]' WHERE name = 'fig2'")
    with (
        Store(path, create=False) as store,
        pytest.raises(NeurohoverError, match="experiment fig2 \\(quick\\), unit .*'s result is damaged \\(a JSON list, not an object\\)"),
    ):
        reproduce(cfg, store, LocalExecutor(1), progress=False)


def test_evaluate_agent_refuses_to_write_its_rows_onto_the_policy_it_flies(tmp_path: Path, capsys) -> None:
    """issue 37, fourth trial: evaluate-agent --json onto its own --policy file overwrote the policy with the rows."""
    from neurohover.policies import baseline_policy, save_policy

    policy = save_policy(baseline_policy(), tmp_path / "p.json")
    before = policy.read_bytes()
    rc = main(["evaluate-agent", "--task", "ghh08", "--policy", str(policy), "--n-mdps", "1", "--episode-steps", "20", "--json", str(policy)])
    assert rc == 2 and "is the file of --policy" in capsys.readouterr().err and policy.read_bytes() == before


@pytest.mark.parametrize(
    "command", [["compete", "--agent", "baseline", "--runs", "1", "--episodes", "2"], ["evolve", "--mdp", "train:0", "--budget", "20"], ["build-policies"]]
)
def test_episode_steps_out_of_range_are_named_by_their_option(command: list[str], tmp_path: Path, capsys) -> None:
    """issue 37, fourth trial: compete said "experiment 'compete-ghh08-baseline': n_steps = 0", evolve and build-policies
    "n_steps=..." for --episode-steps."""
    out = ["--out", str(tmp_path / ("o.json" if command[0] == "evolve" else "o"))]
    for steps in ("0", "10000001"):
        assert main([command[0], "--task", "ghh08", *command[1:], "--episode-steps", steps, *out]) == 2
        assert f"--episode-steps {steps} is out of range: allowed an integer in 1..10,000,000" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


def test_the_fourth_trials_ignored_options_are_refused(tmp_path: Path, capsys) -> None:
    """issue 37, fourth trial: options accepted and then ignored or overridden without a word."""
    from neurohover.agents.risk import RiskSettings

    cases = [
        (["reproduce", "fig7", "--progress", "--no-progress", "--store", str(tmp_path / "s.sqlite")], "--progress and --no-progress are both given"),
        (["reproduce", "--list", "fig7"], "--list lists every experiment and takes no NAME (got 'fig7')"),
        (["fly", "--task", "fghh", "--episodes", "1", "--params=-0.18,-0.43,-0.54,-0.49,-42.15,-12.78,33.04,-10.12,-33.32,-10.5,1", "--sigma", "0.2"],
         "--sigma is the breadth of the MDPs drawn from FGHH's distribution; --params sets the MDP itself"),
        (["plot", "--compete", str(tmp_path), str(tmp_path / "." / ""), "--out", str(tmp_path / "p")], "--compete names"),
    ]  # fmt: skip
    for argv, message in cases:
        with pytest.raises(SystemExit) if argv[0] == "reproduce" and "--progress" in argv else contextlib.nullcontext():
            rc = main(argv)
            assert rc == 2
        assert message in capsys.readouterr().err, argv
    with pytest.raises(NeurohoverError, match="risk trials=10000000000000 is out of range: allowed an integer in 1..1,000,000"):
        RiskSettings(trials=10**13)
    assert not (tmp_path / "p").exists() and not (tmp_path / "s.sqlite").exists()


def test_a_build_says_it_replaces_the_set_in_its_out_directory(tmp_path: Path, capsys) -> None:
    """issue 37, fourth trial: a build into --out replaced the 13-file set there without a word (only the shipped set's
    replacement was said)."""
    argv = ["build-policies", "--task", "ghh08", "--budget", "2", "--episode-steps", "10", "--out", str(tmp_path)]
    assert main(argv) == 0 and "is replaced" not in capsys.readouterr().err
    assert main(argv) == 0 and f"note: the set {tmp_path / 'ghh08'} is replaced once the build completes" in capsys.readouterr().err


def test_a_negative_value_is_named_by_its_option_not_taken_for_one(tmp_path: Path, capsys) -> None:
    """issue 37, fourth trial: `wins --runs -1,5` said only "argument --runs: expected one argument"."""
    from neurohover.experiments import Store

    Store(tmp_path / "s.sqlite").close()
    assert main(["wins", "fig7", "--store", str(tmp_path / "s.sqlite"), "--runs", "-1,5"]) == 2
    assert "--runs '-1,5' is not allowed: give whole numbers >= 1" in capsys.readouterr().err
    assert main(["fly", "--task", "ghh08", "--episodes", "-1"]) == 2
    assert "--episodes -1 is out of range" in capsys.readouterr().err


def test_a_stored_run_or_config_of_the_wrong_shape_is_named(tmp_path: Path) -> None:
    """Fifth trial: a stored test run's result that is a list or lacks its MDP, and a stored config without a title,
    were TypeError and KeyError tracebacks in `wins` and `report`."""
    from neurohover.experiments.config import ExperimentConfig, load_config
    from neurohover.experiments.wins import stored_runs

    key = "run/model-free/test0/rep0"
    run = {
        "agent": "model-free", "mdp": "ghh08/test:0", "score": -2, "returns": [-1, -1], "crash_episodes": [], "safeguard_episodes": [],
        "policy_changes": [[0, "specialised:0"]], "learning_episodes": 0, "mean_return_after_learning": -1, "timing": {"seconds": 1.0, "offline_seconds": 0.0},
    }  # fmt: skip
    assert stored_runs({key: run}) == {"model-free": {"ghh08/test:0": [-2.0]}}
    for bad in ([1, 2], {"score": -1.0}, {"mdp": "ghh08/test:0", "score": "x"}, {"mdp": "ghh08/test:0", "score": True}):
        with pytest.raises(NeurohoverError, match="the stored result of unit 'run/model-free/test0/rep0' is damaged"):
            stored_runs({key: bad})
    stored = load_config("fig7", "quick").to_dict()
    assert ExperimentConfig.from_dict(stored).hash == load_config("fig7", "quick").hash
    for bad, named in (({**stored, "title": 3}, "title"), ({k: v for k, v in stored.items() if k != "settings"}, "settings"), ([1], "the whole config")):
        with pytest.raises(NeurohoverError, match=f"a stored experiment config is damaged: {named}.* missing or of the wrong kind"):
            ExperimentConfig.from_dict(bad)  # type: ignore[arg-type]


def test_the_current_directory_as_a_path_and_an_empty_directory_option_are_named(tmp_path: Path, capsys, monkeypatch) -> None:
    """Fifth trial: a path of '.' was `max() arg is an empty sequence` in every path check; --policy-dir '' and plot
    --compete '' were taken for the current directory."""
    monkeypatch.chdir(tmp_path)
    for argv, message in (
        (["fly", "--task", "ghh08", "--policy", ".", "--episodes", "1"], "policy file '.' is a directory"),
        (["results", "fig7", "--store", "."], "--store '.' is a directory"),
        (["fly", "--task", "ghh08", "--episodes", "1", "--record", "./"], "--record './' is a directory"),
        (["compete", "--task", "ghh08", "--agent", "model-free", "--runs", "1", "--episodes", "1", "--policy-dir", "", "--out", "o"], "--policy-dir is empty"),
        (["plot", "--compete", ""], "--compete is empty; give a directory"),
    ):
        assert main(argv) == 2, argv
        err = capsys.readouterr().err
        assert message in err and "Traceback" not in err, (argv, err)
    with pytest.raises(SystemExit) as stop:  # argparse's own refusal
        main(["build-policies", "--task", "ghh08", "--budget", "1"])
    assert stop.value.code == 2 and "the following arguments are required: --out" in capsys.readouterr().err


def test_a_store_is_never_made_of_a_device_and_a_build_never_defaults_onto_the_shipped_set(tmp_path: Path) -> None:
    """Fifth trial: Store() on a character device took it for a new store and deleted the device node when SQLite
    could not write it; build-policies without --out overwrote the package's shipped policies, even at a budget of 1."""
    import inspect
    import os
    import stat

    from neurohover.experiments import Store
    from neurohover.policysets import build_policy_set

    device = tmp_path / "full"
    try:
        os.mknod(device, 0o666 | stat.S_IFCHR, os.makedev(1, 7))  # /dev/full's numbers
    except PermissionError:
        pytest.skip("making a device node needs root")
    for create in (True, False):
        with pytest.raises(NeurohoverError, match="is not a regular file \\(a device, pipe or socket\\)"):
            Store(device, create=create)
    assert stat.S_ISCHR(device.stat().st_mode) and sorted(p.name for p in tmp_path.iterdir()) == ["full"]
    assert inspect.signature(build_policy_set).parameters["out"].default is inspect.Parameter.empty


def test_the_command_line_leftovers_of_the_fifth_trial(tmp_path: Path, capsys) -> None:
    """Fifth trial: --obs-dtype beside a --policy file and a sensor correlation without noise were ignored, results --out
    onto another results store turned it into CSV, a directory given as a config was called missing, and wins named an
    option that was not given."""
    import shutil
    import sqlite3

    store = tmp_path / "s.sqlite"
    with sqlite3.connect(store) as conn:
        conn.execute("CREATE TABLE t (x)")
    victim = tmp_path / "victim.sqlite"
    shutil.copy(store, victim)
    (tmp_path / "dir.toml").mkdir()
    for argv, message in (
        (["evaluate-agent", "--task", "ghh08", "--n-mdps", "1", "--policy", "baseline", "--obs-dtype", "float64"], "--obs-dtype applies to an agent that"),
        (["fly", "--task", "ghh08", "--obs-noise=correlation=0.9", "--episodes", "1"], "sensor correlation=0.9 applies to noise"),
        (["results", "fig7", "--store", str(store), "--out", str(victim)], "is a results store (SQLite): give another path"),
        (["reproduce", str(tmp_path / "dir.toml"), "--store", str(tmp_path / "x.sqlite")], "dir.toml' is a directory; give a .toml config file"),
    ):
        assert main(argv) == 2, argv
        err = capsys.readouterr().err
        assert message in err and "Traceback" not in err, (argv, err)
    assert victim.read_bytes() == store.read_bytes()


def test_a_stored_row_that_is_no_json_object_is_named(tmp_path: Path, capsys) -> None:
    """Sixth trial: a result stored as a non-UTF-8 BLOB was a UnicodeDecodeError, a config stored as [] a TypeError."""
    import sqlite3

    from neurohover.experiments import LocalExecutor, Store, load_config, reproduce

    path = tmp_path / "s.sqlite"
    with Store(path) as store:
        reproduce(load_config("fig2", "quick", {"runs": 1, "budget": 40, "n_steps": 20}), store, LocalExecutor(1), progress=False)
    for sql, what in (
        # a BLOB is no text cell at all (T47-B03: named by table, row and column), text that is no JSON a damaged result
        ("UPDATE units SET result = X'80FF00' WHERE key = (SELECT min(key) FROM units)", "column result holds a BLOB (b'\\x80\\xff\\x00'), not the text"),
        ("UPDATE units SET result = 'x{' WHERE key = (SELECT min(key) FROM units)", "'s result is damaged (not JSON"),
        ("UPDATE experiments SET config = '[]'", "'s config is damaged (a JSON list, not an object)"),
    ):
        damaged = tmp_path / "d.sqlite"
        damaged.write_bytes(path.read_bytes())
        with sqlite3.connect(damaged) as conn:
            conn.execute(sql)
        assert main(["results", "fig2", "--store", str(damaged), "--scale", "quick", "--format", "json"]) == 2
        err = capsys.readouterr().err
        assert what in err and "Traceback" not in err, err


@pytest.mark.slow
def test_a_stored_value_of_the_wrong_kind_is_named_by_report_results_and_wins(tmp_path: Path, capsys) -> None:
    """Sixth trial: a stored test run's score "x" was a ValueError in report (leaving a lone figure), exported by results
    --format json with exit 0."""
    import sqlite3

    out = tmp_path / "c"
    assert main(["compete", "--task", "ghh08", "--agent", "baseline", "--runs", "1", "--episodes", "2", "--episode-steps", "20", "--out", str(out)]) == 0
    name = json.loads((out / "summary.json").read_text())["experiment"]
    capsys.readouterr()
    damaged = tmp_path / "d.sqlite"
    damaged.write_bytes((out / "results.sqlite").read_bytes())
    with sqlite3.connect(damaged) as conn:
        conn.execute("UPDATE units SET result = json_set(result, '$.score', 'x') WHERE key LIKE 'run/%'")
    assert main(["report", "--store", str(damaged), "--out", str(tmp_path / "rep")]) == 2  # nothing else to report (T19-07)
    assert "score = 'x' is not Num" in capsys.readouterr().err
    for argv in (["results", name, "--store", str(damaged), "--format", "json"], ["wins", name, "--store", str(damaged)]):
        assert main(argv) == 2, argv
        err = capsys.readouterr().err
        assert "run/baseline/test0/rep0" in err and "Traceback" not in err, err
    foreign = tmp_path / "f.sqlite"  # sixth trial: a unit of no planned group was entered as agent "bogus"
    foreign.write_bytes((out / "results.sqlite").read_bytes())
    with sqlite3.connect(foreign) as conn:
        conn.execute("INSERT INTO units SELECT name, scale, 'run/bogus/test0/rep0', kind, config_hash, params, result, seconds, worker, finished FROM units")
    assert main(["wins", name, "--store", str(foreign)]) == 2
    assert "it holds unit 'run/bogus/test0/rep0', which the config does not plan" in capsys.readouterr().err  # one check for every command (T21-02)


def test_sigma_beside_the_zero_setting_is_refused(capsys) -> None:
    """Sixth trial: fly or evolve --task fghh --mdp zero --sigma 0.5 was accepted; the zero setting is the same at every sigma."""
    for argv in (["fly", "--task", "fghh", "--mdp", "zero", "--sigma", "0.5"], ["fly", "--task", "fghh", "--sigma", "0.5"],
                 ["evolve", "--task", "fghh", "--mdp", "zero", "--sigma", "0.5", "--budget", "10", "--out", "e.json"]):  # fmt: skip
        assert main(argv) == 2
        assert "the zero setting is the same at every sigma" in capsys.readouterr().err
