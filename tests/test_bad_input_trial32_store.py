"""Bad-input trial 32 (the Python API): a results store written from another thread (T32-B09), its file moved or
replaced under an open Store (T32-B10), a unit result's non-text keys (T32-B11); a model's stats changed before save
(T32-B05); a policy-set manifest's safe list of other than 2 policies (T32-B12); NaN and Infinity in a policy file's
metadata (T32-B17) and in a flight-data file's (T32-B18)."""

from __future__ import annotations

import json
import os
import shutil
import threading
from pathlib import Path

import numpy as np
import pytest
import store_edits as SE

from neurohover.errors import NeurohoverError
from neurohover.evaluate import evaluate
from neurohover.experiments import Store, Unit
from neurohover.flightdata import FlightData
from neurohover.models import LearnedModel
from neurohover.models.lr import learn_lr
from neurohover.policies import baseline_policy, load_policy, save_policy
from neurohover.policysets import load_policy_set, policy_dir
from neurohover.tasks import get_task_family

# T32-B09 ------------------------------------------------------------------------------------------------------------


def _in_thread(call):
    """What ``call()`` returned in a thread of its own, or the exception it raised."""
    out: list = []

    def run() -> None:
        try:
            out.append(call())
        except Exception as err:  # noqa: BLE001  (what the thread raised is the test's to look at)
            out.append(err)

    thread = threading.Thread(target=run)
    thread.start()
    thread.join()
    return out[0]


def test_a_store_is_read_and_written_from_another_thread(tmp_path: Path) -> None:
    """A Store opened in one thread and written from another was sqlite3's ProgrammingError, and its reads there called
    the sound store "damaged"."""
    with Store(tmp_path / "thr.sqlite") as store:
        h = SE.begin(store, "tr2")
        assert _in_thread(store.experiments) == [("tr2", "quick", h, 0)]
        assert _in_thread(lambda: store.put("tr2", "quick", h, Unit("tr2", "k1", "diagnostic", {}), {"value": 1, "seed": None}, 1.0)) is True
        assert store.results("tr2", "quick") == {"k1": {"value": 1, "seed": None}}
        assert _in_thread(lambda: store.results("tr2", "quick")) == {"k1": {"value": 1, "seed": None}}


def test_puts_from_several_threads_at_once_all_land(tmp_path: Path) -> None:
    """Threads writing one Store at once take turns (one transaction at a time on its connection)."""
    with Store(tmp_path / "thr.sqlite") as store:
        h = SE.begin(store, "tr2")
        units = [Unit("tr2", f"k{i}", "diagnostic", {}) for i in range(8)]
        threads = [threading.Thread(target=store.put, args=("tr2", "quick", h, u, {"value": 1, "seed": None}, 1.0)) for u in units]
        for thread in threads:
            thread.start()
        for thread in threads:
            thread.join()
        assert sorted(store.results("tr2", "quick")) == sorted(u.key for u in units)


# T32-B10 ------------------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("how", ["rename", "remove", "replace"])
def test_a_store_whose_file_is_gone_is_refused_naming_it(tmp_path: Path, how: str) -> None:
    """The store file moved, removed or replaced under an open Store: put was sqlite3's "attempt to write a readonly
    database", and experiments() read the old rows without a word."""
    path = tmp_path / "gone.sqlite"
    store = Store(path)
    h = SE.begin(store, "tr2")
    if how == "rename":
        os.rename(path, tmp_path / "moved.sqlite")
    elif how == "remove":
        os.remove(path)
    else:
        (tmp_path / "other").write_text("{}")
        os.replace(tmp_path / "other", path)
    gone = f"results store {str(path)!r} is gone: its file was moved, removed or replaced since this Store opened it"
    with pytest.raises(NeurohoverError, match="^" + gone.replace("(", r"\(").replace(")", r"\)")):
        store.put("tr2", "quick", h, Unit("tr2", "k", "diagnostic", {}), {"value": 1, "seed": None}, 1.0)
    with pytest.raises(NeurohoverError, match="is gone: its file was moved"):
        store.experiments()
    store.close()
    if how == "rename":
        with Store(tmp_path / "moved.sqlite") as moved:  # the moved file is the store, as it was
            assert moved.experiments() == [("tr2", "quick", h, 0)]


# T32-B11 ------------------------------------------------------------------------------------------------------------


@pytest.mark.parametrize(("result", "key"), [({1: 2}, "key 1 is"), ({"n": {3: 4}}, "key 3 (under 'n') is"), ({"a": [{None: 1}]}, "key None (under 'a')")])
def test_a_result_with_keys_that_are_not_text_is_refused(tmp_path: Path, result: dict, key: str) -> None:
    """Store.put stored {1: 2, "n": {3: 4}} as {'1': 2, 'n': {'3': 4}}."""
    with Store(tmp_path / "s.sqlite") as store:
        h = SE.begin(store, "tr3")
        with pytest.raises(NeurohoverError) as err:
            store.put("tr3", "quick", h, Unit("tr3", "k", "test_run", {}), result, 1.0)
        assert f"', put: unit k's result {key}" in str(err.value) and "not allowed: give text keys" in str(err.value), err.value
        assert store.results("tr3", "quick") == {}


# T32-B05 ------------------------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def model_path(tmp_path_factory) -> Path:
    """An LR model of a recorded baseline episode (200 steps, GHH-08's zero MDP)."""
    flight = evaluate(baseline_policy(), get_task_family("ghh08").zero(), record=True, seed=1, n_steps=200).flight_data
    return learn_lr(flight).save(tmp_path_factory.mktemp("models32") / "m.json")


@pytest.mark.parametrize(
    ("key", "value", "fragment"),
    [
        ("residual_rms", float("nan"), "model stats entry 'residual_rms' = nan is not allowed: give strict JSON values"),
        ("x", float("inf"), "model stats entry 'x' = inf is not allowed"),
        ("x", object(), "model stats entry 'x' = <object object"),
        ("x", b"b", "model stats entry 'x' = b'b' is not allowed"),
        ("x", {1: 2}, "model stats key 1 (under 'x') is not allowed: give text keys"),
        ("n_episodes", -5, "model file '{out}': its stats.n_episodes -5 is not allowed: allowed an integer in 1.."),
        ("x", 1, "model file '{out}': its stats entry 'x' is not allowed: the stats of a lr fit hold only"),
    ],
)
def test_model_stats_changed_after_making_are_refused_by_save(model_path: Path, tmp_path: Path, key: str, value, fragment: str) -> None:
    """LearnedModel.save leaked json's ValueError (NaN) or TypeError (an object, bytes) and wrote stats its own load then
    refused (n_episodes -5): it checks what load checks, and writes nothing."""
    model = LearnedModel.load(model_path)
    model.stats[key] = value
    out = tmp_path / "o.json"
    with pytest.raises(NeurohoverError) as err:
        model.save(out)
    assert str(err.value).startswith(fragment.format(out=out)), err.value
    assert not out.exists()


def test_a_model_as_learned_and_as_loaded_is_saved(model_path: Path, tmp_path: Path) -> None:
    assert LearnedModel.load(LearnedModel.load(model_path).save(tmp_path / "again.json")) == LearnedModel.load(model_path)


# T32-B12 ------------------------------------------------------------------------------------------------------------


def _ghh08_with_safe(tmp_path: Path, safe) -> Path:
    shutil.copytree(policy_dir("ghh08"), tmp_path / "ghh08")
    manifest = tmp_path / "ghh08" / "manifest.json"
    manifest.write_text(json.dumps({**json.loads(manifest.read_text()), "safe": safe}))
    return manifest


@pytest.mark.parametrize("safe", [[], [6], [2], [6, 2, 0]])
def test_a_manifest_of_other_than_two_safe_policies_is_refused(tmp_path: Path, safe: list) -> None:
    """A GHH manifest with "safe": [] or [6] loaded (safe () or (6,)) while its tables choose (6, 2): build-policies
    lists 2, and the hybrid agents fly 2."""
    manifest = _ghh08_with_safe(tmp_path, safe)
    with pytest.raises(NeurohoverError) as err:
        load_policy_set("ghh08", tmp_path)
    assert str(err.value).startswith(f"policy-set manifest {str(manifest)!r}: safe={safe!r} is not allowed: give a list of the 2 safe"), err.value


def test_a_manifest_of_the_two_safe_policies_loads(tmp_path: Path) -> None:
    _ghh08_with_safe(tmp_path, [6, 2])  # in the order its tables give: [2, 6] is refused since T37-B07 (trial 37's tests)
    assert load_policy_set("ghh08", tmp_path).safe == (6, 2)
    assert load_policy_set("ghh08").safe == (6, 2)


# T32-B17 ------------------------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("literal", "shown"), [("NaN", "nan"), ("Infinity", "inf"), ("-Infinity", "-inf"), ("[NaN]", "[nan]"), ('{"a": Infinity}', "{'a': inf}")]
)
def test_a_policy_file_with_nan_metadata_is_refused_on_load(tmp_path: Path, literal: str, shown: str) -> None:
    """load_policy took NaN / Infinity literals (no JSON) in a policy file's metadata; save_policy then refused the
    loaded policy."""
    path = save_policy(baseline_policy(), tmp_path / "p.json", note="x")
    path.write_text(path.read_text().replace('"note": "x"', f'"note": {literal}'))
    with pytest.raises(NeurohoverError) as err:
        load_policy(path)
    assert str(err.value).startswith(f"policy file {str(path)!r}: its note {shown} is not allowed: give strict JSON values, numbers finite"), err.value


def test_a_policy_file_with_finite_metadata_loads_and_saves(tmp_path: Path) -> None:
    path = save_policy(baseline_policy(), tmp_path / "p.json", note=[1.5, {"a": None}])
    assert save_policy(load_policy(path), tmp_path / "q.json").exists()


# T32-B18 ------------------------------------------------------------------------------------------------------------


def test_flight_data_with_nan_metadata_is_refused_naming_the_file(tmp_path: Path) -> None:
    """FlightData.load of metadata holding NaN said "flight data metadata cannot be saved as JSON", naming no file."""
    flight = evaluate(baseline_policy(), get_task_family("ghh08").zero(), record=True, seed=1, n_steps=20).flight_data
    good = flight.save(tmp_path / "f.npz")
    with np.load(good) as z:
        arrays = {k: z[k] for k in z.files}
    text = str(arrays["metadata"])
    bad = tmp_path / "nan.npz"
    np.savez_compressed(bad, **{**arrays, "metadata": np.array(text[:-1] + ', "note": NaN}')})
    with pytest.raises(NeurohoverError) as err:
        FlightData.load(bad)
    assert str(err.value).startswith(f"flight-data file {str(bad)!r}: its metadata note=nan is not allowed: give strict JSON values"), err.value
    assert FlightData.load(good) == flight
