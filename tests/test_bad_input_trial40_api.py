"""Bad-input trial 40, side B (the Python API): an agent's async or generator update was accepted and its body never ran
(T40-B04); a user TaskFamily named as a shipped family overwrote that family's wind kinds (T40-B01), and one with
contradictory class attributes failed only in rows() (T40-B15); a registered variant id lost its defining setting to
gym.make's kwargs (T40-B12); an MDP label took newlines (T40-B13); a drift walk too small to move a row (T40-B08) and a
CrashAwareReward scale that makes every reward a denormal (T40-B16) were accepted."""

from __future__ import annotations

import pytest

import neurohover as nh
from neurohover.agents import Agent, Choice, run_test
from neurohover.errors import NeurohoverError

P = nh.baseline_policy()
FAM = nh.get_task_family("ghh08")


class _Learner(Agent):
    name = "learner"

    def choose(self, episode):
        return Choice(P, "baseline")

    def update(self, outcome):
        pass


class _AsyncUpdate(_Learner):
    async def update(self, outcome):
        pass


class _GeneratorUpdate(_Learner):
    def update(self, outcome):
        yield outcome


class _AsyncGeneratorStart(_Learner):
    async def start(self, family, rng):
        yield family


class _StaticGeneratorChoose(_Learner):
    @staticmethod
    def choose(episode):
        yield Choice(P, "baseline")


@pytest.mark.parametrize(
    ("cls", "method", "kind"),
    [
        (_AsyncUpdate, "update", "an async def function"),
        (_GeneratorUpdate, "update", r"a generator function \(yield in its body\)"),
        (_AsyncGeneratorStart, "start", "an async generator function"),
        (_StaticGeneratorChoose, "choose", r"a generator function \(yield in its body\)"),
    ],
)
def test_an_agents_async_or_generator_method_is_refused_before_the_run(cls, method, kind):
    """T40-B04: an async or generator update was called, made a coroutine or generator and never ran its body (the run
    went on without a word); every method of the protocol, as a class defines it or an instance holds it, is refused."""
    agent = cls()
    with pytest.raises(NeurohoverError, match=rf"^agent class {cls.__name__}'s {method}, {kind}, is not allowed: its call only makes"):
        run_test(agent, FAM, FAM.zero(), episodes=2, n_steps=20)
    plain = _Learner()

    async def update(outcome):
        pass

    plain.update = update
    with pytest.raises(NeurohoverError, match=r"^agent 'learner''s update, an async def function, is not allowed"):
        run_test(plain, FAM, FAM.zero(), episodes=2, n_steps=20)
    assert run_test(_Learner(), FAM, FAM.zero(), episodes=2, n_steps=20).policy == ["baseline", "baseline"]
