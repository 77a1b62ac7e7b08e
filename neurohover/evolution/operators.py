"""Genome variation operators of the paper's neuroevolution (docs/model.md, Neuroevolution; Appendix A).

Genomes are flat float vectors (the network weights). Both operators are
elementwise, so they also accept stacked genomes of any shape; they never
modify their inputs.

Each operator draws its random numbers with NumPy, then combines them with the
genes in a compiled loop: with the paper's settings the steady-state method
breeds one offspring per episode, and a handful of small NumPy calls per gene
array would cost more than the loop itself.
"""

from __future__ import annotations

from typing import Protocol

import numba
import numpy as np

from ..errors import NeurohoverError, brief
from .common import MAX_SPREAD, MIN_SPREAD, as_floats, require_prob, require_spread

__all__ = ["MutationParams", "CrossoverParams", "mutate", "crossover"]


class MutationParams(Protocol):
    """Anything carrying the three mutation settings (e.g. ``SteadyStateSettings``)."""

    @property
    def mutate_frac(self) -> float: ...

    @property
    def mutate_std(self) -> float: ...

    @property
    def mutate_repl(self) -> float: ...


class CrossoverParams(Protocol):
    """Anything carrying ``averaging_prob`` (e.g. ``SteadyStateSettings``)."""

    @property
    def averaging_prob(self) -> float: ...


def mutate(genome: np.ndarray, rng: np.random.Generator, settings: MutationParams, scale: np.ndarray | None = None) -> np.ndarray:
    """Return a mutated copy of ``genome``.

    Each gene is, independently with probability ``settings.mutate_frac``,
    perturbed by ``delta ~ N(0, settings.mutate_std)``; a perturbed gene is,
    with probability ``settings.mutate_repl``, replaced by ``delta`` instead
    of shifted by it. With ``scale``, gene i's ``delta`` is multiplied by
    ``scale[i]`` (the same random draws, so ``scale=None`` and a scale of ones
    give identical genomes).

    Parameters
    ----------
    genome : np.ndarray
        Genome (any shape; every element is a gene).
    rng : np.random.Generator
        Source of randomness. Exactly three arrays of ``genome.size`` draws are
        consumed per call, whatever the outcome, so runs stay reproducible.
    settings : MutationParams
        Provides ``mutate_frac``, ``mutate_std`` and ``mutate_repl``.
    scale : np.ndarray, optional
        Per-gene scale of ``delta`` (shape of ``genome``).

    Returns
    -------
    np.ndarray
        New float64 array of the same shape as ``genome``.

    Raises
    ------
    NeurohoverError
        A genome or scale that is no real numbers, a non-finite gene, a scale below 0 or of another size, an ``rng`` that is no Generator, or
        settings without the three fields in range (checked before any draw).
    """
    g = genome if type(genome) is np.ndarray and genome.dtype is _F64 else _genes(genome, "genome")
    _check_finite(g, "genome")
    if not isinstance(rng, np.random.Generator):
        raise _bad_rng(rng)
    try:
        frac, std, repl = settings.mutate_frac, settings.mutate_std, settings.mutate_repl
    except AttributeError:
        raise _bad_settings(settings, "mutate_frac, mutate_std and mutate_repl") from None
    fast = type(frac) is float and type(std) is float and type(repl) is float and 0.0 <= frac <= 1.0 and 0.0 <= repl <= 1.0
    if not (fast and (std == 0.0 or MIN_SPREAD <= std <= MAX_SPREAD)):  # 1e-320 flew as 0 (T57-A01)
        require_prob("mutate_frac", frac)  # the settings classes' checks, for what the fast test above does not pass
        require_prob("mutate_repl", repl)
        std = require_spread("mutate_std", std)
    std += 0.0  # -0.0 as 0.0: NumPy's normal() refuses it
    if scale is not None:
        scale = _genes(scale, "scale")
        if scale.size != g.size:  # was NumPy's broadcast error after the draws
            raise NeurohoverError(f"scale has shape {scale.shape}: give one number per gene of the genome, shape {g.shape}")
        if not (np.isfinite(scale) & (scale >= 0)).all():  # -1 and NaN were taken (T27-B13)
            raise NeurohoverError(f"scale={brief(scale)} is not allowed: give one finite number >= 0 per gene (a scale of delta)")
    hit_r = rng.random(g.size)
    delta = rng.normal(0.0, std, g.size)
    if scale is not None:
        delta *= scale.reshape(-1)
    replace_r = rng.random(g.size)
    return _mutate_genes(g, hit_r, delta, replace_r, frac, repl)


def crossover(a: np.ndarray, b: np.ndarray, rng: np.random.Generator, settings: CrossoverParams) -> np.ndarray:
    """Return a child of two aligned genomes.

    Each child gene is, with probability ``settings.averaging_prob``, the mean
    of the parents' genes; otherwise it is a copy of the gene of one parent
    picked uniformly at random (independently per gene).

    Parameters
    ----------
    a, b : np.ndarray
        Parent genomes of identical shape.
    rng : np.random.Generator
        Source of randomness (two arrays of ``a.size`` draws per call).
    settings : CrossoverParams
        Provides ``averaging_prob``.

    Returns
    -------
    np.ndarray
        New float64 array of the parents' shape.

    Raises
    ------
    NeurohoverError
        Parents that are no real numbers, hold a non-finite gene or differ in shape, an ``rng`` that is no Generator, or settings without
        ``averaging_prob`` in [0, 1] (checked before any draw).
    """
    a = a if type(a) is np.ndarray and a.dtype is _F64 else _genes(a, "a")
    b = b if type(b) is np.ndarray and b.dtype is _F64 else _genes(b, "b")
    if a.shape != b.shape:
        raise NeurohoverError(f"crossover parents must have the same shape, got {a.shape} and {b.shape}")
    _check_finite(a, "a")
    _check_finite(b, "b")
    if not isinstance(rng, np.random.Generator):
        raise _bad_rng(rng)
    try:
        averaging = settings.averaging_prob
    except AttributeError:
        raise _bad_settings(settings, "averaging_prob") from None
    if type(averaging) is not float or not 0.0 <= averaging <= 1.0:
        require_prob("averaging_prob", averaging)
    average_r = rng.random(a.size)
    take_a_r = rng.random(a.size)
    return _crossover_genes(a, b, average_r, take_a_r, averaging)


# The checks run at every offspring (fifteenth trial: a bad argument was an AttributeError, NumPy's or numba's error):
# O(1) type tests inline first, and the shared checks (their messages) only for what fails them.

_F64 = np.dtype(np.float64)


def _genes(values, name: str) -> np.ndarray:
    """``values`` as float64 genes, or :func:`~neurohover.evolution.common.as_floats`' error."""
    return as_floats(values, name, "a genome: an array of real numbers")


def _check_finite(genes: np.ndarray, name: str) -> None:
    """NeurohoverError unless every gene is finite, as Policy, SteadyStateNE and CMAES require: NaN parents gave NaN
    children silently (T27-B13)."""
    if not np.isfinite(genes).all():
        bad = np.flatnonzero(~np.isfinite(genes))
        raise NeurohoverError(f"{name}={brief(genes)} is not allowed: a genome must hold finite numbers; genes {brief(bad.tolist())} are not")


def _bad_rng(rng) -> NeurohoverError:
    return NeurohoverError(f"rng={brief(rng)} is not allowed: give a numpy.random.Generator (np.random.default_rng(seed))")


def _bad_settings(settings, fields: str) -> NeurohoverError:
    return NeurohoverError(f"settings={brief(settings)} is not allowed: give settings with {fields} (e.g. a SteadyStateSettings)")


# Gene i in C order (``.flat[i]``) gets draw i, as if the draws had been made in the genome's shape.


@numba.njit(cache=True)
def _mutate_genes(g, hit_r, delta, replace_r, mutate_frac, mutate_repl):
    child = np.empty(g.shape)
    for i in range(g.size):
        if hit_r[i] < mutate_frac:
            child.flat[i] = delta[i] if replace_r[i] < mutate_repl else g.flat[i] + delta[i]
        else:
            child.flat[i] = g.flat[i]
    return child


@numba.njit(cache=True)
def _crossover_genes(a, b, average_r, take_a_r, averaging_prob):
    child = np.empty(a.shape)
    for i in range(a.size):
        if average_r[i] < averaging_prob:
            child.flat[i] = 0.5 * (a.flat[i] + b.flat[i])
        elif take_a_r[i] < 0.5:
            child.flat[i] = a.flat[i]
        else:
            child.flat[i] = b.flat[i]
    return child
