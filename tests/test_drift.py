"""Drifting dynamics (neurohover.tasks.drift): the drifted rows, the test-run harness, configs and the CLI."""

from __future__ import annotations

import json
import re
import sqlite3

import numpy as np
import pytest

from neurohover import NeurohoverError, baseline_policy, evaluate_jobs, get_task_family
from neurohover.agents.protocol import run_test
from neurohover.agents.registry import agent_spec, policies_from_set
from neurohover.agents.spec import AgentOptions
from neurohover.policysets import load_policy_set
from neurohover.sim.constants import PARAM_NAMES, ROW_PARAMS
from neurohover.tasks import MDP, Drift

D_W = PARAM_NAMES.index("D_w")


def test_no_drift_is_the_default_and_leaves_dicts_as_they_were() -> None:
    mdp = get_task_family("fghh").mdp("test:2")
    assert mdp.drift.none and "drift" not in mdp.to_dict()
    drifting = mdp.with_drift(Drift(0.01, (("D_w", 0.8),)))
    assert MDP.from_dict(drifting.to_dict()) == drifting and drifting.row().tolist() == mdp.row().tolist()


def test_drifted_rows_start_at_the_mdp_change_once_and_walk_by_the_stated_std() -> None:
    row = get_task_family("fghh").mdp("test:2").row()
    step = Drift(0.0, (("D_w", 0.8),), (10, 40))
    rows = step.rows(row, 60, seed=5)
    at = step.change_episode(5)
    assert 10 <= at <= 40
    assert (rows[:at] == row).all()
    np.testing.assert_allclose(rows[at:, D_W], row[D_W] * 0.8)
    others = [i for i in range(len(PARAM_NAMES)) if i != D_W]
    assert (rows[:, ROW_PARAMS][:, others] == row[ROW_PARAMS][others]).all()
    walk = Drift(0.02).rows(row, 2001, seed=1)
    steps = np.diff(np.log(walk[:, ROW_PARAMS] / row[ROW_PARAMS]), axis=0)
    assert (walk[0] == row).all() and steps.std() == pytest.approx(0.02, rel=0.05)
    assert np.array_equal(Drift(0.02).rows(row, 50, seed=1), walk[:50]) and not np.array_equal(Drift(0.02).rows(row, 50, seed=2), walk[:50])
    assert {Drift(0.0, (("D_w", 0.8),), (0, 999)).change_episode(s) for s in range(20)} != {0}  # drawn, not fixed


@pytest.mark.parametrize(
    ("make", "message"),
    [
        (lambda: Drift(-0.1), "walk=-0.1 is out of range"),
        (lambda: Drift(0.0, (("D_x", 0.8),)), "'D_x': not a dynamics parameter"),
        (lambda: Drift(0.0, (("D_w", 0.0),)), "D_w=0.0 is out of range"),
        (lambda: Drift(0.0, (), (9, 3)), "change_at=(9, 3) is out of range"),
        (lambda: Drift.parse("D_w=abc"), "'D_w=abc' is not understood"),
        (lambda: Drift.from_dict({"wlak": 0.1}), "unknown drift setting"),
        (lambda: Drift.from_dict({"walk": "abc"}), "walk='abc' is not a number"),
        (lambda: Drift.from_dict({"walk": True}), "walk=True is not a number"),
        (lambda: Drift(change=(("D_w",),)), "drift change=(('D_w',),) is not allowed: give parameter factors as a table"),  # second trial
        (lambda: Drift(change="D_w=0.8"), "change='D_w=0.8' is not allowed"),  # type: ignore[arg-type]
        (lambda: Drift.from_dict({"change_at": 5}), "change_at=5 is not allowed"),
        (lambda: Drift(0.0, (("D_w", 0.8),), (True, 2)), "change_at=(True, 2) is not allowed"),
        (lambda: Drift.from_dict({"walk": 0.01, "change_at": [3, 5]}), "change_at=[3, 5] is given without a change"),  # was ignored
        (lambda: Drift.parse("walk=0.01@3-5"), "the walk has no window (it drifts every episode)"),
        (lambda: Drift.parse("walk=0.01@0-1,D_w=0.8"), "the walk has no window"),  # gave the change its window (sixth trial)
        (lambda: Drift.parse("D_w=0.8@0-1,C_u=0.9@2-2"), "gives its changes different windows"),  # both took the last (sixth trial)
        (lambda: Drift(0.0, (("D_w", 0.8), ("D_w", 0.9))), "sets a parameter twice"),  # kept the last (sixth trial)
        (lambda: Drift.parse("D_w=0.8@0-1,D_w=0.9@0-1"), "sets D_w twice: give each once"),  # kept the last (second trial)
        (lambda: Drift.parse("walk=0.01,,D_w=0.8"), "has an empty setting between commas"),
        (lambda: Drift.parse(""), "drift '' is not understood"),
        (lambda: Drift.parse("walk=\u0661"), "numbers in ASCII digits"),
        (lambda: get_task_family("ghh08").with_drift("slow"), "must be a neurohover Drift"),  # type: ignore[arg-type]
        (lambda: Drift(0.01, (("D_w", 1e300),)), "D_w=1e+300 is out of range: allowed a factor in 0.01..100"),  # flown (fifth trial)
        (lambda: Drift.parse("D_w=0.001@0-1"), "D_w=0.001 is out of range: allowed a factor in 0.01..100"),
    ],
)
def test_bad_drift_settings_get_one_clear_message(make, message: str) -> None:
    with pytest.raises(NeurohoverError, match=re.escape(message)):
        make()


def test_a_test_run_too_short_for_its_change_is_refused() -> None:
    """run_test flew a change due at episode 200..800 in 12 episodes as if fixed (bad-input trial); the last possible episode is allowed."""
    mdp = get_task_family("ghh08").mdp("test:3")
    default = "drift change_at=[200, 800] (the default where no @LO-HI is given) can come after the last of a test run's 12 episodes"
    with pytest.raises(NeurohoverError, match=re.escape(default)):
        _generic_run(mdp.with_drift(Drift.parse("D_w=0.8")))
    assert _generic_run(mdp.with_drift(Drift.parse("D_w=0.8@11")), episodes=12).returns.shape == (12,)


def test_compete_names_a_drift_too_late_for_its_episodes_by_its_options(cli, tmp_path) -> None:
    """issue 37, third trial: --drift D_w=0.8 with 2 episodes was refused naming an inline experiment's group, not the options,
    and its example used another parameter than the one given."""
    rc, _, err = cli("compete", "--task", "ghh08", "--agent", "baseline", "--runs", "1", "--episodes", "2", "--drift", "D_v=1.1", "--out", str(tmp_path / "o"))
    assert rc == 2 and "--drift 'D_v=1.1' with --episodes 2: drift change_at=[200, 800] (the default where no @LO-HI is given)" in err
    assert "(e.g. D_v=1.1@1-1)" in err and not (tmp_path / "o").exists()


def test_parse_reads_the_command_lines_form() -> None:
    assert Drift.parse("walk=0.01,D_w=0.8@200-800") == Drift(0.01, (("D_w", 0.8),), (200, 800))
    assert Drift.parse("C_u=1.5@300") == Drift(0.0, (("C_u", 1.5),), (300, 300))


def _generic_run(mdp: MDP, episodes: int = 12):
    spec = agent_spec("generic")
    agent = spec.build(policies_from_set(spec, load_policy_set("ghh08")), AgentOptions())
    return run_test(agent, get_task_family("ghh08"), mdp, episodes=episodes, seed=4, n_steps=400)


def test_the_harness_flies_episode_e_on_drifted_row_e() -> None:
    mdp = get_task_family("ghh08").mdp("test:3")
    drift = Drift(0.03, (("D_w", 0.5),), (4, 8))
    run = _generic_run(mdp.with_drift(drift))
    rows = drift.rows(mdp.row(), 12, seed=4)
    generic = load_policy_set("ghh08").generic
    direct = evaluate_jobs([generic], rows, [0] * 12, range(12), range(12), seed=4, n_steps=400)
    assert np.array_equal(run.returns, direct.returns)
    assert np.array_equal(_generic_run(mdp.with_drift(Drift())).returns, _generic_run(mdp).returns)
    assert not np.array_equal(run.returns, _generic_run(mdp).returns)


def test_test_runs_config_and_groups_carry_the_drift_into_their_units(tmp_path) -> None:
    from neurohover.experiments.config import load_config
    from neurohover.experiments.plans import plan

    config = tmp_path / "drift.toml"
    config.write_text(
        'name = "drift"\ntitle = "t"\nkind = "test_runs"\n[settings]\ntask = "ghh08"\nseed = 3\nepisodes = 2\npolicies = "shipped"\n'
        "drift = { walk = 0.01 }\n"
        '[[settings.groups]]\nagent = "generic"\nn_mdps = 1\n'
        '[[settings.groups]]\nagent = "generic"\nlabel = "stepped"\nn_mdps = 1\ndrift = { change = { D_w = 0.8 }, change_at = [0, 1] }\n[scales.quick]\n'
    )
    units = {u.key: u for u in plan(load_config(str(config), "quick"), {}, {}).units}
    assert MDP.from_dict(units["run/generic/test0/rep0"].params["mdp"]).drift == Drift(0.01)
    assert MDP.from_dict(units["run/stepped/test0/rep0"].params["mdp"]).drift == Drift(0.0, (("D_w", 0.8),), (0, 1))
    config.write_text(config.read_text().replace("walk = 0.01", "walk = -1"))
    with pytest.raises(NeurohoverError, match="drift"):
        load_config(str(config), "quick")
    # A change some 2-episode runs would never reach was silently never flown (bad-input trial): refused by name.
    config.write_text(config.read_text().replace("walk = -1", "walk = 0.01").replace("[0, 1]", "[1, 2]"))
    with pytest.raises(NeurohoverError, match=re.escape("group 'stepped': drift change_at=[1, 2] can come after the last of a test run's 2 episodes")):
        load_config(str(config), "quick")


@pytest.mark.slow
def test_compete_flies_a_drifting_task_from_the_command_line(cli, tmp_path) -> None:
    out = tmp_path / "c"
    rc, _, err = cli("compete", "--task", "ghh08", "--agent", "baseline", "--runs", "1", "--episodes", "3", "--episode-steps", "100",
                     "--drift", "walk=0.05", "--obs-noise", "0.5", "--out", str(out))  # fmt: skip
    assert rc == 0, err
    with sqlite3.connect(out / "results.sqlite") as conn:
        (params,) = [json.loads(p) for (p,) in conn.execute("SELECT params FROM units WHERE key LIKE 'run/%'")]
    assert params["mdp"]["drift"]["walk"] == 0.05 and params["mdp"]["sensor"]["velocity"] == pytest.approx(0.05)
    rc, _, err = cli("compete", "--task", "ghh08", "--agent", "baseline", "--drift", "D_q=2@x", "--out", str(tmp_path / "d"))
    assert rc == 2 and "is not understood" in err


def test_baseline_flies_the_same_with_or_without_a_zero_drift() -> None:
    mdp = get_task_family("fghh").mdp("test:1")
    rows = Drift().rows(mdp.row(), 3, seed=0)
    a = evaluate_jobs([baseline_policy()], rows, [0] * 3, range(3), range(3), seed=1, n_steps=200)
    b = evaluate_jobs([baseline_policy()], [mdp], [0] * 3, [0] * 3, range(3), seed=1, n_steps=200)
    assert np.array_equal(a.returns, b.returns)


@pytest.mark.slow
def test_the_benchmark_report_tabulates_agents_by_condition(cli, tmp_path) -> None:
    store = tmp_path / "r.sqlite"
    assert cli("reproduce", "bench-drift", "--store", str(store), "--no-progress")[0] == 0
    assert cli("report", "bench-drift", "--store", str(store), "--out", str(tmp_path / "report"))[0] == 0
    text = (tmp_path / "report" / "report.md").read_text()
    section = text[text.index("### Agents by condition") :]
    header, rule, *rows = section.split("\n\n")[1].splitlines()
    assert header == "| agent | fixed | walk | change | load |"
    assert [r.split(" | ")[0] for r in rows] == ["| baseline", "| generic", "| model-free", "| incremental", "| hybrid", "| continual"]
    assert all(r.count("%") == 4 for r in rows)


# -- Gymnasium: a drifting environment's episodes are test runs ---------------------------------------


def _fly_baseline(env, **reset) -> tuple[float, tuple[int, int]]:
    obs, info = env.reset(**reset)
    policy, total, done = baseline_policy(), 0.0, False
    while not done:
        obs, reward, terminated, truncated, info = env.step(np.array(policy.act(obs)))
        total += reward
        done = terminated or truncated
    return total, env.noise_stream


def test_a_drifting_environment_flies_episode_e_of_its_run_on_drifted_row_e() -> None:
    from neurohover.envs import HoverEnv

    mdp = get_task_family("fghh").test_mdps()[2]
    env = HoverEnv(task="fghh", mdp=mdp, episode_steps=150, drift={"walk": 0.05, "change": {"D_w": 0.5}, "change_at": [2, 2]})
    flown = [_fly_baseline(env, seed=4)] + [_fly_baseline(env) for _ in range(3)]
    run = env.drift_run
    assert run is not None and env._info(False)["run_episode"] == 3
    rows = env.drift.rows(mdp.row(), 4, run.seed)
    for e, (total, (seed, index)) in enumerate(flown):
        ev = evaluate_jobs([baseline_policy()], rows[e : e + 1], [0], [0], [index], seed=seed, n_steps=150)
        assert not ev.crashed[0] and np.isclose(total, ev.returns[0], rtol=1e-12, atol=1e-9), e
    assert len({round(t, 6) for t, _ in flown}) == 4  # the dynamics (and gusts) differ from episode to episode
    _fly_baseline(env, seed=4)  # a seeded reset begins the run again: the same drift
    assert env.drift_run.seed == run.seed and env._info(False)["run_episode"] == 0


def test_an_explicit_mdps_own_drift_drifts_the_environment_and_no_drift_leaves_it_as_it_was() -> None:
    from neurohover.envs import HoverEnv

    mdp = get_task_family("ghh08").mdp("train:1")
    plain = [_fly_baseline(HoverEnv(task="ghh08", mdp=mdp, episode_steps=100), seed=s)[0] for s in (1, 2)]
    still = HoverEnv(task="ghh08", mdp=mdp.with_drift(Drift()), episode_steps=100)
    assert [_fly_baseline(still, seed=s)[0] for s in (1, 2)] == plain and still.drift_run is None
    own = HoverEnv(task="ghh08", mdp=mdp.with_drift(Drift(0.2)), episode_steps=100)
    _fly_baseline(own, seed=1)
    _fly_baseline(own)
    assert own.drift_run is not None and own.drift_run.drift == Drift(0.2)


@pytest.mark.parametrize("suffix", ["DriftingDynamics", "AbruptChange"])
@pytest.mark.parametrize("task", ["GHH08", "GHH09", "FGHH"])
def test_registered_drift_variants_pass_gymnasiums_checker(task: str, suffix: str) -> None:
    import gymnasium as gym
    from gymnasium.utils.env_checker import check_env

    env = gym.make(f"neurohover/{task}-{suffix}-v0")
    check_env(env.unwrapped, skip_render_check=True)
    assert not env.unwrapped.drift.none
    vec = gym.make_vec(f"neurohover/{task}-{suffix}-v0", num_envs=2, vectorization_mode="sync")
    assert vec.reset(seed=0)[0].shape == (2, 12)


def test_what_flies_a_drifting_mdp_as_fixed_refuses_it_by_name() -> None:
    from neurohover.envs import HoverEnv, HoverVectorEnv
    from neurohover.evolution.evolve import evolve

    drifting = get_task_family("ghh08").mdp("train:1").with_drift(Drift(0.01))
    with pytest.raises(NeurohoverError, match="ghh08/train:1 has drifting dynamics .* which this batch would fly as if fixed"):
        evaluate_jobs([baseline_policy()], drifting, [0], [0], [0], n_steps=10)
    with pytest.raises(NeurohoverError, match="which evolution would fly as if fixed"):
        evolve(drifting, budget=10, n_steps=10)
    with pytest.raises(NeurohoverError, match="which evolution would fly as if fixed"):
        evolve(get_task_family("fghh", drift=Drift(0.01)), budget=10, n_steps=10)
    with pytest.raises(NeurohoverError, match="which the vector environment"):
        HoverVectorEnv(2, task="ghh08", mdp=drifting)
    with pytest.raises(NeurohoverError, match="drift=3 is not allowed"):
        HoverEnv(task="ghh08", drift=3)
    with pytest.raises(NeurohoverError, match="not a dynamics parameter"):
        HoverEnv(task="ghh08", drift="D_x=0.8")
