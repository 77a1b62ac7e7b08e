"""Bad input, trial 26: policy files' run records, model files' stats and policy sets (T26-B04, the policy part;
T26-B06, T26-B07, T26-B08, T26-B12, T26-B13 and T26-B14).

A policy file's generations were never held to its evaluations (generations 40 or 0 beside the 50 evaluations of
generation 1, which the checkpoint loader refuses); its episodes to its budget (5,000 episodes of a budget of 10, or a
plateau stop after 1,000 of them); its task and MDP, once mdp_params was gone, to the registered families (ghh10,
train:12, test:999); its sensor to its mdp_params' (a delay of 5 beside 2); its seconds, a model file's and a manifest's
to 100 years (1e30). A model file's residual rms 10 times the one its stationary noise estimate was made of loaded. A
policy set took an slp of 40 genes as a specialised policy, ignored a stray specialised_10.json and loaded a chain's set
without its ancestor.json. Each is refused by name; everything the code writes still loads."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from conftest import CliRun
from policy_edits import edited, refused

import neurohover as nh
from neurohover.errors import NeurohoverError
from neurohover.models.model import LearnedModel
from neurohover.policy_records import policy_record_problem
from neurohover.policysets import build_policy_set, load_policy_set

SHORT = ("--episode-steps", "20", "--validation-episodes", "1", "--seed", "1")


@pytest.fixture(scope="module")
def written(tmp_path_factory) -> Path:
    """What the trial wrote: steady state on ghh08/train:0 (budget 10: 50 episodes, generation 1), the same through a
    sensor of delay 2, a generational run over G (pop_size 5, fixed:2, budget 12), an LR model and a built ghh08 set."""
    from neurohover.cli import main
    from neurohover.evaluate import evaluate_jobs
    from neurohover.models.lr import learn_lr
    from neurohover.policies import baseline_policy
    from neurohover.tasks import get_task_family

    where = tmp_path_factory.mktemp("written26")
    runs = {
        "p": ["--mdp", "train:0", "--budget", "10"],
        "pd": ["--mdp", "train:0", "--budget", "10", "--obs-delay", "2"],
        "g": ["--mdp", "G", "--budget", "12", "--resampling", "fixed:2", "--setting", "pop_size=5", "--setting", "select_size=2"],
    }
    for name, extra in runs.items():
        argv = ["evolve", "--task", "ghh08", "--topology", "slp", "--seed-policy", "baseline", *extra, *SHORT, "--out", str(where / f"{name}.json")]
        assert main(argv) == 0, name
    mdp = get_task_family("ghh08").training_mdps()[1]
    ev = evaluate_jobs([baseline_policy()], [mdp], [0], [0], [0], record=[True], n_steps=400)
    learn_lr(ev.flight_data).save(where / "m.json")
    build_policy_set("ghh08", where / "bp", budget=10, n_steps=20, safety_episodes=1)
    return where


def test_everything_written_still_loads(written: Path) -> None:
    for name in ("p", "pd", "g"):
        assert policy_record_problem(nh.load_policy(written / f"{name}.json").metadata) == "", name
    p, g = nh.load_policy(written / "p.json").metadata, nh.load_policy(written / "g.json").metadata
    assert (p["episodes"], p["evaluations"], p["generations"], p["budget"]) == (50, 50, 1, 10)
    assert (g["method"], g["episodes"], g["evaluations"], g["generations"]) == ("generational", 20, 10, 2)
    LearnedModel.load(written / "m.json")
    (written / "bp" / "ghh08" / "README").write_text("notes: a file of another name is left alone\n")
    ps = load_policy_set("ghh08", written / "bp")
    assert ps.manifest["lineage"] == "chain" and all(p.topology == "mlp" for p in (ps.generic, *ps.specialised))
    for task in ("ghh08", "ghh09", "fghh"):
        load_policy_set(task)


@pytest.mark.parametrize(("generations", "evaluations"), [(40, 89), (0, 0), (2, 51)])
def test_generations_agree_with_evaluations_by_the_checkpoints_rule(written: Path, tmp_path: Path, generations: int, evaluations: int) -> None:
    """T26-B04: pop_size 50, elite_size 49: generation g is 50 + (g - 1) evaluations, as a checkpoint is held to."""
    refused(
        edited(written / "p.json", tmp_path / "b04.json", generations=generations),
        f"its generations {generations} is not allowed beside its evaluations 50: generation {generations} of a steady-state run is "
        f"{evaluations} evaluations (pop_size 50, then 1 a generation, by its settings)",
    )


def test_a_generational_run_evaluates_its_population_each_generation(written: Path, tmp_path: Path) -> None:
    refused(edited(written / "g.json", tmp_path / "g3.json", generations=3), "generation 3 of a generational run is 15 evaluations (pop_size 5 a generation")
    # a longer run that agrees with itself (and its budget) loads
    nh.load_policy(edited(written / "p.json", tmp_path / "ok.json", budget=60, episodes=60, evaluations=60, generations=11))


def test_episodes_agree_with_the_budget_and_the_stop(written: Path, tmp_path: Path) -> None:
    """T26-B06: a run stops at the first generation boundary at or past its budget, and by its budget first."""
    refused(
        edited(written / "p.json", tmp_path / "a.json", episodes=5000, evaluations=5000, generations=4951),
        "its episodes 5000 is not allowed beside its budget 10: a run stops at the first generation boundary at or past its budget, "
        "here after at most 50 episodes (steady-state, fixed:1, pop_size 50, then 1 a generation)",
    )
    refused(edited(written / "p.json", tmp_path / "b.json", episodes=5000, evaluations=5000), "its generations 1 is not allowed beside its evaluations 5000")
    refused(
        edited(written / "p.json", tmp_path / "c.json", episodes=1000, evaluations=1000, generations=951, stop_reason="plateau"),
        "its stop_reason 'plateau' is not allowed beside its 1,000 episodes and budget 10: they reached it",
    )
    refused(edited(written / "g.json", tmp_path / "d.json", episodes=40, evaluations=20, generations=4), "here after at most 21 episodes")


def test_a_chain_ancestor_sums_the_episodes_of_its_stages(written: Path, tmp_path: Path) -> None:
    settings = nh.load_policy(written / "p.json").metadata["settings"]
    ancestor = written / "bp" / "ghh08" / "ancestor.json"
    assert nh.load_policy(ancestor).metadata["episodes"] == 500  # ten stages of 50
    nh.load_policy(edited(ancestor, tmp_path / "a.json", settings=settings))
    refused(edited(ancestor, tmp_path / "b.json", settings=settings, episodes=501), "at most 50 episodes in each of its 10 stages")


@pytest.mark.parametrize(
    ("changes", "words"),
    [
        ({"mdp_params": None, "task": "ghh10", "target": "ghh10/train:0"}, "its task 'ghh10' is not allowed: allowed ghh08, ghh09, fghh"),
        ({"mdp_params": None, "mdp": "train:12", "target": "ghh08/train:12"}, "its mdp 'train:12' is not allowed: ghh08 has no such MDP"),
        ({"mdp_params": None, "mdp": "test:999", "target": "ghh08/test:999"}, "MDP index 999 in 'test:999' is out of range: allowed 0..99"),
        ({"mdp_params": None, "task": None, "mdp": None, "target": "ghh10/train:0"}, "its target 'ghh10/train:0' is not allowed: 'ghh10' is no task"),
        ({"mdp_params": None, "mdp": None, "target": "ghh08/seeded-train:10"}, "its target 'ghh08/seeded-train:10' is not allowed"),
    ],
)
def test_a_record_names_a_task_and_mdp_that_exist(written: Path, tmp_path: Path, changes: dict, words: str) -> None:
    """T26-B07: with mdp_params removed, a task or MDP that does not exist was taken."""
    refused(edited(written / "p.json", tmp_path / "b07.json", **changes), words)


def test_save_policy_refuses_a_task_that_does_not_exist(tmp_path: Path) -> None:
    with pytest.raises(NeurohoverError, match="its task 'ghh10' is not allowed"):
        nh.save_policy(nh.load_policy("baseline"), tmp_path / "x.json", task="ghh10", target="ghh10/train:0")
    assert not (tmp_path / "x.json").exists()


def test_a_records_sensor_agrees_with_its_mdp_params(written: Path, tmp_path: Path) -> None:
    """T26-B08: a delay of 5 beside mdp_params' 2 was taken."""
    sensor = nh.load_policy(written / "pd.json").metadata["sensor"]
    refused(
        edited(written / "pd.json", tmp_path / "s.json", sensor={**sensor, "delay": 5}),
        "its sensor's delay 5 is not allowed beside its mdp_params' sensor's 2",
    )
    refused(edited(written / "p.json", tmp_path / "t.json", sensor=sensor), "its sensor's delay 2 is not allowed beside its mdp_params' sensor's 0")


def test_seconds_past_100_years_are_refused(written: Path, tmp_path: Path) -> None:
    """T26-B13: 1e30 seconds were taken in policy files, model files and a set's manifest."""
    refused(
        edited(written / "p.json", tmp_path / "p.json", seconds=1e30), "its seconds 1e+30 is not allowed: allowed a number of seconds >= 0 and <= 3.15576e+09"
    )
    nh.load_policy(edited(written / "p.json", tmp_path / "q.json", seconds=3e9))
    with pytest.raises(NeurohoverError, match=r"its seconds 1e\+30 is not allowed: allowed a number of seconds >= 0 and <= 3.15576e\+09"):
        LearnedModel.load(edited(written / "m.json", tmp_path / "m.json", seconds=1e30))
    root = tmp_path / "sets"
    shutil.copytree(written / "bp" / "ghh08", root / "ghh08")
    edited(root / "ghh08" / "manifest.json", root / "ghh08" / "manifest.json", seconds=1e30)
    with pytest.raises(NeurohoverError, match=r"manifest.json': its seconds 1e\+30 is not allowed"):
        load_policy_set("ghh08", root)


def test_an_lr_models_residual_rms_agrees_with_its_stationary_noise(written: Path, tmp_path: Path) -> None:
    """T26-B14: LR writes noise_std_stationary as 1.5 x residual_rms; residual_rms x 10 was taken."""
    data = json.loads((written / "m.json").read_text())
    stats = data["stats"]
    assert stats["noise_std_stationary"] == pytest.approx([1.5 * r for r in stats["residual_rms"]], rel=1e-12)
    bad = edited(written / "m.json", tmp_path / "m.json", stats={**stats, "residual_rms": [10 * r for r in stats["residual_rms"]]})
    with pytest.raises(NeurohoverError, match=r"its stats.residual_rms \[.* is not allowed: LR writes its stats.noise_std_stationary .* as 1.5 x"):
        LearnedModel.load(bad)


def _damaged_set(written: Path, tmp_path: Path, damage) -> Path:
    root = tmp_path / "sets"
    shutil.copytree(written / "bp" / "ghh08", root / "ghh08")
    damage(root / "ghh08")
    return root


def test_a_set_policy_is_an_mlp(written: Path, tmp_path: Path) -> None:
    """T26-B12 (a): specialised_3.json as an slp of 40 genes was flown."""
    root = _damaged_set(written, tmp_path, lambda d: edited(d / "specialised_3.json", d / "specialised_3.json", topology="slp", genome=[0.1] * 40))
    with pytest.raises(NeurohoverError, match=r"specialised_3.json \(specialised policy 3\) has topology 'slp', which is not allowed: a build evolves"):
        load_policy_set("ghh08", root)


def test_a_stray_json_file_in_a_set_is_refused_by_name(written: Path, tmp_path: Path, cli: CliRun) -> None:
    """T26-B12 (b): a copy of specialised_9.json as specialised_10.json was ignored without a word."""
    root = _damaged_set(written, tmp_path, lambda d: shutil.copy(d / "specialised_9.json", d / "specialised_10.json"))
    with pytest.raises(
        NeurohoverError, match="specialised_10.json is no file of a ghh08 set: a build writes manifest.json, generic.json, specialised_0..9.json"
    ):
        load_policy_set("ghh08", root)
    rc, _, err = cli(
        "compete", "--task", "ghh08", "--agent", "model-free", "--policy-dir", str(root), "--runs", "1", "--episodes", "1", "--out", str(tmp_path / "o")
    )
    assert rc == 2 and "specialised_10.json is no file of a ghh08 set" in err, err


def test_a_chain_set_holds_its_ancestor(written: Path, tmp_path: Path) -> None:
    """T26-B12 (c): a chain's set without ancestor.json was loaded (the reverse was refused, T25-14)."""
    root = _damaged_set(written, tmp_path, lambda d: (d / "ancestor.json").unlink())
    with pytest.raises(NeurohoverError, match="its lineage 'chain' is not allowed without ancestor.json"):
        load_policy_set("ghh08", root)
