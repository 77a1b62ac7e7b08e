"""A run's optimiser's answers, checked (README, A new optimiser): what :class:`~.run.Run` takes from any
:class:`~.common.Optimiser`, and a user's optimiser registered at run time above all, is checked before it is flown,
recorded or written, and a bad answer is refused naming the optimiser and the method that gave it."""

from __future__ import annotations

import json
import math
import time
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import NeurohoverError, brief, finite_real, masked_note, real_number, refused_signature
from ..jsontext import MAX_NOTE_DEPTH
from ..sim.constants import lowest_return
from .common import STATE_DAMAGE, Optimiser, enc_float
from .records import decode_history

if TYPE_CHECKING:
    from .config import RunConfig

__all__ = [
    "AnswerError",
    "asked_genomes",
    "check_made",
    "check_restored",
    "check_round_trip",
    "check_state_json",
    "check_state_nesting",
    "checked_champion",
    "checked_champion_genome",
    "held_champion",
    "read_only",
    "stopped",
    "told_champion",
]

#: What a run calls of its optimiser, and with how many positional arguments (README, A new optimiser).
CALLS = {"ask": (0,), "tell": (1, 2), "stop": (0,), "state_dict": (0,), "from_state_dict": (1,)}


class AnswerError(NeurohoverError):
    """An optimiser's answer refused by name: raised as it is where a checkpoint is read, not as a damaged checkpoint."""


def check_made(opt: Any, optimizer: str, called: str = "make") -> None:
    """AnswerError unless ``opt`` (what ``called`` answered) is an optimiser a run can use: its ask, tell, stop, state_dict
    and from_state_dict callable with what a run gives them, and its champion_genome and champion_return readable. A make
    answering None was an AttributeError at the first ask; a tell(self, fitness) a TypeError after the first generation
    was flown (T52-B08, B10)."""
    calls = ", ".join(f"{name}()" for name in CALLS)
    for name, counts in CALLS.items():
        method = getattr(opt, name, None)
        if not callable(method):
            raise AnswerError(
                f"optimizer {brief(optimizer)}: its {called} answered {type(opt).__name__} {brief(opt)}, which has no {name}() and is not allowed: "
                f"answer an optimiser with {calls}, champion_genome and champion_return"
            )
        refused = next(filter(None, (refused_signature(method, n) for n in counts)), None)
        if refused:
            takes = "tell(fitness, info=None) (info a TellInfo, left out on a task family)" if name == "tell" else f"{name}({'state' if counts[0] else ''})"
            raise AnswerError(
                f"optimizer {brief(optimizer)}: its {name} of signature {brief(refused)} is not allowed: a run calls {takes}; give one taking that"
            )
    for name in ("champion_genome", "champion_return"):
        if not hasattr(opt, name):
            raise AnswerError(f"optimizer {brief(optimizer)}: its {called} answered {type(opt).__name__} {brief(opt)}, which has no {name} and is not allowed")


def asked_genomes(opt: Optimiser, cfg: RunConfig) -> np.ndarray:
    """The optimiser's next generation, checked: a user's optimiser (README, A new optimiser) asking genomes of another
    length, none, or a list failed in the flyer or in numba ("number of threads must be between 1 and 2"; T40-B05); a
    masked array is refused, as every array given is (:func:`~neurohover.errors.as_floats`)."""
    genomes = opt.ask()
    d = cfg.prototype.genome.size
    if isinstance(genomes, np.ma.MaskedArray):  # isfinite skips masked genes, which flew at their hidden values, NaN too (T56-B02)
        gave = f"a masked array of shape {genomes.shape}"
    elif isinstance(genomes, np.ndarray) and genomes.dtype.kind in "fiu" and genomes.ndim == 2 and genomes.shape[0] >= 1 and genomes.shape[1] == d:
        if np.isfinite(genomes).all():
            return genomes
        gave = f"an array of shape {genomes.shape} with genes NaN or infinite"
    elif isinstance(genomes, np.ndarray):
        gave = f"an array of shape {genomes.shape} and dtype {genomes.dtype}"
    else:
        gave = f"a {type(genomes).__name__} {brief(genomes)}"
    raise NeurohoverError(
        f"optimizer {brief(cfg.optimizer)}: its ask() gave {gave}, which is not allowed: give a NumPy array of real numbers of shape (n, {d}), "
        f"n >= 1 genomes of the {cfg.topology} topology's {d} finite genes{masked_note(genomes)}"
    )


def read_only(values: np.ndarray) -> np.ndarray:
    """A read-only copy of ``values`` (what a run tells its optimiser): a tell() writing into its fitness argument changed
    the returns the run then recorded, so that the run's result was 0.0 for a champion flying -73.5 (T54-B04)."""
    told = np.array(values)
    told.flags.writeable = False
    return told


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


def check_restored(opt: Any, state: dict, cfg: RunConfig, written: Any, since: float) -> None:
    """AnswerError naming a user optimiser's from_state_dict where its answer is no optimiser, or (on one MDP, where the
    run's champion is its optimiser's) one whose champion_return is not the one the checkpoint's history records last:
    one that ignored its state, or answered None, was called "a damaged checkpoint" of an intact file (T52-B12). Then,
    on one MDP and over a family, one whose state_dict() is not ``written`` (the checkpoint's optimiser state, as read,
    restored from at ``time.perf_counter()`` ``since``), by :func:`check_round_trip`: one that forgot its generator or
    champion resumed as another run (T55-B04)."""
    check_made(opt, cfg.optimizer, "from_state_dict")
    if cfg.family is None:
        try:
            history = decode_history(state["history"])
            ret = float(opt.champion_return)
        except STATE_DAMAGE:  # (a damaged history, or a return no number: the checks of the checkpoint name it)
            history, ret = None, math.nan
        saved = history[-1].champion_return if history else -math.inf
        if history is not None and ret != saved:
            row = f"its last history row's, at generation {history[-1].generation:,}" if history else "its history has no row"
            raise AnswerError(
                f"optimizer {brief(cfg.optimizer)}: its from_state_dict answered an optimiser of champion_return {enc_float(ret)}, where the checkpoint's "
                f"champion has return {enc_float(saved)} ({row}), which is not allowed: from_state_dict(state) gives back the optimiser whose "
                "state_dict() wrote state, its champion too"
            )
    check_round_trip(opt, written, cfg.optimizer, since)


def check_round_trip(opt: Any, written: Any, optimizer: str, since: float) -> None:
    """AnswerError naming the first entry (its path) where ``opt.state_dict()``, as strict JSON writes it, is not
    ``written``, the state ``opt`` was restored from at ``time.perf_counter()`` ``since``: the README's "strict JSON
    that reads back as it was" (T55-B04). Only a ``wall_seconds`` entry (the wall clock :class:`~.common.Clock`
    continues) may have grown, by at most the seconds since then."""
    mine = opt.state_dict()
    seconds = time.perf_counter() - since
    check_state_json(mine, optimizer)
    found = _difference(json.loads(json.dumps(mine, allow_nan=False)), written, "", seconds)
    if found is not None:
        at, now, was = found
        raise AnswerError(
            f"optimizer {brief(optimizer)}: its from_state_dict answered an optimiser whose state_dict() entry {at or '(the whole state)'} is {now}, "
            f"where the checkpoint's state has {was}, which is not allowed: from_state_dict(state) gives back the optimiser whose state_dict() "
            "wrote state, all of it (its generator's state and champion too)"
        )


def _difference(mine: Any, was: Any, at: str, seconds: float) -> tuple[str, str, str] | None:
    """The first path under ``at`` where ``mine`` is not ``was`` as strict JSON writes them (a key missing, another type,
    1 for 1.0), with the two shown; None where they agree (``wall_seconds`` may have grown by ``seconds``)."""
    if isinstance(mine, dict) and isinstance(was, dict):
        for key in [*was, *(k for k in mine if k not in was)]:
            if key not in mine or key not in was:
                return f"{at}[{key!r}]", "missing" if key not in mine else brief(mine[key]), "no such entry" if key not in was else brief(was[key])
            found = _difference(mine[key], was[key], f"{at}[{key!r}]", seconds)
            if found is not None:
                return found
        return None
    if isinstance(mine, list) and isinstance(was, list) and len(mine) == len(was):
        return next(filter(None, (_difference(a, b, f"{at}[{i}]", seconds) for i, (a, b) in enumerate(zip(mine, was)))), None)
    if isinstance(mine, list) and isinstance(was, list):
        return at, f"a list of {len(mine):,}", f"a list of {len(was):,}"
    if json.dumps(mine) == json.dumps(was):
        return None
    if at.endswith("['wall_seconds']") and all(type(v) is float for v in (mine, was)) and 0 <= mine - was <= seconds:
        return None  # the wall clock ran on between from_state_dict and state_dict (a PopulationOptimiser's)
    return at, brief(mine), brief(was)


def checked_champion_genome(opt: Optimiser, cfg: RunConfig) -> np.ndarray | None:
    """The optimiser's champion_genome, checked where it is the run's champion: None (no champion yet) or real numbers of
    the genome's shape, finite. 'x' was "could not convert string to float", a ragged list NumPy's inhomogeneous shape, a
    table a TypeError, and a complex genome taken with only NumPy's ComplexWarning (T52-B07)."""
    genome = opt.champion_genome
    if genome is None:
        return None
    d = cfg.prototype.genome.size
    try:
        # a masked array's masked genes would be recorded at their hidden values, as its ask() is refused (T56-B02)
        a = np.asarray(genome) if isinstance(genome, (np.ndarray, list, tuple)) and not isinstance(genome, np.ma.MaskedArray) else None
    except (ValueError, TypeError):  # a ragged list
        a = None
    if a is not None and a.dtype.kind in "fiu" and a.shape == (d,):
        if np.isfinite(a).all():
            return a.astype(float)
        gave = f"genes NaN or infinite ({', '.join(map(str, np.flatnonzero(~np.isfinite(a))[:5]))}...)"
    else:
        gave = f"{type(genome).__name__} {brief(genome)}" + ("" if a is None else f" (shape {a.shape}, dtype {a.dtype})")
    raise NeurohoverError(
        f"optimizer {brief(cfg.optimizer)}: its champion_genome {gave} is not allowed: give None (no champion yet) or a NumPy array of real numbers of "
        f"shape ({d},), the {cfg.topology} topology's {d} finite genes{masked_note(genome)}"
    )


#: A champion the run holds for its optimiser: its genome (None before one) and return (-inf before a finite one).
Held = tuple[np.ndarray | None, float]


def held_champion(opt: Optimiser, cfg: RunConfig) -> Held:
    """The optimiser's champion genome and return, checked one by one and together: a genome held with return -inf was taken,
    and lost only where save_policy refused its metadata (T54-B05); a finite return without a genome names no champion."""
    genome, ret = checked_champion_genome(opt, cfg), told_champion(opt, cfg)
    if (genome is None) != (ret == -math.inf):
        raise NeurohoverError(
            f"optimizer {brief(cfg.optimizer)}: its champion_return {brief(ret)} with {'champion_genome None' if genome is None else 'a champion_genome held'} "
            "is not allowed: give -inf with champion_genome None (no finite return told yet), or a genome with the return told for it"
        )
    return genome, ret


def checked_champion(opt: Optimiser, cfg: RunConfig, held: Held, genomes: np.ndarray, returns: np.ndarray) -> Held:
    """The optimiser's champion after the run told it ``returns`` of ``genomes`` (its last ask(), as flown), where ``held``
    was its champion before: that one, or a genome of ``genomes`` with the return told for it. A champion_return above
    every return told (T54-B03), or a genome never asked recorded with another's return (T54-B06), was the run's result.
    Only the champion before and the last generation are kept, so a long run holds one genome more, not every one told."""
    genome, ret = held_champion(opt, cfg)
    if genome is None:
        return genome, ret
    rows = np.flatnonzero((genomes == genome).all(axis=1))  # (by value: a copy of an asked genome, a list too, is that genome)
    allowed = {float(r) for r in returns[rows]} | ({held[1]} if held[0] is not None and np.array_equal(held[0], genome) else set())
    if not allowed:
        raise NeurohoverError(
            f"optimizer {brief(cfg.optimizer)}: its champion_genome {brief(genome)} is not allowed: it is no genome its ask() gave, and the run flies and "
            "tells only those; give None (no champion yet), the champion before, or a genome of the last ask()"
        )
    if ret not in allowed:
        told = ", ".join(map(str, sorted(allowed, reverse=True)[:5]))
        raise NeurohoverError(
            f"optimizer {brief(cfg.optimizer)}: its champion_return {brief(ret)} is not allowed: give a return told for its champion_genome ({told})"
        )
    return genome, ret


def stopped(opt: Optimiser, optimizer: str) -> bool:
    """The answer of the optimiser's stop(), checked to be a bool (Python's or NumPy's): "yes", None and [] were taken by
    their truth (T52-B11)."""
    answer = opt.stop()
    if isinstance(answer, (bool, np.bool_)):
        return bool(answer)
    raise AnswerError(f"optimizer {brief(optimizer)}: its stop() answered {type(answer).__name__} {brief(answer)}, which is not allowed: answer True or False")


def check_state_json(state: Any, optimizer: str) -> None:
    """NeurohoverError naming the first entry of optimiser state ``state`` that strict JSON cannot write (an np.float32,
    an array, NaN, a list that holds itself), or a state nested too deep (:func:`check_state_nesting`): ``state_dict()``
    returns a plain JSON-serialisable snapshot (:class:`~.common.Optimiser`)."""
    check_state_nesting(state, optimizer)  # first: the walk below recurses, and is bounded only once this has passed
    where = _unwritable(state, "")
    if where is not None:
        at, value = where
        raise NeurohoverError(
            f"optimizer {brief(optimizer)}: its state_dict() entry {at or '(the whole state)'} is {type(value).__name__} {brief(value)}, "
            "which is not allowed: "
            "a checkpoint is strict JSON, so state_dict() gives plain numbers (finite; non-finite as text), text, lists and tables of text keys "
            "(an np.float32 as float(...), an array as .tolist())"
        )


def check_state_nesting(state: Any, optimizer: str) -> None:
    """NeurohoverError where optimiser state ``state`` holds a list or table that holds itself, or nests lists and tables
    (itself counted) more than :data:`~neurohover.jsontext.MAX_NOTE_DEPTH` deep: a state 900 deep was written, and its
    checkpoint then failed to resume, a RecursionError in copying it; 5,000 deep was one in this check (T61-B02, B03).
    Measured without recursion, each list or table once."""
    found = _deepest(state)
    if found is None:
        return
    keys, depth = found
    if depth is None:
        raise NeurohoverError(
            f"optimizer {brief(optimizer)}: its state_dict() entry {_path_text(keys)} (a list or table that holds itself, which JSON cannot write) "
            "is not allowed: a checkpoint is strict JSON, so state_dict() gives plain numbers, text, lists and tables, none holding itself"
        )
    if depth > MAX_NOTE_DEPTH:
        raise NeurohoverError(
            f"optimizer {brief(optimizer)}: its state_dict() is nested {depth:,} lists or tables deep (the state counted; deepest under entry "
            f"{_path_text(keys)}), which is not allowed: at most {MAX_NOTE_DEPTH}, so that a run resumes from its checkpoint "
            "(a state much deeper cannot be copied or read back)"
        )


def _path_text(keys: list[Any]) -> str:
    """The entry at path ``keys`` as ``['a'][0]``, its first levels only where it is long."""
    shown = "".join(f"[{k!r}]" if isinstance(k, (str, int)) else f"[{brief(k)}]" for k in keys[:6])
    return shown + (f"... ({len(keys):,} levels down)" if len(keys) > 6 else "") if keys else "(the whole state)"


def _deepest(value: Any) -> tuple[list[Any], int | None] | None:
    """The path to the deepest point of ``value`` and how many lists, tuples and tables nest there (itself counted), or the
    path to a list or table that holds itself and None; None where ``value`` is none of those. Without recursion (a
    state 5,000 deep was a RecursionError here, T61-B03); a list or table held twice is measured once."""
    if not isinstance(value, (list, tuple, dict)):
        return None
    heights: dict[int, tuple[int, Any]] = {}  # id -> (its depth, the key of its deepest child; None: no list below)
    frames: list[list[Any]] = [[value, iter(_items(value)), 1, None]]  # container, its items left, its depth so far, its deepest key
    path: list[Any] = []
    on_path = {id(value)}
    while frames:
        frame = frames[-1]
        for key, item in frame[1]:
            if not isinstance(item, (list, tuple, dict)):
                continue
            if id(item) in on_path:
                return [*path, key], None
            if id(item) not in heights:
                frames.append([item, iter(_items(item)), 1, None])
                path.append(key)
                on_path.add(id(item))
                break
            if heights[id(item)][0] + 1 > frame[2]:
                frame[2], frame[3] = heights[id(item)][0] + 1, key
        else:
            frames.pop()
            on_path.discard(id(frame[0]))
            heights[id(frame[0])] = (frame[2], frame[3])
            if frames:
                key = path.pop()
                if frame[2] + 1 > frames[-1][2]:
                    frames[-1][2], frames[-1][3] = frame[2] + 1, key
    keys, node = [], value
    while heights[id(node)][1] is not None:  # down the deepest children
        keys.append(heights[id(node)][1])
        node = node[keys[-1]]
    return keys, heights[id(value)][0]


def _items(value: list | tuple | dict) -> Any:
    return value.items() if isinstance(value, dict) else enumerate(value)


def _unwritable(value: Any, at: str, writable: bool | None = None) -> tuple[str, Any] | None:
    """Where in ``value`` (its path from ``at``, and what is there) strict JSON cannot write, or writes as another value
    (a key that is no text comes back as text, a tuple as a list: T52-B17), or None where it writes ``value`` as it is.
    ``writable``: whether ``json.dumps`` writes it (None: not yet asked). ``value`` holds no list or table that holds
    itself, and nests at most :data:`~neurohover.jsontext.MAX_NOTE_DEPTH` deep (:func:`check_state_nesting` ran first)."""
    if writable is None:
        try:
            json.dumps(value, allow_nan=False)
            writable = True
        except (TypeError, ValueError, RecursionError):
            writable = False
    if isinstance(value, tuple):
        return f"{at} (a tuple, which JSON writes as a list)", value
    if isinstance(value, dict):
        for key, item in value.items():
            if not isinstance(key, str):
                return f"{at}[{brief(key)}] (a key that is no text, which JSON writes as text)", key
            found = _unwritable(item, f"{at}[{key!r}]", True if writable else None)
            if found is not None:
                return found
    elif isinstance(value, list):
        for i, item in enumerate(value):
            found = _unwritable(item, f"{at}[{i}]", True if writable else None)
            if found is not None:
                return found
    elif not writable:
        return at, value
    return None
