"""Task families (generalized tasks) and their MDPs: docs/model.md, Task families.

A task family is a distribution G over MDPs; an MDP is fully fixed by its parameters. Each family
offers its zero setting (the mean MDP), explicit construction from parameters (validated), a
sampler of fresh MDPs (as objects or as kernel rows), and fixed sets of 10 training and 100 test
MDPs. The protocol is :class:`~neurohover.tasks.base.TaskFamily`; each family is one module of
this package that names its class ``TASK_FAMILY``, found here without a list to edit.

The fixed sets are the competitions' own MDPs, as the paper's authors used them (their experiment
code's lists, shipped as ``neurohover/data/competition-mdps.json``; 0-based, the paper numbers
from 1): GHH-08, GHH-09 and FGHH at sigma = 0.3. Seeded draws from G form a second, harder pair of
sets, named ``seeded-train:N`` / ``seeded-test:N`` (``seeded_training_mdps``); for FGHH at any
other sigma they are the only fixed sets, and ``train:N`` / ``test:N`` name them.

Example
-------
>>> from neurohover.tasks import get_task_family
>>> family = get_task_family("ghh08")
>>> mdp = family.make([2.5, -1.0])            # constant wind (m/s)
>>> train = family.training_mdps()            # 10 fixed MDPs
"""

from __future__ import annotations

import importlib
import pkgutil
from types import MappingProxyType

from ..errors import NeurohoverError, brief, finite_real, package_path, refuse_reloaded, registry_entry_problem, unknown_keys
from .base import COMPETITION_MDPS_FILE, MDP, N_TEST, N_TRAINING, TaskFamily, competition_rows, finite_vector
from .drift import NO_DRIFT, Drift, refuse_drift
from .family_checks import class_problem
from .fghh import COMPETITION_FGHH_SIGMA, FGHH
from .ghh08 import GHH08, MAX_WIND
from .ghh09 import GHH09, GHH09_PARAM_NAMES
from .rows import check_rows, refuse_unordered_mdps
from .sensor import EXACT, Sensor

_FIRST = ("ghh08", "ghh09", "fghh")  # the paper's order in help texts; other families follow by name


def discover(package: str) -> dict[str, type[TaskFamily]]:
    """The ``TASK_FAMILY`` class of every module of ``package`` (an importable package's dotted name, e.g.
    ``"neurohover.tasks"``), by family name, in a stable order; modules whose names start with ``_`` are not imported (as
    the agents' discover). A ``TASK_FAMILY`` that is no TaskFamily subclass with a name of its own, a name declared twice
    and a bad package are refused by name (an AttributeError 'name', a ModuleNotFoundError; T52-B16)."""
    path = package_path(package, __name__, "task family modules")
    names = sorted(
        (m.name for m in pkgutil.iter_modules(path) if not m.name.startswith("_")), key=lambda n: (_FIRST.index(n) if n in _FIRST else len(_FIRST), n)
    )
    found: dict[str, type[TaskFamily]] = {}
    for module in names:
        cls = getattr(importlib.import_module(f"{package}.{module}"), "TASK_FAMILY", None)
        if cls is None:
            continue
        if not (isinstance(cls, type) and issubclass(cls, TaskFamily) and cls.__dict__.get("name")):
            raise NeurohoverError(
                f"module {package}.{module}'s TASK_FAMILY={brief(cls)} is not allowed: declare a TaskFamily subclass (the class, not an instance) "
                "that sets a name of its own"
            )
        if cls.name in found:
            raise NeurohoverError(f"task family {cls.name!r} is declared twice (module {package}.{module} and another): give each family a name of its own")
        found[cls.name] = cls
    return found


#: Every task family class by name. A run-time entry is a TaskFamily subclass under its own name; a shipped name holds
#: its shipped class (:func:`family_class` checks the entry it reads).
TASK_FAMILIES: dict[str, type[TaskFamily]] = discover(__name__)
TASK_NAMES: tuple[str, ...] = tuple(TASK_FAMILIES)
_SHIPPED = MappingProxyType(dict(TASK_FAMILIES))


def entry_problem(name: object, cls: object) -> str:
    """What is wrong with the registry entry ``TASK_FAMILIES[name] = cls`` ('' when nothing): no TaskFamily subclass (5
    was an AttributeError 'has_sigma'), a shipped name holding another class (``TASK_FAMILIES["ghh08"] = GHH09`` gave
    GHH-09 for ghh08), or a class whose name is not its key (an alias 'zz' gave a family named ghh08; T43-B10); of a
    run-time class, a name the records cannot hold, a flag that is no bool or has_sigma without a sigma field
    (:func:`~neurohover.tasks.family_checks.class_problem`; T54-B08, B10, B11)."""
    shared = registry_entry_problem("TASK_FAMILIES", name, cls, TaskFamily, _SHIPPED, "task family", "class")
    if shared or name in _SHIPPED:
        return shared
    return class_problem(f"TASK_FAMILIES[{brief(name)}] = {brief(cls)} is not allowed", name, cls)  # type: ignore[arg-type]


def task_names() -> tuple[str, ...]:
    """The task families' names as :data:`TASK_FAMILIES` holds them now, run-time entries too and bad entries left out
    (:func:`entry_problem`): what a policy's task and target, a compete summary's task and a config's task may name.
    :data:`TASK_NAMES`, frozen at import, refused a champion evolved on a family registered at run time (T46-B07)."""
    return tuple(n for n, c in list(TASK_FAMILIES.items()) if isinstance(n, str) and not entry_problem(n, c))


def family_class(name: object) -> type[TaskFamily]:
    """The registry's class of task family ``name`` (a key of :data:`TASK_FAMILIES`), its entry checked
    (:func:`entry_problem`; NeurohoverError naming a bad one, or an unknown name with the registry's names as it is)."""
    if isinstance(name, TaskFamily):  # a family where its name goes was "unknown task FGHH(sigma=0.2)" (T56-B06)
        raise NeurohoverError(f"task={brief(name)} is not allowed: give the task's name, {_name_of(name)}")
    if not isinstance(name, str) or name not in TASK_FAMILIES:
        raise NeurohoverError(f"unknown task {brief(name)}: allowed {', '.join(task_names())}")  # TASK_NAMES listed a deleted entry
    cls = TASK_FAMILIES[name]
    problem = entry_problem(name, cls)
    if problem:
        raise NeurohoverError(problem)
    return cls


def _name_of(family: TaskFamily) -> str:
    """How :func:`family_class`'s refusal of the task family object ``family`` names what to give instead: its name and its settings."""
    settings = [f"sigma={family.sigma!r}"] if getattr(family, "has_sigma", False) else []
    sensor, drift = getattr(family, "sensor", None), getattr(family, "drift", None)
    settings += ["its sensor"] if isinstance(sensor, Sensor) and not sensor.exact else []
    settings += ["its drift"] if isinstance(drift, Drift) and not drift.none else []
    return f"{brief(family.name)}" + (f" (and {', '.join(settings)})" if settings else "")


def get_task_family(name: str, sigma: float | None = None, sensor: Sensor | None = None, drift: Drift | None = None) -> TaskFamily:
    """The task family called ``name`` (``ghh08``, ``ghh09``, ``fghh``, ...; ``sigma``: its breadth, where it has one),
    seen through ``sensor`` (:mod:`neurohover.tasks.sensor`; None: exact sensors), its dynamics drifting
    over a test run by ``drift`` (:mod:`neurohover.tasks.drift`; None: fixed)."""
    if sensor is not None and not isinstance(sensor, Sensor):
        refuse_reloaded(sensor, Sensor, "sensor")  # importlib.reload(tasks.sensor): its Sensor was "no neurohover.Sensor" (T42-B07)
        raise NeurohoverError(
            f"sensor={sensor!r} is not allowed: give a neurohover.Sensor (e.g. Sensor.of(obs_noise=1.0) or Sensor.parse('level=1.0')) or None for exact sensors"
        )
    if drift is not None and not isinstance(drift, Drift):
        refuse_reloaded(drift, Drift, "drift")
        raise NeurohoverError(f"drift={drift!r} is not allowed: give a neurohover.Drift or None for fixed dynamics")
    family = _family(name, sigma)
    if sensor is not None and not sensor.exact:
        family = family.with_sensor(sensor)
    return family if drift is None or drift.none else family.with_drift(drift)


def task_key(name: object) -> object:
    """The registry's key that ``name`` spells as the task lookup reads it (any case, hyphens dropped: 'GHH-08' is
    ghh08), else ``name`` as given, for :func:`family_class` to refuse by what was written. The one spelling rule of a
    task's name: the command line's --task, the families' lookups and the models' default substeps read it."""
    key = str(name).lower().replace("-", "")
    return key if key in TASK_FAMILIES else name


def _family(name: str, sigma: float | None) -> TaskFamily:
    cls = family_class(task_key(name))  # an unknown name refused as written, naming the registry's names
    if sigma is not None and not cls.has_sigma:
        with_sigma = [n for n, c in list(TASK_FAMILIES.items()) if not entry_problem(n, c) and c.has_sigma]
        raise NeurohoverError(f"sigma applies to the {', '.join(with_sigma)} task only, not to {brief(name)}")
    if cls.has_sigma and sigma is not None:  # the family's own check and message: 10**400 was cut to 40 digits, its range unnamed (T26-B16)
        return cls(sigma=sigma)  # type: ignore[call-arg]
    return cls()


#: What :func:`family_from_dict` reads; ``task`` is the experiments' name for ``family`` (their stored unit params).
FAMILY_KEYS = ("family", "sigma", "sensor", "drift")


def family_from_dict(d: dict) -> TaskFamily:
    """The task family of :meth:`TaskFamily.to_dict`'s dict (``task`` is read as ``family``; unknown keys refused)."""
    if not isinstance(d, dict):
        raise NeurohoverError(f"a task family must be a table {{family, sigma, sensor, drift}}, got {d!r:.80}")
    d = dict(d)
    if "task" in d and "family" not in d:
        d["family"] = d.pop("task")
    unknown = unknown_keys(d, FAMILY_KEYS)  # each as its repr: the key '' was named as nothing
    if unknown or "family" not in d:
        what = f"unknown key(s) {unknown}" if unknown else "no family name"
        raise NeurohoverError(f"task family table {d!r:.120}: {what}; allowed {', '.join(FAMILY_KEYS)} (family required)")
    sensor = None if d.get("sensor") is None else Sensor.from_dict(d["sensor"])
    drift = None if d.get("drift") is None else Drift.from_dict(d["drift"])
    return get_task_family(d["family"], d.get("sigma"), sensor, drift)


def family_for(name: str, sigma: float | None, sensor: Sensor | None = None, drift: Drift | None = None) -> TaskFamily:
    """Like :func:`get_task_family`, but a ``sigma`` is ignored for families without one (configs carry one for all)."""
    key = task_key(name)  # a list or an array, unhashable, was a TypeError here; get_task_family refuses it by name (T45-B04)
    has = isinstance(key, str) and key in TASK_FAMILIES and family_class(key).has_sigma
    return get_task_family(name, sigma if has else None, sensor, drift)


def set_name(task: object, sigma: object, spec: object) -> object:
    """What ``spec`` names among ``task``'s MDPs at breadth ``sigma``, as their labels write it (:meth:`TaskFamily.set_name`:
    FGHH's ``test`` at sigma 0.2 is ``seeded-test``); ``spec`` itself where task, sigma or spec is none a family takes (refused
    where they are checked). Read back in files that wrote the spec asked for (compete's summary before T37-A02)."""
    if not (isinstance(spec, str) and isinstance(task, str) and task in TASK_FAMILIES and (sigma is None or finite_real(sigma))):
        return spec
    try:
        return family_for(str(task), sigma).set_name(spec)  # type: ignore[arg-type]
    except NeurohoverError:
        return spec


__all__ = [
    "COMPETITION_FGHH_SIGMA",
    "COMPETITION_MDPS_FILE",
    "FGHH",
    "GHH08",
    "GHH09",
    "GHH09_PARAM_NAMES",
    "MAX_WIND",
    "MDP",
    "N_TEST",
    "N_TRAINING",
    "EXACT",
    "NO_DRIFT",
    "Drift",
    "Sensor",
    "TASK_FAMILIES",
    "TASK_NAMES",
    "TaskFamily",
    "check_rows",
    "competition_rows",
    "FAMILY_KEYS",
    "family_for",
    "family_from_dict",
    "finite_vector",
    "get_task_family",
    "refuse_drift",
    "refuse_unordered_mdps",
    "set_name",
    "task_key",
]
