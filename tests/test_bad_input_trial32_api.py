"""Bad-input trial 32 (32b), the Python API: T32-B02 (a set of MDPs flew in hash order), T32-B03 (Drift's check was an
assert, stripped by python -O), T32-B04 (an environment's episode_steps changed after it was made: a crash paid +3497.6),
T32-B13 (PolicyTable.from_genomes flies genomes Policy refuses: documented, pinned), T32-B14 (with_genome kept the old
genome's results), T32-B15/B16 (neat records with missing or repeated nodes and connections, keys of 0.5, weights of
1e308) and T32-B19 (an unpickled HoverVectorEnv failed at reset)."""

from __future__ import annotations

import ast
import pickle
import subprocess
import sys
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

import neurohover as nh
from neurohover.envs import HoverEnv, HoverVectorEnv
from neurohover.errors import NeurohoverError
from neurohover.evaluate import PolicyTable, evaluate_jobs
from neurohover.integrations.flying import evaluate_callable
from neurohover.policysets import crash_matrix

MDPS = [nh.get_task_family("ghh08").mdp(f"train:{i}") for i in range(3)]


@pytest.mark.parametrize("unordered", [set, frozenset, lambda m: dict.fromkeys(m).keys()], ids=["set", "frozenset", "dict_keys"])
def test_b02_a_set_of_mdps_is_refused_by_name(unordered) -> None:
    """T32-B02: evaluate, evaluate_jobs, crash_matrix and evaluate_callable flew a set of MDPs in hash order: which MDP was
    in which column, and its episodes' gusts, changed with PYTHONHASHSEED. A set of policies was refused already."""
    b = nh.baseline_policy()
    calls = [
        lambda m: nh.evaluate(b, m, n_steps=5),
        lambda m: evaluate_jobs([b], m, [0, 0], [0, 1], [0, 0], seed=0, n_steps=5),
        lambda m: crash_matrix([b], m, 1, 0, 5),
        lambda m: evaluate_callable(lambda obs: np.zeros((len(obs), 4)), m, n_steps=5),
    ]
    for call in calls:
        with pytest.raises(NeurohoverError, match=r"^mdps=.* is not allowed: a \w+ has no order.*give an MDP or a list or tuple of MDPs"):
            call(unordered(MDPS))
    assert nh.evaluate(b, tuple(MDPS), n_steps=5).returns.shape == (1, 3, 1)  # a sequence still flies


@pytest.mark.slow
def test_b03_drift_refuses_text_under_python_O() -> None:
    """T32-B03: Drift's check of ``change`` was an assert inside try/except AssertionError: under ``python -O`` the assert
    was gone and 'D_w=0.8' was an AttributeError. No check in the package is an assert caught as an error now."""
    code = (
        "import neurohover as nh\n"
        "for c in ('D_w=0.8', {1: 0.8}):\n"
        "    try:\n        nh.Drift(change=c)\n    except nh.NeurohoverError as e:\n        print(e)\n"
    )
    run = subprocess.run([sys.executable, "-O", "-c", code], capture_output=True, text=True, timeout=60)
    assert run.returncode == 0, run.stderr[-2000:]
    lines = run.stdout.splitlines()
    assert len(lines) == 2 and all("is not allowed: give parameter factors as a table" in line for line in lines), run.stdout
    caught = []  # an assert inside a try that catches AssertionError: a check that python -O strips
    for path in Path(nh.__file__).parent.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Try) and "AssertionError" in " ".join(ast.unparse(h.type) for h in node.handlers if h.type):
                caught += [(path.name, n.lineno) for stmt in node.body for n in ast.walk(stmt) if isinstance(n, ast.Assert)]
    assert not caught


def _crash(env) -> tuple:
    env.reset(seed=1)
    return env.step(np.full(4, np.nan))[1:4]


@pytest.mark.parametrize("value", [-1, 0, 1.5, "20", 10**30, 30])
def test_b04_a_made_environments_episode_steps_cannot_change(value) -> None:
    """T32-B04: episode_steps was a plain attribute, checked only when the environment was made: -1 set afterwards made a
    crash pay +3497.6, '20' was numba's TypingError, 10**30 an OverflowError (set_wrapper_attr and the vector env alike)."""
    env = HoverEnv(task="ghh08", episode_steps=20)
    normal = _crash(env)
    with pytest.raises(NeurohoverError, match=r"^episode_steps=.* is not allowed: an environment's episode_steps is fixed when it is made"):
        env.episode_steps = value
    wrapped = gym.make("neurohover/GHH08-v0", episode_steps=20)
    with pytest.raises(NeurohoverError, match="episode_steps is fixed"):
        wrapped.set_wrapper_attr("episode_steps", value)
    vec = HoverVectorEnv(num_envs=3, task="ghh08", episode_steps=20)
    for name in ("episode_steps", "max_episode_steps", "num_envs"):
        with pytest.raises(NeurohoverError, match=f"^{name}=.* is not allowed: an environment's {name} is fixed"):
            setattr(vec, name, value)
    assert env.episode_steps == vec.episode_steps == vec.max_episode_steps == 20 and vec.num_envs == 3
    assert _crash(env) == normal and normal[0] < 0 and normal[1:] == (True, False)


def test_b04_the_other_settings_are_fixed_too() -> None:
    env = HoverEnv(task="ghh08", episode_steps=20)
    for name, value in (("family", None), ("drift", None), ("obs_dtype", "float32"), ("action_dtype", "float32"), ("task", "fghh")):
        with pytest.raises(NeurohoverError, match=f"^{name}=.* is not allowed: an environment's {name} is fixed when it is made"):
            setattr(env, name, value)
    with pytest.raises(NeurohoverError, match=r"reset\(options=\{'mdp': \.\.\.\}\) flies another MDP"):
        env.mdp = MDPS[0]
    vec = HoverVectorEnv(num_envs=2, task="ghh08", episode_steps=20)
    for name in ("device", "family", "obs_dtype"):
        with pytest.raises(NeurohoverError, match=f"{name} is fixed"):
            setattr(vec, name, "cuda")


def test_b13_from_genomes_flies_diverged_genomes_as_crashes_as_documented() -> None:
    """T32-B13: not a bug. PolicyTable.from_genomes is the evolution's fast path and documents that it takes what Policy
    refuses (non-finite and huge genes): an optimiser's diverged sample flies and crashes at once instead of stopping the
    run. Pinned: genes of +-1.7e308 crash at the first step."""
    assert "Non-finite genes are allowed here" in (PolicyTable.from_genomes.__doc__ or "")
    g = np.tile([1.7e308, -1.7e308], 20)[None, :]
    with pytest.raises(NeurohoverError, match="out of range"):
        nh.Policy("slp", g[0])
    ev = nh.evaluate(PolicyTable.from_genomes(g, "slp"), MDPS[0], n_steps=20)
    assert ev.crashed.all() and ev.steps.ravel().tolist() == [1]


EVOLVED = {
    "prototype": "baseline", "method": "steady-state", "optimizer": "ne", "resampling": "fixed:1", "target": "ghh08/train:0",
    "seed": 1, "budget": 10, "episodes": 50, "evaluations": 50, "generations": 1, "champion_return": -25.55, "n_steps": 20,
    "stop_reason": "budget", "task": "ghh08", "mdp": "train:0", "seed_policy": "baseline", "champion_fitness_scale": "return",
    "validation_return": -29.25, "validation_sd": 1.89, "validation_episodes": 10, "episode_steps": 20, "seconds": 0.158,
    "history": "p.json.history.csv",
}  # fmt: skip
RESULTS = {"episodes", "evaluations", "generations", "champion_return", "stop_reason", "champion_fitness_scale", "validation_return",
           "validation_sd", "validation_episodes", "seconds", "history"}  # fmt: skip


def test_b14_with_genome_drops_the_old_genomes_results(tmp_path) -> None:
    """T32-B14: with_genome kept champion_return, validation, history, evaluations and stop_reason: a saved policy claimed
    another genome's return. They are left out now; what describes the run's setting is kept, and a given key is taken."""
    p = nh.Policy("mlp", np.zeros(42), EVOLVED)
    nh.save_policy(p, tmp_path / "p.json")
    assert nh.load_policy(tmp_path / "p.json").metadata == EVOLVED
    q = nh.load_policy(tmp_path / "p.json").with_genome(np.zeros(42), note="hand-made")
    assert not RESULTS & set(q.metadata) and RESULTS <= nh.policies.GENOME_RESULT_KEYS
    assert q.metadata == {**{k: v for k, v in EVOLVED.items() if k not in RESULTS}, "note": "hand-made"}
    nh.save_policy(q, tmp_path / "q.json")
    assert nh.load_policy(tmp_path / "q.json") == q
    assert p.with_genome(np.zeros(42), champion_return=-1.0).metadata["champion_return"] == -1.0


OUTS = [v for key in range(4) for v in (key, 0.0, 1.0, 0)]  # the 4 output nodes 0..3: key, bias, response, identity


@pytest.mark.parametrize(
    "record, words",
    [
        ([0.0], r"node keys \[\] is not allowed: give each node once, the outputs 0..3 among them"),
        ([3.0] + OUTS[:12], r"node keys \[0, 1, 2\] is not allowed"),
        ([4.0] + OUTS + [55, 0, 1.0], r"connection 55 -> 0 is not allowed: give it once, from an input -9..-1 or a node"),
        ([4.0] + OUTS + [-10, 0, 1.0], r"connection -10 -> 0 is not allowed"),
        ([4.0] + OUTS + [0, -1, 1.0], r"connection 0 -> -1 is not allowed"),
        ([4.0] + OUTS + [-1, 0, 1e308, -2, 0, -1e308], r"weight 1e\+308 is not allowed: allowed numbers in \[-30, 30\]"),
        ([4.0] + OUTS[:13] + [1e300] + OUTS[14:], r"bias 1e\+300 is not allowed"),
        ([4.0] + OUTS + [-1, 0, 1.0, -1, 0, 2.0], r"connection -1 -> 0 is not allowed: it is listed twice"),
        ([5.0] + OUTS + [0.5, 0, 1, 0], r"node key 0.5 is not allowed: allowed a whole number in 0..2\*\*53"),
        ([5.0] + OUTS + [0, 0, 1, 0], r"node keys \[0, 1, 2, 3, 0\] is not allowed: give each node once"),
        ([5.0] + OUTS + [-1, 0, 1, 0], r"node key -1 is not allowed"),
        ([5.0] + OUTS + [1e300, 0, 1, 0], r"node key 1e\+300 is not allowed"),
    ],
)
def test_b15_b16_a_neat_records_network_is_checked(record, words) -> None:
    """T32-B15: a record without nodes was neat-python's KeyError 0, a connection from a missing node its KeyError 55.
    T32-B16: weights of +-1e308 flew NaN, a repeated connection or node kept the last, a node key of 0.5 was cut to 0."""
    from neurohover.integrations.neat import network_of_record

    with pytest.raises(NeurohoverError, match="^a NEAT record's " + words):
        network_of_record(record)


def test_b15_b16_a_record_within_bounds_flies() -> None:
    from neurohover.integrations.neat import forward, network_of_record

    record = [5.0] + OUTS + [7, 0, 1, 1] + [-1, 7, 1.0, 7, 0, 2.0, -3, 1, -30.0]
    out = forward(network_of_record(record), np.zeros(1, np.int64), np.ones((1, 12)))
    assert np.isfinite(out).all() and out[0, 1] == -30.0


def test_b19_an_unpickled_vector_env_flies_the_same_episodes() -> None:
    """T32-B19: ``spec is SAMPLE`` compared identity with the sentinel string: an unpickled copy held an equal string, and
    its reset was AttributeError: 'str' object has no attribute 'row'. Pickled before reset and mid-episode, the copy
    flies the original's episodes, autoresets included."""
    rng = np.random.default_rng(0)
    v = HoverVectorEnv(num_envs=2, task="ghh08", episode_steps=20)
    w = pickle.loads(pickle.dumps(v))
    assert (v.reset(seed=1)[0] == w.reset(seed=1)[0]).all()
    for copy in (w, None):
        u = copy if copy is not None else pickle.loads(pickle.dumps(v))
        for _ in range(25):
            a = rng.uniform(-1, 1, (2, 4))
            got, want = u.step(a), v.step(a)
            assert all(np.array_equal(x, y) for x, y in zip(got[:4], want[:4]))
        assert u.mdps == v.mdps


def test_b04_fixed_settings_cost_a_step_nothing() -> None:
    """T32-B04's fix first took every attribute set through a Python ``__setattr__`` (10% of a HoverEnv step): the
    settings are descriptors now, a step's own attributes plain sets, and a setting read is a plain read."""
    from neurohover.envs import HoverEnv, HoverVectorEnv

    for cls in (HoverEnv, HoverVectorEnv):
        assert cls.__setattr__ is object.__setattr__, cls
    env = HoverEnv("ghh08")
    assert "episode_steps" in env.__dict__ and env.episode_steps == 6000
    assert not hasattr(env, "task")  # an argument it keeps no attribute of reads as none
    with pytest.raises(NeurohoverError, match="episode_steps=20 is not allowed"):
        env.episode_steps = 20
