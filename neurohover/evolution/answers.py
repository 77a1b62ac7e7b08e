"""A run's optimiser's answers, checked (README, A new optimiser): what :class:`~.run.Run` takes from any
:class:`~.common.Optimiser`, and a user's optimiser registered at run time above all, is checked before it is flown,
recorded or written, and a bad answer is refused naming the optimiser and the method that gave it."""

from __future__ import annotations

import json
import math
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import NeurohoverError, brief, finite_real, real_number
from ..sim.constants import lowest_return
from .common import Optimiser

if TYPE_CHECKING:
    from .config import RunConfig

__all__ = ["asked_genomes", "check_state_json", "told_champion"]


def asked_genomes(opt: Optimiser, cfg: RunConfig) -> np.ndarray:
    """The optimiser's next generation, checked: a user's optimiser (README, A new optimiser) asking genomes of another
    length, none, or a list failed in the flyer or in numba ("number of threads must be between 1 and 2"; T40-B05)."""
    genomes = opt.ask()
    d = cfg.prototype.genome.size
    if isinstance(genomes, np.ndarray) and genomes.dtype.kind in "fiu" and genomes.ndim == 2 and genomes.shape[0] >= 1 and genomes.shape[1] == d:
        if np.isfinite(genomes).all():
            return genomes
        gave = f"an array of shape {genomes.shape} with genes NaN or infinite"
    elif isinstance(genomes, np.ndarray):
        gave = f"an array of shape {genomes.shape} and dtype {genomes.dtype}"
    else:
        gave = f"a {type(genomes).__name__} {brief(genomes)}"
    raise NeurohoverError(
        f"optimizer {brief(cfg.optimizer)}: its ask() gave {gave}, which is not allowed: give a NumPy array of real numbers of shape (n, {d}), "
        f"n >= 1 genomes of the {cfg.topology} topology's {d} finite genes"
    )


def told_champion(opt: Optimiser, cfg: RunConfig) -> float:
    """The optimiser's champion_return, checked where it is the run's (on one MDP, on the return scale): -inf before a
    finite return, else a return an episode can have; a user's optimiser reporting 1e9 was taken as the result (T40-B06b)."""
    ret = opt.champion_return
    if cfg.method == "generational" or (finite_real(ret) and lowest_return(cfg.n_steps) * (1 + 1e-9) <= ret <= 0):
        return float(ret)
    if real_number(ret) and float(ret) == -math.inf:
        return float(ret)
    raise NeurohoverError(
        f"optimizer {brief(cfg.optimizer)}: its champion_return {brief(ret)} is not allowed: allowed -inf (no finite return told yet) or a return "
        f"told, in [{lowest_return(cfg.n_steps):.6g}, 0] for episodes of {cfg.n_steps} steps (every reward is minus a sum of squares)"
    )


def check_state_json(state: Any, optimizer: str) -> None:
    """NeurohoverError naming the first entry of optimiser state ``state`` that strict JSON cannot write (an np.float32,
    an array, NaN): ``state_dict()`` returns a plain JSON-serialisable snapshot (:class:`~.common.Optimiser`)."""
    where = _unwritable(state, "")
    if where is not None:
        at, value = where
        raise NeurohoverError(
            f"optimizer {brief(optimizer)}: its state_dict() entry {at or '(the whole state)'} is {type(value).__name__} {brief(value)}, "
            "which is not allowed: "
            "a checkpoint is strict JSON, so state_dict() gives plain numbers (finite; non-finite as text), text, lists and tables of text keys "
            "(an np.float32 as float(...), an array as .tolist())"
        )


def _unwritable(value: Any, at: str) -> tuple[str, Any] | None:
    """Where in ``value`` (its path from ``at``, and what is there) strict JSON cannot write, or None where it can."""
    try:
        json.dumps(value, allow_nan=False)
        return None
    except (TypeError, ValueError, RecursionError):
        pass
    if isinstance(value, dict):
        for key, item in value.items():
            if not isinstance(key, str):
                return f"{at}[{brief(key)}] (a key that is no text)", key
            found = _unwritable(item, f"{at}[{key!r}]")
            if found is not None:
                return found
    elif isinstance(value, (list, tuple)):
        for i, item in enumerate(value):
            found = _unwritable(item, f"{at}[{i}]")
            if found is not None:
                return found
    return at, value
