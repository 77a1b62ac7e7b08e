"""The twenty-second bad-input trial's findings in evolution runs and their checkpoints (T22-10 to T22-14): a
checkpoint's champion, history, prototype or stop reason that contradicts the rest of it is refused on resume, as a
damaged checkpoint, and a tell() of fewer episodes than genomes asked is refused; a generation's episodes that are no
integer are "not allowed", not "out of range"."""

from __future__ import annotations

import re

import numpy as np
import pytest

from neurohover.errors import NeurohoverError
from neurohover.evolution.common import TellInfo


def _raises(fragment: str):
    return pytest.raises(NeurohoverError, match=re.escape(fragment))


# --------------------------------------------------------------------------- T22-14: episodes that are no integer


@pytest.mark.parametrize("episodes", [3.0, True, "3", np.float64(2.0)])
def test_a_generations_episodes_of_the_wrong_type_are_not_allowed(episodes) -> None:
    """T22-14: TellInfo(episodes=3.0) said "is out of range" (a type problem); now "is not allowed", with the range."""
    with _raises(f"episodes={episodes!r} is not allowed: allowed an integer in 0..10,000,000,000 (the episodes one generation cost)"):
        TellInfo(episodes=episodes)


@pytest.mark.parametrize("episodes", [-1, 10**10 + 1])
def test_a_generations_episodes_out_of_range_stay_out_of_range(episodes: int) -> None:
    """T22-14: an integer outside 0..MAX_EPISODES is still "out of range"."""
    with _raises(f"episodes={episodes!r} is out of range: allowed an integer in 0..10,000,000,000"):
        TellInfo(episodes=episodes)
