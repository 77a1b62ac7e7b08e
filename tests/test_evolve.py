"""Whole evolution runs (neurohover.evolution.evolve) and the learning commands (evolve, learn-model).

Short episodes (300-600 control steps) and small budgets keep every run well under a second.
"""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path

import numba
import numpy as np
import pytest

from neurohover.cli import main
from neurohover.errors import CheckpointReplaced, NeurohoverError
from neurohover.evolution.evolve import (
    HISTORY_COLUMNS,
    EvolutionInterrupted,
    evolve,
    parse_resampling,
    read_history_csv,
    validation_return,
)
from neurohover.policies import Policy, load_policy, prototype
from neurohover.tasks import get_task_family

GHH08 = get_task_family("ghh08")
FGHH = get_task_family("fghh", 0.3)
TWO_THREADS = numba.config.NUMBA_NUM_THREADS >= 2


def _key(result) -> tuple:
    """Everything of a result that must be reproducible (not the wall times)."""
    return (
        result.champion.genome.tobytes(),
        result.champion_return,
        result.episodes,
        result.steps,
        result.evaluations,
        result.generations,
        result.stop_reason,
        [(h.generation, h.evaluations, h.episodes, h.generation_episodes, h.champion_return) for h in result.history],
    )


# --------------------------------------------------------------------------------- input checks


def test_resampling_specs() -> None:
    assert str(parse_resampling("fixed:5")) == "fixed:5" and parse_resampling("fixed:5").k == 5
    assert parse_resampling("race:0.2").delta == 0.2 and str(parse_resampling("race:0.2")) == "race:0.2"
    assert parse_resampling(None).kind == "fixed" and parse_resampling(None).k == 1
    for bad, words in [
        ("race:1.5", "between 0 and 1"),
        ("race:0", "between 0 and 1"),
        ("race:x", "between 0 and 1"),
        ("fixed:0", ">= 1"),
        ("fixed:-2", ">= 1"),
        ("fixed:2.5", ">= 1"),
        ("resample:3", "unknown resampling"),
        ("fixed", "unknown resampling"),
    ]:
        with pytest.raises(NeurohoverError, match=words):
            parse_resampling(bad)


def test_bad_arguments_are_clear_errors() -> None:
    mdp = GHH08.zero()
    cases = [
        (dict(budget=0), "budget=0 is out of range"),
        (dict(seed=-1), "seed=-1 is out of range"),
        (dict(topology="rnn"), "unknown topology"),
        (dict(prototype="random"), "prototype must be"),
        (dict(prototype=prototype("slp"), topology="mlp"), "slp policy but topology"),
        (dict(optimizer="sgd"), "unknown optimizer"),
        (dict(resampling="race:0.5"), "needs the generational method"),
        (dict(settings={"pop_sise": 10}), "unknown steady-state setting"),
        (dict(settings={"elite_size": 60}), "bad steady-state settings"),
        (dict(optimizer="cma", settings={"sigma0": -1}), "sigma0"),
        (dict(n_steps=0), "n_steps=0"),
        (dict(resume=True), "needs the checkpoint path"),
    ]
    for kwargs, words in cases:
        with pytest.raises(NeurohoverError, match=words):
            evolve(mdp, **{"budget": 60, "n_steps": 50, **kwargs})
    with pytest.raises(NeurohoverError, match="needs an MDP, a learned model or a task family"):
        evolve("ghh08", budget=10)
    with pytest.raises(NeurohoverError, match="generational method"):
        evolve(FGHH, method="steady-state", budget=10)


# --------------------------------------------------------------------------------- building blocks


@pytest.mark.parametrize("family", [GHH08, get_task_family("ghh09"), FGHH])
def test_mdp_stream_is_the_family_sampler_in_batches(family) -> None:
    stream = np.random.default_rng(7)  # a run draws its MDPs in batches of sample_rows from one generator
    rows = np.vstack([family.sample_rows(stream, 3), family.sample_rows(stream, 1), family.sample_rows(stream, 4)])
    rng = np.random.default_rng(7)
    expected = np.stack([family.sample(rng).row() for _ in range(8)])
    np.testing.assert_array_equal(rows, expected)


# --------------------------------------------------------------------------------- evolution


def test_steady_state_improves_the_mean_return_from_the_baseline() -> None:
    mdp = GHH08.mdp("train:1")
    result = evolve(mdp, topology="mlp", prototype="baseline", budget=1000, seed=1, n_steps=600, threads=1)
    assert result.episodes == 1000 and result.evaluations == 1000 and result.stop_reason == "budget"
    assert result.generations == 1 + 950  # the initial population, then one offspring per generation
    # Re-evaluate on fresh episodes (not the optimistic best-ever fitness).
    base = validation_return(prototype("mlp", "baseline"), mdp, episodes=20, seed=11, n_steps=600)
    champ = validation_return(result.champion, mdp, episodes=20, seed=11, n_steps=600)
    se = math.hypot(base.std(), champ.std()) / math.sqrt(20)
    assert champ.mean() - base.mean() > 20 * se, (base.mean(), champ.mean(), se)
    assert champ.mean() > 0.2 * base.mean()  # at least 5 times less error (about 50x here)
    # History: one record per new champion (improving), the last one at the end of the run.
    h = result.history
    assert [r.champion_return for r in h] == sorted(r.champion_return for r in h)
    assert h[0].episodes == 50 and h[-1].episodes == 1000 and h[-1].champion_return == result.champion_return
    meta = result.champion.metadata
    assert meta["method"] == "steady-state" and meta["target"] == "ghh08/train:1" and meta["episodes"] == 1000
    assert result.settings["settings"]["pop_size"] == 50 and result.settings["resampling"] == "fixed:1"


def test_plateau_stops_a_run_without_budget() -> None:
    result = evolve(GHH08.zero(), topology="slp", n_steps=30, seed=2, settings={"plateau_threshold": 40, "pop_size": 10, "elite_size": 9})
    assert result.stop_reason == "plateau"
    last_new = result.history[-2].evaluations if len(result.history) > 1 else 10
    assert result.evaluations - last_new >= 40


def test_fixed_k_on_an_mdp_counts_episodes() -> None:
    result = evolve(GHH08.mdp("train:2"), topology="slp", budget=300, resampling="fixed:3", seed=4, n_steps=200, settings={"pop_size": 20, "elite_size": 19})
    assert result.episodes == 300 and result.evaluations == 100  # 20 + 80 candidates, 3 episodes each


def test_generational_fixed_resampling_on_fghh() -> None:
    result = evolve(FGHH, topology="mlp", budget=600, resampling="fixed:3", seed=3, n_steps=300)
    assert result.settings["method"] == "generational" and result.stop_reason == "budget"
    assert result.generations == 4 and result.episodes == 600  # 150 episodes per generation
    assert [h.generation_episodes for h in result.history] == [150] * 4
    assert [h.generation for h in result.history] == [1, 2, 3, 4]
    assert result.champion.metadata["target"] == "fghh/G(sigma=0.3)"


def test_generational_races_record_episodes_per_generation() -> None:
    result = evolve(FGHH, topology="mlp", budget=700, resampling="race:0.5", seed=3, n_steps=300)
    eps = [h.generation_episodes for h in result.history]
    assert len(eps) == result.generations >= 2
    assert all(50 <= e <= 500 for e in eps)  # every candidate once, at most t_limit = 10 times
    assert sum(eps) == result.episodes >= 700
    assert len(set(eps)) > 1 or eps[0] > 50  # races fly extra episodes where candidates are undecided
    assert np.diff([h.episodes for h in result.history]).tolist() == eps[1:]


def test_generational_method_on_one_mdp() -> None:
    result = evolve(GHH08.mdp("train:1"), method="generational", resampling="race:0.5", budget=200, seed=1, n_steps=200)
    assert result.settings["method"] == "generational" and result.episodes >= 200
    assert all(h.generation_episodes >= 50 for h in result.history)


@pytest.mark.parametrize("target", [GHH08.mdp("train:1"), FGHH], ids=["mdp", "family"])
def test_cma_es_on_the_same_budget(target) -> None:
    result = evolve(target, topology="slp", optimizer="cma", budget=400, seed=2, n_steps=300, resampling="fixed:2" if target is FGHH else None)
    popsize = 4 + int(3 * math.log(40))
    k = 2 if target is FGHH else 1
    assert result.stop_reason == "budget" and 400 <= result.episodes < 400 + popsize * k
    assert result.settings["optimizer"] == "cma" and result.champion.metadata["optimizer"] == "cma"
    assert math.isfinite(result.champion_return)


def test_cma_es_improves_on_an_mdp() -> None:
    mdp = GHH08.mdp("train:1")
    result = evolve(mdp, topology="slp", optimizer="cma", budget=600, seed=2, n_steps=400)
    base = validation_return(prototype("slp", "baseline"), mdp, episodes=10, seed=3, n_steps=400)
    champ = validation_return(result.champion, mdp, episodes=10, seed=3, n_steps=400)
    assert champ.mean() > 0.2 * base.mean()


@pytest.mark.skipif(not TWO_THREADS, reason="needs 2 kernel threads")
@pytest.mark.parametrize(
    "target,kwargs",
    [
        (GHH08.mdp("train:3"), dict()),
        (FGHH, dict(resampling="race:0.6")),
        (FGHH, dict(resampling="fixed:2", optimizer="cma")),
    ],
    ids=["steady", "race", "cma-family"],
)
def test_results_do_not_depend_on_threads(target, kwargs) -> None:
    runs = [evolve(target, topology="mlp", budget=400, seed=8, n_steps=300, threads=t, **kwargs) for t in (1, 2)]
    assert _key(runs[0]) == _key(runs[1])


def test_seed_changes_the_run() -> None:
    a, b = (evolve(GHH08.mdp("train:0"), topology="slp", budget=200, seed=s, n_steps=200) for s in (1, 2))
    assert _key(a) != _key(b)


@pytest.mark.slow
@pytest.mark.parametrize(
    "target,kwargs",
    [
        (GHH08.mdp("train:1"), dict()),
        (GHH08.mdp("train:1"), dict(optimizer="cma")),
        (FGHH, dict(resampling="race:0.6")),
        (FGHH, dict(resampling="race:auto")),  # its delta changes race by race: the checkpoint keeps it
        (FGHH, dict(resampling="fixed:2", optimizer="cma")),
    ],
    ids=["steady", "cma-mdp", "race", "race-auto", "cma-family"],
)
def test_interrupted_and_resumed_equals_uninterrupted(tmp_path: Path, target, kwargs) -> None:
    common = dict(topology="slp", seed=3, n_steps=300, **kwargs)
    full = evolve(target, budget=600, **common)
    ckpt = tmp_path / "run.checkpoint.json"

    def stop_midway(info) -> None:
        if info.episodes >= 250 and not info.done:
            raise KeyboardInterrupt

    with pytest.raises(EvolutionInterrupted) as err:
        evolve(target, budget=600, checkpoint=ckpt, progress=stop_midway, progress_every_s=0, **common)
    assert err.value.checkpoint == ckpt and ckpt.is_file() and not list(ckpt.parent.glob(ckpt.name + "*.tmp"))
    state = json.loads(ckpt.read_text())
    assert 250 <= state["counters"]["episodes"] < 600
    resumed = evolve(target, budget=600, checkpoint=ckpt, resume=True, **common)
    assert _key(resumed) == _key(full)
    # A finished run with a smaller budget continues to the larger one, also bit for bit.
    with pytest.warns(CheckpointReplaced):  # the interrupted run's checkpoint is replaced, and said so (T38-B08)
        evolve(target, budget=300, checkpoint=ckpt, **common)
    extended = evolve(target, budget=600, checkpoint=ckpt, resume=True, **common)
    assert _key(extended) == _key(full)


def test_resume_refuses_another_run(tmp_path: Path) -> None:
    ckpt = tmp_path / "c.json"
    evolve(GHH08.zero(), topology="slp", budget=60, seed=1, n_steps=50, checkpoint=ckpt)
    with pytest.raises(NeurohoverError, match=r"\(seed: the checkpoint.s 1, given 2\)"):
        evolve(GHH08.zero(), topology="slp", budget=100, seed=2, n_steps=50, checkpoint=ckpt, resume=True)
    with pytest.raises(NeurohoverError, match="does not exist"):
        evolve(GHH08.zero(), topology="slp", budget=100, seed=1, n_steps=50, checkpoint=tmp_path / "none.json", resume=True)


def test_learned_model_and_policy_prototype_are_accepted() -> None:
    from neurohover.models import LearnedModel

    model = LearnedModel(tuple(np.array([-0.2, -0.4, -0.5, -0.5, -40.0, -7.5, 20.0, -6.5, -21.0, -5.5, 45.0])), (0.2, 0.3, 0.6, 0.15, 0.25, 0.07), "lr")
    seed_policy = Policy("slp", prototype("slp", "baseline").genome, {"name": "mine"})
    result = evolve(model, topology="slp", prototype=seed_policy, budget=120, seed=1, n_steps=200)
    assert result.champion.metadata["target"] == "model/lr" and "name" not in result.champion.metadata  # the seed's record is its own


def test_validation_episodes_are_fresh_and_reproducible() -> None:
    policy = prototype("mlp", "baseline")
    a = validation_return(policy, FGHH, episodes=5, seed=1, n_steps=200)
    np.testing.assert_array_equal(a, validation_return(policy, FGHH, episodes=5, seed=1, n_steps=200))
    assert len(set(a.tolist())) == 5


# --------------------------------------------------------------------------------- commands


@pytest.mark.slow
def test_evolve_command_writes_policy_history_and_resumes(cli, tmp_path: Path) -> None:
    out = tmp_path / "champ.json"
    args = ["evolve", "--task", "ghh08", "--mdp", "train:1", "--topology", "slp", "--episode-steps", "300", "--seed", "5", "--out", str(out), "--json"]
    rc, stdout, _ = cli(*args, "--budget", "300")
    assert rc == 0
    summary = json.loads(stdout)
    policy = load_policy(out)
    assert policy.topology == "slp"
    meta = json.loads(out.read_text())
    for key in ("task", "mdp", "optimizer", "resampling", "budget", "seed", "champion_return", "validation_return"):
        assert key in meta, key
    assert meta["task"] == "ghh08" and meta["mdp"] == "train:1" and meta["budget"] == 300 and meta["seed"] == 5
    assert meta["validation_episodes"] == 10 and math.isfinite(meta["validation_return"])
    assert summary["champion_return"] == meta["champion_return"]
    history = read_history_csv(Path(f"{out}.history.csv"))
    assert Path(f"{out}.history.csv").read_text().splitlines()[0] == ",".join(HISTORY_COLUMNS)
    assert history[-1].episodes == 300
    assert Path(f"{out}.checkpoint.json").is_file()
    # --resume with a larger budget continues to exactly what one run of that budget gives.
    rc, _, _ = cli(*args, "--budget", "600", "--resume")
    assert rc == 0
    resumed = load_policy(out)
    direct = tmp_path / "direct.json"
    rc, _, _ = cli(*[a if a != str(out) else str(direct) for a in args], "--budget", "600")
    assert rc == 0
    np.testing.assert_array_equal(resumed.genome, load_policy(direct).genome)
    assert read_history_csv(Path(f"{out}.history.csv"))[-1].episodes == 600
    # Without --resume a run starts afresh and says so, but only once it is under way: a refused one overwrites nothing.
    before = Path(f"{out}.checkpoint.json").read_bytes()
    rc, _, err = cli(*args, "--budget", "300", "--setting", "pop_size=1")
    assert rc == 2 and "starting afresh" not in err and Path(f"{out}.checkpoint.json").read_bytes() == before
    rc, _, err = cli(*args, "--budget", "300")
    assert rc == 0 and "starting afresh" in err


def test_evolve_command_over_the_family_with_races(cli, tmp_path: Path) -> None:
    out = tmp_path / "generic.json"
    rc, stdout, _ = cli(
        "evolve",
        "--task",
        "fghh",
        "--sigma",
        "0.2",
        "--resampling",
        "race:0.5",
        "--budget",
        "200",
        "--episode-steps",
        "200",
        "--seed",
        "1",
        "--out",
        str(out),
        "--json",
    )
    assert rc == 0
    meta = json.loads(out.read_text())
    assert meta["mdp"] == "G" and meta["sigma"] == 0.2 and meta["method"] == "generational" and meta["resampling"] == "race:0.5"
    assert all(h.generation_episodes >= 50 for h in read_history_csv(Path(f"{out}.history.csv")))


def test_evolve_command_ctrl_c_saves_the_checkpoint(cli, tmp_path: Path, monkeypatch) -> None:
    from neurohover.cli import learning as commands_learning

    def interrupt(self, info) -> None:
        raise KeyboardInterrupt

    monkeypatch.setattr(commands_learning._Bar, "__call__", interrupt)
    out = tmp_path / "p.json"
    rc, _, err = cli("evolve", "--task", "ghh08", "--topology", "slp", "--budget", "100000", "--episode-steps", "3000", "--out", str(out))
    assert rc == 130
    assert f"checkpoint saved to {out}.checkpoint.json" in err and "--resume" in err
    assert Path(f"{out}.checkpoint.json").is_file() and not out.exists()


@pytest.mark.parametrize(
    "argv,words",
    [
        (["--resampling", "race:1.5"], "strictly between 0 and 1"),
        (["--resampling", "fixed:0"], "K must be an integer in 1..100,000"),
        (["--budget", "0"], "--budget 0 is out of range"),
        (["--seed-policy", "nope.json"], "no such file"),
        (["--resume"], "no checkpoint"),
        (["--mdp", "train:1", "--resampling", "race:0.5"], "needs the generational method"),
        (["--mdp", "train:99"], "out of range"),
        (["--wind", "9,0"], "out of range"),
    ],
)
def test_evolve_command_bad_input(cli, tmp_path: Path, argv, words) -> None:
    budget = [] if "--budget" in argv else ["--budget", "60"]  # an option given twice is refused on its own
    rc, _, err = cli("evolve", "--task", "ghh08", *budget, "--episode-steps", "50", "--out", str(tmp_path / "x.json"), *argv)
    assert rc == 2
    assert err.startswith("neurohover evolve: error:") and words in err


def test_learn_model_command_prints_learned_next_to_true(cli, tmp_path: Path) -> None:
    data = tmp_path / "flight.npz"
    rc, _, _ = cli("fly", "--task", "ghh08", "--mdp", "zero", "--episodes", "2", "--seed", "3", "--record", str(data))
    assert rc == 0
    model_file = tmp_path / "model.json"
    rc, out, _ = cli("learn-model", "--flight-data", str(data), "--method", "lr", "--out", str(model_file))
    assert rc == 0
    assert "true ones of ghh08/zero" in out and "C_p" in out and "D_r" in out
    from neurohover.models import LearnedModel

    assert LearnedModel.load(model_file).method == "lr"
    rc, out, _ = cli("learn-model", "--flight-data", str(data), "--method", "ec-meno", "--budget", "100", "--out", str(tmp_path / "meno.json"))
    assert rc == 0 and "ec-meno model written" in out


def test_learn_model_command_bad_input(cli, tmp_path: Path) -> None:
    rc, _, err = cli("learn-model", "--flight-data", str(tmp_path / "missing.npz"), "--method", "lr", "--out", str(tmp_path / "m.json"))
    assert rc == 2 and "no such flight-data file" in err
    rc, _, err = cli("learn-model", "--flight-data", str(tmp_path / "missing.npz"), "--method", "ec-mer", "--budget", "0", "--out", str(tmp_path / "m.json"))
    assert rc == 2 and "--budget 0 is out of range" in err


def test_commands_have_help(capsys) -> None:
    for command in ("evolve", "learn-model"):
        with pytest.raises(SystemExit) as exit_info:
            main([command, "--help"])
        assert exit_info.value.code == 0
        assert "usage: neurohover " + command in capsys.readouterr().out


def test_generational_evolution_over_fghh_beats_its_seed_on_fresh_mdps() -> None:
    """Evolving a generic policy over G (fixed resampling) improves on the baseline seed on MDPs
    the run never saw; the elitist generational method on raw returns (a preset) keeps that progress."""
    from neurohover import evaluate, get_task_family, prototype

    family = get_task_family("fghh", 0.3)
    result = evolve(family, topology="mlp", prototype="baseline", resampling="fixed:3", budget=3000, seed=2, n_steps=600, settings="raw-elitist")
    ev = evaluate([result.champion, prototype("mlp", "baseline")], family.test_mdps()[:30], seed=8, n_steps=600)
    assert not ev.crashed[0].any()
    assert np.median(ev.returns[0]) > 2 * np.median(ev.returns[1])  # returns are negative: less than half the error


def test_a_ctrl_c_after_the_last_generation_check_still_reaches_the_caller() -> None:
    import signal

    from neurohover.evolution.run import InterruptFlag

    before = signal.getsignal(signal.SIGINT)
    with pytest.raises(KeyboardInterrupt):
        with InterruptFlag() as flag:
            assert signal.getsignal(signal.SIGINT) != before
            flag._handler(signal.SIGINT, None)  # arrives after the last check; the block ends normally
    assert signal.getsignal(signal.SIGINT) == before  # the previous handler is back


def test_two_equal_runs_give_equal_results_whatever_their_wall_clock() -> None:
    from neurohover.policies import Policy, prototype

    mdp = get_task_family("ghh08").mdp("train:1")
    a = evolve(mdp, budget=100, n_steps=50, seed=3, threads=1)
    b = evolve(mdp, budget=100, n_steps=50, seed=3, threads=1)
    assert a == b and a.history == b.history
    # The clocks are not part of a result: the same run read an hour later on another machine is equal.
    late = [dataclasses.replace(h, wall_seconds=h.wall_seconds + 3600.0) for h in b.history]
    b = dataclasses.replace(b, seconds=b.seconds + 3600.0, kernel_seconds=b.kernel_seconds + 3600.0, history=tuple(late))
    assert a == b and a.history == b.history
    assert a != evolve(mdp, budget=100, n_steps=50, seed=4, threads=1)
    p = prototype("mlp", "baseline")
    assert p == Policy("mlp", p.genome.copy(), {"note": "metadata does not count"}) and len({p, prototype("mlp", "baseline")}) == 1
    assert p != prototype("mlp", "zero") and p != prototype("slp", "baseline")


def test_a_resume_with_other_sensors_is_refused(tmp_path: Path) -> None:
    """Issue 34's bug: a noisy-sensor run's checkpoint recorded the same target as an exact-sensor one, so a
    resume could silently continue it with other sensors."""
    from neurohover.tasks import Sensor, get_task_family

    exact = get_task_family("ghh08")
    noisy = exact.with_sensor(Sensor.of(obs_noise=0.5))
    ckpt = tmp_path / "run.ckpt.json"
    common = dict(topology="slp", prototype="baseline", seed=3, n_steps=50)
    evolve(noisy, budget=60, checkpoint=ckpt, **common)
    saved = json.loads(ckpt.read_text())["config"]["target"]
    assert saved["sensor"] == noisy.sensor.to_dict() and "sensor" not in evolve(exact, budget=60, **common).settings["target"]
    with pytest.raises(NeurohoverError, match=r"written by a different run \(target.sensor: the checkpoint.s \{.*, given None\)"):
        evolve(exact, budget=120, checkpoint=ckpt, resume=True, **common)
    assert evolve(noisy, budget=120, checkpoint=ckpt, resume=True, **common).episodes >= 60  # the same sensors resume


def test_race_auto_matches_the_cost_of_fixed_resampling() -> None:
    """race:auto (Section 7's automatic delta): each race's delta narrows when the last race cost more than fixed:K's
    K x lambda episodes and widens when it cost less, within its range."""
    from neurohover.evolution.config import AUTO_RANGE, AUTO_STEP, next_auto_delta, parse_resampling

    spec = parse_resampling("race:auto")
    assert (spec.kind, spec.auto, spec.k, str(spec)) == ("race", True, 5, "race:auto") and str(parse_resampling("race:auto:10")) == "race:auto:10"
    with pytest.raises(NeurohoverError, match="race:auto\\[:K\\] matches fixed:K's cost, K an integer in 1..10"):
        parse_resampling("race:auto:0")
    assert next_auto_delta(0.5, 300, 250) == pytest.approx(0.5 * AUTO_STEP) and next_auto_delta(0.5, 200, 250) == pytest.approx(0.5 / AUTO_STEP)
    assert next_auto_delta(AUTO_RANGE[0], 999, 250) == AUTO_RANGE[0] and next_auto_delta(AUTO_RANGE[1], 0, 250) == AUTO_RANGE[1]
    run = evolve(FGHH, topology="slp", resampling="race:auto", budget=2000, seed=4, n_steps=100)
    fixed_cost = 5 * 50 * run.generations
    assert run.settings["resampling"] == "race:auto" and 0.5 * fixed_cost <= run.episodes <= 1.5 * fixed_cost


@pytest.mark.slow
def test_evolve_says_when_the_plateau_ends_a_run_before_its_budget(tmp_path: Path, capsys) -> None:
    """issue 37: a --budget on one MDP is a cap; a run the plateau stopped first said nothing of it."""
    args = ["evolve", "--task", "ghh08", "--mdp", "train:0", "--episode-steps", "20", "--validation-episodes", "1", "--out", str(tmp_path / "p.json")]
    assert main([*args, "--budget", "100000"]) == 0
    err = capsys.readouterr().err
    assert "note: stopped by plateau after" in err and "of the --budget 100,000 episodes: the budget is a cap, not a length" in err
    assert main([*args, "--budget", "100"]) == 0  # the budget ends it, at a generation's boundary: no note
    assert "note:" not in capsys.readouterr().err
    assert main([*args, "--budget", "20"]) == 0  # below the first population of 50: flown whole, and said (second trial)
    assert "note: flew 50 episodes for the --budget 20" in capsys.readouterr().err


@pytest.mark.parametrize(
    "damage, message",
    [
        (lambda s: [s], "is not an evolution checkpoint"),
        (lambda s: s.pop("config"), "damaged checkpoint: it has no 'config' entry"),
        (lambda s: s.update(optimizer_state="x"), "cannot restore the optimiser \\(state dict is a str"),
        (lambda s: s["optimizer_state"].update(population={"shape": [50, 3], "data": [0.0] * 150}), "population has shape \\(50, 3\\), expected \\(n, 42\\)"),
        (lambda s: s["optimizer_state"].update(champion_genome={"shape": [3], "data": [0.0] * 3}), "optimiser \\(champion genome has shape"),
        (lambda s: s["optimizer_state"].update(rng={"bit_generator": "XX"}), "rng={'bit_generator': 'XX'} is not allowed: allowed a PCG64 state table"),
        (lambda s: s.pop("counters"), "it has no 'counters' entry"),
        (lambda s: s["counters"].update(episodes=-5), "counter 'episodes' is -5, not a count"),
        (lambda s: s["counters"].update(wall_seconds=-1.0), "counter 'wall_seconds' is -1.0"),
        (lambda s: s["champion"].update(genome=[1.0, 2.0, 3.0]), "champion genome has shape \\(3,\\), expected \\(42,\\)"),
        (lambda s: s["champion"].update(genome=None, **{"return": "abc"}), "damaged checkpoint: could not convert string to float"),
        (lambda s: s["champion"].update(genome=[float("nan")] * 42), "the champion genome holds a gene that is not a finite number"),  # eighth trial
        (lambda s: s["champion"].update(**{"return": "nan"}), "the champion's return is nan"),
        (lambda s: s["optimizer_state"].update(population={"shape": [1, 42], "data": [float("nan")] * 42}), "population holds a gene that is not a finite"),
        (lambda s: s.update(history=["x"]), "damaged checkpoint: history row 0 \\(from 0\\) is .x.: allowed a list of 6 values"),
        (lambda s: s.update(mdp_stream=None), "damaged checkpoint: mdp_stream=None is not allowed"),
    ],
)
def test_a_damaged_checkpoint_is_refused_by_name(tmp_path: Path, damage, message) -> None:
    """Issue 37's fifth trial: a hand-damaged checkpoint raised AttributeError, KeyError or TypeError from inside the
    restore, or was accepted (negative counters, a short champion genome, a population of other genomes)."""
    ckpt = tmp_path / "run.ckpt.json"
    common = dict(topology="mlp", prototype="baseline", seed=3, n_steps=20)
    evolve(GHH08, budget=60, checkpoint=ckpt, **common)
    state = json.loads(ckpt.read_text())
    out = damage(state)
    ckpt.write_text(json.dumps(out if isinstance(out, list) else state))
    with pytest.raises(NeurohoverError, match=message):
        evolve(GHH08, budget=120, checkpoint=ckpt, resume=True, **common)


def test_a_steady_state_optimiser_refuses_a_state_of_other_genomes() -> None:
    from neurohover.evolution.steady_state import SteadyStateNE

    opt = SteadyStateNE(np.zeros(5), seed=1)
    opt.tell(np.zeros(len(opt.ask())))
    state = opt.state_dict()
    back = SteadyStateNE.from_state_dict(json.loads(json.dumps(state))).state_dict()
    assert {k: v for k, v in back.items() if k != "wall_seconds"} == {k: v for k, v in state.items() if k != "wall_seconds"}
    with pytest.raises(ValueError, match="fitness has shape \\(2,\\): one return per genome of the population"):
        SteadyStateNE.from_state_dict({**state, "fitness": {"shape": [2], "data": [0.0, 0.0]}})
    with pytest.raises(ValueError, match="pending genomes has shape \\(1, 4\\), expected \\(n, 5\\)"):
        SteadyStateNE.from_state_dict({**state, "pending": {"shape": [1, 4], "data": [0.0] * 4}})
