"""The seventeenth bad-input trial's findings in the Python API (evaluation, agents, environments, tasks, plots): a NumPy
time span where a number goes, a NaN given as a dtype and a policy directory for an agent that flies no policy set each
give one NeurohoverError naming the value and what is allowed; the good inputs beside them still work."""

from __future__ import annotations

import re
from collections.abc import Callable
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

import neurohover as nh
from neurohover.agents.continual import ContinualSettings
from neurohover.agents.protocol import run_test
from neurohover.agents.registry import check_agent, make_agent
from neurohover.agents.risk import RiskSettings
from neurohover.envs import HoverEnv, HoverVectorEnv
from neurohover.errors import NeurohoverError, brief
from neurohover.evaluate import DangerousState, evaluate
from neurohover.evolution.steady_state import SteadyStateSettings
from neurohover.plots import plot_flight_data
from neurohover.tasks.drift import Drift
from neurohover.tasks.sensor import Sensor

TIMES = [np.timedelta64(5, "s"), np.timedelta64(4)]  # np.timedelta64 is a np.signedinteger: it passed integer checks
FAMILY = nh.get_task_family("ghh08")
MDP = FAMILY.mdp("test:0")
POLICY = nh.baseline_policy()


def _flight() -> object:
    return evaluate(POLICY, MDP, n_steps=5, record=True).flight_data


#: Per argument: the call with value v, the start of its message for v (given the shown value), and a good value.
CASES: dict[str, tuple[Callable[[object], object], str, object]] = {
    "get_task_family name": (lambda v: nh.get_task_family(v), "unknown task {}", "ghh08"),
    "get_task_family sigma": (lambda v: nh.get_task_family("fghh", sigma=v), "FGHH sigma={} is not allowed", 0.5),
    "make_agent name": (lambda v: make_agent(v, FAMILY), "unknown agent {}", "baseline"),
    "evaluate episodes": (lambda v: evaluate(POLICY, MDP, episodes=v, n_steps=5), "episodes={} is not allowed", 1),  # not a range (T24-11)
    "evaluate seed": (lambda v: evaluate(POLICY, MDP, seed=v, n_steps=5), "seed={} is not allowed", 3),
    "evaluate n_steps": (lambda v: evaluate(POLICY, MDP, n_steps=v), "n_steps={} is not allowed", 5),
    "run_test episodes": (
        lambda v: run_test(make_agent("baseline", FAMILY), FAMILY, MDP, episodes=v, n_steps=5),
        "episodes={} is not allowed",
        1,
    ),  # not a range (T24-11)
    "run_test seed": (lambda v: run_test(make_agent("baseline", FAMILY), FAMILY, MDP, episodes=1, seed=v, n_steps=5), "seed={} is not allowed", 3),
    "run_test n_steps": (lambda v: run_test(make_agent("baseline", FAMILY), FAMILY, MDP, episodes=1, n_steps=v), "n_steps={} is not allowed", 5),
    "HoverEnv episode_steps": (lambda v: HoverEnv(episode_steps=v), "episode_steps={} is not allowed", 20),
    "HoverEnv reset seed": (lambda v: HoverEnv(episode_steps=20).reset(seed=v), "seed={} is not allowed", 3),
    "HoverVectorEnv num_envs": (lambda v: HoverVectorEnv(num_envs=v, episode_steps=20), "num_envs={} is not allowed", 2),
    "HoverVectorEnv episode_steps": (lambda v: HoverVectorEnv(num_envs=2, episode_steps=v), "episode_steps={} is not allowed", 20),
    "HoverVectorEnv reset seed": (lambda v: HoverVectorEnv(num_envs=2, episode_steps=20).reset(seed=v), "seed={} is not allowed", 3),
    "HoverVectorEnv reset seeds": (lambda v: HoverVectorEnv(num_envs=2, episode_steps=20).reset(seed=[v, 1]), "seed=[{}, 1] is not allowed", 3),
    "gym.make episode_steps": (lambda v: gym.make("neurohover/GHH08-v0", episode_steps=v), "episode_steps={} is not allowed", 20),
    "gym.make reset seed": (lambda v: gym.make("neurohover/GHH08-v0", episode_steps=20).reset(seed=v), "seed={} is not allowed", 3),
    "plot_flight_data episodes": (lambda v: plot_flight_data(_flight(), OUT[0], episodes=[v]), "episode {} is not allowed", 0),
    "DangerousState box": (lambda v: DangerousState(box=v), "safeguard box={} is not allowed", 0.5),
    "DangerousState arm_after": (lambda v: DangerousState(arm_after=v), "safeguard arm_after={} is not allowed", 5),
    "Sensor velocity": (lambda v: Sensor(velocity=v), "sensor velocity={} is not a number", 0.5),
    "Sensor dropout": (lambda v: Sensor(dropout=v), "sensor dropout={} is not a number", 0.1),  # not a range (T33-B16)
    "Sensor delay": (lambda v: Sensor(delay=v), "sensor delay={} is not allowed", 2),  # not a range (T24-11)
    "Sensor.parse delay": (lambda v: Sensor.parse("position=0.1", delay=v), "sensor delay={} is not allowed", 2),  # 4 was taken as delay 4
    "Drift walk": (lambda v: Drift(walk=v), "drift walk={} is not a number", 0.1),
    "Drift change": (lambda v: Drift(change={"D_w": v}), "drift change D_w={} is not a number", 0.8),
    "Drift change_at": (lambda v: Drift(change={"D_w": 0.8}, change_at=(v, 5)), "drift change_at=({}, 5) is not allowed", 2),
}
OUT: list[Path] = []  # plot_flight_data's output directory, set by the test


@pytest.mark.slow
@pytest.mark.parametrize("time", TIMES, ids=["5s", "4-no-unit"])
@pytest.mark.parametrize("case", list(CASES))
def test_a_time_span_is_no_number(case: str, time: np.timedelta64, tmp_path: Path) -> None:
    """T17-1: a np.timedelta64 passed every ``isinstance(x, (int, np.integer))`` and ``numbers.Real`` check, then int() or
    float() of it was a TypeError traceback ('datetime.timedelta'), or np.timedelta64(4) (no unit) was taken as 4
    (episode_steps, seeds, num_envs, a drift's change_at)."""
    OUT[:] = [tmp_path]
    call, message, good = CASES[case]
    with pytest.raises(NeurohoverError, match="^" + re.escape(message.format(brief(time)))):
        call(time)
    call(good)  # the good input still works, a NumPy integer too
    if isinstance(good, int):
        call(np.int64(good))


@pytest.mark.parametrize("dtype", [np.float32("nan"), np.float32(1.0), np.zeros(2, dtype=np.float32)], ids=["nan", "number", "array"])
def test_a_value_is_no_dtype(dtype: object) -> None:
    """T17-7: HoverEnv(obs_dtype=np.float32('nan')) flew float32 observations: np.dtype() reads any value's .dtype, so a
    number or an array was taken as its dtype."""
    for make in (lambda **kw: HoverEnv(episode_steps=20, **kw), lambda **kw: HoverVectorEnv(num_envs=2, episode_steps=20, **kw)):
        for name in ("obs_dtype", "action_dtype"):
            with pytest.raises(NeurohoverError, match=re.escape(f"{name}={brief(dtype)} is not allowed: use 'float64' or 'float32'")):
                make(**{name: dtype})
    for good, dtype_out in (("float32", np.float32), (np.float32, np.float32), (np.dtype("float32"), np.float32), (float, np.float64)):
        env = HoverEnv(episode_steps=20, obs_dtype=good)
        assert env.observation_space.dtype == dtype_out and env.reset(seed=0)[0].dtype == dtype_out


@pytest.mark.parametrize("policy_dir", ["/nonexistent/dir", "5"])
def test_a_policy_dir_for_an_agent_without_a_policy_set_is_refused(policy_dir: str) -> None:
    """T17-8: make_agent('baseline', 'ghh08', policy_dir='/nonexistent/dir') returned a BaselineAgent, the directory ignored
    without a word (make_agent('generic', ...) named the missing set); check_agent (compete's check) ignored it too."""
    message = (
        f"policy_dir={policy_dir!r} is not allowed for agent 'baseline': it flies no policy set, so leave it out "
        "(a policy set's directory applies to every agent but baseline)"
    )
    with pytest.raises(NeurohoverError, match=re.escape(message)):
        make_agent("baseline", "ghh08", policy_dir=policy_dir)
    with pytest.raises(NeurohoverError, match=re.escape(message)):
        check_agent("baseline", FAMILY, policy_dir)
    assert type(make_agent("baseline", "ghh08", policy_dir=None)).__name__ == "BaselineAgent"  # the default, as the CLI passes it
    check_agent("baseline", FAMILY, None)
    with pytest.raises(NeurohoverError, match=re.escape("no policy set for ghh08 in ")):
        make_agent("generic", "ghh08", policy_dir="/nonexistent/dir")


@pytest.mark.parametrize(
    "make, field",
    [
        (lambda v: ContinualSettings(threshold=v), "threshold"),
        (lambda v: RiskSettings(level=v), "level"),
        (lambda v: SteadyStateSettings(mutation_floor=v), "mutation_floor"),
        (lambda v: nh.get_task_family("fghh", sigma=v), "sigma"),
    ],
    ids=["continual threshold", "risk level", "mutation_floor", "fghh sigma"],
)
def test_any_real_number_type_is_a_number(make: Callable[[object], object], field: str) -> None:
    """Settings that tested ``isinstance(x, (int, float))`` called np.float32(1.5) "out of range" or "not a number" (as the
    twelfth trial's U1 found for gamma); they now test errors.real_number, so a NumPy float is taken as its value and a
    time span is still refused."""
    assert getattr(make(np.float32(1.5 if field == "threshold" else 0.25)), field) == pytest.approx(1.5 if field == "threshold" else 0.25)
    with pytest.raises(NeurohoverError, match=re.escape(brief(np.timedelta64(4)))):
        make(np.timedelta64(4))
