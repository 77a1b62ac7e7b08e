"""GHH-08, the 2008 competition: a constant world wind (docs/model.md, Task families)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..errors import NeurohoverError
from ..sim.constants import ROW_WIND, WIND_CONSTANT
from .base import MDP, TaskFamily, finite_vector, mdp_label

MAX_WIND = 5.0


@dataclass(frozen=True)
class GHH08(TaskFamily):
    """2008 competition: constant world wind (wind_u, wind_v), each uniform in [-5, 5] m/s."""

    name = "ghh08"
    n_params = 2
    param_names = ("wind_u", "wind_v")
    row_slice = slice(ROW_WIND.start, ROW_WIND.start + 2)
    set_code = 8
    wind_kind = WIND_CONSTANT
    param_bounds = (-MAX_WIND, MAX_WIND)

    def make(self, params: Sequence[float] | np.ndarray, label: str = "") -> MDP:
        wind = finite_vector(params, 2, "GHH-08 wind (wind_u, wind_v)") + 0.0  # a -0.0 labelled another run (T31-A07)
        if np.any(np.abs(wind) > MAX_WIND):
            raise NeurohoverError(f"GHH-08 wind {wind.tolist()} m/s is out of range: each component must lie in [-5, 5]")
        return MDP("ghh08", wind_kind=WIND_CONSTANT, wind=tuple(wind.tolist()), label=mdp_label(label, f"ghh08/wind={wind.tolist()}"))

    def zero(self) -> MDP:
        return MDP("ghh08", label="ghh08/zero")  # no wind: the zero setting is the same MDP in every family

    def sample_params(self, rng: np.random.Generator, n: int) -> np.ndarray:
        return rng.uniform(-MAX_WIND, MAX_WIND, (n, 2))

    def competition_params(self, row: Sequence[float]) -> Sequence[float]:
        return [MAX_WIND * v for v in row]  # the file lists the wind as values in [-1, 1]


TASK_FAMILY = GHH08
