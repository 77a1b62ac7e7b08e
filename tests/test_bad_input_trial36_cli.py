"""Bad-input trial 36 (the command line): an integer of more than 4,300 digits in --set, --setting, --agent-setting or
a config, tomllib's ValueError a traceback (T36-A01); --vers (argparse's prefix of --version) dropping the command
(T36-A02); --progress/--no-progress repeated or abbreviated, the last winning (T36-A03); --version --version naming ''
(T36-A04); a .net file's integer of 5,000 digits refused with Python's advice to call sys.set_int_max_str_digits()
(T36-A05); `settings ne` refused though evolve's help says `settings OPTIMIZER` lists them (T36-A06). Trial 37's weak
ones: --jobs bounded by the machine's cores, not the process's (T37-A06); a shipped alias unknown to results, report and
wins (T37-A05); "letters" meaning ASCII letters (T37-A07)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

HUGE = "1" * 4301


def refused(capsys, *argv: str) -> str:
    """What ``neurohover ARGV`` says as argparse refuses it (exit status 2), in this process."""
    from neurohover.cli import main

    with pytest.raises(SystemExit) as done:
        main(list(argv))
    assert done.value.code == 2
    return capsys.readouterr().err


CONFIG = """name = "mine"
kind = "test_runs"
[settings]
task = "ghh08"
seed = 1
groups = [{ agent = "baseline", mdps = "test", n_mdps = 1 }]
[scales.quick]
episodes = EPISODES
n_steps = 20
"""


@pytest.mark.parametrize(
    "argv",
    [
        ["reproduce", "CONFIG", "--store", "STORE", "--set", f"episodes={HUGE}"],
        ["reproduce", "CONFIG", "--store", "STORE", "--set", f"seed=-{HUGE}"],
        ["reproduce", "CONFIG", "--store", "STORE", "--set", f'groups=[{{agent="baseline",mdps="test",n_mdps={HUGE}}}]'],
        ["evolve", "--task", "ghh08", "--budget", "10", "--episode-steps", "20", "--setting", f"pop_size={HUGE}", "--out", "OUT.json"],
        ["compete", "--task", "ghh08", "--agent", "continual", "--runs", "1", "--episodes", "2", "--agent-setting", f"cooldown={HUGE}", "--out", "OUT"],
        ["reproduce", "BIG", "--store", "STORE"],
    ],
    ids=["set", "set-negative", "set-inline-table", "evolve-setting", "agent-setting", "config-file"],
)
def test_an_integer_past_pythons_digit_limit_is_refused_by_name(cli, tmp_path: Path, argv: list[str]) -> None:
    (tmp_path / "c.toml").write_text(CONFIG.replace("EPISODES", "2"))
    (tmp_path / "big.toml").write_text(CONFIG.replace("EPISODES", HUGE))
    paths = {"CONFIG": tmp_path / "c.toml", "BIG": tmp_path / "big.toml", "STORE": tmp_path / "s.sqlite", "OUT": tmp_path / "out"}
    argv = [str(paths[a]) if a in paths else str(paths["OUT"]) + ".json" if a == "OUT.json" else a for a in argv]
    rc, _, err = cli(*argv, *(["--no-progress"] if argv[0] == "reproduce" else []))
    assert rc == 2 and "Traceback" not in err and "more than 4300 digits" in err and "set_int_max_str_digits" not in err, err
    assert not (tmp_path / "s.sqlite").exists() and not (tmp_path / "out").exists()


@pytest.mark.parametrize("first", ["--vers", "--versio", "--v"])
def test_an_abbreviated_version_with_a_command_is_refused_not_dropped(capsys, first: str) -> None:
    err = refused(capsys, first, "fly", "--task", "ghh08", "--episodes", "2")
    assert "--version takes no other arguments, got 'fly --task ghh08 --episodes 2'" in err, err


def test_version_given_twice_is_named_so(capsys) -> None:
    err = refused(capsys, "--version", "--vers")
    assert "--version is given more than once (--version --vers)" in err and "got ''" not in err, err


def test_a_version_alone_or_abbreviated_alone_prints_it(capsys) -> None:
    from neurohover import __version__
    from neurohover.cli import main

    for arg in ("--version", "--vers"):
        with pytest.raises(SystemExit) as done:
            main([arg])
        assert done.value.code == 0 and capsys.readouterr().out.strip() == f"neurohover {__version__}"


@pytest.mark.parametrize(
    "switches", [["--prog", "--no-progress"], ["--no-prog", "--progress"], ["--progress", "--progress"], ["--no-progress", "--no-progress"]]
)
def test_the_progress_switch_given_twice_in_any_spelling_is_refused(capsys, tmp_path: Path, switches: list[str]) -> None:
    (tmp_path / "c.toml").write_text(CONFIG.replace("EPISODES", "2"))
    err = refused(capsys, "reproduce", str(tmp_path / "c.toml"), "--store", str(tmp_path / "s.sqlite"), *switches)
    assert "--progress/--no-progress is given more than once: give it once" in err, err
    assert not (tmp_path / "s.sqlite").exists()


@pytest.mark.parametrize("line", ["n {} 0 0 0.0", "n 1 {} 0 0.0"])
def test_a_net_files_integer_of_thousands_of_digits_is_refused_with_what_is_allowed(cli, tmp_path: Path, line: str) -> None:
    net = tmp_path / "a.net"
    net.write_text(line.format("1" * 5000) + "\n")
    rc, _, err = cli("fly", "--task", "ghh08", "--episodes", "1", "--policy", str(net))
    assert rc == 2 and "give an integer of at most 18 digits" in err and "set_int_max_str_digits" not in err, err


def test_settings_of_the_ne_optimiser_are_its_methods(cli) -> None:
    rc, out, err = cli("settings", "ne")
    assert rc == 0, err
    assert "steady-state: Settings of SteadyStateNE" in out and "generational:" in out and "pop_size = 50" in out


# ------------------------------------------------------------------------------------------- trial 37, weak findings


@pytest.mark.slow
@pytest.mark.skipif(not hasattr(os, "sched_setaffinity"), reason="CPU affinity is Linux's")
def test_jobs_are_bounded_by_the_cores_the_process_may_use() -> None:
    """T37-A06: under `taskset -c 0` --jobs 2 was taken (two workers on one core) and the run recorded as on 2 cores."""
    script = "from neurohover.experiments.executors import check_jobs\ncheck_jobs(1)\ncheck_jobs(2)\n"
    proc = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120, preexec_fn=lambda: os.sched_setaffinity(0, {0}))
    assert "NeurohoverError: --jobs 2 is out of range: allowed an integer in 1..1 (the cores this process may use)" in proc.stderr, proc.stderr[-2000:]


def test_a_config_name_of_a_non_ascii_letter_is_refused_saying_ascii(cli, tmp_path: Path) -> None:
    """T37-A07: 'café' was refused as not '1-100 letters', though é is one: the rule is ASCII letters."""
    (tmp_path / "c.toml").write_text(CONFIG.replace("EPISODES", "2").replace('name = "mine"', 'name = "café"'))
    rc, _, err = cli("reproduce", str(tmp_path / "c.toml"), "--store", str(tmp_path / "s.sqlite"), "--no-progress")
    assert rc == 2 and "name = 'café' is not allowed: give 1-100 ASCII letters (A-Z, a-z), digits" in err, err


@pytest.mark.slow
def test_results_wins_and_report_take_a_shipped_alias_as_reproduce_does(cli, committed_store: Path, tmp_path: Path) -> None:
    """T37-A05: reproduce table3 ran fig2, but results, report and wins said the store holds no experiment 'table3'."""
    by_alias = cli("results", "table3", "--store", str(committed_store), "--scale", "quick")
    assert by_alias[0] == 0 and by_alias[1] == cli("results", "fig2", "--store", str(committed_store), "--scale", "quick")[1]
    rc, _, err = cli("wins", "table3", "--store", str(committed_store), "--scale", "quick")
    assert rc == 2 and "experiment 'fig2' (quick) has no stored test runs" in err, err  # found, and named by its name
    rc, _, err = cli("report", "table3", "--store", str(committed_store), "--scale", "quick", "--out", str(tmp_path / "r"))
    assert rc == 0 and (tmp_path / "r" / "report.md").is_file(), err
