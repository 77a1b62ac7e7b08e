"""The twenty-fourth bad-input trial's finding in learned models (T24-08): LearnedModel.load took a model file whose stats
contradict themselves: an EC-MER file with a return above 0, a return error that is not |predicted - true|, seed -1, a
champion history of an evaluation past those made, a negative error; an LR file with a stats entry no fit writes (a
top-level one was refused). Each stat a fit writes is now checked for its kind, range and relation to the others, and
an unknown entry beside a fit's stats is refused, while every model the code writes (and a caller's own stats) loads."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from neurohover import baseline_policy, evaluate, get_task_family
from neurohover.errors import NeurohoverError
from neurohover.models import LearnedModel, learn_ec_meno, learn_ec_mer, learn_lr


def _raises(fragment: str):
    return pytest.raises(NeurohoverError, match=re.escape(fragment))


@pytest.fixture(scope="module")
def flight():
    """A baseline episode of 200 steps on GHH-08's zero MDP, recorded."""
    return evaluate(baseline_policy(), get_task_family("ghh08").zero(), record=True, seed=1, n_steps=200).flight_data


@pytest.fixture(scope="module")
def files(flight, tmp_path_factory) -> dict[str, dict]:
    """The files of an EC-MER, an EC-MENO and an LR model, as dicts to edit."""
    out = tmp_path_factory.mktemp("models")
    models = {
        "ec-mer": learn_ec_mer(flight, baseline_policy(), budget=60, seed=3),
        "ec-meno": learn_ec_meno(flight, budget=300, seed=2),
        "lr": learn_lr(flight),
    }
    return {method: json.loads(model.save(out / f"{method}.json").read_text()) for method, model in models.items()}


def _load(d: dict, tmp_path: Path) -> LearnedModel:
    path = tmp_path / "m.json"
    path.write_text(json.dumps(d))
    return LearnedModel.load(path)


# --------------------------------------------------------------------------- every model the code writes loads


@pytest.mark.slow
@pytest.mark.parametrize(("budget", "seed"), [(5, 0), (30, 7), (150, 11)])
def test_ec_models_of_budgets_and_seeds_load(flight, budget: int, seed: int, tmp_path: Path) -> None:
    """T24-08: the new checks take EC-MER's and EC-MENO's models of several budgets, seeds, episodes and scalings."""
    for model in (
        learn_ec_mer(flight, baseline_policy(), budget=budget, seed=seed, episode_seed=seed + 1, episodes=1 + seed % 3),
        learn_ec_meno(flight, budget=budget * 4, seed=seed),
        learn_ec_meno(flight, budget=budget * 4, seed=seed, scaling="default"),
    ):
        assert LearnedModel.load(model.save(tmp_path / "m.json")) == model


@pytest.mark.slow
def test_ec_models_of_crashed_flights_and_the_plateau_stop_load(flight, tmp_path: Path) -> None:
    """T24-08: EC-MER given the recorded return of a crashed episode (as the experiments give it) and EC-MENO run to
    its plateau stop (budget null) load too."""
    crashed = evaluate(baseline_policy(), get_task_family("ghh08").zero(), record=True, seed=2, n_steps=200, episodes=3).flight_data
    policy = baseline_policy()
    for model in (learn_ec_mer(crashed, policy, -4.5e5, budget=20), learn_ec_meno(flight, seed=1)):
        assert LearnedModel.load(model.save(tmp_path / "m.json")) == model


# --------------------------------------------------------------------------- T24-08: stats against themselves


def _stats(key: str, value):
    return lambda d: d["stats"].__setitem__(key, value)


EDITS = {
    "ec-mer true_return": ("ec-mer", _stats("true_return", 5.0), "its stats.true_return 5.0 is not allowed: allowed a finite return in [-"),
    "ec-mer predicted_return": ("ec-mer", _stats("predicted_return", 5.0), "its stats.predicted_return 5.0 is not allowed: allowed a finite return in"),
    "ec-mer return_error": ("ec-mer", _stats("return_error", 1.0), "its stats.return_error 1.0 is not allowed: allowed |predicted_return - true_return| = "),
    "ec-mer seed": ("ec-mer", _stats("seed", -1), "its stats.seed -1 is not allowed: allowed an integer in 0..2**63-1 (the seed the fit ran with)"),
    "ec-mer episode_seed": ("ec-mer", _stats("episode_seed", 1.5), "its stats.episode_seed 1.5 is not allowed: allowed an integer in 0..2**63-1"),
    "ec-mer history past the evaluations": (
        "ec-mer",
        _stats("history", [[100, -1.0]]),
        "its stats.history [[100, -1.0]] is not allowed: allowed [evaluations, return] of each new champion, both rising, evaluations in 1..60",
    ),
    "ec-mer history not the champion's": (
        "ec-mer",
        lambda d: d["stats"]["history"][-1].__setitem__(1, d["stats"]["history"][-1][1] * 2),
        ("its stats.history [[1, ", "is not allowed: its last record is the champion's: a return of -"),
    ),
    "ec-mer history falling": (
        "ec-mer",
        lambda d: d["stats"]["history"].insert(1, [d["stats"]["history"][0][0], -1.0]),
        ("its stats.history [[1, ", "is not allowed: allowed [evaluations, return] of each new champion, both rising, evaluations in 1..60"),
    ),
    "ec-mer prototype_return_error": (
        "ec-mer",
        _stats("prototype_return_error", -5),
        "its stats.prototype_return_error -5 is not allowed: allowed a finite number >= 0",
    ),
    "ec-mer episodes": ("ec-mer", _stats("episodes", 10**6), "its stats.episodes 1000000 is not allowed: allowed an integer in 1..10,000"),
    "ec-mer budget null": ("ec-mer", _stats("budget", None), "its stats.budget None is not allowed: allowed an integer >= 1"),
    "ec-mer unknown entry": ("ec-mer", _stats("zzz", 1), "its stats entry 'zzz' is not allowed: the stats of a ec-mer fit hold only budget, evaluations"),
    "ec-meno scaling": ("ec-meno", _stats("scaling", "zz"), "its stats.scaling 'zz' is not allowed: allowed data or default (EC-MENO's gene scalings)"),
    "ec-meno scaling beside its gene scale": (
        "ec-meno",
        _stats("scaling", "default"),
        ("its stats.gene_scale [", "is not allowed: allowed |default parameters| (its scaling 'default')"),
    ),
    "ec-meno one_step_error": ("ec-meno", _stats("one_step_error", -1.0), "its stats.one_step_error -1.0 is not allowed: allowed a finite number >= 0"),
    "ec-meno excess": ("ec-meno", _stats("excess", 5.0), "its stats.excess 5.0 is not allowed: allowed (one_step_error - least_squares_one_step_error)"),
    "ec-meno least squares above": (
        "ec-meno",
        lambda d: d["stats"].update(least_squares_one_step_error=1.0, excess=None),
        "its stats.least_squares_one_step_error 1.0 is not allowed: allowed at most stats.one_step_error",
    ),
    "ec-meno unknown entry": ("ec-meno", _stats("estimated", True), "its stats entry 'estimated' is not allowed: the stats of a ec-meno fit hold only"),
    "lr unknown entry": ("lr", _stats("zzz", 1), "its stats entry 'zzz' is not allowed: the stats of a lr fit hold only estimator, intercepts"),
    "lr wind stats without a wind": (
        "lr",
        _stats("wind_fit_rounds", 1),
        "its stats.wind_fit_rounds 1 is not allowed: allowed only in the stats of a model with a wind",
    ),
}


@pytest.mark.parametrize("case", list(EDITS))
def test_model_stats_that_contradict_themselves_are_refused(case: str, files: dict, tmp_path: Path) -> None:
    """T24-08: each edit of a fit's stats was loaded as it was; now refused at load, naming the file, the stat, its value
    and what is allowed."""
    method, edit, fragment = EDITS[case]
    d = json.loads(json.dumps(files[method]))
    edit(d)
    fragments = (fragment,) if isinstance(fragment, str) else fragment  # in this order, the value (shortened) between
    with pytest.raises(NeurohoverError, match=re.escape(f"model file '{tmp_path / 'm.json'}': ") + ".*".join(map(re.escape, fragments))) as err:
        _load(d, tmp_path)
    assert str(err.value).count("\n") == 0  # one line


def test_an_ec_meno_history_must_end_at_its_champion(files: dict, tmp_path: Path) -> None:
    """T24-08: EC-MENO's last history record is minus the transitions times the champion's one-step error."""
    d = json.loads(json.dumps(files["ec-meno"]))
    d["stats"]["history"][-1][1] *= 0.5
    with _raises("its last record is the champion's: a return of -"):
        _load(d, tmp_path)


def test_an_lr_noise_std_must_be_the_estimate_its_stats_name(files: dict, tmp_path: Path) -> None:
    """T24-08: an LR model's noise std is stats.noise_std_<noise>; with the other estimate named it contradicts them."""
    d = json.loads(json.dumps(files["lr"]))
    d["stats"]["noise"] = "innovations"
    with _raises("is not allowed: its stats.noise 'innovations' gives stats.noise_std_innovations ["):
        _load(d, tmp_path)
    d["noise_std"] = d["stats"]["noise_std_innovations"]
    assert _load(d, tmp_path).noise_std == tuple(d["stats"]["noise_std_innovations"])  # the estimate named: as learn_lr(noise=...) writes


def test_a_callers_own_stats_still_load(flight, tmp_path: Path) -> None:
    """T24-08 leaves a caller's own stats (none of a fit's entries) as they were: only stats beside a fit's are refused."""
    model = LearnedModel(learn_lr(flight).params, (0.1,) * 6, "ec-mer", stats={"zzz": 1, "note": "mine"})
    assert LearnedModel.load(model.save(tmp_path / "m.json")).stats == model.stats


@pytest.mark.slow
def test_the_findings_steps_on_the_command_line(cli, tmp_path: Path) -> None:
    """T24-08 as found: fly --record, learn-model --method ec-mer --budget 10 --out me.json, then stats.true_return set to
    5.0 (or stats.return_error 1.0) in the file: LearnedModel.load refuses it, naming the stat."""
    data, model = tmp_path / "f.npz", tmp_path / "me.json"
    assert cli("fly", "--task", "ghh08", "--episodes", "1", "--record", str(data))[0] == 0
    rc, _, err = cli("learn-model", "--flight-data", str(data), "--method", "ec-mer", "--budget", "10", "--out", str(model))
    assert rc == 0, err
    written = json.loads(model.read_text())
    assert LearnedModel.load(model).method == "ec-mer"  # as written, it loads
    for key, value in (("true_return", 5.0), ("return_error", 1.0)):
        model.write_text(json.dumps({**written, "stats": {**written["stats"], key: value}}))
        with _raises(f"model file '{model}': its stats.{key} {value} is not allowed"):
            LearnedModel.load(model)


def test_learn_ec_mer_refuses_a_true_return_above_0() -> None:
    """T24-08: learn_ec_mer(..., true_return=5.0) learned and returned a model whose file load then refuses (a return is
    minus a sum of squares); refused before learning, as a True was (T16-18)."""
    import neurohover as nh
    from neurohover.models import learn_ec_mer

    base = nh.baseline_policy()
    fd = nh.evaluate(base, nh.get_task_family("ghh08").zero(), episodes=1, record=True, n_steps=20).flight_data
    with pytest.raises(NeurohoverError, match=r"^true_return=5\.0 is not allowed: a return is in \[-1\.75e\+10, 0\]"):
        learn_ec_mer(fd, base, 5.0, budget=2)


@pytest.mark.parametrize(("episodes", "says"), [(1.5, "is not allowed"), (True, "is not allowed"), (0, "is out of range")])
def test_learn_ec_mer_tells_a_non_integer_episodes_from_one_out_of_range(episodes, says: str) -> None:
    """T24-11: learn_ec_mer's episodes=1.5 was called 'out of range'; a non-integer is not allowed (errors.whole_in)."""
    import neurohover as nh
    from neurohover.models import learn_ec_mer

    base = nh.baseline_policy()
    fd = nh.evaluate(base, nh.get_task_family("ghh08").zero(), episodes=1, record=True, n_steps=20).flight_data
    with pytest.raises(NeurohoverError, match=rf"^episodes={episodes!r} {says}: allowed an integer in 1\.\.[0-9,]+ \(per candidate\)$"):
        learn_ec_mer(fd, base, -1.0, budget=2, episodes=episodes)
