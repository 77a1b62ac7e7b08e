"""Task families (generalized tasks) and their MDPs: docs/model.md, Task families.

A task family is a distribution G over MDPs; an MDP is fully fixed by its parameters. Each family
offers its zero setting (the mean MDP), explicit construction from parameters (validated), a
sampler of fresh MDPs, and fixed sets of 10 training and 100 test MDPs.

The fixed sets are the competitions' own MDPs, as the paper's authors used them (their experiment
code's lists, shipped as ``neurohover/data/competition-mdps.json``; 0-based, the paper numbers
from 1): GHH-08, GHH-09 and FGHH at sigma = 0.3. Seeded draws from G form a second, harder pair of
sets, named ``seeded-train:N`` / ``seeded-test:N`` (:meth:`seeded_training_mdps`); for FGHH at any
other sigma they are the only fixed sets, and ``train:N`` / ``test:N`` name them.

Example
-------
>>> from neurohover.tasks import get_task_family
>>> family = get_task_family("ghh08")
>>> mdp = family.make([2.5, -1.0])            # constant wind (m/s)
>>> train = family.training_mdps()            # 10 fixed MDPs
"""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from pathlib import Path
from dataclasses import dataclass, field

import numpy as np

from .errors import NeurohoverError
from .sim.constants import (
    DEFAULT_NOISE_STD,
    DEFAULT_PARAMS,
    MDP_ROW_LEN,
    PARAM_NAMES,
    ROW_D_U,
    SUBSTEP_DT,
    SUBSTEPS,
    WIND_CONSTANT,
    WIND_NONE,
    WIND_SINUSOID,
)
from .sim.reference import ReferenceMDP

TASK_NAMES = ("ghh08", "ghh09", "fghh")
N_TRAINING = 10
N_TEST = 100
MAX_WIND = 5.0
GHH09_PARAM_NAMES = (
    "x_maxf", "x_freq", "x_phase", "x_center", "y_maxf", "y_freq", "y_phase", "y_center",
)
_SET_ENTROPY = 20110401  # fixed root of the seeded training and test sets (the paper's year)
_FAMILY_CODE = {"ghh08": 8, "ghh09": 9, "fghh": 12}
_FIXED_SETS: dict[tuple[str, int, int], tuple["MDP", ...]] = {}
COMPETITION_MDPS_FILE = Path(__file__).parent / "data" / "competition-mdps.json"
COMPETITION_FGHH_SIGMA = 0.3  # the only FGHH sigma the authors' code lists MDPs for
_COMPETITION: dict[str, dict] = {}


@dataclass(frozen=True)
class MDP:
    """One fully specified helicopter MDP (or learned model).

    Attributes
    ----------
    family : str
        ``"ghh08"``, ``"ghh09"``, ``"fghh"`` or ``"model"`` (a learned model).
    params : tuple of float
        The 11 dynamics parameters, in the order of ``neurohover.sim.constants.PARAM_NAMES``.
    noise_std : tuple of float
        Gust-noise standard deviations for u, v, w, p, q, r.
    wind_kind : int
        0 none, 1 constant (GHH-08), 2 sinusoidal (GHH-09).
    wind : tuple of float
        (wind_u, wind_v) in m/s for kind 1; the 8 GHH-09 parameters for kind 2.
    substeps, dt : int, float
        Integration substeps per 0.1 s control step and their length (a learned model: 1, 0.1).
    d_u : float
        Constant body-frame u acceleration, the paper's D_u: 0 in every true MDP; a learned model
        may fit it (a constant wind acts near hover as a constant acceleration).
    label : str
        Human-readable name, e.g. ``"ghh08/train:3"``.
    """

    family: str
    params: tuple[float, ...] = tuple(DEFAULT_PARAMS)
    noise_std: tuple[float, ...] = tuple(DEFAULT_NOISE_STD)
    wind_kind: int = WIND_NONE
    wind: tuple[float, ...] = ()
    substeps: int = SUBSTEPS
    dt: float = SUBSTEP_DT
    label: str = field(default="", compare=False)
    d_u: float = 0.0

    def row(self) -> np.ndarray:
        """The float64 row the compiled kernel reads (layout in ``sim.constants``)."""
        row = np.zeros(MDP_ROW_LEN)
        row[0:11] = self.params
        row[11:17] = self.noise_std
        row[17] = self.substeps
        row[18] = self.dt
        row[19] = self.wind_kind
        row[20 : 20 + len(self.wind)] = self.wind
        row[ROW_D_U] = self.d_u
        return row

    def to_reference(self) -> ReferenceMDP:
        """The same MDP for the plain-Python reference simulator."""
        wind = tuple(self.wind) + (0.0,) * (8 - len(self.wind))
        return ReferenceMDP(self.params, self.noise_std, self.wind_kind, wind, self.substeps, self.dt, self.d_u)

    def to_dict(self) -> dict:
        return {
            "family": self.family, "params": list(self.params), "noise_std": list(self.noise_std),
            "wind_kind": self.wind_kind, "wind": list(self.wind), "substeps": self.substeps,
            "dt": self.dt, "label": self.label, "d_u": self.d_u,
        }

    @classmethod
    def from_dict(cls, d: dict) -> "MDP":
        return cls(
            d["family"], tuple(map(float, d["params"])), tuple(map(float, d["noise_std"])),
            int(d["wind_kind"]), tuple(map(float, d["wind"])), int(d["substeps"]), float(d["dt"]),
            d.get("label", ""), float(d.get("d_u", 0.0)),
        )


def _as_finite_vector(values: Sequence[float] | np.ndarray, length: int, what: str) -> np.ndarray:
    try:
        arr = np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        raise NeurohoverError(f"{what} must be {length} numbers, got {values!r}") from None
    if arr.shape != (length,):
        raise NeurohoverError(f"{what} must be {length} numbers, got {arr.size}: {values!r}")
    if not np.all(np.isfinite(arr)):
        raise NeurohoverError(f"{what} must be finite numbers, got {arr.tolist()}")
    return arr


def _seed_sequence(family: str, which: int, extra: int = 0) -> np.random.SeedSequence:
    return np.random.SeedSequence([_SET_ENTROPY, _FAMILY_CODE[family], which, extra])


class _FamilyBase:
    """Shared behaviour: fixed sets and sampling are defined through ``_from_unit`` draws."""

    name: str
    n_params: int

    def make(self, params: Sequence[float]) -> MDP:  # pragma: no cover - overridden
        raise NotImplementedError

    def zero(self) -> MDP:  # pragma: no cover - overridden
        raise NotImplementedError

    def _draw(self, rng: np.random.Generator) -> np.ndarray:  # pragma: no cover - overridden
        raise NotImplementedError

    def _set_key(self) -> int:
        return 0

    def sample(self, rng: np.random.Generator | int | None = None, label: str = "") -> MDP:
        """A fresh MDP drawn from G."""
        rng = np.random.default_rng(rng)
        return self.make(self._draw(rng), label=label or f"{self.name}/sample")

    def _seeded_set(self, which: int, n: int, kind: str) -> list[MDP]:
        key = (self.name, self._set_key(), which)
        if key not in _FIXED_SETS:  # MDPs are immutable, so each set is built once per process
            rng = np.random.default_rng(_seed_sequence(self.name, which, self._set_key()))
            _FIXED_SETS[key] = tuple(self.make(self._draw(rng), label=f"{self.name}/{kind}:{i}") for i in range(n))
        return list(_FIXED_SETS[key])

    @property
    def has_competition_sets(self) -> bool:
        """True when ``train:N`` / ``test:N`` are the competition's MDPs (else the seeded draws)."""
        return True

    def _competition_row(self, value: Sequence[float]) -> Sequence[float]:
        """The MDP parameters of one row of the competition file (GHH-08 scales it to m/s)."""
        return value

    def _competition_set(self, kind: str) -> list[MDP]:
        key = (self.name, -1, 0 if kind == "train" else 1)
        if key not in _FIXED_SETS:
            rows = competition_rows(self.name)[kind]
            _FIXED_SETS[key] = tuple(
                self.make(self._competition_row(r), label=f"{self.name}/{kind}:{i}") for i, r in enumerate(rows)
            )
        return list(_FIXED_SETS[key])

    def training_mdps(self) -> list[MDP]:
        """The 10 training MDPs: the competition's (seeded draws where it has none)."""
        if self.has_competition_sets:
            return self._competition_set("train")
        return self.seeded_training_mdps()

    def test_mdps(self) -> list[MDP]:
        """The 100 test MDPs: the competition's (seeded draws where it has none)."""
        if self.has_competition_sets:
            return self._competition_set("test")
        return self.seeded_test_mdps()

    def seeded_training_mdps(self) -> list[MDP]:
        """10 training MDPs drawn from G with a fixed seed (``seeded-train:N``): harder than the competition's."""
        return self._seeded_set(0, N_TRAINING, "seeded-train")

    def seeded_test_mdps(self) -> list[MDP]:
        """100 test MDPs drawn from G with a fixed seed (``seeded-test:N``)."""
        return self._seeded_set(1, N_TEST, "seeded-test")

    def mdp(self, spec: str, rng: np.random.Generator | int | None = None) -> MDP:
        """An MDP by name: ``zero``, ``train:N``, ``test:N``, ``seeded-train:N``, ``seeded-test:N`` or ``sample``."""
        if spec == "zero":
            return self.zero()
        if spec == "sample":
            return self.sample(rng)
        kind, _, index = spec.partition(":")
        sets = {
            "train": (self.training_mdps, N_TRAINING), "test": (self.test_mdps, N_TEST),
            "seeded-train": (self.seeded_training_mdps, N_TRAINING), "seeded-test": (self.seeded_test_mdps, N_TEST),
        }
        if kind in sets and index.isdigit():
            getter, n = sets[kind]
            if int(index) < n:
                return getter()[int(index)]
            raise NeurohoverError(f"MDP index {index} in {spec!r} is out of range: allowed 0..{n - 1}")
        raise NeurohoverError(
            f"unknown MDP {spec!r}: allowed zero, sample, train:N and seeded-train:N (0..{N_TRAINING - 1}), "
            f"test:N and seeded-test:N (0..{N_TEST - 1})"
        )


def competition_rows(family: str) -> dict:
    """The competition's training and test rows of ``family`` as listed in the shipped data file."""
    if not _COMPETITION:
        _COMPETITION.update(json.loads(COMPETITION_MDPS_FILE.read_text()))
    return _COMPETITION[family]


@dataclass(frozen=True)
class GHH08(_FamilyBase):
    """2008 competition: constant world wind (wind_u, wind_v), each uniform in [-5, 5] m/s."""

    name: str = "ghh08"
    n_params: int = 2

    def make(self, params: Sequence[float], label: str = "") -> MDP:
        wind = _as_finite_vector(params, 2, "GHH-08 wind (wind_u, wind_v)")
        if np.any(np.abs(wind) > MAX_WIND):
            raise NeurohoverError(f"GHH-08 wind {wind.tolist()} m/s is out of range: each component must lie in [-5, 5]")
        return MDP("ghh08", wind_kind=WIND_CONSTANT, wind=tuple(wind.tolist()), label=label or f"ghh08/wind={wind.tolist()}")

    def zero(self) -> MDP:
        return MDP("ghh08", label="ghh08/zero")  # no wind: the zero setting is the same MDP in every family

    def _draw(self, rng: np.random.Generator) -> np.ndarray:
        return rng.uniform(-MAX_WIND, MAX_WIND, 2)

    def _competition_row(self, value: Sequence[float]) -> Sequence[float]:
        return [MAX_WIND * v for v in value]  # the file lists the wind as values in [-1, 1]


@dataclass(frozen=True)
class GHH09(_FamilyBase):
    """2009 competition: sinusoidal x and y winds, 8 parameters (maxf, freq, phase, center) x 2 in [0, 1]."""

    name: str = "ghh09"
    n_params: int = 8

    def make(self, params: Sequence[float], label: str = "") -> MDP:
        p = _as_finite_vector(params, 8, "GHH-09 parameters " + "/".join(GHH09_PARAM_NAMES))
        bad = [f"{n}={v}" for n, v in zip(GHH09_PARAM_NAMES, p) if not 0.0 <= v <= 1.0]
        if bad:
            raise NeurohoverError(f"GHH-09 parameters out of range ({', '.join(bad)}): each must lie in [0, 1]")
        return MDP("ghh09", wind_kind=WIND_SINUSOID, wind=tuple(p.tolist()), label=label or "ghh09/custom")

    def zero(self) -> MDP:
        return MDP("ghh09", label="ghh09/zero")

    def _draw(self, rng: np.random.Generator) -> np.ndarray:
        return rng.uniform(0.0, 1.0, 8)


@dataclass(frozen=True)
class FGHH(_FamilyBase):
    """Fully generalized: no wind; each of the 11 dynamics parameters ~ N(d, (|d| sigma)^2)."""

    sigma: float = 0.3
    name: str = "fghh"
    n_params: int = 11

    def __post_init__(self) -> None:
        if not (isinstance(self.sigma, (int, float)) and math.isfinite(self.sigma) and 0.0 <= self.sigma <= 1.0):
            raise NeurohoverError(f"FGHH sigma={self.sigma!r} is out of range: allowed 0 <= sigma <= 1 (the paper uses 0.2 and 0.3)")

    def make(self, params: Sequence[float], label: str = "") -> MDP:
        p = _as_finite_vector(params, 11, "FGHH dynamics parameters " + "/".join(PARAM_NAMES))
        return MDP("fghh", params=tuple(p.tolist()), label=label or "fghh/custom")

    def zero(self) -> MDP:
        return MDP("fghh", label="fghh/zero")

    def _draw(self, rng: np.random.Generator) -> np.ndarray:
        return rng.normal(DEFAULT_PARAMS, np.abs(DEFAULT_PARAMS) * self.sigma)

    def _set_key(self) -> int:
        return int(round(self.sigma * 1_000_000))

    @property
    def has_competition_sets(self) -> bool:
        return self.sigma == COMPETITION_FGHH_SIGMA


TaskFamily = GHH08 | GHH09 | FGHH


def get_task_family(name: str, sigma: float | None = None) -> TaskFamily:
    """The task family called ``name`` (``ghh08``, ``ghh09`` or ``fghh``; ``sigma`` for FGHH)."""
    key = str(name).lower().replace("-", "")
    if key not in TASK_NAMES:
        raise NeurohoverError(f"unknown task {name!r}: allowed {', '.join(TASK_NAMES)}")
    if sigma is not None and key != "fghh":
        raise NeurohoverError(f"sigma applies to the fghh task only, not to {name!r}")
    if key == "ghh08":
        return GHH08()
    if key == "ghh09":
        return GHH09()
    return FGHH(0.3 if sigma is None else float(sigma))
