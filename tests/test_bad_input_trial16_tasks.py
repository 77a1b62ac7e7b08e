"""The sixteenth bad-input trial's findings in the tasks, policies, evaluate, launch, flight data and plots."""

from __future__ import annotations

import datetime
import re
from decimal import Decimal

import numpy as np
import pytest

import neurohover as nh
from neurohover.errors import NeurohoverError
from neurohover.evaluate import PolicyTable
from neurohover.launch import check_device
from neurohover.plots import attitude_angles


def _masked(values: np.ndarray) -> np.ma.MaskedArray:
    """``values`` with their last entry masked (hidden)."""
    mask = np.zeros(values.shape, dtype=bool)
    mask.flat[-1] = True
    return np.ma.masked_array(values, mask=mask)


OBS, ACT = np.zeros((3, 12)), np.zeros((2, 4))
SLP = nh.baseline_policy()


@pytest.mark.parametrize(
    ("call", "good", "message"),
    [
        (lambda a: nh.get_task_family("ghh08").make(a), [1.0, 2.0], "GHH-08 wind (wind_u, wind_v) must be 2 finite numbers, got masked_array("),
        (lambda a: nh.get_task_family("ghh09").make(a), [0.5] * 8, "GHH-09 parameters x_maxf/"),
        (lambda a: nh.get_task_family("fghh").make(a), list(nh.MDP("fghh").params), "FGHH dynamics parameters "),
        (lambda a: nh.MDP("model", params=a), list(nh.MDP("ghh08").params), "MDP params=masked_array("),  # any dynamics: a model's
        (lambda a: nh.MDP("model", noise_std=a), [0.1] * 6, "MDP noise_std=masked_array("),
        (lambda a: nh.get_task_family("ghh09").rows(a), np.full((2, 8), 0.5), "ghh09 parameters masked_array("),
        (lambda a: nh.Policy("slp", a), np.ones(40), "a slp genome must be a list of finite real numbers, got masked_array("),
        (lambda a: SLP.with_genome(a), np.ones(40), "a slp genome must be a list of finite real numbers, got masked_array("),
        (lambda a: SLP.act(a), np.zeros(12), "observation masked_array("),
        (lambda a: PolicyTable(np.zeros(2, dtype=np.int64), a), np.zeros((2, 42)), "PolicyTable genomes=masked_array("),
        (lambda a: PolicyTable(a, np.zeros((2, 42))), np.zeros(2, dtype=np.int64), "PolicyTable kinds=masked_array("),
        (lambda a: PolicyTable.from_genomes(a, "slp"), np.ones((2, 40)), "slp genomes of a masked array are not allowed"),
        (lambda a: attitude_angles(a), np.zeros((3, 12)), "observations=masked_array("),
        (lambda a: nh.FlightData((a,), (ACT,)), OBS, "flight data observations must be arrays of real numbers (plain, not masked)"),
        (lambda a: nh.Drift(walk=0.01).rows(a, 2, 0), nh.MDP("ghh08").row(), "row=masked_array("),
    ],
)
def test_masked_arrays_are_refused(call, good, message: str) -> None:
    """T16-9: the mask was dropped and the hidden values flown, stored or plotted (the wind (1.0, 2.0) of [1, --])."""
    with pytest.raises(NeurohoverError, match=re.escape(message)):
        call(_masked(np.asarray(good)))
    call(np.asarray(good))  # the same values as a plain array still work


@pytest.mark.parametrize(
    "genome",
    [
        np.full(40, "0.5"),
        np.full(40, np.datetime64("2020-01-01")),
        np.full(40, 0.5 + 1j),
        np.array([Decimal("0.5")] * 40, dtype=object),
        np.ones(40, dtype=bool),
    ],
    ids=["text", "date", "complex", "Decimal", "bool"],
)
def test_with_genome_refuses_what_policy_refuses(genome: np.ndarray) -> None:
    """T16-10: with_genome cast the genome with float() first, so '0.5', a date (18262.0), a complex number (its imaginary
    part dropped), a Decimal and True were taken, while Policy('slp', same) refused them."""
    with pytest.raises(NeurohoverError, match=re.escape("a slp genome must be a list of finite real numbers, got array(")):
        SLP.with_genome(genome)
    with pytest.raises(NeurohoverError, match=re.escape("a slp genome must be a list of finite real numbers")):
        nh.Policy("slp", genome)
    assert SLP.with_genome(np.full(40, 0.5)).genome.tolist() == [0.5] * 40
    assert SLP.with_genome([1] * 40).genome.dtype == np.float64


@pytest.mark.parametrize(("name", "length"), [("params", 11), ("noise_std", 6)])
@pytest.mark.parametrize("kind", ["date", "time span"])
def test_mdp_refuses_dates(name: str, length: int, kind: str) -> None:
    """T16-11: MDP params and noise_std of dates were taken as their day numbers (18262.0 x 11)."""
    value = np.full(length, np.datetime64("2020-01-01") if kind == "date" else np.timedelta64(1, "D"))
    with pytest.raises(NeurohoverError, match=re.escape(f"MDP {name}=array([")):
        nh.MDP("model", **{name: value})
    with pytest.raises(NeurohoverError, match=re.escape(f"MDP {name}=")):
        nh.MDP("model", **{name: [datetime.date(2020, 1, 1)] * length})
    assert nh.MDP("model", **{name: np.full(length, 0.25)}).__getattribute__(name) == (0.25,) * length  # a model: any dynamics


NAMES = np.array(["slp", "mlp"])


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda: nh.Policy(NAMES, np.zeros(40)), "unknown policy topology array(['slp', 'mlp'], dtype='<U3'): allowed slp, mlp"),
        (lambda: nh.prototype(NAMES), "unknown policy topology array(['slp', 'mlp']"),
        (lambda: nh.prototype("mlp", seed=np.array(["zero", "baseline"])), "unknown prototype array(['zero', 'baseline']"),
        (lambda: PolicyTable.from_genomes(np.zeros((1, 40)), NAMES), "unknown policy topology array(['slp', 'mlp']"),
        (lambda: nh.DangerousState(rule=np.array(["code", "paper"])), "unknown safeguard rule array(['code', 'paper']"),
        (
            lambda: nh.evaluate(SLP, nh.get_task_family("ghh08").zero(), n_steps=5, device=np.array(["cpu", "cuda"])),
            "device=array(['cpu', 'cuda'], dtype='<U4') is unknown: allowed 'cpu' or 'cuda'",
        ),
        (lambda: nh.get_task_family("ghh08").make([1, 1], label=np.array(["a", "b"])), "MDP label=array(['a', 'b'], dtype='<U1') is not allowed"),
        (lambda: nh.FlightData((OBS,), (ACT,)).save("/tmp/x.npz", dtype=np.array(["float32", "float64"])), "flight-data dtype array(['float32'"),
    ],
)
def test_an_array_where_a_name_goes_is_refused(call, message: str) -> None:
    """T16-12: an array of names was NumPy's "The truth value of an array with more than one element is ambiguous"."""
    with pytest.raises(NeurohoverError, match=re.escape(message)):
        call()
    assert nh.prototype("mlp", seed="zero").topology == "mlp"
    assert nh.DangerousState(rule="paper").rule == "paper"
    check_device("cpu")


def test_drift_refuses_a_masked_change_at() -> None:
    """T16-13: a masked change_at was numpy.ma's MaskError "Cannot convert masked element to a Python int"."""
    with pytest.raises(
        NeurohoverError,
        match=re.escape("drift change_at=masked_array(data=[1, --], mask=[False, True], fill_value... is not allowed: give two episode numbers"),
    ):
        nh.Drift(change=(("D_w", 0.8),), change_at=np.ma.masked_array([1, 2], mask=[0, 1]))
    with pytest.raises(NeurohoverError, match=re.escape("drift change_at=('1', '2') is not allowed: give two episode numbers")):
        nh.Drift(change=(("D_w", 0.8),), change_at=("1", "2"))
    assert nh.Drift(change=(("D_w", 0.8),), change_at=np.array([1, 2])).change_at == (1, 2)


@pytest.mark.parametrize("family", ["ghh08", "ghh09", "fghh"])
@pytest.mark.parametrize("label", [0, {}, [], -0.0, 1.5, True])
def test_make_refuses_a_label_that_is_no_text(family: str, label: object) -> None:
    """T16-14: a false label (0, {}, [], -0.0) silently became the default label, while 1.5 or True were refused."""
    fam = nh.get_task_family(family)
    params = fam.zero().wind if family == "ghh08" else fam.sample_params(np.random.default_rng(0), 1)[0]
    params = [1.0, 1.0] if family == "ghh08" else params
    with pytest.raises(NeurohoverError, match=re.escape(f"MDP label={label!r} is not allowed: give a string (or leave it out for")):
        fam.make(params, label=label)
    with pytest.raises(NeurohoverError, match=re.escape(f"MDP label={label!r} is not allowed")):
        fam.sample(0, label=label)  # type: ignore[arg-type]
    assert fam.make(params, label="mine").label == "mine"
    assert fam.make(params).label == fam.make(params, label=None).label != ""  # type: ignore[arg-type]
    assert fam.sample(0).label == f"{family}/sample"


def test_flight_data_metadata_must_be_strict_json(tmp_path) -> None:
    """T16-24: metadata {'x': nan} was written and loaded back as NaN, while save_policy refused it as not strict JSON."""
    with pytest.raises(NeurohoverError, match=re.escape("flight data metadata cannot be saved as JSON: give strict JSON values (numbers finite)")):
        nh.FlightData((OBS,), (ACT,), metadata={"x": float("nan")}).save(tmp_path / "f.npz")
    assert not (tmp_path / "f.npz").exists()
    path = nh.FlightData((OBS,), (ACT,), metadata={"x": 1.5}).save(tmp_path / "g.npz")
    assert nh.FlightData.load(path).metadata == {"x": 1.5}
