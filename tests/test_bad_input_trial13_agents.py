"""The thirteenth trial's findings in agents and integrations (F11, F12, F13, F19): each bad argument gives one
NeurohoverError naming it and what is allowed; in-range NumPy scalars are taken as plain ones."""

from __future__ import annotations

import numpy as np
import pytest

from neurohover import get_task_family
from neurohover.agents.protocol import Agent, Choice, EpisodeOutcome, run_test
from neurohover.errors import NeurohoverError
from neurohover.policies import baseline_policy


@pytest.fixture(scope="module")
def family():
    return get_task_family("ghh08")


def test_agents_refuse_a_generic_or_specialised_that_is_no_policy() -> None:
    """F11/F12: GenericAgent(None) was an AttributeError 'topology' deep in evaluate, ModelFreeAgent(None) a TypeError from len()."""
    from neurohover.agents.model_free import ModelFreeAgent
    from neurohover.agents.reference import GenericAgent

    with pytest.raises(NeurohoverError, match=r"generic=None is not allowed: give a Policy"):
        GenericAgent(None)  # type: ignore[arg-type]
    with pytest.raises(NeurohoverError, match=r"specialised=None is not allowed: give a list of at least one Policy"):
        ModelFreeAgent(None)  # type: ignore[arg-type]
    with pytest.raises(NeurohoverError, match=r"specialised=Policy\(.* is not allowed: give a list"):
        ModelFreeAgent(baseline_policy())  # type: ignore[arg-type]


def test_run_test_refuses_a_choose_that_returns_no_choice(family) -> None:
    """F11: an agent whose choose returned a Policy was an AttributeError "'Policy' object has no attribute 'final'"."""

    class PolicyNotChoice(Agent):
        name = "hand-written"

        def choose(self, episode):
            return baseline_policy()

        def update(self, outcome):
            pass

    with pytest.raises(NeurohoverError, match=r"agent 'hand-written' chose Policy\(.* for episode 0: its choose must return a Choice"):
        run_test(PolicyNotChoice(), family, family.test_mdps()[0], episodes=3, n_steps=20)


@pytest.mark.parametrize(
    ("kwargs", "fragment"),
    [
        ({"label": 5}, "Choice label=5 is not allowed: give a non-empty text"),
        ({"label": ""}, "Choice label='' is not allowed: give a non-empty text"),
        ({"label": "x", "final": True, "repeat": True}, "Choice final=True with repeat=True is not allowed"),
        ({"label": "x", "record": "yes"}, "Choice record='yes' is not allowed: give True or False"),
        ({"label": "x", "fallback": "baseline"}, "Choice fallback='baseline' is not allowed: give a Policy or None"),
    ],
)
def test_a_choice_checks_itself(kwargs, fragment) -> None:
    """F11: Choice(policy, 5) put 5 in the run's records, '' and final with repeat were taken, record='yes' spoke of arrays and jobs."""
    with pytest.raises(NeurohoverError) as err:
        Choice(baseline_policy(), **kwargs)
    assert fragment in str(err.value)


def test_a_choice_takes_numpy_flags() -> None:
    """F11: a NumPy bool is a flag like True."""
    assert Choice(baseline_policy(), "x", record=np.bool_(True)).record is True


def test_episode_outcome_checks_itself() -> None:
    """F12: EpisodeOutcome('a', 'b', ...) was made, then taken by some agents and a TypeError in others."""
    # a type, not a range; no bound but int64's (T24-11: whole_in)
    with pytest.raises(NeurohoverError, match=r"EpisodeOutcome episode='a' is not allowed: allowed an integer in 0..2\*\*63-1"):
        EpisodeOutcome("a", "b", "c", "d", "e", "f")  # type: ignore[arg-type]
    with pytest.raises(NeurohoverError, match=r"EpisodeOutcome ret='x' is not allowed: give the episode's return, a finite number"):
        EpisodeOutcome(0, "x", False, 20, -1, None)  # type: ignore[arg-type]
    outcome = EpisodeOutcome(np.int64(0), np.float32(-1.0), np.bool_(False), np.int64(20), -1, None)  # type: ignore[arg-type]
    assert outcome.episode == 0


@pytest.mark.parametrize("name", ["model-free", "model-based", "hybrid", "continual", "incremental", "model-free-risk"])
def test_every_agent_checks_its_protocol_arguments(name, family) -> None:
    """F12: update(None) was an AttributeError in every agent, choose('x') a TypeError, choose(-1) 'specialised:9', start(None, None) taken."""
    from neurohover.agents.registry import make_agent

    agent = make_agent(name, family)
    with pytest.raises(NeurohoverError, match=r"family=None is not allowed: give a TaskFamily"):
        agent.start(None, None)  # type: ignore[arg-type]
    agent.start(family, np.random.default_rng(0))
    with pytest.raises(NeurohoverError, match=r"outcome=None is not allowed: give an EpisodeOutcome"):
        agent.update(None)  # type: ignore[arg-type]
    for bad, problem in ((-1, "is out of range"), ("x", "is not allowed"), (1.5, "is not allowed")):  # a type is no range (T24-11)
        with pytest.raises(NeurohoverError, match=rf"episode={bad!r} {problem}: allowed an integer in 0..2\*\*63-1"):
            agent.choose(bad)  # type: ignore[arg-type]
    assert isinstance(agent.choose(np.int64(0)), Choice)


def test_an_outcome_without_the_flight_data_asked_for_is_refused(family) -> None:
    """F12: the incremental agent's update of an outcome with no flight data after it chose to record was a bare AssertionError."""
    from neurohover.agents.registry import make_agent

    agent = make_agent("incremental", family)
    agent.start(family, np.random.default_rng(0))
    agent.choose(0)
    with pytest.raises(NeurohoverError, match=r"outcome of episode 7 has no flight data, but agent 'incremental' chose to record it"):
        agent.update(EpisodeOutcome(7, -1.0, False, 20, -1, None))


@pytest.mark.parametrize("bad", [None, 5, b"x.zip"])
def test_integrations_refuse_a_path_that_is_no_path(bad) -> None:
    """F13: sb3_policy(None), rl_zoo_files(None), rl_zoo_policy(None), cleanrl_files(None), cleanrl_policy(None) were pathlib's TypeError."""
    pytest.importorskip("stable_baselines3")
    from neurohover.integrations import cleanrl, sb3

    shown = repr(bad)
    for call, fragment in [
        (sb3.sb3_policy, f"model_zip={shown} is not allowed: give a MODEL.zip file path"),
        (sb3.rl_zoo_files, f"run={shown} is not allowed: give a path of an RL Zoo run folder"),
        (sb3.rl_zoo_policy, f"run={shown} is not allowed: give a path of an RL Zoo run folder"),
        (cleanrl.cleanrl_files, f"run={shown} is not allowed: give a path of a CleanRL run folder"),
    ]:
        with pytest.raises(NeurohoverError) as err:
            call(bad)
        assert fragment in str(err.value)


def test_cleanrl_policy_refuses_a_path_that_is_no_path() -> None:
    """F13: cleanrl_policy(None) was pathlib's TypeError."""
    pytest.importorskip("torch")
    from neurohover.integrations import cleanrl

    with pytest.raises(NeurohoverError, match=r"run=None is not allowed: give a path of a CleanRL run folder"):
        cleanrl.cleanrl_policy(None)  # type: ignore[arg-type]


def test_sb3_refuses_an_algo_that_is_no_name(tmp_path) -> None:
    """F13: algo=['ppo'] and algo={} were a TypeError "unhashable type"; RecurrentPolicy(None) an AttributeError at its first step."""
    pytest.importorskip("stable_baselines3")
    from neurohover.integrations import sb3

    (tmp_path / "empty.zip").write_bytes(b"")
    with pytest.raises(NeurohoverError, match=r"algo=\['ppo'\] is not supported: allowed ppo, "):
        sb3.sb3_policy(tmp_path / "empty.zip", algo=["ppo"])  # type: ignore[arg-type]
    with pytest.raises(NeurohoverError, match=r"algo=\{\} is not supported: allowed ppo, "):
        sb3.rl_zoo_files(tmp_path, algo={})  # type: ignore[arg-type]
    with pytest.raises(NeurohoverError, match=r"model=None is not allowed: give a recurrent Stable-Baselines3 model"):
        sb3.RecurrentPolicy(None)


@pytest.fixture(scope="module")
def neat_result():
    pytest.importorskip("neat")
    from neurohover.integrations import neat as N

    return N.evolve_topology(get_task_family("ghh08").zero(), budget=150, n_steps=20)


@pytest.mark.parametrize("obs", [np.zeros(12), np.zeros((2, 5)), "x", np.full((1, 12), np.nan)])
def test_a_neat_result_refuses_observations_as_policy_act_does(neat_result, obs) -> None:
    """F19: r.act(np.zeros(12)) and (2, 5) were an IndexError, 'x' a ValueError, and NaN observations flew to [[1, 1, 1, 1]]."""
    shapes = r"(of shape \(12,\)|of shape \(2, 5\)|'x'|of shape \(1, 12\) holding NaN or inf)"
    with pytest.raises(NeurohoverError, match=rf"observations {shapes} are not allowed: give a \(B, 12\) array of finite numbers"):
        neat_result.act(obs)
    assert neat_result.act(np.zeros((2, 12))).shape == (2, 4)


def test_neat_records_and_forward_refuse_what_is_no_record(neat_result) -> None:
    """F19: network_of_record([]) was an IndexError, (None) a TypeError; genome_record(None), forward(None, ...) an AttributeError."""
    from neurohover.integrations import neat as N

    for bad in ([], None):
        with pytest.raises(NeurohoverError, match=r"record=.* is not allowed: give a genome_record \(a non-empty list of finite numbers\)"):
            N.network_of_record(bad)  # type: ignore[arg-type]
    with pytest.raises(NeurohoverError, match=r"genome=None is not allowed: give a neat-python genome"):
        N.genome_record(None)
    with pytest.raises(NeurohoverError, match=r"packed=None is not allowed: give PackedNetworks"):
        N.forward(None, np.zeros(1, dtype=np.int64), np.zeros((1, 12)))  # type: ignore[arg-type]
    packed = N.network_of_record(N.genome_record(neat_result.champion))
    with pytest.raises(NeurohoverError, match=r"net_of_row=array\(\[1\]\) is not allowed: give one network index 0..0 per observation row \(1\)"):
        N.forward(packed, np.ones(1, dtype=np.int64), np.zeros((1, 12)))
    assert np.array_equal(N.forward(packed, np.zeros(2, dtype=np.int64), np.zeros((2, 12))), neat_result.act(np.zeros((2, 12))))
