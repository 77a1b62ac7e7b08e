"""LR as the authors fitted it (docs/model.md): the u constant discarded, their noise estimate, and
their evolution on the model (an SLP from the baseline by their ``eonn``), each a setting."""

from __future__ import annotations

import json

import numpy as np
import pytest

from neurohover import MDP, NeurohoverError, baseline_policy, evaluate, get_task_family
from neurohover.agents.model_based import ModelEvolution, evolve_on_model
from neurohover.evolution.eonn import EonnSettings, eonn_evolve
from neurohover.experiments import load_config
from neurohover.experiments.config import make_config
from neurohover.experiments.plans import plan
from neurohover.models import Transitions, authors_noise, learn_lr, noise_from_residuals, one_substep_params
from neurohover.sim.constants import DEFAULT_NOISE_STD

SEED = 11
MODEL_TRUTH = MDP("model", params=tuple(one_substep_params()[0]), substeps=1, dt=0.1, label="model-truth")


@pytest.fixture(scope="module")
def windy_flight():
    """One baseline episode on GHH-08 train:0 (a constant wind of a few m/s)."""
    ev = evaluate(baseline_policy(), get_task_family("ghh08").training_mdps()[0], seed=SEED, record=True)
    assert not ev.crashed.any()
    return ev.flight_data


def test_discarding_d_u_keeps_every_parameter_and_moves_the_constant_into_the_noise(windy_flight) -> None:
    kept = learn_lr(windy_flight, noise="innovations")  # body-frame residuals: the u axis's noise alone moves
    dropped = learn_lr(windy_flight, d_u="discard", noise="innovations")
    assert dropped.params == kept.params  # the same fit: the u slope is fitted with its constant either way
    assert kept.d_u != 0.0 and dropped.d_u == 0.0
    assert dropped.stats["discarded_intercepts"]["u"] == pytest.approx(kept.d_u, rel=1e-12)
    # the wind's drag the constant carried is now unexplained u acceleration: more gust noise on u only
    assert dropped.noise_std[0] > 1.2 * kept.noise_std[0]
    assert dropped.noise_std[1:] == kept.noise_std[1:]
    rms_kept, rms_dropped = learn_lr(windy_flight), learn_lr(windy_flight, d_u="discard")  # the default: world-frame velocities
    assert rms_dropped.noise_std[0] > 1.2 * rms_kept.noise_std[0] and rms_dropped.noise_std[3:] == rms_kept.noise_std[3:]
    assert learn_lr(windy_flight, "v", d_u="discard").params == learn_lr(windy_flight, "v").params  # no D_u to keep


def test_the_authors_noise_estimate_reads_four_thirds_of_pure_ar1_gusts() -> None:
    """On data flown in a one-substep model, the true parameters leave the AR(1) gusts themselves as
    residuals: ours reads their std, the authors' rms / 0.05 reads 2 * 0.4 / 0.6 = 4/3 of it."""
    ev = evaluate(baseline_policy(), MODEL_TRUTH, episodes=10, seed=SEED, record=True)
    tr = Transitions(ev.flight_data)
    residuals = tr.model_residuals(np.asarray(MODEL_TRUTH.params))[0]
    ours, _ = noise_from_residuals(tr, residuals)
    theirs = authors_noise(tr, residuals)
    true = np.asarray(MODEL_TRUTH.noise_std)
    assert np.allclose(true, DEFAULT_NOISE_STD)
    assert np.all(np.abs(ours / true - 1) < 0.03), ours / true
    assert np.all(np.abs(theirs / true - 4 / 3) < 0.06), theirs / true


def test_the_authors_noise_is_the_rms_one_step_error_of_world_velocities_and_rates(windy_flight) -> None:
    """Their estimate_std flies the model one step from every observed state: check it against that,
    step by step in plain NumPy (world velocities from the quaternion, rates as observed)."""
    model = learn_lr(windy_flight, d_u="discard", noise="rms")
    tr = Transitions(windy_flight)
    p = np.asarray(model.params)
    o, a = tr.obs, tr.act
    body = np.column_stack([p[0] * o[:, 0], p[1] * o[:, 1] + p[2], p[3] * o[:, 2] + p[4] * a[:, 3]])
    v_pred = tr.V + 0.1 * (np.einsum("nij,nj->ni", tr.R, body) + np.array([0.0, 0.0, 9.81]))
    r_pred = o[:, 6:9] + 0.1 * np.column_stack([p[5] * o[:, 6] + p[6] * a[:, 0], p[7] * o[:, 7] + p[8] * a[:, 1], p[9] * o[:, 8] + p[10] * a[:, 2]])
    error = np.column_stack([tr.Vn - v_pred, tr.nxt[:, 6:9] - r_pred])
    expected = np.sqrt(np.mean(error**2, axis=0)) / 0.05
    assert np.allclose(model.noise_std, expected, rtol=1e-9)
    assert model.stats["noise"] == "rms" and model.stats["noise_std_rms"] == list(model.noise_std)
    ours = learn_lr(windy_flight, d_u="discard", noise="innovations")
    assert ours.stats["noise_std_innovations"] == list(ours.noise_std) and ours.stats["noise_std_rms"] == list(model.noise_std)


def test_bad_lr_fit_settings_are_refused(windy_flight) -> None:
    with pytest.raises(NeurohoverError, match="d_u='drop' is not allowed: choose one of keep, discard"):
        learn_lr(windy_flight, d_u="drop")
    with pytest.raises(NeurohoverError, match="noise='std' is not allowed: choose one of innovations, rms"):
        learn_lr(windy_flight, noise="std")
    for field, value in (("d_u", "x"), ("noise", "x"), ("model_policy", "theirs"), ("authors_generations", 0)):
        with pytest.raises(NeurohoverError, match=field):
            ModelEvolution(**{field: value})


def test_eonn_is_deterministic_counts_its_episodes_and_ignores_threads() -> None:
    mdp = get_task_family("ghh08").training_mdps()[2]
    s = EonnSettings(pop_size=6, keep=5, generations=4)
    one = eonn_evolve(mdp, baseline_policy(), settings=s, seed=5, n_steps=150, threads=1)
    two = eonn_evolve(mdp, baseline_policy(), settings=s, seed=5, n_steps=150, threads=2)
    assert one.champion == two.champion and one.fitness == two.fitness
    assert one.episodes == 6 + 4 * 1 == s.episodes  # the first pool, then one offspring a generation
    assert one.champion.topology == "slp"
    other = eonn_evolve(mdp, baseline_policy(), settings=s, seed=6, n_steps=150)
    assert other.fitness != one.fitness  # other gusts (the baseline, unmutated, may win both)


def test_eonn_keeps_the_score_a_genome_was_first_given() -> None:
    """Their eonn flies only the genomes without an episode: with no variation every genome is the
    prototype, episode i of the seed is the i-th flown, and the best score ever drawn survives every
    generation, so the champion's fitness is the best 1/ln(error) of the 3 + 3 episodes flown, not a mean."""
    mdp = get_task_family("ghh08").training_mdps()[1]
    s = EonnSettings(pop_size=3, keep=2, generations=3, tournament_size=2, mutate_prob=0.0, spawn_frac=0.0, averaging_prob=1.0)
    result = eonn_evolve(mdp, baseline_policy(), settings=s, seed=3, n_steps=100)
    assert result.champion == baseline_policy() and result.episodes == 6
    flown = evaluate(baseline_policy(), mdp, episodes=6, seed=3, n_steps=100).returns.ravel()
    assert result.fitness == pytest.approx((1.0 / np.log(-flown)).max(), rel=1e-12)


def test_bad_eonn_settings_are_refused() -> None:
    with pytest.raises(NeurohoverError, match="keep=50"):
        EonnSettings(keep=50)
    with pytest.raises(NeurohoverError, match="generations=0"):
        EonnSettings(generations=0)
    with pytest.raises(NeurohoverError, match="mutate_prob=1.5"):
        EonnSettings(mutate_prob=1.5)


def test_the_authors_model_policy_is_an_slp_from_the_baseline_whatever_the_generic() -> None:
    from neurohover.policysets import load_policy_set

    generic = load_policy_set("ghh09").generic
    assert generic.topology == "mlp"
    ev = evaluate(baseline_policy(), get_task_family("ghh09").training_mdps()[3], seed=SEED, record=True, n_steps=400)
    model = learn_lr(ev.flight_data, d_u="discard", noise="rms").mdp()
    settings = ModelEvolution(n_steps=100, model_policy="authors", authors_generations=2)
    policy, predicted = evolve_on_model(model, generic, settings, seed=4)
    assert policy.topology == "slp" and np.isfinite(predicted)
    direct = eonn_evolve(model, baseline_policy(), settings=EonnSettings(generations=2), seed=4, n_steps=100)
    assert policy == direct.champion
    ours, _ = evolve_on_model(model, generic, ModelEvolution(n_steps=100, budget=60), seed=4)
    assert ours.topology == "mlp"


def test_fits_plan_paired_units_and_leave_our_params_as_before() -> None:
    cfg = load_config("lr-authors-table4", "quick")
    units = {u.key: u for u in plan(cfg, {}).units}
    assert len(units) == 8 * 3
    seeds = {u.params["seed"] for k, u in units.items() if k.endswith("/test0")}
    assert len(seeds) == 1  # every fit of an MDP: the same flight data and test gusts
    ours = units["model/lr@ours/test0"].params
    assert not {"d_u", "noise", "model_policy", "authors_generations"} & set(ours)  # absent: as before these settings
    theirs = units["model/lr@authors/test0"].params
    assert (theirs["d_u"], theirs["noise"], theirs["model_policy"], theirs["authors_generations"]) == ("discard", "rms", "authors", 5)
    assert units["model/lr@du/test0"].params["d_u"] == "discard" and "model_policy" not in units["model/lr@du/test0"].params


def test_factorial_test_runs_take_figure_8s_seeds() -> None:
    """Every group flies Figure 8's seeds: its "ours" groups are Figure 8's runs again, the others paired with them."""
    from neurohover.experiments.units import unit_seed

    fig8 = load_config("fig8", "paper")
    runs = [u for u in plan(load_config("lr-authors-fig8", "paper"), {}).units if u.kind == "test_run" and u.key.endswith("/train3/rep2")]
    assert len(runs) == 17  # model-free and 2 agents x 8 fits
    for u in runs:
        agent = u.params["agent"]
        assert u.params["seed"] == unit_seed(fig8.typed.seed, "fig8", f"run/{agent}/train3/rep2"), u.key


def test_bad_lr_fit_configs_are_refused() -> None:
    base = {"task": "ghh09", "seed": 1, "episodes": 2, "policies": "shipped"}
    with pytest.raises(NeurohoverError, match="d_u applies to the agents that learn models"):
        make_config("x", "test_runs", "quick", {**base, "groups": [{"agent": "model-free", "n_mdps": 1, "d_u": "discard"}]})
    with pytest.raises(NeurohoverError, match="wind_model applies to the agents that learn models"):  # ignored before
        make_config("x", "test_runs", "quick", {**base, "groups": [{"agent": "model-free", "n_mdps": 1, "wind_model": "sinusoid"}]})
    with pytest.raises(NeurohoverError, match="noise"):
        make_config("x", "test_runs", "quick", {**base, "groups": [{"agent": "incremental", "n_mdps": 1, "noise": "loud"}]})
    ml = {"task": "ghh08", "seed": 1, "n_mdps": 1, "generic": "shipped"}
    with pytest.raises(NeurohoverError, match="fits apply to the LR methods only"):
        make_config("y", "model_learning", "quick", {**ml, "methods": ["ec-mer"], "fits": [{"key": "a"}]})
    with pytest.raises(NeurohoverError, match="fit keys must be unique"):
        make_config("y", "model_learning", "quick", {**ml, "methods": ["lr"], "fits": [{"key": "a"}, {"key": "a"}]})
    with pytest.raises(NeurohoverError, match="model_policy"):
        make_config("y", "model_learning", "quick", {**ml, "methods": ["lr"], "fits": [{"key": "a", "model_policy": "mine"}]})


def test_the_agents_hand_their_lr_fit_to_the_model(monkeypatch) -> None:
    """ModelEvolution's d_u, noise and model substeps reach learn_model through every agent that learns a model."""
    import neurohover.agents.model_based as mb
    from neurohover.agents.model_based import IncrementalModelBasedAgent, ModelBasedAgent
    from neurohover.agents.protocol import EpisodeOutcome

    ev = evaluate(baseline_policy(), get_task_family("ghh08").training_mdps()[0], seed=SEED, record=True, n_steps=200)
    seen = []

    def spy(flight_data, estimator="ols", wind_model="none", *, d_u="keep", noise="innovations", substeps=1):
        seen.append((d_u, noise, substeps))
        raise RuntimeError("stop before evolving")

    monkeypatch.setattr(mb, "learn_model", spy)
    for cls in (ModelBasedAgent, IncrementalModelBasedAgent):
        agent = cls(baseline_policy(), ModelEvolution(d_u="discard", noise="rms", model_substeps=10))
        agent.start(get_task_family("ghh08"), np.random.default_rng(0))
        with pytest.raises(RuntimeError, match="stop before evolving"):
            agent.update(EpisodeOutcome(0, float(ev.returns.ravel()[0]), False, 200, -1, ev.flight_data))
    assert seen == [("discard", "rms", 10)] * 2


def test_main_effects_pair_cells_that_differ_in_one_factor() -> None:
    """A known answer: discarding D_u adds 1 to every MDP's return, the other two factors nothing."""
    from itertools import product

    from neurohover.experiments.report_factorial import main_effects

    cells, values = {}, {}
    rng = np.random.default_rng(0)
    base = {f"mdp{i}": float(rng.normal()) for i in range(10)}
    for d_u, noise, policy in product(("keep", "discard"), ("innovations", "rms"), ("ours", "authors")):
        label = f"{d_u}-{noise}-{policy}"
        cells[label] = {"d_u": d_u, "noise": noise, "model_policy": policy}
        values[label] = {k: v + (1.0 if d_u == "discard" else 0.0) for k, v in base.items()}
    values["keep-rms-ours"].pop("mdp3")  # a missing unit drops only its pairs
    d_u, noise, policy = main_effects(cells, values)
    assert d_u["pairs"] == 39 and d_u["median"] == 1.0 and d_u["better"] == 39 and d_u["p"] < 1e-6
    assert noise["pairs"] == 39 and noise["median"] == 0.0 and noise["p"] is None
    assert policy["pairs"] == 39 and policy["better"] == 0
    # cells that vary one factor only measure that one
    two = {k: cells[k] for k in ("keep-innovations-ours", "keep-rms-ours")}
    (only,) = main_effects(two, values)
    assert only["factor"].startswith("the noise estimate") and only["pairs"] == 9


@pytest.mark.slow
def test_the_factorial_reports_every_fit_and_each_factors_effect(tmp_path) -> None:
    from neurohover.experiments import LocalExecutor, Store, reproduce, write_report

    with Store(tmp_path / "s.sqlite") as store:
        for name in ("lr-authors-table4", "lr-authors-fig8"):
            cfg = load_config(name, "quick", {"n_steps": 60} if name.endswith("table4") else {"n_steps": 60, "episodes": 4})
            assert reproduce(cfg, store, LocalExecutor(1), progress=False).status == "finished"
        # the authors' policy set "flown": Figure 8's model-free runs of this store, each 10 better
        runs = [u for u in store.units("lr-authors-fig8", "quick") if u["params"]["group"] == "model-free"]
        theirs = [{"key": u["key"], "mdp": "m", "score": u["result"]["score"] + 10, "crash_episodes": [], "episodes": 4} for u in runs]
        (tmp_path / "report").mkdir()
        (tmp_path / "report" / "authors-ghh09-policies.json").write_text(json.dumps({"fig8-quick": {"model-free": theirs}}))
        report = write_report(store, tmp_path / "report").read_text()
    sections = {part.split("\n", 1)[0]: part for part in report.split("\n## ")}
    table4 = sections["LR as the authors fitted it: Table 4's protocol on GHH-08 [quick]"]
    for fit in ("ours", "du", "noise", "policy", "du-noise", "du-policy", "noise-policy", "authors"):
        assert f"\n| {fit} |" in table4
    assert "the policy evolved on the model (model_policy: ours -> authors)" in table4
    assert "LR, fit 'authors': our median" in table4  # beside the paper's LR
    fig8 = sections["LR as the authors fitted it: Figure 8's protocol on GHH-09 [quick]"]
    assert "#### incremental" in fig8 and "#### hybrid" in fig8 and "incremental: the u constant D_u" in fig8
    assert "| model-free | the authors' | 2 |" in fig8
    assert "model-free with the authors' published policies instead of ours: better (median paired difference of the cumulative reward 10 over 2 runs" in fig8
