"""Issue 37, the eighth fresh trial: each case it found gives one clear message (exit 2 / NeurohoverError), a full
disk is not taken for a damaged store, and a damaged stage of an interrupted build loses no other finished run."""

from __future__ import annotations

from pathlib import Path

import gymnasium as gym
import pytest
from test_bad_input_trial7 import _config, _damaged, _save_unchecked, tiny_store  # noqa: F401  (tiny_store: the fixture)

import neurohover as nh
from neurohover.errors import NeurohoverError, finite_real, float_of

HUGE = "1" + "0" * 400


def test_numbers_past_a_floats_range_are_named_not_read_as_inf_or_an_overflow_error() -> None:
    """T1, U1: 10**400 was an OverflowError in Drift, the risk level and the evolution settings, and '1' and 400 zeros
    was read as inf by --wind, --obs-noise, --drift and --safeguard-box."""
    assert not finite_real(10**400) and not finite_real(True) and finite_real(3) and not finite_real(float("nan"))
    assert float_of("inf") == float("inf") and float_of(" 2.5") == 2.5
    with pytest.raises(ValueError, match=r"1000000000...\(401 characters\) is past a float's range"):
        float_of(HUGE)
    for call, message in (
        (lambda: nh.Drift(walk=10**400), "drift walk=.* is out of range"),
        (lambda: gym.make("neurohover/GHH08-v0", drift={"walk": 10**400}), "drift walk=.* is out of range"),
        (lambda: nh.Drift.parse(f"walk={HUGE}"), "is past a float's range"),
        (lambda: nh.Sensor.parse(HUGE), "sensor level .* is past a float's range"),
        (lambda: nh.Sensor.parse(f"velocity={HUGE}"), "needs a number after '=': .* is past a float's range"),
    ):
        with pytest.raises(NeurohoverError, match=message):
            call()


@pytest.mark.parametrize(
    "argv",
    [
        ["compete", "--task", "ghh08", "--agent", "hybrid-risk", "--runs", "1", "--episodes", "2", "--episode-steps", "20", "--agent-setting", f"level={HUGE}"],
        ["evolve", "--task", "ghh08", "--budget", "3", "--episode-steps", "20", "--setting", f"mutate_std={HUGE}"],
        ["evolve", "--task", "ghh08", "--budget", "3", "--checkpoint-every", HUGE],
        ["fly", "--task", "ghh08", "--wind", f"1,{HUGE}"],
        ["compete", "--task", "ghh08", "--agent", "hybrid", "--runs", "1", "--safeguard-box", HUGE],
    ],
)
def test_the_command_line_refuses_numbers_past_a_floats_range_in_one_short_line(argv, tmp_path, cli, capsys) -> None:
    out = ["--out", str(tmp_path / ("e.json" if argv[0] == "evolve" else "c"))] if argv[0] in ("evolve", "compete") else []
    try:
        rc, _, err = cli(*argv, *out)
    except SystemExit as stop:  # argparse's own refusal
        rc, err = stop.code, capsys.readouterr().err
    assert rc == 2 and "Traceback" not in err and HUGE not in err and "inf" not in err.split("error:")[-1], err


def test_risk_level_of_text_is_not_a_number_and_a_method_given_twice_is_refused(tmp_path) -> None:
    """U7, U5: level 'abc' was "out of range"; methods ["lr", "lr"] ended in "2 units could not be planned"."""
    from neurohover.agents.risk import RiskSettings
    from neurohover.experiments import load_config

    with pytest.raises(NeurohoverError, match="risk level='abc' is not a number"):
        RiskSettings(level="abc")  # type: ignore[arg-type]
    path = tmp_path / "ml.toml"
    path.write_text('name = "myml"\nkind = "model_learning"\n[settings]\ntask = "ghh08"\nseed = 1\nmethods = ["lr", "lr"]\n[scales.quick]\nn_mdps = 1\n')
    with pytest.raises(NeurohoverError, match="methods .* a non-empty list of distinct names"):
        load_config(str(path), "quick")


def test_damaged_stored_configs_and_overflowing_returns_are_named(tmp_path) -> None:
    """T2, T3: a stored config of kind 'foo' was a KeyError in report, groups 'x' a RuntimeError; returns of 1e308 an
    OverflowError in fsum."""
    from neurohover.experiments.config import ExperimentConfig, load_config
    from neurohover.experiments.results import result_from_dict

    good = load_config("fig7", "quick").to_dict()
    for damage, message in (({"kind": "foo"}, "kind 'foo' is none of"), ({"settings": {**good["settings"], "groups": "x"}}, "do not read as a test_runs")):
        with pytest.raises(NeurohoverError, match=f"a stored experiment config is damaged: .*{message}"):
            ExperimentConfig.from_dict({**good, **damage})
    run = {
        "agent": "baseline", "mdp": "m", "score": 3e308, "returns": [1e308] * 3, "crash_episodes": [], "safeguard_episodes": [],
        "policy_changes": [], "learning_episodes": 0, "mean_return_after_learning": 1e308, "timing": {"seconds": 1.0, "offline_seconds": 0.5},
    }  # fmt: skip
    with pytest.raises(NeurohoverError, match="its returns sum past a float's range"):
        result_from_dict("test_run", run, "run/x/test0/rep0")


def test_deeply_nested_checkpoints_and_compete_summaries_and_huge_returns_are_refused(tmp_path, cli) -> None:
    """T4, T5: a checkpoint or summary.json nested 100,000 deep was a RecursionError; a return of -1e308 in a compete
    folder an OverflowError in the plot."""
    from neurohover.evolution.records import read_checkpoint
    from neurohover.experiments.config import parse_override

    deep = "[" * 100_000 + "]" * 100_000
    (tmp_path / "x.checkpoint.json").write_text(deep)
    with pytest.raises(NeurohoverError, match="its JSON is nested too deeply"):
        read_checkpoint(tmp_path / "x.checkpoint.json")
    folder = tmp_path / "c"
    folder.mkdir()
    (folder / "episodes.csv").write_text("run,mdp,episode,return,crashed,steps\n0,m,0,-5.0,0,20\n0,m,1,-6.0,0,20\n")
    (folder / "summary.json").write_text(deep)
    rc, _, err = cli("plot", "--compete", str(folder), "--out", str(tmp_path / "p.png"))
    assert rc == 2 and "summary.json' cannot be read" in err, err
    (folder / "summary.json").unlink()
    (folder / "episodes.csv").write_text("run,mdp,episode,return,crashed,steps\n0,m,0,-1e308,0,20\n")
    rc, _, err = cli("plot", "--compete", str(folder), "--out", str(tmp_path / "p.png"))
    assert rc == 2 and "return '-1e308' is not an episode's" in err, err
    for bad in (None, 5):  # T6: an AttributeError
        with pytest.raises(NeurohoverError, match="is not allowed: give KEY=VALUE as text"):
            parse_override(bad)  # type: ignore[arg-type]


@pytest.mark.slow
def test_a_damaged_stage_of_an_interrupted_build_is_flown_again_and_the_others_kept(tmp_path) -> None:
    """S1: one empty stage file failed the resumed build, which then deleted every finished run."""
    from neurohover.policysets import build_policy_set

    first = build_policy_set("ghh08", tmp_path / "a", budget=4, n_steps=20, safety_episodes=1)
    finished: list[str] = []

    def stop_after_three(line: str) -> None:
        finished.extend([line] if ": champion " in line else [])
        if len(finished) == 3:
            raise KeyboardInterrupt  # interrupted with three runs finished

    with pytest.raises(KeyboardInterrupt):
        build_policy_set("ghh08", tmp_path / "b", budget=4, n_steps=20, safety_episodes=1, progress=stop_after_three)
    stages = sorted(p for p in (tmp_path / "b" / "ghh08.building" / "stages").glob("*.json") if p.name != "build.json")
    assert len(stages) == 3
    stages[0].write_text("")
    said: list[str] = []
    again = build_policy_set("ghh08", tmp_path / "b", budget=4, n_steps=20, safety_episodes=1, progress=said.append)
    assert sum("is damaged; this run is flown again" in line for line in said) == 1, said
    assert sum("kept from the interrupted build" in line for line in said) == 2, said
    assert again.generic == first.generic and again.specialised == first.specialised  # the same build, resumed


@pytest.mark.slow
def test_a_full_disk_while_report_draws_a_figure_is_no_damaged_store(tmp_path, cli) -> None:
    """S2: the figure's write failed, and report.md said "the store's copy is damaged", exit 0."""
    import subprocess

    from test_paths import _full_disk  # type: ignore[import-not-found]

    from neurohover.experiments import Store, load_config, make_executor, reproduce

    store = tmp_path / "s.sqlite"
    with Store(store) as s:
        reproduce(load_config("fig2", "quick"), s, make_executor("local", jobs=1), progress=False, only=["evolve/slp-zero/train0/run0"])
    disk = _full_disk(tmp_path)
    try:
        (disk / "fill").write_bytes(bytes(16 * 1024))
        rc, _, err = cli("report", "--store", str(store), "--out", str(disk / "rep"))
        assert rc == 2 and "cannot write it (No space left on device)" in err and "damaged" not in err, err
    finally:
        subprocess.run(["umount", str(disk)], check=False)


def test_variant_keys_that_escape_and_wins_on_a_damaged_run_are_refused(tmp_path) -> None:
    """S4, S11: a variant key "../x" became unit keys evolve/../x/...; wins read the score of a run that results,
    report and reproduce call damaged."""
    from neurohover.experiments import load_config
    from neurohover.experiments.wins import stored_runs

    text = (Path(nh.__file__).parent / "experiments" / "configs" / "fig15.toml").read_text()
    path = tmp_path / "mine.toml"
    path.write_text(text.replace('name = "fig15"', 'name = "mine"').replace('key = "k5"', 'key = "../x"', 1))
    with pytest.raises(NeurohoverError, match="variant key '../x' is not allowed"):
        load_config(str(path), "quick")
    run = {"agent": "baseline", "mdp": 5, "score": -1.0, "returns": "x"}
    with pytest.raises(NeurohoverError, match="the stored result of unit 'run/b/test0/rep0' is damaged"):
        stored_runs({"run/b/test0/rep0": run})


@pytest.mark.parametrize(
    ("meta", "message"),
    [
        ({"task": 5}, "task=5 is not allowed: give text"),
        ({"policy": 123}, "policy=123 is not allowed"),
        ({"returns": "x"}, "returns='x' is not allowed: one number per episode"),
        ({"returns": [1.0, 2.0]}, "returns=.* is not allowed"),
        ({"mdps": [{"family": "x"}, 5]}, "mdps=.* is not allowed: one MDP"),
    ],
)
def test_flight_data_metadata_that_titles_and_model_checks_read_is_checked(meta, message, tmp_path) -> None:
    """S10: a task 5, returns "x" or mdps of another length were taken, and learn-model's comparison with the true MDP
    then dropped out without a word."""
    import numpy as np

    from neurohover.flightdata import FlightData

    with pytest.raises(NeurohoverError, match=message):  # refused when made too (T18-4)
        FlightData((np.zeros((3, 12)),), (np.zeros((2, 4)),), meta)
    _save_unchecked(tmp_path / "f.npz", (np.zeros((3, 12)),), (np.zeros((2, 4)),), meta)
    with pytest.raises(NeurohoverError, match=message):
        FlightData.load(tmp_path / "f.npz")


def test_a_stored_unit_of_other_params_is_refused_not_reused(tmp_path, cli, tiny_store) -> None:  # noqa: F811  (the fixture)
    """S12: a unit whose params name agent "foo" (or whose kind differs) was taken as finished and reused."""
    store = _damaged(tiny_store, tmp_path, "UPDATE units SET params = json_set(params, '$.agent', 'foo') WHERE key LIKE 'run/baseline/test0/%'")
    rc, _, err = cli("reproduce", str(_config(tmp_path)), "--store", str(store), "--no-progress")
    assert rc == 2 and "unit 'run/baseline/test0/rep0' holds other settings than its config plans for it" in err, err
    rc, out, err = cli("reproduce", str(_config(tmp_path)), "--store", str(tiny_store), "--no-progress")
    assert rc == 0 and "0 units" in out + err, err  # the undamaged store: every unit finished, none run again


@pytest.mark.slow
def test_a_competition_into_a_folder_of_another_says_it_replaces_its_files(tmp_path, cli) -> None:
    """S8: compete --out D with another agent replaced D's episodes.csv, summary.json and plot without a word."""
    base = ["compete", "--task", "ghh08", "--runs", "1", "--episodes", "2", "--episode-steps", "20", "--out", str(tmp_path / "d")]
    rc, _, err = cli(*base, "--agent", "baseline")
    assert rc == 0 and "note:" not in err, err
    rc, _, err = cli(*base, "--agent", "baseline")  # the same competition again: its runs reused, nothing replaced
    assert rc == 0 and "held the competition" not in err, err
    rc, _, err = cli(*base, "--agent", "model-free")
    assert rc == 0 and "held the competition of baseline on ghh08; its episodes.csv, summary.json and plot are replaced" in err, err


@pytest.mark.slow
def test_a_compete_file_cut_short_is_refused_not_plotted_short(tmp_path, cli) -> None:
    """S9: an episodes.csv whose last run was cut mid-way was plotted with every run cut to the shortest."""
    folder = tmp_path / "c"
    folder.mkdir()
    rows = "".join(f"{run},m,{e},-{e + 1}.0,0,20\n" for run in (0, 1) for e in range(3))
    (folder / "episodes.csv").write_text("run,mdp,episode,return,crashed,steps\n" + rows.rsplit("\n", 2)[0] + "\n")
    rc, _, err = cli("plot", "--compete", str(folder), "--out", str(tmp_path / "p.png"))
    assert rc == 2 and "run 1 has 2 episodes where run 0 has 3: the file is cut short" in err, err
    (folder / "episodes.csv").write_text("run,mdp,episode,return,crashed,steps\n" + rows)
    rc, _, err = cli("plot", "--compete", str(folder), "--out", str(tmp_path / "p.png"))
    assert rc == 0 and (tmp_path / "p.png").stat().st_size > 0, err


def test_a_missing_generic_source_is_named_as_generic(tmp_path, cli) -> None:
    """U6: a model-learning config's generic = "nope" was refused as "policies = 'nope'", without 'baseline'."""
    path = tmp_path / "ml.toml"
    path.write_text('name = "myml"\nkind = "model_learning"\n[settings]\ntask = "ghh08"\nseed = 1\ngeneric = "nope"\n[scales.quick]\nn_mdps = 1\n')
    rc, _, err = cli("reproduce", str(path), "--store", str(tmp_path / "s.sqlite"))
    assert rc == 2 and "generic = 'nope' is not allowed: give 'evolve', 'baseline', 'shipped' or a directory" in err, err
    assert not (tmp_path / "s.sqlite").exists()


def test_reproduce_plans_a_finished_experiment_once(tiny_store, tmp_path, monkeypatch) -> None:  # noqa: F811  (the fixture)
    """Left from the eighth trial: the check for stray units planned the experiment, then the first round again. The
    shared check (export) plans it too: counted beside the runner's, once in all."""
    import neurohover.experiments.export as export
    import neurohover.experiments.runner as runner
    from neurohover.experiments import Store, load_config, make_executor, reproduce

    calls = []
    real_plan = runner.plan
    for module in (runner, export):
        monkeypatch.setattr(module, "plan", lambda *a, **k: calls.append(1) or real_plan(*a, **k))
    path = tmp_path / "s.sqlite"
    path.write_bytes(tiny_store.read_bytes())
    with Store(path) as store:
        summary = reproduce(load_config(str(_config(tmp_path)), "quick"), store, make_executor("local", jobs=1), progress=False)
    assert summary.status == "finished" and summary.units_run == 0 and len(calls) == 1
