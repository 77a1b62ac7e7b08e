"""Trial 35, helper B (Python API and hand-edited files): T35-B04 (race bounds of huge or denormal returns), T35-B10
(a race's delta of the wrong type), T35-B05 (plots written under a name that is no .png), T35-B06 (a store with a
column added by hand), T35-B09 (drift windows read as Python's int() reads)."""

from __future__ import annotations

import decimal

import numpy as np
import pytest

from neurohover.errors import NeurohoverError
from neurohover.evolution import bayes_mean_bounds, selection_race


@pytest.mark.parametrize("delta", ["0.5", decimal.Decimal("0.5"), np.array(0.5), True, [0.5]])
def test_t35_b10_delta_of_the_wrong_type_is_not_a_number(delta):
    pattern = r"is not a number: allowed a confidence level strictly between 0 and 1"
    with pytest.raises(NeurohoverError, match=pattern):
        selection_race(lambda idx: -np.ones(len(idx)), 4, 2, delta)
    with pytest.raises(NeurohoverError, match=pattern):
        bayes_mean_bounds(np.array([1.0, 2.0]), delta)
    with pytest.raises(NeurohoverError, match=r"delta=1\.5 must be a confidence level"):
        bayes_mean_bounds(np.array([1.0, 2.0]), 1.5)
