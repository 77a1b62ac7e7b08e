"""The checks :class:`~neurohover.tasks.base.TaskFamily` puts around a family's own methods as the family class is defined:
its ``make`` and ``zero`` answer MDPs of the family (checked) through its sensor and drift, and its ``sample_params`` is called with a checked
generator and count; and :func:`generator`, the one reading of an ``rng`` argument."""

from __future__ import annotations

import functools

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
        return checked_answer(self, method(self, rng, int(n)), int(n))

    return draws


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
