"""The MDP and the task-family protocol that every family implements (docs/model.md, Task families)."""

from __future__ import annotations

import copy
import functools
import json
from collections.abc import Sequence
from dataclasses import dataclass, field, fields, replace
from pathlib import Path

import numpy as np

from ..errors import (
    NeurohoverError,
    as_floats,
    brief,
    check_length,
    check_name_text,
    finite_real,
    masked_note,
    refuse_reloaded,
    setting_float,
    whole_in,
    whole_number,
)
from ..sim.constants import (
    CONTROL_DT,
    DEFAULT_NOISE_STD,
    DEFAULT_PARAMS,
    MDP_ROW_LEN,
    ROW_D_U,
    ROW_DT,
    ROW_NOISE,
    ROW_PARAMS,
    ROW_SENSOR,
    ROW_SUBSTEPS,
    ROW_WIND_KIND,
    ROW_WIND_START,
    SUBSTEP_DT,
    SUBSTEPS,
    WIND_CONSTANT,
    WIND_NONE,
    WIND_SINUSOID,
)
from ..sim.reference import ReferenceMDP
from .drift import NO_DRIFT, Drift
from .family_checks import checked_draws, generator, through_sensor
from .held import LEARNED_MODEL, check_held, family_code, register_family
from .held import WIND_KINDS as _WIND_KINDS
from .sensor import EXACT, Sensor

N_TRAINING = 10
N_TEST = 100
MAX_SUBSTEPS = 1000  # substeps per 0.1 s control step (the simulator takes 10): more is a typo, and a slow one
#: The largest magnitude of any number of an MDP (dynamics parameters, noise stds, wind numbers, D_u): 140 times the
#: defaults' largest (70.54); at it a crash is flown at once, and far past it (1e300) the simulation overflowed to a NaN
#: return (T27-B06). FGHH's make() holds its parameters to it.
MAX_MAGNITUDE = 10_000.0
#: How far substeps x dt may lie from the control step they integrate (a learned model: 1 x 0.1 s; the simulator 10 x 0.01 s).
COVER_TOLERANCE = 1e-9
_SET_ENTROPY = 20110401  # fixed root of the seeded training and test sets (the paper's year)
#: The fixed sets and row templates built, by the family's class (not its name: a subclass of GHH08 that kept the name
#: "ghh08" replaced GHH-08's sets, and a user's family defined again kept the first definition's; T52-B01, T52-B02).
_FIXED_SETS: dict[tuple[type, int, float | None, int, Sensor, Drift], tuple[MDP, ...]] = {}
_ROW_LAYOUTS: dict[tuple[type, int, Sensor], np.ndarray] = {}
COMPETITION_MDPS_FILE = Path(__file__).parent.parent / "data" / "competition-mdps.json"
_COMPETITION: dict[str, dict] = {}
#: The keys of :meth:`MDP.to_dict`'s table that :meth:`MDP.from_dict` needs (``label``, ``d_u``, ``sensor``, ``drift`` may be left out).
MDP_KEYS = ("family", "params", "noise_std", "wind_kind", "wind", "substeps", "dt")
#: The keys :meth:`MDP.from_dict` also reads; any other is refused.
MDP_OPTIONAL_KEYS = ("label", "d_u", "sensor", "drift")
#: How many wind numbers each wind kind reads (MDP.row() packs them into ROW_WIND), and what to give.
WIND_SLOTS = {
    WIND_NONE: (0, "no wind numbers: wind=()"),
    WIND_CONSTANT: (2, "2 finite numbers: wind_u, wind_v in m/s"),
    WIND_SINUSOID: (8, "8 finite numbers: maxf, freq, phase, center for x, then for y"),
}


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
    sensor : Sensor
        What the policy sees (:mod:`neurohover.tasks.sensor`); exact sensors by default.
    drift : Drift
        How its dynamics change between the episodes of a test run (:mod:`neurohover.tasks.drift`); none by default.
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
    sensor: Sensor = EXACT
    drift: Drift = NO_DRIFT

    def __post_init__(self) -> None:
        if not isinstance(self.sensor, Sensor):
            refuse_reloaded(self.sensor, Sensor, "sensor")  # importlib.reload(tasks.sensor): "got Sensor(...)" named no cause (T42-B07)
            raise NeurohoverError(f"sensor must be a neurohover Sensor, got {self.sensor!r}")
        if not isinstance(self.drift, Drift):
            refuse_reloaded(self.drift, Drift, "drift")
            raise NeurohoverError(f"drift must be a neurohover Drift, got {self.drift!r}")
        if not isinstance(self.label, str):  # make(label=5) was kept as the number (second trial)
            raise NeurohoverError(f"MDP label={self.label!r:.60} is not allowed: give a string")
        check_name_text("MDP label", self.label, "the MDP (e.g. 'ghh08/gusty')", empty=True)  # 'wind\nrun 2' was taken (T40-B13)
        if not isinstance(self.family, str) or self.family not in _WIND_KINDS:
            names = [n for n in _WIND_KINDS if n != LEARNED_MODEL]
            raise NeurohoverError(f"MDP family={brief(self.family)} is not allowed: give a task family's name ({', '.join(names)}) or {LEARNED_MODEL!r}")
        if not whole_number(self.wind_kind) or self.wind_kind not in WIND_SLOTS:
            raise NeurohoverError(f"MDP wind_kind={brief(self.wind_kind)} is not allowed: 0 (none), 1 (constant, GHH-08) or 2 (sinusoidal, GHH-09)")
        object.__setattr__(self, "wind_kind", int(self.wind_kind))
        if self.wind_kind not in _WIND_KINDS[self.family]:
            allowed = " or ".join(map(str, _WIND_KINDS[self.family]))
            raise NeurohoverError(f"MDP wind_kind={self.wind_kind} is not allowed in family {self.family!r}: its MDPs have wind_kind {allowed}")
        # finite_vector refuses text, bools and dicts, which float() read as numbers ('12' as 1.0, 2.0); the wind as its kind reads it (T15-14, T15-15)
        wind_length, wind_allowed = WIND_SLOTS[self.wind_kind]
        for name, length, allowed in (
            ("params", len(DEFAULT_PARAMS), f"give {len(DEFAULT_PARAMS)} finite numbers"),
            ("noise_std", len(DEFAULT_NOISE_STD), f"give {len(DEFAULT_NOISE_STD)} finite numbers"),
            ("wind", wind_length, f"with wind_kind {self.wind_kind} give {wind_allowed}"),
        ):
            values = getattr(self, name)
            try:
                vector = finite_vector(values, length, f"MDP {name}")
            except NeurohoverError:
                raise NeurohoverError(f"MDP {name}={brief(values)} is not allowed: {allowed}") from None
            # plain Python numbers: reprs read MDP(params=(-0.18, ...)); + 0.0: a -0.0 is 0.0, the same MDP (T31-A07, as genes in T28-B15)
            object.__setattr__(self, name, tuple((vector + 0.0).tolist()))
        if min(self.noise_std) < 0:
            raise NeurohoverError(f"MDP noise_std={self.noise_std!r} is out of range: allowed stds >= 0")
        # T24-11: whole_in, so 1.5 or True "is not allowed" (a type) and 0 "is out of range"; both said out of range
        object.__setattr__(self, "substeps", whole_in(self.substeps, "MDP substeps", 1, MAX_SUBSTEPS))
        for name in ("dt", "d_u"):
            value = getattr(self, name)
            if not finite_real(value):  # np.timedelta64 was float()'s TypeError (T17-1), 10**400 an OverflowError
                raise NeurohoverError(f"MDP {name}={brief(value)} is not allowed: give a finite number")
            object.__setattr__(self, name, setting_float(value))  # -0.0 as 0.0, np.float32(0.3) as 0.3 (T56-B03)
        if not self.dt > 0:
            raise NeurohoverError(f"MDP dt={self.dt!r} is out of range: allowed a substep length > 0")
        if abs(self.substeps * self.dt - CONTROL_DT) > COVER_TOLERANCE:  # a dt of 1e9 was flown (T27-B05)
            raise NeurohoverError(
                f"MDP substeps={self.substeps} x dt={self.dt!r} is not allowed: the substeps must cover one {CONTROL_DT} s control step "
                f"(the simulator's {SUBSTEPS} x {SUBSTEP_DT}, a learned model's 1 x {CONTROL_DT})"
            )
        for name in ("params", "noise_std", "wind", "d_u"):  # 1e300 flew to a NaN return (T27-B06)
            value = getattr(self, name)
            if (max(map(abs, value), default=0.0) if isinstance(value, tuple) else abs(value)) > MAX_MAGNITUDE:
                raise NeurohoverError(f"MDP {name}={brief(value)} is out of range: allowed numbers in [-{MAX_MAGNITUDE:g}, {MAX_MAGNITUDE:g}]")
        check_held(self)  # an MDP of a task family is one the family holds, its label the one it names (T27-B05)

    def row(self) -> np.ndarray:
        """The float64 row the compiled kernel reads (layout in ``sim.constants``)."""
        row = np.zeros(MDP_ROW_LEN)
        row[ROW_PARAMS] = self.params
        row[ROW_NOISE] = self.noise_std
        row[ROW_SUBSTEPS] = self.substeps
        row[ROW_DT] = self.dt
        row[ROW_WIND_KIND] = self.wind_kind
        row[ROW_WIND_START : ROW_WIND_START + len(self.wind)] = self.wind
        row[ROW_D_U] = self.d_u
        row[ROW_SENSOR] = self.sensor.row_values()
        return row

    def with_sensor(self, sensor: Sensor) -> MDP:
        """The same MDP seen through ``sensor``."""
        return replace(self, sensor=sensor)

    def with_drift(self, drift: Drift) -> MDP:
        """The same MDP, its dynamics drifting by ``drift`` over a test run."""
        return replace(self, drift=drift)

    def to_reference(self) -> ReferenceMDP:
        """The same MDP for the plain-Python reference simulator."""
        wind = tuple(self.wind) + (0.0,) * (8 - len(self.wind))
        return ReferenceMDP(self.params, self.noise_std, self.wind_kind, wind, self.substeps, self.dt, self.d_u, self.sensor.row_values())

    def to_dict(self) -> dict:
        """The MDP as plain data (``sensor`` only when not exact, so older dicts read the same)."""
        d = {
            "family": self.family,
            "params": list(self.params),
            "noise_std": list(self.noise_std),
            "wind_kind": self.wind_kind,
            "wind": list(self.wind),
            "substeps": self.substeps,
            "dt": self.dt,
            "label": self.label,
            "d_u": self.d_u,
        }
        if not self.sensor.exact:
            d["sensor"] = self.sensor.to_dict()
        if not self.drift.none:
            d["drift"] = self.drift.to_dict()
        return d

    @classmethod
    def from_dict(cls, d: dict) -> MDP:
        """The MDP of :meth:`to_dict`'s table (its values checked as the MDP's own: a missing key is named)."""
        if not isinstance(d, dict):  # 5 was a TypeError (sixth trial)
            raise NeurohoverError(f"an MDP's dict {d!r:.60} is not allowed: give MDP.to_dict()'s table")
        missing = [k for k in MDP_KEYS if k not in d]
        if missing:  # {} was a KeyError (T14-17)
            raise NeurohoverError(f"an MDP's dict {brief(d)} lacks {', '.join(missing)}: give MDP.to_dict()'s table (keys {', '.join(MDP_KEYS)})")
        unknown = [k for k in d if k not in MDP_KEYS + MDP_OPTIONAL_KEYS]
        if unknown:  # a misspelt key ('lable') was ignored without a word (T15-14)
            raise NeurohoverError(f"an MDP's dict has unknown keys {', '.join(brief(k) for k in unknown)}: allowed {', '.join(MDP_KEYS + MDP_OPTIONAL_KEYS)}")
        return cls(  # the values as they are: the MDP checks each (int() cut substeps 10.7 to 10, float() read '0.01')
            d["family"],
            d["params"],
            d["noise_std"],
            d["wind_kind"],
            d["wind"],
            d["substeps"],
            d["dt"],
            d.get("label", ""),
            d.get("d_u", 0.0),
            Sensor.from_dict(d["sensor"]) if "sensor" in d else EXACT,
            Drift.from_dict(d["drift"]) if "drift" in d else NO_DRIFT,
        )


def finite_vector(values: Sequence[float] | np.ndarray, length: int, what: str) -> np.ndarray:
    """``values`` as a float array of ``length`` finite numbers, or a clear error naming ``what``."""
    check_length(length, what, 0)
    # complex numbers too: NumPy dropped their imaginary part with a warning only (fourth trial)
    objects = np.asarray(values, dtype=object)
    if isinstance(values, str) or any(isinstance(v, (str, bytes, bool, np.bool_, complex, np.complexfloating)) for v in np.ravel(objects)):
        raise NeurohoverError(f"{what} must be {length} numbers, got {brief(values)}")
    try:  # as_floats: a masked array's hidden values and a date's day number were taken as numbers (T16-9, T16-11)
        arr = as_floats(values, what, "")  # its message is replaced by this function's own
    except NeurohoverError:  # objects such as 10**400, dates, ragged lists; a masked array
        if isinstance(values, np.ma.MaskedArray) or not objects.size or not all(finite_real(v) for v in objects.flat):
            raise NeurohoverError(f"{what} must be {length} finite numbers, got {brief(values)}{masked_note(values)}") from None
        # real numbers NumPy holds as objects (a Fraction, an int past int64), each taken as every float setting takes
        # one (finite_real; Decimal is none); a Fraction was "must be 2 finite numbers" (T36-B09)
        arr = np.array([float(v) for v in objects.flat]).reshape(objects.shape)
    items = (
        list(values.flat)
        if isinstance(values, np.ndarray) and values.dtype.kind == "f" and values.dtype.itemsize < 8
        else values
        if isinstance(values, (list, tuple))
        else ()
    )
    if arr.ndim == 1 and any(isinstance(v, np.floating) and v.itemsize < 8 for v in items):  # np.float32(0.3) as 0.3 (T56-B03)
        arr = np.array([setting_float(v) for v in items])
    if arr.ndim > 1:  # a (1, 2) array was "must be 2 numbers, got 2" (T34-B15)
        raise NeurohoverError(f"{what} must be a flat sequence of {length} numbers, got shape {arr.shape}: {brief(values)}")
    if arr.shape != (length,):
        raise NeurohoverError(f"{what} must be {length} numbers, got {arr.size}: {brief(values)}")
    if not np.all(np.isfinite(arr)):
        raise NeurohoverError(f"{what} must be finite numbers, got {brief(arr.tolist())}")
    return arr


def mdp_label(label: object, default: str) -> str:
    """A family's ``make(label=...)``: text, or ``default`` where it is None or ''; anything else refused (0, {} and -0.0
    became the default without a word, an array was NumPy's "truth value is ambiguous"; T16-14, T16-12)."""
    if label is not None and not isinstance(label, str):
        raise NeurohoverError(f"MDP label={brief(label)} is not allowed: give a string (or leave it out for {default!r})")
    return label or default


def competition_rows(family: str) -> dict:
    """The competition's training and test rows of ``family`` as listed in the shipped data file: a copy of its own, so
    an edit of it changes no MDP (the cache itself was returned: an edited row flew as the competition's train:0, and
    ``.clear()`` had the family refused for the rest of the process; T43-B07)."""
    if not isinstance(family, str) or family not in competition_families():  # an array: NumPy's ambiguous truth (T47-B06)
        raise NeurohoverError(f"the competition data file lists no MDPs of {brief(family)}: it has {', '.join(competition_families())}")
    return copy.deepcopy(_COMPETITION[family])


def competition_families() -> tuple[str, ...]:
    """The families the competition's data file lists MDPs of."""
    if not _COMPETITION:
        _COMPETITION.update(json.loads(COMPETITION_MDPS_FILE.read_text(encoding="utf-8")))
    return tuple(k for k, v in _COMPETITION.items() if isinstance(v, dict) and "train" in v)  # not its "about" note


def _checked_competition_row(method):
    """A family's ``competition_params`` with its row checked: the family's ``n_params`` finite numbers ('ab' was a
    TypeError, [1] scaled to [5.0] for a two-number GHH-08 row; T15-5)."""

    @functools.wraps(method)
    def scaled(self, row):
        values = finite_vector(row, self.n_params, f"a {self.name} competition row ({', '.join(self.param_names)})")
        return method(self, values.tolist())

    return scaled


def _family_eq(self, other) -> bool:
    if type(other) is not type(self):
        return NotImplemented
    same = all(getattr(self, f.name) == getattr(other, f.name) for f in fields(self))
    return same and self.sensor == other.sensor and self.drift == other.drift


def _family_hash(self) -> int:
    return hash((type(self).__name__, *(getattr(self, f.name) for f in fields(self)), self.sensor, self.drift))


def _family_repr(self) -> str:
    args = [f"{f.name}={getattr(self, f.name)!r}" for f in fields(self)]
    if not self.sensor.exact:
        args.append(f"sensor={self.sensor!r}")
    if not self.drift.none:
        args.append(f"drift={self.drift!r}")
    return f"{type(self).__name__}({', '.join(args)})"


class TaskFamily:
    """A task family: a distribution G over MDPs, each MDP fixed by ``n_params`` numbers.

    A family module subclasses this (as a frozen dataclass) and sets the class attributes and
    the three methods marked below; sampling, kernel rows, fixed sets and names come from here.
    The class is checked as it is defined (:func:`~neurohover.tasks.held.register_family`): its name
    its own (another class's, ``model`` included, is refused) and its attributes in agreement.

    Attributes
    ----------
    name : str
        Its id (``--task``), e.g. ``"ghh08"``: lowercase letters, digits, ``.`` and ``_`` (``family_checks.FAMILY_NAME``).
    n_params, param_names
        The MDP parameters :meth:`make` takes.
    row_slice : slice
        Where those parameters sit in an MDP's kernel row (the rest of a sampled row is fixed).
    param_bounds : (float, float)
        The range each parameter lies in (:meth:`make` and :meth:`rows` refuse one outside it).
    set_code : int
        Distinguishes its seeded fixed sets from other families'.
    has_sigma : bool
        Whether it has a breadth ``sigma`` (FGHH), a field of its dataclass.
    wind_kind : int
        The wind its MDPs fly besides none (``sim.constants``: WIND_CONSTANT for GHH-08, WIND_SINUSOID for GHH-09;
        WIND_NONE: no wind); an MDP of its name with another is refused.
    generic_over_distribution : bool
        Whether its generic policies are evolved over G (FGHH: fixed resampling and races) rather
        than on the zero setting (GHH-08, GHH-09); decides the layout of its policy set.
    sensor : Sensor
        What the policy sees in every MDP of the family (:meth:`with_sensor`; exact by default).
    drift : Drift
        How the dynamics of every MDP of the family drift over a test run (:meth:`with_drift`; none by default).
    """

    name: str = ""
    n_params: int = 0
    param_names: tuple[str, ...] = ()
    row_slice: slice = slice(0, 0)
    param_bounds: tuple[float, float] = (-MAX_MAGNITUDE, MAX_MAGNITUDE)
    set_code: int = 0
    has_sigma: bool = False
    wind_kind: int = WIND_NONE
    sigma: float | None = None  # the breadth of G, for families with has_sigma
    generic_over_distribution: bool = False
    sensor: Sensor = EXACT  # set on a copy by with_sensor(); part of the family's identity
    drift: Drift = NO_DRIFT  # likewise, by with_drift()

    def __init_subclass__(cls, **kwargs) -> None:
        super().__init_subclass__(**kwargs)
        if cls.__dict__.get("name"):  # its attributes checked, the wind kinds an MDP of its name may have (MDP's own check)
            register_family(cls)
        for name in ("make", "zero"):  # the one place a family's MDPs get its sensor
            if name in cls.__dict__:
                setattr(cls, name, through_sensor(cls.__dict__[name], name, MDP))
        if "competition_params" in cls.__dict__:
            cls.competition_params = _checked_competition_row(cls.__dict__["competition_params"])  # type: ignore[method-assign]
        if "sample_params" in cls.__dict__:
            cls.sample_params = checked_draws(cls.__dict__["sample_params"])  # type: ignore[method-assign]
        # Defined before the dataclass decorator runs, so it keeps them: equality includes the sensor.
        cls.__eq__ = _family_eq  # type: ignore[method-assign]
        cls.__hash__ = _family_hash  # type: ignore[method-assign]
        cls.__repr__ = _family_repr  # type: ignore[method-assign]

    def with_sensor(self, sensor: Sensor) -> TaskFamily:
        """This family seen through ``sensor``: every MDP it makes, samples or lists carries it."""
        if not isinstance(sensor, Sensor):
            refuse_reloaded(sensor, Sensor, "sensor")  # T42-B07
            raise NeurohoverError(f"sensor must be a neurohover Sensor, got {sensor!r}")
        out = copy.copy(self)
        object.__setattr__(out, "sensor", sensor)
        return out

    def with_drift(self, drift: Drift) -> TaskFamily:
        """This family with drifting dynamics: every MDP it makes, samples or lists carries ``drift``."""
        if not isinstance(drift, Drift):
            refuse_reloaded(drift, Drift, "drift")  # T42-B07
            raise NeurohoverError(f"drift must be a neurohover Drift, got {drift!r}")
        out = copy.copy(self)
        object.__setattr__(out, "drift", drift)
        return out

    def to_dict(self) -> dict:
        """All the family is, as one JSON-ready dict: ``family`` (its name), and where set ``sigma``, ``sensor`` and
        ``drift`` (their tables); :func:`neurohover.tasks.family_from_dict` builds it back. Evolution checkpoints,
        results and unit params record a family this way."""
        d: dict = {"family": self.name}
        if self.sigma is not None:
            d["sigma"] = float(self.sigma)
        if self.sensor != EXACT:
            d["sensor"] = self.sensor.to_dict()
        if not self.drift.none:
            d["drift"] = self.drift.to_dict()
        return d

    # -- what a family defines ------------------------------------------------------------

    def make(self, params: Sequence[float] | np.ndarray, label: str = "") -> MDP:  # pragma: no cover - overridden
        """The MDP of ``params`` (validated; a clear error names a bad value)."""
        raise NotImplementedError

    def zero(self) -> MDP:  # pragma: no cover - overridden
        """The zero setting: no wind, default dynamics."""
        raise NotImplementedError

    def sample_params(self, rng: np.random.Generator, n: int) -> np.ndarray:  # pragma: no cover - overridden
        """Parameters of ``n`` fresh MDPs from G, shape (n, n_params): the generator is consumed as
        by ``n`` consecutive one-MDP draws, so a stream of MDPs does not depend on batch sizes."""
        raise NotImplementedError

    # -- what every family gets -----------------------------------------------------------

    def set_variant(self) -> int:
        """Distinguishes seeded fixed sets of one family (FGHH: by sigma)."""
        return 0

    @_checked_competition_row
    def competition_params(self, row: Sequence[float]) -> Sequence[float]:
        """The MDP parameters of one row of the competition file (GHH-08 scales it to m/s): a row of ``n_params`` finite
        numbers, else a clear error."""
        return row

    @property
    def has_competition_sets(self) -> bool:
        """True when ``train:N`` / ``test:N`` are the competition's MDPs: the data file lists the
        family (else they are the seeded draws, as for a new family)."""
        return self.name in competition_families()

    def sample(self, rng: np.random.Generator | int | None = None, label: str = "") -> MDP:
        """A fresh MDP drawn from G."""
        rng = generator(rng)
        return self.make(self.sample_params(rng, 1)[0], label=mdp_label(label, f"{self.name}/sample"))

    def row_template(self) -> np.ndarray:
        """The kernel row every sampled MDP shares outside :attr:`row_slice`, built once by :meth:`make` (whose every call
        checks that its row holds its params at :attr:`row_slice`: T54-B12, T59-B02)."""
        key = (type(self), self.set_variant(), self.sensor)
        if key not in _ROW_LAYOUTS:
            _ROW_LAYOUTS[key] = self.make(self.sample_params(np.random.default_rng(0), 1)[0]).row()
        return _ROW_LAYOUTS[key].copy()

    def rows(self, params: np.ndarray) -> np.ndarray:
        """Kernel rows of the MDPs of ``params`` (n, n_params), as ``make(p).row()`` gives: their shape, finiteness and
        :attr:`param_bounds` are checked."""
        try:  # numbers only (NumPy reads '1' as 1.0), not a masked array, whose hidden values were used (T16-9)
            arr: np.ndarray | None = as_floats(params, "params", "")
        except NeurohoverError:
            arr = None
        # NaN rows were returned, (2, 3) a broadcast error (T14-18)
        if arr is None or arr.ndim != 2 or arr.shape[1] != self.n_params or not np.isfinite(arr).all():
            shown = f"of shape {arr.shape}" if arr is not None and (arr.ndim != 2 or arr.shape[1] != self.n_params) else " ".join(brief(params).split())
            raise NeurohoverError(
                f"{self.name} parameters {shown} are not allowed: give an array of shape (n, {self.n_params}) of finite numbers ({', '.join(self.param_names)})"
            )
        low, high = self.param_bounds  # as make() refuses them: a GHH-08 wind of 99 m/s was flown from rows (T29-B02)
        outside = np.flatnonzero(((arr < low) | (arr > high)).any(axis=1))
        if outside.size:
            i = int(outside[0])
            raise NeurohoverError(
                f"{self.name} parameters row {i} {brief(arr[i].tolist())} is out of range: each must lie in [{low:g}, {high:g}] ({', '.join(self.param_names)})"
            )
        params = arr
        out = np.repeat(self.row_template()[None, :], params.shape[0], axis=0)
        out[:, self.row_slice] = params
        return out

    def sample_rows(self, rng: np.random.Generator, n: int) -> np.ndarray:
        """Kernel rows of ``n`` fresh MDPs: the rows of ``n`` consecutive :meth:`sample` calls."""
        return self.rows(self.sample_params(rng, n))

    def _seeded_set(self, which: int, n: int, kind: str) -> list[MDP]:
        # the family's own sigma too: sigmas of one variant (0.2000001, 0.2000004) draw from one seed, but not one set
        key = (type(self), self.set_variant(), getattr(self, "sigma", None), which, self.sensor, self.drift)
        if key not in _FIXED_SETS:  # MDPs are immutable, so each set is built once per process
            rng = np.random.default_rng(np.random.SeedSequence([_SET_ENTROPY, self.set_code, which, self.set_variant()]))
            with family_code():  # the set's own labels name it: checking them would build the set again
                _FIXED_SETS[key] = tuple(self.make(self.sample_params(rng, 1)[0], label=f"{self.name}/{kind}:{i}") for i in range(n))
        return list(_FIXED_SETS[key])

    def _competition_set(self, kind: str) -> list[MDP]:
        key = (type(self), -1, None, 0 if kind == "train" else 1, self.sensor, self.drift)
        if key not in _FIXED_SETS:
            rows = competition_rows(self.name)[kind]
            with family_code():  # as _seeded_set's
                _FIXED_SETS[key] = tuple(self.make(self.competition_params(r), label=f"{self.name}/{kind}:{i}") for i, r in enumerate(rows))
        return list(_FIXED_SETS[key])

    def set_name(self, spec: str) -> str:
        """What ``spec`` (``train``, ``test``, ``train:N``, ``test:N`` or any other MDP name) flies, as its MDPs' labels
        name it: the one place that decides it. Where the family has no competition sets (FGHH at a sigma other than
        0.3) ``train`` and ``test`` are its seeded sets, labelled ``seeded-train:N`` / ``seeded-test:N``; a policy's mdp,
        compete's and evaluate-agent's ``mdps`` write this name, as the MDPs flown are labelled (T37-A01, T37-A02)."""
        kind, colon, index = spec.partition(":")
        if kind in ("train", "test") and not self.has_competition_sets:
            return f"seeded-{kind}{colon}{index}"
        return spec

    def training_mdps(self) -> list[MDP]:
        """The 10 training MDPs: the competition's (seeded draws where it has none: :meth:`set_name`)."""
        if self.has_competition_sets:
            return self._competition_set("train")
        return self.seeded_training_mdps()

    def test_mdps(self) -> list[MDP]:
        """The 100 test MDPs: the competition's (seeded draws where it has none: :meth:`set_name`)."""
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
        if not isinstance(spec, str):
            raise NeurohoverError(f"MDP {brief(spec)} is not allowed: give its name as a string, e.g. 'zero', 'train:3' or 'test:12'")
        if spec == "zero":
            return self.zero()
        if spec == "sample":
            return self.sample(rng)
        kind, _, index = spec.partition(":")
        sets = {
            "train": (self.training_mdps, N_TRAINING),
            "test": (self.test_mdps, N_TEST),
            "seeded-train": (self.seeded_training_mdps, N_TRAINING),
            "seeded-test": (self.seeded_test_mdps, N_TEST),
        }
        if kind in sets and index.isascii() and index.isdigit():  # ASCII digits only: str.isdigit also takes other scripts' digits
            getter, n = sets[kind]
            digits = index.lstrip("0") or "0"  # 5,000 digits were int()'s ValueError, a traceback (eleventh trial)
            if len(digits) <= 6 and int(digits) < n:
                return getter()[int(digits)]
            shown = index if len(index) <= 30 else f"{index[:10]}...({len(index)} digits)"  # as the command line shows numbers
            raise NeurohoverError(f"MDP index {shown} in {brief(spec)} is out of range: allowed 0..{n - 1}")
        raise NeurohoverError(
            f"unknown MDP {brief(spec)}: allowed zero, sample, train:N and seeded-train:N (0..{N_TRAINING - 1}), test:N and seeded-test:N (0..{N_TEST - 1})"
        )
