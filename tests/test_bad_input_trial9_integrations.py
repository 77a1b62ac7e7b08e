"""Issue 37, the ninth fresh trial, the learning libraries' side: damaged RL Zoo and CleanRL run folders, a callable's
actions that are no real numbers, --json onto a file the agent is read from, and SB3VecEnv's seed, actions and options
each give one clear message (exit 2 / NeurohoverError), and the options SB3 documents are applied."""

from __future__ import annotations

import os
import pickle
from pathlib import Path

import numpy as np
import pytest

from neurohover.errors import NeurohoverError

pytest.importorskip("stable_baselines3", reason="stable-baselines3 is not installed (pip install 'neurohover[examples]')")
torch = pytest.importorskip("torch", reason="torch is not installed (pip install torch==2.13.0)")

from neurohover.integrations.cleanrl import cleanrl_policy  # noqa: E402
from neurohover.integrations.flying import evaluate_callable  # noqa: E402
from neurohover.integrations.sb3 import SB3VecEnv, rl_zoo_policy  # noqa: E402
from neurohover.tasks import get_task_family  # noqa: E402

ENV = "neurohover-GHH08-RL-v0"
BASE = ("evaluate-agent", "--task", "ghh08", "--n-mdps", "1", "--episode-steps", "20")


@pytest.fixture(scope="module")
def model_zip(tmp_path_factory) -> Path:
    """A PPO model of the RL id, untrained (what is flown does not matter here, only what is read)."""
    from stable_baselines3 import PPO

    path = tmp_path_factory.mktemp("model") / "ppo.zip"
    PPO("MlpPolicy", SB3VecEnv("neurohover/GHH08-RL-v0", num_envs=2), n_steps=8, batch_size=8, device="cpu").save(path)
    return path


def _vecnormalize(path: Path, **stats) -> None:
    from stable_baselines3.common.vec_env import VecNormalize

    norm = VecNormalize(SB3VecEnv("neurohover/GHH08-RL-v0", num_envs=2))
    for name, value in stats.items():
        getattr(norm.obs_rms, name)[3] = value
    norm.save(str(path))


def _zoo(tmp_path: Path, model_zip: Path, stats: str | None) -> Path:
    """An RL Zoo run folder: its final model and ENV/vecnormalize.pkl as ``stats`` makes it."""
    run = tmp_path / "zoo"
    (run / ENV).mkdir(parents=True)
    (run / f"{ENV}.zip").write_bytes(model_zip.read_bytes())
    file = run / ENV / "vecnormalize.pkl"
    if stats == "garbage":
        file.write_text("garbage\n")
    elif stats == "dict":
        file.write_bytes(pickle.dumps({"a": 1}))
    elif stats == "directory":
        file.mkdir()
    elif stats == "good":
        _vecnormalize(file)
    elif stats is not None:
        _vecnormalize(file, **{stats.split("=")[0]: float(stats.split("=")[1])})
    return run


@pytest.mark.parametrize(
    ("stats", "message"),
    [
        ("garbage", r"vecnormalize.pkl' cannot be read as VecNormalize statistics \(ValueError"),
        ("dict", r"vecnormalize.pkl' cannot be read as VecNormalize statistics \(it holds dict"),
        ("directory", "vecnormalize.pkl' is not a file: expected the run's VecNormalize statistics"),
        ("var=-1", r"\(its obs_rms\) holds a var of -1.0 at observation 3: expected finite numbers, variances >= 0"),
        ("mean=nan", r"\(its obs_rms\) holds a mean of nan at observation 3: expected finite numbers"),
    ],
)
def test_an_rl_zoo_run_of_damaged_statistics_is_refused_by_name(stats, message, tmp_path, model_zip) -> None:
    """T1, S4: garbage and a dict were tracebacks, a directory was skipped (flown unnormalised), negative or NaN
    statistics were flown and reported as the agent crashing."""
    run = _zoo(tmp_path, model_zip, stats)
    with pytest.raises(NeurohoverError, match=message):
        rl_zoo_policy(run)


def test_an_rl_zoo_run_of_damaged_statistics_is_one_line_on_the_command_line(tmp_path, model_zip, cli) -> None:
    rc, _, err = cli(*BASE, "--rl-zoo", str(_zoo(tmp_path, model_zip, "dict")))
    assert rc == 2 and "cannot be read as VecNormalize statistics" in err and "Traceback" not in err, err
    assert rl_zoo_policy(_zoo(tmp_path / "good", model_zip, "good"))(np.zeros((3, 12), dtype=np.float32)).shape == (3, 4)


def _cleanrl(folder: Path, *, stats=None, drop: str | None = None, n_obs: int = 12, weights=None) -> Path:
    """A CleanRL run folder (its actor 12-8-8-4 and (mean, var)), damaged as the arguments say."""
    nn = torch.nn
    actor = nn.Sequential(nn.Linear(n_obs, 8), nn.Tanh(), nn.Linear(8, 8), nn.Tanh(), nn.Linear(8, 4))
    state = {f"actor_mean.{k}": v for k, v in actor.state_dict().items() if k != drop}
    if weights is not None:
        state = {k: weights(v) for k, v in state.items()}
    folder.mkdir(parents=True)
    torch.save(state, folder / "a.cleanrl_model")
    (folder / "obs_rms.pkl").write_bytes(pickle.dumps((np.zeros(12), np.ones(12)) if stats is None else stats))
    return folder


@pytest.mark.parametrize(
    ("damage", "message"),
    [
        ({"stats": 5}, "obs_rms.pkl' holds 5, not \\(mean, var\\) arrays of 12"),
        ({"stats": {"a": 1, "b": 2}}, "obs_rms.pkl' holds {'a': 1, 'b': 2}, not \\(mean, var\\) arrays of 12"),
        ({"stats": (np.zeros(3), np.ones(3))}, r"obs_rms.pkl' holds a mean of shape \(3,\) of float64, not an array of 12 real numbers"),
        ({"stats": (np.zeros(12), np.full(12, -1.0))}, "holds a var of -1.0 at observation 0: expected finite numbers, variances >= 0"),
        ({"stats": (np.zeros(12), np.full(12, np.nan))}, "holds a var of nan at observation 0"),
        ({"stats": (np.zeros(12), ["a"] * 12)}, r"holds a var of shape \(12,\) of <U1, not an array of 12 real numbers"),
        ({"drop": "4.weight"}, "holds actor_mean layers 0.bias, 0.weight, 2.bias, 2.weight, 4.bias: expected 0.weight"),
        ({"n_obs": 5}, "the model's actor takes 5 inputs and gives 4 actions, not 12 and 4"),
        ({"weights": lambda v: v.tolist()}, "actor_mean.0.weight is list .*, not a tensor of real weights"),
        ({"weights": lambda v: v * np.nan}, r"actor_mean.0.weight holds non-finite weights \(NaN or inf\)"),
    ],
)
def test_a_damaged_cleanrl_run_is_refused_naming_the_file_and_what_is_wrong(damage, message, tmp_path) -> None:
    """T2, S4: each was a traceback (TypeError, ValueError, KeyError, RuntimeError, AttributeError) or, for negative and
    NaN statistics and weights, flown and reported as the agent crashing."""
    with pytest.raises(NeurohoverError, match=message):
        cleanrl_policy(_cleanrl(tmp_path / "run", **damage))


def test_a_damaged_cleanrl_run_is_one_line_on_the_command_line(tmp_path, cli) -> None:
    rc, _, err = cli(*BASE, "--cleanrl", str(_cleanrl(tmp_path / "run", n_obs=5)))
    assert rc == 2 and "the model's actor takes 5 inputs" in err and "Traceback" not in err, err
    act = cleanrl_policy(_cleanrl(tmp_path / "good"))
    assert act(np.zeros((2, 12))).shape == (2, 4)


@pytest.mark.parametrize(
    "returned",
    [
        lambda n: np.zeros((n, 4)) + 0j,
        lambda n: np.full((n, 4), "0.1", dtype=object),
        lambda n: [[None] * 4] * n,
        lambda n: np.zeros((n, 4), dtype=bool),
    ],
    ids=["complex", "text", "None", "bool"],
)
def test_a_callables_actions_that_are_no_real_numbers_are_refused(returned) -> None:
    """S3: complex actions were cut to their real part, text "0.1" read as 0.1, None as NaN and False as 0."""
    mdp = get_task_family("ghh08").mdp("test:0")
    with pytest.raises(NeurohoverError, match=r"act returned .*: expected numbers \(real ones: not text, booleans, complex or None\)"):
        evaluate_callable(lambda obs: returned(len(obs)), mdp, n_steps=5)


def test_json_onto_any_file_the_agent_is_read_from_is_refused(tmp_path, model_zip, cli, monkeypatch) -> None:
    """S5: --json onto the RL Zoo run's model or statistics, the --callable's module or a CleanRL run's files
    overwrote them with the rows (only --policy and --sb3 were refused)."""
    run = _zoo(tmp_path, model_zip, "good")
    cleanrl = _cleanrl(tmp_path / "cleanrl")
    (tmp_path / "nh_trial9_act.py").write_text("import numpy as np\n\n\ndef act(obs):\n    return np.zeros((len(obs), 4))\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    for source, read, named in (
        (("--rl-zoo", str(run)), run / f"{ENV}.zip", "--rl-zoo (its model)"),
        (("--rl-zoo", str(run)), run / ENV / "vecnormalize.pkl", "--rl-zoo (its statistics)"),
        (("--callable", "nh_trial9_act:act"), tmp_path / "nh_trial9_act.py", "--callable"),
        (("--cleanrl", str(cleanrl)), cleanrl / "a.cleanrl_model", "--cleanrl (its model)"),
        (("--cleanrl", str(cleanrl)), cleanrl / "obs_rms.pkl", "--cleanrl (its obs_rms.pkl)"),
    ):
        before = read.read_bytes()
        link = tmp_path / f"rows-{read.name}.json"  # --json takes a JSON name only: one that is the file read
        link.unlink(missing_ok=True)
        os.link(read, link)  # a hard link: a JSON name, the very file (a symbolic link is refused by its target's name)
        rc, _, err = cli(*BASE, *source, "--json", str(link))
        assert rc == 2 and f"is the file of {named}: give another path (writing it would destroy what is read)" in err, err
        assert read.read_bytes() == before


def test_sb3vecenv_seed_refuses_what_reset_would_and_keeps_nothing() -> None:
    """T12: seed('a') was a TypeError that kept 'a' (every later reset failed); seed(-1) was refused only at reset;
    step_wait without step_async was a bare AssertionError."""
    env = SB3VecEnv("neurohover/GHH08-v0", num_envs=2)
    for bad in ("a", -1, 2**63 - 1, True, 1.5):
        with pytest.raises(NeurohoverError, match=r"seed=.* is not allowed: give None or an integer in 0..2\*\*63-2"):
            env.seed(bad)  # type: ignore[arg-type]
    assert env.seed(2**63 - 2) == [2**63 - 2, 2**63 - 1]
    env.seed(7)
    first = env.reset()
    env.seed(7)
    np.testing.assert_array_equal(env.reset(), first)
    with pytest.raises(NeurohoverError, match=r"step_wait\(\) without a pending step_async"):
        env.step_wait()


def test_sb3vecenv_refuses_actions_of_any_other_shape_than_one_row_per_helicopter() -> None:
    """S1: (4, 2), (8,) and (1, 8) were reshaped and flown; (3, 4) was named as (2, 6), a shape never given."""
    env = SB3VecEnv("neurohover/GHH08-v0", num_envs=2)
    env.reset()
    for shape in ((4, 2), (8,), (1, 8), (3, 4), (2, 4, 1)):
        with pytest.raises(NeurohoverError, match=rf"actions have shape {re_shape(shape)}, expected \(2, 4\)"):
            env.step(np.zeros(shape))
    obs, rewards, done, infos = env.step(np.zeros((2, 4), dtype=np.float32))  # what SB3 passes
    assert obs.shape == (2, 12) and rewards.shape == (2,)


def re_shape(shape: tuple[int, ...]) -> str:
    return str(shape).replace("(", r"\(").replace(")", r"\)")


def test_sb3vecenv_applies_set_options_at_the_next_reset_only_and_refuses_bad_ones() -> None:
    """S2: set_options (SB3's VecEnv: options for the next reset) was ignored, and a bad one not refused."""
    env = SB3VecEnv("neurohover/GHH08-v0", num_envs=2, mdp="test:0")
    env.reset()
    env.set_options({"mdp": "test:3"})
    env.reset()
    assert [i["mdp"] for i in env.reset_infos] == ["ghh08/test:3"] * 2
    env.set_options([{"mdp": "test:4"}, {}])  # one per helicopter; the second keeps its MDP
    env.reset()
    assert [i["mdp"] for i in env.reset_infos] == ["ghh08/test:4", "ghh08/test:3"]
    env.set_options({"noise": (0, 5)})  # each helicopter's own options, as HoverEnv.reset takes them
    env.reset()
    np.testing.assert_array_equal(env.native.noise_streams, [[0, 5], [0, 5]])
    env.reset()  # options apply once
    assert [i["mdp"] for i in env.reset_infos] == ["ghh08/test:4", "ghh08/test:3"] and env.native.noise_streams[0, 1] != 5
    for bad, message in (
        ({"mdp": "test:100"}, "MDP index 100 in 'test:100' is out of range"),
        ({"mdpp": 1}, "unknown reset option\\(s\\) mdpp: allowed mdp, noise"),
        ({"reset_mask": np.ones(2, dtype=bool)}, "unknown reset option\\(s\\) reset_mask"),
        ([{}], "is not allowed: give None, a dict, or a list of 2 dicts"),
        ([{"noise": (0, 1)}, {}], "options give noise to helicopter\\(s\\) \\[0\\] only"),
        ({"noise": (0, -1)}, "noise episode=-1 is out of range"),
    ):
        with pytest.raises(NeurohoverError, match=message):
            env.set_options(bad)  # type: ignore[arg-type]
    env.reset()  # nothing of the refused options kept
    assert [i["mdp"] for i in env.reset_infos] == ["ghh08/test:4", "ghh08/test:3"]
