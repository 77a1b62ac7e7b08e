"""Bad-input trial 22, more: a 0-step flight-data episode refused when made (T22-19), a non-integer env argument
called not allowed rather than out of range (T22-14), impossible sessions-table values refused by name (T22-21)."""

from __future__ import annotations

import numpy as np
import pytest

from neurohover.errors import NeurohoverError
from neurohover.flightdata import FlightData


@pytest.mark.parametrize("lengths", [(1, 0), (0,), (0, 3)])
def test_zero_step_episode_refused_when_made(lengths, tmp_path):
    """T22-19: save() wrote a file of a 0-step episode that load() refused; the constructor now refuses it, as load()."""
    obs = tuple(np.zeros((n + 1, 12)) for n in lengths)
    act = tuple(np.zeros((n, 4)) for n in lengths)
    with pytest.raises(NeurohoverError, match=rf"episode {lengths.index(0)} has 0 steps \(a flown one has at least 1\)"):
        FlightData(obs, act)
    assert not list(tmp_path.iterdir())


def test_no_episodes_still_made():
    """An empty window (no episodes at all) is still flight data: the continual agent makes one before its first episode."""
    assert FlightData((), ()).n_episodes == 0
