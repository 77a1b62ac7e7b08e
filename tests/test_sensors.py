"""Noisy and late sensors (neurohover.tasks.sensor): kernel, reference, environments, CLI and configs."""

from __future__ import annotations

import json
import re

import gymnasium as gym
import numpy as np
import pytest
from cuda_sim import run_simulated

from neurohover import NeurohoverError, Policy, baseline_policy, evaluate_jobs, get_task_family
from neurohover.envs import SENSOR_ENV_IDS
from neurohover.envs.hover import HoverEnv
from neurohover.envs.vector import HoverVectorEnv
from neurohover.launch import use_lanes
from neurohover.sim.constants import ROW_SENSOR
from neurohover.sim.lanes import LANES
from neurohover.sim.reference import fly_episode
from neurohover.sim.rng import episode_normals, sensor_normals
from neurohover.tasks import MDP, Sensor

SEED, EPISODE = 11, 5
CORRELATED = Sensor(0.2, 0.3, 0.1, 0.02, correlation=0.9)


def open_loop() -> Policy:
    """Actions that do not depend on what the policy sees (an SLP of biases only): the trajectory ignores the sensors."""
    g = np.zeros(40)
    g[36:40] = baseline_policy().genome[36:40]
    return Policy("slp", g)


def fly(mdp: MDP, policy: Policy, n_steps: int = 300, episodes=(EPISODE,)):
    n = len(episodes)
    return evaluate_jobs([policy], [mdp], [0] * n, [0] * n, list(episodes), seed=SEED, record=[True] * n, n_steps=n_steps)


# -- the sensor model's settings -----------------------------------------------------------


def test_exact_sensor_is_the_default_and_leaves_rows_and_dicts_as_they_were() -> None:
    mdp = get_task_family("ghh09").mdp("train:3")
    assert mdp.sensor == Sensor() and mdp.sensor.exact
    assert not mdp.row()[ROW_SENSOR].any()
    assert "sensor" not in mdp.to_dict()  # older dicts (and the store's unit params) read the same
    noisy = mdp.with_sensor(CORRELATED)
    assert noisy != mdp and MDP.from_dict(noisy.to_dict()) == noisy
    assert noisy.row()[ROW_SENSOR].tolist() == [0.2, 0.3, 0.1, 0.02, 0.9, 0.0, 0.0]


@pytest.mark.parametrize(
    ("make", "message"),
    [
        (lambda: Sensor(velocity=-0.1), "velocity=-0.1 is out of range"),
        (lambda: Sensor(correlation=1.0), "correlation=1.0 is out of range"),
        (lambda: Sensor(delay=11), "delay=11 is out of range"),
        (lambda: Sensor(delay=1.5), "delay=1.5 is not allowed"),  # type: ignore[arg-type]  # a type, not a range (T24-11)
        (lambda: Sensor.parse("foo=1"), "'foo=1' is not understood"),
        (lambda: Sensor.parse("position=abc"), "needs a number"),
        (lambda: Sensor.at_level(-1), "level=-1 is out of range"),
        (lambda: Sensor(velocity=1e300), "velocity=1e+300 is out of range: allowed a std in 0..100"),  # bad-input trial: was accepted
        (lambda: Sensor.parse("1e9"), "level=1000000000.0 is out of range: allowed a number in 0..1000"),
        (lambda: Sensor.parse("velocity=0.1,,position=0.1"), "has an empty setting between commas"),  # was ignored (second trial)
        (lambda: Sensor.parse("velocity=\u0661"), "give numbers in ASCII digits"),
        (lambda: Sensor.from_dict({"levle": 1}), "unknown sensor setting"),
        (lambda: Sensor.of(Sensor(delay=3), 2), "conflicts"),
        (lambda: get_task_family("ghh08").with_sensor("noisy"), "must be a neurohover Sensor"),  # type: ignore[arg-type]
    ],
)
def test_bad_sensor_settings_get_one_clear_message(make, message: str) -> None:
    with pytest.raises(NeurohoverError, match=re.escape(message)):
        make()


def test_numpy_numbers_are_numbers_and_text_is_not() -> None:
    """Second trial: np.float32(0.1) and np.int64(3) were refused as out of range, '0.1' as out of range too."""
    assert Sensor(velocity=np.float32(0.5), delay=np.int64(3)) == Sensor(velocity=0.5, delay=3)  # type: ignore[arg-type]
    with pytest.raises(NeurohoverError, match="sensor velocity='0.1' is not a number"):
        Sensor(velocity="0.1")  # type: ignore[arg-type]


def test_a_dropout_is_read_from_text_and_tables_and_left_out_of_dicts_without_one() -> None:
    sensor = Sensor.parse("level=1,dropout=0.2", delay=1)
    assert sensor == Sensor(0.1, 0.1, 0.1, 0.01, delay=1, dropout=0.2) and Sensor.from_dict(sensor.to_dict()) == sensor
    assert sensor.row_values()[-1] == 0.2 and Sensor.from_row_values(sensor.row_values()) == sensor
    assert "dropout" not in Sensor.at_level(1.0).to_dict()  # the store's unit params of sensors before it read the same
    assert not Sensor(dropout=0.2).exact
    for bad in (1.0, -0.1, float("nan"), True):  # True is refused for its type: "not a number" (T33-B16)
        with pytest.raises(NeurohoverError, match="dropout=.* is (out of range|not a number): allowed a probability 0 <= dropout < 1"):
            Sensor(dropout=bad)


def test_sensor_text_and_levels() -> None:
    assert Sensor.parse("0.5") == Sensor.at_level(0.5) == Sensor(0.05, 0.05, 0.05, 0.005)
    assert Sensor.parse("level=1,position=0.3,correlation=0.9", delay=2) == Sensor(0.1, 0.3, 0.1, 0.01, 0.9, 2)
    assert Sensor.of(None, 2) == Sensor(delay=2) and Sensor.of({"level": 1}, None) == Sensor.at_level(1)


def test_a_family_seen_through_a_sensor_puts_it_on_every_mdp_it_makes() -> None:
    plain = get_task_family("fghh")
    family = plain.with_sensor(CORRELATED)
    assert family != plain and hash(family) != hash(plain) and family == get_task_family("fghh", sensor=CORRELATED)
    assert plain.training_mdps()[0].sensor.exact  # the plain family's cached sets are untouched
    made = [family.zero(), family.make(np.ones(11)), family.sample(0), family.training_mdps()[4], family.mdp("seeded-test:7")]
    assert all(m.sensor == CORRELATED for m in made)
    rows = family.sample_rows(np.random.default_rng(0), 3)
    assert (rows[:, ROW_SENSOR] == CORRELATED.row_values()).all()
    assert family.training_mdps()[4].params == plain.training_mdps()[4].params  # the same MDPs, other sensors
    assert "sensor=Sensor(" in repr(family) and "sensor" not in repr(plain)


@pytest.mark.parametrize(("slot", "value", "message"), [(5, 12, "delay=12 is out of range"), (5, -1, "delay=-1 is out of range"), (4, 1.0, "correlation=1.0")])
def test_kernel_refuses_raw_rows_with_an_invalid_sensor_model(slot: int, value: float, message: str) -> None:
    rows = np.repeat(get_task_family("ghh08").mdp("train:0").row()[None, :], 2, axis=0)
    rows[1, ROW_SENSOR.start + slot] = value  # beyond the ring buffer, before the reset, or noise that never settles
    with pytest.raises(NeurohoverError, match=f"MDP row 1 has an invalid sensor model .*{message}"):
        evaluate_jobs([baseline_policy()], rows, [0], [0], [0], n_steps=10)


# -- the kernel against the reference simulator, and what the sensors may not change -------


@pytest.mark.parametrize(
    "sensor",
    [
        Sensor.at_level(1.0),
        CORRELATED,
        Sensor.at_level(0.5, correlation=0.5, delay=3),
        Sensor(delay=10),
        Sensor(dropout=0.3),
        Sensor(0.1, 0.1, 0.1, 0.01, correlation=0.8, delay=2, dropout=0.5),
    ],
)
def test_kernel_agrees_with_the_reference_simulator_under_sensor_noise(sensor: Sensor) -> None:
    mdp = get_task_family("ghh09").training_mdps()[2].with_sensor(sensor)
    n = 300
    ev = fly(mdp, baseline_policy(), n)
    ref_return, ref_crash, ref_readings = fly_episode(
        mdp.to_reference(),
        baseline_policy().act,
        episode_normals(np.uint64(SEED), np.uint64(EPISODE), n).tolist(),
        n,
        sensor_normals(np.uint64(SEED), np.uint64(EPISODE), n + 1, per_reading=13 if sensor.dropout else 12).tolist(),
    )
    readings = ev.flight_data.observations[0]
    assert bool(ev.crashed[0]) == ref_crash and readings.shape == (len(ref_readings), 12)
    assert ev.returns[0] == pytest.approx(ref_return, rel=1e-9)
    np.testing.assert_allclose(readings, ref_readings, rtol=0, atol=1e-9)


def test_sensor_noise_never_changes_the_gusts_the_reward_or_the_crash_test() -> None:
    # Actions that ignore the readings fly the same trajectory, so everything but the readings must match.
    mdp = get_task_family("ghh08").mdp("train:1")
    exact = fly(mdp, open_loop(), 200, episodes=range(8))
    noisy = fly(mdp.with_sensor(Sensor.at_level(3.0, correlation=0.8, delay=4)), open_loop(), 200, episodes=range(8))
    assert np.array_equal(exact.returns, noisy.returns) and np.array_equal(exact.steps, noisy.steps)
    assert all(np.array_equal(a, b) for a, b in zip(exact.flight_data.actions, noisy.flight_data.actions))
    assert not np.allclose(exact.flight_data.observations[0], noisy.flight_data.observations[0])


def test_a_delay_shifts_the_readings_by_that_many_steps() -> None:
    mdp = get_task_family("ghh08").mdp("train:1")
    true_obs = fly(mdp, open_loop(), 100).flight_data.observations[0]
    late = fly(mdp.with_sensor(Sensor(delay=3)), open_loop(), 100).flight_data.observations[0]
    expected = np.concatenate([np.repeat(true_obs[:1], 3, axis=0), true_obs[:-3]])
    assert np.array_equal(late, expected)


def test_a_dropout_loses_the_stated_share_of_readings_and_holds_the_last_one() -> None:
    """Each reading after the reset's is lost with probability p: the policy sees the one delivered last again."""
    mdp = get_task_family("ghh08").mdp("train:1")
    episodes = range(20)
    exact = fly(mdp, open_loop(), 150, episodes).flight_data.observations
    dropped = fly(mdp.with_sensor(Sensor(dropout=0.3)), open_loop(), 150, episodes).flight_data.observations
    held = []
    for true_obs, seen in zip(exact, dropped):
        assert np.array_equal(seen[0], true_obs[0])  # the reset's reading always arrives
        fresh = np.all(seen == true_obs, axis=1)  # exact sensors otherwise: a reading either arrives or is a repeat
        repeat = np.r_[False, np.all(seen[1:] == seen[:-1], axis=1)]
        assert np.all(fresh | repeat)
        held.append(~fresh[1:])
    assert np.mean(np.concatenate(held)) == pytest.approx(0.3, abs=0.03)  # 3,000 readings: std of the share 0.008


def test_the_noise_has_the_stated_std_and_correlation() -> None:
    mdp = get_task_family("ghh08").mdp("train:1")
    sensor = Sensor(0.2, 0.4, 0.1, 0.02, correlation=0.7)
    episodes = range(40)
    exact = fly(mdp, open_loop(), 150, episodes).flight_data.observations
    noisy = fly(mdp.with_sensor(sensor), open_loop(), 150, episodes).flight_data.observations
    e = np.concatenate([n - x for n, x in zip(noisy, exact)])  # (readings, 12), in episode order
    stds = e.std(axis=0).reshape(4, 3).mean(axis=1)
    np.testing.assert_allclose(stds, sensor.stds, rtol=0.06)
    lagged = np.concatenate([(n - x)[1:] for n, x in zip(noisy, exact)])
    lead = np.concatenate([(n - x)[:-1] for n, x in zip(noisy, exact)])
    rho = (lagged * lead).sum(axis=0) / (lead * lead).sum(axis=0)
    np.testing.assert_allclose(rho, 0.7, atol=0.04)


def test_sensing_batches_fly_in_the_lanes_with_the_scalar_kernels_results() -> None:
    family = get_task_family("fghh").with_sensor(Sensor.at_level(1.0, correlation=0.8, delay=2))
    rows = family.sample_rows(np.random.default_rng(0), 3)
    n = 2 * LANES + 1
    idx = np.arange(n) % 3
    assert use_lanes("cpu", rows, idx)
    lanes = evaluate_jobs([baseline_policy()], rows, [0] * n, idx, range(n), seed=2, n_steps=400)
    scalar = evaluate_jobs([baseline_policy()], rows, [0] * n, idx, range(n), seed=2, n_steps=400, record=[True] + [False] * (n - 1))
    assert np.array_equal(lanes.returns, scalar.returns) and np.array_equal(lanes.steps, scalar.steps)


def test_safeguard_sees_the_readings() -> None:
    # Position readings far outside the paper's box fire the safeguard at once, though the true state is at rest.
    from neurohover import evaluate
    from neurohover.evaluate import DangerousState, Safeguard

    mdp = get_task_family("ghh08").mdp("zero")
    guard = Safeguard(baseline_policy(), DangerousState(rule="paper"))
    calm = evaluate(baseline_policy(), mdp, episodes=4, seed=1, n_steps=50, safeguard=guard)
    loud = evaluate(baseline_policy(), mdp.with_sensor(Sensor(position=5.0)), episodes=4, seed=1, n_steps=50, safeguard=guard)
    assert (calm.safeguard_step.ravel() != 0).all() and (loud.safeguard_step.ravel() == 0).all()


# -- the environments ------------------------------------------------------------------------


@pytest.mark.parametrize("kwargs", [{"obs_noise": 1.0}, {"obs_noise": {"level": 2, "correlation": 0.9}, "obs_delay": 3}])
def test_environments_return_the_readings_the_kernel_records(kwargs: dict) -> None:
    policy = baseline_policy()
    env = HoverEnv(task="ghh09", mdp="train:1", episode_steps=200, **kwargs)
    obs, _ = env.reset(seed=3)
    seen, done = [obs], False
    while not done:
        obs, _, terminated, truncated, _ = env.step(policy.act(obs))
        seen.append(obs)
        done = terminated or truncated
    seed, episode = env.noise_stream
    ev = evaluate_jobs([policy], [env.mdp], [0], [0], [episode], seed=seed, record=[True], n_steps=200)
    np.testing.assert_allclose(np.asarray(seen), ev.flight_data.observations[0], rtol=0, atol=1e-12)
    assert env.episode_return == pytest.approx(ev.returns[0], rel=1e-12)

    vec = HoverVectorEnv(2, task="ghh09", mdp="train:1", episode_steps=200, **kwargs)
    obs, _ = vec.reset(options={"noise": [(seed, episode)] * 2})
    first = [obs[0]]
    for _ in range(len(seen) - 1):
        obs, *_ = vec.step(np.stack([policy.act(o) for o in obs]))
        first.append(obs[0])
    np.testing.assert_allclose(np.asarray(first), ev.flight_data.observations[0], rtol=0, atol=1e-12)


def test_vector_env_widens_its_state_for_a_sensing_mdp_given_at_reset() -> None:
    vec = HoverVectorEnv(2, task="ghh08", mdp="train:1")
    vec.reset(seed=1)
    late = get_task_family("ghh08").mdp("train:1").with_sensor(Sensor(position=0.5))
    obs, _ = vec.reset(options={"mdp": [late, "train:1"]})
    assert np.abs(obs[0, 3:6]).max() > 0 and not obs[1].any()  # the sensing one's first reading is noisy, the other's zeros


@pytest.mark.parametrize("env_id", sorted(SENSOR_ENV_IDS))
def test_registered_sensor_variants_pass_gymnasiums_checker(env_id: str) -> None:
    from gymnasium.utils.env_checker import check_env

    env = gym.make(env_id)
    check_env(env.unwrapped, skip_render_check=True)
    assert not env.unwrapped.family.sensor.exact
    vec = gym.make_vec(env_id, num_envs=2, vectorization_mode="vector_entry_point")
    obs, _ = vec.reset(seed=0)
    assert obs.shape == (2, 12)


def test_env_sensor_arguments_are_checked() -> None:
    with pytest.raises(NeurohoverError, match="obs_delay"):
        HoverEnv(task="ghh08", obs_delay="2")
    with pytest.raises(NeurohoverError, match="correlation"):
        HoverVectorEnv(2, task="ghh08", obs_noise={"correlation": 1.5})


# -- the command line and the configs ---------------------------------------------------------


def test_fly_with_noisy_sensors_from_the_command_line(cli) -> None:
    base = ("fly", "--policy", "baseline", "--task", "ghh08", "--mdp", "train:1", "--episodes", "4", "--json")
    exact = json.loads(cli(*base)[1])
    noisy = json.loads(cli(*base, "--obs-noise", "position=0.3,correlation=0.9", "--obs-delay", "1")[1])
    assert "sensor" not in exact and noisy["sensor"] == Sensor(position=0.3, correlation=0.9, delay=1).to_dict()
    assert noisy["mean_return"] != exact["mean_return"]
    rc, _, err = cli(*base, "--obs-noise", "foo=1")
    assert rc == 2 and "'foo=1' is not understood" in err and "Traceback" not in err


def test_a_test_runs_group_flies_its_mdps_through_its_sensor(tmp_path) -> None:
    from neurohover.experiments.config import load_config
    from neurohover.experiments.plans import plan

    config = tmp_path / "sensors.toml"
    config.write_text(
        'name = "sensors"\ntitle = "t"\nkind = "test_runs"\n[settings]\ntask = "ghh08"\nseed = 3\nepisodes = 2\npolicies = "shipped"\n'
        '[[settings.groups]]\nagent = "generic"\nn_mdps = 2\n'
        '[[settings.groups]]\nagent = "generic"\nlabel = "noisy"\nn_mdps = 2\nsensor = {level = 2.0, correlation = 0.9}\n[scales.quick]\n'
    )
    units = {u.key: u for u in plan(load_config(str(config), "quick"), {}, {}).units}
    noisy = [u for k, u in units.items() if "/noisy/" in k]
    plain = [u for k, u in units.items() if "/generic/" in k]
    assert len(noisy) == len(plain) == 2
    assert all(MDP.from_dict(u.params["mdp"]).sensor == Sensor.at_level(2.0, correlation=0.9) for u in noisy)
    assert all("sensor" not in u.params and "sensor" not in u.params["mdp"] for u in plain)
    config.write_text(config.read_text().replace("level = 2.0", "level = -2.0"))
    with pytest.raises(NeurohoverError, match="sensor"):
        load_config(str(config), "quick")


# -- the CUDA build ----------------------------------------------------------------------------

CUDA_SCRIPT = r"""
import json, warnings
import numpy as np
from neurohover import baseline_policy, evaluate_jobs, get_task_family
from neurohover.envs.vector import HoverVectorEnv
from neurohover.tasks import Sensor
warnings.filterwarnings("ignore", "overflow encountered", RuntimeWarning)
mdp = get_task_family("ghh09").mdp("train:0").with_sensor(Sensor.at_level(1.0, correlation=0.8, delay=2))
out = {}
for device in ("cpu", "cuda"):
    ev = evaluate_jobs([baseline_policy()], [mdp], [0, 0], [0, 0], [1, 2], seed=5, record=[True, False], n_steps=30, device=device)
    env = HoverVectorEnv(2, task="ghh09", mdp=mdp, episode_steps=30, device=device)
    obs, _ = env.reset(options={"noise": (5, 1)})
    seen = [obs.tolist()]
    for _ in range(5):
        obs, *_ = env.step(np.stack([baseline_policy().act(o) for o in obs]))
        seen.append(obs.tolist())
    out[device] = {"returns": ev.returns.tolist(), "obs": ev.flight_data.observations[0].tolist(), "env": seen}
print(json.dumps(out))
"""


@pytest.mark.slow
def test_cuda_build_senses_as_the_cpu_kernel_under_the_simulator() -> None:
    out = run_simulated(CUDA_SCRIPT)
    np.testing.assert_allclose(out["cuda"]["returns"], out["cpu"]["returns"], rtol=1e-9)
    np.testing.assert_allclose(out["cuda"]["obs"], out["cpu"]["obs"], rtol=0, atol=1e-9)
    np.testing.assert_allclose(out["cuda"]["env"], out["cpu"]["env"], rtol=0, atol=1e-9)


def test_a_delay_named_in_the_noise_and_again_as_obs_delay_is_refused() -> None:
    """Sixth trial: --obs-noise level=0.5,delay=0 --obs-delay 2 flew a delay of 2 without a word."""
    for noise in ("level=0.5,delay=0", {"level": 0.5, "delay": 0}, "level=0.5, delay = 1"):
        with pytest.raises(NeurohoverError, match="obs_delay=2 conflicts with the delay=[01] that obs_noise sets"):
            Sensor.of(noise, 2)
    assert Sensor.of("level=0.5", 2).delay == 2 and Sensor.of("level=0.5,delay=2", 2).delay == 2
