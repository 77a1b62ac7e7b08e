"""Bad-input trial 19, paths and files: '..' out of a directory to be made, dangling links as outputs, unknown manifest
keys, a config that is no UTF-8, progress on a terminal that reports no width (T19-11, T19-12, T19-13, T19-15, T19-16);
and from the twentieth: a policy set's manifest tables, its files' unknown keys, files that are no UTF-8, bench's progress
(T20-06 to T20-09)."""

from __future__ import annotations

import io
import json
import os
import re
import select
import shutil
import sys
from pathlib import Path
from types import SimpleNamespace

import pytest

from neurohover.errors import NeurohoverError
from neurohover.paths import output_dir, output_file, writing

FLY = ("fly", "--task", "ghh08", "--mdp", "train:0", "--episodes", "1")
EVOLVE = ("evolve", "--task", "ghh08", "--mdp", "train:0", "--budget", "3", "--episode-steps", "10")


def test_a_dotdot_out_of_a_directory_to_be_made_is_refused_and_nothing_is_made(tmp_path: Path, monkeypatch, cli) -> None:
    """T19-12: compete --out 'pp/../pp/x/..' made the stray directory pp/x and wrote into pp."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "pp").mkdir()
    with pytest.raises(NeurohoverError, match=r"--out 'pp/\.\./pp/x/\.\.': '\.\.' climbs out of 'pp/\.\./pp/x', which does not exist"):
        output_dir("pp/../pp/x/..", "--out")
    with pytest.raises(NeurohoverError, match=f"'..' climbs out of 'pp/q', which does not exist: .*give the path without it \\('{tmp_path}/pp/f.csv'\\)"):
        output_file("pp/q/../f.csv", "--out")
    argv = ("--agent", "baseline", "--runs", "1", "--episodes", "1", "--episode-steps", "10", "--out", "pp/../pp/x/..")
    rc, _, err = cli("compete", "--task", "ghh08", *argv)
    assert rc == 2 and "climbs out of 'pp/../pp/x'" in err, err
    assert sorted(os.listdir(tmp_path / "pp")) == []  # no pp/x, no results
    (tmp_path / "pp" / "x").mkdir()  # out of a directory that exists, '..' is the parent as ever
    assert output_dir("pp/x/..", "--out") == Path("pp/x/..") and output_file("pp/x/../f.csv", "--out") == Path("pp/x/../f.csv")


def test_a_dangling_link_is_refused_as_every_output_and_nothing_is_written_through_it(tmp_path: Path, monkeypatch, cli) -> None:
    """T19-12, T19-16: results --out LINK wrote its CSV where the link pointed (outside the work folder), compete and
    report said "File exists", evolve "a file, not a directory"; fly --record LINK wrote through it too."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "pp").mkdir()
    target = tmp_path / "outside_target"
    (tmp_path / "pp" / "out_link").symlink_to(target)
    (tmp_path / "pp" / "out_link.json").symlink_to(target)  # evolve --out takes a name ending .json only (T24-01)
    why = f"is a symbolic link to '{target}': a symbolic link to a missing target is not written through"
    for check in (lambda: output_file("pp/out_link", "--out"), lambda: output_dir("pp/out_link", "--out")):
        with pytest.raises(NeurohoverError, match=f"--out 'pp/out_link' {why}"):
            check()
    with pytest.raises(NeurohoverError, match=f"--out 'pp/out_link/r.csv' is 'pp/out_link', a symbolic link to '{target}'"):
        output_file("pp/out_link/r.csv", "--out")
    with pytest.raises(NeurohoverError, match=f"--out 'pp/out_link' {why}"):
        with writing("pp/out_link", "--out") as partial:
            partial.write_text("x")
    for argv in ((*FLY, "--record", "pp/out_link"), (*EVOLVE, "--out", "pp/out_link.json"), (*EVOLVE, "--out", "pp/out_link/p.json")):
        rc, _, err = cli(*argv)
        assert rc == 2 and "a symbolic link to a missing target is not written through" in err and "a file, not a directory" not in err, err
    assert not target.exists() and not os.path.lexists("pp/out_link.json.history.csv")
    target.write_text("")  # a link to a file that exists is written through, the link kept (empty: not a user's own, T55-A02)
    rc, _, err = cli(*EVOLVE, "--out", "pp/out_link.json")
    assert rc == 0 and (tmp_path / "pp" / "out_link.json").is_symlink() and json.loads(target.read_text())["genome"], err


def _set_with(tmp_path: Path, task: str, **extra) -> Path:
    from neurohover.policysets import policy_dir

    shutil.copytree(policy_dir(task), tmp_path / task)
    manifest = tmp_path / task / "manifest.json"
    manifest.write_text(json.dumps({**json.loads(manifest.read_text()), **extra}))
    return manifest


@pytest.mark.parametrize(("task", "key"), [("ghh08", "bogus"), ("ghh09", "saef"), ("fghh", "Sigma")])
def test_an_unknown_manifest_key_is_refused_naming_the_file_and_the_allowed_keys(tmp_path: Path, task: str, key: str) -> None:
    """T19-13: a policy set's manifest with "bogus": 1 was flown without a word (a misspelt key is lost the same way)."""
    from neurohover.policysets import load_policy_set

    manifest = _set_with(tmp_path, task, **{key: 1})
    with pytest.raises(NeurohoverError, match=f"policy-set manifest '{manifest}' has unknown keys '{key}': allowed task, sigma, budget, .*table3$"):
        load_policy_set(task, tmp_path)


def test_compete_refuses_a_policy_set_whose_manifest_has_an_unknown_key(tmp_path: Path, cli) -> None:
    """T19-13, as found: compete --policy-dir D ran without a word."""
    manifest = _set_with(tmp_path / "pd", "ghh08", bogus=1)
    argv = ("--agent", "model-free", "--runs", "1", "--episodes", "1", "--episode-steps", "10", "--out", str(tmp_path / "o"))
    rc, _, err = cli("compete", "--task", "ghh08", *argv, "--policy-dir", str(tmp_path / "pd"))
    assert rc == 2 and f"policy-set manifest '{manifest}' has unknown keys 'bogus': allowed task," in err and "safe" in err, err


@pytest.mark.parametrize(("text", "where"), [(b'name = "\xe9"\n', "line 1, column 9"), (b'\xef\xbb\xbfname = "a"\n# \xc3\xa9t\xe9\n', "line 2, column 5")])
def test_a_config_that_is_no_utf8_names_the_rule_and_the_byte(tmp_path: Path, cli, text: bytes, where: str) -> None:
    """T19-15: a Latin-1 config was "cannot be read (UnicodeDecodeError)"; the place counts characters, from after a byte-order mark."""
    from neurohover.experiments.config import load_config

    (tmp_path / "bad.toml").write_bytes(text)
    why = f"config '{tmp_path}/bad.toml' cannot be read: a config must be UTF-8 text, and byte 0xe9 at {where} is not"
    with pytest.raises(NeurohoverError, match=re.escape(why)):
        load_config(str(tmp_path / "bad.toml"), "quick")
    rc, _, err = cli("reproduce", str(tmp_path / "bad.toml"), "--store", str(tmp_path / "s.sqlite"))
    assert rc == 2 and why in err and not (tmp_path / "s.sqlite").exists(), err


def _drawn(master: int) -> str:
    """What the pseudo-terminal ``master`` has been sent so far."""
    out = b""
    while select.select([master], [], [], 0.2)[0]:
        chunk = os.read(master, 65536)
        if not chunk:
            break
        out += chunk
    return out.decode(errors="replace")


def _show_both_bars(learning, desc: str) -> None:
    """learn-model's elapsed-time bar, then evolve's bar at 10 of 40 episodes, on sys.stderr."""
    with learning._Ticker("learning a model"):
        pass
    bar = learning._Bar(40, desc)
    bar(SimpleNamespace(episodes=10, champion_return=-5.0, evaluations=10, episodes_per_second=100.0))
    bar.close()


def test_progress_is_drawn_on_a_terminal_that_reports_no_width_and_not_on_a_pipe(monkeypatch) -> None:
    """T19-11: on a pseudo-terminal nobody sized (width 0: script, docker exec -t), learn-model's and evolve's progress
    bars drew nothing, and the commands sat silent for minutes; a stream that is no terminal still sees nothing."""
    from neurohover.cli import learning

    master, slave = os.openpty()
    assert os.get_terminal_size(slave).columns == 0  # a fresh pseudo-terminal is never sized
    with os.fdopen(slave, "w") as terminal:
        monkeypatch.setattr(sys, "stderr", terminal)
        _show_both_bars(learning, "evolve ghh08/train:0")
        terminal.flush()
        drawn = _drawn(master)
    os.close(master)
    assert "learning a model: 00:00" in drawn and "evolve ghh08/train:0" in drawn and "10/40" in drawn, drawn
    pipe = io.StringIO()
    monkeypatch.setattr(sys, "stderr", pipe)
    _show_both_bars(learning, "evolve")
    assert pipe.getvalue() == ""


def test_every_commands_bar_is_drawn_on_a_terminal_that_reports_no_width(monkeypatch) -> None:
    """T19-11, the rest: fly, demo, evaluate-agent, reproduce (compete) and report each built their own tqdm bar, which
    drew nothing on an unsized pseudo-terminal; every bar now comes from neurohover.progress. fly shows it."""
    from neurohover.cli import main

    master, slave = os.openpty()
    with os.fdopen(slave, "w") as terminal:
        monkeypatch.setattr(sys, "stderr", terminal)
        assert main(["fly", "--task", "ghh08", "--mdp", "train:0", "--episodes", "3"]) == 0
        terminal.flush()
        drawn = _drawn(master)
    os.close(master)
    assert "fly ghh08/train:0" in drawn and "3/3" in drawn, drawn


@pytest.mark.parametrize(
    ("table", "value", "why"),
    [
        ("crashes_on_training_mdps", [[0]], "give 10 rows .* of 10 whole numbers >= 0"),
        ("crashes_on_training_mdps", [[0] * 10] * 9 + [[0] * 9 + [-1]], "give 10 rows .* of 10 whole numbers >= 0"),
        ("mean_return_on_training_mdps", [[1.5] * 10] * 10 + [[1.5] * 10], "give 10 rows .* of 10 finite numbers"),
    ],
)
def test_a_manifest_table_of_another_shape_than_the_set_is_refused(tmp_path: Path, cli, table: str, value, why: str) -> None:
    """T20-06: crashes_on_training_mdps=[[0]] in a set of 10 specialised policies on 10 training MDPs was accepted."""
    from neurohover.policysets import load_policy_set

    manifest = _set_with(tmp_path / "pd", "ghh08", **{table: value})
    with pytest.raises(NeurohoverError, match=f"policy-set manifest '{manifest}': {table}=.* is not allowed: {why}"):
        load_policy_set("ghh08", tmp_path / "pd")
    argv = ("--agent", "model-free", "--runs", "1", "--episodes", "2", "--episode-steps", "20", "--out", str(tmp_path / "o"))
    rc, _, err = cli("compete", "--task", "ghh08", *argv, "--policy-dir", str(tmp_path / "pd"))
    assert rc == 2 and f"{table}=" in err and "Traceback" not in err, err


def test_a_set_policy_file_with_an_unknown_key_is_refused_and_the_shipped_ones_are_not(tmp_path: Path, cli) -> None:
    """T20-07: generic.json with "zzz_extra": 1 in a policy directory was flown, where a manifest's unknown key is refused."""
    from neurohover.policysets import load_policy_set

    for task in ("ghh08", "ghh09", "fghh"):  # every key the shipped files (and so the builds) write is allowed
        load_policy_set(task)
    _set_with(tmp_path / "pd", "ghh08")
    generic = tmp_path / "pd" / "ghh08" / "generic.json"
    generic.write_text(json.dumps({**json.loads(generic.read_text()), "zzz_extra": 1}))
    why = f"policy set '{generic.parent}': generic.json (the generic policy) has unknown keys 'zzz_extra': allowed topology, genome,"
    with pytest.raises(NeurohoverError, match=re.escape(why)):
        load_policy_set("ghh08", tmp_path / "pd")
    argv = ("--agent", "model-free", "--runs", "1", "--episodes", "2", "--episode-steps", "20", "--out", str(tmp_path / "o"))
    rc, _, err = cli("compete", "--task", "ghh08", *argv, "--policy-dir", str(tmp_path / "pd"))
    assert rc == 2 and why in err, err


def test_a_manifest_or_policy_file_that_is_no_utf8_names_the_rule_and_the_byte(tmp_path: Path) -> None:
    """T20-08: a manifest of bytes ff fe was "cannot be read as JSON: Expecting value", a policy file's Latin-1
    "is not valid JSON: 'utf-8' codec can't decode"; both now say the rule and the place, as configs do (T19-15)."""
    from neurohover.policies import load_policy
    from neurohover.policysets import load_policy_set

    manifest = _set_with(tmp_path / "pd", "ghh08")
    manifest.write_bytes(b"\xff\xfe{}")
    why = f"policy-set manifest '{manifest}' cannot be read: a manifest must be UTF-8 text, and byte 0xff at line 1, column 1 is not"
    with pytest.raises(NeurohoverError, match=re.escape(why)):
        load_policy_set("ghh08", tmp_path / "pd")
    policy = tmp_path / "p.json"
    policy.write_bytes(b'\xef\xbb\xbf{"topology": "mlp",\n "note": "\xc3\xa9t\xe9"}')
    why = f"policy file '{policy}' cannot be read: a policy file must be UTF-8 text, and byte 0xe9 at line 2, column 13 is not"
    with pytest.raises(NeurohoverError, match=re.escape(why)):
        load_policy(policy)


def test_bench_shows_its_stages_on_a_terminal_and_nothing_on_a_pipe(monkeypatch) -> None:
    """T20-09: neurohover bench (not --quick) printed nothing on a terminal for 40 s and more; it now draws a bar over
    its stages on standard error, on a terminal only (its output, --json's too, is unchanged). Every measurement is a
    stub here: the stages are counted as run_benchmarks and benchmark_evolution go through them."""
    import importlib

    from neurohover import bench, bench_gpu

    evolve_module = importlib.import_module("neurohover.evolution.evolve")  # the module: the package exports the function

    def fake_evolve(*_args, _trace=None, _flown=None, **_kw):
        if _flown is not None:
            _flown["steps"] = 1
        return SimpleNamespace(seconds=1.0, episodes=1, steps=1)

    for name in ("reference_episodes_per_second", "kernel_episodes_per_second", "vector_env_steps_per_second", "test_run_seconds"):
        monkeypatch.setattr(bench, name, lambda *_a, **_k: 1.0)
    monkeypatch.setattr(bench, "lr_seconds_per_episode_of_flight_data", lambda: 1.0)
    monkeypatch.setattr(bench, "_replay_seconds", lambda *_a: 1.0)
    monkeypatch.setattr(evolve_module, "evolve", fake_evolve)
    monkeypatch.setattr(bench_gpu, "gpu_benchmarks", lambda *_a, **_k: {"status": "no CUDA device"})
    total = 11 + 2 * len({1, bench.numba.config.NUMBA_NUM_THREADS})
    master, slave = os.openpty()
    with os.fdopen(slave, "w") as terminal:
        monkeypatch.setattr(sys, "stderr", terminal)
        report = bench.run_benchmarks(quick=True)
        terminal.flush()
        drawn = _drawn(master)
    os.close(master)
    assert "bench: 100%" in drawn and f" {total}/{total} [" in drawn and "bench: evolve_generational_fixed5_1_cores" in drawn, drawn
    pipe = io.StringIO()
    monkeypatch.setattr(sys, "stderr", pipe)
    assert bench.run_benchmarks(quick=True) == report and pipe.getvalue() == ""
