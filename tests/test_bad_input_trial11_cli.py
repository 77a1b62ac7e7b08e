"""Issue 37, the eleventh fresh trial: its findings about the command line, compete and the task names (S1, S3, S8, U1,
U2, U6, U7, U8 in part) each give one clear message (exit 2 / NeurohoverError) or are taken as a user would expect."""

from __future__ import annotations

import sqlite3
from pathlib import Path

import pytest
from conftest import tiny_test_runs

from neurohover.errors import NeurohoverError

COMPETE = ["compete", "--task", "ghh08", "--agent", "baseline", "--runs", "1", "--episode-steps", "20"]


def test_list_beside_other_options_is_refused_naming_them(tmp_path: Path, cli) -> None:
    """S1: reproduce --list dropped --store, --set, --scale, --jobs, --only, --update and --fresh without a word."""
    store = tmp_path / "x.sqlite"
    argv = ["reproduce", "--list", "--store", str(store), "--set", "runs=1", "--scale", "paper", "--jobs", "2", "--only", "x", "--update"]
    rc, out, err = cli(*argv)
    assert rc == 2 and out == "" and not store.exists(), err
    assert "--list lists every experiment and takes no other options (got --jobs, --scale, --store, --update, --set, --only): give one" in err, err
    for extra, named in ((["--fresh"], "--fresh"), (["--scale", "quick"], "--scale"), (["--no-progress"], "--no-progress")):
        rc, _, err = cli("reproduce", "--list", *extra)
        assert rc == 2 and f"takes no other options (got {named})" in err, err
    rc, out, _ = cli("reproduce", "--list")
    assert rc == 0 and "fig2" in out.split()


@pytest.mark.parametrize(
    ("make", "message"),
    [
        (lambda d: d.parse("walk=0"), "drift 'walk=0' changes nothing: give walk > 0 (up to 1) or a change of a factor other than 1"),
        (lambda d: d.parse("walk=0.0,D_w=0.8"), "drift 'walk=0.0' changes nothing"),
        (lambda d: d.parse("D_w=1@1-1"), "drift change D_w=1.0 changes nothing: give a factor other than 1 (in 0.01..100) or leave D_w out"),
        (lambda d: d(0.0, (("C_u", 1),)), "drift change C_u=1 changes nothing"),
        (lambda d: d.from_dict({"walk": 0}), "drift walk=0 changes nothing"),
    ],
)
def test_a_drift_that_changes_nothing_is_refused(make, message: str) -> None:
    """S3: --drift walk=0 and D_w=1@1-1 were flown and stored as another experiment, identical to no drift."""
    from neurohover.tasks import Drift

    with pytest.raises(NeurohoverError, match="^" + message.replace("(", r"\(").replace(")", r"\)").replace(".", r"\.")):
        make(Drift)
    assert Drift.from_dict({"walk": 0.0, "change": {"D_w": 0.8}}) == Drift.parse("D_w=0.8")  # a change's table keeps walk 0
    assert Drift().none and Drift.from_dict({}).none


def test_compete_refuses_a_drift_that_changes_nothing(tmp_path: Path, cli) -> None:
    """S3 on the command line: exit 2, no --out made."""
    for drift, message in (("walk=0", "drift 'walk=0' changes nothing"), ("D_w=1@1-1", "drift change D_w=1.0 changes nothing")):
        rc, _, err = cli(*COMPETE, "--episodes", "2", "--out", str(tmp_path / "c"), "--drift", drift)
        assert rc == 2 and message in err, err
    assert list(tmp_path.iterdir()) == []


def test_a_config_named_after_a_shipped_alias_is_refused(tmp_path: Path, cli) -> None:
    """S8: a config named table3 (fig2's alias) ran; `reproduce table3` then meant fig2 and `results table3` this one."""
    config = tmp_path / "fake.toml"
    config.write_text(tiny_test_runs("baseline", name="table3"))
    store = tmp_path / "s.sqlite"
    rc, _, err = cli("reproduce", str(config), "--store", str(store), "--no-progress")
    assert rc == 2 and not store.exists(), err
    assert f"config '{config}': name = 'table3' is an alias of the shipped experiment 'fig2': a config of your own needs a name of its own" in err, err
    from neurohover.experiments import Store, load_config, make_executor, reproduce

    with Store(store) as db, pytest.raises(NeurohoverError, match="name = 'table3' is an alias of the shipped experiment 'fig2'"):
        reproduce(load_config(config, "quick"), db, make_executor("local", jobs=1), progress=False)  # Python checks it as the CLI does
    with Store(store) as db:
        assert db.experiments() == []


def test_results_out_dash_points_to_standard_output(tmp_path: Path, cli) -> None:
    """S7: `results --out -` wrote a file named '-'; its default is standard output, which the message now names."""
    from store_edits import begin

    from neurohover.experiments import Store

    with Store(tmp_path / "s.sqlite") as db:
        begin(db, "fig2")
    rc, _, err = cli("results", "fig2", "--store", str(tmp_path / "s.sqlite"), "--out", "-")
    assert rc == 2 and "--out '-' is not a file name here: leave --out out for standard output" in err, err
    assert not (tmp_path / "-").exists() and not Path("-").exists()


@pytest.mark.slow
def test_results_and_wins_take_the_scales_a_compete_store_holds(tmp_path: Path, cli) -> None:
    """U1: "choose one with --scale" named scales like settings-e4eae2eb06, which --scale (quick, paper) refused."""
    out = tmp_path / "c"
    for episodes in ("1", "2"):
        assert cli(*COMPETE, "--episodes", episodes, "--out", str(out))[0] == 0
    store = out / "results.sqlite"
    with sqlite3.connect(store) as db:
        scales = [r[0] for r in db.execute("SELECT scale FROM experiments ORDER BY created")]
    rc, _, err = cli("results", "compete-ghh08-baseline", "--store", str(store))
    assert rc == 2 and f"at scales {', '.join(scales)}: choose one with --scale (e.g. --scale {scales[-1]})" in err, err
    rc, text, err = cli("results", "compete-ghh08-baseline", "--store", str(store), "--scale", scales[-1])
    assert rc == 0 and f"compete-ghh08-baseline,{scales[-1]},run/baseline/test0/rep0" in text, err
    rc, _, err = cli("wins", "compete-ghh08-baseline", "--store", str(store), "--scale", scales[0])
    assert rc == 2 and "invalid choice" not in err and "a competition needs two or more" in err, err  # past the scale (T34-A03: what works)
    rc, _, err = cli("report", "--store", str(store), "--out", str(tmp_path / "r"), "--scale", "nope")
    assert rc == 2 and "holds nothing at scale 'nope'; it holds: compete-ghh08-baseline (settings-" in err and not (tmp_path / "r").exists(), err


def test_compete_takes_the_settings_that_neurohover_settings_lists(tmp_path: Path, cli) -> None:
    """U2: compete refused --agent incremental --agent-setting max_learning_episodes=3, which `neurohover settings incremental`
    lists, with a message about the hybrid agents' options."""
    from neurohover.compete import agents_with_settings, competition_config

    config = competition_config("ghh08", "incremental", runs=1, episodes=2, agent_settings={"max_learning_episodes": 3})
    assert config.settings["max_learning_episodes"] == 3 and "incremental" in agents_with_settings()
    assert competition_config("ghh08", "incremental", runs=1, episodes=2).settings["max_learning_episodes"] == 25
    argv = ["compete", "--task", "ghh08", "--runs", "1", "--episodes", "1", "--episode-steps", "20", "--out", str(tmp_path / "c")]
    rc, _, err = cli(*argv, "--agent", "hybrid", "--agent-setting", "box=0.3")
    assert rc == 2 and "agent 'hybrid' takes no settings table of its own (its settings, `neurohover settings hybrid`, are the --safeguard-*/--hybrid-*" in err
    assert "agents that do: continual, hybrid-baseline-risk, hybrid-risk, incremental," in err, err
    rc, _, err = cli(*argv, "--agent", "incremental", "--agent-setting", "max_learning_episodes=0")
    assert rc == 2 and "max_learning_episodes=0 is out of range: allowed an integer in 1..2**63-1" in err, err


@pytest.mark.parametrize(
    ("argv", "start"),
    [
        (["fly", "--task", "g" * 100_000, "--episodes", "1"], "unknown task 'gggg"),
        (["fly", "--task", "ghh08", "--mdp", "g" * 100_000], "unknown MDP 'gggg"),
        (["fly", "--task", "ghh08", "--mdp", "train:" + "1" * 5000], "MDP index 1111111111...(5000 digits) in 'train:"),
        (["compete", "--task", "ghh08", "--agent", "g" * 100_000, "--out", "c"], "unknown agent 'gggg"),
        (["compete", "--task", "ghh08", "--agent", "continual", "--agent-setting", "g" * 100_000 + "=1", "--out", "c"], "setting(s) 'gggg"),
        (["settings", "g" * 100_000], "no settings named 'gggg"),
        (["reproduce", "g" * 100_000, "--store", "s.sqlite"], "unknown experiment 'gggg"),
    ],
)
def test_long_task_mdp_and_agent_names_are_shortened(argv: list[str], start: str, tmp_path: Path, cli, monkeypatch) -> None:
    """U6: a 100,000-character --task, --mdp, --agent, settings or agent-setting name, experiment or choice was echoed whole
    (a 100 kB line); 5,000 digits after train: were int()'s traceback."""
    monkeypatch.chdir(tmp_path)
    rc, _, err = cli(*argv)
    assert rc == 2 and len(err) < 800 and start in err and "characters)" in err, err
    assert list(tmp_path.iterdir()) == []


def test_argparse_refusals_shorten_a_long_value(capsys) -> None:
    """U6: argparse's "invalid choice: 'ggg...'" echoed a 100,000-character value whole."""
    from neurohover.cli import main

    with pytest.raises(SystemExit) as stop:  # argparse's own refusal
        main(["fly", "--task", "ghh08", "--record-dtype", "g" * 100_000])
    err = capsys.readouterr().err
    assert stop.value.code == 2 and "invalid choice: 'gggg" in err and "(100,002 characters) (choose from 'float64', 'float32')" in err
    assert len(err) < 2000, err


def test_an_abbreviated_option_takes_a_negative_value(cli) -> None:
    """U7: fly --win -3,1 (argparse's abbreviation of --wind) said "expected one argument"; now it reaches --wind's check."""
    rc, _, err = cli("fly", "--task", "ghh08", "--episodes", "1", "--win", "-300,1")
    assert rc == 2 and "GHH-08 wind [-300.0, 1.0] m/s is out of range" in err, err


def test_messages_name_the_options_as_typed(tmp_path: Path, cli, monkeypatch) -> None:
    """U8 (in part): the delay conflict named obs_delay / obs_noise only; compete's too-long --out was called out."""
    from neurohover.tasks import Sensor

    with pytest.raises(
        NeurohoverError,
        match=r"obs_delay=5 conflicts with the delay=3 that obs_noise sets: give the delay once \(on the command line: --obs-delay, or delay= in --obs-noise\)",
    ):
        Sensor.of("delay=3", 5)
    monkeypatch.chdir(tmp_path)
    rc, _, err = cli(*COMPETE, "--episodes", "1", "--out", "a" * 300)
    assert rc == 2 and "error: --out 'aaaa" in err and "is too long: at most 255 bytes" in err and list(tmp_path.iterdir()) == [], err


def test_long_names_are_shortened_in_python_too(tmp_path: Path) -> None:
    """U6: the command line shortened a 100,000-character name, but Python's messages (unknown task, MDP, agent, stored
    experiment, settings key) still held it whole: one helper (errors.brief) shortens them all."""
    import neurohover as nh
    from neurohover.agents.model_based import IncrementalSettings
    from neurohover.agents.registry import agent_spec
    from neurohover.experiments import Store
    from neurohover.settings_checks import settings_from_dict

    long = "g" * 100_000
    calls = [
        lambda: nh.get_task_family(long),
        lambda: nh.get_task_family("ghh08").mdp(long),
        lambda: agent_spec(long),
        lambda: settings_from_dict(IncrementalSettings, {long: 1}, unknown_what="incremental", bad_what="incremental"),
    ]
    with Store(tmp_path / "s.sqlite") as db:
        messages = [db.missing_message(long, "quick")]
    for call in calls:
        with pytest.raises(NeurohoverError) as err:
            call()
        messages.append(str(err.value))
    for message in messages:
        assert len(message) < 400 and "'gggggggggggggggggggggggggggggggggggggggg' ... 'gggggggggggggggggggg' (100,000 characters)" in message, message


def test_compete_keeps_the_continual_agents_own_settings(tmp_path: Path, cli) -> None:
    """Twelfth trial, S3: compete dropped every continual setting without a word (the incremental agents' one setting of
    the whole experiment, max_learning_episodes, was picked out by key, and continual has a key of that name), and a
    safeguard_after past the episode was refused only once a run had started."""
    from neurohover.compete import competition_config

    config = competition_config("ghh08", "continual", runs=1, episodes=2, n_steps=50, agent_settings={"window": 1, "safeguard_after": 10})
    (group,) = config.settings["groups"]
    assert group["settings"]["window"] == 1 and group["settings"]["safeguard_after"] == 10, group
    with pytest.raises(NeurohoverError, match="continual safeguard_after=50 is not below the episode's 50 control steps"):
        competition_config("ghh08", "continual", runs=1, episodes=2, n_steps=50, agent_settings={"safeguard_after": 50})
    argv = ["compete", "--task", "ghh08", "--agent", "continual", "--runs", "1", "--episodes", "1", "--episode-steps", "20"]
    rc, _, err = cli(*argv, "--agent-setting", "safeguard_after=20", "--out", str(tmp_path / "c"))
    assert rc == 2 and "continual safeguard_after=20 is not below the episode's 20 control steps" in err and not (tmp_path / "c").exists(), err


def test_a_config_whose_continual_safeguard_never_tests_is_refused_before_it_runs(tmp_path: Path, cli) -> None:
    """Twelfth trial, S3: a test-runs config giving continual a safeguard_after past its episodes failed in its first unit
    (exit 1) instead of being refused with the config (exit 2)."""
    config = tmp_path / "c.toml"
    config.write_text(tiny_test_runs("continual", name="mine", settings="{ safeguard_after = 20 }"))
    store = tmp_path / "s.sqlite"
    rc, _, err = cli("reproduce", str(config), "--store", str(store), "--no-progress")
    assert rc == 2 and "group 'continual': continual safeguard_after=20 is not below the episode's 20 control steps" in err and not store.exists(), err
