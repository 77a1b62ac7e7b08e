"""Bad input of the thirty-fifth trial, helper B, in the Python API: T35-B01 (a PolicyTable's arrays written after
its padding check), T35-B02 (an Agent subclass without update or choose), T35-B03 (a safeguard armed at or past the
episode's end), T35-B07 (compare_agent on FGHH MDPs of another sigma than the shipped generic's) and T35-B08
(CrashAwareReward's scale past which a crash's reward is -inf)."""

from __future__ import annotations

import re
import warnings

import numpy as np
import pytest

import neurohover as nh
from neurohover.agents import Agent, Choice, run_test
from neurohover.errors import NeurohoverError
from neurohover.evaluate import DangerousState, PolicyTable, Safeguard
from neurohover.integrations.flying import compare_agent
from neurohover.wrappers import MAX_SCALE, CrashAwareReward, crash_aware


def test_policy_table_arrays_are_read_only_and_the_callers_stay_writable() -> None:
    """T35-B01: ``T.kinds[1] = 0`` made an MLP row an SLP after the T33-B10 padding check (-14,020, its genes 40 and 41
    unread, without a word)."""
    table = PolicyTable.from_policies([nh.baseline_policy(), nh.prototype("mlp", "baseline")])
    for made in (table, PolicyTable.from_genomes(np.zeros((2, 40)), "slp")):
        with pytest.raises(ValueError, match="read-only"):
            made.kinds[0] = 1
        with pytest.raises(ValueError, match="read-only"):
            made.genomes[0, 41] = 1.0
    kinds, genomes = np.zeros(2, dtype=np.int64), np.zeros((2, 42))
    built = PolicyTable(kinds, genomes)  # the caller's arrays: copied, not frozen
    assert kinds.flags.writeable and genomes.flags.writeable and not np.shares_memory(kinds, built.kinds)
    genomes[0, 41] = 1.0
    assert built.genomes[0, 41] == 0.0 and PolicyTable(built.kinds, built.genomes) == built
    mdp = nh.get_task_family("ghh09").training_mdps()[0]
    ev = nh.evaluate_jobs(table, mdp, [1], [0], [0], seed=0, n_steps=10)  # flown through the kernel's writable copies
    assert ev.returns[0] == nh.evaluate(nh.prototype("mlp", "baseline"), mdp, episodes=1, seed=0, n_steps=10).returns.ravel()[0]


class _OnlyChoose(Agent):
    name = "only-choose"

    def choose(self, episode):
        return Choice(nh.baseline_policy(), "baseline")


class _OnlyUpdate(Agent):
    def update(self, outcome):
        pass


@pytest.mark.parametrize(("agent", "method"), [(_OnlyChoose, "update"), (_OnlyUpdate, "choose")])
def test_an_agent_without_update_or_choose_is_named(agent, method) -> None:
    """T35-B02: an agent without update ended episode 0 in a bare NotImplementedError."""
    family = nh.get_task_family("ghh08")
    wanted = rf"agent class {agent.__name__} does not define {method}, which is not allowed: an Agent subclass implements both choose"
    with pytest.raises(NeurohoverError, match=wanted):
        run_test(agent(), family, family.test_mdps()[0], episodes=2, seed=0, n_steps=20)
    with pytest.raises(NeurohoverError, match=wanted):  # called by hand, the base method says the same
        getattr(agent(), method)(0)


def test_a_safeguard_armed_at_or_past_the_episode_end_is_refused() -> None:
    """T35-B03: DangerousState(arm_after=6000 or 10**6) flew 6000-step episodes, the safeguard never armed."""
    family = nh.get_task_family("ghh08")
    mdp = family.training_mdps()[0]
    fly = lambda arm: nh.evaluate(  # noqa: E731
        nh.prototype("mlp", "zero"), mdp, episodes=1, seed=0, n_steps=20, safeguard=Safeguard(nh.baseline_policy(), DangerousState(rule="paper", arm_after=arm))
    )
    assert fly(19).returns.shape == (1, 1, 1)  # the last step can still hand over
    for arm in (20, 10**6):
        with pytest.raises(
            NeurohoverError, match=rf"safeguard arm_after={arm} is not below the episode's 20 control steps \(n_steps\): .* give arm_after below 20"
        ):
            fly(arm)

    class Late(Agent):
        def choose(self, episode):
            return Choice(nh.baseline_policy(), "b", fallback=nh.baseline_policy(), dangerous=DangerousState(arm_after=20))

        def update(self, outcome):
            pass

    with pytest.raises(NeurohoverError, match="safeguard arm_after=20 is not below the episode's 20 control steps"):
        run_test(Late(), family, family.test_mdps()[0], episodes=1, seed=0, n_steps=20)


def test_compare_agent_refuses_the_shipped_generic_at_another_sigma() -> None:
    """T35-B07: compare_agent on FGHH MDPs of sigma 0.5 flew the sigma-0.3 generic as their generic, without a word."""
    other = nh.get_task_family("fghh", sigma=0.5).training_mdps()[:1]
    with pytest.raises(
        NeurohoverError, match=re.escape("mdps 'fghh/seeded-train:0' is not allowed with the shipped fghh generic: it is no fghh MDP of sigma = 0.3")
    ):
        compare_agent(nh.baseline_policy(), other, n_steps=10)
    rows = compare_agent(nh.baseline_policy(), other, n_steps=10, generic=nh.prototype("mlp", "baseline"))  # a generic of one's own
    assert [r.name for r in rows] == ["agent", "baseline", "generic"]
    shipped = nh.get_task_family("fghh").training_mdps()[:1]
    assert [r.name for r in compare_agent(nh.baseline_policy(), shipped, n_steps=10)] == ["agent", "baseline", "generic"]


def test_crash_aware_scale_is_bounded_so_a_crash_stays_finite() -> None:
    """T35-B08: scale=1e308 passed "a finite number > 0" and crash rewards were -inf with an overflow warning."""
    import gymnasium as gym

    with pytest.raises(NeurohoverError, match=re.escape("scale=1e+308 is out of range: allowed a finite number > 0 and <= 1e+300")):
        CrashAwareReward(gym.make("neurohover/GHH08-Short-v0"), scale=1e308)
    with pytest.raises(NeurohoverError, match=re.escape("scale=1e+308 is out of range")):
        crash_aware(-2e7, scale=1e308)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert np.isfinite(crash_aware(-1e7 * 2e3, gamma=1.0, scale=MAX_SCALE))  # 10**7 steps' charge, at the bound
        with pytest.raises(NeurohoverError, match="past the largest float; give a crash charge of at most 10,000,000 steps"):
            crash_aware(-1e300, gamma=1.0, scale=MAX_SCALE)
