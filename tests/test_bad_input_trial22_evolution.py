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
from neurohover.evolution.generational import GenerationalNE, GenerationalSettings
from neurohover.evolution.optimisers import OPTIMISERS
from neurohover.evolution.steady_state import SteadyStateNE


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


# --------------------------------------------------------------------------- T22-13: fewer episodes than genomes asked


def test_a_generation_of_fewer_episodes_than_genomes_is_refused() -> None:
    """T22-13: GenerationalNE.tell(fitness, TellInfo(episodes=0)) was taken for a generation of ten asked genomes: its
    evaluations (the episodes its budget counts) stayed 0 and stop() never came. Each evaluation flies an episode or
    more, so now a TellInfo of fewer episodes than genomes asked is refused, naming both, and nothing is told."""
    g = GenerationalNE(np.zeros(40), GenerationalSettings(budget=100, pop_size=10, select_size=3))
    x = g.ask()
    for episodes in (0, 9):
        with _raises(f"TellInfo episodes={episodes} is not allowed: fewer than the 10 genomes asked"):
            g.tell(-np.ones(len(x)), TellInfo(episodes=episodes))
    assert g.state_dict()["evaluations"] == 0 and g.generation == 0
    g.tell(-np.ones(len(x)), TellInfo(episodes=10))  # the batch still asked, told as flown
    for _ in range(9):  # as many as asked: the budget of 100 episodes stops it after ten generations
        g.tell(-np.ones(len(g.ask())), TellInfo(episodes=10))
    assert g.evaluations == 100 and g.stop()


@pytest.mark.parametrize("name", ["steady-state", *sorted(OPTIMISERS)])
def test_every_optimiser_refuses_fewer_episodes_than_genomes(name: str) -> None:
    """T22-13: the check is TellInfo's (at every tell), also for optimisers that do not read its episodes."""
    genome = np.zeros(6)
    opt = SteadyStateNE(genome, seed=1) if name == "steady-state" else OPTIMISERS[name].make(genome, OPTIMISERS[name].settings(), 1)
    n = len(opt.ask())
    with _raises(f"TellInfo episodes={n - 1} is not allowed: fewer than the {n} genomes asked"):
        opt.tell(-np.ones(n), TellInfo(episodes=n - 1))
    opt.tell(-np.ones(n), TellInfo(episodes=n))  # the same batch, told as flown
