"""Bad-input trial 23, T23-12: a CMA-ES state's pickle could name any global, which was looked up and called while the
state was read back (a pickle of os.mkdir made its directory before the resume was refused)."""

from __future__ import annotations

import base64
import os
import pickle
from pathlib import Path

import numpy as np
import pytest

from neurohover.errors import NeurohoverError
from neurohover.evolution.optimisers.cma import CMAES
from neurohover.evolution.optimisers.uh_cma import UHCMAES, UHCMASettings


def test_a_state_pickle_naming_another_global_is_refused_before_it_runs(tmp_path: Path) -> None:
    made = tmp_path / "made"

    class Hostile:
        def __reduce__(self):
            return (os.mkdir, (str(made),))

    state = {"type": "CMAES", "version": 1, "pickle": base64.b64encode(pickle.dumps(Hostile())).decode()}
    with pytest.raises(NeurohoverError, match=r"its pickle names 'posix\.mkdir', which no CMA state holds"):
        CMAES.from_state_dict(state)
    assert not made.exists()
    state["pickle"] = base64.b64encode(pickle.dumps(len)).decode()  # not print: Ray, once started in this process, replaces it
    with pytest.raises(NeurohoverError, match=r"its pickle names 'builtins\.len'"):
        CMAES.from_state_dict(state)


def test_a_state_pickle_naming_a_pycma_function_is_refused() -> None:
    import cma.utilities.utils as utils

    state = {"type": "CMAES", "version": 1, "pickle": base64.b64encode(pickle.dumps(utils.print_warning)).decode()}
    with pytest.raises(NeurohoverError, match=r"its pickle names 'cma\.utilities\.utils\.print_warning', which no CMA state holds"):
        CMAES.from_state_dict(state)


@pytest.mark.parametrize("make", [lambda: CMAES(np.zeros(6), popsize=5, seed=2), lambda: UHCMAES(np.zeros(6), UHCMASettings(popsize=5), seed=2)])
def test_what_state_dict_pickles_still_reads_back(make) -> None:
    opt = make()
    for _ in range(3):
        x = opt.ask()
        opt.tell(-np.sum(x**2, axis=1))
        again = type(opt).from_state_dict(opt.state_dict())
        y = opt.ask()
        assert np.array_equal(again.ask(), y)
        opt.tell(-np.ones(len(y)))
