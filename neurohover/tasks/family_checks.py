"""The checks :class:`~neurohover.tasks.base.TaskFamily` puts around a family's own methods as the family class is defined:
its ``make`` and ``zero`` answer MDPs of the family (checked) through its sensor and drift, and its ``sample_params`` is called with a checked
generator and count; the checks of a registered family class (:func:`class_problem`) and of its kernel row layout
(:func:`row_layout_problem`); and :func:`generator`, the one reading of an ``rng`` argument."""

from __future__ import annotations

import copy
import dataclasses
import functools
import re

import numpy as np

from ..errors import NeurohoverError, as_floats, brief, whole_in, whole_number
from ..sim.rng import MAX_SEED
from .held import check_label, family_code


def through_sensor(method, which: str, mdp_class: type):
    """``method`` (a family's make or zero) with its answer checked (:func:`check_made`) and the family's sensor and drift
    put on the MDP it returns; ``which``: the method's name, ``mdp_class``: the MDP class of the module that defined the
    family (after ``importlib.reload`` of tasks.base the shipped families still build the first import's)."""

    @functools.wraps(method)
    def made(self, *args, **kwargs):
        with family_code():  # what the family's own code builds, it holds: not checked again (tasks.held)
            mdp = method(self, *args, **kwargs)
            check_made(self, which, mdp, mdp_class)
            if which == "make":
                check_made_label(self, mdp, kwargs.get("label", args[1] if len(args) > 1 else ""))
                check_made_row(self, mdp, kwargs.get("params", args[0] if args else None))
                check_made_bounds(self, mdp)
            if not self.sensor.exact:
                mdp = mdp.with_sensor(self.sensor)
            mdp = mdp if self.drift.none else mdp.with_drift(self.drift)
        check_label(mdp)  # but a caller's label= is the caller's: it must name this MDP (T29-B01)
        return mdp

    return made


def check_made(family, method: str, mdp: object, mdp_class: type) -> None:
    """Refuse what a family's ``make`` or ``zero`` answered where it is no MDP of the family (an MDP whose family is the
    family's name): None was an AttributeError 'label' (T52-B04), and a renamed subclass of a shipped family, whose
    inherited make and zero answer the shipped family's MDPs, was refused only at run_test (T52-B05)."""
    name = family.name
    if not isinstance(mdp, mdp_class):
        raise NeurohoverError(f"{name} {method}()'s answer {brief(mdp)} is not allowed: it must be an MDP of the family, neurohover.MDP({name!r}, ...)")
    if mdp.family != name:  # type: ignore[attr-defined]
        owner = next(c for c in type(family).__mro__ if method in c.__dict__)
        inherited = (
            ""
            if owner is type(family)
            else f" ({type(family).__name__} inherits {method} from {owner.__name__}: a renamed subclass must override make and zero)"
        )
        raise NeurohoverError(
            f"{name} {method}()'s answer {brief(mdp.label or mdp)} is not allowed: it is a {mdp.family!r} MDP, but make and zero must answer "  # type: ignore[attr-defined]
            f"MDPs of {name!r}, neurohover.MDP({name!r}, ...){inherited}"
        )


def check_made_label(family, mdp, label: object) -> None:
    """Refuse an MDP that ``family.make(params, label=label)`` answered under another label than the text ``label`` given:
    a make that ignored it labelled all 110 fixed MDPs alike, so records and stores could not tell them apart (T54-B13)."""
    if isinstance(label, str) and label and mdp.label != label:
        raise NeurohoverError(
            f"{family.name} make()'s answer labelled {brief(mdp.label)} is not allowed: make(params, label={label!r}) must answer "
            f"an MDP of that label, neurohover.MDP({family.name!r}, ..., label=label)"
        )


def check_made_row(family, mdp, params: object) -> None:
    """Refuse an MDP that ``family.make(params)`` answered whose kernel row does not hold ``params`` at the family's
    ``row_slice`` (:func:`row_layout_problem`): only rows() checked it, so a make that ignored its params flew
    training_mdps, sample(), evaluate and HoverEnv at the default dynamics without a word (T59-B02). Checked at every
    call where the params read one way only: a float64 array (every sampled and seeded MDP's) or plain Python numbers
    (the competition's); a narrower float (np.float32(0.3): 0.3 or 0.30000001?) or a Fraction is make's own to read."""
    plain = isinstance(params, (list, tuple)) and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in params)
    if not (plain or (isinstance(params, np.ndarray) and params.dtype == np.float64)):
        return
    try:
        probe = np.asarray(params, dtype=float).reshape(-1)
    except (TypeError, ValueError, OverflowError):  # a ragged list, an int past float64: make took it its own way
        return
    if probe.shape == (family.n_params,):
        problem = row_layout_problem(family, probe, mdp.row())
        if problem:
            raise NeurohoverError(problem)


def check_made_bounds(family, mdp) -> None:
    """Refuse an MDP that ``family.make`` answered whose parameters (its kernel row at the family's ``row_slice``, where
    :meth:`~neurohover.tasks.base.TaskFamily.rows` writes them) lie outside the family's ``param_bounds``, naming the
    first such parameter: it was flown, where rows() of the same parameters refused them (T55-B05)."""
    low, high = family.param_bounds
    values = mdp.row()[family.row_slice]
    outside = np.flatnonzero((values < low) | (values > high))
    if outside.size:
        j = int(outside[0])
        raise NeurohoverError(
            f"{family.name} make()'s answer {brief(mdp.label or mdp)} is out of range: its {family.param_names[j]}={float(values[j])!r} lies "
            f"outside the family's param_bounds; each parameter must lie in [{low:g}, {high:g}] ({', '.join(family.param_names)})"
        )


MAX_SAMPLES = 10**7  # MDPs drawn in one call (their rows: 2.9 GB)


def generator(rng, what: str = "rng") -> np.random.Generator:
    """``rng`` as a NumPy Generator: a Generator, a seed (an integer >= 0) or None (fresh entropy); else a clear error."""
    if rng is None or isinstance(rng, np.random.Generator):
        return np.random.default_rng(rng)
    if not whole_number(rng) or not 0 <= rng <= MAX_SEED:  # every seed's range; np.timedelta64 was int()'s TypeError (T17-1)
        raise NeurohoverError(f"{what}={brief(rng)} is not allowed: give a numpy Generator, a seed (an integer in 0..2**63-1) or None")
    return np.random.default_rng(int(rng))


def checked_draws(method):
    """A family's ``sample_params`` with its arguments and its answer checked (it is the family's own code): the one
    check of every caller's draws (sample, the seeded sets, sample_rows, the environments)."""

    @functools.wraps(method)
    def draws(self, rng, n):
        if not isinstance(rng, np.random.Generator):
            raise NeurohoverError(f"rng={rng!r} is not allowed: give a numpy Generator (np.random.default_rng(seed))")
        whole_in(n, "n", 0, MAX_SAMPLES, f"{MAX_SAMPLES:,} (MDPs drawn in one call)")  # np.timedelta64 was int()'s TypeError (T17-1)
        probe = None if type(self) in _DRAWS_AS_SINGLES else copy.deepcopy(rng)  # the generator as it was, for the check below
        answer = checked_answer(self, method(self, rng, int(n)), int(n))
        if probe is not None:  # once per class: its batches drew MDPs its single draws never gave, unnoticed (T54-B01)
            _DRAWS_AS_SINGLES.add(type(self))  # before: a sample_params that calls itself does not check again
            try:
                check_batches(self, method, probe)
            except BaseException:
                _DRAWS_AS_SINGLES.discard(type(self))
                raise
        return answer

    return draws


#: The family classes whose sample_params was found to draw n MDPs as n single draws would (:func:`check_batches`).
_DRAWS_AS_SINGLES: set[type] = set()


def check_batches(family, method, rng: np.random.Generator) -> None:
    """Refuse a family whose ``sample_params`` (``method``, unchecked) does not draw 2 MDPs as 2 single draws would, both
    values and the generator consumed, from copies of ``rng``: the protocol's promise that a stream of MDPs does not
    depend on batch sizes (sample_rows, evolution over G and the vector environment would fly MDPs sample() never gives)."""
    batched, single = copy.deepcopy(rng), rng
    pair = checked_answer(family, method(family, batched, 2), 2)
    one_by_one = np.concatenate([checked_answer(family, method(family, single, 1), 1) for _ in range(2)])
    what = f"{family.name} sample_params(rng, 2)'s answer"
    allowed = "give n draws that consume the generator as n single draws would (a stream of MDPs must not depend on batch sizes)"
    close = np.isclose(pair, one_by_one, rtol=1e-9, atol=1e-12)
    if not close.all():
        i, j = (int(k) for k in np.argwhere(~close)[0])
        raise NeurohoverError(
            f"{what} is not allowed: its row {i} has {family.param_names[j]}={float(pair[i, j])!r}, where single draws sample_params(rng, 1) from the "
            f"same generator give {float(one_by_one[i, j])!r} (draw {i}); {allowed}"
        )
    if not np.array_equal(batched.bit_generator.random_raw(2), single.bit_generator.random_raw(2)):
        raise NeurohoverError(f"{what} is not allowed: it leaves the generator elsewhere than 2 single draws sample_params(rng, 1) do; {allowed}")


def checked_answer(family, answer, n: int) -> np.ndarray:
    """``answer`` of ``family.sample_params(rng, n)`` as a float array of shape (n, n_params) of finite numbers within the
    family's ``param_bounds``, else one error naming sample_params, what it gave and what is asked: 4 rows for 3 were
    flown without a word (T51-B04), and a 1-D answer's first number handed to make() by sample() (T51-B05)."""
    what = f"{family.name} sample_params(rng, {n})'s answer"
    allowed = f"it must be an array of shape (n, n_params) = ({n}, {family.n_params}) of finite numbers ({', '.join(family.param_names)})"
    if type(answer) is np.ndarray and answer.dtype == np.float64:  # the shipped families' own: not copied (up to MAX_SAMPLES rows)
        arr = answer
    else:
        try:
            arr = as_floats(answer, what, "")
        except NeurohoverError:
            raise NeurohoverError(f"{what} {brief(answer)} is not allowed: {allowed}") from None
    if arr.shape != (n, family.n_params):
        raise NeurohoverError(f"{what} of shape {arr.shape} is not allowed: {allowed}")
    if not np.isfinite(arr).all():
        raise NeurohoverError(f"{what} {brief(arr.tolist())} is not allowed: {allowed}")
    low, high = family.param_bounds  # as rows() and make() refuse them: the vector environment writes the draws into its rows
    outside = np.flatnonzero(((arr < low) | (arr > high)).any(axis=1))
    if outside.size:
        i = int(outside[0])
        raise NeurohoverError(f"{what} row {i} {brief(arr[i].tolist())} is out of range: each parameter must lie in [{low:g}, {high:g}]")
    return arr


#: What a task family's name may be: the records write it before '/' in MDP labels and targets, before ':' in specs and
#: inside Gymnasium ids, and the task lookup reads any case with hyphens dropped (tasks.task_key), so one line of at most
#: 64 lowercase letters, digits, '.' and '_' ('he/avy/seeded-train:1' read as family 'he'; T54-B08).
FAMILY_NAME = re.compile(r"[a-z0-9][a-z0-9._]{0,63}")
#: The flags of a family class, with what True means (T54-B11).
FLAGS = {"has_sigma": "it has a breadth sigma, a field of its dataclass", "generic_over_distribution": "its generic policies are evolved over G"}


def class_problem(entry: str, name: str, cls: type) -> str:
    """What is wrong with a run-time task family class registered as ``name`` ('' when nothing), beside the registry's
    shared checks (``entry``: the refusal's start, ``TASK_FAMILIES['x'] = ... is not allowed``): a name the records cannot
    hold (T54-B08), a flag that is no bool ('no' read as True; T54-B11), has_sigma without a ``sigma`` field
    (get_task_family(name, 0.3) was a TypeError; T54-B10)."""
    if not FAMILY_NAME.fullmatch(name):
        return (
            f"{entry}: a task family's name is one line of at most 64 lowercase letters, digits, '.' and '_' (no '/', ':', spaces, capitals "
            "or '-': the records write it in MDP labels F/train:N, and the task lookup reads any case with hyphens dropped)"
        )
    flags = {flag: getattr(cls, flag, None) for flag in FLAGS}
    for flag, value in flags.items():
        if not isinstance(value, (bool, np.bool_)):
            return f"{entry}: its {flag} {brief(value)} is no bool: give True ({FLAGS[flag]}) or False"
    if flags["has_sigma"] and not (dataclasses.is_dataclass(cls) and any(f.name == "sigma" and f.init for f in dataclasses.fields(cls))):
        return (
            f"{entry}: its has_sigma is True, but it has no sigma field: declare one in its dataclass (sigma: float = 0.3, as FGHH does) "
            "or set has_sigma = False"
        )
    return ""


def row_layout_problem(family, probe: np.ndarray, template: np.ndarray) -> str:
    """Why ``template``, the kernel row of ``family.make(probe)``, does not hold ``probe`` at the family's ``row_slice``
    ('' when it does), naming where the parameters sit if they sit together elsewhere (it was a RuntimeError; T54-B12)."""
    where = family.row_slice
    check = template.copy()
    check[where] = probe
    if np.array_equal(check, template):
        return ""
    n = len(probe)
    found = next((i for i in range(len(template) - n + 1) if np.array_equal(template[i : i + n], probe)), None)
    hint = (
        f"they sit at slice({found}, {found + n}): give row_slice = slice({found}, {found + n})"
        if found is not None
        else "they sit nowhere in its row: make(params) must build the MDP of those parameters"
    )
    return (
        f"{family.name} make()'s kernel row is not allowed: it does not put the parameters {brief(probe.tolist())} in row_slice {where} "
        f"(it holds {brief(template[where].tolist())} there); {hint}"
    )
