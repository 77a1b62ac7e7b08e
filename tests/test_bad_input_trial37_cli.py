"""Bad-input trial 37 (the command line): FGHH's train:N / test:N at a sigma other than 0.3 are its seeded sets, and
what neurohover writes of them says so, as the MDPs flown are labelled (TaskFamily.set_name, the one place that decides
it): evolve --mdp test:0 --sigma 0.2 flew its whole budget, then refused its own policy file (metadata 'test:0' beside
target 'fghh/seeded-test:0'), and --resume the same; a record load_policy would refuse is now refused before flying
(T37-A01). compete --sigma 0.2 (the paper's FGHH sigma) wrote summary mdps 'test' beside seeded-test rows, which plot
--compete refused as two competitions; evaluate-agent --json wrote mdps 'test' for them too (T37-A02). A compete folder
of a version before a8bc471, whose episodes.csv holds an offline_seconds column, is read as that older layout; a column
no version writes is still refused (T37-A03)."""

from __future__ import annotations

import csv
import datetime
import json
import shutil
from pathlib import Path

import pytest


def refused(capsys, *argv: str) -> str:
    """What ``neurohover ARGV`` says as it refuses it (exit status 2), in this process."""
    from neurohover.cli import main

    try:
        rc = main(list(argv))
    except SystemExit as done:  # argparse's refusals exit; the commands' own return 2
        rc = done.code
    assert rc == 2
    return capsys.readouterr().err


TINY = ("--runs", "1", "--episodes", "2", "--episode-steps", "20")


@pytest.fixture(scope="module")
def fghh_compete(tmp_path_factory) -> Path:
    """compete's own folder for FGHH at sigma 0.2 (the paper's FGHH sigma; its test MDPs are the seeded ones)."""
    from neurohover.cli import main

    out = tmp_path_factory.mktemp("t37a02") / "c"
    assert main(["compete", "--task", "fghh", "--sigma", "0.2", "--agent", "baseline", *TINY, "--out", str(out)]) == 0
    return out


@pytest.fixture(scope="module")
def ghh08_compete(tmp_path_factory) -> Path:
    from neurohover.cli import main

    out = tmp_path_factory.mktemp("t37a03") / "c"
    assert main(["compete", "--task", "ghh08", "--agent", "baseline", *TINY, "--out", str(out)]) == 0
    return out


@pytest.mark.parametrize("spec", ["test:0", "train:1"])
def test_evolve_fghh_set_at_another_sigma_writes_its_policy(cli, tmp_path, spec):
    """T37-A01: the policy file is written, naming what was flown (seeded-*), and load_policy reads it."""
    from neurohover.policies import load_policy

    out = tmp_path / "a.json"
    rc, _, err = cli("evolve", "--task", "fghh", "--mdp", spec, "--sigma", "0.2", "--budget", "10", "--episode-steps", "20", "--out", str(out))
    assert rc == 0, err
    meta = load_policy(out).metadata
    assert meta["mdp"] == f"seeded-{spec}" and meta["target"] == f"fghh/seeded-{spec}"


def test_evolve_competition_sets_keep_their_names(cli, tmp_path):
    """T37-A01: at sigma 0.3 (and for GHH-08) test:N is the competition's MDP, named so."""
    from neurohover.policies import load_policy

    out = tmp_path / "g.json"
    assert cli("evolve", "--task", "ghh08", "--mdp", "test:2", "--budget", "10", "--episode-steps", "20", "--out", str(out))[0] == 0
    assert load_policy(out).metadata["mdp"] == "test:2"


def test_evolve_refuses_a_contradictory_record_before_flying(capsys, tmp_path, monkeypatch):
    """T37-A01: a record load_policy would refuse is refused before a single episode is flown (no checkpoint written)."""
    import neurohover.policies

    monkeypatch.setattr(neurohover.policies, "record_problem", lambda meta: f"its mdp {meta['mdp']!r} is not allowed: (a contradiction)")
    out = tmp_path / "a.json"
    err = refused(capsys, "evolve", "--task", "fghh", "--mdp", "test:0", "--sigma", "0.2", "--budget", "10", "--episode-steps", "20", "--out", str(out))
    assert "nothing is flown" in err and "(a contradiction)" in err
    assert not list(tmp_path.iterdir())


def test_compete_fghh_at_sigma_02_plots(cli, fghh_compete, tmp_path):
    """T37-A02: compete names the set its rows fly (seeded-test), and plot --compete reads its own folder."""
    summary = json.loads((fghh_compete / "summary.json").read_text())
    assert summary["mdps"] == "seeded-test"
    with open(fghh_compete / "episodes.csv", newline="") as f:
        assert {row["mdp"] for row in csv.DictReader(f)} == {"fghh/seeded-test:0"}
    rc, _, err = cli("plot", "--compete", str(fghh_compete), "--out", str(tmp_path / "p"))
    assert rc == 0, err


def test_compete_summary_of_the_older_layout_plots(cli, capsys, fghh_compete, tmp_path):
    """T37-A02: a summary written before the fix ('test' for the seeded test MDPs at sigma 0.2) is read; one naming
    another set, or 'test' at sigma 0.3 beside seeded rows, is still refused as a contradiction."""
    older = tmp_path / "older"
    shutil.copytree(fghh_compete, older)
    summary = json.loads((older / "summary.json").read_text())
    (older / "summary.json").write_text(json.dumps({**summary, "mdps": "test"}))
    rc, _, err = cli("plot", "--compete", str(older), "--out", str(tmp_path / "p"))
    assert rc == 0, err
    for edit in ({"mdps": "train"}, {"mdps": "seeded-train"}, {"mdps": "test", "sigma": 0.3}):
        (older / "summary.json").write_text(json.dumps({**summary, **edit}))
        err = refused(capsys, "plot", "--compete", str(older), "--out", str(tmp_path / "q"))
        assert "the two are of different competitions" in err and "seeded-test" in err


def test_evaluate_agent_json_names_the_seeded_set(cli, tmp_path):
    """T37-A02 (minor note): evaluate-agent --json names what its rows flew, as compete does."""
    out = tmp_path / "e.json"
    argv = ("evaluate-agent", "--task", "fghh", "--policy", "baseline", "--n-mdps", "1", "--episode-steps", "20", "--json", str(out))
    rc, printed, err = cli(*argv, "--sigma", "0.2")
    assert rc == 0, err
    assert json.loads(out.read_text())["mdps"] == "seeded-test"
    assert printed.startswith("fghh seeded-test MDPs 0-0,")  # its screen says so too
    rc, printed, _ = cli(*argv)  # sigma 0.3: the competition's test MDPs
    assert rc == 0 and printed.startswith("fghh test MDPs 0-0,")
    assert json.loads(out.read_text())["mdps"] == "test"


def _add_column(folder: Path, name: str, value: str) -> None:
    path = folder / "episodes.csv"
    lines = path.read_text().splitlines()
    path.write_text("\n".join([f"{lines[0]},{name}"] + [f"{line},{value}" for line in lines[1:]]) + "\n")


def test_plot_reads_an_older_offline_seconds_column(cli, capsys, ghh08_compete, tmp_path):
    """T37-A03: offline_seconds, each row's, as compete wrote it before a8bc471, is read; a column no version writes
    is refused, naming both."""
    older = tmp_path / "older"
    shutil.copytree(ghh08_compete, older)
    _add_column(older, "offline_seconds", "0.000000")
    rc, _, err = cli("plot", "--compete", str(older), "--out", str(tmp_path / "p"))
    assert rc == 0, err
    odd = tmp_path / "odd"
    shutil.copytree(ghh08_compete, odd)
    _add_column(odd, "online_seconds", "0.0")
    err = refused(capsys, "plot", "--compete", str(odd), "--out", str(tmp_path / "q"))
    assert "column 'online_seconds' is not allowed" in err and "older versions also offline_seconds" in err


# ------------------------------------------------------------------------------------------- T37-A04


def test_a_setting_that_takes_none_takes_the_word_none_from_the_command_line() -> None:
    """T37-A04: `--setting init_mutate_frac=none` was "must be a probability in [0, 1]", though documented as float or None."""
    from neurohover.errors import NeurohoverError
    from neurohover.evolution.config import make_settings

    generational = make_settings("generational", "ne", {"init_mutate_frac": "none", "init_mutate_std": "None"})
    assert generational.init_mutate_frac is None and generational.init_mutate_std is None
    assert make_settings("steady-state", "ne", {"mutation_floor": "NONE"}).mutation_floor is None
    with pytest.raises(NeurohoverError, match="bad generational settings"):  # a setting that takes no None still refuses it
        make_settings("generational", "ne", {"mutate_frac": "none"})


def test_a_resume_names_every_differing_setting_at_once() -> None:
    """T37-A04: a resume named one differing setting per try (three runs to learn three differences)."""
    from neurohover.evolution.records import config_difference

    saved = {"method": "generational", "settings": {"elitist": True, "fitness": "return", "pop_size": 50, "init_mutate_frac": None}}
    given = {"method": "generational", "settings": {"elitist": False, "fitness": "inv-log-error", "pop_size": 50, "init_mutate_frac": 0.5}}
    found = config_difference("config", saved, given)
    assert found is not None and [part.split(":")[0] for part in found.split("; ")] == [
        "config.settings.elitist",
        "config.settings.fitness",
        "config.settings.init_mutate_frac",
    ], found
    assert config_difference("config", saved, saved) is None


def test_a_resumed_build_counts_only_the_runs_of_its_own_seed(tmp_path):
    """T37 (minor note): after stages/build.json was edited by hand to another seed, build-policies said "resuming the
    interrupted build ... (1 runs finished)" and then flew that run again (its stage is named by the other seed's run)."""
    from neurohover.policysets import build_policy_set

    lines: list[str] = []

    def stop_after_the_first_run(line: str) -> None:
        lines.append(line)
        if "champion" in line:
            raise KeyboardInterrupt

    tiny = {"budget": 2, "safety_episodes": 1, "n_steps": 10}
    with pytest.raises(KeyboardInterrupt):
        build_policy_set("ghh08", tmp_path, seed=0, progress=stop_after_the_first_run, **tiny)
    with pytest.raises(KeyboardInterrupt):  # the same build: its first run is kept, its second flown
        build_policy_set("ghh08", tmp_path, seed=0, progress=stop_after_the_first_run, **tiny)
    assert any(line.endswith("(1 runs finished)") for line in lines), lines
    state = tmp_path / "ghh08.building" / "stages" / "build.json"
    state.write_text(json.dumps({**json.loads(state.read_text()), "seed": 1}))  # edited to match the next command
    lines.clear()
    with pytest.raises(KeyboardInterrupt):
        build_policy_set("ghh08", tmp_path, seed=1, progress=stop_after_the_first_run, **tiny)
    assert any(line.endswith("(0 runs finished)") for line in lines), lines  # seed 0's two runs are not seed 1's
    assert not any("kept from the interrupted build" in line for line in lines), lines


def test_a_toml_date_is_echoed_as_toml_writes_it(capsys, tmp_path):
    """T37 (minor note): a TOML date in a config was echoed as Python's repr, `seed = datetime.date(1979, 5, 27)`."""
    from neurohover.errors import brief
    from neurohover.experiments.config import CONFIG_DIR

    text = (CONFIG_DIR / "fig2.toml").read_text()
    kept = [line for line in text.splitlines() if not line.startswith(("aliases", "name =", "title ="))]
    config = tmp_path / "d.toml"
    config.write_text("\n".join(['name = "d"', *kept]).replace("seed = 2011", "seed = 1979-05-27", 1) + "\n")
    err = refused(capsys, "reproduce", str(config), "--store", str(tmp_path / "s.sqlite"))
    assert "seed = 1979-05-27 (a date) is not allowed: expected an integer" in err and "datetime" not in err, err
    config.write_text(config.read_text().replace("seed = 1979-05-27", "seed = 2011").replace('name = "d"', 'name = "d"\ntitle = 07:32:00'))
    assert "title = 07:32:00 (a time) is not allowed: give text" in refused(capsys, "reproduce", str(config), "--store", str(tmp_path / "s.sqlite"))
    assert brief(datetime.datetime(1979, 5, 27, 7, 32)) == "1979-05-27T07:32:00 (a date and time)"
    assert not (tmp_path / "s.sqlite").exists()


def test_a_generational_checkpoint_of_a_preset_names_it(capsys, cli, tmp_path):
    """T37-A04 (left then): resuming a generational checkpoint of other settings named each differing setting, but not
    that they were a preset's (an older version's checkpoint runs raw-elitist's rules): the message gives the preset
    and the settings beside it, as the command line and as Python take them, and the command it gives resumes."""
    out = str(tmp_path / "p.json")
    run = ("evolve", "--task", "fghh", "--mdp", "G", "--episode-steps", "10", "--out", out)
    rc, _, err = cli(*run, "--budget", "100", "--preset", "raw-elitist", "--setting", "pop_size=40")
    assert rc == 0, err
    err = refused(capsys, *run, "--budget", "140", "--resume")
    hint = "its settings are the 'raw-elitist' preset's but pop_size: evolve --preset raw-elitist --setting pop_size=40"
    assert hint in err and "(settings={'preset': 'raw-elitist', 'pop_size': 40} in Python)" in err, err
    err = refused(capsys, *run, "--budget", "140", "--resume", "--preset", "authors-script")
    assert hint in err, err
    rc, _, err = cli(*run, "--budget", "140", "--resume", "--preset", "raw-elitist", "--setting", "pop_size=40")
    assert rc == 0, err
    err = refused(capsys, *run, "--budget", "180", "--resume", "--preset", "raw-elitist")  # nearer than any preset: no hint
    assert "settings.pop_size: the checkpoint's 40, given 50" in err and "preset's" not in err, err


def test_checkpoint_every_inf_checkpoints_at_the_end_only(cli, tmp_path):
    """Noticed in trial 37, a documented choice: `--checkpoint-every inf` is no periodic checkpoint, the one at the
    end (and on a stop) still written, from which --resume continues."""
    out = tmp_path / "p.json"
    run = ("evolve", "--task", "ghh08", "--episode-steps", "10", "--out", str(out), "--checkpoint-every", "inf")
    rc, _, err = cli(*run, "--budget", "20")
    assert rc == 0, err
    state = json.loads((tmp_path / "p.json.checkpoint.json").read_text())
    assert state["counters"]["episodes"] >= 20 and state["budget"] == 20
    rc, _, err = cli(*run, "--budget", "100", "--resume")  # the first generation of 50 overran 20
    assert rc == 0 and json.loads((tmp_path / "p.json.checkpoint.json").read_text())["counters"]["episodes"] >= 100, err


def test_a_relative_policy_directory_is_read_from_the_working_directory(monkeypatch, tmp_path):
    """Noticed in trial 37, a documented choice (README, Reproducing the paper): a config's relative `policies = "DIR"`
    is read from the working directory, as command-line paths are; when it is missing, the message says where it looked."""
    from neurohover.errors import NeurohoverError
    from neurohover.experiments.external import load_external

    monkeypatch.chdir(tmp_path)
    with pytest.raises(NeurohoverError, match=f"no such directory in the working directory '{tmp_path}'; build it with"):
        load_external("ghh08", "pd")
    (tmp_path / "pd").mkdir()
    with pytest.raises(NeurohoverError, match="pd") as err:  # found there: what it holds is checked next
        load_external("ghh08", "pd")
    assert "no such directory" not in str(err.value)
