"""Bad-input trial 54, side B (files and helpers): crash_aware took a positive reward as its absolute value (+5 squashed
as -5, +2000 charged as a crash; T54-B07): neurohover's rewards are at most 0, so a positive one is refused by name."""

from __future__ import annotations

import numpy as np
import pytest

from neurohover import NeurohoverError
from neurohover.wrappers import crash_aware


@pytest.mark.parametrize("reward", [5.0, 2000.0, 1e-300, np.array([-1.0, 0.5]), [[-2.0], [3.0]]])
def test_b07_a_positive_reward_is_refused_not_squashed_as_its_size(reward) -> None:
    with pytest.raises(NeurohoverError, match=r"is not allowed: give rewards <= 0, as neurohover's are"):
        crash_aware(reward)


def test_b07_rewards_at_most_zero_are_squashed_as_before() -> None:
    assert crash_aware(-0.0) == 0.0 and crash_aware(0) == 0.0 and crash_aware(-3) == pytest.approx(-np.log(4.0))
    assert crash_aware(np.array([-1.0, -5.0])) == pytest.approx(-np.log1p([1.0, 5.0]))
