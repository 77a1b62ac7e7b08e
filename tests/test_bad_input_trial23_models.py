"""The twenty-third bad-input trial's findings in learned models (T23-10, T23-15, T23-16): a model file edited by hand
(noise names reversed, an unknown estimator, -1 transitions, standard errors of the wrong length, more episodes than
transitions, intercepts or a method that contradict the stats, an unknown entry) was loaded as it was; learn_ec_mer
fitted a policy that never flew its flight data (the command line refused it); learn-model --out m.npz wrote JSON
under a NumPy archive's name. Every model the code writes still loads."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from neurohover import baseline_policy, evaluate, get_task_family
from neurohover.errors import NeurohoverError, brief
from neurohover.models import LearnedModel, learn_ec_meno, learn_ec_mer, learn_lr
from neurohover.policies import Policy


def _raises(fragment: str):
    return pytest.raises(NeurohoverError, match=re.escape(fragment))


@pytest.fixture(scope="module")
def flight():
    """A baseline episode of 200 steps on GHH-08's zero MDP, recorded."""
    return evaluate(baseline_policy(), get_task_family("ghh08").zero(), record=True, seed=1, n_steps=200).flight_data


LR_OPTIONS = [
    dict(intercepts=i, wind_model=w, d_u=d, estimator=e, noise=n)
    for i in ("uv", "v", "all", "none")
    for w, d, e, n in (
        ("none", "keep", "ols", "rms"),
        ("none", "discard", "gls", "innovations"),
        ("constant", "keep", "ols", "rms"),
        ("sinusoid", "discard", "ols", "rms"),
    )
]


@pytest.fixture(scope="module")
def lr_file(flight, tmp_path_factory) -> dict:
    """The file of learn_lr's default model (intercepts uv, D_u kept, no wind), as a dict to edit."""
    path = learn_lr(flight).save(tmp_path_factory.mktemp("lr") / "m.json")
    return json.loads(path.read_text())


def _load(d: dict, tmp_path: Path, name: str = "m.json") -> LearnedModel:
    path = tmp_path / name
    path.write_text(json.dumps(d))
    return LearnedModel.load(path)


# --------------------------------------------------------------------------- every model the code writes loads


@pytest.mark.parametrize("options", LR_OPTIONS, ids=lambda o: "-".join(o.values()))
def test_every_lr_model_loads(flight, options: dict, tmp_path: Path) -> None:
    """T23-10: the checks take every model learn_lr writes (each intercepts, wind, d_u, estimator and noise)."""
    model = learn_lr(flight, **options)
    assert LearnedModel.load(model.save(tmp_path / "m.json")) == model


def test_ec_models_and_a_callers_own_stats_load(flight, tmp_path: Path) -> None:
    """T23-10: EC-MENO's and EC-MER's models, and a model of a caller's own stats, load."""
    for model in (
        learn_ec_meno(flight, budget=60),
        learn_ec_mer(flight, baseline_policy(), budget=5),
        LearnedModel(learn_lr(flight).params, (0.1,) * 6, "lr", stats={"mine": [1, "x"]}),
    ):
        assert LearnedModel.load(model.save(tmp_path / "m.json")) == model


def test_an_older_model_file_loads(lr_file: dict, tmp_path: Path) -> None:
    """T23-10: a file of before winds and D_u (no wind, d_u, noise_names; stats without noise, d_u, wind_model; "uv"
    then discarded the u constant) still loads."""
    d = json.loads(json.dumps(lr_file))
    for key in ("wind", "d_u", "noise_names"):
        del d[key]
    for key in ("noise", "d_u", "wind_model", "noise_std_innovations", "noise_std_rms"):
        del d["stats"][key]
    d["stats"]["discarded_intercepts"] = {"u": 0.01}
    assert _load(d, tmp_path).d_u == 0.0


# --------------------------------------------------------------------------- T23-10: a model file against itself


def _stats(key: str, value):
    return lambda d: d["stats"].__setitem__(key, value)


EDITS = {
    "noise names reversed": (
        lambda d: d.__setitem__("noise_names", d["noise_names"][::-1]),
        "its noise_names ['r', 'q', 'p', 'w', 'v', 'u'] is not allowed: allowed ['u', 'v', 'w', 'p', 'q', 'r'] (the order of noise_std)",
    ),
    "estimator": (_stats("estimator", "zz"), "its stats.estimator 'zz' is not allowed: allowed ols or gls (LR's estimator choices)"),
    "transitions": (_stats("n_transitions", -1), "its stats.n_transitions -1 is not allowed: allowed an integer >= 20"),
    "param_se": (_stats("param_se", [0.1, 0.2, 0.3]), "its stats.param_se [0.1, 0.2, 0.3] is not allowed: allowed 11 finite numbers >= 0 (one per parameter)"),
    "episodes": (
        _stats("n_episodes", 99999),
        "its stats.n_episodes 99999 is not allowed: allowed an integer in 1..200 (each episode has a transition or more)",
    ),
    "intercepts beside D_u": (
        lambda d: d.update(d_u=0.25, stats={**d["stats"], "intercepts": "v"}),
        "its d_u 0.25 is not allowed: allowed 0.0: its stats say intercepts 'v', which keeps no u constant",
    ),
    "discarded intercepts": (
        _stats("discarded_intercepts", {"w": 1.5}),
        "its stats.discarded_intercepts {'w': 1.5} is not allowed: its intercepts 'uv' (d_u 'keep', wind 'none') discard none",
    ),
    "method": (lambda d: d.__setitem__("method", "ec-meno"), "its method 'ec-meno' is not allowed: its stats hold estimator, which lr alone writes"),
    "unknown entry": (lambda d: d.__setitem__("colour", "red"), "its entry 'colour' is not allowed: a model file has only format, method, param_names"),
    "wind": (_stats("wind_model", "constant"), "its wind 'none' is not allowed: stats.wind_model is 'constant': allowed a 'constant' wind"),
}


@pytest.mark.parametrize("case", list(EDITS))
def test_a_model_file_that_contradicts_itself_is_refused(case: str, lr_file: dict, tmp_path: Path) -> None:
    """T23-10: each hand edit was loaded as it was; now refused at load, naming the file, the entry, its value and what
    is allowed."""
    edit, fragment = EDITS[case]
    d = json.loads(json.dumps(lr_file))
    edit(d)
    with _raises(f"model file '{tmp_path / 'm.json'}': {fragment}"):
        _load(d, tmp_path)


def test_an_intercepts_all_model_must_discard_its_constants(flight, tmp_path: Path) -> None:
    """T23-10: intercepts 'all' discards the u, w, p, q and r constants; a file that lost one contradicts itself."""
    d = json.loads(learn_lr(flight, "all").save(tmp_path / "a.json").read_text())
    del d["stats"]["discarded_intercepts"]["w"]
    with _raises("its intercepts 'all' (d_u 'keep', wind 'none') discard p, q, r, u, w"):
        _load(d, tmp_path)


def test_an_ec_meno_file_called_lr_is_refused(flight, tmp_path: Path) -> None:
    """T23-10: a method contradicting its stats the other way (EC-MENO's stats under method 'lr')."""
    d = json.loads(learn_ec_meno(flight, budget=30).save(tmp_path / "e.json").read_text())
    d["method"] = "lr"
    with _raises("its method 'lr' is not allowed: its stats hold scaling, which ec-meno alone writes"):
        _load(d, tmp_path)


# --------------------------------------------------------------------------- T23-15: EC-MER's policy in the Python API


def test_learn_ec_mer_refuses_a_policy_that_did_not_fly_the_data(flight) -> None:
    """T23-15: learn_ec_mer(data, another policy) fitted the closed loop of a policy that never flew the data (the
    command line's ec_mer_policy refused it); now learn_ec_mer checks the recorded actions itself."""
    base = baseline_policy()
    genome = base.genome.copy()
    genome[1] += 0.5
    other = Policy(base.topology, genome)
    with _raises("flight data: generic_policy did not fly them (EC-MER fits the closed loop of the policy that did): at step "):
        learn_ec_mer(flight, other, budget=5)
    assert learn_ec_mer(flight, base, budget=5).method == "ec-mer"  # the policy that flew them


# --------------------------------------------------------------------------- T23-16: a model file's name


def test_learn_model_refuses_an_npz_name_before_learning(cli, tmp_path: Path, monkeypatch) -> None:
    """T23-16: learn-model --out m.npz wrote JSON into a file named .npz; now exit 2 before anything is learned."""
    data = tmp_path / "f.npz"
    assert cli("fly", "--task", "ghh08", "--mdp", "zero", "--episodes", "1", "--record", str(data))[0] == 0

    def no_learning(*args, **kwargs):
        raise AssertionError("learned before the name was checked")

    monkeypatch.setattr("neurohover.models.learn_lr", no_learning)
    monkeypatch.chdir(tmp_path)
    rc, _, err = cli("learn-model", "--flight-data", str(data), "--method", "lr", "--out", "m.npz")
    assert rc == 2 and not (tmp_path / "m.npz").exists() and "Traceback" not in err, err
    assert "--out 'm.npz' is not allowed: a model file is JSON; give a path ending .json (e.g. 'm.json')" in err, err


def test_save_refuses_another_suffix_and_takes_none(flight, tmp_path: Path) -> None:
    """T23-16 in the Python API: LearnedModel.save('m.npz') is refused; .json is written (a name without a suffix was
    too, and is refused since T32-B20: tests/test_bad_input_trial32_paths.py)."""
    model = learn_lr(flight)
    with _raises("model file '/tmp/x/m.npz' is not allowed: a model file is JSON; give a path ending .json (e.g. '/tmp/x/m.json')"):
        model.save("/tmp/x/m.npz")
    with _raises(f"model file {brief(str(tmp_path / 'm.npz'))} is not allowed: a model file is JSON; give a path ending .json"):
        model.save(tmp_path / "m.npz")
    assert not (tmp_path / "m.npz").exists()
    assert LearnedModel.load(model.save(tmp_path / "M.JSON")) == model
