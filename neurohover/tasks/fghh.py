"""FGHH, the fully generalized task: no wind, every dynamics parameter perturbed (docs/model.md, Task families)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..errors import NeurohoverError, brief, finite_real, real_number, setting_float
from ..sim.constants import DEFAULT_PARAMS, MIN_NOISE, PARAM_NAMES, ROW_PARAMS
from .base import MAX_MAGNITUDE, MDP, TaskFamily, finite_vector, mdp_label

COMPETITION_FGHH_SIGMA = 0.3  # the only FGHH sigma the authors' code lists MDPs for


#: The largest magnitude of an FGHH dynamics parameter make() takes: 140 times the defaults' largest (sigma <= 1 draws
#: stay far inside); at it a crash is flown at once, and far past it (1e300) the simulation overflowed to NaN.
MAX_PARAM = MAX_MAGNITUDE
#: The smallest sigma but 0, float64's epsilon 2**-52 as drift's smallest walk and a sensor's smallest std: a draw is
#: d + |d| sigma z, and below it a parameter's std |d| sigma is under one float64 step of d, so a draw is d or a step
#: from it (1e-17 drew the zero setting 200 times in 200, labelled and recorded as its own sigma; T50-B02).
MIN_SIGMA = MIN_NOISE


@dataclass(frozen=True)
class FGHH(TaskFamily):
    """Fully generalized: no wind; each of the 11 dynamics parameters ~ N(d, (|d| sigma)^2)."""

    sigma: float = 0.3  # a field here; None on families without a breadth
    name = "fghh"
    n_params = 11
    param_names = PARAM_NAMES
    row_slice = ROW_PARAMS
    set_code = 12
    has_sigma = True
    generic_over_distribution = True

    def __post_init__(self) -> None:
        s = self.sigma
        allowed = "0 <= sigma <= 1 (the paper uses 0.2 and 0.3)"
        if not real_number(s):  # 'x' was called out of range (T26-B17)
            raise NeurohoverError(f"FGHH sigma={brief(s)} is not allowed: give a number {allowed}")
        if not (finite_real(s) and 0.0 <= s <= 1.0):  # any real number type, np.float32 too
            raise NeurohoverError(f"FGHH sigma={brief(s)} is out of range: allowed {allowed}")
        if 0 < s < MIN_SIGMA:  # flew as sigma 0 (T50-B02)
            raise NeurohoverError(
                f"FGHH sigma={brief(s)} is out of range, too small to change the dynamics (a parameter's std below 2**-52 of it): "
                f"allowed 0 (the zero setting's dynamics) or a number in {MIN_SIGMA!r}..1 (the paper uses 0.2 and 0.3)"
            )
        object.__setattr__(self, "sigma", setting_float(s))  # -0.0 passes 0 <= sigma but was NumPy's "scale < 0" at the first draw (T14-2)

    def make(self, params: Sequence[float] | np.ndarray, label: str = "") -> MDP:
        p = finite_vector(params, 11, "FGHH dynamics parameters " + "/".join(PARAM_NAMES))
        if np.abs(p).max() > MAX_PARAM:  # 1e300 overflowed the simulation to NaN returns (third trial)
            raise NeurohoverError(f"FGHH dynamics parameters must lie in [-{MAX_PARAM:g}, {MAX_PARAM:g}] (the defaults' largest is 70.54), got {p.tolist()}")
        return MDP("fghh", params=tuple(p.tolist()), label=mdp_label(label, "fghh/custom"))

    def zero(self) -> MDP:
        return MDP("fghh", label="fghh/zero")

    def sample_params(self, rng: np.random.Generator, n: int) -> np.ndarray:
        return rng.normal(DEFAULT_PARAMS, np.abs(DEFAULT_PARAMS) * self.sigma, (n, 11))

    def set_variant(self) -> int:
        return int(round(self.sigma * 1_000_000))

    @property
    def has_competition_sets(self) -> bool:
        return self.sigma == COMPETITION_FGHH_SIGMA


TASK_FAMILY = FGHH
