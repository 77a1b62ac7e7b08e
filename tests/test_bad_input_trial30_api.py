"""Trial 30b's findings in the Python API and hand-edited files (T30-B01, T30-B02, T30-B03, T30-B04, T30-B05): a policy
took genes up to 1.7e308 and acted NaN; a policy file's mdp could be any text that is no MDP spec beside a target naming
one MDP; Store.put stored a unit of a kind its readers call damaged; a flight-data archive holding a member twice was
read without a word; a history CSV after a UTF-8 byte-order mark was "not an evolution history"."""

from __future__ import annotations

import json
import re
import warnings
import zipfile
from pathlib import Path

import numpy as np
import pytest
from policy_edits import edited, evolved_policy_file, refused
from store_edits import begin

import neurohover as nh
from neurohover.errors import NeurohoverError
from neurohover.evolution.evolve import read_history_csv, write_history_csv
from neurohover.evolution.records import HistoryRecord
from neurohover.experiments import Store, Unit
from neurohover.flightdata import FlightData

OBSERVATION = [2.0, -2.0] + [0.0] * 10
MAX_GENE = 1e120  # neurohover.policies.MAX_GENE


@pytest.fixture(scope="module")
def policy_file(tmp_path_factory) -> Path:
    """A policy file as evolve writes it: a 10-episode run of 20-step episodes on ghh08/train:0."""
    return evolved_policy_file(tmp_path_factory.mktemp("p30"))


# ----------------------------------------------------------------------------------------------- T30-B01


@pytest.mark.parametrize(("topology", "size"), [("slp", 40), ("mlp", 42)])
def test_genes_past_the_bound_are_refused_by_name(topology: str, size: int) -> None:
    """Genes of 1e308 were taken and acted (nan, nan, nan, nan); the bound is named."""
    genome = np.zeros(size)
    genome[3] = -1e308
    with pytest.raises(NeurohoverError, match=rf"^a {topology} genome's gene 3 -1e\+308 is out of range: allowed numbers in \[-1e\+120, 1e\+120\]$"):
        nh.Policy(topology, genome)


@pytest.mark.parametrize("topology", ["slp", "mlp"])
def test_genes_at_the_bound_act_finite(topology: str) -> None:
    """The largest genes taken, of either sign, still give finite actions (the MLP's gene x gene product included)."""
    for sign in (1.0, -1.0):
        policy = nh.Policy(topology, np.full(nh.policies.GENOME_LENGTH[topology], sign * MAX_GENE))
        assert np.isfinite(policy.act(OBSERVATION)).all()
        assert np.isfinite(policy.act([1e6] * 12)).all()


def test_shipped_policies_are_far_inside_the_bound() -> None:
    """Every shipped policy loads (the largest gene of all of them, and of the committed store's champions, is under 20)."""
    root = Path(nh.__file__).parent / "data" / "policies"
    genes = [np.abs(nh.load_policy(p).genome).max() for p in root.glob("*/*.json") if p.name != "manifest.json"]
    assert genes and max(genes) < 20 < MAX_GENE


def test_a_policy_file_with_a_huge_gene_is_refused(policy_file: Path, tmp_path: Path) -> None:
    data = json.loads(policy_file.read_text())
    huge = edited(policy_file, tmp_path / "big.json", genome=[1e308] + data["genome"][1:])
    with pytest.raises(NeurohoverError, match="gene 0 1e\\+308 is out of range"):
        nh.load_policy(huge)


# ----------------------------------------------------------------------------------------------- T30-B02


@pytest.mark.parametrize("mdp", ["banana", "", "TRAIN:0", "train:0 ", "train: 0", "m.json", "wind=1,2"])
def test_an_mdp_other_than_the_targets_spec_is_refused(policy_file: Path, tmp_path: Path, mdp: str) -> None:
    """Beside target ghh08/train:0 evolve writes mdp 'train:0' and nothing else."""
    assert json.loads(policy_file.read_text())["target"] == "ghh08/train:0"
    refused(edited(policy_file, tmp_path / "m.json", mdp=mdp), f"its mdp {mdp!r} is not allowed beside its target 'ghh08/train:0'")


def test_the_targets_own_spec_is_taken(policy_file: Path) -> None:
    assert nh.load_policy(policy_file).metadata["mdp"] == "train:0"


def test_a_wind_run_keeps_its_own_words(tmp_path: Path) -> None:
    """evolve --wind writes mdp 'wind=...' beside its MDP's own label: still taken."""
    from neurohover.cli import main

    out = tmp_path / "w.json"
    argv = ["evolve", "--task", "ghh08", "--wind", "1,2", "--topology", "slp", "--seed-policy", "baseline", "--budget", "4"]
    assert main([*argv, "--episode-steps", "20", "--seed", "1", "--out", str(out)]) == 0
    meta = nh.load_policy(out).metadata
    assert meta["mdp"] == "wind=1,2" and not meta["target"].endswith("/train:0"), meta


# ----------------------------------------------------------------------------------------------- T30-B03


def test_put_refuses_a_unit_of_an_unknown_kind(tmp_path: Path) -> None:
    """The readers' words, before anything is written."""
    with Store(tmp_path / "s.sqlite") as store:
        h = begin(store, "tr2")
        with pytest.raises(
            NeurohoverError, match=r"put: unit 'k1': unknown unit kind 'banana': allowed evolve, robustness, safety, model, test_run, diagnostic$"
        ):
            store.put("tr2", "quick", h, Unit("tr2", "k1", "banana", {}), {"r": 1}, 1.0)
        assert store.units("tr2", "quick") == []
        assert store.put("tr2", "quick", h, Unit("tr2", "k1", "diagnostic", {}), {"value": 1, "seed": None}, 1.0)


# ----------------------------------------------------------------------------------------------- T30-B04


@pytest.fixture(scope="module")
def flight_file(tmp_path_factory) -> Path:
    family = nh.get_task_family("ghh08")
    data = nh.evaluate(nh.load_policy("baseline"), family.zero(), n_steps=20, record=True).flight_data
    return data.save(tmp_path_factory.mktemp("f30") / "f.npz")


@pytest.mark.parametrize("member", ["observations.npy", "format.npy"])
def test_an_archive_holding_a_member_twice_is_refused(flight_file: Path, tmp_path: Path, member: str) -> None:
    out = tmp_path / "dup.npz"
    with zipfile.ZipFile(flight_file) as src, zipfile.ZipFile(out, "w") as dst, warnings.catch_warnings():
        warnings.simplefilter("ignore")  # zipfile's "Duplicate name"
        for name in src.namelist():
            dst.writestr(name, src.read(name))
        dst.writestr(member, src.read(member))
    with pytest.raises(NeurohoverError, match=rf"is not a readable flight-data file: it holds member\(s\) {member} more than once"):
        FlightData.load(out)
    assert FlightData.load(flight_file).observations[0].shape[1] == 12  # what save writes still loads


# ----------------------------------------------------------------------------------------------- T30-B05


def test_a_history_after_a_byte_order_mark_is_read(tmp_path: Path) -> None:
    plain = write_history_csv([HistoryRecord(1, 2, 2, 2, -5.0, 0.1), HistoryRecord(2, 4, 4, 2, -4.0, 0.2)], tmp_path / "h.history.csv")
    bom = tmp_path / "bom.history.csv"
    bom.write_text(plain.read_text(), encoding="utf-8-sig")
    assert bom.read_bytes().startswith(b"\xef\xbb\xbf")
    assert read_history_csv(bom) == read_history_csv(plain)


def test_a_history_that_is_not_utf8_is_refused_by_name(tmp_path: Path) -> None:
    bad = tmp_path / "bad.history.csv"
    bad.write_bytes(b"\xff\xfegeneration")
    with pytest.raises(NeurohoverError, match=r"is not an evolution history: it is not UTF-8 text \(byte 0\)$"):
        read_history_csv(bad)


def test_load_policy_names_another_kind_of_neurohover_file(tmp_path) -> None:
    """Trial 30 (borderline): a results store given as a policy was "must be UTF-8 text", a model file "missing key(s)
    topology, genome"; a file neurohover can tell apart is named by its kind."""
    import sqlite3

    store = tmp_path / "s.sqlite"
    sqlite3.connect(store).execute("CREATE TABLE t (x)").connection.commit()
    summary = tmp_path / "summary.json"
    summary.write_text('{"experiment": "e", "agent": "baseline", "task": "ghh08", "runs": 1}')
    for path, kind in ((store, "a results store (SQLite)"), (summary, "a competition summary (summary.json)")):
        with pytest.raises(NeurohoverError, match=f"^policy file '{re.escape(str(path))}' is {re.escape(kind)}, not a policy file: give a policy file"):
            nh.load_policy(path)
    assert nh.load_policy(nh.save_policy(nh.baseline_policy(), tmp_path / "b.json")) == nh.baseline_policy()
