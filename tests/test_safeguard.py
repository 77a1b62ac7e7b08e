"""The safeguard's dangerous-state test: the authors' rule (tilted and outside the box) and the paper's."""

from __future__ import annotations

import math

import numpy as np
import pytest

from neurohover import DangerousState, NeurohoverError, Policy, Safeguard, baseline_policy, evaluate, get_task_family


def _qw(obs: np.ndarray) -> np.ndarray:
    return np.sqrt(np.maximum(0.0, 1.0 - (obs[:, 9:12] ** 2).sum(axis=1)))


def _drifter() -> Policy:
    # The baseline plus a steady collective offset: the helicopter climbs out of the box while level.
    g = np.zeros(40)
    g[:36] = np.array(
        [
            [0, -0.0367, 0, 0, -0.0196, 0, -0.7475, 0, 0],
            [-0.0322, 0, 0, -0.0185, 0, 0, 0, 0.7904, 0],
            [0, 0, 0, 0, 0, 0, 0, 0, -0.1969],
            [0, 0, 0.1348, 0, 0, 0.0513, 0, 0, 0],
        ]
    ).ravel()
    g[36:] = (0.02, 0.0, 0.0, 0.23 + 0.03)
    return Policy("slp", g)


def test_code_rule_needs_a_tilt_where_the_box_alone_fires() -> None:
    mdp = get_task_family("ghh08").zero()
    drifter = _drifter()
    paper = evaluate(drifter, mdp, episodes=4, seed=3, n_steps=600, record=True, safeguard=Safeguard(baseline_policy(), DangerousState("paper")))
    code = evaluate(drifter, mdp, episodes=4, seed=3, n_steps=600, record=True, safeguard=Safeguard(baseline_policy(), DangerousState("code")))
    assert (paper.safeguard_step >= 0).all()  # a level drift leaves the 0.5 box...
    obs = code.flight_data.observations
    for e in range(4):
        k = int(code.safeguard_step.ravel()[e])
        seen = obs[e][: (k if k >= 0 else len(obs[e]) - 1)]
        outside = (np.abs(seen[:, :9]) > 0.5).any(axis=1)
        assert outside.any() and not (outside & (_qw(seen) < 0.99)).any()  # ...but never while tilted before k
        if k >= 0:
            assert np.abs(obs[e][k, :9]).max() > 0.5 and _qw(obs[e][k : k + 1])[0] < 0.99
    assert (code.safeguard_step == -1).all()  # a level drift is not dangerous to the authors' code


def test_a_rolling_policy_is_caught_by_both_rules() -> None:
    g = np.zeros(40)
    g[36] = 0.6  # constant aileron: rolls over
    roller = Policy("slp", g)
    mdp = get_task_family("ghh08").zero()
    for rule in ("code", "paper"):
        ev = evaluate(roller, mdp, episodes=2, seed=1, safeguard=Safeguard(baseline_policy(), DangerousState(rule)))
        assert (ev.safeguard_step > 0).all() and not ev.crashed.any()


def test_an_armed_test_fires_at_the_first_dangerous_step_from_its_arming_step() -> None:
    g = np.zeros(40)
    g[36] = 0.6  # constant aileron: rolls over, dangerous from some step k0 on
    roller = Policy("slp", g)
    mdp = get_task_family("ghh08").zero()

    def fly(d: DangerousState):
        return evaluate(roller, mdp, episodes=2, seed=1, n_steps=300, safeguard=Safeguard(baseline_policy(), d))

    k0 = fly(DangerousState()).safeguard_step.ravel()
    assert (k0 > 0).all()
    assert (fly(DangerousState(arm_after=int(k0.min()))).safeguard_step.ravel() == k0).all()  # armed in time: the same step
    late = fly(DangerousState(arm_after=int(k0.max()) + 1))
    steps = late.safeguard_step.ravel()
    # armed later: it fires no earlier than its arming step, or the roller crashed before the fallback could take over
    assert ((steps >= k0.max() + 1) | ((steps == -1) & late.crashed.ravel())).all()
    with pytest.raises(NeurohoverError, match="safeguard arm_after=1000000 is not below the episode's 300 control steps"):
        fly(DangerousState(arm_after=10**6))  # it would never arm: refused since T35-B03


_RATIOS = [5.0] * 3 + [20.0] * 3 + [4 * math.pi] * 3 + [1.0] * 3


def test_limits_are_settings() -> None:
    np.testing.assert_array_equal(DangerousState().limits(), [0.5] * 9 + [0.99, 0, 0.15, *_RATIOS, 0])
    np.testing.assert_array_equal(DangerousState("paper", box=0.8).limits(), [0.8] * 9 + [math.inf, 0, 0.15, *_RATIOS, 0])
    np.testing.assert_array_equal(DangerousState(box=1.0, tilt=0.95, arm_after=7).limits(), [1.0] * 9 + [0.95, 0, 0.15, *_RATIOS, 7])
    np.testing.assert_array_equal(DangerousState("ratio-sum", threshold=0.2).limits()[10:12], [1, 0.2])
    with pytest.raises(NeurohoverError, match="safeguard threshold=0 is out of range"):
        DangerousState("ratio-sum", threshold=0)


def test_the_ratio_sum_rule_fires_at_the_first_step_whose_signed_ratio_sum_exceeds_the_threshold() -> None:
    """The authors' FGHH agent's test: sum over the 12 observation entries of entry / limit > 0.15."""
    family = get_task_family("fghh", 0.3)
    mdps = family.test_mdps()[:6]
    wobbly = Policy("slp", np.r_[np.zeros(36), 0.05, -0.05, 0.1, 0.3])  # no feedback: drifts off within seconds
    guard = Safeguard(baseline_policy(), DangerousState("ratio-sum"))
    ev = evaluate(wobbly, mdps, episodes=1, seed=5, n_steps=400, record=True, safeguard=guard)
    steps = ev.safeguard_step.ravel()
    assert (steps > 0).sum() >= 2
    for e, k in enumerate(steps):
        obs = ev.flight_data.observations[e]
        ratio = (obs / np.array(_RATIOS)).sum(axis=1)  # signed: a drift the other way never fires
        if k >= 0:
            assert ratio[k] > 0.15 and (ratio[:k] <= 0.15).all()  # the observation the policy would have acted on next
        else:
            assert (ratio[:-1] <= 0.15).all()
    box = evaluate(wobbly, mdps, episodes=1, seed=5, n_steps=400, safeguard=Safeguard(baseline_policy(), DangerousState("code")))
    assert not np.array_equal(box.safeguard_step, ev.safeguard_step)  # another test, other steps
    # a wider box fires later (or not at all) on the same flights
    roller = Policy("slp", np.r_[np.zeros(36), 0.3, 0, 0, 0.23])
    mdp = get_task_family("ghh08").zero()
    steps = [evaluate(roller, mdp, episodes=2, seed=5, safeguard=Safeguard(baseline_policy(), DangerousState(box=b))).safeguard_step for b in (0.5, 2.0)]
    assert (steps[0] >= 0).all() and ((steps[1] > steps[0]) | (steps[1] == -1)).all()


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"rule": "literal"}, "unknown safeguard rule 'literal': allowed code, paper"),
        ({"box": -0.5}, "box=-0.5 is out of range"),
        ({"box": 0}, "box=0 is out of range"),
        ({"tilt": 1.2}, r"tilt=1.2 is out of range: allowed 0 < tilt <= 1"),
        ({"tilt": 0}, "tilt=0 is out of range"),
        ({"box": float("nan")}, "box=nan is out of range"),
        ({"arm_after": -1}, r"arm_after=-1 is out of range: allowed an integer in 0..1000000"),
        ({"arm_after": 2.5}, "arm_after=2.5 is not allowed"),
    ],
)
def test_bad_settings_are_refused(kwargs: dict, message: str) -> None:
    with pytest.raises(NeurohoverError, match=message):
        DangerousState(**kwargs)


# ------------------------------------------------------------------ settings of experiments and compete

from pathlib import Path  # noqa: E402

from neurohover.agents.hybrid import HybridSettings  # noqa: E402
from neurohover.cli import main  # noqa: E402
from neurohover.experiments.config import CONFIG_DIR, load_config  # noqa: E402
from neurohover.experiments.plans import group_hybrid_settings, plan  # noqa: E402


def _fig8_with(tmp_path: Path, group_extra: str, agent: str = "hybrid") -> Path:
    text = (CONFIG_DIR / "fig8.toml").read_text()
    marker = f'[[settings.groups]]\nagent = "{agent}"\n'
    assert marker in text
    path = tmp_path / "fig8x.toml"
    path.write_text(text.replace(marker, marker + group_extra, 1))
    return path


def test_experiment_groups_carry_thegroup_hybrid_settings_into_their_units(tmp_path: Path) -> None:
    cfg = load_config(str(_fig8_with(tmp_path, 'hybrid = { replacement = "evolve", rule = "paper", box = 0.7 }\n')), "paper")
    group = next(g for g in cfg.typed.groups if g.agent == "hybrid")
    want = {"replacement": "evolve", "model_from": "first-safe", "rule": "paper", "box": 0.7, "tilt": 0.99}
    assert group.hybrid == want and group_hybrid_settings(group) == want
    incremental = next(g for g in cfg.typed.groups if g.agent == "incremental")
    assert group_hybrid_settings(incremental) is None  # other agents' units carry no hybrid settings
    default = load_config("fig8", "paper")
    assert default.hash != cfg.hash  # the settings are part of the experiment's identity


def test_a_hybrid_group_takes_its_settings_under_the_name_every_agent_uses(tmp_path: Path) -> None:
    table = '{ replacement = "evolve", rule = "paper", box = 0.7 }'
    as_settings = load_config(str(_fig8_with(tmp_path, f"settings = {table}\n")), "paper")
    as_hybrid = load_config(str(_fig8_with(tmp_path, f"hybrid = {table}\n")), "paper")
    group = next(g for g in as_settings.typed.groups if g.agent == "hybrid")
    assert group.hybrid["rule"] == "paper" and group.hybrid["box"] == 0.7
    assert as_settings.hash == as_hybrid.hash  # resolved under `hybrid`: stored experiments keep their hash
    assert as_settings.hash != load_config("fig8", "paper").hash
    with pytest.raises(NeurohoverError, match="give the hybrid settings once"):
        load_config(str(_fig8_with(tmp_path, f"settings = {table}\nhybrid = {{ box = 0.5 }}\n")), "paper")
    with pytest.raises(NeurohoverError, match="box=-1 is out of range"):
        load_config(str(_fig8_with(tmp_path, "settings = { box = -1 }\n")), "paper")


@pytest.mark.parametrize(
    ("extra", "agent", "message"),
    [
        ("hybrid = { tilt = 1.5 }\n", "hybrid", "tilt=1.5 is out of range"),
        ("hybrid = { box = -1 }\n", "hybrid", "box=-1 is out of range"),
        ('hybrid = { replacement = "magic" }\n', "hybrid", "unknown hybrid replacement 'magic'"),
        ('hybrid = { colour = "red" }\n', "hybrid", "unknown hybrid setting(s) 'colour'"),
        ('hybrid = { rule = "paper" }\n', "incremental", "hybrid settings apply to the agents hybrid, hybrid-baseline only"),
    ],
)
def test_badgroup_hybrid_settings_in_configs_are_refused(tmp_path: Path, extra: str, agent: str, message: str) -> None:
    with pytest.raises(NeurohoverError) as err:
        load_config(str(_fig8_with(tmp_path, extra, agent)), "paper")
    assert message in str(err.value)


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--agent", "hybrid", "--safeguard-tilt", "0"], "tilt=0.0 is out of range"),
        (["--agent", "hybrid", "--safeguard-box", "-0.5"], "box=-0.5 is out of range"),
        (["--agent", "hybrid", "--safeguard-rule", "text"], "unknown safeguard rule 'text'"),
        (["--agent", "hybrid", "--hybrid-replacement", "x"], "unknown hybrid replacement 'x'"),
        (["--agent", "model-free", "--safeguard-rule", "paper"], "--safeguard-rule applies to the hybrid agents only"),
    ],
)
def test_compete_refuses_bad_hybrid_options(tmp_path: Path, capsys, argv: list[str], message: str) -> None:
    rc = main(["compete", "--task", "ghh09", "--runs", "1", "--episodes", "2", "--out", str(tmp_path / "o"), *argv])
    err = capsys.readouterr().err
    assert rc == 2 and message in err and "Traceback" not in err
    assert not (tmp_path / "o").exists()


def test_ablation_groups_reach_their_agents() -> None:
    from neurohover.experiments.units import unit_agent

    units = {u.key: u for u in plan(load_config("ablation-hybrid", "paper"), {}).units}
    gls = unit_agent(units["run/incremental-gls/train3/rep0"].params)
    ols = unit_agent(units["run/incremental/train3/rep0"].params)
    assert gls.settings.estimator == "gls" and ols.settings.estimator == "ols"
    text = unit_agent(units["run/hybrid-paper-text/train0/rep0"].params)
    assert text.hybrid == HybridSettings("evolve", "both", DangerousState("paper"))
    assert unit_agent(units["run/hybrid/train0/rep0"].params).hybrid == HybridSettings()
