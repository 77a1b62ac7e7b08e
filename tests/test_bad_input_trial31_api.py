"""Bad input, trial 31: NumPy small integers as sizes, model numbers past every MDP's bound, observations past
Policy.act's bound (T31-B02, T31-B04, T31-B05).

T31-B02: n_steps=np.int8(127) passed the n_steps check but was not converted, so evaluate's ``n_steps + 1`` overflowed
(NumPy's "negative dimensions", or with record=True a message naming internal Batch buffers); the same from
evaluate_jobs, run_test and compare_agent. The checks' returned Python int is now the value used (sizes, seeds, episode
counts and indices). T31-B04: a model file's d_u or parameters of 1e308 loaded, compared and saved again; only flying
it refused, naming no file. The model's numbers are now held to the MDP's bound when it is made, a file's refusal
naming the file. T31-B05: Policy.act gave inf and NaN actions for finite observations of 1e190 or 1.7e308; it now
refuses an entry past MAX_OBSERVATION (1e60), under which genes up to MAX_GENE keep every action finite."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from neurohover import Policy, baseline_policy, evaluate, get_task_family, policies
from neurohover.agents import ModelFreeAgent
from neurohover.agents.protocol import EpisodeOutcome, run_test
from neurohover.errors import NeurohoverError
from neurohover.flightmeta import action_mismatch
from neurohover.integrations.flying import compare_agent
from neurohover.models import LearnedModel, learn_lr
from neurohover.policies import MAX_GENE
from neurohover.sim.constants import DEFAULT_NOISE_STD, DEFAULT_PARAMS


@pytest.fixture(scope="module")
def ghh08():
    family = get_task_family("ghh08")
    return family, family.mdp("train:0")


# T31-B02 ------------------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("n_steps", [np.int8(127), np.uint8(255), np.int16(32767), np.uint16(65535)])
@pytest.mark.parametrize("record", [False, True])
def test_numpy_small_int_n_steps_fly_their_steps(ghh08, n_steps, record: bool) -> None:
    """np.int8(127) flew as 127 + 1 = -128 (negative dimensions); np.uint8(255) recorded was a Batch buffers' message."""
    _, mdp = ghh08
    ev = evaluate(baseline_policy(), mdp, n_steps=n_steps, record=record)
    plain = evaluate(baseline_policy(), mdp, n_steps=int(n_steps))
    assert ev.steps.ravel().tolist() == plain.steps.ravel().tolist() and ev.returns.tolist() == plain.returns.tolist()
    if record:
        assert ev.flight_data.observations[0].shape == (int(ev.steps.ravel()[0]) + 1, 12)


def test_numpy_small_int_episodes_and_indices_are_their_values(ghh08) -> None:
    """episodes, first_episode and seed as NumPy small integers fly as the same Python ints (no wrapped arithmetic)."""
    _, mdp = ghh08
    given = evaluate(baseline_policy(), [mdp, mdp], episodes=np.int8(100), first_episode=np.int8(127), seed=np.uint8(255), n_steps=3)
    plain = evaluate(baseline_policy(), [mdp, mdp], episodes=100, first_episode=127, seed=255, n_steps=3)
    assert given.returns.shape == (1, 2, 100) and np.array_equal(given.returns, plain.returns)


def test_run_test_and_compare_agent_take_numpy_small_ints(ghh08) -> None:
    """run_test and compare_agent reached the same overflow (T31-B02)."""
    family, mdp = ghh08
    b = baseline_policy()
    given = run_test(ModelFreeAgent([b]), family, mdp, episodes=np.int8(2), n_steps=np.int8(127), seed=np.uint8(3))
    plain = run_test(ModelFreeAgent([b]), family, mdp, episodes=2, n_steps=127, seed=3)
    assert given.steps.tolist() == plain.steps.tolist() == [127, 127] and given.returns.tolist() == plain.returns.tolist()
    rows = compare_agent(b, mdp, episodes=np.int8(2), n_steps=np.int8(127))
    assert [row.name for row in rows] == [row.name for row in compare_agent(b, mdp, episodes=2, n_steps=127)]
    with pytest.raises(NeurohoverError, match=r"^n_steps=1\.5 is not allowed: allowed an integer in 1\.\.") as err:
        run_test(ModelFreeAgent([b]), family, mdp, episodes=2, n_steps=1.5)
    assert "\n" not in str(err.value)


def test_episode_outcome_holds_python_ints() -> None:
    """The value checked is the value kept: NumPy integers become ints."""
    out = EpisodeOutcome(np.int8(3), -1.0, False, np.int16(300), np.int8(-1), None)
    assert (type(out.episode), type(out.steps), type(out.safeguard_step)) == (int, int, int)
    assert (out.episode, out.steps, out.safeguard_step) == (3, 300, -1)


# T31-B04 ------------------------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def model_file(tmp_path_factory) -> dict:
    """An LR model of a recorded baseline episode (200 steps, GHH-08's zero MDP), as its file's dict."""
    flight = evaluate(baseline_policy(), get_task_family("ghh08").zero(), record=True, seed=1, n_steps=200).flight_data
    path = learn_lr(flight).save(tmp_path_factory.mktemp("models31") / "m.json")
    return json.loads(path.read_text())


def _refused(d: dict, tmp_path: Path, fragment: str) -> str:
    path = tmp_path / "x.json"
    path.write_text(json.dumps(d))
    with pytest.raises(NeurohoverError) as err:
        LearnedModel.load(path)
    message = str(err.value)
    assert message.startswith(f"model file {str(path)!r}: {fragment}"), message
    assert "allowed numbers in [-10000, 10000]" in message and "\n" not in message, message
    return message


@pytest.mark.parametrize("d_u", [1e308, -1e300, 1e5, 2**63, -(2**63) - 1])
def test_model_file_d_u_past_every_mdps_bound_is_refused(model_file: dict, tmp_path: Path, d_u) -> None:
    """A d_u of 1e308 loaded, compared and saved again; only .mdp() refused it, naming no file."""
    _refused({**model_file, "d_u": d_u}, tmp_path, "model d_u=")


@pytest.mark.parametrize("value", [1e308, 1e5, -1e5])
def test_model_file_params_past_every_mdps_bound_are_refused(model_file: dict, tmp_path: Path, value: float) -> None:
    params = list(model_file["params"])
    params[0] = value
    _refused({**model_file, "params": params}, tmp_path, "model C_u=")


def test_model_made_past_the_bound_is_refused_and_written_ones_load(model_file: dict, tmp_path: Path) -> None:
    """The same check where a model is made (LearnedModel(...)); what learn_lr writes, and the bound itself, load."""
    with pytest.raises(NeurohoverError, match=r"^model noise std w=100000\.0 is out of range: allowed numbers in \[-10000, 10000\]"):
        LearnedModel(DEFAULT_PARAMS, (0.1, 0.1, 1e5, 0.1, 0.1, 0.1), "ec-meno")
    with pytest.raises(NeurohoverError, match=r"^model D_r=-1e\+308 is out of range"):
        LearnedModel((*DEFAULT_PARAMS[:10], -1e308), DEFAULT_NOISE_STD, "ec-meno")
    edge = LearnedModel(DEFAULT_PARAMS, DEFAULT_NOISE_STD, "ec-meno", d_u=1e4)
    assert edge.mdp().d_u == 1e4
    path = tmp_path / "ok.json"
    path.write_text(json.dumps(model_file))
    assert LearnedModel.load(path).to_dict()["params"] == model_file["params"]


# T31-B05 ------------------------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("topology", "genes", "observation", "name", "value"),
    [
        ("mlp", MAX_GENE, [1e190, -1e190] + [1e190] * 10, "u", "1e+190"),
        ("slp", 1.0, [1.7e308] * 12, "u", "1.7e+308"),
        ("mlp", 1.0, [0.0] * 11 + [-2e60], "qz", "-2e+60"),
    ],
)
def test_act_refuses_observations_past_its_bound(topology: str, genes: float, observation, name: str, value: str) -> None:
    """Finite observations of 1e190 or 1.7e308 acted inf and NaN; the message names the entry and the range."""
    policy = Policy(topology, np.full(42 if topology == "mlp" else 40, genes))
    with pytest.raises(NeurohoverError) as err:
        policy.act(observation)
    message = str(err.value)
    assert f"is out of range: its {name} {value} is past 1e+60; allowed 12 finite numbers in [-1e+60, 1e+60]" in message, message
    assert message.startswith("observation [") and "\n" not in message


@pytest.mark.parametrize("topology", ["slp", "mlp"])
def test_act_at_the_bound_with_genes_at_max_gene_stays_finite(topology: str) -> None:
    """The rule documented: every entry up to MAX_OBSERVATION, every gene up to MAX_GENE, any signs: finite actions."""
    rng = np.random.default_rng(31)
    bound = policies.MAX_OBSERVATION
    n = 42 if topology == "mlp" else 40
    for k in range(200):
        genes = np.full(n, MAX_GENE) if k == 0 else rng.choice([-MAX_GENE, MAX_GENE], n)
        obs = np.full(12, bound) if k == 0 else rng.choice([-bound, bound], 12)
        assert np.all(np.isfinite(Policy(topology, genes).act(obs)))


def test_recorded_readings_past_the_bound_are_passed_over() -> None:
    """A recording's check of its policy passes such readings over, as non-finite ones (no observation error there)."""
    obs = np.array([[1e100] * 12, [0.0] * 12])
    actions = np.array([[0.0] * 4, list(np.clip(baseline_policy().act([0.0] * 12), -1, 1))])
    assert action_mismatch(baseline_policy(), obs, actions) is None
