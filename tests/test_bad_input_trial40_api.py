"""Bad-input trial 40, side B (the Python API): an agent's async or generator update was accepted and its body never ran
(T40-B04); a user TaskFamily named as a shipped family overwrote that family's wind kinds (T40-B01), and one with
contradictory class attributes failed only in rows() (T40-B15); a registered variant id lost its defining setting to
gym.make's kwargs (T40-B12); an MDP label took newlines (T40-B13); a drift walk too small to move a row (T40-B08) and a
CrashAwareReward scale that makes every reward a denormal (T40-B16) were accepted. Left from trial 39: a subclass of a
built-in agent whose own __init__ skipped its base class's failed with a bare AttributeError."""

from __future__ import annotations

from dataclasses import dataclass

import pytest

import neurohover as nh
from neurohover.agents import Agent, Choice, run_test
from neurohover.errors import NeurohoverError
from neurohover.sim.constants import ROW_PARAMS
from neurohover.tasks import MDP, TaskFamily

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


def test_a_user_family_may_not_take_a_shipped_familys_name():
    """T40-B01: a class named 'ghh08' replaced GHH-08's wind kinds as it was defined, and GHH-08's own windy MDPs were
    refused for the rest of the process; now the class is refused by name and GHH-08 is untouched."""
    ghh08 = nh.get_task_family("ghh08")
    for taken in ("ghh08", "model"):
        with pytest.raises(NeurohoverError, match=rf"^task family class Mine's name '{taken}' is not allowed: .* has it, .*give the family a name of its own"):

            @dataclass(frozen=True)
            class Mine(TaskFamily):
                name = taken
                n_params = 2

    assert ghh08.make([1, 2]).wind == (1.0, 2.0)
    assert MDP.from_dict(ghh08.mdp("train:1").to_dict()) == ghh08.mdp("train:1")


_NAMES = ("C_u", "C_v", "D_v", "C_w", "D_w", "C_p", "D_p", "C_q", "D_q", "C_r", "D_r")


@pytest.mark.parametrize(
    ("attributes", "message"),
    [
        ({"n_params": 20}, r"its n_params 20 is not allowed: it must be the number of its param_names, 11 \(C_u, "),
        ({"param_bounds": (1.0, -1.0)}, r"its param_bounds \(1.0, -1.0\) is not allowed: give \(low, high\), two finite numbers with low < high"),
        ({"row_slice": slice(0, 5)}, r"its row_slice slice\(0, 5, None\) is not allowed: give the slice of the"),
        ({"param_names": ("a",) * 11}, r"its param_names \('a', .* is not allowed: give a tuple of distinct non-empty texts"),
        ({"n_params": 0, "param_names": (), "row_slice": slice(0, 0)}, r"its n_params 0 is not allowed: give how many parameters make\(\) takes"),
        ({"wind_kind": 7}, r"its wind_kind 7 is not allowed: give 0 \(none\), 1 \(constant\) or 2 \(sinusoidal\)"),
    ],
)
def test_a_user_familys_contradictory_class_attributes_are_refused_as_it_is_defined(attributes, message):
    """T40-B15: n_params 20 beside 11 param_names, or param_bounds (1, -1), were taken; sample() and the fixed sets worked
    and only rows() refused. The class's own attributes are checked once, as it is defined; a consistent one passes."""
    base = {"name": "heavy40", "n_params": 11, "param_names": _NAMES, "row_slice": ROW_PARAMS}
    with pytest.raises(NeurohoverError, match=r"^task family class Heavy \('heavy40'\): " + message):
        type("Heavy", (TaskFamily,), {**base, **attributes})
    assert type("Heavy", (TaskFamily,), base).n_params == 11  # defined again: the same class, its name its own


def test_an_mdp_label_is_one_printable_line():
    """T40-B13: make(label='wind\\nrun 2') was taken and shown in an env's info['mdp'], though a Choice's label and an
    agent's name are refused so; MDP.from_dict refuses it too, and the labels neurohover writes load."""
    fam = nh.get_task_family("ghh08")
    for bad in ("wind\nrun 2", "a\tb", "  "):
        with pytest.raises(NeurohoverError, match=r"^MDP label=.* is not allowed: give a text \(one line, printable\) naming the MDP"):
            fam.make([1, 2], label=bad)
    d = fam.mdp("train:1").to_dict()
    with pytest.raises(NeurohoverError, match=r"^MDP label='x\\ny' is not allowed"):
        MDP.from_dict({**d, "label": "x\ny"})
    for mdp in (fam.make([1, 2]), fam.make([1, 2], label="wind run 2"), fam.zero(), fam.sample(0), nh.get_task_family("fghh").mdp("test:4")):
        assert MDP.from_dict(mdp.to_dict()).label == mdp.label
    assert MDP.from_dict({k: v for k, v in d.items() if k != "label"}).label == ""


@pytest.mark.parametrize(
    ("env_id", "kwargs", "key", "keeps"),
    [
        ("FGHH-DriftingDynamics", {"drift": None}, "drift=None", "a walk > 0"),
        ("FGHH-AbruptChange", {"drift": {"walk": 0.01}}, r"drift=\{'walk': 0.01\}", "a change"),
        ("GHH09-DelayedSensors", {"obs_delay": 0}, "obs_delay=0", "a delay > 0"),
        ("GHH09-NoisySensors", {"obs_noise": 0}, "obs_noise=0", "a noise level > 0"),
        ("GHH08-CorrelatedSensors", {"obs_noise": 1.0}, "obs_noise=1.0", "a noise level > 0 and a correlation > 0"),
    ],
)
def test_a_variant_ids_defining_setting_is_not_removed_by_make_kwargs(env_id, kwargs, key, keeps):
    """T40-B12: -DriftingDynamics with drift=None flew fixed dynamics, -DelayedSensors with obs_delay=0 exact sensors,
    without a word (another task= is refused for the same reason); a kwarg that keeps the setting is taken."""
    import gymnasium as gym

    name = env_id.split("-")[0]
    with pytest.raises(NeurohoverError, match=rf"^neurohover/{env_id}-v0 is {name} with .*: its {key} removes what defines the id, .*give .* with {keeps}"):
        gym.make(f"neurohover/{env_id}-v0", **kwargs)
    assert gym.make("neurohover/GHH09-DelayedSensors-v0", obs_delay=3).unwrapped.family.sensor.delay == 3
    assert gym.make("neurohover/FGHH-DriftingDynamics-v0", drift={"walk": 0.02}).unwrapped.drift.walk == 0.02
    assert gym.make("neurohover/GHH08-NoisySensors-v0", obs_delay=1).unwrapped.family.sensor.delay == 1


def test_a_drift_walk_too_small_to_move_a_parameter_is_refused():
    """T40-B08: walk=1e-300 (or 1e-320) was taken though every drifted row equalled the fixed one, while walk=0 is refused
    for that reason; a walk below float64's epsilon (exp(walk) == 1.0) is refused naming the range, the smallest allowed
    one moves the rows."""
    from neurohover.tasks.drift import MIN_WALK

    for bad in ("walk=1e-300", "walk=1e-320", "walk=1e-17"):
        with pytest.raises(NeurohoverError, match=r"^drift walk=1e-\d+ is out of range, too small to change the dynamics: allowed 0 \(none\) or .* 2.23e-16"):
            nh.Drift.parse(bad)
    with pytest.raises(NeurohoverError, match=r"^drift walk=5e-324 is out of range, too small"):
        nh.Drift.from_dict({"walk": 5e-324})
    row = nh.get_task_family("fghh").mdp("test:0").row()
    assert not (nh.Drift(MIN_WALK).rows(row, 5, 0) == row).all()
    assert nh.Drift().none and nh.Drift(0.0).none


def test_a_crash_aware_scale_that_makes_rewards_denormal_is_refused():
    """T40-B16: scale=5e-324 made every reward a denormal (-5e-324, -1e-323, -1e-323: steps alike) while scale=0 is
    refused; the wrapper and crash_aware refuse a scale below MIN_SCALE (1e-300) naming it and the range."""
    import gymnasium as gym

    from neurohover.wrappers import MIN_SCALE, CrashAwareReward, crash_aware

    allowed = r"is out of range: allowed a finite number > 0 and <= 1e\+300 \(.*\) and >= 1e-300 \(a smaller one makes rewards denormal floats"
    for scale in (5e-324, 1e-310, 1e-301):
        with pytest.raises(NeurohoverError, match=rf"^scale={scale!r} {allowed}"):
            crash_aware(-0.2, scale=scale)
        with pytest.raises(NeurohoverError, match=rf"^scale={scale!r} {allowed}"):
            CrashAwareReward(gym.make("neurohover/GHH08-Short-v0"), scale=scale)
    rewards = crash_aware([-0.2, -0.21, -1748.8 * 900, -1e-7], scale=MIN_SCALE)
    assert len(set(rewards.tolist())) == 4 and all(abs(r) >= 2.2250738585072014e-308 for r in rewards)


def test_a_subclass_of_a_built_in_agent_skipping_its_base_constructor_is_named():
    """Left from trial 39: a ModelFreeAgent subclass whose own __init__ never called ModelFreeAgent's was refused by a bare
    AttributeError ('Mine' object has no attribute 'specialised') from run_test's check of its arguments."""
    from neurohover.agents import ModelFreeAgent

    class Mine(ModelFreeAgent):
        def __init__(self, note: str = "x") -> None:
            self.note = note

    fam = nh.get_task_family("ghh08")
    with pytest.raises(NeurohoverError, match=r"agent 'model-free' has no attribute 'specialised'.*call super\(\)\.__init__\(\.\.\.\) in Mine\.__init__"):
        run_test(Mine(), fam, fam.mdp("test:1"), episodes=2, seed=0, n_steps=20)
