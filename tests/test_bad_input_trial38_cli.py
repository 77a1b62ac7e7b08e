"""Bad-input trial 38 (the command line): SIGPWR, SIGIO, SIGSTKFLT and the real-time signals ended evolve and reproduce
without a word, leaving their lock files (T38-A04): they stop a command as SIGTERM does. The writers that refuse a
policy set's directory gave compete --policy-dir's refusal of other files as their reason, where a set's loader leaves
files other than JSON alone (T38-A06): the reason now says what the loader does, and that choice is pinned."""

from __future__ import annotations

import os
import shutil
import signal
import sys
from pathlib import Path

import pytest

LINUX = sys.platform.startswith("linux")


@pytest.mark.skipif(not LINUX, reason="Linux's SIGPWR, SIGSTKFLT and real-time signals")
def test_every_signal_that_ends_a_process_quietly_stops_a_command_as_sigterm_does() -> None:
    from neurohover.errors import Terminated, raise_terminated, stop_signals
    from neurohover.procs import stop_words

    also = {signal.SIGPWR, signal.SIGIO, signal.SIGSTKFLT, signal.SIGRTMIN, signal.SIGRTMIN + 1, signal.SIGRTMAX}
    assert also <= set(stop_signals()) and not also & set(stop_signals(command=False))
    assert not {signal.SIGQUIT, signal.SIGTRAP, signal.SIGSEGV, signal.SIGCHLD, signal.SIGWINCH} & set(stop_signals())
    for signum in also:
        with pytest.raises(Terminated) as caught:
            raise_terminated(signum, None)
        assert stop_words(caught.value) == ("terminated", 128 + signum)


@pytest.mark.slow
@pytest.mark.skipif(not LINUX, reason="real processes signalled, found in /proc")
def test_evolve_stopped_by_a_real_time_signal_saves_its_checkpoint_and_says_so(tmp_path: Path) -> None:
    from test_bad_input_trial35_cli import assert_evolve_stops_on  # type: ignore[import-not-found]

    assert_evolve_stops_on(tmp_path, signal.SIGRTMIN + 1)  # one with no name of its own


@pytest.mark.slow
def test_a_policy_sets_other_files_are_left_alone_and_writers_say_so(cli, tmp_path: Path) -> None:
    """T38-A06: compete --policy-dir flies a set beside a store, flight data or a folder of the user's (notes, as a
    README is), and refuses a JSON file no build writes; the writers' refusal gives that as its reason."""
    from neurohover.policysets import SHIPPED

    shutil.copytree(SHIPPED / "ghh08", tmp_path / "sets" / "ghh08")
    (tmp_path / "sets" / "ghh08" / "notes").mkdir()
    (tmp_path / "sets" / "ghh08" / "f.npz").write_bytes(b"PK\x03\x04")
    argv = ("compete", "--task", "ghh08", "--agent", "model-free", "--runs", "1", "--episodes", "2", "--episode-steps", "10")
    rc, _, err = cli(*argv, "--policy-dir", str(tmp_path / "sets"), "--out", str(tmp_path / "c"))
    assert rc == 0, err
    rc, _, err = cli("fly", "--task", "ghh08", "--episodes", "1", "--record", str(tmp_path / "sets" / "ghh08" / "r.npz"))
    assert rc == 2 and "a set holds only what build-policies writes (its loader refuses a JSON file no build writes" in err, err
    (tmp_path / "sets" / "ghh08" / "extra.json").write_text("{}")
    rc, _, err = cli(*argv, "--policy-dir", str(tmp_path / "sets"), "--out", str(tmp_path / "d"))
    assert rc == 2 and "extra.json" in err, err


@pytest.mark.slow
def test_evaluate_agent_imports_a_callable_from_the_working_directory(tmp_path: Path) -> None:
    """T38-A03: the documented `neurohover evaluate-agent --callable my_agents:act` beside my_agents.py was "No module
    named 'my_agents'" through the installed script, whose import path starts with the script's folder, not the
    working directory (python -m neurohover has it). Run as such a script: one in another folder."""
    import subprocess

    script, work = tmp_path / "bin" / "neurohover_script.py", tmp_path / "work"
    script.parent.mkdir()
    work.mkdir()
    script.write_text("import sys\nfrom neurohover.cli import main\nsys.exit(main())\n")
    (work / "my_agents_t38.py").write_text("import numpy as np\n\n\ndef act(obs):\n    return np.zeros((len(obs), 4))\n")
    argv = ["evaluate-agent", "--task", "ghh08", "--callable", "my_agents_t38:act", "--n-mdps", "1", "--episode-steps", "10"]
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"} | {"PYTHONPATH": str(Path(__file__).resolve().parents[1])}
    done = subprocess.run([sys.executable, str(script), *argv], cwd=work, capture_output=True, text=True, timeout=300, env=env)
    assert done.returncode == 0 and done.stdout.splitlines()[2].startswith("agent "), done.stderr[-2000:]
    assert "my_agents_t38" not in " ".join(sys.path)


def test_a_model_option_given_another_kind_of_input_names_it(cli, tmp_path: Path) -> None:
    """T38-A05: --sb3 given a neurohover policy file or flight data, and --rl-zoo a folder of no run, answered "needs
    stable_baselines3: pip install ..." where it is not installed; the input is checked first, whether it is or not."""
    policy, data = tmp_path / "e1.json", tmp_path / "r1.npz"
    base = ("evaluate-agent", "--task", "ghh08", "--n-mdps", "1", "--episode-steps", "10")
    from neurohover import baseline_policy, save_policy

    save_policy(baseline_policy(), policy)
    assert cli("fly", "--task", "ghh08", "--episodes", "1", "--record", str(data))[0] == 0
    rc, _, err = cli(*base, "--sb3", str(policy))
    assert rc == 2 and "is a policy file of neurohover's, not a Stable-Baselines3 model file: fly it with --policy" in err, err
    rc, _, err = cli(*base, "--sb3", str(data))
    assert rc == 2 and "is flight data (a NumPy archive) of neurohover's, not a Stable-Baselines3 model file" in err, err
    rc, _, err = cli(*base, "--rl-zoo", str(tmp_path))
    assert rc == 2 and "is not an RL Zoo run folder: expected one ENV.zip (or best_model.zip) in it" in err, err
    for _, _, err in (cli(*base, "--sb3", str(policy)), cli(*base, "--rl-zoo", str(tmp_path))):
        assert "pip install" not in err
