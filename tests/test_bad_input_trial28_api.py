"""Trial 28 (bad input, Python API): T28-B01 (number subclasses whose float()/int() lie), T28-B02 (whole reprs in
messages), T28-B03 (a copied or unpickled Policy's writable genome; an inf genome blamed on the metadata), T28-B05
(a policy's metadata edited in place to hold its genome), T28-B06 (np.matrix flight data), T28-B14 (policy metadata
load_policy refuses or reads otherwise), T28-B15 (a -0.0 gene hashed apart)."""

from __future__ import annotations

import copy
import json
import pickle

import gymnasium as gym
import numpy as np
import pytest

import neurohover as nh
from neurohover.errors import NeurohoverError, brief, finite_real, real_number, whole_in, whole_number


class NanFloat(float):
    """A float whose float() is NaN."""

    def __float__(self) -> float:
        return float("nan")


class BigFloat(float):
    """A float whose float() is ten times its value."""

    def __float__(self) -> float:
        return 10 * float.__float__(self)


class BigInt(int):
    """An int whose int() is 10**9."""

    def __int__(self) -> int:
        return 10**9


class HonestFloat(float):
    """A float subclass whose float() is its value."""


class HonestInt(int):
    """An int subclass whose int() is its value."""


def zero_mdp() -> nh.MDP:
    return nh.get_task_family("ghh08").zero()


def test_t28_b01_helpers_check_the_converted_value() -> None:
    assert not finite_real(NanFloat(0.0)) and not real_number(NanFloat(0.0)) and not real_number(BigFloat(0.5))
    assert not whole_number(BigInt(20)) and not real_number(BigInt(20))
    with pytest.raises(NeurohoverError, match=r"^n=BigInt\(20\) is not allowed: allowed an integer in 1\.\.100$"):
        whole_in(BigInt(20), "n", 1, 100)
    assert brief(NanFloat(0.5)) == "NanFloat(0.5)"
    # honest numbers, NumPy's and subclasses that do not lie, are as they were
    for value in (3, 2.5, np.float64(1.5), np.float32(2.0), np.int64(3), np.uint8(3), HonestFloat(0.5), HonestInt(4)):
        assert real_number(value) and finite_real(value)
    assert whole_number(HonestInt(4)) and whole_in(HonestInt(4), "n", 1, 10) == 4
    assert whole_in(np.int64(5), "n", 1, 10) == 5 and type(whole_in(np.int64(5), "n", 1, 10)) is int
    assert real_number(10**400) and not finite_real(10**400) and not finite_real(float("nan"))


@pytest.mark.parametrize(
    "make, message",
    [
        (lambda: nh.MDP("model", substeps=1, dt=0.1, d_u=NanFloat(0.0)), r"MDP d_u=NanFloat\(0\.0\) is not allowed"),
        (lambda: nh.Sensor(velocity=NanFloat(0.1)), r"sensor velocity=NanFloat\(0\.1\) is not a number"),
        (lambda: nh.Sensor(velocity=BigFloat(0.1)), r"sensor velocity=BigFloat\(0\.1\) is not a number"),
        (lambda: nh.Drift(walk=NanFloat(0.01)), r"drift walk=NanFloat\(0\.01\) is not a number"),
        (lambda: nh.Drift(change={"D_w": NanFloat(0.8)}), r"drift change D_w=NanFloat\(0\.8\) is not a number"),
        (lambda: nh.evaluate(nh.baseline_policy(), zero_mdp(), n_steps=BigInt(20)), r"n_steps=BigInt\(20\) is not allowed"),
        (lambda: nh.evaluate(nh.baseline_policy(), zero_mdp(), n_steps=20, episodes=BigInt(2)), r"episodes=BigInt\(2\) is not allowed"),
    ],
)
def test_t28_b01_lying_numbers_are_refused_by_name(make, message) -> None:
    with pytest.raises(NeurohoverError, match=message):
        make()


def test_t28_b02_policies_and_mdp_messages_are_brief() -> None:
    b = nh.baseline_policy()
    with pytest.raises(NeurohoverError) as err:
        nh.evaluate({nh.Policy("slp", b.genome + i) for i in range(100)}, zero_mdp(), n_steps=20)
    assert len(str(err.value)) < 300 and "\n" not in str(err.value)
    with pytest.raises(NeurohoverError) as err:
        nh.evaluate([b, {"a": b}], zero_mdp(), n_steps=20)
    assert len(str(err.value)) < 300 and "\n" not in str(err.value)
    with pytest.raises(NeurohoverError) as err:
        gym.make("neurohover/GHH08-v0", mdp=[zero_mdp()], episode_steps=20)
    assert len(str(err.value)) < 300 and str(err.value).startswith("mdp=[MDP(")


def test_t28_b03_copies_keep_a_read_only_genome(tmp_path) -> None:
    p = nh.baseline_policy()
    for q in (copy.deepcopy(p), pickle.loads(pickle.dumps(p)), copy.copy(p)):
        assert q == p and q.metadata == p.metadata and not q.genome.flags.writeable
        with pytest.raises(ValueError):
            q.genome[0] = np.nan
    r = pickle.loads(pickle.dumps(p))
    r.genome.setflags(write=True)  # only by asking for it
    r.genome[0] = np.inf
    with pytest.raises(NeurohoverError, match=r"^a slp genome must hold finite numbers; genes \[0\] are not$"):
        nh.save_policy(r, tmp_path / "inf.json")
    assert not (tmp_path / "inf.json").exists()


@pytest.mark.parametrize("key, value", [("genome", [0.0] * 40), ("topology", "mlp")])
def test_t28_b05_own_keys_edited_into_metadata_are_refused_at_save(tmp_path, key, value) -> None:
    p = nh.baseline_policy()
    p.metadata[key] = value
    with pytest.raises(NeurohoverError, match=rf"^policy metadata key\(s\) {key} are the policy's own: give the metadata other names$"):
        nh.save_policy(p, tmp_path / "x.json")
    assert not (tmp_path / "x.json").exists()


def test_t28_b14_metadata_load_policy_refuses_or_changes_is_not_written(tmp_path) -> None:
    b = nh.baseline_policy()
    with pytest.raises(NeurohoverError, match=r"policy metadata must be strict JSON values .*\(401 digits\) is out of range"):
        nh.save_policy(b, tmp_path / "big.json", x=10**400)
    for metadata in ({1: 2}, {"a": [{(1, 2): 3}]}):
        with pytest.raises(NeurohoverError, match=r"^policy metadata key .* is not allowed: give text keys"):
            nh.save_policy(nh.Policy("slp", b.genome, metadata), tmp_path / "ik.json")
    cycle: dict = {}
    cycle["c"] = cycle
    with pytest.raises(NeurohoverError, match="Circular reference"):
        nh.save_policy(nh.Policy("slp", b.genome, {"c": cycle}), tmp_path / "cyc.json")
    assert list(tmp_path.iterdir()) == []
    # what neurohover writes still round-trips: tuples, NumPy numbers, nested text keys
    path = nh.save_policy(b, tmp_path / "ok.json", x=(1, 2), y={"a": np.float64(2.0)}, z=[{"k": 10**20}])
    q = nh.load_policy(path)
    assert q == b and q.metadata == {"name": "baseline", "x": [1, 2], "y": {"a": 2.0}, "z": [{"k": 10**20}]}
    assert json.loads(path.read_text())["z"] == [{"k": 10**20}]


def test_t28_b15_equal_policies_hash_alike() -> None:
    b = nh.baseline_policy()
    p2 = nh.Policy("slp", np.where(b.genome == 0, -0.0, b.genome))
    assert p2 == b and hash(p2) == hash(b) and len({b, p2}) == 1


@pytest.mark.filterwarnings("ignore::PendingDeprecationWarning")
def test_t28_b06_matrix_flight_data_are_refused_by_name() -> None:
    fd = nh.evaluate(nh.baseline_policy(), zero_mdp(), n_steps=20, record=True).flight_data
    with pytest.raises(NeurohoverError, match=r"must be arrays of real numbers \(plain, not masked\), one per episode \(not matrix: give np\.asarray of it\)$"):
        nh.FlightData([np.asmatrix(fd.observations[0])], [np.asmatrix(fd.actions[0])], {})
    with pytest.raises(NeurohoverError, match=r"\(plain, not masked\), one per episode$"):
        nh.FlightData([np.ma.masked_array(fd.observations[0])], list(fd.actions), {})
    assert nh.FlightData([np.asarray(np.asmatrix(fd.observations[0]))], list(fd.actions), {}) == nh.FlightData(list(fd.observations), list(fd.actions), {})
