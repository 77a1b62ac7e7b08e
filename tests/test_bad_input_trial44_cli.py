"""Bad-input trial 44 (the command line): docs/optimisers.md's `--optimiser` spelling was refused, evolve and
build-policies defining only --optimizer (T44-A01); evolve --resume without --budget dropped the checkpoint's budget
and ran on to the plateau (a 100-episode run flew 2,758, its policy's budget null) without a word (T44-A03); a subnormal
or negligible --obs-noise (1e-320, 5e-324, 1e-17) flew exact sensors recorded as noisy, where drift walk=5e-324 is
refused (T44-A04)."""

from __future__ import annotations

import json
import math

import pytest

from neurohover.errors import NeurohoverError
from neurohover.sim.constants import MIN_NOISE
from neurohover.tasks.drift import MIN_WALK
from neurohover.tasks.sensor import MIN_LEVEL, MIN_STD, Sensor

EVOLVE = ("evolve", "--task", "ghh08", "--mdp", "train:0", "--episode-steps", "20", "--validation-episodes", "1")


# T44-A01 -------------------------------------------------------------------------------------------------------------


def test_the_help_of_evolve_and_build_policies_shows_both_spellings(capsys) -> None:
    from neurohover.cli.app import build_parser

    parser = build_parser()
    for command in ("evolve", "build-policies"):
        with pytest.raises(SystemExit):
            parser.parse_args([command, "--help"])
        out = capsys.readouterr().out
        assert "--optimizer {" in out and "--optimiser {" in out, out


@pytest.mark.parametrize("spelling", ["--optimiser", "--optimizer", "--optim", "--optimis"])
def test_evolve_takes_the_optimiser_spelling(cli, tmp_path, spelling: str) -> None:
    out = tmp_path / "p.json"
    rc, _, err = cli(*EVOLVE, "--budget", "10", "--out", str(out), f"{spelling}=cma", "--json")
    assert rc == 0, err
    assert json.loads(out.read_text())["optimizer"] == "cma"


@pytest.mark.parametrize(
    "given",
    [("--optimizer", "ne", "--optimiser", "cma"), ("--optimiser", "cma", "--optimizer", "cma"), ("--optimiser", "ne", "--optimiser", "cma")],
)
def test_both_spellings_together_are_the_option_given_twice(capsys, tmp_path, given) -> None:
    from neurohover.cli import main

    for command in (EVOLVE, ("build-policies", "--task", "ghh08", "--episode-steps", "20")):
        with pytest.raises(SystemExit) as done:  # argparse's refusal, in one line
            main([*command, "--budget", "10", "--out", str(tmp_path / "o.json"), *given])
        assert done.value.code == 2
        err = capsys.readouterr().err
        assert "--optimizer/--optimiser is given more than once: give it once" in err, err
    assert not list(tmp_path.iterdir())


# T44-A03 -------------------------------------------------------------------------------------------------------------


def test_resume_without_budget_keeps_the_checkpoints_budget(cli, tmp_path) -> None:
    out = tmp_path / "q.json"
    rc, first, err = cli(*EVOLVE, "--budget", "20", "--out", str(out), "--json")
    assert rc == 0, err
    flown = json.loads(first)["episodes"]
    rc, again, err = cli(*EVOLVE, "--out", str(out), "--resume", "--json")  # it ran on to the plateau, its budget null
    assert rc == 0, err
    summary = json.loads(again)
    assert summary["episodes"] == flown and summary["stop_reason"] == "budget"
    assert json.loads(out.read_text())["budget"] == 20
    assert "Traceback" not in err


def test_resume_with_a_budget_given_raises_it_and_a_lower_one_is_refused(cli, tmp_path) -> None:
    out = tmp_path / "q.json"
    rc, first, err = cli(*EVOLVE, "--budget", "20", "--out", str(out), "--json")
    assert rc == 0, err
    flown = json.loads(first)["episodes"]
    rc, _, err = cli(*EVOLVE, "--budget", str(flown - 1), "--out", str(out), "--resume")
    assert rc == 2 and "a resumed run's budget may only be raised" in err, err
    rc, again, err = cli(*EVOLVE, "--budget", str(flown + 50), "--out", str(out), "--resume", "--json")
    assert rc == 0, err
    assert json.loads(again)["episodes"] >= flown + 50
    assert json.loads(out.read_text())["budget"] == flown + 50


def test_resume_without_a_checkpoint_is_still_refused_by_name(cli, tmp_path) -> None:
    rc, _, err = cli(*EVOLVE, "--out", str(tmp_path / "none.json"), "--resume")
    assert rc == 2 and "--resume: no checkpoint" in err and "none.json.checkpoint.json" in err, err


# T44-A04 -------------------------------------------------------------------------------------------------------------


def test_the_sensor_floor_is_the_drifts() -> None:
    assert MIN_STD == MIN_WALK == MIN_NOISE == 2.0**-52
    assert math.isclose(MIN_LEVEL, MIN_STD / 0.01)


@pytest.mark.parametrize("level", [1e-320, 5e-324, 1e-17, 1e-300, MIN_LEVEL / 2])
def test_a_negligible_noise_level_is_refused(level: float) -> None:
    with pytest.raises(
        NeurohoverError, match=r"sensor noise level=.* is out of range, too small to change a reading .*allowed 0 \(exact\) or a number in 2.23e-14..1000"
    ):
        Sensor.at_level(level)
    with pytest.raises(NeurohoverError, match="too small to change a reading"):
        Sensor.parse(repr(level))
    with pytest.raises(NeurohoverError, match="too small to change a reading"):
        Sensor.of({"level": level})


@pytest.mark.parametrize("group", ["velocity", "position", "rates", "attitude"])
@pytest.mark.parametrize("std", [1e-320, 5e-324, 1e-17])
def test_a_negligible_group_std_is_refused(group: str, std: float) -> None:
    said = rf"sensor {group}={std!r} is out of range, too small to change a reading .*allowed 0 \(exact\) or a std in 2.23e-16..100"
    with pytest.raises(NeurohoverError, match=said):
        Sensor(**{group: std})
    with pytest.raises(NeurohoverError, match=said):
        Sensor.parse(f"{group}={std!r}")


def test_zero_and_the_floor_itself_are_allowed() -> None:
    assert Sensor.at_level(0).exact and Sensor.parse("0").exact and Sensor.parse("velocity=0").exact
    assert Sensor.at_level(MIN_LEVEL).attitude >= MIN_STD
    assert Sensor(velocity=MIN_STD).velocity == MIN_STD


@pytest.mark.parametrize("noise", ["1e-320", "5e-324", "1e-17", "velocity=1e-320"])
def test_fly_and_compete_refuse_a_negligible_obs_noise(cli, tmp_path, noise: str) -> None:
    rc, _, err = cli("fly", "--task", "ghh08", "--episodes", "1", f"--obs-noise={noise}")
    assert rc == 2 and "too small to change a reading" in err and "Traceback" not in err, err
    out = tmp_path / "c"
    rc, _, err = cli(
        "compete", "--task", "ghh08", "--agent", "baseline", "--runs", "1", "--episodes", "2", "--episode-steps", "20", "--obs-noise", noise, "--out", str(out)
    )
    assert rc == 2 and "too small to change a reading" in err, err
    assert not out.exists()


def test_a_stop_during_the_final_validation_names_the_checkpoint_and_resume(tmp_path, monkeypatch, capsys) -> None:
    """A Ctrl-C (or SIGTERM) while evolve validated its champion said only "interrupted"; the run is over and its
    checkpoint kept, and --resume validates the champion without evolving again."""
    import importlib

    from neurohover.cli import main

    evolve_module = importlib.import_module("neurohover.evolution.evolve")  # the package's `evolve` is the function

    out = tmp_path / "v.json"
    argv = ["evolve", "--task", "ghh08", "--mdp", "train:0", "--budget", "20", "--episode-steps", "20", "--validation-episodes", "1", "--out", str(out)]
    real = evolve_module.validation_return

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(evolve_module, "validation_return", interrupted)
    assert main(argv) == 130
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert "interrupted during the champion's validation" in err and "v.json.checkpoint.json" in err and "--resume" in err, err
    assert not out.exists()
    monkeypatch.setattr(evolve_module, "validation_return", real)
    assert main([*argv, "--resume"]) == 0
    assert out.exists()
