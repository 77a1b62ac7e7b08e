"""Issue 37, the tenth fresh trial: each case it found gives one clear message (exit 2 / NeurohoverError) or is
taken as a user would expect; the Python API's (equality, SB3VecEnv) are in test_bad_input_trial10_api.py."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from neurohover.errors import NeurohoverError


@pytest.mark.parametrize("value", ["0", "-3", "abc", "", "٣", "99999"])  # 99999: numba's SIGSEGV without a word (T18-2)
def test_numba_threads_of_the_environment_that_numba_cannot_take_are_named(value: str, tmp_path: Path) -> None:
    """T1: NUMBA_NUM_THREADS=0 was numba's traceback from every command, --help too; 'abc' its warning, then its default."""
    env = {**os.environ, "NUMBA_NUM_THREADS": value}
    proc = subprocess.run([sys.executable, "-m", "neurohover", "--help"], env=env, cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2 and proc.stdout == "", proc.stderr
    allowed = "give a whole number in 1..4096 (numba's threads), or unset it"
    assert proc.stderr == f"neurohover: error: environment variable NUMBA_NUM_THREADS={value!r} is not allowed: {allowed}\n"
    code = "import neurohover"
    proc = subprocess.run([sys.executable, "-c", code], env=env, cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 1 and proc.stderr.strip().endswith(
        f"NeurohoverError: environment variable NUMBA_NUM_THREADS={value!r} is not allowed: give a whole number in 1..4096 (numba's threads), or unset it"
    )


def test_an_agent_made_for_one_family_is_not_run_on_another() -> None:
    """S2: a model-free agent made for GHH-08 flew FGHH's MDPs with GHH-08's policies (make_agent refuses it for FGHH)."""
    import neurohover as nh
    from neurohover.agents import run_test
    from neurohover.agents.registry import make_agent

    g8, fghh = nh.get_task_family("ghh08"), nh.get_task_family("fghh")
    agent = make_agent("model-free", g8)
    with pytest.raises(NeurohoverError, match=r"agent 'model-free' was made for ghh08, but the run's family is fghh \(sigma 0.3\): make the agent"):
        run_test(agent, fghh, fghh.test_mdps()[0], episodes=1, n_steps=10)
    assert run_test(agent, g8, g8.test_mdps()[0], episodes=1, n_steps=10).returns.shape == (1,)


def test_resume_names_the_checkpoints_value_and_the_given_one(tmp_path: Path, cli) -> None:
    """U2: a changed option on --resume was "seed differ" or "target differ", neither value named."""
    argv = ["evolve", "--task", "ghh08", "--episode-steps", "20", "--out", str(tmp_path / "b.json"), "--validation-episodes", "1"]
    assert cli(*argv, "--budget", "6")[0] == 0
    rc, _, err = cli(*argv, "--budget", "100", "--resume", "--seed", "1")
    assert rc == 2 and "was written by a different run (seed: the checkpoint's 0, given 1); resume with the same" in err, err
    rc, _, err = cli(*argv, "--budget", "100", "--resume", "--mdp", "train:1")
    assert rc == 2 and "(target.mdp.label: the checkpoint's 'ghh08/zero', given 'ghh08/train:1')" in err, err


def test_a_hybrid_agent_without_two_safe_policies_names_the_manifest(tmp_path: Path, cli) -> None:
    """U3: "the hybrid agent needs exactly 2 safe specialised policies, got 1" named no file."""
    import json
    import shutil

    from neurohover.policysets import policy_dir

    shutil.copytree(policy_dir("ghh08"), tmp_path / "pd" / "ghh08")
    manifest = tmp_path / "pd" / "ghh08" / "manifest.json"
    manifest.write_text(json.dumps({**json.loads(manifest.read_text()), "safe": [6]}))
    argv = ["compete", "--task", "ghh08", "--agent", "hybrid", "--runs", "1", "--episodes", "2", "--episode-steps", "20"]
    rc, _, err = cli(*argv, "--out", str(tmp_path / "c"), "--policy-dir", str(tmp_path / "pd"))
    assert rc == 2 and f"policy-set manifest '{manifest}': safe=[6] is not allowed: give a list of the 2 safe" in err, err  # at load (T32-B12)


def test_sigma_beside_the_zero_setting_says_which_mdps_take_it(cli) -> None:
    """U4: fly --task fghh --sigma 0.5 was refused with "give another --mdp", not saying zero is the default or what is."""
    rc, _, err = cli("fly", "--task", "fghh", "--sigma", "0.5", "--episodes", "1")
    assert rc == 2 and "--sigma 0.5 does nothing with --mdp zero (the default)" in err and "give --mdp sample, train:N or test:N" in err, err


def test_policy_tables_compare_by_value() -> None:
    """T2 (PolicyTable): == raised NumPy's "truth value of an array is ambiguous"."""
    import numpy as np

    from neurohover.evaluate import PolicyTable

    a = PolicyTable.from_genomes(np.full((2, 40), np.nan), "slp")
    assert a == PolicyTable.from_genomes(np.full((2, 40), np.nan), "slp") and a != PolicyTable.from_genomes(np.zeros((2, 40)), "slp")
    with pytest.raises(TypeError, match="unhashable"):
        hash(a)


@pytest.mark.slow
def test_a_store_of_the_competition_run_with_another_policy_set_is_refused_and_the_folder_kept(tmp_path: Path, cli) -> None:
    """U1, S3: the refusal named two hashes and --update / --fresh, which compete does not take; a failed competition
    rewrote its --out folder's episodes.csv (a header only, or another competition's rows under its summary)."""
    import json
    import shutil

    from neurohover.manifest import DIGESTS, genome_digest
    from neurohover.policies import load_policy
    from neurohover.policysets import policy_dir

    shutil.copytree(policy_dir("ghh08"), tmp_path / "pd" / "ghh08")
    argv = ["compete", "--task", "ghh08", "--agent", "generic", "--runs", "1", "--episodes", "2", "--episode-steps", "20", "--policy-dir", str(tmp_path / "pd")]
    assert cli(*argv, "--out", str(tmp_path / "c1"))[0] == 0
    other = ["compete", "--task", "ghh08", "--agent", "baseline", "--runs", "1", "--episodes", "3", "--episode-steps", "20"]
    assert cli(*other, "--out", str(tmp_path / "c2"))[0] == 0
    before = {p.name: p.read_bytes() for p in (tmp_path / "c2").iterdir() if p.is_file()}
    generic = tmp_path / "pd" / "ghh08" / "generic.json"
    policy = json.loads(generic.read_text())
    generic.write_text(json.dumps({**policy, "genome": [g * 0.5 for g in policy["genome"]]}))
    manifest = json.loads((generic.parent / "manifest.json").read_text())  # another build's set: its manifest records it (T36-B05)
    manifest[DIGESTS]["generic.json"] = genome_digest(load_policy(generic))
    (generic.parent / "manifest.json").write_text(json.dumps(manifest))
    rc, _, err = cli(*argv, "--out", str(tmp_path / "c2"), "--store", str(tmp_path / "c1" / "results.sqlite"))
    assert rc == 2 and "holds this competition (compete-ghh08-generic) run with other settings (the policy set's files differ" in err, err
    assert "--update" not in err and "--fresh" not in err
    assert {p.name: p.read_bytes() for p in (tmp_path / "c2").iterdir() if p.is_file()} == before


def test_a_second_evolve_on_an_output_being_written_is_refused(tmp_path: Path, cli) -> None:
    """S1: two evolve runs on one --out both said they finished, leaving one's policy beside the other's checkpoint."""
    from neurohover.paths import sole_writer

    out = tmp_path / "k.json"
    argv = ["evolve", "--task", "ghh08", "--mdp", "train:0", "--budget", "30", "--episode-steps", "20", "--out", str(out)]
    with sole_writer(out, "--out"):  # another run writing it (the lock is the OS's: another process's alike)
        (tmp_path / ".k.json.lock").write_text("4242\n")
        rc, _, err = cli(*argv)
        assert rc == 2 and f"--out '{out}' is being written by another run (pid 4242): wait for it to end, or give another --out" in err, err
        assert not out.exists()
    rc, _, err = cli(*argv)
    assert rc == 0 and out.is_file() and not (tmp_path / ".k.json.lock").exists(), err
