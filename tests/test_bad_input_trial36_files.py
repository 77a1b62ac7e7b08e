"""Bad-input trial 36, files and flags: T36-B01 (the store's readers ended in SQLite's UnicodeEncodeError on an
experiment name or scale holding a lone surrogate), T36-B05 (a policy set whose genomes were edited by hand loaded with
its stale manifest, and the hybrid agent flew policies that now always crash), T36-B07 (check_flag refused a NumPy
bool) and T36-B08 (policy metadata and model stats refused the NumPy numbers flight data's metadata takes)."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest
import store_edits

import neurohover as nh
from neurohover.errors import NeurohoverError, check_flag
from neurohover.experiments import Store
from neurohover.manifest import DIGESTS, genome_digest, set_files
from neurohover.models import LearnedModel
from neurohover.policysets import SHIPPED, build_policy_set, load_policy_set
from neurohover.sim.constants import DEFAULT_NOISE_STD, DEFAULT_PARAMS

# ---------------------------------------------------------------------------------------------- T36-B01


@pytest.mark.parametrize("reader", ["results", "units", "sessions", "config", "config_hash", "unit_config_hashes"])
@pytest.mark.parametrize("name, scale", [("\udcff", "quick"), ("tr2", "\ud800")])
def test_a_store_read_of_a_name_with_a_lone_surrogate_is_refused_by_name(tmp_path: Path, reader: str, name: str, scale: str) -> None:
    """T36-B01: Store.results('\\udcff', 'quick') (a name os.fsdecode gives for a non-UTF-8 byte) was SQLite's
    UnicodeEncodeError; it is refused as the writes refuse a lone surrogate (T31-B06), naming the value."""
    store = Store(tmp_path / "sur.sqlite")
    store_edits.begin(store, "tr2")
    shown = ascii(name if name != "tr2" else scale)[1:-1]  # \udcff
    with pytest.raises(NeurohoverError, match=rf"experiment name or scale = '\{shown}' is not allowed: it holds '\{shown}', a lone surrogate"):
        getattr(store, reader)(name, scale)


def test_the_other_store_readers_refuse_a_lone_surrogate_and_an_unknown_name_is_still_none(tmp_path: Path) -> None:
    """T36-B01: scales and orphan_units too; a plain name the store does not hold is answered as before (results refuses
    it, listing what the store holds, unless missing_ok: T38-B05)."""
    store = Store(tmp_path / "sur.sqlite")
    store_edits.begin(store, "tr2")
    for call in (lambda: store.scales("\udcff"), lambda: store.orphan_units("\udcff")):
        with pytest.raises(NeurohoverError, match="a lone surrogate, which UTF-8 cannot store"):
            call()
    assert store.results("nope", "quick", missing_ok=True) == {} and store.config_hash("nope", "quick") is None and store.orphan_units("nope") == []


# ---------------------------------------------------------------------------------------------- T36-B07


def test_check_flag_takes_a_numpy_bool_as_the_python_bool_it_means() -> None:
    """T36-B07: (a > 0).any() or a flag read from an .npz was refused by every check_flag argument."""
    for value, want in ((np.bool_(True), True), (np.bool_(False), False), (True, True), (False, False)):
        got = check_flag(value, "fresh", "start over")
        assert got is want
    for value in (1, 0, "no", None, np.int64(1), np.array([True])):  # still refused
        with pytest.raises(NeurohoverError, match="is not allowed: give True"):
            check_flag(value, "fresh", "start over")


def test_the_flag_arguments_take_a_numpy_bool(tmp_path: Path) -> None:
    """T36-B07: Store(create=), Store.begin(fresh=), Resampling(auto=) and evolve(resume=) took no np.bool_."""
    from neurohover.evolution import Resampling, evolve

    path = tmp_path / "s.sqlite"
    Store(path).close()
    store = Store(path, create=np.bool_(False))
    store_edits.begin(store, "tr2", fresh=np.bool_(False))
    assert [e[0] for e in store.experiments()] == ["tr2"]
    store_edits.begin(store, "tr2", fresh=np.bool_(True))
    assert Resampling("race", delta=0.2, auto=np.bool_(False)) == Resampling("race", delta=0.2)
    assert str(Resampling("race", k=5, delta=0.2, auto=np.bool_(True))) == "race:auto"
    assert type(Resampling("race", k=5, delta=0.2, auto=np.bool_(True)).auto) is bool  # kept as Python's: its repr and JSON
    m = nh.get_task_family("ghh08").training_mdps()[0]
    assert evolve(m, topology="slp", budget=20, n_steps=10, resume=np.bool_(False)).episodes >= 20


# ---------------------------------------------------------------------------------------------- T36-B08

NUMPY_NOTES = {"gen": np.int64(7), "score": np.float32(-1.5), "flag": np.bool_(True), "per_mdp": np.arange(3), "mean": np.float64(0.25)}
PLAIN_NOTES = {"gen": 7, "score": -1.5, "flag": True, "per_mdp": [0, 1, 2], "mean": 0.25}


def test_policy_metadata_takes_numpy_numbers_as_flight_data_does(tmp_path: Path) -> None:
    """T36-B08: save_policy(champ, 'p.json', best_index=np.argmax(r)) and a Policy's own NumPy metadata were refused."""
    p = nh.baseline_policy()
    assert nh.load_policy(nh.save_policy(p, tmp_path / "a.json", **NUMPY_NOTES)).metadata == {"name": "baseline", **PLAIN_NOTES}
    own = nh.Policy(p.topology, p.genome, dict(NUMPY_NOTES))
    assert nh.load_policy(nh.save_policy(own, tmp_path / "b.json")).metadata == PLAIN_NOTES


def test_model_stats_take_numpy_numbers_as_flight_data_does(tmp_path: Path) -> None:
    """T36-B08: LearnedModel(stats={'a': np.float32(1.5)}).save(...) was refused."""
    model = LearnedModel(DEFAULT_PARAMS, DEFAULT_NOISE_STD, "lr", stats=dict(NUMPY_NOTES))
    assert LearnedModel.load(model.save(tmp_path / "m.json")).stats == PLAIN_NOTES


@pytest.mark.parametrize("value", [object(), np.complex64(1j), float("nan"), np.float32("nan")])
def test_a_policy_metadata_value_still_refused_is_named_by_its_key(tmp_path: Path, value: object) -> None:
    """T36-B08: the policy message did not say which key held the value (flight data's and the model's do)."""
    with pytest.raises(NeurohoverError, match=r"policy metadata must be strict JSON values \(numbers finite\), not bad_note="):
        nh.save_policy(nh.baseline_policy(), tmp_path / "p.json", ok=1, bad_note=value)
    assert not (tmp_path / "p.json").exists()


# ---------------------------------------------------------------------------------------------- T36-B05


def _copy(task: str, where: Path) -> Path:
    shutil.copytree(SHIPPED / task, where / task)
    return where / task


def _scale(path: Path, factor: float = 1000.0) -> None:
    d = json.loads(path.read_text())
    d["genome"] = [x * factor for x in d["genome"]]
    path.write_text(json.dumps(d, indent=1) + "\n")


@pytest.mark.parametrize("task", ["ghh08", "ghh09", "fghh"])
def test_the_shipped_manifests_record_each_files_genome(task: str) -> None:
    """T36-B05: the shipped sets' manifests record the digest of every policy file they hold (and load)."""
    ps = load_policy_set(task)
    files = set_files(ps.generic if not ps.generics else None, ps.specialised, generics=ps.generics)
    recorded = ps.manifest[DIGESTS]
    assert {name: genome_digest(p) for name, p in files.items()} == {k: v for k, v in recorded.items() if k != "ancestor.json"}
    assert sorted(recorded) == sorted(f.name for f in (SHIPPED / task).glob("*.json") if f.name != "manifest.json")


@pytest.mark.parametrize("file", ["specialised_6.json", "generic.json", "ancestor.json"])
def test_a_set_with_a_genome_edited_by_hand_is_refused_naming_the_file(tmp_path: Path, file: str) -> None:
    """T36-B05: the two safe specialised genomes x1000 loaded with the stale safe list and crash table, and make_agent
    built the hybrid agent on policies that now always crash."""
    from neurohover.agents.registry import make_agent

    root = _copy("ghh08", tmp_path)
    _scale(root / file)
    why = rf"policy set .*: its manifest.json records {file}'s genome as [0-9a-f]{{16}}, and the file holds [0-9a-f]{{16}} .*build-policies --task ghh08"
    with pytest.raises(NeurohoverError, match=why):
        load_policy_set("ghh08", tmp_path)
    with pytest.raises(NeurohoverError, match=why):
        make_agent("hybrid", nh.get_task_family("ghh08"), policy_dir=tmp_path)


def test_an_fghh_set_with_a_generic_edited_by_hand_is_refused(tmp_path: Path) -> None:
    """T36-B05: the FGHH set's generics are checked against its manifest too."""
    root = _copy("fghh", tmp_path)
    _scale(root / "generic_race.json", 2.0)
    with pytest.raises(NeurohoverError, match="records generic_race.json's genome as"):
        load_policy_set("fghh", tmp_path)


def test_a_manifest_without_digests_loads_as_before_and_a_bad_digest_table_is_refused(tmp_path: Path) -> None:
    """T36-B05: an older build's manifest records no digests: its set loads unchecked, as it did; a table of digests that
    is no table of 16 hex digits is refused by name, and one missing a file's entry names the file."""
    root = _copy("ghh08", tmp_path)
    manifest = json.loads((root / "manifest.json").read_text())
    older = {k: v for k, v in manifest.items() if k != DIGESTS}
    (root / "manifest.json").write_text(json.dumps(older, indent=1) + "\n")
    _scale(root / "specialised_3.json", 1.0001)
    assert load_policy_set("ghh08", tmp_path).safe == (6, 2)
    shutil.copy(SHIPPED / "ghh08" / "specialised_3.json", root / "specialised_3.json")
    for table, why in (({"generic.json": "zz"}, f"its {DIGESTS} .* is not allowed: give a table"), ([1], f"its {DIGESTS}")):
        (root / "manifest.json").write_text(json.dumps({**older, DIGESTS: table}))
        with pytest.raises(NeurohoverError, match=why):
            load_policy_set("ghh08", tmp_path)
    partial = {k: v for k, v in manifest[DIGESTS].items() if k != "specialised_9.json"}
    (root / "manifest.json").write_text(json.dumps({**older, DIGESTS: partial}))
    with pytest.raises(NeurohoverError, match=f"its manifest.json records no {DIGESTS} of specialised_9.json"):
        load_policy_set("ghh08", tmp_path)


def test_a_build_records_each_files_digest_and_its_set_loads(tmp_path: Path) -> None:
    """T36-B05: build-policies writes the digests; the set it writes loads, and a genome edited after it is refused."""
    ps = build_policy_set("ghh08", tmp_path, budget=10, n_steps=20, safety_episodes=1, lineage="independent")
    want = {"generic.json", *(f"specialised_{i}.json" for i in range(10))}
    assert set(ps.manifest[DIGESTS]) == want and load_policy_set("ghh08", tmp_path).manifest[DIGESTS] == ps.manifest[DIGESTS]
    _scale(tmp_path / "ghh08" / "specialised_0.json", -1.0)
    with pytest.raises(NeurohoverError, match="records specialised_0.json's genome as"):
        load_policy_set("ghh08", tmp_path)
