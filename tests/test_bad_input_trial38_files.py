"""Bad-input trial 38 (files edited by hand, the results store): a model file with a UTF-8 byte-order mark was refused
(T38-B02); a JSON or CSV file of another kind with one was no neurohover file to the writers, which replaced it, and a
policy set whose manifest had one was written into (T38-B03); a Store could not be pickled or copied, the error naming an
internal class (T38-B04); the store's readers returned nothing for an experiment or scale it does not hold, where
``Store.config`` names what it holds (T38-B05); a Store through a dangling link got SQLite's "unable to open database
file" (T38-B07)."""

from __future__ import annotations

import copy
import os
import pickle
import re
import shutil
from pathlib import Path

import pytest
from store_edits import begin, edited_policy_set

from neurohover.errors import NeurohoverError
from neurohover.evolution.records import HistoryRecord, write_history_csv
from neurohover.experiments import Store
from neurohover.filekinds import held_kind
from neurohover.models import LearnedModel, one_substep_params
from neurohover.policies import baseline_policy, load_policy, save_policy

BOM = b"\xef\xbb\xbf"


def _model() -> LearnedModel:
    return LearnedModel(one_substep_params()[0], (0.1,) * 6, "lr")


def _with_bom(path: Path, at: Path) -> Path:
    """A copy of ``path`` at ``at`` that starts with a byte-order mark (an editor's "UTF-8 with BOM")."""
    at.write_bytes(BOM + path.read_bytes())
    return at


def test_a_model_file_with_a_byte_order_mark_loads(tmp_path: Path) -> None:
    """T38-B02: "is not valid JSON: Unexpected UTF-8 BOM", where a policy file with one loads."""
    model = _model()
    plain = model.save(tmp_path / "m.json")
    assert LearnedModel.load(_with_bom(plain, tmp_path / "m_bom.json")) == model
    (tmp_path / "latin.json").write_bytes(plain.read_bytes().replace(b'"lr"', b'"l\xe9"'))
    with pytest.raises(NeurohoverError, match=r"model file '.*latin.json' cannot be read: a model file must be UTF-8 text, and byte 0xe9 at line"):
        LearnedModel.load(tmp_path / "latin.json")


def test_a_file_with_a_byte_order_mark_is_told_apart_and_not_replaced(tmp_path: Path, tiny_checkpoint: Path) -> None:
    """T38-B03: a checkpoint, policy, model or history CSV with a byte-order mark was "no neurohover file", and each writer
    replaced it without a word (evolve --resume and load_policy had read it)."""
    plain = {
        "checkpoint": Path(shutil.copy(tiny_checkpoint, tmp_path / "ck.json")),
        "policy": save_policy(baseline_policy(), tmp_path / "p.json"),
        "model": _model().save(tmp_path / "m.json"),
        "history": write_history_csv([HistoryRecord(1, 2, 2, 2, -5.0, 0.1)], tmp_path / "h.csv"),
    }
    marked = {what: _with_bom(path, tmp_path / f"bom_{path.name}") for what, path in plain.items()}
    for what, path in plain.items():
        assert held_kind(path) is not None and held_kind(marked[what]) == held_kind(path), what
    assert load_policy(marked["policy"]).topology == "slp"  # what is read is what is kept
    for write, what in (
        (lambda p: save_policy(baseline_policy(), p), "checkpoint"),
        (_model().save, "policy"),
        (lambda p: save_policy(baseline_policy(), p), "model"),
    ):
        before = marked[what].read_bytes()
        with pytest.raises(NeurohoverError, match=f"{re.escape(marked[what].name)}'.* is {held_kind(plain[what])}: give another path"):
            write(marked[what])
        assert marked[what].read_bytes() == before, what


@pytest.mark.slow
def test_results_out_does_not_replace_a_history_with_a_byte_order_mark(tmp_path: Path, cli) -> None:
    """T38-B03 (the command line): results --out replaced an evolve history CSV with a byte-order mark: "wrote bom_h.csv"."""
    from store_edits import competed_store

    store = competed_store(tmp_path)
    history = _with_bom(write_history_csv([HistoryRecord(1, 2, 2, 2, -5.0, 0.1)], tmp_path / "h.csv"), tmp_path / "bom_h.csv")
    before = history.read_bytes()
    with Store(store, create=False) as held:
        name = held.experiments()[0][0]
    rc, _, err = cli("results", name, "--store", str(store), "--out", str(history))
    assert rc == 2 and "is an evolution history (.history.csv): give another path" in err, err
    assert history.read_bytes() == before


def test_a_policy_set_whose_manifest_has_a_byte_order_mark_is_not_written_into(tmp_path: Path) -> None:
    """T38-B03: the set loaded, but save_policy and LearnedModel.save wrote into its folder (load_policy_set then refused
    the whole set) and over its manifest."""
    from neurohover.policysets import load_policy_set

    where = edited_policy_set(tmp_path, "ghh08", lambda manifest: None)
    manifest = where / "ghh08" / "manifest.json"
    manifest.write_bytes(BOM + manifest.read_bytes())
    assert len(load_policy_set("ghh08", where).specialised) == 10
    for write, path in ((_model().save, "model.json"), (lambda p: save_policy(baseline_policy(), p), "p.json")):
        with pytest.raises(NeurohoverError, match="which is a policy set's directory \\(its manifest.json\\)"):
            write(where / "ghh08" / path)
    with pytest.raises(NeurohoverError, match="is a policy set's manifest|a policy set's directory"):
        save_policy(baseline_policy(), manifest)
    assert sorted(os.listdir(where / "ghh08")) == sorted(os.listdir(edited_policy_set(tmp_path / "again", "ghh08", lambda m: None) / "ghh08"))
    assert len(load_policy_set("ghh08", where).specialised) == 10


def test_a_store_is_not_pickled_or_copied_and_says_how_to_pass_one(tmp_path: Path) -> None:
    """T38-B04: "TypeError: cannot pickle 'GuardedConnection' object"."""
    with Store(tmp_path / "s.sqlite") as store:
        for copier in (pickle.dumps, copy.deepcopy, copy.copy):
            with pytest.raises(NeurohoverError, match=r"a Store \('.*s.sqlite'\) holds an open SQLite connection .*: pass its path and open Store\(path\)"):
                copier(store)
        assert store.experiments() == []  # still open, unchanged


def test_the_store_readers_refuse_an_experiment_it_does_not_hold(tmp_path: Path) -> None:
    """T38-B05: results, units, sessions and unit_config_hashes returned nothing for 'FIG7', 'fig7 ' or 'QUICK', where
    Store.config lists what the store holds; one stored without units yet reads as empty, and missing_ok=True (reproduce's
    sources, not stored yet) reads anything as empty."""
    with Store(tmp_path / "s.sqlite") as store:
        begin(store, "tr1", "quick")
        readers = (store.results, store.units, store.sessions, store.unit_config_hashes)
        assert [len(read("tr1", "quick")) for read in readers] == [0, 0, 0, 0]
        for name, scale in (("TR1", "quick"), ("tr1 ", "quick"), ("tr1", "QUICK"), ("zzz", "quick")):
            for read in readers:
                with pytest.raises(NeurohoverError, match=f"holds no experiment '{re.escape(name)}' at scale '{scale}'; it holds: tr1 \\(quick\\)$"):
                    read(name, scale)
                assert len(read(name, scale, missing_ok=True)) == 0
        with pytest.raises(NeurohoverError, match="missing_ok"):
            store.results("zzz", "quick", missing_ok="no")  # type: ignore[arg-type]


def test_a_store_through_a_dangling_link_is_named_as_one(tmp_path: Path) -> None:
    """T38-B07: "cannot create the results store 'dl.sqlite' (unable to open database file)", where the file writers
    and --store name the link; the link is left as it was."""
    link = tmp_path / "dl.sqlite"
    link.symlink_to("missing_dir/s.sqlite")
    with pytest.raises(
        NeurohoverError,
        match=f"results store '{re.escape(str(link))}' is a symbolic link to 'missing_dir/s.sqlite', whose directory '{re.escape(str(tmp_path))}/missing_dir' "
        "does not exist: a symbolic link to a missing target is not written through",
    ):
        Store(link)
    assert link.is_symlink() and not (tmp_path / "missing_dir").exists()
