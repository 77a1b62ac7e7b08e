"""GHH-09, the 2009 competition: sinusoidal x and y winds (docs/model.md, Task families)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..errors import NeurohoverError
from ..sim.constants import ROW_WIND, WIND_SINUSOID
from .base import MDP, TaskFamily, finite_vector, mdp_label

GHH09_PARAM_NAMES = (
    "x_maxf",
    "x_freq",
    "x_phase",
    "x_center",
    "y_maxf",
    "y_freq",
    "y_phase",
    "y_center",
)


@dataclass(frozen=True)
class GHH09(TaskFamily):
    """2009 competition: sinusoidal x and y winds, 8 parameters (maxf, freq, phase, center) x 2 in [0, 1]."""

    name = "ghh09"
    n_params = 8
    param_names = GHH09_PARAM_NAMES
    row_slice = slice(ROW_WIND.start, ROW_WIND.start + 8)
    set_code = 9
    wind_kind = WIND_SINUSOID
    param_bounds = (0.0, 1.0)

    def make(self, params: Sequence[float] | np.ndarray, label: str = "") -> MDP:
        p = finite_vector(params, 8, "GHH-09 parameters " + "/".join(GHH09_PARAM_NAMES))
        bad = [f"{n}={v}" for n, v in zip(GHH09_PARAM_NAMES, p) if not self.param_bounds[0] <= v <= self.param_bounds[1]]
        if bad:
            raise NeurohoverError(f"GHH-09 parameters out of range ({', '.join(bad)}): each must lie in [0, 1]")
        return MDP("ghh09", wind_kind=WIND_SINUSOID, wind=tuple(p.tolist()), label=mdp_label(label, "ghh09/custom"))

    def zero(self) -> MDP:
        return MDP("ghh09", label="ghh09/zero")

    def sample_params(self, rng: np.random.Generator, n: int) -> np.ndarray:
        return rng.uniform(0.0, 1.0, (n, 8))


TASK_FAMILY = GHH09
