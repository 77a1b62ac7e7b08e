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
    """
    g = np.asarray(genome, dtype=np.float64)
    hit_r = rng.random(g.size)
    delta = rng.normal(0.0, settings.mutate_std, g.size)
    if scale is not None:
        delta *= np.asarray(scale, dtype=np.float64).reshape(-1)
    replace_r = rng.random(g.size)
    return _mutate_genes(g, hit_r, delta, replace_r, settings.mutate_frac, settings.mutate_repl)


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
    ValueError
        If the parents' shapes differ.
    """
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    if a.shape != b.shape:
        raise ValueError(f"crossover parents must have the same shape, got {a.shape} and {b.shape}")
    average_r = rng.random(a.size)
    take_a_r = rng.random(a.size)
    return _crossover_genes(a, b, average_r, take_a_r, settings.averaging_prob)


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
