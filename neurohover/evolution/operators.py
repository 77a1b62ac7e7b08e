"""Genome variation operators of the paper's neuroevolution (SPEC 4, Appendix A).

Genomes are flat float vectors (the network weights). Both operators are
elementwise, so they also accept stacked genomes of any shape; they never
modify their inputs.
"""

from __future__ import annotations

from typing import Protocol

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


def mutate(genome: np.ndarray, rng: np.random.Generator, settings: MutationParams) -> np.ndarray:
    """Return a mutated copy of ``genome``.

    Each gene is, independently with probability ``settings.mutate_frac``,
    perturbed by ``delta ~ N(0, settings.mutate_std)``; a perturbed gene is,
    with probability ``settings.mutate_repl``, replaced by ``delta`` instead
    of shifted by it.

    Parameters
    ----------
    genome : np.ndarray
        Genome (any shape; every element is a gene).
    rng : np.random.Generator
        Source of randomness. Exactly three arrays of ``genome.size`` draws are
        consumed per call, whatever the outcome, so runs stay reproducible.
    settings : MutationParams
        Provides ``mutate_frac``, ``mutate_std`` and ``mutate_repl``.

    Returns
    -------
    np.ndarray
        New float64 array of the same shape as ``genome``.
    """
    g = np.asarray(genome, dtype=np.float64)
    hit = rng.random(g.shape) < settings.mutate_frac
    delta = rng.normal(0.0, settings.mutate_std, g.shape)
    replace = rng.random(g.shape) < settings.mutate_repl
    return np.where(hit, np.where(replace, delta, g + delta), g)


def crossover(
    a: np.ndarray, b: np.ndarray, rng: np.random.Generator, settings: CrossoverParams
) -> np.ndarray:
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
    average = rng.random(a.shape) < settings.averaging_prob
    take_a = rng.random(a.shape) < 0.5
    return np.where(average, 0.5 * (a + b), np.where(take_a, a, b))
