"""Bad paths and conflicting options on the command line: each must end with one clear message.

Run as a script (``python3 tests/bad_input.py``) it flies every case in a fresh process and prints
one line per case: exit status, whether a traceback appeared, and the message (``--every K``:
every K-th case). The test suite (tests/test_bad_input.py) runs every case in-process and every
8th through the script.
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
from pathlib import Path

# (arguments, a piece of the expected message); paths are relative to the directory made by setup().
CASES: list[tuple[list[str], str]] = [
    (["fly", "--task", "ghh08", "--episodes", "1", "--record", "adir"], "is a directory"),
    (["fly", "--task", "ghh08", "--episodes", "1", "--record", "afile/x.npz"], "is a file, not a directory"),
    (["fly", "--task", "ghh08", "--episodes", "1", "--record", "/proc/x.npz"], "cannot create a file in '/proc'"),
    (["fly", "--task", "ghh08", "--policy", "/proc/self/mem"], "cannot read this policy file"),
    (["fly", "--task", "ghh08", "--policy", "adir"], "is a directory"),
    (["evolve", "--task", "ghh08", "--budget", "1000000000", "--out", "adir"], "is a directory"),
    (["evolve", "--task", "ghh08", "--budget", "1000000000", "--out", "/proc/p.json"], "cannot create a file in '/proc'"),
    (["evolve", "--task", "ghh08", "--budget", "1000000000", "--out", "afile/p.json"], "is a file, not a directory"),
    (["learn-model", "--flight-data", "fd.npz", "--method", "lr", "--out", "adir"], "is a directory"),
    (["learn-model", "--flight-data", "j.json", "--method", "lr", "--out", "m.json"], "not a neurohover flight-data file"),
    (["learn-model", "--flight-data", "adir", "--method", "lr", "--out", "m.json"], "is a directory"),
    (["learn-model", "--flight-data", "/proc/self/mem", "--method", "lr", "--out", "m.json"], "cannot read this flight-data file"),
    (["learn-model", "--flight-data", "missing.npz", "--method", "lr", "--out", "m.json"], "no such flight-data file"),
    (["learn-model", "--flight-data", "fd.npz", "--method", "ec-mer", "--wind-model", "sinusoid", "--out", "m.json"], "applies to --method lr only"),
    (["compete", "--task", "ghh09", "--agent", "model-free", "--wind-model", "sinusoid", "--out", "q"], "--wind-model applies to the agents that learn models"),
    (["results", "fig2", "--store", "store.sqlite", "--out", "adir"], "is a directory"),
    (["results", "fig2", "--store", "adir"], "is a directory"),
    (["report", "--store", "store.sqlite", "--out", "afile"], "is a file; give a directory"),
    (["compete", "--task", "ghh08", "--agent", "baseline", "--runs", "1", "--episodes", "2", "--out", "afile"], "is a file; give a directory"),
    (
        ["compete", "--task", "ghh08", "--agent", "model-free", "--runs", "1", "--episodes", "2", "--out", "q", "--policy-dir", "afile"],
        "is a file; give a directory",
    ),
    (["build-policies", "--task", "ghh08", "--budget", "10", "--out", "afile"], "is a file; give a directory"),
    (["build-policies", "--task", "ghh08", "--budget", "10", "--out", "q", "--lineage", "tree"], "lineage 'tree' is not known: allowed chain, independent"),
    (["reproduce", "fig2", "--store", "adir"], "is a directory"),
    (["reproduce", "fig2", "--store", "/proc/s.sqlite"], "cannot create a file in '/proc'"),
    (["reproduce", "adir/x.toml", "--store", "s.sqlite"], "does not exist"),
    (["reproduce", "fig2", "--store", "s.sqlite", "--executor", "ray", "--address", "notanaddress"], "'notanaddress'"),
    (["reproduce", "fig2", "--store", "s.sqlite", "--executor", "ray", "--address", "127.0.0.1:1"], "127.0.0.1:1"),
    # option conflicts
    (["fly", "--task", "ghh08", "--wind", "1,1", "--mdp", "train:0"], "cannot be combined with --mdp train:0"),
    (["fly", "--task", "ghh08", "--params", "1,1", "--mdp", "test:3"], "cannot be combined with --mdp test:3"),
    (["evolve", "--task", "ghh08", "--wind", "1,1", "--mdp", "train:0", "--out", "p.json"], "cannot be combined with --mdp train:0"),
    (["learn-model", "--flight-data", "fd.npz", "--method", "lr", "--budget", "5", "--out", "m.json"], "not to --method lr"),
    (["learn-model", "--flight-data", "fd.npz", "--method", "ec-meno", "--estimator", "ols", "--out", "m.json"], "--estimator applies to --method lr only"),
    (["learn-model", "--flight-data", "fd.npz", "--method", "lr", "--policy", "baseline", "--out", "m.json"], "--policy applies to --method ec-mer only"),
    (["reproduce", "fig2", "--store", "s.sqlite", "--address", "127.0.0.1:6379"], "add --executor ray"),
    (["compete", "--task", "ghh08", "--agent", "baseline", "--safeguard-box", "0.3", "--out", "q"], "hybrid agents only"),
    # Sizes that would exhaust memory, more processes than cores, seeds out of the one range, unknown policy sources.
    (["fly", "--task", "ghh08", "--episodes", "10000000000000"], "--episodes 10000000000000 is out of range"),
    (["compete", "--task", "ghh08", "--agent", "baseline", "--runs", "1000000000", "--out", "q"], "runs=1000000000 x episodes=1000 is out of range"),
    (
        ["compete", "--task", "ghh08", "--agent", "baseline", "--runs", "100000", "--episodes", "10000", "--out", "q"],
        "at most 100,000 runs and 100,000,000 episodes",
    ),
    (["compete", "--task", "ghh08", "--agent", "baseline", "--runs", "1", "--episodes", "2", "--out", "q", "--jobs", "64"], "--jobs 64 is out of range"),
    (
        ["compete", "--task", "ghh08", "--agent", "baseline", "--runs", "1", "--episodes", "2", "--out", "q", "--seed", str(2**70)],
        "is out of range: allowed an integer in 0..2**63-1",
    ),
    (["reproduce", "fig7", "--store", "s.sqlite", "--set", 'policies="bought"'], "policies = 'bought' is not allowed: give 'evolve', 'shipped' or a directory"),
    # issue 37: sizes refused up front (not after an evolution), every --seed in one range, no silent defaults
    (
        ["evolve", "--task", "ghh08", "--budget", "10", "--validation-episodes", "10000000000000", "--out", "p.json"],
        "--validation-episodes 10000000000000 is out of range: 10,000,000,000,000 episodes, at most 100,000,000 in one call",
    ),
    (["demo", "--episodes", "10000000000000"], "episodes=10000000000000 is out of range"),
    (["demo", "--mdps", "-1"], "--mdps -1 is out of range: allowed 0..10"),
    (["demo", "--episodes", "0"], "--episodes 0 is out of range: allowed an integer >= 1"),
    (["evaluate-agent", "--task", "ghh08", "--rl-zoo", "nonexist"], "--rl-zoo 'nonexist': no such directory"),  # was "needs SB3"
    (["evaluate-agent", "--task", "ghh08", "--sb3", "nonexist.zip"], "--sb3 'nonexist.zip': no such SB3 model file"),
    (["fly", "--task", "fghh", "--params=1e300,1,1,1,1,1,1,1,1,1,1"], "must lie in [-10000, 10000]"),  # flew NaN returns
    # third trial: an output onto an input destroyed it (the store became CSV, the flight data a model)
    (["results", "fig2", "--store", "store.sqlite", "--out", "store.sqlite"], "--out 'store.sqlite' is the file of --store"),
    (["reproduce", "fig2", "--store", "store.sqlite", "--fresh", "--only", "x"], "--fresh discards every stored result, and --only"),  # sixth trial
    (["learn-model", "--flight-data", "fd.npz", "--method", "lr", "--out", "fd.npz"], "--out 'fd.npz' is the file of --flight-data"),
    (["reproduce", "fig2", "--store", "s.sqlite", "--set", "sensor={noise=1, noise=2}"], "VALUE is not valid TOML (Duplicate inline table key 'noise')"),
    (["build-policies", "--task", "ghh08", "--budget", "10", "--seed", "-1", "--out", "q"], "seed=-1 is out of range: allowed an integer in 0..2**63-1"),
    (["evolve", "--task", "ghh08", "--budget", "10", "--seed", "-5", "--out", "p.json"], "seed=-5 is out of range"),
    (["fly", "--task", "ghh08", "--mdp", ""], "unknown MDP ''"),
    (["build-policies", "--task", "fghh", "--lineage", "chain", "--budget", "10", "--out", "q"], "lineage applies to the GHH tasks' specialised policies"),
    (["build-policies", "--task", "ghh08", "--fghh-budget", "10", "--out", "q"], "--fghh-budget) applies to task fghh"),
    (["build-policies", "--task", "fghh", "--budget", "20", "--fghh-budget", "0", "--out", "q"], "--fghh-budget 0 is out of range: allowed >= 1"),
    (["evaluate-agent", "--task", "ghh08", "--policy", "baseline", "--algo", "sac"], "--algo sac applies to --rl-zoo and --sb3 models, not to --policy"),
    (["fly", "--task", "ghh08", "--policy", ""], "policy file is empty"),  # was "'.' is not a file" (second trial)
    (["learn-model", "--flight-data", "fd.npz", "--method", "ec-mer", "--out", "m.json", "--policy", ""], "--policy is empty"),
    (["evolve", "--task", "ghh08", "--out", "x.json", "--seed-policy", "/tmp"], "--seed-policy '/tmp': is a directory"),
    (
        ["compete", "--task", "ghh08", "--agent", "baseline", "--runs", "1", "--episodes", "2", "--policy-dir", ".", "--out", "q"],
        "--policy-dir applies to agents that fly a policy set's policies, not to --agent baseline",
    ),
    (["learn-model", "--flight-data", "fd.npz", "--method", "lr", "--seed", "3", "--out", "m.json"], "--seed applies to the evolutionary methods"),
]


def setup(directory: Path) -> Path:
    """Make the files the cases name: a directory, a plain file, a JSON file, flight data, a store."""
    from neurohover.evaluate import evaluate_jobs
    from neurohover.experiments import Store
    from neurohover.policies import baseline_policy
    from neurohover.tasks import get_task_family

    (directory / "adir").mkdir()
    (directory / "afile").write_text("not a directory\n")
    (directory / "j.json").write_text("{}\n")
    ev = evaluate_jobs([baseline_policy()], [get_task_family("ghh08").zero()], [0], [0], [0], record=[True], n_steps=50)
    ev.flight_data.save(directory / "fd.npz")
    Store(directory / "store.sqlite").close()
    return directory


def run_case(args: list[str], cwd: Path, timeout: float = 120.0) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "neurohover", *args], cwd=cwd, capture_output=True, text=True, timeout=timeout)


def main(argv: list[str] | None = None) -> int:
    """Fly every case (or, with ``--every K``, every K-th) in a fresh process; one line each."""
    argv = sys.argv[1:] if argv is None else argv
    step = int(argv[1]) if argv[:1] == ["--every"] else 1
    cases = CASES[::step]
    bad = 0
    with tempfile.TemporaryDirectory() as tmp:
        cwd = setup(Path(tmp))
        for args, expected in cases:
            proc = run_case(args, cwd)
            lines = proc.stderr.strip().splitlines()
            ok = proc.returncode == 2 and "Traceback" not in proc.stderr and len(lines) == 1 and expected in proc.stderr
            bad += not ok
            print(
                f"{'ok ' if ok else 'BAD'} exit={proc.returncode} traceback={'Traceback' in proc.stderr} "
                f"neurohover {' '.join(args)} -> {lines[-1] if lines else '(no message)'}"
            )
    print(f"{len(cases) - bad} of {len(cases)} cases refused cleanly")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
