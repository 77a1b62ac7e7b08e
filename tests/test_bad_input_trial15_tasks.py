"""The fifteenth bad-input trial's findings in the tasks (MDP, check_rows, competition rows), evaluate and policies."""

from __future__ import annotations

import re

import numpy as np
import pytest

import neurohover as nh
from neurohover import tasks
from neurohover.errors import NeurohoverError

Z = nh.get_task_family("ghh08").mdp("zero")
P = Z.params


def test_a_safeguard_box_past_a_floats_range_is_refused_by_name() -> None:
    """T15-2: box=10**400 was a TypeError from np.isfinite."""
    with pytest.raises(NeurohoverError, match=re.escape("safeguard box=1000000000...(401 digits) is out of range: allowed a finite number > 0")):
        nh.DangerousState(box=10**400)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"box": True}, "safeguard box=True is not allowed: give a number > 0"),
        ({"tilt": True}, "safeguard tilt=True is not allowed: give a number with 0 < tilt <= 1"),
        ({"rule": "ratio-sum", "threshold": True}, "safeguard threshold=True is not allowed: give a number > 0"),
        ({"arm_after": True}, "safeguard arm_after=True is not allowed: allowed an integer in 0..1000000"),
    ],
)
def test_a_safeguard_refuses_bools(kwargs: dict, message: str) -> None:
    """T15-17: box=True and tilt=True were taken as 1.0."""
    with pytest.raises(NeurohoverError, match=re.escape(message)):
        nh.DangerousState(**kwargs)


def test_a_safeguard_takes_numpy_numbers() -> None:
    """T15-17: np.float32(0.5) and np.int64(5) were refused as out of range though valid."""
    d = nh.DangerousState(box=np.float32(0.5), tilt=np.float64(0.99), arm_after=np.int64(5))
    assert d == nh.DangerousState(box=0.5, tilt=0.99, arm_after=5) and type(d.arm_after) is int
    assert nh.DangerousState(rule="ratio-sum", threshold=np.float32(0.25)).threshold == 0.25


@pytest.mark.parametrize(
    ("rows", "shown"),
    [
        (np.zeros(36), "shape (36,), dtype float64"),
        ([[0] * 36], "[[0, 0, 0,"),
        (np.zeros((2, 36), dtype=complex), "shape (2, 36), dtype complex128"),
    ],
)
def test_check_rows_refuses_what_is_no_row_array(rows, shown: str) -> None:
    """T15-4: check_rows(np.zeros(36)) was an IndexError, a list a TypeError."""
    with pytest.raises(NeurohoverError, match=re.escape("MDP rows must be a float array of shape (M, 36), rows as MDP.row() gives them; got " + shown)):
        tasks.check_rows(rows)


def test_check_rows_refuses_a_non_finite_row_and_takes_good_ones() -> None:
    """T15-4: the finiteness test is check_rows' own too (evaluate's fast path calls it alone)."""
    rows = np.vstack([Z.row(), Z.row()])
    tasks.check_rows(rows)
    rows[1, 0] = np.nan
    with pytest.raises(NeurohoverError, match=re.escape("MDP rows must be a float array of shape (M, 36) of finite numbers; got row 1: [nan,")):
        tasks.check_rows(rows)
    with pytest.raises(NeurohoverError, match=re.escape("got row 1: [nan,")):
        nh.evaluate(nh.baseline_policy(), rows, n_steps=10)


@pytest.mark.parametrize("family", ["ghh08", "ghh09", "fghh"])
def test_a_competition_row_of_another_length_or_text_is_refused(family: str) -> None:
    """T15-5: competition_params('ab') was a TypeError, [1] returned [5.0]; every family's row is checked."""
    fam = nh.get_task_family(family)
    with pytest.raises(NeurohoverError, match=re.escape(f"a {family} competition row ({', '.join(fam.param_names)}) must be {fam.n_params} numbers, got 'ab'")):
        fam.competition_params("ab")
    with pytest.raises(NeurohoverError, match=re.escape(f"must be {fam.n_params} numbers, got 1: [1]")):
        fam.competition_params([1])
    row = tasks.competition_rows(family)["train"][0]
    assert fam.make(fam.competition_params(row)) == fam.mdp("train:0")


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"params": "12345678901"}, "MDP params='12345678901' is not allowed: give 11 finite numbers"),
        ({"params": ("1",) * 11}, "MDP params=('1', '1', "),
        ({"params": (True,) * 11}, "MDP params=(True, True, "),
        ({"noise_std": "000000"}, "MDP noise_std='000000' is not allowed: give 6 finite numbers"),
        ({"wind_kind": 1, "wind": "12"}, "MDP wind='12' is not allowed: with wind_kind 1 give 2 finite numbers: wind_u, wind_v in m/s"),
        ({"wind_kind": 1, "wind": {1: 0, 2: 0}}, "MDP wind={1: 0, 2: 0} is not allowed: with wind_kind 1 give 2 finite numbers"),
    ],
)
def test_an_mdp_refuses_text_bools_and_dicts_for_numbers(kwargs: dict, message: str) -> None:
    """T15-14: float() read each character of a text as a number, True as 1.0 and a dict's keys as the wind."""
    with pytest.raises(NeurohoverError, match=re.escape(message)):
        nh.MDP("ghh08", **{"params": P, **kwargs})


def test_an_mdp_dict_with_text_params_or_an_unknown_key_is_refused() -> None:
    """T15-14: from_dict took params '12345678901' as 11 numbers and ignored a key it does not know."""
    with pytest.raises(NeurohoverError, match=re.escape("MDP params='12345678901' is not allowed: give 11 finite numbers")):
        nh.MDP.from_dict({**Z.to_dict(), "params": "12345678901"})
    with pytest.raises(
        NeurohoverError, match=re.escape("an MDP's dict has unknown keys 'foo': allowed family, params, noise_std, wind_kind, wind, substeps, dt, label")
    ):
        nh.MDP.from_dict({**Z.to_dict(), "foo": 1})
    assert nh.MDP.from_dict(Z.to_dict()) == Z


@pytest.mark.parametrize(
    ("kind", "wind", "allowed"),
    [
        (1, (), "with wind_kind 1 give 2 finite numbers: wind_u, wind_v in m/s"),
        (1, (3,), "with wind_kind 1 give 2 finite numbers"),
        (1, (3,) * 8, "with wind_kind 1 give 2 finite numbers"),
        (0, (3, 3), "with wind_kind 0 give no wind numbers: wind=()"),
        (2, (0.5,) * 2, "with wind_kind 2 give 8 finite numbers: maxf, freq, phase, center for x, then for y"),
    ],
)
def test_an_mdps_wind_has_the_length_its_kind_reads(kind: int, wind: tuple, allowed: str) -> None:
    """T15-15: wind=(), (3,) and (3,)*8 were taken for a constant wind (its missing numbers flown as 0)."""
    with pytest.raises(NeurohoverError, match=re.escape(f"MDP wind={wind!r} is not allowed: {allowed}")):
        nh.MDP("model", P, wind_kind=kind, wind=wind)
    assert nh.MDP("ghh08", P, wind_kind=1, wind=(np.float32(3), 1)).wind == (3.0, 1.0)


def test_evaluate_refuses_an_empty_policy_table() -> None:
    """T15-20: an empty PolicyTable returned an empty Evaluation, where [] is refused."""
    empty = nh.PolicyTable(np.zeros(0, int), np.zeros((0, 42)))
    with pytest.raises(NeurohoverError, match=re.escape("policies=PolicyTable of 0 policies is not allowed: give a non-empty sequence of Policy objects")):
        nh.evaluate(empty, Z, n_steps=10)


@pytest.mark.parametrize("obs", [np.zeros((3, 4)), np.zeros((1, 12)), np.zeros((12, 1)), np.array(["1"] * 12)])
def test_act_takes_one_observation_of_shape_12(obs) -> None:
    """T15-28: act(np.zeros((3, 4))) was flown as 12 observations flattened; act takes one observation, no batch."""
    with pytest.raises(NeurohoverError, match=re.escape("is not allowed: give 12 finite numbers of shape (12,)")):
        nh.baseline_policy().act(obs)
    assert nh.baseline_policy().act(list(np.zeros(12))) == pytest.approx((0.02, 0.0, 0.0, 0.23))
