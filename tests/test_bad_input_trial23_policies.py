"""Bad input, trial 23: policy files and policy-set manifests whose record of their runs contradicts itself (T23-11).

A policy file written by ``neurohover evolve --out p.json`` or ``neurohover build-policies`` records the run that evolved
it; hand-edited, a budget of -5, n_steps of 0, more evaluations than episodes, a steady-state run over a task family, a
return of 5.0, a stop reason 'zzz' or a seed of -3 were all read by load_policy and flown by ``neurohover compete
--policy-dir``, as were a manifest's budget or n_steps of 0 and a manifest contradicting its own policies. Each file kind
is now checked against itself in one place (neurohover.manifest: policy_record_problem, and the manifest's checks), naming
the file, the field, the value and what is allowed; every file the code writes still loads."""

from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import Any

import pytest
from conftest import CliRun

from neurohover import load_policy
from neurohover.errors import NeurohoverError
from neurohover.manifest import policy_record_problem
from neurohover.policysets import SHIPPED, build_policy_set, load_policy_set

#: Evolve runs whose champions' files must load: (name, extra arguments of ``neurohover evolve --task ghh08``).
EVOLVE_RUNS = {
    "steady": ["--budget", "10"],
    "generational": ["--mdp", "G", "--budget", "100"],  # its champion_return is a fitness 1/ln(error) > 0
    "race": ["--mdp", "G", "--budget", "100", "--resampling", "race:0.2"],
    "cma": ["--optimizer", "cma", "--budget", "30"],
    "cma-over-G": ["--mdp", "G", "--optimizer", "cma", "--budget", "30"],
    "openai-es": ["--optimizer", "openai-es", "--budget", "30"],
    "uh-cma": ["--optimizer", "uh-cma", "--budget", "30"],
    "plateau": [],  # no budget: steady state runs to its plateau
}


@pytest.fixture(scope="module")
def written(tmp_path_factory) -> Path:
    """What the code writes: a champion of each run of EVOLVE_RUNS (20-step episodes) and small GHH-08 (chain lineage,
    its ancestor too), GHH-09 (OpenAI-ES) and FGHH sets, in one directory (sets under ``sets/``)."""
    from neurohover.cli import main

    where = tmp_path_factory.mktemp("written23")
    for name, extra in EVOLVE_RUNS.items():
        out = where / f"{name}.json"
        argv = ["evolve", "--task", "ghh08", "--episode-steps", "20", "--validation-episodes", "1", "--out", str(out), "--json", *extra]
        assert main(argv) == 0, name
    build_policy_set("ghh08", where / "sets", budget=10, n_steps=20, safety_episodes=1)
    build_policy_set("ghh09", where / "sets", budget=10, n_steps=20, safety_episodes=1, optimizer="openai-es")
    build_policy_set("fghh", where / "sets", budget=10, fghh_budget=50, n_steps=20)
    return where


@pytest.mark.slow
def test_every_file_the_code_writes_still_loads(written: Path) -> None:
    """The published sets (ancestors included), each evolve output and each built set load, file by file and as sets."""
    for name in EVOLVE_RUNS:
        policy = load_policy(written / f"{name}.json")
        assert policy_record_problem(policy.metadata) == ""
    assert load_policy(written / "generational.json").metadata["champion_return"] > 0  # a fitness, not a return
    assert load_policy(written / "plateau.json").metadata["stop_reason"] == "plateau"
    for root in (SHIPPED, written / "sets"):
        files = sorted(p for p in root.rglob("*.json") if p.name != "manifest.json")
        assert any(p.name == "ancestor.json" for p in files)
        for path in files:
            load_policy(path)
        for task in ("ghh08", "ghh09", "fghh"):
            load_policy_set(task, None if root == SHIPPED else root)


def _edited_policy(written: Path, at: Path, name: str, **changes: Any) -> Path:
    """A copy of ``written``'s evolve output ``name`` at ``at`` with ``changes`` to its record."""
    data = json.loads((written / f"{name}.json").read_text())
    data.update(changes)
    at.write_text(json.dumps(data))
    return at


@pytest.mark.slow
@pytest.mark.parametrize(
    ("name", "changes", "says"),
    [
        ("steady", {"budget": -5}, "its budget -5 is not allowed: allowed an integer in 1..10,000,000,000 (episodes), or null"),
        ("steady", {"budget": "10"}, "its budget '10' is not allowed: allowed an integer in 1..10,000,000,000"),
        ("steady", {"n_steps": 0}, "its n_steps 0 is not allowed: allowed an integer in 1..10,000,000 (control steps per episode)"),
        ("steady", {"seed": -3}, "its seed -3 is not allowed: allowed an integer in 0..2**63-1 (the run's root seed)"),
        ("steady", {"episodes": None}, "its episodes None is not allowed: allowed an integer >= 1 (episodes flown)"),
        ("steady", {"evaluations": 10**6}, "its evaluations 1000000 is not allowed: more than its episodes 50, and each evaluation flies at least one episode"),
        ("steady", {"generations": 51}, "its generations 51 is not allowed: more than its evaluations 50, and each generation evaluates"),
        ("steady", {"target": "ghh08/G"}, "its method 'steady-state' is not allowed beside its target 'ghh08/G': steady state evolves on one MDP"),
        ("steady", {"method": "zzz"}, "its method 'zzz' is not allowed: allowed steady-state, generational, cma-es"),
        ("steady", {"optimizer": "cma"}, "its method 'steady-state' is not allowed: optimizer 'cma' evolves by cma-es"),
        (
            "steady",
            {"resampling": "race:0.2"},
            "its resampling 'race:0.2' is not allowed beside its method 'steady-state': a race or bandit needs the generational",
        ),
        (
            "steady",
            {"champion_return": 5.0},
            "its champion_return 5.0 is not allowed: allowed a return in [-1.75e+10, 0] (every reward is minus a sum of squares) for a steady-state run",
        ),
        (
            "generational",
            {"champion_return": 1e7},
            "its champion_return 10000000.0 is not allowed: allowed a return in [-1.75e+10, 0] (every reward is minus a sum of squares), "
            "or a fitness 1/ln(error) in (0, 1000000.5]",
        ),
        ("cma", {"champion_return": float("nan")}, "its champion_return nan is not allowed"),
        (
            "steady",
            {"stop_reason": "zzz"},
            "its stop_reason 'zzz' is not allowed: allowed budget, plateau, generations, cma-stop, optimiser-stop (why the run stopped)",
        ),
        ("steady", {"stop_reason": "generations"}, "its stop_reason 'generations' is not allowed beside its method 'steady-state': allowed budget or plateau"),
        ("steady", {"budget": 1000}, "its stop_reason 'budget' is not allowed: its 50 episodes are fewer than its budget 1,000"),
        ("plateau", {"stop_reason": "budget"}, "its stop_reason 'budget' is not allowed: it has no budget"),
    ],
)
def test_a_hand_edited_policy_file_is_refused_by_name(written: Path, tmp_path: Path, name: str, changes: dict, says: str) -> None:
    path = _edited_policy(written, tmp_path / "p.json", name, **changes)
    with pytest.raises(NeurohoverError) as caught:
        load_policy(path)
    assert f"policy file {str(path)!r}: " in str(caught.value) and says in str(caught.value)


@pytest.mark.slow
def test_the_command_line_refuses_it_with_status_2(written: Path, tmp_path: Path, cli: CliRun) -> None:
    path = _edited_policy(written, tmp_path / "p.json", "steady", stop_reason="zzz")
    rc, _, err = cli("fly", "--task", "ghh08", "--policy", str(path), "--episodes", "1")
    assert rc == 2 and "its stop_reason 'zzz' is not allowed: allowed budget, plateau" in err and "Traceback" not in err


def _edited_set(written: Path, at: Path, task: str, file: str, **changes: Any) -> Path:
    """A copy of ``written``'s ``task`` set under ``at`` whose ``file`` has ``changes``; returns the policy directory."""
    shutil.copytree(written / "sets" / task, at / task)
    path = at / task / file
    data = json.loads(path.read_text())
    data.update(changes)
    path.write_text(json.dumps(data))
    return at


@pytest.mark.slow
@pytest.mark.parametrize(
    ("task", "file", "changes", "says"),
    [
        ("ghh08", "specialised_3.json", {"stop_reason": "zzz"}, "specialised_3.json': its stop_reason 'zzz' is not allowed"),
        ("ghh08", "generic.json", {"champion_return": 5.0}, "generic.json': its champion_return 5.0 is not allowed"),
        ("ghh08", "generic.json", {"method": "generational"}, "generic.json (the generic policy) records method 'generational', not 'steady-state'"),
        ("fghh", "generic_race.json", {"method": "steady-state"}, "its method 'steady-state' is not allowed beside its target 'fghh/G(sigma=0.3)'"),
        ("ghh09", "generic.json", {"method": "steady-state", "optimizer": "ne"}, "records method 'steady-state', not 'openai-es'"),
        (
            "ghh08",
            "manifest.json",
            {"budget": 0},
            "manifest.json': its budget 0 is not allowed: allowed an integer in 1..10,000,000,000 (episodes of each run)",
        ),
        ("ghh08", "manifest.json", {"n_steps": 0}, "manifest.json': its n_steps 0 is not allowed: allowed an integer in 1..10,000,000"),
        ("ghh08", "manifest.json", {"safety_episodes": 0}, "its safety_episodes 0 is not allowed: allowed an integer in 1.."),
        ("fghh", "manifest.json", {"fghh_budget": 0}, "its fghh_budget 0 is not allowed"),
        (
            "ghh08",
            "manifest.json",
            {"n_steps": 999},
            "generic.json (the generic policy) records n_steps 20, not 999 (what its manifest.json says the build ran",
        ),
        ("ghh08", "manifest.json", {"budget": 77}, "records budget 10, not 77"),
        ("fghh", "manifest.json", {"fghh_budget": 77}, "generic_fixed.json (the fixed generic policy) records budget 50, not 77"),
        # T54-B02: a manifest's optimizer no build of its files ran was read as sound (only 'cma' was caught, by its method)
        ("ghh08", "manifest.json", {"optimizer": "pso"}, "generic.json (the generic policy) records optimizer 'ne', not 'user:pso'"),
        ("ghh09", "manifest.json", {"optimizer": "ne"}, "generic.json (the generic policy) records method 'openai-es', not 'steady-state'"),
        ("ghh09", "manifest.json", {"optimizer": "uh-cma"}, "generic.json (the generic policy) records method 'openai-es', not 'uh-cma-es'"),
        ("ghh08", "manifest.json", {"optimizer": ""}, "manifest.json': its optimizer '' is not allowed: give the name build-policies --optimizer took"),
        ("ghh08", "manifest.json", {"optimizer": "user:foo"}, "its optimizer 'user:foo' is not allowed: give the name build-policies --optimizer took"),
    ],
)
def test_a_hand_edited_policy_set_is_refused_by_name(written: Path, tmp_path: Path, task: str, file: str, changes: dict, says: str) -> None:
    directory = _edited_set(written, tmp_path, task, file, **changes)
    with pytest.raises(NeurohoverError, match=None) as caught:
        load_policy_set(task, directory)
    assert says in str(caught.value) and str(directory) in str(caught.value)


@pytest.mark.slow
def test_compete_refuses_a_hand_edited_set_with_status_2(written: Path, tmp_path: Path, cli: CliRun) -> None:
    directory = _edited_set(written, tmp_path, "ghh08", "specialised_3.json", seed=-3)
    argv = ["compete", "--task", "ghh08", "--agent", "model-free", "--policy-dir", str(directory), "--runs", "1", "--episodes", "1"]
    rc, _, err = cli(*argv, "--episode-steps", "20", "--out", str(tmp_path / "out"))
    assert rc == 2 and "specialised_3.json': its seed -3 is not allowed: allowed an integer in 0..2**63-1" in err and "Traceback" not in err
