"""Bad-input trial 22, more: a 0-step flight-data episode refused when made (T22-19), a non-integer env argument
called not allowed rather than out of range (T22-14), impossible sessions-table values refused by name (T22-21)."""

from __future__ import annotations

import re

import numpy as np
import pytest
from store_edits import begin

from neurohover.errors import NeurohoverError
from neurohover.experiments.store import Store
from neurohover.flightdata import FlightData


@pytest.mark.parametrize("lengths", [(1, 0), (0,), (0, 3)])
def test_zero_step_episode_refused_when_made(lengths, tmp_path):
    """T22-19: save() wrote a file of a 0-step episode that load() refused; the constructor now refuses it, as load()."""
    obs = tuple(np.zeros((n + 1, 12)) for n in lengths)
    act = tuple(np.zeros((n, 4)) for n in lengths)
    with pytest.raises(NeurohoverError, match=rf"episode {lengths.index(0)} has 0 steps \(a flown one has at least 1\)"):
        FlightData(obs, act)
    assert not list(tmp_path.iterdir())


def test_no_episodes_still_made():
    """An empty window (no episodes at all) is still flight data: the continual agent makes one before its first episode."""
    assert FlightData((), ()).n_episodes == 0


@pytest.mark.parametrize("value", [20.0, "20", True, None])
@pytest.mark.parametrize("name", ["episode_steps", "max_episode_steps", "num_envs"])
def test_env_count_of_wrong_type_not_allowed(name, value):
    """T22-14: gymnasium.make(..., episode_steps=20.0) said 'is out of range' (a type problem called a range one); a
    non-integer is now 'not allowed', an integer past the range still 'out of range'."""
    import gymnasium as gym

    from neurohover.envs.vector import HoverVectorEnv
    from neurohover.errors import brief

    if name == "episode_steps":
        make = lambda v: gym.make("neurohover/GHH08-v0", episode_steps=v)  # noqa: E731
    else:
        make = lambda v: HoverVectorEnv(**{"num_envs": 2, "episode_steps": 20, name: v})  # noqa: E731
    if value is None and name == "max_episode_steps":
        return  # None is its default: the episode budget
    with pytest.raises(NeurohoverError, match=rf"^{name}={re.escape(brief(value))} is not allowed: allowed an integer in 1\.\."):
        make(value)
    with pytest.raises(NeurohoverError, match=rf"^{name}=0 is out of range: allowed an integer in 1\.\."):
        make(0)


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ("units_run = 99", "units_before 0 and units_run 99 are not allowed: together at most the 0 units the experiment stores"),
        ("units_before = -5", "units_before -5 is not allowed: allowed a whole number >= 0"),
        ("units_run = 1.5", "units_run 1.5 is not allowed: allowed a whole number >= 0"),
        ("status = 'zzz'", "status 'zzz' is not allowed: allowed 'running', 'finished'"),
        ("executor = 'zzz'", "executor 'zzz' is not allowed: allowed 'local', 'ray'"),
        ("started = -1e300", "started -1e+300 is not allowed: allowed a time (seconds since 1970) from 2001 to 2106"),
        ("started = 1e12", "started 1000000000000.0 is not allowed: allowed a time"),
        ("started = 'x'", "started 'x' is not allowed"),
    ],
)
def test_impossible_session_row_is_store_damage(change, message, tmp_path):
    """T22-21: sessions rows of units_run 99 (of no unit), units_before -5, status 'zzz', executor 'zzz' or a start in
    1e12 were read, and printed by results and report; Store.sessions() now names the session, field and value."""
    with Store(tmp_path / "s.sqlite") as store:
        session = store.start_session("e", "quick", begin(store, "e"), "local", 1, 0)  # of a begun experiment (T29-B04)
        assert store.sessions("e", "quick")[0]["status"] == "running"  # a run killed by SIGKILL stays 'running': allowed
        store.conn.execute(f"UPDATE sessions SET {change} WHERE id = ?", (session,))
        with pytest.raises(NeurohoverError, match=re.escape(f"experiment e (quick), session {session} is damaged: {message}")):
            store.sessions("e", "quick")


def test_repeated_session_row_is_store_damage(tmp_path):
    """T22-21: a sessions row copied (a new id, every other field the same) counted one run twice."""
    with Store(tmp_path / "s.sqlite") as store:
        first = store.start_session("e", "quick", begin(store, "e"), "local", 1, 0)
        store.end_session(first, "finished")
        store.conn.execute(
            "INSERT INTO sessions SELECT NULL, name, scale, config_hash, executor, cores, started, wall_seconds, units_run, units_before, status FROM sessions"
        )
        with pytest.raises(NeurohoverError, match=re.escape(f"session {first + 1} is damaged: it repeats session {first} field for field")):
            store.sessions("e", "quick")
