"""Thirty-seventh bad-input trial, helper B (Python API): T37-B01 (a byte-swapped obs_dtype / action_dtype is refused by
name), T37-B06 (an instance of an MDP subclass is refused naming its class, not as "its  differ from ... ()"), T37-B09
(a finished run whose budget is below one population resumes with its own budget, API and CLI), T37-B10 (np.longdouble
values past float64's range give no "overflow encountered in cast" warning), T37-B11 (an evaluate_callable act of the
wrong arity is named with what ``indexed`` asks) and T37-B12 (obs_delay=2.0 and Drift change_at=(5.0, 5.0) are refused
as Sensor(delay=2.0) is: one rule for whole-number settings)."""

from __future__ import annotations

import dataclasses
import json
import re
import warnings

import gymnasium as gym
import numpy as np
import pytest

import neurohover as nh
from neurohover.envs.vector import HoverVectorEnv
from neurohover.errors import NeurohoverError
from neurohover.evolution import evolve
from neurohover.integrations.flying import evaluate_callable

GHH08 = nh.get_task_family("ghh08")
BIG = np.longdouble("1e400")  # past float64's range (1.8e308)


# --------------------------------------------------------------------------- T37-B01: byte order


@pytest.mark.parametrize(
    "make",
    [
        lambda: gym.make("neurohover/GHH08-v0", obs_dtype=">f8"),
        lambda: gym.make("neurohover/GHH08-v0", action_dtype=">f4"),
        lambda: HoverVectorEnv(2, obs_dtype=np.dtype(">f4")),
        lambda: HoverVectorEnv(2, action_dtype=">f8"),
        lambda: evaluate_callable(lambda o: np.zeros((len(o), 4)), GHH08.zero(), n_steps=1, obs_dtype=">f4"),
    ],
)
def test_a_byte_swapped_dtype_is_refused(make) -> None:
    """T37-B01: '>f8' passed as 'float64' and every observation came back byte-swapped, which PyTorch refuses."""
    with pytest.raises(NeurohoverError, match=r"dtype='>f[48]'|dtype=dtype\('>f[48]'\)") as err:
        make()
    assert "byte order is not this machine's; use 'float64' or 'float32' (native byte order)" in str(err.value)


def test_native_dtypes_spelt_any_way_are_taken() -> None:
    """T37-B01: '<f8' on a little-endian machine and '=f4' are native: taken, observations native."""
    native = "<f8" if np.little_endian else ">f8"
    for dtype, name in ((native, "float64"), ("=f4", "float32"), (np.float32, "float32")):
        env = gym.make("neurohover/GHH08-v0", obs_dtype=dtype)
        obs, _ = env.reset(seed=0)
        assert obs.dtype.name == name and obs.dtype.isnative


# --------------------------------------------------------------------------- T37-B06: MDP subclasses


def test_an_mdp_subclass_instance_is_refused_naming_its_class() -> None:
    """T37-B06: its message was "its  differ from every ghh08 MDP's ()": the dataclass == compares classes."""

    class MyMDP(nh.MDP):
        pass

    zero = GHH08.zero()
    with pytest.raises(NeurohoverError, match=r"MDP 'ghh08/zero' is not allowed: it is a 'MyMDP' \(a subclass of neurohover.MDP\)") as err:
        MyMDP(**{f.name: getattr(zero, f.name) for f in dataclasses.fields(zero)})
    assert "a subclass of neurohover.MDP" in str(err.value) and "give neurohover.MDP(" in str(err.value)
    assert "differ" not in str(err.value)


# --------------------------------------------------------------------------- T37-B09: resuming a finished run


def test_a_finished_run_below_one_population_resumes_with_its_own_budget(tmp_path, cli) -> None:
    """T37-B09: budget 10 flew 50 (its first population); the same call resumed was refused as a lowered budget."""
    mdp, ckpt = GHH08.mdp("train:0"), tmp_path / "ck.json"
    first = evolve(mdp, topology="slp", budget=10, seed=0, n_steps=20, checkpoint=ckpt)
    assert first.episodes > 10 and first.stop_reason == "budget"
    again = evolve(mdp, topology="slp", budget=10, seed=0, n_steps=20, checkpoint=ckpt, resume=True)
    assert (again.episodes, again.stop_reason, again.champion_return) == (first.episodes, "budget", first.champion_return)
    with pytest.raises(NeurohoverError, match=rf"budget 5 is below the {first.episodes} episodes .*give at least {first.episodes}, or its own budget, 10"):
        evolve(mdp, topology="slp", budget=5, seed=0, n_steps=20, checkpoint=ckpt, resume=True)
    out = str(tmp_path / "e.json")
    args = ("evolve", "--task", "ghh08", "--mdp", "train:0", "--budget", "10", "--seed", "1", "--episode-steps", "20", "--out", out)
    rc, _, err = cli(*args)
    assert rc == 0, err
    flown = json.loads((tmp_path / "e.json").read_text())["episodes"]
    rc, _, err = cli(*args, "--resume")
    assert rc == 0 and "below" not in err, err
    assert json.loads((tmp_path / "e.json").read_text())["episodes"] == flown


# --------------------------------------------------------------------------- T37-B10: longdouble past float64's range


def _quietly(call):
    """``call()``'s result (or its NeurohoverError) with every warning an error."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        try:
            return call()
        except NeurohoverError as err:
            return err


def test_longdouble_past_float64_gives_no_overflow_warning() -> None:
    """T37-B10: NumPy's 'overflow encountered in cast' leaked from the genome, Policy.act, env steps and evaluate_callable."""
    genome = nh.baseline_policy().genome.astype(np.longdouble)
    genome[0] = BIG
    assert "genes [0] are not" in str(_quietly(lambda: nh.Policy("slp", genome)))
    assert "give 12 finite numbers" in str(_quietly(lambda: nh.baseline_policy().act(np.full(12, BIG))))
    venv = HoverVectorEnv(2, episode_steps=5)
    venv.reset(seed=0)
    _, _, terminated, _, _ = _quietly(lambda: venv.step(np.full((2, 4), BIG)))
    inf = HoverVectorEnv(2, episode_steps=5)  # flown as the inf it is, as an inf action is
    inf.reset(seed=0)
    assert np.array_equal(terminated, inf.step(np.full((2, 4), np.inf))[2])
    env = gym.make("neurohover/GHH08-v0", episode_steps=5)
    env.reset(seed=0)
    _quietly(lambda: env.step(np.full(4, BIG)))
    ev = _quietly(lambda: evaluate_callable(lambda o: np.full((len(o), 4), BIG), GHH08.zero(), n_steps=2))
    assert ev.returns.shape == (1, 1)


# --------------------------------------------------------------------------- T37-B11: evaluate_callable's act arity


@pytest.mark.parametrize(
    ("act", "indexed", "signature"),
    [(lambda obs, k: np.zeros((len(obs), 4)), False, "(obs, k)"), (lambda obs: np.zeros((len(obs), 4)), True, "(obs)"), (lambda: 0, False, "()")],
)
def test_an_act_of_the_wrong_arity_is_named(act, indexed, signature) -> None:
    """T37-B11: a bare TypeError ("<lambda>() missing 1 required positional argument: 'k'") that named neither act nor indexed."""
    with pytest.raises(
        NeurohoverError, match=rf"act '<lambda>' of signature '{re.escape(signature)}' is not allowed: indexed={indexed} calls it as act\(observations"
    ):
        evaluate_callable(act, GHH08.zero(), n_steps=2, indexed=indexed)


def test_an_act_without_a_readable_signature_is_named_at_its_first_call() -> None:
    """T37-B11: where inspect reads no signature, the TypeError of the first call is named so."""

    class Act:
        __signature__ = "unreadable"  # inspect.signature raises TypeError

        def __call__(self, obs):
            return np.zeros((len(obs), 4))

    with pytest.raises(
        NeurohoverError, match=r"act 'Act' is not allowed: indexed=True calls it as act\(observations, indices\).*its first call raised TypeError"
    ):
        evaluate_callable(Act(), GHH08.zero(), n_steps=2, indexed=True)
    assert evaluate_callable(Act(), GHH08.zero(), n_steps=2).returns.shape == (1, 1)


# --------------------------------------------------------------------------- T37-B12: whole-number settings


@pytest.mark.parametrize(
    ("make", "message"),
    [
        (lambda: gym.make("neurohover/GHH08-v0", obs_delay=2.0), "obs_delay=2.0 is not allowed: give a whole number of control steps in 0..10"),
        (lambda: HoverVectorEnv(2, obs_delay=np.float64(2.0)), "obs_delay=np.float64(2.0) is not allowed: give a whole number"),
        (lambda: nh.Sensor.parse("level=1", delay=2.0), "sensor delay=2.0 is not allowed: give a whole number of control steps in 0..10"),
        (lambda: nh.Drift(change=(("D_w", 0.8),), change_at=(5.0, 5.0)), "drift change_at=(5.0, 5.0) is not allowed: give two episode numbers"),
        (lambda: nh.Sensor(delay=2.0), "sensor delay=2.0 is not allowed"),  # the rule these now follow (whole_in)
    ],
)
def test_integral_floats_are_refused_by_every_whole_number_setting(make, message) -> None:
    """T37-B12: obs_delay=2.0 and change_at=(5.0, 5.0) were taken while Sensor(delay=2.0) was refused."""
    with pytest.raises(NeurohoverError, match=re.escape(message)):
        make()


def test_numpy_integers_stay_whole_numbers() -> None:
    """T37-B12: the rule is whole_number's: NumPy integers are taken."""
    assert gym.make("neurohover/GHH08-v0", obs_delay=np.int64(2)).unwrapped.family.sensor.delay == 2
    assert nh.Drift(change=(("D_w", 0.8),), change_at=np.array([5, 6])).change_at == (5, 6)
    assert nh.Sensor.parse("level=1", delay=np.int8(3)).delay == 3
