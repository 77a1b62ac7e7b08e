"""Bad input in Python: one NeurohoverError naming the value and what is allowed."""

from __future__ import annotations

import re

import numpy as np
import pytest

import neurohover as nh
from neurohover import NeurohoverError


def test_evaluate_takes_baseline_by_name_as_a_policy_file_would() -> None:
    mdp = nh.get_task_family("ghh08").zero()
    by_name = nh.evaluate("baseline", mdp, episodes=2, seed=1, n_steps=50).returns
    by_object = nh.evaluate(nh.baseline_policy(), mdp, episodes=2, seed=1, n_steps=50).returns
    np.testing.assert_array_equal(by_name, by_object)
    assert nh.evaluate(["baseline", nh.baseline_policy()], mdp, episodes=1, n_steps=20).returns.shape[0] == 2


@pytest.mark.parametrize("bad", [3, None, [nh.baseline_policy(), 2.5]])
def test_evaluate_refuses_what_is_not_a_policy(bad) -> None:
    with pytest.raises(NeurohoverError, match="is not allowed: give a Policy, a policy file's path or 'baseline'"):
        nh.evaluate(bad, nh.get_task_family("ghh08").zero(), episodes=1, n_steps=10)


@pytest.mark.parametrize("obs", [np.zeros(3), np.full(12, np.nan), [0.0] * 11 + [np.inf], "twelve"])
def test_act_refuses_an_observation_that_is_not_12_finite_numbers(obs) -> None:
    with pytest.raises(NeurohoverError, match="give 12 finite numbers"):
        nh.baseline_policy().act(obs)
    assert nh.baseline_policy().act(np.zeros(12)) == pytest.approx((0.02, 0.0, 0.0, 0.23))


def test_an_env_refuses_an_unknown_argument_naming_the_allowed_ones() -> None:
    import gymnasium as gym

    with pytest.raises(NeurohoverError, match="unknown argument.s. windd: allowed task, sigma, mdp, episode_steps"):
        gym.make("neurohover/GHH08-v0", windd=3)
    with pytest.raises(NeurohoverError, match="unknown argument.s. windd: allowed num_envs"):
        gym.make_vec("neurohover/GHH08-v0", num_envs=2, vectorization_mode="vector_entry_point", windd=3)


def test_an_env_refuses_an_mdp_of_another_family_but_takes_a_learned_model() -> None:
    import gymnasium as gym

    env = gym.make("neurohover/GHH08-v0")
    with pytest.raises(NeurohoverError, match="is an MDP of ghh09, not of this environment's family ghh08"):
        env.reset(options={"mdp": nh.get_task_family("ghh09").mdp("train:1")})
    from neurohover.models import learn_lr

    flights = nh.evaluate(nh.baseline_policy(), nh.get_task_family("ghh08").zero(), episodes=1, record=True, n_steps=300).flight_data
    model = learn_lr(flights).mdp()
    assert model.family == "model"
    obs, info = env.reset(seed=0, options={"mdp": model})
    assert obs.shape == (12,)


def test_a_typo_in_the_scale_not_run_is_refused_at_once(tmp_path) -> None:
    from neurohover.experiments import load_config
    from neurohover.experiments.config import CONFIG_DIR

    text = (CONFIG_DIR / "fig7.toml").read_text()
    assert "[[scales.paper.groups]]" not in text  # the paper scale's groups come from [settings]
    bad = tmp_path / "fig7-typo.toml"
    bad.write_text(text.replace("[scales.paper]", '[scales.paper]\nagnet = "x"'))
    with pytest.raises(NeurohoverError, match="at scale 'paper': unknown setting.s. 'agnet'"):
        load_config(str(bad), "quick")
    load_config("fig7", "quick")  # the shipped one loads
    titled = tmp_path / "mine.toml"  # sixth trial: title = 5 was stored, then called a damaged store's config
    lines = ["title = 5" if line.startswith("title = ") else line for line in text.replace('name = "fig7"', 'name = "mine"', 1).splitlines()]
    titled.write_text("\n".join(lines) + "\n")
    with pytest.raises(NeurohoverError, match="mine.toml.*: title = 5 is not allowed: give text"):
        load_config(str(titled), "quick")


def test_sizes_that_would_exhaust_memory_are_refused_up_front() -> None:
    """issue 37: evaluate(episodes=10**13) was a NumPy MemoryError (72.8 TiB); validation_return the same."""
    from neurohover.evaluate import MAX_EPISODES_PER_CALL
    from neurohover.evolution.evolve import validation_return

    mdp = nh.get_task_family("ghh08").zero()
    # episodes alone past the limit is refused by its own range (T24-11: whole_in); with policies x MDPs below
    with pytest.raises(NeurohoverError, match=r"episodes=10000000000000 is out of range: allowed an integer in 1..100,000,000 \(policies x MDPs"):
        nh.evaluate("baseline", mdp, episodes=10**13, n_steps=10)
    with pytest.raises(NeurohoverError, match="at most 100,000,000 in one call"):
        nh.evaluate(["baseline"] * 2, [mdp] * 5, episodes=MAX_EPISODES_PER_CALL // 10 + 1, n_steps=10)
    with pytest.raises(NeurohoverError, match="episodes=10000000000000 is out of range"):
        validation_return(nh.baseline_policy(), mdp, episodes=10**13, seed=0, n_steps=10)


@pytest.mark.parametrize(
    ("call", "expected"),
    [
        (lambda: nh.get_task_family("ghh08", sensor="x"), "sensor='x' is not allowed: give a neurohover.Sensor"),
        (lambda: nh.get_task_family("ghh08", drift="fast"), "drift='fast' is not allowed: give a neurohover.Drift"),
        (lambda: nh.get_task_family("fghh", sigma="0.3"), "sigma='0.3' is not allowed: give a number"),
        (lambda: nh.get_task_family("ghh08").mdp(3), "MDP 3 is not allowed: give its name as a string"),
        (lambda: nh.get_task_family("ghh08").mdp("train:\u0663"), "unknown MDP 'train:\u0663'"),  # an Arabic-Indic 3 is not train:3
        (lambda: nh.get_task_family("ghh08").make(["1", "2"]), "must be 2 numbers, got ['1', '2']"),
        (lambda: nh.load_policy(None), "policy source None is not allowed"),
        (lambda: nh.evaluate("baseline", nh.get_task_family("ghh08").zero(), n_steps=5, record="yes"), "record='yes' is not allowed: give True or False"),
        (
            lambda: nh.evaluate_jobs([nh.baseline_policy()], [nh.get_task_family("ghh08").zero()], [0], [0], [0], n_steps=5, record="x"),
            "give one True/False flag per job",
        ),
    ],
)
def test_the_python_api_checks_its_arguments_as_the_command_line_does(call, expected) -> None:
    """issue 37: each of these was an AttributeError or TypeError, or was silently accepted."""
    with pytest.raises(NeurohoverError) as err:
        call()
    assert expected in str(err.value)


def test_numbers_of_numpy_types_are_still_taken() -> None:
    fam = nh.get_task_family("ghh08")
    assert fam.make(np.array([1, 2.0])) == fam.make([1, 2.0])
    assert nh.get_task_family("fghh", sigma=np.float64(0.2)).sigma == 0.2
    assert nh.evaluate("baseline", fam.zero(), n_steps=5, record=np.True_).flight_data is not None


def test_run_test_evaluate_jobs_and_the_env_check_their_arguments() -> None:
    """issue 37: an AttributeError/TypeError, NumPy's error, 2-D indices flattened silently, and gymnasium's own error class."""
    import gymnasium as gym

    from neurohover.agents import run_test
    from neurohover.agents.registry import make_agent
    from neurohover.evaluate import evaluate_jobs

    fam = nh.get_task_family("ghh08")
    agent = make_agent("baseline", fam)
    for kwargs, expected in (
        ({"agent": None}, "agent=None is not allowed: give an Agent"),
        ({"mdp": "zero"}, "mdp='zero' is not allowed: give an MDP"),
        ({"seed": -1}, "seed=-1 is out of range"),
        ({"episodes": 10**13}, r"episodes=10000000000000 is out of range: allowed an integer in 1..100,000,000 \(episodes in one call\)"),  # T24-11
    ):
        args = {"agent": agent, "family": fam, "mdp": fam.zero(), "episodes": 2, "n_steps": 10, **kwargs}
        with pytest.raises(NeurohoverError, match=expected):
            run_test(args.pop("agent"), args.pop("family"), args.pop("mdp"), **args)
    with pytest.raises(NeurohoverError, match=r"policy_index must be a 1-D array of job indices, got shape \(1, 1\)"):
        evaluate_jobs([nh.baseline_policy()], [fam.zero()], [[0]], [[0]], [[0]], n_steps=5)
    with pytest.raises(NeurohoverError, match="seed=-1 is out of range"):
        gym.make("neurohover/GHH08-v0").reset(seed=-1)
    # A NumPy integer seed, which the vector env takes, was gymnasium's error (second trial): the same episode as the int's.
    envs = [gym.make("neurohover/GHH08-v0") for _ in range(3)]
    for env, seed in zip(envs, (np.int64(3), 3, 4)):
        env.reset(seed=seed)
    drawn = [env.unwrapped.mdp.wind for env in envs]  # each reset draws its MDP (a GHH-08 wind) from the seed
    assert drawn[0] == drawn[1] != drawn[2]
    # A task's name where a family goes was an AttributeError (issue 37, still there in the second trial): taken, as agent_spec takes it.
    assert type(make_agent("incremental", "ghh08")) is type(make_agent("incremental", fam))
    with pytest.raises(NeurohoverError, match="family=3 is not allowed: give a task family"):
        make_agent("baseline", 3)  # type: ignore[arg-type]


def test_a_run_on_another_familys_mdp_is_refused() -> None:
    """issue 37: a GHH-08 agent flew a GHH-09 MDP without a word."""
    from neurohover.agents import run_test
    from neurohover.agents.registry import make_agent

    ghh08, ghh09 = nh.get_task_family("ghh08"), nh.get_task_family("ghh09")
    with pytest.raises(NeurohoverError, match="is a ghh09 MDP, but the run's family is ghh08"):
        run_test(make_agent("baseline", ghh08), ghh08, ghh09.mdp("train:0"), episodes=2, n_steps=10)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"substeps": 0}, "substeps=0 is out of range: allowed an integer in 1..1000"),  # flew as a perfect 0.0 (second trial)
        ({"params": (1, 2)}, "params=(1, 2) is not allowed: give 11 finite numbers"),
        ({"dt": -1}, "dt=-1.0 is out of range"),
        ({"wind_kind": 9}, "wind_kind=9 is not allowed"),
        ({"noise_std": (-1.0,) * 6}, "noise_std=.* is out of range: allowed stds >= 0"),
        ({"params": (float("nan"),) * 11}, "give 11 finite numbers"),
        ({"label": 5}, "label=5 is not allowed: give a string"),  # kept as the number (second trial)
    ],
)
def test_an_mdp_is_checked_when_it_is_made(kwargs: dict, message: str) -> None:
    with pytest.raises(NeurohoverError, match=message.replace("(", r"\(").replace(")", r"\)")):
        nh.MDP("ghh08", **kwargs)


def test_a_checkpoint_write_that_fails_leaves_the_last_checkpoint_and_no_partial_file(tmp_path) -> None:
    """Second trial: SIGINT mid-write left a truncated PATH.tmp beside the checkpoint."""
    from neurohover.evolution.records import read_checkpoint, write_checkpoint

    path = tmp_path / "run.checkpoint.json"
    write_checkpoint(path, {"generation": 1})
    with pytest.raises(ValueError):  # strict JSON: a NaN fails mid-write, as an interrupt would
        write_checkpoint(path, {"generation": 2, "champion": float("nan")})
    assert read_checkpoint(path) == {"generation": 1} and sorted(p.name for p in tmp_path.iterdir()) == [path.name]


def test_an_ec_model_refuses_a_negative_seed_by_name() -> None:
    from neurohover.models.ec import learn_ec_meno

    ev = nh.evaluate(nh.baseline_policy(), nh.get_task_family("ghh08").zero(), episodes=1, n_steps=30, record=True)
    with pytest.raises(NeurohoverError, match=r"seed=-1 is out of range: allowed an integer in 0..2\*\*63-1"):
        learn_ec_meno(ev.flight_data, budget=5, seed=-1)  # was NumPy's "expected non-negative integer"


def test_evaluate_and_the_safeguard_check_their_arguments() -> None:
    """Second trial: TypeError, OverflowError or an AttributeError when the batch was first flown."""
    from neurohover.evaluate import DangerousState, Safeguard

    b, zero = nh.baseline_policy(), nh.get_task_family("ghh08").zero()
    for call, message in (
        (lambda: nh.evaluate(b, zero, episodes=True), "episodes=True is not allowed"),  # a type, not a range (T24-11)
        (lambda: nh.evaluate(b, zero, first_episode=10**20), "first_episode=100000000000000000000 is out of range"),
        (lambda: nh.evaluate(b, None), "mdps=None is not allowed"),
        (lambda: nh.evaluate(b, zero, safeguard="x"), "safeguard='x' is not allowed"),
        (lambda: Safeguard("baseline"), "Safeguard fallback='baseline' is not allowed: give a Policy"),
        (lambda: Safeguard(b, dangerous="code"), "Safeguard dangerous='code' is not allowed"),
    ):
        with pytest.raises(NeurohoverError, match=message):
            call()
    assert Safeguard(b, DangerousState(rule="paper")).fallback is b


def test_compete_names_a_missing_out_and_a_sensor_of_the_wrong_type(tmp_path) -> None:
    from neurohover.compete import compete

    for kwargs, message in (({"out": None}, "out=None is not allowed"), ({"out": tmp_path / "c", "sensor": "x"}, "sensor='x' is not allowed")):
        with pytest.raises(NeurohoverError, match=message):  # TypeError and AttributeError before (second trial)
            compete("ghh08", "baseline", runs=1, episodes=2, n_steps=10, **kwargs)
    assert not (tmp_path / "c").exists()


def test_save_policy_refuses_what_it_cannot_write_as_a_policy_file(tmp_path) -> None:
    """Second trial: OSError, AttributeError or TypeError; metadata named genome overwrote the policy; NaN written as NaN."""
    b = nh.baseline_policy()
    for call, message in (
        (lambda: nh.save_policy(b, tmp_path), "is a directory; give a file path"),
        (lambda: nh.save_policy(b, ""), "policy file is empty"),
        (lambda: nh.save_policy("baseline", tmp_path / "a.json"), "policy='baseline' is not allowed: give a Policy"),
        (lambda: nh.save_policy(b, tmp_path / "a.json", genome=[1]), "metadata key\\(s\\) genome are the policy's own"),
        (lambda: nh.save_policy(b, tmp_path / "a.json", r=float("nan")), "strict JSON values"),
    ):
        with pytest.raises(NeurohoverError, match=message):
            call()
    assert not (tmp_path / "a.json").exists()
    assert nh.load_policy(nh.save_policy(b, tmp_path / "b.json", note="kept")).genome.tolist() == b.genome.tolist()


def test_a_familys_draws_check_their_generator_and_count() -> None:
    """Second trial: NumPy's TypeError/ValueError, a MemoryError for 10**13 draws, an AttributeError for a seed."""
    fam = nh.get_task_family("ghh08")
    for call, message in (
        (lambda: fam.mdp("sample", rng="x"), "rng='x' is not allowed"),
        (lambda: fam.sample(-1), "rng=-1 is not allowed"),
        (lambda: fam.sample_params(np.random.default_rng(0), 10**13), "n=10000000000000 is out of range"),
        (lambda: fam.sample_params(0, 3), "rng=0 is not allowed: give a numpy Generator"),
    ):
        with pytest.raises(NeurohoverError, match=message):
            call()
    assert fam.sample(5) == fam.sample(np.random.default_rng(5))  # a seed is the Generator it seeds


def test_flight_data_files_are_checked_as_the_command_line_checks_them(tmp_path) -> None:
    """Second trial: saving to /dev/null was a struct.error, to a directory an OSError; loading None a TypeError."""
    from neurohover.flightdata import FlightData

    fd = nh.evaluate(nh.baseline_policy(), nh.get_task_family("ghh08").zero(), episodes=1, n_steps=20, record=True).flight_data
    for call, message in (
        (lambda: fd.save(tmp_path), "is a directory; give a file path"),
        (lambda: fd.save(""), "flight-data file is empty"),
        (lambda: FlightData.load(None), "flight-data file None is not allowed"),
        (lambda: FlightData.load(tmp_path), "is a directory; give a file"),
    ):
        with pytest.raises(NeurohoverError, match=message):
            call()
    assert FlightData.load(fd.save(tmp_path / "fd.npz")).actions[0].shape == (20, 4)


def test_an_episode_index_past_2_63_is_named_as_it_was_given() -> None:
    """Second trial: it wrapped to a negative number and was reported as such."""
    with pytest.raises(NeurohoverError, match=r"episode_index holds 9223372036854775808, out of range: allowed 0..2\*\*63-1"):
        nh.evaluate_jobs([nh.baseline_policy()], [nh.get_task_family("ghh08").zero()], [0], [0], [2**63], n_steps=5)


def test_a_policy_table_or_policy_built_by_hand_is_checked() -> None:
    """Second trial: a kind 9 was flown, a genome of the wrong width and metadata [1] were kept."""
    from neurohover.evaluate import PolicyTable

    for call, message in (
        (lambda: PolicyTable(np.array([9]), np.zeros((1, 42))), "PolicyTable kinds must be a 1-D integer array of \\[0, 1\\]"),
        (lambda: PolicyTable(np.array([0]), np.zeros((1, 40))), "PolicyTable genomes must be an array of shape \\(1, 42\\)"),
        (lambda: nh.Policy("slp", nh.baseline_policy().genome, metadata=[1]), "policy metadata=\\[1\\] is not allowed: give a dict"),
    ):
        with pytest.raises(NeurohoverError, match=message):
            call()


def test_a_policy_where_a_sequence_goes_and_a_name_where_a_policy_goes() -> None:
    """Second trial: evaluate_jobs(policy, ...) was a TypeError, validation_return('baseline', ...) an AttributeError."""
    from neurohover.evolution.evolve import validation_return

    b, zero = nh.baseline_policy(), nh.get_task_family("ghh08").zero()
    assert nh.evaluate_jobs(b, [zero], [0], [0], [0], n_steps=5).returns.shape == (1,)  # one policy is a table of one
    with pytest.raises(NeurohoverError, match="policy 'baseline' is not a Policy: load one with neurohover.load_policy"):
        validation_return("baseline", zero, episodes=1, n_steps=5)  # type: ignore[arg-type]


def test_the_last_python_api_leftovers_of_the_second_trial_are_refused_by_name(tmp_path) -> None:
    """issue 37: an AttributeError, a TypeError mid-run, a misleading message, and settings ignored without a word."""
    import gymnasium as gym

    from neurohover.compete import compete
    from neurohover.evolution.evolve import evolve

    fam = nh.get_task_family("ghh08")
    calls = (
        (lambda: compete("ghh08", "hybrid", runs=1, episodes=1, hybrid="x", out=tmp_path / "c"), "hybrid='x' is not allowed: give a HybridSettings"),
        (lambda: compete("ghh08", "baseline", runs=1, episodes=1, hybrid={"box": 0.3}, out=tmp_path / "c"), "apply to the hybrid agents only"),
        (lambda: evolve(fam.zero(), budget=2, n_steps=5, progress_every_s=-1), "progress_every_s=-1 is out of range"),
        (lambda: evolve(fam.zero(), budget=2, n_steps=5, progress=3), "progress=3 is not allowed: give a callable"),
        (lambda: evolve(fam.zero(), budget=2, n_steps=5, settings="x"), "a preset's name is for the generational method"),
    )
    for call, expected in calls:
        with pytest.raises(NeurohoverError, match=expected):
            call()
    assert not (tmp_path / "c").exists()
    env = gym.make("neurohover/GHH08-v0")
    env.reset(seed=0)
    for action in (np.array([1j, 0, 0, 0]), ["0.1", "0", "0", "0"]):  # cut to its real part with a warning; read as numbers
        with pytest.raises(NeurohoverError, match="is not allowed: give 4 real numbers"):
            env.step(action)
    vec = gym.make_vec("neurohover/GHH08-v0", num_envs=2, vectorization_mode="vector_entry_point")
    vec.reset(seed=0)
    with pytest.raises(NeurohoverError, match=r"actions must be a \(2, 4\) array of real numbers"):
        vec.step(np.zeros((2, 4), dtype=complex))
    assert env.step([0, 0, 0, 0])[0].shape == (12,)  # integers and lists still fly


def test_the_third_trials_files_and_paths_are_refused_by_name(tmp_path) -> None:
    """issue 37, third trial: tracebacks (OverflowError, RecursionError, TypeError, FileExistsError), a duplicated key kept
    without a word, and refusals that left an output directory or deleted the user's files."""
    import json

    from neurohover.compete import compete
    from neurohover.models.model import LearnedModel
    from neurohover.policysets import build_policy_set

    genome = [0.0] * 39
    files = {
        "big.json": '{"topology": "slp", "genome": [' + ", ".join(["0"] * 39) + ", " + "9" * 400 + "]}",
        "deep.json": "[" * 100_000 + "]" * 100_000,
        "dup.json": json.dumps({"topology": "slp", "genome": genome + [0.0]})[:-1] + ', "topology": "mlp"}',
    }
    for name, text in files.items():
        (tmp_path / name).write_text(text)
    for name, message in (
        ("big.json", "400 digits. is out of range"),
        ("deep.json", "nested too deeply"),
        ("dup.json", "key 'topology' is given more than once"),
    ):
        with pytest.raises(NeurohoverError, match=message):
            nh.load_policy(tmp_path / name)
    with pytest.raises(NeurohoverError, match="nested too deeply"):
        LearnedModel.load(tmp_path / "deep.json")
    b = nh.baseline_policy()
    for call, message in (
        (lambda: LearnedModel.load(None), "model file=None is not allowed"),
        (lambda: nh.save_policy(b, 3), "policy file=3 is not allowed: give a file path"),
        (lambda: nh.save_policy(b, "x\x00.json"), "holds a NUL character"),
    ):
        with pytest.raises(NeurohoverError, match=message):
            call()
    (tmp_path / "afile").write_text("x")
    kw = {"runs": 1, "episodes": 1, "n_steps": 5}
    for extra, message in (
        ({"out": tmp_path / "afile"}, "is a file; give a directory"),
        ({"out": tmp_path / "c", "on_result": 3}, "on_result=3 is not allowed"),
        ({"out": tmp_path / "c", "progress": "yes"}, "progress='yes' is not allowed"),
        ({"out": tmp_path / "c", "device": "gpu"}, "gpu"),
    ):
        with pytest.raises(NeurohoverError, match=message):
            compete("ghh08", "baseline", **kw, **extra)
    assert not (tmp_path / "c").exists()  # refused before the directory is made
    mine = tmp_path / "bp" / "ghh08"
    mine.mkdir(parents=True)
    (mine / "mine.txt").write_text("keep")
    with pytest.raises(NeurohoverError, match="holds files but no policy set"):
        build_policy_set("ghh08", tmp_path / "bp", budget=2, n_steps=5)
    assert (mine / "mine.txt").read_text() == "keep"  # the build replaced the directory whole (third trial)
    with pytest.raises(NeurohoverError, match="progress=3 is not allowed"):
        build_policy_set("ghh08", tmp_path / "bp2", budget=2, n_steps=5, progress=3)


@pytest.mark.parametrize(
    ("kwargs", "unread"), [({"rule": "paper", "tilt": 0.5}, "tilt"), ({"rule": "ratio-sum", "box": 0.3}, "box"), ({"threshold": 0.2}, "threshold")]
)
def test_a_safeguard_setting_its_rule_does_not_read_is_refused(kwargs: dict, unread: str) -> None:
    """issue 37, third trial: ignored without a word; the defaults of the unread settings still pass."""
    with pytest.raises(NeurohoverError, match=f"safeguard {unread}=.* is not read by rule"):
        nh.DangerousState(**kwargs)
    assert nh.DangerousState(rule=kwargs.get("rule", "code")).rule == kwargs.get("rule", "code")


def test_seeds_past_2_63_and_real_numbers_that_are_not_numbers_are_refused(tmp_path) -> None:
    """issue 37, third trial: a seed of 2**64 was taken where every other seed is refused past 2**63-1; text, booleans and
    complex numbers were read as numbers (a complex one cut to its real part with a warning); a .net name got JSON."""
    import gymnasium as gym

    fam = nh.get_task_family("ghh08")
    with pytest.raises(NeurohoverError, match=r"an integer in 0..2\*\*63-1"):
        fam.sample(2**64)
    with pytest.raises(NeurohoverError, match=r"an integer in 0..2\*\*63-1"):
        gym.make("neurohover/GHH08-v0").reset(seed=2**64)
    with pytest.raises(NeurohoverError, match=r"out of range: allowed an integer in 0..2\*\*63-2"):
        gym.make_vec("neurohover/GHH08-v0", num_envs=2, vectorization_mode="vector_entry_point").reset(seed=2**63 - 1)
    b = nh.baseline_policy()
    for genome in (np.full(40, 1j), np.array(["0"] * 40), [True] * 40):
        with pytest.raises(NeurohoverError, match="must be a list of finite real numbers"):
            nh.Policy("slp", genome)
    for obs in ([True] * 12, np.full(12, 1j)):
        with pytest.raises(NeurohoverError, match="give 12 finite numbers"):
            b.act(obs)
    env = gym.make("neurohover/GHH08-v0")
    env.reset(seed=0)
    with pytest.raises(NeurohoverError, match="give 4 real numbers"):
        env.step([True] * 4)
    with pytest.raises(NeurohoverError, match="written as JSON, which load_policy would misread"):
        nh.save_policy(b, tmp_path / "x.net")
    assert nh.Policy("slp", [0] * 40).genome.dtype == np.float64 and b.act([0] * 12) == b.act(np.zeros(12))  # integers still are numbers


def test_sizes_that_would_exhaust_memory_before_the_check_are_refused() -> None:
    """issue 37, third trial: fixed:100000000000 and 10**9 one-byte job indices were MemoryErrors, not refusals."""
    from neurohover.evolution.evolve import evolve

    with pytest.raises(NeurohoverError, match="K must be an integer in 1..100,000"):
        evolve(nh.get_task_family("ghh08").zero(), budget=2, n_steps=5, resampling="fixed:100000000000")
    with pytest.raises(NeurohoverError, match="policy_index of 1,000,000,000 jobs is out of range"):
        nh.evaluate_jobs([nh.baseline_policy()], [nh.get_task_family("ghh08").zero()], np.zeros(10**9, dtype=np.int8), [0], [0], n_steps=5)


def test_fghh_parameters_past_what_the_simulation_holds_are_refused() -> None:
    """issue 37, third trial: 1e300 was taken and flew NaN returns."""
    fam = nh.get_task_family("fghh")
    with pytest.raises(NeurohoverError, match=r"must lie in \[-10000, 10000\]"):
        fam.make([1e300] + [1.0] * 10)
    assert np.isfinite(nh.evaluate("baseline", fam.make([1e4] * 11), episodes=1, n_steps=20).returns).all()  # the bound itself flies


@pytest.mark.parametrize(
    ("optimizer", "settings", "message"),
    [
        ("ne", {"pop_size": 10**9}, "pop_size=1000000000 must be an integer in 2..100,000"),
        ("cma", {"popsize": 10**11}, "popsize=100000000000 must be None or an integer in 2..100,000"),
    ],
)
def test_a_population_that_would_never_finish_a_generation_is_refused(optimizer: str, settings: dict, message: str) -> None:
    """issue 37, third trial: these hung or ran on without a word."""
    from neurohover.evolution.evolve import evolve

    with pytest.raises(NeurohoverError, match=message):
        evolve(nh.get_task_family("ghh08"), optimizer=optimizer, settings=settings, budget=4, n_steps=5)


def test_the_third_trials_last_sizes_and_stores_are_refused_before_anything_is_made(tmp_path) -> None:
    """issue 37, third trial's leftovers: an EC-MER budget of 10**15 ran on; a safety_episodes of 10**12 and a store that
    is not a store were refused only after the output directory was made."""
    from neurohover.compete import compete
    from neurohover.evolution import evolve
    from neurohover.models import learn_ec_mer
    from neurohover.policysets import build_policy_set

    flights = nh.evaluate(nh.baseline_policy(), nh.get_task_family("ghh08").zero(), episodes=1, record=True, n_steps=30).flight_data
    with pytest.raises(NeurohoverError, match=r"budget=1000000000000000 is out of range: allowed an integer in 1..10,000,000,000 \(evaluations\)"):
        learn_ec_mer(flights, nh.baseline_policy(), budget=10**15)
    with pytest.raises(NeurohoverError, match=r"budget=100000000000 is out of range: allowed an integer in 1..10,000,000,000 \(episodes\)"):
        evolve(nh.get_task_family("ghh08").zero(), topology="slp", budget=10**11, n_steps=10)
    with pytest.raises(NeurohoverError, match=r"safety_episodes=1000000000000 is out of range: allowed a whole number in 1..1,000,000"):
        build_policy_set("ghh08", tmp_path / "bp", safety_episodes=10**12)
    notes = tmp_path / "notes.txt"
    notes.write_text("not a store\n")
    with pytest.raises(NeurohoverError, match="is not a neurohover results store"):
        compete("ghh08", "baseline", out=tmp_path / "out", runs=1, episodes=1, store=notes)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["notes.txt"] and notes.read_text() == "not a store\n"


def test_a_store_read_with_a_name_that_is_not_text_is_refused(tmp_path) -> None:
    """issue 37, fourth trial: Store.results(None, None) returned {} as if the experiment held nothing."""
    from neurohover.experiments import Store

    with Store(tmp_path / "s.sqlite") as store:
        for call in (lambda: store.results(None, None), lambda: store.units("fig7", 3), lambda: store.config(["fig7"], "paper")):
            with pytest.raises(NeurohoverError, match="is not allowed as an experiment name or scale: give text"):
                call()


def _fourth_trial_calls(tmp_path):
    """The fourth trial's Python API cases that raised TypeError, AttributeError, MemoryError or NumPy's errors, or were
    accepted without a word: (call, the message's start)."""
    from neurohover.agents import run_test
    from neurohover.agents.registry import make_agent
    from neurohover.agents.spec import AgentOptions
    from neurohover.experiments import Store, load_config, reproduce
    from neurohover.flightdata import FlightData
    from neurohover.models import learn_ec_mer
    from neurohover.policysets import build_policy_set

    fam, mdp, base = nh.get_task_family("ghh08"), nh.get_task_family("ghh08").mdp("train:0"), nh.baseline_policy()
    (tmp_path / "junk.bin").write_bytes(b"x")
    return [
        (lambda: nh.evaluate(base, mdp, episodes=1, n_steps=True), "n_steps=True is not allowed"),
        (lambda: nh.evaluate(base, mdp, episodes=1, seed=True), "seed=True is not allowed"),
        (lambda: nh.evaluate(base, mdp, episodes=1, threads=True), "threads=True is not allowed: give an integer in 1"),
        (lambda: nh.evaluate(base, mdp, episodes=10**8, n_steps=10**7), "100,000,000 episodes of n_steps=10,000,000 are"),
        (lambda: nh.evaluate(base, mdp, episodes=10**5, n_steps=6000, record=True), "recording 100,000 episodes of n_steps=6,000 takes 71.5 GiB"),
        (lambda: nh.evaluate(nh.PolicyTable(np.array([1]), np.zeros((1, 42), complex)), mdp, episodes=1, n_steps=20), "PolicyTable genomes must be real"),
        (lambda: run_test(make_agent("baseline", fam), fam, mdp, episodes=True, n_steps=20), "episodes=True is not allowed"),  # a type, not a range (T24-11)
        (lambda: make_agent("generic", fam, policy_dir=3), "policy_dir=3 is not allowed"),
        (lambda: make_agent("model-based", fam, options=AgentOptions(evolution="x")), "AgentOptions evolution='x' is not allowed"),
        (lambda: make_agent("generic", fam, options=AgentOptions(settings={"criterion": "lcb"})), "agent 'generic' takes no settings"),
        (lambda: make_agent("hybrid-risk", fam, options=AgentOptions(settings={"criterion": "best"})), "bad RiskSettings: risk criterion 'best'"),
        (lambda: make_agent("hybrid-risk", fam, options=AgentOptions(settings=3)), "agent 'hybrid-risk' takes settings of RiskSettings"),
        (lambda: build_policy_set("ghh08", "/dev/full", budget=5, n_steps=10), "out '/dev/full': '/dev/full' is not a directory"),
        (lambda: build_policy_set("ghh08", tmp_path / "junk.bin", budget=5, n_steps=10), "is a file; give a directory"),
        (lambda: load_config("fig7", "quick", [1]), "overrides=[1] is not allowed: give a dict"),
        (lambda: reproduce(load_config("fig2", "quick"), "x", "local"), "store='x' is not allowed: give a Store"),
        (lambda: reproduce(load_config("fig2", "quick"), Store(tmp_path / "s.sqlite"), None), "executor=None is not allowed"),
        (lambda: FlightData(observations=[np.zeros((51, 12))], actions="x"), "flight data actions='x' is not allowed"),
        (
            lambda: learn_ec_mer(nh.evaluate(base, mdp, episodes=1, record=True, n_steps=30).flight_data, base, budget=3, episodes=10**13),
            "episodes=10000000000000",
        ),
    ]


def test_the_fourth_trials_python_api_cases_are_refused_by_name(tmp_path) -> None:
    for call, message in _fourth_trial_calls(tmp_path):
        with pytest.raises(NeurohoverError, match=re.escape(message)):
            call()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["junk.bin", "s.sqlite"]  # nothing made but the store given


def test_a_complex_mdp_parameter_is_refused_not_cut_to_its_real_part() -> None:
    """issue 37, fourth trial: fam.make(np.array([1+2j, 0])) flew wind (1, 0) after a NumPy ComplexWarning."""
    with pytest.raises(NeurohoverError, match=re.escape("GHH-08 wind (wind_u, wind_v) must be 2 numbers, got array([1.+2.j, 0.+0.j])")):
        nh.get_task_family("ghh08").make(np.array([1 + 2j, 0]))


def test_a_flight_data_file_with_damaged_parts_is_refused_by_name(tmp_path) -> None:
    """Fifth trial: metadata that is a list, episode lengths in floats or text, and text observations were an
    AttributeError in learn-model and NumPy errors (split, sum) in FlightData.load."""
    import json

    from neurohover.flightdata import FORMAT, FlightData

    fd = nh.evaluate(nh.baseline_policy(), nh.get_task_family("ghh08").zero(), episodes=2, n_steps=10, record=True).flight_data
    good = dict(np.load(fd.save(tmp_path / "fd.npz")))
    assert str(good["format"]) == FORMAT
    for name, change, message in (
        ("meta", {"metadata": np.array(json.dumps([1, 2]))}, "its metadata is a list, not a JSON object"),
        ("lenfloat", {"lengths": np.array([10.0, 10.0])}, "episode lengths are not one count"),
        ("lentext", {"lengths": np.array(["10", "10"])}, "episode lengths are not one count"),
        ("len2d", {"lengths": np.array([[10, 10]])}, "episode lengths are not one count"),
        ("lenneg", {"lengths": np.array([-1, 21])}, "episode lengths are not one count"),
        ("obstext", {"observations": good["observations"].astype(str)}, "observations and actions are <U32 and float64, not real numbers"),
    ):
        path = tmp_path / f"{name}.npz"
        np.savez(path, **{**good, **change})
        with pytest.raises(NeurohoverError, match=message):
            FlightData.load(path)


def test_the_python_leftovers_of_the_fifth_trial_are_refused_by_name() -> None:
    """Fifth trial: OverflowError, NumPy's ValueError, a None reward that became nan, a crash-aware discount of 2 and a
    complex genome whose imaginary part was dropped."""
    from neurohover.evaluate import PolicyTable
    from neurohover.wrappers import crash_aware

    bp, fam = nh.baseline_policy(), nh.get_task_family("ghh08")
    for call, message in (
        (lambda: fam.make([10**400, 0]), "wind \\(wind_u, wind_v\\) must be 2 finite numbers"),
        (lambda: nh.Sensor.parse("level=0.5", delay="x"), "sensor delay='x' is not allowed"),
        (lambda: nh.evaluate_jobs([bp], [fam.zero()], [0], [0], [0], n_steps=10, fallback_index=["x"]), "fallback_index=\\['x'\\] is not allowed"),
        (lambda: nh.evaluate_jobs([bp], [fam.zero()], [0], [0], [0], n_steps=10, fallback_index=[0.5]), "fallback_index=\\[0.5\\] is not allowed"),
        (lambda: PolicyTable.from_genomes([["a"] * 40], "slp"), "slp genomes of <U1 are not allowed"),
        (lambda: PolicyTable.from_genomes(np.ones((1, 40)) * 1j, "slp"), "slp genomes of complex128 are not allowed"),
        (lambda: crash_aware("x"), "reward='x' is not allowed"),
        (lambda: crash_aware(None), "reward=None is not allowed"),
        (lambda: crash_aware(1.0, gamma=2), "gamma=2 is out of range"),
        (lambda: crash_aware(1.0, scale=-1), "scale=-1 is out of range"),
        (lambda: crash_aware(float("nan")), "reward=nan is not allowed: give finite numbers"),
        (lambda: crash_aware(np.array([1.0, np.inf])), "give finite numbers"),
    ):
        with pytest.raises(NeurohoverError, match=message):
            call()
    assert crash_aware(-3) == pytest.approx(-np.log(4.0)) and nh.evaluate_jobs(
        [bp], [fam.zero()], [0], [0], [0], n_steps=10, fallback_index=[0]
    ).returns.shape == (1,)


def test_the_sixth_trials_severe_cases(tmp_path) -> None:
    """Sixth trial: build_policy_set(task, None) rebuilt the installed package's shipped set; a flight-data archive whose
    header declared (1e11, 12) was a MemoryError of 8.73 TiB, one with damaged compressed bytes a zlib.error."""
    import io
    import zipfile

    from neurohover.flightdata import FlightData
    from neurohover.policysets import build_policy_set

    with pytest.raises(NeurohoverError, match="out=None is not allowed: give the directory to write the set into"):
        build_policy_set("ghh08", None, budget=1, n_steps=5)  # type: ignore[arg-type]
    fd = nh.evaluate(nh.baseline_policy(), nh.get_task_family("ghh08").zero(), episodes=2, n_steps=10, record=True).flight_data
    arrays = dict(np.load(fd.save(tmp_path / "fd.npz")))
    header = io.BytesIO()
    np.lib.format.write_array_header_1_0(header, {"descr": "<f8", "fortran_order": False, "shape": (10**11, 12)})
    with zipfile.ZipFile(tmp_path / "bomb.npz", "w") as archive:
        for key, value in arrays.items():
            member = io.BytesIO()
            np.save(member, value)
            archive.writestr(f"{key}.npy", header.getvalue() if key == "observations" else member.getvalue())
    with pytest.raises(NeurohoverError, match=r"declares arrays of 9,600,000,00\d,\d{3} bytes: more than half the memory free now"):  # + metadata
        FlightData.load(tmp_path / "bomb.npz")
    with zipfile.ZipFile(tmp_path / "deflated.npz", "w", zipfile.ZIP_DEFLATED) as archive:
        for key, value in arrays.items():
            member = io.BytesIO()
            np.save(member, value)
            archive.writestr(f"{key}.npy", member.getvalue())
    data = bytearray((tmp_path / "deflated.npz").read_bytes())
    start = data.index(b"observations.npy") + 40  # inside the member's compressed bytes
    data[start : start + 200] = bytes(range(200))
    (tmp_path / "damaged.npz").write_bytes(bytes(data))
    with pytest.raises(NeurohoverError, match="damaged.npz' is not a readable flight-data file"):
        FlightData.load(tmp_path / "damaged.npz")


def test_the_sixth_trials_python_cases_are_refused_by_name(tmp_path) -> None:
    """Sixth trial: OverflowError, TypeError, AttributeError and plain ValueError from the Python API, and silent
    acceptances (a drift setting a parameter twice, create='no', write_report('') into the current directory, a
    name read letter by letter, flight data saved that load() refuses)."""
    from neurohover.evolution.steady_state import SteadyStateSettings
    from neurohover.experiments import Store, write_report
    from neurohover.flightdata import FlightData
    from neurohover.integrations.flying import evaluate_callable
    from neurohover.netfile import policy_from_net, policy_to_net

    fam = nh.get_task_family("ghh08")
    fd = nh.evaluate(nh.baseline_policy(), fam.zero(), episodes=1, n_steps=5, record=True).flight_data
    with Store(tmp_path / "s.sqlite") as store:
        for call, message in (
            (lambda: nh.get_task_family("fghh", sigma=10**400), "sigma=1000.* is out of range"),
            (lambda: nh.Sensor.at_level(10**400), "sensor noise level=1000.* is out of range"),
            (lambda: nh.Drift(0.0, (("D_w", 0.8), ("D_w", 0.9))), "sets a parameter twice"),
            (lambda: Store(tmp_path / "t.sqlite", create="no"), "create='no' is not allowed"),  # type: ignore[arg-type]
            (lambda: nh.MDP.from_dict(5), "an MDP's dict 5 is not allowed"),  # type: ignore[arg-type]
            (lambda: evaluate_callable(None, fam.zero()), "act=None is not allowed"),  # type: ignore[arg-type]
            (lambda: evaluate_callable(lambda o: o[:, :4], fam.zero(), indexed="yes"), "indexed='yes' is not allowed"),  # type: ignore[arg-type]
            (lambda: FlightData(fd.observations, fd.actions, {"x": object()}).save(tmp_path / "m.npz"), "metadata cannot be saved as JSON"),
            (lambda: FlightData(fd.observations, fd.actions, 5), "its metadata 5 is not allowed: give a dict"),  # type: ignore[arg-type]
            (lambda: FlightData((), (), {}).save(tmp_path / "m.npz"), "at least one step flown"),
            (lambda: write_report(None, tmp_path / "r"), "store=None is not allowed"),  # type: ignore[arg-type]
            (lambda: write_report(store, ""), "report directory is empty"),
            (lambda: write_report(store, tmp_path / "r", names="fig2"), "names='fig2' is not allowed"),  # type: ignore[arg-type]
            (lambda: SteadyStateSettings(pop_size=10, elite_size=10), "elite_size=10 must be smaller than pop_size=10"),
            (lambda: policy_from_net(None), "NoneType None is not allowed: give the file's text"),  # type: ignore[arg-type]
            (lambda: policy_to_net("baseline"), "policy 'baseline' is not a Policy"),  # type: ignore[arg-type]
        ):
            with pytest.raises(NeurohoverError, match=message):
                call()
    assert not (tmp_path / "m.npz").exists() and not (tmp_path / "t.sqlite").exists() and not (tmp_path / "r").exists()


def test_a_call_too_large_to_fly_is_refused_before_its_job_arrays_are_made() -> None:
    """evaluate(episodes=10**8, n_steps=10**7) built 10**8-long job arrays (GBs, 50 s) before refusing the call's size."""
    import tracemalloc

    mdp = nh.get_task_family("ghh08").mdp("train:0")
    tracemalloc.start()
    try:
        with pytest.raises(NeurohoverError, match="control steps, more than one call flies"):
            nh.evaluate(nh.baseline_policy(), mdp, episodes=10**8, n_steps=10**7)
        with pytest.raises(NeurohoverError, match="n_steps=0 is out of range"):
            nh.evaluate(nh.baseline_policy(), mdp, episodes=10**8, n_steps=0)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 2**27, f"{peak / 2**20:.0f} MiB allocated before the refusal"
