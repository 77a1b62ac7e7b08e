"""Which MDPs a task family holds: the one check of an MDP against its family, run as every MDP is built (T27-B05).

An MDP of a task family is one its family holds: its zero, or what its :meth:`~neurohover.tasks.base.TaskFamily.make`
gives of the parameters at the family's ``row_slice`` (their ranges checked there); an MDP that differs from both in
another field (a GHH-08 wind of 99 m/s, a D_u on a true MDP) is none (T23-02). Its label, where it names one of the
family's MDPs, must name that MDP (T23-04).

The labels the code writes for an MDP, and which are checked against its parameters: ``F/zero``, ``F/train:N``,
``F/test:N`` and ``F/seeded-train:N``, ``F/seeded-test:N`` (the MDP the family names so; FGHH's seeded sets not, they
depend on a sigma an MDP does not record) and ``ghh08/wind=[u, v]`` (``fly --wind``: the wind itself; T24-05). Left
unchecked, as they name no parameters: ``F/custom`` (``fly --params``), ``F/sample`` and ``F/sample:N`` (drawn from G
by a seed the label does not record) and any other label given to ``make(label=...)``. A learned model's MDPs (family
``model``) may fly any wind and dynamics, under any label but one that names a task family's MDP, with the family or
without it (``ghh08/train:3``, T28-B09; ``train:3``, ``zero``, T33-B09).

The family's own :meth:`make` and :meth:`zero` build MDPs it holds by definition, so MDPs built while they run are not
checked again (:func:`family_code`): the check never recurses, and a family's fixed sets are built once. A label the
caller gives make() or sample() is still checked against the MDP built (:func:`check_label`).
"""

from __future__ import annotations

import contextlib
import re
import threading
from collections.abc import Iterator
from dataclasses import fields, replace
from typing import TYPE_CHECKING

from ..errors import NeurohoverError, brief, check_name_text, finite_real, other_import, real_number, reloaded_text, whole_number
from ..sim.constants import MDP_ROW_LEN, WIND_CONSTANT, WIND_NONE, WIND_SINUSOID
from ..sim.rng import MAX_SEED

if TYPE_CHECKING:
    from .base import MDP

LEARNED_MODEL = "model"  # the family name of a learned model's MDP, which may fly any wind
#: The wind kinds the MDPs of each family may have, by family name: each TaskFamily subclass registers its own as it is
#: defined (none, or none and its ``wind_kind``); an unknown family, or ghh09's wind under ghh08's name, was flown (T14-17).
WIND_KINDS: dict[str, tuple[int, ...]] = {LEARNED_MODEL: (WIND_NONE, WIND_CONSTANT, WIND_SINUSOID)}
_OWNERS: dict[str, str] = {LEARNED_MODEL: "the learned models' family"}  # the class of each family name (class module.qualname)

#: A label naming one of a family's MDPs by :meth:`TaskFamily.mdp`'s names, as its fixed sets and zero label them.
SET_LABEL = re.compile(r"(?:(?P<family>[^/]+)/)?(?P<spec>zero|(?:seeded-)?(?:train|test):[0-9]+)")
#: A label naming a constant wind as GHH-08's make() writes it by default (``fly --wind``): ``ghh08/wind=[1.0, -2.0]``.
WIND_LABEL = re.compile(r"(?:(?P<family>[^/]+)/)?wind=(?P<wind>\[.*\])")

_inside = threading.local()  # per thread: whether a family's own make() or zero() is running


@contextlib.contextmanager
def family_code() -> Iterator[None]:
    """While a family's own make() or zero() runs: the MDPs it builds are held by definition, not checked again."""
    outer = getattr(_inside, "active", False)
    _inside.active = True
    try:
        yield
    finally:
        _inside.active = outer


def check_held(mdp: MDP) -> None:
    """Refuse ``mdp`` where its task family does not hold it (:func:`held_problem`); MDPs a family's own code builds and
    a learned model's pass."""
    if getattr(_inside, "active", False):
        return
    from . import TASK_FAMILIES

    if mdp.family not in TASK_FAMILIES:  # a learned model's MDP: any wind, any dynamics, but no task family's label
        match = SET_LABEL.fullmatch(mdp.label) or WIND_LABEL.fullmatch(mdp.label)
        named = match.group("family") if match else None
        # 'ghh08/train:0' on a model was evolved on, and claimed as the policy's target (T28-B09); 'train:3' or 'zero',
        # a task family's names without the family, the same (T33-B09)
        if match is not None and (named is None or named in TASK_FAMILIES):
            names = f"a {brief(named)} MDP" if named else f"a task family's MDP ({brief(match.group(0))}, as a family names its own)"
            raise NeurohoverError(
                f"MDP {brief(mdp.label)} is not allowed: its label names {names}, but the MDP is a learned model's "
                f"(family {brief(mdp.family)}): give it a label of its own, e.g. 'model/lr'"
            )
        return
    with family_code():
        problem = held_problem(mdp)
    if problem:
        raise NeurohoverError(f"MDP {brief(mdp.label) if mdp.label else '(no label)'} is not allowed: {problem}")


def check_label(mdp: MDP) -> None:
    """Refuse the label a caller gave a family's make() or sample() where it names another MDP than the one built
    ('ghh08/train:0' on a wind of (0, 0), 'zero' on a draw; T29-B01): the family's code holds the MDP, not the label."""
    if getattr(_inside, "active", False) or (SET_LABEL.fullmatch(mdp.label) or WIND_LABEL.fullmatch(mdp.label)) is None:
        return
    from . import get_task_family

    with family_code():
        problem = _label_problem(mdp, get_task_family(mdp.family))
    if problem:
        raise NeurohoverError(f"MDP {brief(mdp.label)} is not allowed: {problem}")


def held_problem(mdp: MDP) -> str:
    """Why ``mdp`` is no MDP its task family holds ('' when it is one, or a learned model's); see the module docstring.
    Call it inside :func:`family_code`: it builds the family's zero, make() and named MDPs to compare."""
    from . import get_task_family
    from .base import MDP

    if type(mdp) is not MDP:  # its == meets no family MDP (a dataclass's == compares classes): refused as "its  differ" (T37-B06)
        return other_import(mdp, MDP) or (  # an MDP of the first import, after importlib.reload(tasks.base) (T42-B09)
            f"it is a {brief(type(mdp).__name__)} (a subclass of neurohover.MDP), but a {mdp.family} MDP is a neurohover.MDP itself: "
            "give neurohover.MDP(**{f.name: getattr(m, f.name) for f in dataclasses.fields(m)})"
        )
    family = get_task_family(mdp.family)  # a sigma only widens FGHH's draws, not what make() takes; its entry checked (T43-B10)
    cls = type(family)
    zero = family.zero()
    if type(zero) is not MDP:  # the families hold the first import's MDP: "its  differ from every fghh MDP's ()" (T42-B09)
        return reloaded_text(MDP)
    zero = replace(zero, sensor=mdp.sensor, drift=mdp.drift)
    if mdp != zero:
        try:
            made = family.make(mdp.row()[cls.row_slice])
        except NeurohoverError as err:
            return f"it is no {mdp.family} MDP: {err}"
        made = replace(made, sensor=mdp.sensor, drift=mdp.drift)
        if mdp != made:  # named against the nearer of the two: a zero MDP's substeps 3 blamed its (zero's) wind too (T25-13)
            near = min((made, zero), key=lambda other: len(differences(mdp, other)))
            return (
                f"it is no {mdp.family} MDP: its {', '.join(differences(mdp, near))} differ from every "
                f"{mdp.family} MDP's ({', '.join(differences(near, mdp))}), whose parameters are {', '.join(cls.param_names)}"
            )
    return _label_problem(mdp, family)


def _label_problem(mdp: MDP, family) -> str:
    """Why ``mdp``'s label contradicts it ('' when it names none of the family's MDPs, or that MDP)."""
    match = SET_LABEL.fullmatch(mdp.label) or WIND_LABEL.fullmatch(mdp.label)
    if match is None:
        return ""
    named = match.group("family") or mdp.family
    if named != mdp.family:
        return f"its label names a {brief(named)} MDP, but the MDP's family is {brief(mdp.family)}"
    if match.re is WIND_LABEL:  # 'ghh08/wind=[9.0, 9.0]' over a wind of [-0.228, 2.898] was taken (T24-05)
        return _wind_label_problem(mdp, match.group("wind"))
    spec = match.group("spec")
    if family.has_sigma and spec.startswith("seeded-"):  # FGHH's seeded sets depend on a sigma an MDP does not record
        return ""
    try:
        named_mdp = family.mdp(spec)
    except NeurohoverError as err:
        return f"its label names no {mdp.family} MDP: {err}"
    if mdp != replace(named_mdp, sensor=mdp.sensor, drift=mdp.drift):
        theirs = ", ".join(differences(named_mdp, mdp))
        return f"its {', '.join(differences(mdp, named_mdp))} contradict its label: {mdp.family}'s {spec} has {theirs}"
    return ""


def _wind_label_problem(mdp: MDP, text: str) -> str:
    """Why a ``wind=[...]`` label (what GHH-08's make() writes of the wind it is given, ``fly --wind``) is refused ('' when
    it is not): its numbers are not the MDP's wind (make() writes them as Python lists, whose text reads back as the same
    floats)."""
    from ..jsontext import strict_json

    try:
        named = strict_json(text)
    except ValueError:  # JSONError: no JSON, or nested past what Python can follow (a RecursionError, T33-B01)
        named = None
    if not isinstance(named, list) or not all(type(v) in (int, float) and finite_real(v) for v in named):  # 10**400: float() overflowed
        return "its label names no wind: give wind=[u, v], a list of numbers, as fly --wind writes it"
    if [float(v) for v in named] != list(mdp.wind):
        return f"its wind={brief(list(mdp.wind))} contradicts its label, which names the wind {brief(named)}"
    return ""


def differences(a: MDP, b: MDP) -> list[str]:
    """The fields (but label, sensor and drift) in which MDP ``a`` differs from ``b``, as ``name=value``."""
    return [
        f"{f.name}={brief(getattr(a, f.name))}" for f in fields(a) if f.name not in ("label", "sensor", "drift") and getattr(a, f.name) != getattr(b, f.name)
    ]


def register_family(cls: type) -> None:
    """Check a TaskFamily subclass that names a family (sets its own ``name``) and register the wind kinds its MDPs may
    have. Its class attributes must agree (n_params 20 with 11 param_names, param_bounds (1, -1) were taken and failed
    only in rows(), T40-B15), and its name must be no other class's: a user's class named 'ghh08' replaced GHH-08's wind
    kinds, and GHH-08's own windy MDPs were refused for the rest of the process (T40-B01). The same class defined again
    (its module reloaded, a notebook cell run again) replaces its own registration."""
    name = cls.__dict__["name"]
    what = f"task family class {cls.__name__}"
    check_name_text(f"{what}'s name", name, "the family (e.g. 'heavy')")
    owner = f"class {cls.__module__}.{cls.__qualname__}"
    if _OWNERS.get(name, owner) != owner:
        raise NeurohoverError(
            f"{what}'s name {name!r} is not allowed: {_OWNERS[name]} has it, and a second family of that name would change which MDPs "
            f"the first holds; give the family a name of its own (taken: {', '.join(sorted(_OWNERS))})"
        )
    problem = _class_problem(cls)
    if problem:
        raise NeurohoverError(f"{what} ({name!r}): {problem}")
    WIND_KINDS[name] = (WIND_NONE,) if cls.wind_kind == WIND_NONE else (WIND_NONE, cls.wind_kind)  # type: ignore[attr-defined]
    _OWNERS[name] = owner


def _class_problem(cls) -> str:
    """Why a task family class's own attributes contradict each other ('' when they agree)."""
    n, names, where, bounds = cls.n_params, cls.param_names, cls.row_slice, cls.param_bounds
    if not whole_number(n) or not 1 <= n <= MDP_ROW_LEN:
        return f"its n_params {brief(n)} is not allowed: give how many parameters make() takes, an integer in 1..{MDP_ROW_LEN}"
    if not isinstance(names, (tuple, list)) or not all(isinstance(x, str) and x for x in names) or len(set(names)) != len(names):
        return f"its param_names {brief(names)} is not allowed: give a tuple of distinct non-empty texts, one per parameter"
    if len(names) != n:
        return f"its n_params {n} is not allowed: it must be the number of its param_names, {len(names)} ({', '.join(names)})"
    if not isinstance(where, slice) or len(range(MDP_ROW_LEN)[where]) != n or where.step not in (None, 1):
        return f"its row_slice {brief(where)} is not allowed: give the slice of the {MDP_ROW_LEN}-number kernel row that holds its {n} parameters"
    if not (isinstance(bounds, tuple) and len(bounds) == 2 and all(real_number(b) and finite_real(b) for b in bounds) and bounds[0] < bounds[1]):
        return f"its param_bounds {brief(bounds)} is not allowed: give (low, high), two finite numbers with low < high, the range of each parameter"
    if cls.wind_kind not in (WIND_NONE, WIND_CONSTANT, WIND_SINUSOID) or isinstance(cls.wind_kind, bool):
        return f"its wind_kind {brief(cls.wind_kind)} is not allowed: give {WIND_NONE} (none), {WIND_CONSTANT} (constant) or {WIND_SINUSOID} (sinusoidal)"
    if not whole_number(cls.set_code) or not 0 <= cls.set_code <= MAX_SEED:  # 1.5 was NumPy's TypeError at training_mdps() (T52-B03)
        return f"its set_code {brief(cls.set_code)} is not allowed: give an integer in 0..2**63-1, a seed that distinguishes its seeded fixed sets"
    return ""
