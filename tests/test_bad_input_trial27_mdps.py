"""Bad-input trial 27, T27-B05 and T27-B06: ``MDP(...)`` built MDPs the loaders refused (a GHH-08 wind of 99 m/s, a label
naming another family's MDP, a D_u on a true MDP, GHH-09 parameters outside [0, 1], a dt of 1e9) and ``evaluate`` flew
them; a model MDP's parameter of 1e300 flew to a NaN return. Every MDP is now checked against its family as it is built
(:mod:`neurohover.tasks.held`), and every number of an MDP or kernel row is bounded (``MAX_MAGNITUDE``)."""

from __future__ import annotations

import re

import numpy as np
import pytest

import neurohover as nh
from neurohover.errors import NeurohoverError
from neurohover.models import LearnedModel, one_substep_params
from neurohover.sim.constants import DEFAULT_PARAMS, ROW_D_U, ROW_DT, ROW_NOISE, ROW_PARAMS, ROW_WIND_START
from neurohover.tasks import TASK_NAMES, check_rows
from neurohover.tasks.base import MAX_MAGNITUDE

OTHER_PARAMS = (1e5, *DEFAULT_PARAMS[1:])


@pytest.mark.parametrize(
    ("kwargs", "says"),
    [
        ({"family": "ghh08", "wind_kind": 1, "wind": (99.0, 0.0), "label": "ghh08/custom"}, "it is no ghh08 MDP: GHH-08 wind [99.0, 0.0] m/s is out of range"),
        ({"family": "ghh08", "wind_kind": 1, "wind": (1.0, 0.0), "label": "ghh09/train:1"}, "its label names a 'ghh09' MDP, but the MDP's family is 'ghh08'"),
        ({"family": "ghh08", "wind_kind": 1, "wind": (1.0, 0.0), "label": "ghh08/train:1"}, "its wind=(1.0, 0.0) contradict its label: ghh08's train:1"),
        ({"family": "ghh08", "wind_kind": 1, "wind": (0.0, 0.0), "d_u": 1.0}, "it is no ghh08 MDP: its d_u=1.0 differ from every ghh08 MDP's (d_u=0.0)"),
        ({"family": "ghh09", "wind_kind": 2, "wind": (5.0,) * 8}, "it is no ghh09 MDP: GHH-09 parameters out of range (x_maxf=5.0"),
        ({"family": "fghh", "noise_std": (0.1,) * 6}, "it is no fghh MDP: its noise_std=(0.1, 0.1, 0.1, 0.1, 0.1, 0.1) differ"),
        ({"family": "ghh08", "params": OTHER_PARAMS}, "MDP params=(100000.0, -0.43"),
        ({"family": "model", "params": (1e300, *DEFAULT_PARAMS[1:])}, "is out of range: allowed numbers in [-10000, 10000]"),
        ({"family": "model", "noise_std": (2e4,) * 6}, "MDP noise_std=(20000.0, "),
        ({"family": "model", "wind_kind": 1, "wind": (0.0, -1e5)}, "MDP wind=(0.0, -100000.0) is out of range"),
        ({"family": "model", "d_u": 1e6}, "MDP d_u=1000000.0 is out of range"),
        ({"family": "model", "dt": 1e9}, "MDP substeps=10 x dt=1000000000.0 is not allowed: the substeps must cover one 0.1 s control step"),
        ({"family": "ghh08", "substeps": 3}, "MDP substeps=3 x dt=0.01 is not allowed"),
    ],
)  # fmt: skip
def test_an_mdp_no_family_holds_is_refused_as_it_is_built(kwargs: dict, says: str) -> None:
    """T27-B05, T27-B06: each was built and flown by evaluate without a word (a NaN return for 1e300)."""
    with pytest.raises(NeurohoverError, match=re.escape(says)):
        nh.MDP(**kwargs)
    table = {**nh.MDP("model").to_dict(), **kwargs}  # the same refusal where a file gives the MDP (from_dict)
    with pytest.raises(NeurohoverError, match=re.escape(says)):
        nh.MDP.from_dict(table)


def test_what_the_families_and_models_build_is_still_built() -> None:
    """The check never recurses and takes every MDP the code itself builds: each family's zero, fixed sets, samples and
    its MDPs seen through a sensor; a learned model's MDP in one or ten substeps; a model at the magnitude bound."""
    for name in TASK_NAMES:
        family = nh.get_task_family(name)
        mdps = [family.zero(), family.sample(3), *family.training_mdps(), *family.test_mdps()[:5], *family.seeded_training_mdps()[:2]]
        sensed = [m.with_sensor(nh.Sensor(velocity=0.1)) for m in mdps]
        assert all(nh.MDP.from_dict(m.to_dict()) == m for m in mdps + sensed)
    assert nh.get_task_family("ghh08").make([5.0, -5.0]).wind == (5.0, -5.0)
    model = LearnedModel(tuple(one_substep_params()[0]), (0.1,) * 6, "lr")  # the simulator as one 0.1 s step
    assert model.mdp(substeps=1).dt == 0.1 and model.mdp(substeps=10).substeps == 10
    edge = nh.MDP("model", params=(-MAX_MAGNITUDE, *DEFAULT_PARAMS[1:]), noise_std=(MAX_MAGNITUDE,) * 6, substeps=1, dt=0.1)
    returns = nh.evaluate(nh.baseline_policy(), edge, n_steps=20).returns
    assert np.isfinite(returns).all() and (returns < 0).all()  # at the bound a crash is flown, its return finite


@pytest.mark.parametrize(
    ("column", "value", "says"),
    [
        (ROW_PARAMS.start, 1e300, "magnitude=1e+300, which no MDP has: allowed at most 10000"),
        (ROW_NOISE.start, 2e4, "magnitude=20000.0, which no MDP has"),
        (ROW_WIND_START, -1e5, "magnitude=100000.0, which no MDP has"),
        (ROW_D_U, 1e6, "magnitude=1000000.0, which no MDP has"),
        (ROW_DT, 1e9, "substeps x dt=1000000000.0, which no MDP has: allowed one 0.1 s control step"),
    ],
)
def test_kernel_rows_past_the_bounds_are_refused(column: int, value: float, says: str) -> None:
    """T27-B06: evaluate_jobs on a row with 1e300 gave a NaN return; rows are bounded as MDPs are."""
    rows = np.stack([nh.MDP("model", substeps=1, dt=0.1).row()] * 2)
    rows[1, column] = value
    with pytest.raises(NeurohoverError, match=re.escape(f"MDP row 1 has {'' if 'dt' in says else 'a parameter, noise std, wind number or D_u of '}{says}")):
        check_rows(rows)
    check_rows(rows[:1])


@pytest.mark.parametrize("label", ["ghh08/train:0", "ghh09/test:5", "fghh/zero", "ghh08/wind=[1.0, 2.0]"])
def test_a_learned_models_mdp_takes_no_task_familys_label(label: str) -> None:
    """T28-B09: a model's MDP labelled 'ghh08/train:0' was evolved on, and the policy file claimed that target; a GHH-09
    env reported 'ghh08/test:5'."""
    model = LearnedModel(tuple(one_substep_params()[0]), (0.1,) * 6, "lr")
    with pytest.raises(
        NeurohoverError, match=re.escape(f"MDP {label!r} is not allowed: its label names a '{label.split('/')[0]}' MDP, but the MDP is a learned model's")
    ):
        model.mdp(label=label)
    assert model.mdp(label="model/lr").label == "model/lr" and model.mdp(label="learned").label == "learned"
    assert nh.MDP("model", substeps=1, dt=0.1, label="model/train:3").label == "model/train:3"  # 'train:3' alone is refused (T33-B09)
