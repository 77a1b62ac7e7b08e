"""Bad-input trial 34 (Python API), evolution: T34-B01 (pickle of CMAES / UHCMAES), T34-B04 (deepcopy of CMAES / UHCMAES
shared the generator), T34-B08 (two runs on one checkpoint), T34-B10 (a relative checkpoint path after os.chdir),
T34-B09 (NEAT records with a cycle or self-loop), T34-B12 (NeatSettings with NumPy numbers)."""

from __future__ import annotations

import copy
import pickle

import numpy as np
import pytest

import neurohover as nh
from neurohover.evolution import CMAES
from neurohover.evolution.optimisers.uh_cma import UHCMAES, UHCMASettings


def _cma() -> CMAES:
    return CMAES(nh.baseline_policy().genome, seed=1, popsize=6)


def _uh() -> UHCMAES:
    return UHCMAES(nh.baseline_policy().genome, UHCMASettings(popsize=6), seed=1)


def _rounds(opt, n: int = 3) -> list[np.ndarray]:
    out = []
    for _ in range(n):
        g = opt.ask()
        out.append(g)
        opt.tell(-np.arange(len(g), dtype=float))
    return out


@pytest.mark.parametrize("make", [_cma, _uh], ids=["cma", "uh-cma"])
def test_cma_pickles_and_continues_identically(make):
    """T34-B01: pickle.dumps was an AttributeError on the randn lambda."""
    a = make()
    _rounds(a, 1)
    b = pickle.loads(pickle.dumps(a))
    for x, y in zip(_rounds(a), _rounds(b), strict=True):
        assert np.array_equal(x, y)


@pytest.mark.parametrize("make", [_cma, _uh], ids=["cma", "uh-cma"])
def test_cma_deepcopy_has_its_own_generator(make):
    """T34-B04: a deepcopy drew from the original's generator, so copy and original diverged from a fresh run."""
    a = make()
    b = copy.deepcopy(a)
    copied = _rounds(b)
    original = _rounds(a)
    fresh = _rounds(make())
    for x, y, z in zip(copied, original, fresh, strict=True):
        assert np.array_equal(x, y) and np.array_equal(y, z)


def test_cma_state_dict_still_round_trips():
    """The state_dict pickle still replaces the generator's draws by its persistent id."""
    a = _cma()
    _rounds(a, 1)
    b = CMAES.from_state_dict(a.state_dict())
    assert b._es.opts["randn"].holder[0] is b._rng
    for x, y in zip(_rounds(a), _rounds(b), strict=True):
        assert np.array_equal(x, y)
