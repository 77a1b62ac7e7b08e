"""Trial 25: outputs that silently overwrote another kind of neurohover file (T25-01 to T25-03)."""

from __future__ import annotations

import json

import pytest
from conftest import tiny_test_runs

from neurohover.filekinds import held_kind

POLICY = {"topology": "slp", "genome": [0.0] * 12, "prototype": "baseline"}


def test_evaluate_agent_json_refuses_another_suffix_and_a_policy_file(tmp_path, cli) -> None:
    """T25-01: --json f.npz wrote JSON rows over flight data; a policy named .json was replaced too."""
    npz = tmp_path / "fw.npz"
    npz.write_bytes(b"PK\x03\x04 format.npy")
    base = ["evaluate-agent", "--task", "ghh08", "--policy", "baseline", "--episode-steps", "5", "--n-mdps", "1", "--json"]
    rc, _, err = cli(*base, str(npz))
    assert rc == 2 and "is not allowed: evaluate-agent writes its rows as JSON; give a path ending .json" in err, err
    assert npz.read_bytes() == b"PK\x03\x04 format.npy"
    pol = tmp_path / "p.json"
    pol.write_text(json.dumps(POLICY))
    rc, _, err = cli(*base, str(pol))
    assert rc == 2 and "is a policy file: give another path" in err, err
    rc, _, err = cli(*base, str(tmp_path / "rows.json"))
    assert rc == 0 and held_kind(tmp_path / "rows.json") == "evaluate-agent rows (--json)", err
    rc, _, err = cli(*base, str(tmp_path / "rows.json"))  # its own kind: written again
    assert rc == 0, err


@pytest.fixture
def tiny_store(tmp_path, cli):
    """A store holding a tiny test-runs experiment (tr1)."""
    config, store = tmp_path / "tr1.toml", tmp_path / "tr1.sqlite"
    config.write_text(tiny_test_runs("baseline"))
    assert cli("reproduce", str(config), "--store", str(store), "--no-progress")[0] == 0
    return store


def test_results_out_refuses_another_suffix_and_a_policy_file(tmp_path, cli, tiny_store) -> None:
    """T25-02: results --out f.npz wrote CSV over flight data, --format json --out p.json replaced a policy."""
    rc, _, err = cli("results", "tr1", "--store", str(tiny_store), "--out", str(tmp_path / "f.npz"))
    assert rc == 2 and "is not allowed: results are written as CSV or JSON; give a path ending .csv or .json" in err, err
    pol = tmp_path / "p.json"
    pol.write_text(json.dumps(POLICY))
    rc, _, err = cli("results", "tr1", "--store", str(tiny_store), "--format", "json", "--out", str(pol))
    assert rc == 2 and "is a policy file: give another path" in err, err
    assert json.loads(pol.read_text()) == POLICY


@pytest.mark.slow
def test_learn_model_out_refuses_a_checkpoint_name_and_a_policy(tmp_path, cli) -> None:
    """T25-03: learn-model --out P.checkpoint.json replaced evolve's checkpoint; --out p.json an evolved policy."""
    data = tmp_path / "f0.npz"
    rc, _, err = cli("fly", "--task", "ghh08", "--episodes", "1", "--record", str(data))
    assert rc == 0, err
    base = ["learn-model", "--flight-data", str(data), "--method", "lr", "--out"]
    rc, _, err = cli(*base, str(tmp_path / "p.json.checkpoint.json"))
    assert rc == 2 and "is not allowed: evolve --out FILE writes FILE.checkpoint.json beside FILE as its run's checkpoint" in err, err
    rc, _, err = cli(*base, str(tmp_path / "p.json.history.csv"))
    assert rc == 2 and "FILE.history.csv beside FILE" in err, err
    pol = tmp_path / "p.json"
    pol.write_text(json.dumps(POLICY))
    rc, _, err = cli(*base, str(pol))
    assert rc == 2 and "is a policy file: give another path (writing a model file there would destroy it)" in err, err
    summary = tmp_path / "summary.json"
    summary.write_text(json.dumps({"task": "ghh09", "agent": "generic", "experiment": "compete-ghh09-generic", "runs": 1}))
    rc, _, err = cli(*base, str(summary))
    assert rc == 2 and "is a competition summary (summary.json)" in err, err
    rc, _, err = cli(*base, str(tmp_path / "m.json"))
    assert rc == 0, err
    rc, _, err = cli(*base, str(tmp_path / "m.json"))  # a model over a model: its own kind
    assert rc == 0, err


def test_results_out_refuses_an_evolve_runs_history_name(tmp_path, cli, tiny_store) -> None:
    """T25-02 (left by the first fix): results --out p.json.history.csv wrote CSV over evolve's history of p.json, a CSV
    that no file kind check tells from an export; refused by its name, as evolve --out and learn-model --out refuse it."""
    history = tmp_path / "p.json.history.csv"
    history.write_text("episodes,champion_return\n50,-300.0\n")
    rc, _, err = cli("results", "tr1", "--store", str(tiny_store), "--out", str(history))
    assert rc == 2 and "is not allowed: evolve --out FILE writes FILE.history.csv beside FILE as its run's history" in err, err
    assert history.read_text() == "episodes,champion_return\n50,-300.0\n"
