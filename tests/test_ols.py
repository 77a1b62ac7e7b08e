"""Models as the paper fitted them: OLS by default, the intercepts as documented, and EC-MENO
against the closed-form minimum of its own objective (neurohover/models/ docstrings).

Flight data: one baseline episode of 1500 control steps on the windy GHH-08 test MDP 0 (the
competition's own set), every number seeded. The tolerances on EC-MENO come from 4 seeds on these
data: relative excess of the one-step error over the minimum at most 2.5e-4 (every axis within
4.2 % of its own minimum) with the default genes and plateau stop, against 2.3 %-4.7 % for the
previous EC-MENO (genes / |default|, 2000 evaluations).
"""

from __future__ import annotations

import inspect

import numpy as np
import pytest

from neurohover import MDP, FlightData, NeurohoverError, baseline_policy, evaluate, get_task_family
from neurohover.agents.hybrid import HybridAgent
from neurohover.agents.model_based import IncrementalModelBasedAgent, ModelBasedAgent, ModelEvolution, learn_model
from neurohover.agents.protocol import EpisodeOutcome
from neurohover.cli import main
from neurohover.models import (
    DEFAULT_ESTIMATOR,
    ESTIMATORS,
    LearnedModel,
    OneStepProblem,
    learn_ec_meno,
    learn_ec_mer,
    learn_lr,
    one_substep_params,
)

STEPS = 1500


def _same_fit(a: LearnedModel, b: LearnedModel) -> bool:
    """Same model up to the wall time spent learning it."""
    return (a.params, a.noise_std, a.d_u, a.method, a.stats) == (b.params, b.noise_std, b.d_u, b.method, b.stats)


@pytest.fixture(scope="module")
def windy() -> FlightData:
    ev = evaluate(baseline_policy(), get_task_family("ghh08").test_mdps()[0], episodes=1, seed=5, record=True, n_steps=STEPS)
    assert not ev.crashed.any()
    return ev.flight_data


# ------------------------------------------------------------------------------- OLS default


def test_ols_is_the_default_of_learn_lr(windy) -> None:
    assert DEFAULT_ESTIMATOR == "ols" and set(ESTIMATORS) == {"ols", "gls"}
    default, ols, gls = learn_lr(windy), learn_lr(windy, estimator="ols"), learn_lr(windy, estimator="gls")
    assert _same_fit(default, ols)
    assert default.stats["estimator"] == "ols" and gls.stats["estimator"] == "gls"
    # GLS is a different fit (the rate parameters differ by a factor of about 3-4 on these data).
    rel = np.abs(np.array(gls.params) - np.array(ols.params)) / np.abs(np.array(gls.params))
    assert rel[5:].min() > 0.5, rel
    with pytest.raises(NeurohoverError, match="estimator"):
        learn_lr(windy, estimator="ar1")


def test_ols_is_the_default_of_every_agents_model_learning(windy, monkeypatch) -> None:
    np.testing.assert_array_equal(learn_model(windy).row(), learn_lr(windy, estimator="ols").mdp(substeps=10).row())  # ten: the default
    np.testing.assert_array_equal(learn_model(windy, "gls", substeps=1).row(), learn_lr(windy, estimator="gls").mdp().row())
    assert ModelEvolution().estimator == "ols"
    with pytest.raises(NeurohoverError, match="estimator"):
        ModelEvolution(estimator="quasi")
    for cls in (ModelBasedAgent, IncrementalModelBasedAgent, HybridAgent):
        assert inspect.signature(cls).parameters["settings"].default.estimator == "ols", cls

    # The agents hand their settings' estimator to learn_model (stopped before any evolution).
    import neurohover.agents.model_based as mb

    class Learned(Exception):
        pass

    def spy(flight_data, estimator="ols", wind_model="none", *, d_u="keep", noise="innovations", substeps=1):
        raise Learned(estimator, wind_model)

    monkeypatch.setattr(mb, "learn_model", spy)
    outcome = EpisodeOutcome(0, -1e4, False, STEPS, -1, windy)
    cases = (
        (ModelEvolution(), ("ols", "none")),
        (ModelEvolution(estimator="gls"), ("gls", "none")),
        (ModelEvolution(wind_model="sinusoid"), ("ols", "sinusoid")),
    )
    for cls in (ModelBasedAgent, IncrementalModelBasedAgent):
        for settings, expected in cases:
            agent = cls(baseline_policy(), settings)
            agent.start(get_task_family("ghh08"), np.random.default_rng(0))
            with pytest.raises(Learned) as caught:
                agent.update(outcome)
            assert caught.value.args == expected, (cls, expected)


def test_learn_model_command_uses_ols_unless_told(windy, tmp_path, capsys) -> None:
    data = windy.save(tmp_path / "flight.npz")
    for extra, expected in (((), "ols"), (("--estimator", "gls"), "gls")):
        out = tmp_path / f"{expected}.json"
        assert main(["learn-model", "--flight-data", str(data), "--method", "lr", "--out", str(out), *extra]) == 0
        assert LearnedModel.load(out).stats["estimator"] == expected
        assert _same_fit(LearnedModel.load(out), learn_lr(windy, estimator=expected))
    capsys.readouterr()


# ------------------------------------------------------------------------------- intercepts


def test_intercepts_do_what_the_docstring_says(windy) -> None:
    m = {ic: learn_lr(windy, ic) for ic in ("uv", "v", "all", "none")}
    p = {ic: np.array(model.params) for ic, model in m.items()}
    # "uv": the u constant is the model's D_u (and its MDP's), nothing is discarded.
    assert m["uv"].d_u != 0.0 and m["uv"].mdp().d_u == m["uv"].d_u
    assert m["uv"].stats["discarded_intercepts"] == {} and m["uv"].stats["intercepts"] == "uv"
    # "all": the same u regression (u on u and a constant, so the same C_u), but the constant is
    # discarded: D_u = 0 and it is reported; w, p, q, r constants too; the v constant is D_v.
    assert m["all"].d_u == 0.0
    discarded = m["all"].stats["discarded_intercepts"]
    assert set(discarded) == {"u", "w", "p", "q", "r"}
    assert discarded["u"] == pytest.approx(m["uv"].d_u, rel=1e-9)
    assert p["all"][0] == pytest.approx(p["uv"][0], rel=1e-9)
    # Residuals (hence noise) of "all" are those of the model without the u constant: with an
    # intercept the OLS residual has mean zero, so rms_all^2 = rms_uv^2 + D_u^2 on u.
    assert m["all"].stats["residual_rms"][0] ** 2 == pytest.approx(m["uv"].stats["residual_rms"][0] ** 2 + m["uv"].d_u ** 2, rel=1e-9)
    assert m["all"].noise_std[0] > m["uv"].noise_std[0]
    # "v": no u constant at all (a different C_u), D_u = 0.
    assert m["v"].d_u == 0.0 and m["v"].stats["discarded_intercepts"] == {}
    assert abs(p["v"][0] - p["uv"][0]) > 1e-3
    # "uv", "v", "all" fit the same v axis: C_v and D_v agree; "none" has no D_v.
    for ic in ("v", "all"):
        np.testing.assert_allclose(p[ic][1:3], p["uv"][1:3], rtol=1e-9)
    assert p["uv"][2] != 0.0 and p["none"][2] == 0.0 and m["none"].d_u == 0.0
    assert m["none"].stats["discarded_intercepts"] == {}
    # Axes without any constant in "uv" are the same fits as in "none".
    np.testing.assert_allclose(p["uv"][3:], p["none"][3:], rtol=1e-9)


# ------------------------------------------------------------------------------- EC-MENO


def test_one_step_error_is_a_sum_of_axes_and_least_squares_is_its_minimum(windy) -> None:
    problem = OneStepProblem(windy)
    rng = np.random.default_rng(1)
    theta = problem.least_squares()
    batch = theta * (1.0 + rng.normal(0.0, 0.3, (20, 11)))
    np.testing.assert_allclose(problem.errors(batch), problem.fixed_error + problem.axis_errors(batch).sum(axis=1), rtol=1e-10)
    # The minimum: every perturbation raises the error, and the gradient of the quadratic vanishes.
    assert np.all(problem.errors(batch) > problem.errors(theta))
    np.testing.assert_allclose(problem._h @ theta + problem._b, 0.0, atol=1e-9 * np.abs(problem._b).max())
    # It is OLS per axis on LR's regressors with intercepts "v": identical for the rates, and for
    # the velocities up to LR's observed (not predicted) next orientation.
    ols_v = np.array(learn_lr(windy, "v", estimator="ols").params)
    np.testing.assert_allclose(theta[5:], ols_v[5:], rtol=1e-8)
    np.testing.assert_allclose(theta[:5], ols_v[:5], rtol=0.02, atol=2e-3)


@pytest.mark.slow
def test_ec_meno_reaches_the_closed_form_minimum(windy) -> None:
    problem = OneStepProblem(windy)
    theta = problem.least_squares()
    e_min, axes_min = problem.errors(theta), problem.axis_errors(theta)
    model = learn_ec_meno(windy, seed=0)  # data genes, the paper's plateau stop
    s = model.stats
    assert s["scaling"] == "data" and s["budget"] is None and s["evaluations"] > 2000
    assert s["least_squares_one_step_error"] == pytest.approx(e_min, rel=1e-12)
    assert s["excess"] == pytest.approx((s["one_step_error"] - e_min) / e_min, rel=1e-9)
    assert 0.0 <= s["excess"] < 1e-3, s["excess"]
    axes_excess = (problem.axis_errors(np.array(model.params)) - axes_min) / axes_min
    assert np.all(axes_excess < 0.10), axes_excess
    # The check can fail: the previous EC-MENO (genes / |default|, 2000 evaluations) misses by > 1 %.
    old = learn_ec_meno(windy, seed=0, scaling="default", budget=2000)
    assert old.stats["evaluations"] == 2000 and old.stats["excess"] > 1e-2


@pytest.mark.slow
def test_ec_meno_moves_d_w_to_where_the_data_put_it() -> None:
    """Data flown in a one-substep model whose D_w is 10 % smaller than the default: EC-MENO
    leaves the prototype's D_w (-42.15) for the least-squares value (about -37)."""
    params, noise = one_substep_params()
    params[4] *= 0.9
    model_mdp = MDP("model", params=tuple(params), noise_std=tuple(noise), substeps=1, dt=0.1, label="D_w x 0.9")
    ev = evaluate(baseline_policy(), model_mdp, episodes=1, seed=3, record=True, n_steps=STEPS)
    assert not ev.crashed.any()
    theta = OneStepProblem(ev.flight_data).least_squares()
    assert abs(theta[4] - params[4]) < 0.5
    learned = learn_ec_meno(ev.flight_data, seed=1)
    assert abs(learned.params[4] - theta[4]) < 0.05, (learned.params[4], theta[4])


def test_ec_meno_options_are_checked(windy) -> None:
    with pytest.raises(NeurohoverError, match="scaling"):
        learn_ec_meno(windy, scaling="magnitude")
    with pytest.raises(NeurohoverError, match="budget"):
        learn_ec_meno(windy, budget=0)
    with pytest.raises(NeurohoverError, match="budget"):
        learn_ec_mer(windy, baseline_policy(), budget=None)
    capped = learn_ec_meno(windy, budget=120, seed=2)
    assert capped.stats["budget"] == 120 and 120 <= capped.stats["evaluations"] < 170
    assert len(capped.stats["gene_scale"]) == 11 and all(x > 0 for x in capped.stats["gene_scale"])
