"""The fourteenth bad-input trial's findings in the task families, the environments, their renderer and evaluate
(T14-2, T14-14, T14-15, T14-17, T14-18, T14-19 and the task parts of T14-21): each bad value gives one NeurohoverError
naming it and what is allowed, and what was dropped or flown without a word is kept or refused."""

from __future__ import annotations

import re
from decimal import Decimal

import gymnasium as gym
import numpy as np
import pytest

import neurohover as nh
from neurohover.envs import hover, render
from neurohover.envs.vector import HoverVectorEnv
from neurohover.errors import NeurohoverError
from neurohover.tasks.drift import Drift, DriftRun


def test_fghh_sigma_minus_zero_is_sigma_zero(cli) -> None:
    """T14-2: sigma=-0.0 passed 0 <= sigma and was NumPy's 'scale < 0' at the first draw (a traceback, CLI exit 1)."""
    family = nh.get_task_family("fghh", sigma=-0.0)
    assert family.sigma == 0.0 and str(family.sigma) == "0.0" and family.to_dict()["sigma"] == 0.0
    assert family.sample(0).params == family.zero().params  # a breadth of 0: every draw is the mean MDP
    assert gym.make("neurohover/FGHH-v0", sigma=-0.0).reset(seed=0)[1]["mdp"] == "fghh/sample"
    HoverVectorEnv(2, task="fghh", sigma=-0.0).reset(seed=0)
    rc, out, err = cli("fly", "--task", "fghh", "--sigma=-0.0", "--mdp", "sample", "--episodes", "1")
    assert rc == 0 and "Traceback" not in err and "crashes: 0" in out


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda: hover.mdp_info(None), "mdp_info: mdp=None is not allowed: give a neurohover.MDP"),
        (lambda: hover.mdp_info("zero"), "mdp_info: mdp='zero' is not allowed: give a neurohover.MDP"),
        (lambda: hover.world_wind(None, 1), "world_wind: mdp=None is not allowed: give a neurohover.MDP"),
        (lambda: render.HoverRenderer(0, 0), "HoverRenderer width=0 is not allowed: give a whole number of pixels in 1..8192"),
        (lambda: render.HoverRenderer(-5, 10), "HoverRenderer width=-5 is not allowed: give a whole number of pixels in 1..8192"),
        (lambda: render.HoverRenderer("a", 10), "HoverRenderer width='a' is not allowed: give a whole number of pixels in 1..8192"),
        (lambda: render.HoverRenderer(10, 1.5), "HoverRenderer height=1.5 is not allowed: give a whole number of pixels in 1..8192"),
        (lambda: render.HoverRenderer(8, 8).pixel_box("nope"), "pixel_box part='nope' is not allowed: give one of top, side, wind, text"),
        (lambda: render.view_range([]), "view_range position=[] is not allowed: give 3 real numbers (a world position x, y, z)"),
        (lambda: render.view_range(["a", 1, 2]), "view_range position=['a', 1, 2] is not allowed: give 3 real numbers"),
        (lambda: render.rotation_matrix("a", 0, 0, 1), "rotation_matrix qx='a' is not allowed: give a quaternion's 4 real numbers qx, qy, qz, qw"),
        (lambda: render.HumanWindow(0), "HumanWindow fps=0 is not allowed: give a finite number of frames per second > 0"),
        (lambda: render.HumanWindow(float("nan")), "HumanWindow fps=nan is not allowed: give a finite number of frames per second > 0"),
        (
            lambda: render.HumanWindow(10).show(np.zeros(3)),
            "HumanWindow frame an array of shape (3,) and dtype float64 is not allowed: give an (height, width, 3) uint8 RGB image",
        ),
    ],
)
def test_the_environments_helpers_name_bad_arguments(call, message: str) -> None:
    """T14-14: these public helpers were AttributeErrors, ZeroDivisionError, matplotlib's ValueErrors, KeyError, IndexError
    or TypeError; HumanWindow(0) and HumanWindow(nan) were taken."""
    with pytest.raises(NeurohoverError, match=re.escape(message)):
        call()


def test_a_frame_is_drawn_only_of_a_state_wind_text_and_trail_it_can_read() -> None:
    """T14-14: draw([0]*3, ...) was an IndexError, a (2, 2) trail NumPy's reshape error; a good call still draws."""
    r = render.HoverRenderer(16, 16)
    state = hover.initial_state()
    with pytest.raises(NeurohoverError, match=re.escape("draw state=[0, 0, 0] is not allowed: give 13 real numbers (velocity, position")):
        r.draw([0] * 3, [0] * 3, "x")
    with pytest.raises(NeurohoverError, match=re.escape("draw trail of shape (2, 2) is not allowed: give an (n, 3) array of world positions")):
        r.draw(state, [0] * 3, "x", trail=np.zeros((2, 2)))
    with pytest.raises(NeurohoverError, match=re.escape("draw wind=[0] is not allowed: give 2 or 3 real numbers")):
        r.draw(state, [0], "x")
    with pytest.raises(NeurohoverError, match=re.escape("draw text=5 is not allowed: give a string")):
        r.draw(state, [0, 0], 5)
    assert r.draw(state, [1.0, 2.0], "ok", trail=np.zeros((3, 3))).shape == (16, 16, 3)


def test_the_vector_environment_renders_as_the_single_one_without_a_render_mode() -> None:
    """T14-14: HoverVectorEnv.render() was Gymnasium's NotImplementedError; like HoverEnv with render_mode None, it warns
    and returns None."""
    with pytest.warns(UserWarning, match="HoverVectorEnv has no rendering"):
        assert HoverVectorEnv(2).render() is None
    with pytest.warns(UserWarning, match="without specifying any render mode"):
        assert hover.HoverEnv().render() is None


def test_a_masked_reset_keeps_the_mdp_entries_of_the_sub_environments_it_does_not_reset() -> None:
    """T14-15: the 'mdp' entry of a sub-environment masked out of the reset was dropped (mdp_specs kept its old MDP),
    though an mdp option is kept for later episodes: it now applies from that sub-environment's next reset."""
    v = HoverVectorEnv(2)
    v.reset(seed=0)
    v.reset(options={"reset_mask": np.array([True, False]), "mdp": ["train:1", "train:2"]})
    assert [s.label for s in v.mdp_specs] == ["ghh08/train:1", "ghh08/train:2"]
    assert [m.label for m in v.mdps] == ["ghh08/train:1", "ghh08/sample"]  # sub-environment 1 flies on in its episode
    v.reset(options={"reset_mask": np.array([False, True])})
    assert [m.label for m in v.mdps] == ["ghh08/train:1", "ghh08/train:2"]


def test_an_mdp_names_a_known_family_with_its_own_wind() -> None:
    """T14-17: an unknown family was made and flown, ghh09's sinusoidal wind under the name ghh08 was taken, and
    MDP.from_dict({}) was a KeyError."""
    zero = nh.get_task_family("ghh08").zero()
    with pytest.raises(NeurohoverError, match=re.escape("MDP family='x' is not allowed: give a task family's name (") + ".*ghh08.*" + re.escape("or 'model'")):
        nh.MDP.from_dict({**zero.to_dict(), "family": "x"})
    train = nh.get_task_family("ghh09").mdp("train:1")
    with pytest.raises(NeurohoverError, match=re.escape("MDP wind_kind=2 is not allowed in family 'ghh08': its MDPs have wind_kind 0 or 1")):
        nh.MDP.from_dict({**train.to_dict(), "family": "ghh08"})
    with pytest.raises(NeurohoverError, match=re.escape("MDP wind_kind=1 is not allowed in family 'fghh': its MDPs have wind_kind 0")):
        nh.MDP("fghh", wind_kind=1, wind=(1.0, 1.0))
    with pytest.raises(NeurohoverError, match=re.escape("an MDP's dict {} lacks family, params, noise_std, wind_kind, wind, substeps, dt")):
        nh.MDP.from_dict({})
    # a type, not a range (T24-11: whole_in)
    with pytest.raises(NeurohoverError, match=re.escape("MDP substeps=10.7 is not allowed: allowed an integer in 1..1000")):
        nh.MDP.from_dict({**zero.to_dict(), "substeps": 10.7})  # int() cut it to 10
    assert nh.MDP.from_dict(train.to_dict()) == train and nh.MDP("model", wind_kind=2, wind=(0.5,) * 8).wind_kind == 2


def test_evaluate_refuses_rows_no_mdp_has() -> None:
    """T14-18: an all-zero row (substeps 0, dt 0) flew and scored 0.0, a perfect return; rows of a bad dt, noise or wind
    kind likewise went to the kernel."""
    row = nh.get_task_family("ghh08").zero().row()
    with pytest.raises(NeurohoverError, match=re.escape("MDP row 0 has substeps=0.0, which no MDP has: allowed a whole number in 1..1000")):
        nh.evaluate(nh.baseline_policy(), np.zeros((1, 36)), n_steps=20)
    for index, value, message in (
        (17, 2.5, "MDP row 1 has substeps=2.5, which no MDP has: allowed a whole number in 1..1000"),
        (18, 0.0, "MDP row 1 has dt=0.0, which no MDP has: allowed a substep length > 0"),
        (11, -1.0, "MDP row 1 has noise_std=[-1.0, "),
        (19, 3.0, "MDP row 1 has wind_kind=3.0, which no MDP has: allowed 0 (none), 1 (constant) or 2 (sinusoidal)"),
    ):
        bad = row.copy()
        bad[index] = value
        with pytest.raises(NeurohoverError, match=re.escape(message)):
            nh.evaluate(nh.baseline_policy(), np.stack([row, bad]), n_steps=20)
    assert nh.evaluate(nh.baseline_policy(), row[None, :], n_steps=20).returns.shape == (1, 1, 1)


def test_family_rows_take_only_finite_parameters_of_the_familys_shape() -> None:
    """T14-18: fam.rows(NaN) returned NaN rows, fam.rows(np.zeros((2, 3))) was NumPy's broadcast error."""
    fam = nh.get_task_family("ghh08")
    allowed = "are not allowed: give an array of shape (n, 2) of finite numbers (wind_u, wind_v)"
    with pytest.raises(NeurohoverError, match=re.escape(f"ghh08 parameters array([[nan, nan]]) {allowed}")):
        fam.rows(np.full((1, 2), np.nan))
    with pytest.raises(NeurohoverError, match=re.escape(f"ghh08 parameters of shape (2, 3) {allowed}")):
        fam.rows(np.zeros((2, 3)))
    for text in ("x", [["1", "2"]]):  # NumPy reads '1' as 1.0
        with pytest.raises(NeurohoverError, match=re.escape(f"ghh08 parameters {text!r} {allowed}")):
            fam.rows(text)
    assert fam.rows(np.zeros((0, 2))).shape == (0, 36)


def test_an_evaluation_reshape_names_a_shape_of_other_size() -> None:
    """T14-19: reshape((3,)) of 2 episodes was NumPy's ValueError, reshape('x') a TypeError."""
    ev = nh.evaluate(nh.baseline_policy(), nh.get_task_family("ghh08").zero(), episodes=2, n_steps=5)
    for shape in ((3,), "x"):
        with pytest.raises(
            NeurohoverError, match=re.escape(f"shape={shape!r} is not allowed: give a shape of 2 episodes, e.g. (2,) (the arrays' shape is (1, 1, 2))")
        ):
            ev.reshape(shape)
    assert ev.reshape((2,)).returns.shape == (2,) and ev.reshape((-1, 1)).steps.shape == (2, 1)


def test_a_drift_run_names_an_episode_past_its_bound() -> None:
    """T14-21: DriftRun(...).row(10**20) and Drift.rows(row, 10**20, 0) were NumPy's OverflowError."""
    drift = Drift(walk=0.01)
    row = nh.get_task_family("fghh").zero().row()
    with pytest.raises(
        NeurohoverError, match=re.escape("episode=100000000000000000000 is not allowed: give an episode number, a whole number >= 0 (below 100,000,000)")
    ):
        DriftRun(drift, row, 0).row(10**20)
    with pytest.raises(
        NeurohoverError, match=re.escape("episodes=100000000000000000000 is not allowed: give a whole number of episodes >= 1 (at most 100,000,000)")
    ):
        drift.rows(row, 10**20, 0)
    assert DriftRun(drift, row, 0).row(3).shape == (36,)


@pytest.mark.parametrize("factor", ["0.8", Decimal("0.8"), None, True])
def test_a_drift_factor_that_is_no_number_is_called_so(factor) -> None:
    """T14-21: Drift(change={'D_w': '0.8'}) and Decimal('0.8') were reported as 'out of range'."""
    with pytest.raises(NeurohoverError, match=re.escape(f"drift change D_w={factor!r} is not a number: allowed a factor in 0.01..100")):
        Drift(change={"D_w": factor})


def test_sensor_row_values_are_numbers_not_text() -> None:
    """T14-21: numeric strings were parsed, then refused with a misleading 'correlation=1.0' message."""
    with pytest.raises(
        NeurohoverError, match=re.escape("sensor row values array(['1', '1', '1', '1', '1', '1', '1'], dtype='<U1') are not allowed: give the 7")
    ):
        nh.Sensor.from_row_values(np.array(["1"] * 7))
    assert nh.Sensor.from_row_values(np.array([0.1, 0, 0, 0, 0.5, 1, 0])) == nh.Sensor(0.1, correlation=0.5, delay=1)


def test_a_vector_of_the_wrong_length_is_shown_briefly() -> None:
    """T14-13's follow-up: finite_vector echoed the whole value (a 100,000-number list made a line as long)."""
    from neurohover.tasks.base import finite_vector

    with pytest.raises(NeurohoverError, match=r"y must be 2 numbers, got 100000: \[0, 1, 2, ") as err:
        finite_vector(list(range(100_000)), 2, "y")
    assert len(str(err.value)) < 120
