"""Fitness scales of an episode (docs/model.md, Fitness under noise; the authors' FGHH code).

A candidate's fitness estimate is the mean over its episodes of one episode's fitness:

- ``inv-log-error`` (the authors' FGHH scripts, and the steady state's roulette weights):
  ``1 / ln(error)`` with ``error = -return`` (crash penalty included). A crash (error about 1e7)
  scores about 0.062, hovering at an error of 1,000 about 0.145, at 150 about 0.200: one crash in
  k episodes costs a bounded amount instead of outweighing everything else.
- ``return``: the raw return (the paper's text read literally).

Errors are clamped to at least :data:`ERROR_FLOOR` (slightly above 1, where ``ln`` is zero), which
only very short episodes reach; a NaN return (a numerical blow-up) gets fitness ``-inf``.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import NeurohoverError, as_floats, brief, finite_real, whole_in
from ..sim.constants import MAX_EPISODE_STEPS, lowest_return

__all__ = ["ERROR_FLOOR", "FITNESS_SCALES", "episode_fitness", "error_of_fitness", "fitness_range", "in_fitness_range"]

#: What a generational run's ``fitness`` setting may be.
FITNESS_SCALES = ("inv-log-error", "return")
#: Errors are clamped to at least this before ``1/ln(error)`` (its fitness is about 1e6).
ERROR_FLOOR = 1.0 + 1e-6


def _check_scale(scale: object) -> None:
    """Refuse a ``scale`` that is not one of :data:`FITNESS_SCALES`: text first, as a comparison with ``np.ma.masked``
    is masked, so neither ``== "return"`` nor ``!= "inv-log-error"`` held and it was taken as inv-log-error (T17-6)."""
    if not isinstance(scale, str) or scale not in FITNESS_SCALES:
        raise NeurohoverError(f"unknown fitness scale {brief(scale)}: allowed {', '.join(FITNESS_SCALES)}")


def episode_fitness(returns: np.ndarray, scale: str) -> np.ndarray:
    """The fitness of each episode's return on ``scale`` (one of :data:`FITNESS_SCALES`); NaN -> ``-inf``."""
    _check_scale(scale)
    r = as_floats(returns, "returns", "episode returns")  # np.asarray(dtype=float) read time spans as numbers (T17-1)
    if scale == "return":
        return np.where(np.isnan(r), -np.inf, r)
    error = np.maximum(np.where(np.isnan(r), np.inf, -r), ERROR_FLOOR)
    return np.where(np.isnan(r), -np.inf, 1.0 / np.log(error))


def error_of_fitness(fitness: np.ndarray | float, scale: str) -> np.ndarray:
    """The error (``-return``) whose fitness on ``scale`` is ``fitness``: ``exp(1/f)`` or ``-f``."""
    _check_scale(scale)  # any other scale was read as inv-log-error
    f = as_floats(fitness, "fitness", "fitness values")  # 'x' was NumPy's ValueError (T44-B04)
    if scale == "return":
        return -f
    with np.errstate(divide="ignore", over="ignore"):
        return np.where(f > 0, np.exp(1.0 / np.where(f > 0, f, 1.0)), np.inf)


def fitness_range(n_steps: int, scale: str) -> tuple[float, float, str]:
    """``(low, high, words)``: the finite fitness estimates a run of ``n_steps``-step episodes can have on ``scale``, a
    mean of its episodes' fitness (never a sum: fixed resampling, races and bandits all average), so within one
    episode's range. On ``return`` it is [lowest_return(n_steps), 0] (every reward is minus a sum of squares, at worst
    the crash charge of each step); on ``inv-log-error`` 1/ln(error) with the error in [ERROR_FLOOR,
    -lowest_return(n_steps)], so [1/ln(-lowest_return(n_steps)), 1/ln(ERROR_FLOOR)]. ``-inf`` (a NaN episode's fitness)
    lies outside; a checker allows it itself. The bounds are exact: a checker allows 1e-9 relative for a mean's
    rounding (-1e9 in a 20-step run's steady-state fitness was resumed; T27-B03)."""
    _check_scale(scale)
    n_steps = whole_in(n_steps, "n_steps", 1, MAX_EPISODE_STEPS)  # -1 or NaN: bounds of nonsense (T44-B04)
    worst = lowest_return(n_steps)
    if scale == "return":
        return worst, 0.0, f"a mean return in [{worst:.10g}, 0] (the worst step, for each of its {n_steps:,} steps, to none)"
    low, high = 1.0 / math.log(max(-worst, ERROR_FLOOR)), 1.0 / math.log(ERROR_FLOOR)
    return low, high, f"a mean 1/ln(error) in [{low:.7g}, {high:.7g}] (an error of at most {-worst:.10g}, the worst step for each of its {n_steps:,} steps)"


def in_fitness_range(values: np.ndarray | float, low: float, high: float) -> np.ndarray:
    """Whether each of ``values`` lies in [low, high] of :func:`fitness_range`, 1e-9 relative each side for a mean's
    rounding (False for NaN and infinities)."""
    for name, bound in (("low", low), ("high", high)):  # None was a TypeError, NaN held nothing (T44-B04)
        if not finite_real(bound):
            raise NeurohoverError(f"{name}={brief(bound)} is not allowed: allowed a finite number (a bound of fitness_range)")
    if float(low) > float(high):
        raise NeurohoverError(f"low={brief(low)} is out of range: allowed a number at most high={brief(high)} (a range of fitness_range)")
    low, high = float(low), float(high)
    v = as_floats(values, "values", "fitness values")
    return (v >= low - 1e-9 * abs(low)) & (v <= high + 1e-9 * abs(high))
