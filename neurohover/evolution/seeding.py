"""The one seed derivation of an evolution run: everything random comes from ``SeedSequence(seed)``.

Child ``(key,)`` of ``numpy.random.SeedSequence(seed)`` seeds one job of a run:

* ``(0,)``, :func:`optimiser_seed`: the optimiser's own generator (NE or CMA-ES);
* ``(1,)``, :func:`mdp_rng`: the stream of MDPs drawn from a task family;
* ``(2,)``, :func:`noise_seed`: the root of the episodes' gust noise. Every episode a run flies
  gets the next index of its episode counter and flies noise stream ``(noise root, index)``, so no
  two episodes of a run share noise and results do not depend on the number of kernel threads;
* ``(3,)``, :func:`validation_seeds`: the noise and MDPs of ``validation_return``, which a run
  never uses, so validation episodes are independent of the run's.

An integer seed taken from a child is its first 64-bit state word shifted right by one (63 bits,
the range the kernel's seeds allow). Every helper checks its seed with :func:`check_seed` (an integer
in ``0..2**63-1``, NumPy's included): None was fresh OS entropy, a list a seed of its own, and 1.5 or
-1 NumPy's errors (T44-B02, T44-B03).
"""

from __future__ import annotations

import numpy as np

from ..errors import whole_in
from ..sim.rng import MAX_SEED, check_seed  # the one seed check; envs use it too

__all__ = ["MAX_SEED", "check_seed", "child_int", "mdp_rng", "noise_seed", "optimiser_seed", "reevaluation_seeds", "validation_seeds"]

_OPTIMISER, _MDPS, _NOISE, _VALIDATION, _REEVALUATION = 0, 1, 2, 3, 4


def child_int(seed: int, key: int) -> int:
    """A 63-bit integer from child ``key`` (an integer in ``0..2**63-1``) of ``SeedSequence(seed)``."""
    root, child = check_seed(seed), whole_in(key, "key", 0, MAX_SEED, "2**63-1")
    return int(np.random.SeedSequence(root, spawn_key=(child,)).generate_state(1, np.uint64)[0] >> np.uint64(1))


def optimiser_seed(seed: int) -> int:
    """Seed of the optimiser of the run with root ``seed``."""
    return child_int(seed, _OPTIMISER)


def noise_seed(seed: int) -> int:
    """Root of the gust noise of the episodes of the run with root ``seed``."""
    return child_int(seed, _NOISE)


def mdp_rng(seed: int) -> np.random.Generator:
    """The generator the run with root ``seed`` draws its task family's MDPs with."""
    return np.random.default_rng(np.random.SeedSequence(check_seed(seed), spawn_key=(_MDPS,)))


def _seed_pair(seed: int, child: int) -> tuple[int, int]:
    """``(noise seed, MDP seed)``: the first two 63-bit words of child ``(child,)`` of root ``seed``."""
    state = np.random.SeedSequence(check_seed(seed), spawn_key=(child,)).generate_state(2, np.uint64)
    noise, mdps = (int(x >> np.uint64(1)) for x in state)
    return noise, mdps


def reevaluation_seeds(seed: int) -> tuple[int, int]:
    """``(noise seed, MDP seed)`` of the episodes that choose a run's champion again
    (:func:`neurohover.evolution.evolve.reevaluated_champion`): child ``(4,)``."""
    return _seed_pair(seed, _REEVALUATION)


def validation_seeds(seed: int) -> tuple[int, int]:
    """``(noise seed, MDP seed)`` of the validation episodes for root ``seed``: child ``(3,)``."""
    return _seed_pair(seed, _VALIDATION)
