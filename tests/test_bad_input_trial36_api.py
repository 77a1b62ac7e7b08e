"""Thirty-sixth bad-input trial, helper B (Python API): T36-B02 (a rendered rgb_array environment pickles and deep-copies),
T36-B03 (deleting an environment's setting is refused by name), T36-B04 (a second tell() of a batch, or an ask() while a
tell() runs, is AskTellOrderError in every population optimiser, not pycma's RuntimeError), T36-B06 (evaluate_callable and
compare_agent fly a learned model's MDP), T36-B09 (a family's make() takes a Fraction), T36-B10 (a Policy of a reloaded
neurohover.policies is refused by its true cause) and T36-B11 (a user's own gym id takes a task= override)."""

from __future__ import annotations

import copy
import importlib
import pickle
import sys
from decimal import Decimal
from fractions import Fraction

import gymnasium as gym
import numpy as np
import pytest

import neurohover as nh
from neurohover.errors import NeurohoverError
from neurohover.evolution import CMAES
from neurohover.evolution.common import AskTellOrderError
from neurohover.evolution.optimisers.openai_es import OpenAIES
from neurohover.evolution.optimisers.uh_cma import UHCMAES, UHCMASettings
from neurohover.integrations.flying import compare_agent, evaluate_callable
from neurohover.models import LearnedModel

GHH08 = nh.get_task_family("ghh08")


# --------------------------------------------------------------------------- T36-B02, T36-B03: environments


def _rendered_env():
    env = gym.make("neurohover/GHH08-v0", render_mode="rgb_array")
    env.reset(seed=1)
    env.step(np.zeros(4))
    env.render()
    return env


@pytest.mark.slow
@pytest.mark.parametrize("how", ["pickle", "deepcopy"])
def test_a_rendered_env_copies_and_the_copy_continues_exactly(how) -> None:
    """T36-B02: after one render() pickle and deepcopy failed inside matplotlib (its BufferRegion is not picklable)."""
    env = _rendered_env()
    twin = pickle.loads(pickle.dumps(env)) if how == "pickle" else copy.deepcopy(env)
    assert twin.unwrapped._renderer is None and env.unwrapped._renderer is not None  # the copy makes its own
    action = np.full(4, 0.01)
    for _ in range(3):
        a, b = env.step(action), twin.step(action)
        assert np.array_equal(a[0], b[0]) and a[1:4] == b[1:4]
    frame, copied = env.render(), twin.render()
    assert copied.shape == frame.shape == (340, 720, 3) and np.array_equal(copied, frame)
    env.close()
    twin.close()


@pytest.mark.parametrize("name", ["episode_steps", "family", "mdp", "task"])
def test_deleting_a_setting_is_refused_as_setting_one_is(name) -> None:
    """T36-B03: ``del env.unwrapped.episode_steps`` was a bare AttributeError '__delete__'."""
    env = gym.make("neurohover/GHH08-v0").unwrapped
    with pytest.raises(NeurohoverError, match=rf"^del {name} is not allowed: an environment's {name} is fixed when it is made"):
        delattr(env, name)
    assert env.episode_steps == 6000 and env.family.name == "ghh08"
    vec = gym.make_vec("neurohover/GHH08-v0", num_envs=2).unwrapped
    with pytest.raises(NeurohoverError, match=r"^del episode_steps is not allowed"):
        del vec.episode_steps


# --------------------------------------------------------------------------- T36-B04: ask/tell order


def _optimisers():
    genome = nh.baseline_policy().genome
    return [
        CMAES(genome, seed=0),
        UHCMAES(genome, UHCMASettings(), seed=0),
        OpenAIES(genome, seed=0),
    ]


@pytest.mark.parametrize("index", [0, 1, 2], ids=["cma", "uh-cma", "openai-es"])
def test_a_tell_or_ask_while_a_tell_runs_is_ask_tell_order_error(index) -> None:
    """T36-B04: a second tell() of a batch reaching the update while the first ran (a thread sharing a CMAES) was
    pycma's RuntimeError 'tell can currently only be called once per iteration'. The other thread's calls are made
    here from inside the update, deterministically."""
    opt = _optimisers()[index]
    X = opt.ask()
    fitness = -np.abs(X).sum(1)
    update, seen = opt._tell, []

    def meanwhile(*args) -> None:
        for call in (lambda: opt.tell(fitness), opt.ask):
            with pytest.raises(AskTellOrderError, match="another ask\\(\\) or tell\\(\\) of this optimiser is running") as err:
                call()
            seen.append(err.value)
        update(*args)

    opt._tell = meanwhile
    opt.tell(fitness)
    del opt._tell
    assert len(seen) == 2 and all(isinstance(e, (NeurohoverError, RuntimeError)) for e in seen)
    assert "_busy" not in opt.__dict__ and opt.evaluations == X.shape[0]
    with pytest.raises(AskTellOrderError, match=r"tell\(\) called without a pending ask\(\)"):
        opt.tell(fitness)  # a second tell in one thread: the package's error, as before
    Y = opt.ask()
    assert np.array_equal(opt.ask(), Y)  # asked again before a tell: the same batch (documented)


def test_the_guard_leaves_results_and_state_as_they_were() -> None:
    """T36-B04: the guard changes no single-thread result, and the state a CMAES saves is the same kind as before."""
    a, b = CMAES(nh.baseline_policy().genome, seed=3), CMAES(nh.baseline_policy().genome, seed=3)
    for _ in range(3):
        X = a.ask()
        a.tell(-np.abs(X).sum(1))
    c = CMAES.from_state_dict(a.state_dict())
    for _ in range(3):
        Y = b.ask()
        b.tell(-np.abs(Y).sum(1))
    assert np.array_equal(a.mean, b.mean) and np.array_equal(c.ask(), b.ask())


def test_a_failed_tell_keeps_the_batch_to_tell() -> None:
    """T36-B04: a tell() refused for its returns leaves the batch pending and the optimiser free."""
    opt = CMAES(nh.baseline_policy().genome, seed=0)
    X = opt.ask()
    with pytest.raises(NeurohoverError):
        opt.tell(np.zeros(X.shape[0] + 1))
    opt.tell(-np.abs(X).sum(1))
    assert opt.evaluations == X.shape[0]


# --------------------------------------------------------------------------- T36-B06: a learned model's MDP


@pytest.fixture(scope="module")
def model_mdp():
    return LearnedModel(GHH08.zero().params, (0.0,) * 6, "lr").mdp()


def test_evaluate_callable_flies_a_model_mdp_as_evaluate_does(model_mdp) -> None:
    """T36-B06: evaluate_callable refused a learned model's MDP as not "of one task family", while evaluate flew it."""
    P = nh.baseline_policy()

    def act(obs):
        return np.array([P.act(o) for o in obs])

    m = GHH08.mdp("train:3")
    for mdps in (model_mdp, [model_mdp], [m, model_mdp]):
        flown = evaluate_callable(act, mdps, n_steps=10, obs_dtype="float64")
        assert np.allclose(flown.returns, nh.evaluate(P, mdps, n_steps=10).returns[0])
    with pytest.raises(NeurohoverError, match=r"one task family \(got ghh08, ghh09\): a learned model's MDP flies beside any"):
        evaluate_callable(act, [m, model_mdp, nh.get_task_family("ghh09").mdp("zero")], n_steps=10)


def test_compare_agent_on_model_mdps_asks_for_the_generic_row(model_mdp) -> None:
    """T36-B06: compare_agent flies a model's MDP; alone, models' MDPs are of no task, so the generic row is the caller's."""
    P = nh.baseline_policy()
    with pytest.raises(NeurohoverError, match=r"^generic=None is not allowed beside mdps of learned models only .*give generic="):
        compare_agent(P, model_mdp, n_steps=10)
    rows = compare_agent(P, model_mdp, n_steps=10, generic=P)
    assert [r.name for r in rows] == ["agent", "baseline", "generic"] and len({r.return_per_episode for r in rows}) == 1
    mixed = compare_agent(P, [GHH08.mdp("train:0"), model_mdp], n_steps=10)  # beside a ghh08 MDP: ghh08's generic
    assert mixed[0].episodes == 2


# --------------------------------------------------------------------------- T36-B09: make() of a Fraction


def test_make_takes_a_fraction_as_every_float_setting_does() -> None:
    """T36-B09: GHH08.make([Fraction(1, 3), 0]) was "must be 2 finite numbers"; Decimal stays refused, as elsewhere."""
    assert GHH08.make([Fraction(1, 3), 0]) == GHH08.make([1 / 3, 0])
    ghh09 = nh.get_task_family("ghh09")
    params = [Fraction(1, 10), 0.5, 0, 0, 0, 0, 0, 0]
    assert ghh09.make(params).wind == ghh09.make([float(v) for v in params]).wind
    assert nh.get_task_family("fghh").make([Fraction(p) for p in GHH08.zero().params]).params == GHH08.zero().params
    for bad in ([Decimal("0.1"), 0], [10**400, 0], [None, 0], [Fraction(1, 3), [1]]):
        with pytest.raises(NeurohoverError, match=r"GHH-08 wind \(wind_u, wind_v\) must be 2 finite numbers"):
            GHH08.make(bad)
    with pytest.raises(NeurohoverError, match="out of range"):
        GHH08.make([Fraction(11, 2), 0])


# --------------------------------------------------------------------------- T36-B10: a reloaded neurohover.policies


def test_a_policy_of_a_reloaded_policies_module_is_refused_by_its_cause() -> None:
    """T36-B10: after importlib.reload(neurohover.policies) an earlier Policy was refused as one with "an act of its own",
    and a fresh one as no Policy. Both are refused as of another import; the module's first contents are put back."""
    module = sys.modules["neurohover.policies"]
    earlier, m = nh.baseline_policy(), GHH08.mdp("train:0")
    saved = dict(module.__dict__)
    try:
        importlib.reload(module)
        fresh = module.baseline_policy()
        for given in (earlier, [earlier], fresh, [fresh]):
            with pytest.raises(NeurohoverError, match=r"a Policy of another import of neurohover\.policies \(the module was reloaded\?\)"):
                nh.evaluate(given, m, n_steps=10)
    finally:
        module.__dict__.clear()
        module.__dict__.update(saved)
    assert nh.evaluate(earlier, m, n_steps=10).returns.shape == (1, 1, 1)


# --------------------------------------------------------------------------- T36-B11: a user's own gym id


def test_a_users_own_id_takes_a_task_override() -> None:
    """T36-B11: a user's id with kwargs task='ghh08' refused make(id, task='ghh09'), suggesting "()"; neurohover's ids
    still refuse another task, and the message names no empty list."""
    gym.register("t36b11/Hover-v0", entry_point="neurohover.envs:HoverEnv", kwargs={"task": "ghh08"}, max_episode_steps=6000)
    gym.register("neurohover/T36B11-v0", entry_point="neurohover.envs:HoverEnv", kwargs={"task": "ghh08"}, max_episode_steps=6000)
    try:
        env = gym.make("t36b11/Hover-v0", task="ghh09")
        assert env.unwrapped.family.name == "ghh09" and env.reset(seed=0)[1]["mdp_info"]["family"] == "ghh09"
        with pytest.raises(NeurohoverError, match=r"conflicts with it; make a ghh09 id instead$"):
            gym.make("neurohover/T36B11-v0", task="ghh09")
        with pytest.raises(NeurohoverError, match=r"make a ghh09 id instead \(neurohover/GHH09-v0"):
            gym.make("neurohover/GHH08-v0", task="ghh09")
    finally:
        del gym.registry["t36b11/Hover-v0"], gym.registry["neurohover/T36B11-v0"]
