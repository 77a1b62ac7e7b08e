"""Bad input, trial 24, counts (T24-11): the count checks written by hand said "X=1.5 is out of range: allowed an integer
>= 1" for a non-integer (1.5, True, '2'); each now goes through errors.whole_in, which says "is not allowed" for a
non-integer and "is out of range" for an integer past the range, each with the allowed integers. Counts with no bound
of their own take int64's (2**63-1); the others keep theirs (a call's episodes, a competition's runs and episodes)."""

from __future__ import annotations

import importlib
import re
import sys
import types
from collections.abc import Callable

import numpy as np
import pytest

import neurohover as nh
from neurohover.agents.continual import ContinualSettings
from neurohover.agents.fghh_code import CodeAgentSettings
from neurohover.agents.model_based import IncrementalSettings, ModelEvolution
from neurohover.agents.protocol import EpisodeOutcome, run_test
from neurohover.agents.registry import make_agent
from neurohover.agents.risk import RiskSettings
from neurohover.compete import competition_config
from neurohover.errors import NeurohoverError, brief
from neurohover.evaluate import PolicyTable
from neurohover.evolution.eonn import EonnSettings
from neurohover.evolution.evolve import evolve, validation_return
from neurohover.experiments.wins import win_probabilities
from neurohover.flyer import KernelFlyer
from neurohover.integrations.flying import evaluate_callable
from neurohover.launch import Batch
from neurohover.tasks.sensor import Sensor

FAMILY = nh.get_task_family("ghh08")
MDP = FAMILY.mdp("test:0")
INT64 = "2**63-1"
HUGE = 10**30  # past every bound
RUNS = {"a": {"m": [1.0]}, "b": {"m": [2.0]}}


def _batch(n_steps: object) -> Batch:
    table = PolicyTable.from_policies([nh.baseline_policy()])
    one = np.zeros(1, dtype=np.int64)
    return Batch(MDP.row()[None, :], table.kinds, table.genomes, one, one, one, 3, n_steps)  # type: ignore[arg-type]


def _hover_problem(episodes: object) -> object:
    """HoverProblem(episodes=...): with EvoTorch and torch stood in for where they are not installed (the check runs
    before either is used); the module imported so is dropped afterwards (see the fixture)."""
    return importlib.import_module("neurohover.integrations.evotorch").HoverProblem(episodes=episodes)


#: entry point -> (call of the value, the name in its message, the lowest allowed, the allowed text after "in low..")
CASES: dict[str, tuple[Callable[[object], object], str, int, str]] = {
    "run_test episodes": (
        lambda v: run_test(make_agent("baseline", FAMILY), FAMILY, MDP, episodes=v, n_steps=5),
        "episodes",
        1,
        "100,000,000 (episodes in one call)",
    ),
    "validation_return episodes": (
        lambda v: validation_return(nh.baseline_policy(), MDP, episodes=v, n_steps=5),
        "episodes",
        1,
        "100,000,000 (episodes in one call)",
    ),
    "EpisodeOutcome episode": (lambda v: EpisodeOutcome(v, -1.0, False, 20, -1, None), "EpisodeOutcome episode", 0, INT64),  # type: ignore[arg-type]
    "EpisodeOutcome steps": (lambda v: EpisodeOutcome(0, -1.0, False, v, -1, None), "EpisodeOutcome steps", 1, "10000000"),  # type: ignore[arg-type]  # T27-B10: 1..MAX_EPISODE_STEPS
    "EpisodeOutcome safeguard_step": (lambda v: EpisodeOutcome(0, -1.0, False, 20, v, None), "EpisodeOutcome safeguard_step", -1, INT64),  # type: ignore[arg-type]
    "Agent.choose episode": (lambda v: make_agent("baseline", FAMILY).choose(v), "episode", 0, INT64),  # type: ignore[arg-type]
    "continual window": (lambda v: ContinualSettings(window=v), "continual window", 1, INT64),  # type: ignore[arg-type]
    "continual patience": (lambda v: ContinualSettings(patience=v), "continual patience", 1, INT64),  # type: ignore[arg-type]
    "continual max_learning_episodes": (lambda v: ContinualSettings(max_learning_episodes=v), "continual max_learning_episodes", 1, INT64),  # type: ignore[arg-type]
    "continual cooldown": (lambda v: ContinualSettings(cooldown=v), "continual cooldown", 0, "1000000 (episodes)"),  # type: ignore[arg-type]
    "ModelEvolution authors_generations": (lambda v: ModelEvolution(authors_generations=v), "authors_generations", 1, INT64),  # type: ignore[arg-type]
    "incremental max_learning_episodes": (lambda v: IncrementalSettings(max_learning_episodes=v), "max_learning_episodes", 1, INT64),  # type: ignore[arg-type]
    "compete runs": (lambda v: competition_config("ghh08", "baseline", runs=v, episodes=2), "runs", 1, "100,000"),  # type: ignore[arg-type]
    "compete episodes": (lambda v: competition_config("ghh08", "baseline", runs=1, episodes=v), "episodes", 1, "100,000,000"),  # type: ignore[arg-type]
    "evaluate_callable episodes": (
        lambda v: evaluate_callable(lambda obs: np.zeros((len(obs), 4)), MDP, episodes=v, n_steps=5),  # type: ignore[arg-type]
        "episodes",
        1,
        "65536 (episodes x MDPs <= 65536)",
    ),
    "HoverProblem episodes": (_hover_problem, "episodes", 1, "100,000,000 (solutions x episodes in one call)"),
    "win_probabilities n_runs": (lambda v: win_probabilities(RUNS, n_runs=v, draws=2), "n_runs", 1, "50,000,000 (draws x n_runs)"),  # type: ignore[arg-type]
    "win_probabilities draws": (lambda v: win_probabilities(RUNS, n_runs=1, draws=v), "draws", 1, "50,000,000 (draws x n_runs)"),  # type: ignore[arg-type]
    "CodeAgentSettings evolutions": (lambda v: CodeAgentSettings(evolutions=v), "evolutions", 1, INT64),  # type: ignore[arg-type]
    "CodeAgentSettings model_budget": (lambda v: CodeAgentSettings(model_budget=v), "model_budget", 50, INT64),  # type: ignore[arg-type]
    "EonnSettings pop_size": (lambda v: EonnSettings(pop_size=v), "pop_size", 2, "100,000"),  # type: ignore[arg-type]  # evolve's (T50-B04)
    "EonnSettings generations": (lambda v: EonnSettings(generations=v), "generations", 1, "10,000,000,000"),  # type: ignore[arg-type]  # MAX_BUDGET
    "RiskSettings trials": (lambda v: RiskSettings(trials=v), "risk trials", 1, "1,000,000"),  # type: ignore[arg-type]
    "MDP substeps": (lambda v: nh.MDP.from_dict({**MDP.to_dict(), "substeps": v}), "MDP substeps", 1, "1000"),
    "Sensor delay": (lambda v: Sensor(delay=v), "sensor delay", 0, "10 (control steps)"),  # type: ignore[arg-type]
    "Batch n_steps": (_batch, "n_steps", 1, "10000000"),
    "KernelFlyer n_steps": (lambda v: KernelFlyer("slp", 0, v), "n_steps", 1, "10000000"),  # type: ignore[arg-type]
    "evolve budget": (lambda v: evolve(MDP, budget=v, n_steps=5), "budget", 1, "10,000,000,000 (episodes)"),  # type: ignore[arg-type]
    "evolve n_steps": (lambda v: evolve(MDP, budget=2, n_steps=v), "n_steps", 1, "10000000"),  # type: ignore[arg-type]
}


@pytest.fixture(autouse=True)
def _evotorch_stand_in(monkeypatch: pytest.MonkeyPatch) -> None:
    """Where EvoTorch (or torch) is not installed, stand-ins named as they are, for HoverProblem's argument checks only;
    neurohover.integrations.evotorch imported over them is dropped again after the test (monkeypatch.setitem)."""
    try:
        import evotorch  # noqa: F401
    except ImportError:
        problem = type("Problem", (), {"__init__": lambda self, *args, **kwargs: None})
        monkeypatch.setitem(sys.modules, "torch", types.SimpleNamespace(float64="float64", Tensor=object))
        monkeypatch.setitem(sys.modules, "evotorch", types.SimpleNamespace(Problem=problem, SolutionBatch=object))
        name = "neurohover.integrations.evotorch"
        monkeypatch.setitem(sys.modules, name, types.ModuleType(name))  # restored (or removed) after the test
        del sys.modules[name]
        monkeypatch.setattr(sys.modules["neurohover.integrations"], "evotorch", None, raising=False)


@pytest.mark.parametrize("bad", [1.5, True, "2"], ids=repr)
@pytest.mark.parametrize("case", list(CASES))
def test_a_non_integer_count_is_not_allowed(case: str, bad: object) -> None:
    """T24-11: 1.5, True or '2' said "is out of range: allowed an integer >= 1" (a type problem called a range one)."""
    call, name, low, high = CASES[case]
    with pytest.raises(NeurohoverError, match="^" + re.escape(f"{name}={brief(bad)} is not allowed: allowed an integer in {low}..{high}") + "$"):
        call(bad)


@pytest.mark.parametrize("where", ["below", "huge"])
@pytest.mark.parametrize("case", list(CASES))
def test_an_integer_past_the_range_is_out_of_range(case: str, where: str) -> None:
    """T24-11: an integer below the range (0 for most) or past it (10**30) is "out of range", with the allowed integers."""
    call, name, low, high = CASES[case]
    bad = low - 1 if where == "below" else HUGE
    message = f"{name}={brief(bad)} is out of range: allowed an integer in {low}..{high}"
    if case.startswith("compete") and where == "huge":  # its bound names both counts, as before (tests/test_bad_input.py)
        runs, episodes = (HUGE, 2) if case == "compete runs" else (1, HUGE)
        message = f"runs={runs} x episodes={episodes} is out of range: at most 100,000 runs and 100,000,000 episodes in all"
    with pytest.raises(NeurohoverError, match="^" + re.escape(message)):
        call(bad)


def test_an_agent_setting_given_on_the_command_line_says_the_same(cli) -> None:
    """T24-11 on the command line: a continual agent's window=1.5 is refused with status 2, in one line, no traceback."""
    rc, _, err = cli("compete", "--task", "ghh08", "--agent", "continual", "--agent-setting", "window=1.5", "--runs", "1", "--episodes", "1", "--out", "unused")
    assert rc == 2 and "continual window=1.5 is not allowed: allowed an integer in 1..2**63-1" in err and "Traceback" not in err, err
