"""Issue 37, items left by the twenty-sixth session and closed in the twenty-seventh: an MDP made before
``importlib.reload(neurohover.tasks.drift)`` was refused by evaluate as "give an MDP or a task family", although it is
one (its Drift is of the first import): now named by its cause, as T42-B07 names a reloaded Sensor's or Drift's."""

from __future__ import annotations

import importlib
import sys

import pytest

import neurohover as nh
from neurohover import NeurohoverError


def test_an_mdp_made_before_a_reload_of_drift_is_named_by_its_cause() -> None:
    mdp = nh.get_task_family("ghh08").test_mdps()[0]
    module = sys.modules["neurohover.tasks.drift"]
    saved = dict(module.__dict__)
    try:
        importlib.reload(module)
        cause = r"^mdp's drift Drift\(.*is a Drift of another import of neurohover\.tasks\.drift \(the module was reloaded\?\)"
        with pytest.raises(NeurohoverError, match=cause):
            nh.evaluate(nh.baseline_policy(), mdp, n_steps=10)
    finally:
        module.__dict__.clear()
        module.__dict__.update(saved)
    assert nh.evaluate(nh.baseline_policy(), mdp, n_steps=10).returns.size == 1  # the first import's again
