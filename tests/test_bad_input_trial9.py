"""Issue 37, the ninth fresh trial: each case it found gives one clear message (exit 2 / NeurohoverError) or is
taken as a user would expect; the integrations' and the files' cases are in test_bad_input_trial9_*.py."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
from test_bad_input_trial7 import _config, tiny_store  # noqa: F401  (tiny_store: the fixture)

from neurohover.errors import NeurohoverError


@pytest.mark.slow
def test_a_path_of_undecodable_bytes_is_printed_under_a_strict_utf8_stdout(tmp_path: Path) -> None:
    """T3: fly --record g<0xff>.npz wrote its file, then raised UnicodeEncodeError printing the path (a strict stdout is
    Python's default under en_US.UTF-8)."""
    name = os.fsdecode(b"g\xff.npz")
    env = {**os.environ, "PYTHONIOENCODING": "utf-8:strict"}
    cmd = [sys.executable, "-m", "neurohover", "fly", "--task", "ghh08", "--episodes", "1", "--record", name]
    proc = subprocess.run(cmd, cwd=tmp_path, env=env, capture_output=True, text=True, errors="replace", timeout=300)
    assert proc.returncode == 0 and "Traceback" not in proc.stderr, proc.stderr
    assert "flight data: g\\udcff.npz" in proc.stdout and (tmp_path / name).is_file()


@pytest.mark.slow
@pytest.mark.parametrize(("make", "reason"), [(lambda p: p.write_bytes(b"abc\xff\xfe def"), "it is not UTF-8 text"), (Path.mkdir, "Is a directory")])
def test_an_unreadable_discussion_is_named_not_a_traceback_or_skipped(make, reason, tmp_path, cli, tiny_store) -> None:  # noqa: F811
    """T4: a discussion file that is not UTF-8 was a UnicodeDecodeError in report; a directory in its place was skipped."""
    (tmp_path / "rep" / "discussion").mkdir(parents=True)
    make(tmp_path / "rep" / "discussion" / "mytest-quick.md")
    rc, _, err = cli("report", "--store", str(tiny_store), "--out", str(tmp_path / "rep"))
    assert rc == 2 and f"discussion '{tmp_path}/rep/discussion/mytest-quick.md' cannot be read ({reason})" in err, err
    assert "damaged" not in err


@pytest.mark.slow
def test_a_discussion_saved_with_a_byte_order_mark_is_read_without_it(tmp_path, cli, tiny_store) -> None:  # noqa: F811
    (tmp_path / "rep" / "discussion").mkdir(parents=True)
    (tmp_path / "rep" / "discussion" / "mytest-quick.md").write_bytes("\ufeffOur words.".encode())
    rc, _, err = cli("report", "--store", str(tiny_store), "--out", str(tmp_path / "rep"))
    assert rc == 0, err
    assert "### Discussion\n\nOur words.\n" in (tmp_path / "rep" / "report.md").read_text()


def test_files_saved_with_a_byte_order_mark_are_read_and_a_positive_return_is_refused(tmp_path, cli) -> None:
    """U2: a config or an episodes.csv starting with a byte-order mark (Windows editors) was "Invalid statement (at line
    1, column 1)" and "no column run"; S11: a positive return, impossible (every reward is <= 0), was plotted."""
    from neurohover.experiments import load_config

    config = _config(tmp_path)
    bom = tmp_path / "bom.toml"
    bom.write_bytes(b"\xef\xbb\xbf" + config.read_bytes())
    assert load_config(str(bom), "quick").hash == load_config(str(config), "quick").hash
    folder = tmp_path / "c"
    folder.mkdir()
    lines = "run,mdp,episode,return,crashed,steps\n0,m,0,-5.0,0,20\n0,m,1,-6.0,0,20\n"
    (folder / "episodes.csv").write_bytes(b"\xef\xbb\xbf" + lines.encode())
    rc, _, err = cli("plot", "--compete", str(folder), "--out", str(tmp_path / "p"))
    assert rc == 0 and (tmp_path / "p" / "compete.png").is_file(), err
    (folder / "episodes.csv").write_text(lines.replace("-6.0", "5.0"))
    rc, _, err = cli("plot", "--compete", str(folder), "--out", str(tmp_path / "p"))
    assert rc == 2 and "line 3: return '5.0' is not an episode's (finite, in [-1.75e+10, 0]: every reward is minus a sum of squares)" in err, err


def test_a_pop_size_below_the_default_elite_says_the_elite_is_a_default(tmp_path, cli) -> None:
    """U4: --setting pop_size=7 was refused over elite_size=49 without saying that 49 is the default, not the user's."""
    argv = ["evolve", "--task", "ghh08", "--mdp", "train:0", "--budget", "60", "--episode-steps", "20", "--out", str(tmp_path / "x.json")]
    rc, _, err = cli(*argv, "--setting", "pop_size=7")
    assert rc == 2 and "elite_size=49 (its default) must be smaller than pop_size=7: give elite_size below it too" in err, err
    rc, _, err = cli(*argv, "--setting", "pop_size=7", "--setting", "elite_size=9")
    assert rc == 2 and "elite_size=9 must be smaller than pop_size=7" in err and "default" not in err, err


@pytest.mark.parametrize(
    "env_id",
    ["neurohover/GHH08-v0", "neurohover/FGHH-Short-v0", "neurohover/GHH09-RL-v0", "neurohover/GHH08-DelayedSensors-v0", "neurohover/GHH08-AbruptChange-v0"],
)
def test_an_episode_after_a_refused_first_reset_flies(env_id: str) -> None:
    """T11: after a refused first reset, the first step of a corrected episode was a TypeError in Gymnasium 1.4's
    passive checker (it marks its reset check done before the reset returns); the ids now register without it."""
    import gymnasium as gym
    import numpy as np

    env = gym.make(env_id)
    with pytest.raises(NeurohoverError, match="seed=-1 is out of range"):
        env.reset(seed=-1)
    env.reset(seed=0)
    _, reward, *_ = env.step(np.zeros(env.action_space.shape, dtype=env.action_space.dtype))
    assert np.isfinite(reward) and reward <= 0


@pytest.mark.parametrize("mdps", ["test", "sample"])
def test_exclude_own_on_mdps_without_specialised_policies_is_refused(mdps: str, tmp_path: Path) -> None:
    """S10: exclude_own = true on test or sampled MDPs (only training MDPs have specialised policies) did nothing."""
    from neurohover.experiments import load_config

    path = tmp_path / "x.toml"
    path.write_text(
        f'name = "x"\nkind = "test_runs"\n[settings]\ntask = "ghh08"\nseed = 1\nepisodes = 2\nn_steps = 20\npolicies = "shipped"\n'
        f'[[settings.groups]]\nagent = "model-free"\nmdps = "{mdps}"\nn_mdps = 2\nexclude_own = true\n[scales.quick]\n'
    )
    with pytest.raises(NeurohoverError, match=f"groups\\[0\\]: exclude_own = true does nothing on mdps = '{mdps}'"):
        load_config(str(path), "quick")
    path.write_text(path.read_text().replace(f'mdps = "{mdps}"', 'mdps = "train"'))
    assert load_config(str(path), "quick").typed.groups[0].exclude_own is True


def test_ec_mer_learns_with_the_policy_that_flew_the_data_not_a_file_of_its_name(tmp_path, cli, monkeypatch) -> None:
    """S6: learn-model --method ec-mer looked the flight data's policy file name up from its own directory, so another
    p.json there was the closed loop it learned (or, with none there, the command failed)."""
    import json

    (tmp_path / "pa").mkdir()
    (tmp_path / "pb").mkdir()
    (tmp_path / "pa" / "p.json").write_text(json.dumps({"topology": "slp", "genome": [0.0] * 36 + [0.02, 0, 0, 0.23]}))
    (tmp_path / "pb" / "p.json").write_text("not the policy that flew")
    monkeypatch.chdir(tmp_path / "pa")
    rc, _, err = cli("fly", "--task", "ghh08", "--episodes", "1", "--policy", "p.json", "--record", "f.npz")
    assert rc == 0, err
    monkeypatch.chdir(tmp_path / "pb")
    rc, out, err = cli("learn-model", "--flight-data", "../pa/f.npz", "--method", "ec-mer", "--budget", "2", "--out", "m.json")
    assert rc == 0 and "ec-mer model written to m.json" in out, err


def test_a_store_given_through_a_symbolic_link_has_the_same_writer_lock(tmp_path: Path) -> None:
    """S8: through a link to the store, a second run locked a lock file of the link's name and wrote beside the first
    (it then said "finished ... 7/41 done")."""
    from neurohover.experiments import Store

    (tmp_path / "link.sqlite").symlink_to(tmp_path / "s.sqlite")
    with Store(tmp_path / "s.sqlite") as first:
        first.lock()
        with Store(tmp_path / "link.sqlite") as second:
            assert second.lock_path == first.lock_path == tmp_path / "s.sqlite.lock"
            with pytest.raises(
                NeurohoverError, match=f"results store '{tmp_path}/link.sqlite' is in use: another open Store of this process \\(pid {os.getpid()} "
            ):
                second.lock()


def test_an_output_through_a_symbolic_link_writes_its_file_and_a_dangling_one_is_named(tmp_path: Path, cli) -> None:
    """U3: --store given as a link whose target's directory is missing was "cannot create a file in '.'"; a result
    written through a link replaced the link by a file."""
    (tmp_path / "dangling.sqlite").symlink_to("nowhere/x.sqlite")
    rc, _, err = cli("reproduce", "fig2", "--store", str(tmp_path / "dangling.sqlite"))
    assert rc == 2 and f"is a symbolic link to 'nowhere/x.sqlite', whose directory '{tmp_path}/nowhere' does not exist" in err, err
    (tmp_path / "real").mkdir()
    (tmp_path / "real" / "p.json").write_text("")  # a link to a file is written through; one to nothing is refused (T19-12); empty, not a user's own (T55-A02)
    (tmp_path / "p.json").symlink_to(tmp_path / "real" / "p.json")
    rc, _, err = cli("evolve", "--task", "ghh08", "--mdp", "train:0", "--budget", "3", "--episode-steps", "20", "--out", str(tmp_path / "p.json"))
    assert rc == 0, err
    assert (tmp_path / "p.json").is_symlink() and (tmp_path / "real" / "p.json").is_file()


def test_joined_recordings_of_two_policies_name_no_one_policy_for_ec_mer(tmp_path, cli) -> None:
    """S6 (continued): the sum of two recordings kept the second's policy for every episode."""
    import json

    from neurohover.flightdata import FlightData

    (tmp_path / "p.json").write_text(json.dumps({"topology": "slp", "genome": [0.0] * 36 + [0.02, 0, 0, 0.23]}))
    for name, policy in (("a.npz", "baseline"), ("b.npz", str(tmp_path / "p.json"))):
        assert cli("fly", "--task", "ghh08", "--episodes", "1", "--policy", policy, "--record", str(tmp_path / name))[0] == 0
    a, b = FlightData.load(tmp_path / "a.npz"), FlightData.load(tmp_path / "b.npz")
    assert (a + a).metadata["policy_flown"] == a.metadata["policy_flown"]
    (a + b).save(tmp_path / "ab.npz")
    rc, _, err = cli("learn-model", "--flight-data", str(tmp_path / "ab.npz"), "--method", "ec-mer", "--budget", "2", "--out", str(tmp_path / "m.json"))
    assert rc == 2 and "were flown by more than one policy (joined recordings): EC-MER learns one closed loop; give --policy FILE" in err, err
