"""The twelfth bad-input trial, for the models helpers, the flying integration, the reward wrappers and evaluate-agent:
each case it found gives one clear message (exit 2 / NeurohoverError) or is taken as a user would expect."""

from __future__ import annotations

import fractions
import json
import sys
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

import neurohover as nh
from neurohover import models as M
from neurohover.errors import NeurohoverError
from neurohover.integrations.flying import compare_agent, evaluate_callable
from neurohover.wrappers import CrashAwareReward, crash_aware


@pytest.fixture(scope="module")
def flight_data() -> nh.FlightData:
    """Two short baseline episodes on the GHH-08 zero setting."""
    return nh.evaluate(nh.baseline_policy(), nh.get_task_family("ghh08").zero(), episodes=2, seed=1, n_steps=40, record=True).flight_data


def _zeros(obs: np.ndarray) -> np.ndarray:
    return np.zeros((len(obs), 4))


@pytest.mark.parametrize("episode", [1.5, True, "0", None])
def test_observed_return_names_an_episode_that_is_no_integer(flight_data: nh.FlightData, episode: object) -> None:
    """T4: observed_return(fd, 1.5) was a TypeError from tuple indexing, and True was taken as episode 1."""
    with pytest.raises(NeurohoverError, match=rf"episode={episode!r} is not allowed: give an integer in 0\.\.1$"):
        M.observed_return(flight_data, episode)  # type: ignore[arg-type]
    assert M.observed_return(flight_data, np.int64(1)) == M.observed_return(flight_data, 1)


def test_one_step_error_and_the_parameter_table_name_what_they_cannot_take(flight_data: nh.FlightData) -> None:
    """T4: one_step_error("x", fd) was NumPy's "could not convert string to float"; format_parameter_table([1, 2]) an
    AttributeError, of a text or a number an AttributeError or TypeError."""
    with pytest.raises(NeurohoverError, match=r"model='x' is not allowed: give a LearnedModel, a one-substep model MDP, 11 parameters or an \(n, 11\)"):
        M.one_step_error("x", flight_data)
    with pytest.raises(NeurohoverError, match=r"row 1 is not allowed: give the ParamRow rows that parameter_table returns"):
        M.format_parameter_table([1, 2])  # type: ignore[list-item]
    for rows in ("x", 5):
        with pytest.raises(NeurohoverError, match=rf"rows={rows!r} is not allowed: give the list of ParamRow that parameter_table returns"):
            M.format_parameter_table(rows)  # type: ignore[arg-type]
    table = M.parameter_table(M.learn_lr(flight_data))
    assert M.format_parameter_table(iter(table)) == M.format_parameter_table(table)


def test_lr_determined_refuses_what_learn_lr_refuses(flight_data: nh.FlightData) -> None:
    """S6: lr_determined(fd, "x") and wind_model="x" answered True where learn_lr refuses both; a text as the flight data
    was an AttributeError."""
    with pytest.raises(NeurohoverError, match=r"intercepts='x' is not allowed: choose one of v, uv, all, none"):
        M.lr_determined(flight_data, "x")
    with pytest.raises(NeurohoverError, match=r"wind_model='x' is not allowed: choose one of none, constant, sinusoid"):
        M.lr_determined(flight_data, wind_model="x")
    with pytest.raises(NeurohoverError, match=r"flight data must be a FlightData, got str"):
        M.lr_determined("x")  # type: ignore[arg-type]
    assert M.lr_determined(flight_data) is True


def test_evaluate_callable_checks_first_episode_and_on_step_before_flying() -> None:
    """T5: first_episode="x" was a TypeError and True taken as 1; on_step=5 a TypeError after the first step had flown."""
    mdp = nh.get_task_family("ghh08").mdp("train:0")
    for value in ("x", True, 1.0):
        with pytest.raises(NeurohoverError, match=rf"first_episode={value!r} is not allowed: give an integer in 0\.\.2\*\*62-1"):
            evaluate_callable(_zeros, mdp, n_steps=5, first_episode=value)  # type: ignore[arg-type]
    calls = []

    def act(obs: np.ndarray) -> np.ndarray:
        calls.append(1)
        return _zeros(obs)

    with pytest.raises(NeurohoverError, match=r"on_step=5 is not allowed: give a function of no arguments \(called after each step\) or None"):
        evaluate_callable(act, mdp, n_steps=5, on_step=5)  # type: ignore[arg-type]
    assert calls == []  # refused before a step flew
    with pytest.raises(NeurohoverError, match=r"on_step=5 is not allowed"):
        compare_agent(nh.baseline_policy(), mdp, n_steps=5, on_step=5)  # type: ignore[arg-type]


def test_compare_agent_takes_one_mdp_as_evaluate_callable_does() -> None:
    """T5: compare_agent(act, one_mdp) was "'MDP' object is not iterable" where evaluate_callable takes one MDP."""
    mdp = nh.get_task_family("ghh08").mdp("train:0")
    for agent in (_zeros, nh.baseline_policy()):
        assert compare_agent(agent, mdp, n_steps=5) == compare_agent(agent, [mdp], n_steps=5)
    with pytest.raises(NeurohoverError, match=r"mdps must be one MDP or a non-empty sequence of MDPs"):
        compare_agent(nh.baseline_policy(), 5, n_steps=5)  # type: ignore[arg-type]


def test_compare_agent_checks_a_policy_as_it_checks_a_callable() -> None:
    """S5: a Policy flew MDPs of two task families (the GHH-08 generic flying a GHH-09 MDP) and obs_dtype='x' was
    ignored, both refused for a callable."""
    m8, m9 = nh.get_task_family("ghh08").mdp("train:0"), nh.get_task_family("ghh09").mdp("train:0")
    for agent in (_zeros, nh.baseline_policy()):
        with pytest.raises(NeurohoverError, match=r"mdps must all be MDPs of one task family \(got ghh08, ghh09\)"):
            compare_agent(agent, [m8, m9], n_steps=5)
        with pytest.raises(NeurohoverError, match=r"obs_dtype='x' is not allowed: use 'float64' or 'float32'"):
            compare_agent(agent, [m8], n_steps=5, obs_dtype="x")
    with pytest.raises(NeurohoverError, match=r"obs_dtype='float64' applies to a callable that receives observations, not to a Policy"):
        compare_agent(nh.baseline_policy(), [m8], n_steps=5, obs_dtype="float64")


def test_crash_aware_names_a_ragged_reward() -> None:
    """T6: crash_aware([[1], [1, 2]]) was NumPy's "inhomogeneous shape" ValueError."""
    with pytest.raises(NeurohoverError, match=r"reward=\[\[1\], \[1, 2\]\] is not allowed: give a real number or an array of them"):
        crash_aware([[1], [1, 2]])


@pytest.mark.parametrize(
    ("gamma", "scale"),
    [(np.float32(0.5), 1.0), (np.int64(1), 1.0), (fractions.Fraction(1, 2), 1.0), (0.5, np.float32(2)), (0.5, fractions.Fraction(3, 2))],
)
def test_crash_aware_takes_any_real_number_type_in_range(gamma: object, scale: object) -> None:
    """U1: gamma=np.float32(0.9), np.int64(1), Fraction(1, 2) and scale=np.float32(2) were refused as "out of range"."""
    expected = crash_aware(np.array([-1e6, -1.0]), float(gamma), float(scale))  # type: ignore[arg-type]
    np.testing.assert_array_equal(crash_aware(np.array([-1e6, -1.0]), gamma, scale), expected)  # type: ignore[arg-type]
    assert expected.dtype == np.float64
    wrapped = CrashAwareReward(gym.make("neurohover/GHH08-Short-v0"), gamma=gamma, scale=scale)  # type: ignore[arg-type]
    assert (wrapped.gamma, wrapped.scale) == (float(gamma), float(scale))  # type: ignore[arg-type]


# the bounds since T35-B08 (the largest) and T40-B16 (the smallest)
SCALES = (
    " and <= 1e+300 (a larger one makes a crash's reward infinite) and >= 1e-300 (a smaller one makes rewards denormal floats, "
    "which lose the differences between steps)"
)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"gamma": "0.9"}, "gamma='0.9' is not allowed: give a real number, a discount in (0, 1]"),
        ({"gamma": True}, "gamma=True is not allowed: give a real number, a discount in (0, 1]"),
        ({"scale": None}, "scale=None is not allowed: give a real number, a finite number > 0" + SCALES),
        ({"gamma": np.float32(1.5)}, "gamma=np.float32(1.5) is out of range: allowed a discount in (0, 1]"),
        ({"scale": float("inf")}, "scale=inf is out of range: allowed a finite number > 0" + SCALES),
    ],
)
def test_crash_aware_says_whether_the_type_or_the_value_is_wrong(kwargs: dict, message: str) -> None:
    """U1: a value of the wrong type was reported as "out of range" whatever it was."""
    with pytest.raises(NeurohoverError) as err:
        crash_aware(-1.0, **kwargs)
    assert str(err.value) == message


@pytest.mark.parametrize(
    ("source", "spec", "message"),
    [
        ("def act(obs):\n    raise SystemExit(0)\n", "agent_exits:act", "--callable 'agent_exits:act' raised SystemExit: 0 when called with a batch"),
        ("import sys\nsys.exit(0)\n", "agent_exits:act", "--callable 'agent_exits:act': importing agent_exits raised SystemExit: 0"),
        ("raise RuntimeError('at import')\n", "agent_exits:act", "--callable 'agent_exits:act': importing agent_exits raised RuntimeError: at import"),
    ],
)
def test_a_callable_that_exits_is_refused_not_taken_as_success(source: str, spec: str, message: str, tmp_path: Path, monkeypatch, cli) -> None:
    """S1: a --callable whose function raised SystemExit(0) ended evaluate-agent with exit 0, nothing printed and no
    --json written; a module exiting or raising at import did the same or gave a traceback."""
    (tmp_path / "agent_exits.py").write_text(source)
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.delitem(sys.modules, "agent_exits", raising=False)
    rc, out, err = cli("evaluate-agent", "--task", "ghh08", "--callable", spec, "--n-mdps", "1", "--episode-steps", "5", "--json", str(tmp_path / "ex.json"))
    assert rc == 2 and message in err, (rc, out, err)
    assert not (tmp_path / "ex.json").exists()


def test_evaluate_agent_with_a_policy_still_writes_its_rows(tmp_path: Path, cli) -> None:
    """S5's CLI side: compare_agent is handed no obs_dtype for a --policy, which it now refuses beside a Policy."""
    rc, _, err = cli("evaluate-agent", "--task", "ghh08", "--policy", "baseline", "--n-mdps", "1", "--episode-steps", "5", "--json", str(tmp_path / "r.json"))
    assert rc == 0, err
    assert [r["name"] for r in json.loads((tmp_path / "r.json").read_text())["rows"]] == ["agent", "baseline", "generic"]
