"""Bad-input trial 28, T28-B17: EC-MENO fitted flight data that LR refuses as undetermined. A documented choice, pinned
here: the evolution starts from the prototype, which holds the directions the data do not see, and its stats say that
the data have no unique least-squares minimum (None)."""

from __future__ import annotations

import numpy as np
import pytest

import neurohover as nh
from neurohover.errors import NeurohoverError
from neurohover.models import learn_ec_meno, learn_lr


def test_data_that_leave_an_axis_undetermined_are_refused_by_lr_and_fitted_by_ec_meno_from_its_prior() -> None:
    still = nh.FlightData([np.zeros((31, 12))], [np.zeros((30, 4))], {})
    with pytest.raises(NeurohoverError, match="flight data do not determine the u axis"):
        learn_lr(still)
    model = learn_ec_meno(still, budget=10)
    assert model.stats["least_squares_one_step_error"] is None and model.stats["excess"] is None
