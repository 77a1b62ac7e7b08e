"""Bad-input trial 29, T29-B01 and T29-B02: a family's make() and sample() took a label naming another MDP ('ghh08/train:0'
on a wind of (0, 0), 'zero' on a draw, another family's MDP), and evolve wrote a policy file claiming that target; a
family's rows() took parameters its make() refuses (a GHH-08 wind of 99 m/s), and evaluate flew them."""

from __future__ import annotations

import re

import numpy as np
import pytest

import neurohover as nh
from neurohover.errors import NeurohoverError


@pytest.mark.parametrize(
    ("family", "call", "says"),
    [
        ("ghh08", lambda f: f.make([0.0, 0.0], label="ghh08/train:0"), "MDP 'ghh08/train:0' is not allowed: its wind=(0.0, 0.0) contradict its label"),
        ("ghh08", lambda f: f.sample(0, label="zero"), "MDP 'zero' is not allowed: its wind_kind=1, wind=("),
        ("ghh08", lambda f: f.make([1.0, 1.0], label="ghh09/test:3"), "its label names a 'ghh09' MDP, but the MDP's family is 'ghh08'"),
        ("ghh09", lambda f: f.sample(1, label="ghh08/zero"), "its label names a 'ghh08' MDP, but the MDP's family is 'ghh09'"),
        ("ghh08", lambda f: f.make([1.0, 1.0], label="ghh08/wind=[1.0, 2.0]"), "contradicts its label, which names the wind [1.0, 2.0]"),
        ("fghh", lambda f: f.make(list(f.zero().params), label="fghh/train:1"), "contradict its label: fghh's train:1 has params="),
    ],
)  # fmt: skip
def test_a_label_given_to_make_or_sample_must_name_the_mdp_built(family: str, call, says: str) -> None:
    with pytest.raises(NeurohoverError, match=re.escape(says)):
        call(nh.get_task_family(family))


def test_labels_that_name_the_mdp_built_and_the_familys_own_are_taken() -> None:
    g8 = nh.get_task_family("ghh08")
    train0 = g8.mdp("train:0")
    assert g8.make(list(train0.wind), label="ghh08/train:0") == train0
    assert g8.make([1.0, 2.0]).label == "ghh08/wind=[1.0, 2.0]" and g8.make([1.0, 2.0], label="mine").label == "mine"
    assert g8.sample(3).label == "ghh08/sample" and g8.sample(3, label="ghh08/sample:7").label == "ghh08/sample:7"
    sensed = nh.get_task_family("ghh09").with_sensor(nh.Sensor(velocity=0.1))
    assert [m.label for m in sensed.test_mdps()[:2]] == ["ghh09/test:0", "ghh09/test:1"]
    assert nh.get_task_family("fghh", sigma=0.2).mdp("train:2").label == "fghh/seeded-train:2"


@pytest.mark.parametrize(
    ("family", "params", "says"),
    [
        ("ghh08", [[1.0, 2.0], [99.0, 0.0]], "ghh08 parameters row 1 [99.0, 0.0] is out of range: each must lie in [-5, 5] (wind_u, wind_v)"),
        ("ghh09", [[0.5] * 8, [2.0] + [0.5] * 7], "ghh09 parameters row 1 [2.0, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5] is out of range: each must lie in [0, 1]"),
        ("fghh", [[1e5] * 11], "fghh parameters row 0 [100000.0, "),
    ],
)  # fmt: skip
def test_rows_refuse_parameters_make_refuses(family: str, params: list, says: str) -> None:
    f = nh.get_task_family(family)
    with pytest.raises(NeurohoverError, match=re.escape(says)):
        f.rows(np.array(params))
    good = np.array(params[:1]) if family != "fghh" else np.array([f.zero().params])
    assert np.array_equal(f.rows(good)[0], f.make(good[0]).row())
