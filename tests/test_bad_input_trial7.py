"""Issue 37, the seventh fresh trial: each case it found gives one clear message (exit 2 / NeurohoverError), and none
writes outside its output or changes a store it refuses."""

from __future__ import annotations

import json
import sqlite3
from pathlib import Path

import numpy as np
import pytest

import neurohover as nh
from neurohover.errors import NeurohoverError

TINY = """name = "mytest"
title = "tiny test"
kind = "test_runs"

[settings]
task = "ghh08"
seed = 7
policies = "shipped"

[[settings.groups]]
agent = "baseline"
mdps = "test"
n_mdps = 2
{extra}

[scales.quick]
episodes = 3
n_steps = 30
"""


def _save_unchecked(path, obs, act, meta: dict) -> None:
    """A flight-data file with ``meta`` as it is: FlightData refuses such metadata when made (T18-4), load() must too."""
    from neurohover.flightdata import FORMAT

    lengths = np.array([a.shape[0] for a in act], dtype=np.int64)
    arrays = {"lengths": lengths, "observations": np.concatenate(obs), "actions": np.concatenate(act)}
    np.savez_compressed(path, format=np.array(FORMAT), metadata=np.array(json.dumps(meta)), **arrays)


def _config(tmp_path: Path, extra: str = "", tail: str = "") -> Path:
    path = tmp_path / "my.toml"
    path.write_text(TINY.format(extra=extra) + tail)
    return path


@pytest.fixture(scope="module")
def tiny_store(tmp_path_factory) -> Path:
    """A store holding the tiny config's two test runs (each test damages a copy)."""
    from neurohover.experiments import Store, load_config, make_executor, reproduce

    root = tmp_path_factory.mktemp("tiny")
    path = root / "s.sqlite"
    with Store(path) as store:
        reproduce(load_config(str(_config(root)), "quick"), store, make_executor("local", jobs=1), progress=False)
    return path


def _damaged(tiny_store: Path, tmp_path: Path, sql: str) -> Path:
    path = tmp_path / "damaged.sqlite"
    path.write_bytes(tiny_store.read_bytes())
    with sqlite3.connect(path) as c:
        c.execute(sql)
    return path


@pytest.mark.parametrize(
    ("sql", "message"),
    [
        ("UPDATE units SET result = json_set(result, '$.returns', json('[]'))", "holds no episode's return"),
        ("UPDATE units SET result = json_set(result, '$.returns', json('[1.0, 2.0]'), '$.score', 3.0)", "holds 2 episodes' returns where"),
        ("UPDATE units SET seconds = 'abc'", "seconds is damaged \\('abc' is no number of seconds >= 0\\)"),
        ("UPDATE sessions SET wall_seconds = 'x'", "wall seconds is damaged"),
    ],
)
def test_report_and_reproduce_name_a_damaged_run_instead_of_a_numpy_or_type_error(tiny_store, tmp_path, cli, sql, message) -> None:
    """T4, T5: a run with returns [] was a NumPy ValueError in report, a seconds 'abc' a TypeError (an empty report
    directory left behind); results and wins took them."""
    store = _damaged(tiny_store, tmp_path, sql)
    rc, _, err = cli("report", "--store", str(store), "--out", str(tmp_path / "rep"))
    if rc == 0:  # one damaged experiment is said in its place in report.md
        text = (tmp_path / "rep" / "report.md").read_text()
        assert "Not reported: the store's copy is damaged" in text and __import__("re").search(message, text), text[-600:]
    else:
        assert rc == 2 and __import__("re").search(message, err), err
    if "sessions" not in sql:
        rc, _, err = cli("reproduce", str(_config(tmp_path)), "--store", str(store), "--no-progress")
        assert rc == 2 and __import__("re").search(message, err) and "is damaged" in err, err


def test_a_stray_unit_in_the_store_is_refused_not_counted_as_done(tiny_store, tmp_path, cli) -> None:
    """S9: a unit key the config does not plan made reproduce print "3/2 done"."""
    stray = "SELECT name, scale, 'run/x/test0/rep0', kind, config_hash, params, result, seconds, worker, finished FROM units LIMIT 1"
    store = _damaged(tiny_store, tmp_path, f"INSERT INTO units {stray}")
    rc, _, err = cli("reproduce", str(_config(tmp_path)), "--store", str(store), "--no-progress")
    assert rc == 2 and "holds unit 'run/x/test0/rep0', which the config does not plan" in err, err


def test_read_only_commands_leave_an_empty_store_file_empty(tmp_path, cli) -> None:
    """S6: results, wins and report on a 0-byte --store refused, but wrote the store's schema into it."""
    empty = tmp_path / "empty.sqlite"
    empty.write_bytes(b"")
    for argv in (["results", "mytest"], ["wins", "mytest", "--runs", "2"], ["report", "--out", str(tmp_path / "r")]):
        rc, _, err = cli(*argv, "--store", str(empty))
        assert rc == 2 and "is empty (0 bytes)" in err and empty.stat().st_size == 0, (argv, err)
    assert not (tmp_path / "r").exists()


def test_results_of_an_experiment_without_units_and_a_repeated_report_name_are_refused(tiny_store, tmp_path, cli) -> None:
    """S10, S11: an experiment whose units are gone printed an empty line; `report mytest mytest` took it once."""
    store = _damaged(tiny_store, tmp_path, "DELETE FROM units")
    rc, out, err = cli("results", "mytest", "--store", str(store))
    assert rc == 2 and out == "" and "has no finished unit yet: nothing to export" in err, err
    rc, _, err = cli("report", "mytest", "mytest", "--store", str(tiny_store), "--out", str(tmp_path / "r"))
    assert rc == 2 and "experiment 'mytest' is named more than once" in err and not (tmp_path / "r").exists(), err


def test_export_results_given_a_path_is_refused_by_name(tiny_store) -> None:
    """T6: export_results('x.sqlite', ...) was an AttributeError."""
    from neurohover.experiments import export_results

    with pytest.raises(NeurohoverError, match="store='.*s.sqlite' is not allowed: give a Store"):
        export_results(str(tiny_store), "mytest")


@pytest.mark.parametrize(
    ("extra", "tail", "message"),
    [
        ('label = "../x"', "", "group label '../x' is not allowed"),
        ('label = "a//b"', "", "group label 'a//b' is not allowed"),
        ('seeds_of = { experiment = "fig1l", seed = 1, group = "x" }', "", "seeds_of names experiment 'fig1l', which is neither shipped nor this one"),
        ("", 'aliases = ["mine"]\n', "aliases apply to the shipped experiments only"),
        ("", "x = " + "[" * 3000 + "]" * 3000 + "\n", "its TOML is nested too deeply"),
    ],
)
def test_config_files_with_escaping_labels_unknown_pairings_aliases_or_deep_nesting_are_refused(tmp_path, cli, extra, tail, message) -> None:
    """S3, S4, S5, T2: a label '../x' became unit keys run/../x/..., a seeds_of typo paired nothing, aliases in a config
    of one's own were ignored, a TOML value nested 5,000 deep was a RecursionError."""
    if tail.startswith("aliases"):  # a top-level key: before the first table
        path = tmp_path / "my.toml"
        path.write_text(tail + TINY.format(extra=extra))
    else:
        path = _config(tmp_path, extra, tail)
    rc, _, err = cli("reproduce", str(path), "--store", str(tmp_path / "s.sqlite"), "--no-progress")
    assert rc == 2 and message in err and "Traceback" not in err and not (tmp_path / "s.sqlite").exists(), err
    rc, _, err = cli("reproduce", "fig2", "--store", str(tmp_path / "s.sqlite"), "--set", "x=" + "[" * 3000 + "]" * 3000)
    assert rc == 2 and "VALUE is nested too deeply" in err, err


def test_a_damaged_build_state_is_named_and_a_full_disk_leaves_none(tmp_path, cli) -> None:
    """T1, U1: an empty stages/build.json (what a full disk left) was a JSONDecodeError; a JSON list was taken."""
    state = tmp_path / "bp" / "ghh08.building" / "stages" / "build.json"
    state.parent.mkdir(parents=True)
    for text in ("", '{"x":', "[1]"):
        state.write_text(text)
        rc, _, err = cli("build-policies", "--task", "ghh08", "--out", str(tmp_path / "bp"), "--budget", "2", "--episode-steps", "10")
        assert rc == 2 and "the interrupted build's state" in err and "is damaged" in err and "to start the build over" in err, err
        assert state.read_text() == text  # refused, left as it was


@pytest.mark.slow
def test_a_full_disk_names_the_file_for_evolve_report_and_build_policies(tiny_store, tmp_path, cli) -> None:
    """U1: evolve, report and build-policies said only "No space left on device"; report left a 0-byte report.md and
    build-policies a 0-byte build.json."""
    from test_paths import _full_disk  # type: ignore[import-not-found]

    disk = _full_disk(tmp_path)
    import subprocess

    try:
        (disk / "fill").write_bytes(bytes(24 * 1024 - 1))
        rc, _, err = cli("evolve", "--task", "ghh08", "--budget", "3", "--episode-steps", "20", "--out", str(disk / "e.json"))
        assert rc == 2 and "cannot write it (No space left on device)" in err and str(disk) in err, err
        rc, _, err = cli("report", "--store", str(tiny_store), "--out", str(disk / "rep"))
        assert rc == 2 and "': cannot write it (No space left on device); no partial file is left" in err and "damaged" not in err, err
        rc, _, err = cli("build-policies", "--task", "ghh08", "--out", str(disk / "bp"), "--budget", "2", "--episode-steps", "10")
        assert rc == 2 and "build.json': cannot write it (No space left on device)" in err, err
        assert sorted(p.name for p in disk.iterdir()) == ["fill", "pad"]
    finally:
        subprocess.run(["umount", str(disk)], check=False)


def test_policy_metadata_cannot_overwrite_its_network(tmp_path) -> None:
    """S1: a Policy whose metadata held 'genome' was saved over its own genome, into a file load_policy refuses."""
    with pytest.raises(NeurohoverError, match="metadata key\\(s\\) genome are the policy's own"):
        nh.Policy("mlp", np.zeros(42), {"genome": [1]})
    with pytest.raises(NeurohoverError, match="metadata key\\(s\\) topology are the policy's own"):
        nh.Policy("slp", np.zeros(40), {"topology": "mlp", "note": 1})
    assert nh.Policy("slp", np.zeros(40), {"note": 1}).metadata == {"note": 1}


def test_an_output_path_ending_in_a_slash_is_refused(tmp_path, cli) -> None:
    """S8: `--out ev/x.json/` and save_policy(p, 'dir/') wrote a file of that name without the slash."""
    with pytest.raises(NeurohoverError, match="ends in '/', which names a directory"):
        nh.save_policy(nh.baseline_policy(), str(tmp_path / "d") + "/")
    rc, _, err = cli("evolve", "--task", "ghh08", "--budget", "3", "--episode-steps", "20", "--out", str(tmp_path / "x.json") + "/")
    assert rc == 2 and "ends in '/'" in err and not (tmp_path / "x.json").exists() and not (tmp_path / "d").exists(), err


def test_continual_safeguard_after_without_the_safeguard_is_refused(cli, tmp_path) -> None:
    """S2: safeguard_after beside safeguard=false was ignored without a word."""
    rc, _, err = cli(
        "compete", "--task", "ghh08", "--agent", "continual", "--runs", "1", "--episodes", "2", "--episode-steps", "20",
        "--agent-setting", "safeguard=false", "--agent-setting", "safeguard_after=5", "--out", str(tmp_path / "c"),
    )  # fmt: skip
    assert rc == 2 and "safeguard_after applies with safeguard = true only" in err and not (tmp_path / "c").exists(), err


def test_resuming_a_finished_run_with_a_lower_budget_is_refused(tmp_path, cli) -> None:
    """S7: `evolve --resume --budget 600` after a run of 3,000+ episodes rewrote its stop reason to "budget"."""
    out = str(tmp_path / "e.json")
    rc, _, err = cli("evolve", "--task", "ghh08", "--budget", "60", "--episode-steps", "20", "--out", out)
    assert rc == 0, err
    flown = json.loads(Path(out).read_text())["episodes"]
    rc, _, err = cli("evolve", "--task", "ghh08", "--budget", "10", "--episode-steps", "20", "--out", out, "--resume")
    assert rc == 2 and f"budget 10 is below the {flown} episodes" in err and "may only be raised" in err, err
    assert json.loads(Path(out).read_text())["stop_reason"] == "budget"


def test_flight_data_metadata_of_the_wrong_kind_and_overflowing_lengths_are_named(tmp_path, cli) -> None:
    """T3, U2: metadata episode_steps "a" was a ValueError in plot; lengths 2**62 twice summed to a negative count."""
    from neurohover.flightdata import FlightData

    obs, act = np.zeros((3, 12)), np.zeros((2, 4))
    good = FlightData((obs,), (act,), {"episode_steps": 2, "crashed": [False]})
    for meta, message in (
        ({"episode_steps": "a"}, "episode_steps='a' is not allowed"),
        ({"episode_steps": 0}, "episode_steps=0 is not allowed"),
        ({"crashed": [1]}, "crashed=\\[1\\] is not allowed: one true or false per episode"),
        ({"crashed": [True, False]}, "crashed=.* is not allowed"),
    ):
        path = tmp_path / "bad.npz"
        with pytest.raises(NeurohoverError, match=message):  # refused when made too (T18-4)
            FlightData((obs,), (act,), meta)
        _save_unchecked(path, (obs,), (act,), meta)
        with pytest.raises(NeurohoverError, match=message):
            FlightData.load(path)
        rc, _, err = cli("plot", str(path), "--out", str(tmp_path / "p"))
        assert rc == 2 and "Traceback" not in err, err
    good.save(tmp_path / "good.npz")
    assert FlightData.load(tmp_path / "good.npz").metadata["crashed"] == [False]
    with np.load(tmp_path / "good.npz") as z:
        arrays = {k: z[k] for k in z.files}
    np.savez(tmp_path / "long.npz", **{**arrays, "lengths": np.array([2**62, 2**62])})
    with pytest.raises(NeurohoverError, match="an episode of 4,611,686,018,427,387,904 steps \\(at most 10,000,000\\)"):
        FlightData.load(tmp_path / "long.npz")


def test_the_unclear_messages_of_the_seventh_trial_say_what_is_wrong(tmp_path, cli, capsys) -> None:
    """U3-U8: a reversed range called "out of range", a missing RL Zoo folder "found []", `--setting budget` "unknown"
    though listed, 400-digit numbers echoed whole or as inf, --n-mdps 0 without its range, "apply" for one option."""
    path = tmp_path / "f.npz"
    from neurohover.flightdata import FlightData

    FlightData((np.zeros((3, 12)), np.zeros((3, 12))), (np.zeros((2, 4)), np.zeros((2, 4))), {}).save(path)
    huge = "1" + "0" * 400
    for argv, message in (
        (["plot", str(path), "--out", str(tmp_path / "p"), "--episodes", "1-0"], "'1-0' is a reversed range"),
        (["evolve", "--task", "ghh08", "--out", str(tmp_path / "e.json"), "--setting", "budget=5"], "the run's budget is its own option (--budget"),
        (["fly", "--task", "ghh08", "--episodes", huge], "--episodes 1000000000...(401 digits) is out of range"),
        (["fly", "--task", "fghh", "--sigma", huge], "1000000000...(401 characters) is past a float's range"),
        (["evaluate-agent", "--task", "ghh08", "--policy", "baseline", "--n-mdps", "0"], "--n-mdps 0 is out of range: allowed 1..100"),
        (["compete", "--task", "ghh09", "--agent", "hybrid-risk", "--safeguard-box", "0.3", "--runs", "1", "--out", str(tmp_path / "c")],
         "--safeguard-box applies to the hybrid agents only (hybrid, hybrid-baseline), not to --agent hybrid-risk (its own settings are --agent-setting"),
    ):  # fmt: skip
        try:
            rc, _, err = cli(*argv)
        except SystemExit as stop:  # argparse's own refusal (a --sigma that is no float)
            rc, err = stop.code, capsys.readouterr().err
        assert rc == 2 and message in err and huge not in err, (argv, err)
    pytest.importorskip("stable_baselines3", reason="evaluate-agent --rl-zoo needs stable-baselines3")
    rc, _, err = cli("evaluate-agent", "--task", "ghh08", "--rl-zoo", str(tmp_path / "missing"))
    assert rc == 2 and "missing': no such directory" in err, err


def test_a_policy_of_another_task_is_flown_with_a_note_and_a_bad_task_is_refused(tmp_path, cli) -> None:
    """S12: a GHH-09 policy flew on GHH-08 without a word; `task: 5` in its metadata was not checked."""
    other = tmp_path / "g9.json"
    nh.save_policy(nh.baseline_policy(), other, task="ghh09")
    rc, _, err = cli("fly", "--task", "ghh08", "--episodes", "1", "--policy", str(other))
    assert rc == 0 and "note: --policy " in err and "was evolved for ghh09; flying it on ghh08" in err, err
    with pytest.raises(nh.NeurohoverError, match="its task 5 is not allowed: allowed ghh08, ghh09, fghh"):  # nor written (T26-B07)
        nh.save_policy(nh.baseline_policy(), tmp_path / "t5.json", task=5)
    (tmp_path / "t5.json").write_text(json.dumps({**json.loads(other.read_text()), "task": 5}))
    rc, _, err = cli("fly", "--task", "ghh08", "--episodes", "1", "--policy", str(tmp_path / "t5.json"))
    assert rc == 2 and "its task 5 is not allowed" in err, err


def test_settings_print_a_shared_entry_once() -> None:
    """U9: one docstring entry for several settings was printed under each of them."""
    from neurohover.evolution.eonn import EonnSettings
    from neurohover.integrations.neat import NeatSettings
    from neurohover.settingsdoc import format_settings

    for cls in (EonnSettings, NeatSettings):
        lines = [line for line in format_settings(cls, "x").splitlines() if line.startswith("    ")]
        assert len(lines) == len(set(lines)), [line for line in lines if lines.count(line) > 1]
