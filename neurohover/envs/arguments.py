"""What the single and the vector environment check of their arguments, one place each: the MDP spec, the
noise stream, the sensors, the id they were made under, sizes, dtypes and reset options."""

from __future__ import annotations

import inspect
import sys
from collections.abc import Callable, Sequence
from types import FrameType
from typing import Any, NoReturn

import gymnasium as gym
import numpy as np

from ..errors import NeurohoverError, brief, float64_of, whole_in, whole_number
from ..sim.constants import MAX_EPISODE_STEPS
from ..tasks import MDP, NO_DRIFT, Drift, TaskFamily, get_task_family
from ..tasks.sensor import Sensor

OBS_DTYPES = ("float64", "float32")
MAX_NOISE_SEED = 2**63 - 1  # the largest seed ``neurohover.evaluate_jobs`` accepts
SAMPLE = "sample"
MDP_OPTIONS = ("zero", "sample", "train:N", "test:N")
RESET_OPTION_KEYS = ("mdp", "noise")
MdpSpec = str | MDP


def resolve_mdp(family: TaskFamily, spec: Any, cache: dict[str, MDP] | None = None) -> MDP | str:
    """The MDP that ``spec`` names, or ``SAMPLE`` for a fresh MDP from G at every reset.

    Parameters
    ----------
    family : TaskFamily
        The environment's task family (it resolves ``zero``, ``train:N`` and ``test:N``).
    spec : str or MDP
        ``"zero"``, ``"sample"``, ``"train:N"``, ``"test:N"`` or an explicit :class:`MDP` of the
        family, or a learned model's (an MDP of another family is refused).
    cache : dict, optional
        Already resolved names; building the fixed sets is not free, so a vector environment
        with many sub-environments resolves each name once.
    """
    if isinstance(spec, MDP):
        if spec.family not in (family.name, "model"):
            raise NeurohoverError(
                f"mdp {spec.label or spec.family!r} is an MDP of {spec.family}, not of this environment's family {family.name}: "
                f"give one of {family.name}'s MDPs (or a learned model)"
            )
        return sensed_mdp(spec, family.sensor)  # flyable: an MDP checks its numbers and substeps when it is made
    if not isinstance(spec, str):
        raise NeurohoverError(f"mdp={brief(spec)} is not allowed: use one of {', '.join(MDP_OPTIONS)} or an MDP instance")
    if spec == SAMPLE:
        return SAMPLE
    if cache is not None and spec in cache:
        return cache[spec]
    mdp = family.mdp(spec)  # raises NeurohoverError naming the allowed names
    if cache is not None:
        cache[spec] = mdp
    return mdp


def sensed_mdp(mdp: MDP, sensor: Sensor) -> MDP:
    """An explicit ``mdp`` seen through the environment's ``sensor``, by the rule of an explicit MDP's drift: its own
    flies where the environment's is exact, the environment's where the MDP's is exact (as the same MDP named by text
    flies), and two different non-exact ones are refused by name. An MDP object flew with exact sensors under
    obs_noise, obs_delay and the -NoisySensors ids without a word (T26-B03)."""
    if sensor.exact or mdp.sensor == sensor:
        return mdp
    if mdp.sensor.exact:
        return mdp.with_sensor(sensor)

    def text(s: Sensor) -> str:
        return "Sensor(" + ", ".join(f"{k}={v:g}" for k, v in s.to_dict().items() if v) + ")"

    raise NeurohoverError(
        f"mdp {mdp.label or mdp.family!r} carries its own sensor {text(mdp.sensor)}, not this environment's {text(sensor)} "
        "(its obs_noise, obs_delay or id): give the MDP without a sensor (mdp.with_sensor(Sensor())) or an environment of "
        "exact sensors, under which it flies its own"
    )


def refuse_idle_sigma(sigma: Any, mdp: Any, *, flags: bool = False, default: bool = False) -> None:
    """Refuse a breadth ``sigma`` (not None) beside an ``mdp`` setting it does not change: ``"zero"`` (the family's mean
    MDP, the same at every sigma), or a sequence of only such settings (one per sub-environment). ``sigma=0.2,
    mdp='zero'`` made an environment whose sigma did nothing (sixteenth trial T16-6). The one rule of the environments
    and the command line: ``flags`` names them as ``--sigma`` and ``--mdp``; ``default``: the zero setting was not given
    but is ``--mdp``'s default. Explicit MDPs are left to their callers (a batch flier passes its MDPs' family sigma)."""
    if sigma is None:
        return
    specs = list(mdp) if isinstance(mdp, (list, tuple)) else [mdp]
    if not specs or not all(isinstance(s, str) and s == "zero" for s in specs):
        return
    if flags:
        given = f"--sigma {sigma:g}", "--mdp zero" + (" (the default)" if default else ""), "--mdp sample, train:N or test:N", "--sigma"
    else:
        given = f"sigma={brief(sigma)}", f"mdp={brief(mdp)}", "mdp='sample', 'train:N' or 'test:N'", "sigma"
    raise NeurohoverError(
        f"{given[0]} does nothing with {given[1]}: sigma is the breadth of the MDPs drawn from FGHH's G, and the zero "
        f"setting is the same at every sigma; give {given[2]}, or leave {given[3]} out"
    )


def check_noise_stream(value: Any, what: str = "noise") -> tuple[int, int]:
    """A ``(seed, episode)`` pair naming one gust-noise stream of the kernel, validated: a tuple, list or 1-D array of two
    integers (a dict was unpacked to its keys and "12" to '1' and '2'; fifteenth trial T15-19)."""
    # a masked array's masked entry was flown as its hidden value (sixteenth trial T16-9)
    pair = isinstance(value, (tuple, list)) or (isinstance(value, np.ndarray) and value.ndim == 1 and not isinstance(value, np.ma.MaskedArray))
    if not pair or len(value) != 2 or not all(whole_number(v) for v in value):
        raise NeurohoverError(f"{what}={brief(value)} is not allowed: give a (seed, episode) pair of integers in 0..2**63-1")
    for name, v in zip(("seed", "episode"), value):
        if not 0 <= int(v) <= MAX_NOISE_SEED:
            raise NeurohoverError(f"{what} {name}={brief(v)} is out of range: allowed an integer in 0..2**63-1")
    return int(value[0]), int(value[1])


def sensed_family(task: str, sigma: float | None, obs_noise: Any, obs_delay: Any) -> TaskFamily:
    """The environment's task family, seen through the sensor of ``obs_noise`` / ``obs_delay`` (:meth:`Sensor.of`)."""
    return get_task_family(task, sigma, sensor=Sensor.of(obs_noise, obs_delay))


#: What defines each variant id (``neurohover/<NAME>-<suffix>-v0``), by suffix: the make() kwarg that sets it, what it
#: is, what keeps it, and whether the environment's sensor and drift keep it. A kwarg may change the setting (another
#: level, delay or walk) but not remove it, as it may not change the id's task: ``-DriftingDynamics`` with drift=None
#: flew fixed dynamics (T40-B12).
VARIANT_SETTINGS: dict[str, tuple[str, str, str, Callable[[Sensor, Drift], bool]]] = {
    "NoisySensors": ("obs_noise", "noisy sensors", "a noise level > 0", lambda s, d: any(s.stds)),
    "CorrelatedSensors": ("obs_noise", "correlated sensor noise", "a noise level > 0 and a correlation > 0", lambda s, d: any(s.stds) and s.correlation > 0),
    "DelayedSensors": ("obs_delay", "late sensors", "a delay > 0", lambda s, d: s.delay > 0),
    "DriftingDynamics": ("drift", "drifting dynamics", "a walk > 0", lambda s, d: d.walk > 0),
    "AbruptChange": ("drift", "an abrupt change of the dynamics", "a change (e.g. {'change': {'D_w': 0.8}})", lambda s, d: bool(d.change)),
}


def _refuse_lost_variant(spec: Any, family: TaskFamily, drift: Drift) -> None:
    """Refuse make()'s kwargs where they remove what defines a variant id (:data:`VARIANT_SETTINGS`)."""
    name, _, rest = spec.id.partition("/")[2].partition("-")
    suffix = rest.rpartition("-v")[0]
    if suffix not in VARIANT_SETTINGS:
        return
    key, what, keeps, kept = VARIANT_SETTINGS[suffix]
    if not kept(family.sensor, drift):
        given = (getattr(spec, "kwargs", None) or {}).get(key)
        raise NeurohoverError(
            f"{spec.id} is {name} with {what}: its {key}={brief(given)} removes what defines the id, which is not allowed: give {key} with {keeps}, "
            f"or make neurohover/{name}-v0 without it"
        )


def check_against_id(spec: Any, family: TaskFamily, episode_steps: int, limit: int | None = None, drift: Drift = NO_DRIFT) -> None:
    """What ``gymnasium.make(id, **kwargs)`` built, checked against the id (``spec``, set once the env is made): a
    ``task`` that is not the id's is refused; episodes that the time limit cuts before their ``episode_steps`` are warned
    of, whether the limit is the id's or one given to make() or make_vec() (``limit``: the truncation the environment
    applies itself, where it knows it: the vector environment's). A warning, not a refusal, for both: truncating before
    ``episode_steps`` is allowed (the vector environment's ``max_episode_steps`` documents it), but a crash is still
    charged for the steps left of ``episode_steps``, so the returns are not those of the shorter episodes (T23-17:
    ``make(id, episode_steps=100, max_episode_steps=50)`` said nothing)."""
    registered = gym.registry.get(getattr(spec, "id", None) or "")
    if registered is None:  # made directly, or from an unregistered spec
        return
    task = registered.kwargs.get("task")
    # a user's own id (not in neurohover's namespace) is the user's: make()'s task= overrides its kwargs, as Gymnasium's
    # make does; it was refused with an empty list of ids to use instead, "()" (T36-B11)
    if task is not None and task != family.name and registered.namespace == "neurohover":
        ids = [
            i
            for i, r in gym.registry.items()
            if i.startswith("neurohover/") and r.kwargs.get("task") == family.name and r.entry_point == registered.entry_point
        ]
        # a family registered at run time has no neurohover id (register_envs makes them for the shipped ones): "make a
        # wide id instead" named none (T52-B06)
        known = any(i.startswith("neurohover/") and r.kwargs.get("task") == family.name for i, r in gym.registry.items())
        instead = (
            f"make a {family.name} id instead" + (f" ({', '.join(ids[:3])})" if ids else "")
            if known
            else f"neurohover has no id for it (its ids are the shipped families'): build neurohover.envs.HoverEnv(task={family.name!r}) "
            f"(or HoverVectorEnv) directly, or register an id of your own with gymnasium.register(id=..., entry_point={registered.entry_point!r}, "
            f"kwargs={{'task': {family.name!r}}})"
        )
        raise NeurohoverError(f"{spec.id} is the {task} task family: task={family.name!r} conflicts with it; {instead}")
    if registered.namespace == "neurohover":
        _refuse_lost_variant(spec, family, drift)
    applied = _make_time_limit(registered.max_episode_steps) if limit is None else limit
    if applied is None or episode_steps <= applied:
        return
    if applied == registered.max_episode_steps:
        gym.logger.warn(
            f"{spec.id}: episode_steps={episode_steps} is longer than the id's time limit of {applied} steps: every episode is "
            f"truncated at {applied} unless make() or make_vec() is given max_episode_steps={episode_steps} too"
        )
    else:  # T23-17: a limit given below episode_steps truncated every episode without a word
        gym.logger.warn(
            f"{spec.id}: max_episode_steps={applied} is shorter than episode_steps={episode_steps}: every episode is truncated at "
            f"{applied} steps while a crash is still charged for the steps left of {episode_steps}; give episode_steps={applied} "
            f"for episodes of {applied} steps, or max_episode_steps={episode_steps}"
        )


def _make_time_limit(registered: int | None) -> int | None:
    """The ``TimeLimit`` that the ``gymnasium.make`` call now building the environment applies: its ``max_episode_steps``
    argument (None for -1, no limit) or else its spec's, read from that call's frame, since make() adds the wrapper after it
    sets the spec and passes the environment neither (T23-17); the id's ``registered`` limit where no make() call is found
    (the spec set by other code). A limit Gymnasium's ``TimeLimit`` would misread or refuse with its TypeError is refused
    by name: True truncated every episode at one step without a word (T28-B10), and ``np.int64(5)``, 5.5 or '5' were
    that TypeError (T28-B11; make() hands the wrapper its own argument, so this cannot convert it)."""
    make_code = getattr(getattr(gym.envs.registration, "make", None), "__code__", None)
    frame: FrameType | None = sys._getframe(1)
    while frame is not None and frame.f_code is not make_code:
        frame = frame.f_back
    if frame is None:
        return registered
    given = frame.f_locals.get("max_episode_steps")
    if given is None:
        given = getattr(frame.f_locals.get("env_spec"), "max_episode_steps", registered)
    if given is not None and (isinstance(given, bool) or not isinstance(given, int)):
        raise NeurohoverError(
            f"max_episode_steps={brief(given)} is not allowed: gymnasium.make's TimeLimit takes a Python int "
            f"(a NumPy integer as int(...)) >= 1, or -1 for no limit"
        )
    return None if given == -1 else given


def check_no_unknown_kwargs(unknown: dict[str, Any], allowed: Sequence[str]) -> None:
    """A clear error for keyword arguments an environment does not take (a typo would be a TypeError)."""
    if unknown:
        raise NeurohoverError(f"unknown argument(s) {', '.join(sorted(unknown))}: allowed {', '.join(allowed)}")


def _refuse_setting(name: str, value: Any, deleted: bool = False) -> NoReturn:
    how = "reset(options={'mdp': ...}) flies another MDP" if name == "mdp" else f"make a new environment with {name}=..."
    what = f"del {name}" if deleted else f"{name}={brief(value)}"
    raise NeurohoverError(f"{what} is not allowed: an environment's {name} is fixed when it is made (its steps trust it); {how}")


class _Setting:
    """A made environment's setting: read from the instance's own attributes (no call: steps read them), refused when
    set once the environment is made (:meth:`FixedSettings.fix_settings`)."""

    def __init__(self, name: str) -> None:
        self.name = name

    def __set__(self, env: Any, value: Any) -> None:
        if env.__dict__.get("_made"):
            _refuse_setting(self.name, value)
        env.__dict__[self.name] = value

    def __delete__(self, env: Any) -> None:  # ``del env.episode_steps`` was a bare AttributeError '__delete__' (T36-B03)
        if env.__dict__.get("_made"):
            _refuse_setting(self.name, None, deleted=True)
        if self.name not in env.__dict__:
            raise AttributeError(f"{type(env).__name__!r} object has no attribute {self.name!r}")
        del env.__dict__[self.name]


class _Absent(_Setting):
    """A constructor argument the environment keeps no attribute of (``task``, ``sigma``, ...): none to read, and refused
    when set (``set_wrapper_attr("task", ...)`` was taken and ignored)."""

    def __get__(self, env: Any, owner: Any = None) -> Any:
        if env is None:
            return self
        raise AttributeError(f"{type(env).__name__!r} object has no attribute {self.name!r}")


class _Property(_Setting):
    """A setting the class gives as a property (HoverEnv's ``mdp``): read through it, refused when set once made."""

    def __init__(self, name: str, prop: property) -> None:
        super().__init__(name)
        self.prop = prop

    def __get__(self, env: Any, owner: Any = None) -> Any:
        return self if env is None else self.prop.__get__(env, owner)

    def __set__(self, env: Any, value: Any) -> None:
        if env.__dict__.get("_made") or self.prop.fset is None:
            _refuse_setting(self.name, value)
        self.prop.__set__(env, value)

    def __delete__(self, env: Any) -> None:
        if env.__dict__.get("_made") or self.prop.fdel is None:
            _refuse_setting(self.name, None, deleted=True)
        self.prop.__delete__(env)


class FixedSettings:
    """An environment whose settings (its constructor's arguments, ``_FIXED``) cannot change once it is made
    (:meth:`fix_settings`): its steps trust the values checked then. ``env.episode_steps = -1`` (or
    ``set_wrapper_attr``) made a crash pay +3497.6, ``"20"`` a numba TypingError, and ``set_wrapper_attr("task", ...)``
    was taken and ignored (T32-B04). Descriptors, not ``__setattr__``: that ran on every attribute a step sets, 10% of a
    HoverEnv step."""

    _FIXED: tuple[str, ...] = ()

    def fix_settings(self) -> None:
        """Fix the settings from here on: called once, at the end of the constructor."""
        cls = type(self)
        for name in self._FIXED:
            given = inspect.getattr_static(cls, name, None)
            if isinstance(given, property):
                setattr(cls, name, _Property(name, given))
            elif not isinstance(given, _Setting):
                setattr(cls, name, _Setting(name) if name in self.__dict__ else _Absent(name))
        self.__dict__["_made"] = True


def check_count(value: Any, name: str, largest: int) -> int:
    """``value`` (the argument ``name``) as an int, refused unless it is an integer in 1..``largest`` (:func:`~neurohover.errors.whole_in`)."""
    return whole_in(value, name, 1, largest)


def check_episode_steps(episode_steps: Any, name: str = "episode_steps") -> int:
    """``episode_steps`` (the argument ``name``) as an int, or a clear error."""
    return check_count(episode_steps, name, MAX_EPISODE_STEPS)


def check_reset_options(options: dict[str, Any] | None, extra: Sequence[str] = ()) -> dict[str, Any]:
    """``options`` as a dict whose keys are all known (a typo would otherwise be silently ignored)."""
    if options is None:
        return {}
    if not isinstance(options, dict):
        raise NeurohoverError(f"options={options!r} is not allowed: give a dict or None")
    allowed = RESET_OPTION_KEYS + tuple(extra)
    unknown = sorted(str(k) for k in options if k not in allowed)
    if unknown:
        raise NeurohoverError(f"unknown reset option(s) {', '.join(unknown)}: allowed {', '.join(allowed)}")
    return options


def draw_stream_seed(rng: np.random.Generator) -> int:
    """A noise-stream seed (0..2**63-1) drawn from an environment's generator."""
    # 63 raw bits: a tenth of the cost of Generator.integers, which matters when a vector
    # environment resets hundreds of crashed helicopters per step.
    return int(rng.bit_generator.random_raw()) >> 1


def real_values(values: Any, message: str | Callable[[], str]) -> np.ndarray:
    """``values`` (actions) as float64, or NeurohoverError(``message``; a function giving it, called only then: an array's
    repr at every step was half a step's time): text, booleans and complex numbers are refused, which NumPy would read
    ('1' as 1.0) or cut to their real part with only a warning, and masked arrays, whose masked entries NumPy would fly
    at their hidden values (sixteenth trial T16-9)."""

    def refused(why: str = "") -> NeurohoverError:
        return NeurohoverError((message if isinstance(message, str) else message()) + why)

    if isinstance(values, np.ma.MaskedArray):  # one isinstance test: this runs at every step
        raise refused(" (not a masked array: its masked entries would be flown at their hidden values)")
    try:
        raw = np.asarray(values)
        if raw.dtype.kind not in "iuf":  # booleans too: [True] * 4 is no action
            raise TypeError(raw.dtype)
        return float64_of(raw, copy=False)  # a longdouble past float64's range: inf, flown as inf is (T37-B10)
    except (TypeError, ValueError):
        raise refused() from None


def _check_dtype(value: Any, name: str) -> np.dtype:
    try:  # a name, a dtype or a type only: np.dtype() reads any value's .dtype (np.float32('nan') was float32; T17-7)
        dtype = np.dtype(value) if isinstance(value, (str, np.dtype, type)) else None
    except TypeError:
        dtype = None
    if value is None or dtype is None or dtype.name not in OBS_DTYPES:
        raise NeurohoverError(f"{name}={brief(value)} is not allowed: use {' or '.join(map(repr, OBS_DTYPES))}")
    if not dtype.isnative:  # '>f8' is named float64 too: its observations were byte-swapped, which PyTorch refuses (T37-B01)
        raise NeurohoverError(
            f"{name}={brief(value)} is not allowed: its byte order is not this machine's; use {' or '.join(map(repr, OBS_DTYPES))} (native byte order)"
        )
    return dtype


def check_obs_dtype(obs_dtype: Any) -> np.dtype:
    """``obs_dtype`` (``"float64"``, ``"float32"`` or the NumPy type) as a dtype, or a clear error."""
    return _check_dtype(obs_dtype, "obs_dtype")


def check_action_dtype(action_dtype: Any) -> np.dtype:
    """``action_dtype`` (``"float64"``, ``"float32"`` or the NumPy type) as a dtype, or a clear error."""
    return _check_dtype(action_dtype, "action_dtype")
