"""What an agent without a ``start`` of its own keeps from one test run to the next (T49-B02).

An agent resets its per-run state in ``start(family, rng)``, which :func:`~neurohover.agents.protocol.run_test` calls
before each run. One whose class keeps the base class's (empty) ``start`` cannot be reset: flown a second time, it
chose from what its first run left (the README's example agent kept the first run's returns, and its second run's
score was another than a fresh agent's, without a word). :func:`run_test` takes a fingerprint of such an agent's
attributes as each run starts and refuses the next run when they changed; an agent that keeps nothing (the
protocol's ``AlwaysBaseline``) flies any number of runs.

Internal: neurohover's plumbing (README, Python API, What is public).
"""

from __future__ import annotations

import hashlib

import numpy as np

from ..errors import NeurohoverError

__all__ = ["note_run_start", "refuse_kept_state"]

_MAX_DEPTH = 4  # containers nested deeper are compared by identity: an agent's state is a few lists and tables
_MARK = "_neurohover_run_start_state"  # where the fingerprint is kept on the agent
_OURS = {_MARK, "_asked_record"}  # what neurohover itself keeps on an agent (the protocol's checks), not compared


def _fingerprint(value, depth: int = 0):
    """A comparable summary of ``value``: numbers and text by value, arrays by shape, type and bytes, lists, tuples,
    sets and dicts element by element (to :data:`_MAX_DEPTH`), any other object by identity."""
    if value is None or isinstance(value, (bool, int, float, complex, str, bytes, np.generic)):
        return (type(value).__name__, repr(value))  # repr: NaN equals NaN, -0.0 differs from 0.0
    if isinstance(value, np.ndarray):
        data = value.tobytes() if value.dtype != object else repr(value.tolist()).encode()
        return ("array", value.shape, value.dtype.str, hashlib.sha256(data).hexdigest())
    if depth < _MAX_DEPTH and isinstance(value, (list, tuple)):
        return (type(value).__name__, tuple(_fingerprint(v, depth + 1) for v in value))
    if depth < _MAX_DEPTH and isinstance(value, (set, frozenset)):
        return (type(value).__name__, tuple(sorted(repr(_fingerprint(v, depth + 1)) for v in value)))
    if depth < _MAX_DEPTH and isinstance(value, dict):
        return ("dict", tuple((repr(k), _fingerprint(v, depth + 1)) for k, v in value.items()))
    return ("object", id(value))


def _state(agent) -> dict:
    own = getattr(agent, "__dict__", {})
    return {name: _fingerprint(value) for name, value in own.items() if name not in _OURS}


def refuse_kept_state(agent) -> None:
    """Refuse to start a run of ``agent`` (whose class keeps the base ``start``) when an attribute changed since its
    previous run started, naming the attribute and what to do."""
    before = getattr(agent, "__dict__", {}).get(_MARK)
    if before is None:
        return
    now = _state(agent)
    changed = sorted(set(before) ^ set(now) | {name for name in set(before) & set(now) if before[name] != now[name]})
    if changed:
        raise NeurohoverError(
            f"agent {agent.name!r} has flown a test run, and its attribute {changed[0]!r} changed in it, but its class "
            f"{type(agent).__name__} defines no start(self, family, rng), so the next run would begin with what the last one "
            "left, which is not allowed: reset the per-run state in start (run_test calls it before each run), or make a new "
            "agent for each run"
        )


def note_run_start(agent) -> None:
    """Keep ``agent``'s fingerprint as its run starts (an agent that takes no new attributes is not followed)."""
    try:
        agent.__dict__[_MARK] = _state(agent)
    except (AttributeError, TypeError):  # __slots__ or a read-only mapping: nothing to keep, nothing compared
        pass
