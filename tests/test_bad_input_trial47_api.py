"""Bad input, trial 47 (Python API): AgentSpec.build without the policies it needs (T47-B01), check_agent_settings'
n_steps (T47-B02), check_episode_count's count (T47-B04), refuse_drift of no MDP (T47-B05), a NumPy array where a name
is wanted (T47-B06), the vector env's mdp as an array of names (T47-B14) and a policy-set manifest without its safe
list for the hybrid agents (T47-B17)."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import neurohover  # noqa: F401  # registers the envs
import neurohover.compete as C
import neurohover.tasks as T
from neurohover.agents.registry import AgentOptions, AgentPolicies, agent_spec, entry_problem, make_agent
from neurohover.errors import NeurohoverError
from neurohover.evaluate import MAX_EPISODES_PER_CALL, check_episode_count
from neurohover.models import WindModel
from tests.store_edits import edited_policy_set

_NEED_GENERIC = ("generic", "hybrid", "continual", "model-based", "incremental", "incremental-race", "authors-race")


@pytest.mark.parametrize("agent", _NEED_GENERIC)
def test_build_without_its_generic_is_refused_by_name(agent) -> None:
    # T47-B01: a bare AssertionError (a NeurohoverError only under python -O)
    with pytest.raises(NeurohoverError, match=r"generic=None is not allowed: give a Policy"):
        agent_spec(agent).build(AgentPolicies(), AgentOptions())


@pytest.mark.parametrize(
    ("n_steps", "text"),
    [("zz", "is not allowed"), (float("nan"), "is not allowed"), (True, "is not allowed"), (10**30, "is out of range"), (-1, "is out of range")],
)
def test_agent_settings_n_steps_is_checked(n_steps, text) -> None:
    # T47-B02: 'zz' was a TypeError, NaN, True and 10**30 were taken, -1 blamed safeguard_after
    with pytest.raises(NeurohoverError, match=rf"^n_steps=.* {text}: allowed an integer in 1\.\."):
        C.check_agent_settings("continual", {}, n_steps=n_steps)
    assert C.check_agent_settings("continual", {}, n_steps=np.int64(6000)) == C.check_agent_settings("continual", {}, n_steps=6000)


@pytest.mark.parametrize("n", ["5", None, 2.5, -3, np.array([1, 2]), True])
def test_episode_count_must_be_a_count(n) -> None:
    # T47-B04: '5' and None were TypeErrors, arrays NumPy's ValueError, 2.5 and -3 taken
    with pytest.raises(NeurohoverError, match=r"^episodes: its episode count .* is not allowed: give a whole number of episodes"):
        check_episode_count(n, "episodes")
    check_episode_count(0, "episodes")
    check_episode_count(np.int32(5), "episodes")
    with pytest.raises(NeurohoverError, match="is out of range"):
        check_episode_count(MAX_EPISODES_PER_CALL + 1, "episodes")


@pytest.mark.parametrize("mdp", ["train:1", None, 5, [1], np.zeros(3)])
def test_refuse_drift_of_no_mdp_is_refused_by_name(mdp) -> None:
    # T47-B05: an AttributeError 'str' object has no attribute 'drift'
    with pytest.raises(NeurohoverError, match=r"^mdp=.* is not allowed: give an MDP or a task family"):
        T.refuse_drift(mdp, "here")
    fam = T.get_task_family("ghh08")
    T.refuse_drift(fam, "here")
    T.refuse_drift(fam.zero(), "here")


def test_an_array_where_a_name_is_wanted_is_refused_as_a_list_is() -> None:
    # T47-B06: NumPy's "truth value of an array ... is ambiguous"
    for family in (np.array(["ghh08", "x"]), np.array(["ghh08"]), ["ghh08"]):
        with pytest.raises(NeurohoverError, match="the competition data file lists no MDPs of"):
            T.competition_rows(family)
    for key in (np.array(["a", "b"]), ["incremental"]):
        assert "is not its key" in entry_problem(key, agent_spec("incremental"))
    for kind in (np.array(["none", "x"]), ["none"]):
        with pytest.raises(NeurohoverError, match=r"^wind model .* is not allowed: choose one of"):
            WindModel(kind=kind)


def _vec(**kwargs):
    return gym.make_vec("neurohover/GHH08-v0", num_envs=2, vectorization_mode="vector_entry_point", episode_steps=20, **kwargs)


def test_vector_env_takes_an_array_of_mdp_names() -> None:
    # T47-B14: refused as no name, while the list was taken and the docstring says "a sequence of num_envs of these"
    names = ["train:1", "zero"]
    env = _vec()
    env.reset(seed=0, options={"mdp": np.array(names)})
    from_array = env.mdp_specs
    env.reset(seed=0, options={"mdp": names})
    assert env.mdp_specs == from_array
    made = _vec(mdp=np.array(names))
    assert [getattr(s, "label", s) for s in made.mdp_specs] == [getattr(s, "label", s) for s in from_array]
    with pytest.raises(NeurohoverError, match=r"has 3 entries but there are num_envs=2"):
        env.reset(seed=0, options={"mdp": np.array([*names, "zero"])})
    with pytest.raises(NeurohoverError, match=r"or a sequence of num_envs=2 of these"):
        env.reset(seed=0, options={"mdp": 5})
    with pytest.raises(NeurohoverError, match=r"or a sequence of num_envs=2 of these"):
        env.reset(seed=0, options={"mdp": np.array([names, names])})  # 2-D: no sequence of names


def test_hybrid_on_a_manifest_without_safe_says_it_has_none(tmp_path) -> None:
    # T47-B17: "safe=[] is not allowed", a value the file does not hold
    pd = edited_policy_set(tmp_path, "ghh08", lambda m: m.pop("safe"))
    for agent in ("hybrid", "hybrid-baseline", "hybrid-risk"):
        with pytest.raises(NeurohoverError, match=r"manifest\.json' has no 'safe' list, which agent .* needs") as info:
            make_agent(agent, "ghh08", policy_dir=str(pd))
        assert "safe=[]" not in str(info.value)
    make_agent("generic", "ghh08", policy_dir=str(pd))  # the set still loads for the agents that fly no safe policies
