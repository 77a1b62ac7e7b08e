"""Bad-input trial 34 (34b), the Python API: T34-B02 (PolicyTable.from_genomes given a ragged list raised NumPy's
ValueError), T34-B03 (FlightData.save and fly --record overwrote a policy file, model file, checkpoint or history reached
by an .npz name or a symbolic link), T34-B05 (CrashAwareReward over another reward wrapper lost the crash charge),
T34-B11 (evaluate_jobs took a 2-D fallback_index), T34-B15 (TaskFamily.make of a (1, N) array said "must be N numbers,
got N") and T34-B16 (saving float32 flight data printed NumPy's overflow RuntimeWarning)."""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import flight_edits as FE
import numpy as np
import pytest

import neurohover as nh
from neurohover.errors import NeurohoverError
from neurohover.evaluate import PolicyTable


@pytest.mark.parametrize("topology", ["slp", "mlp"])
def test_b02_from_genomes_refuses_a_ragged_list_by_name(topology: str) -> None:
    """T34-B02: rows of unequal length were NumPy's "inhomogeneous shape" ValueError; equal rows still make a table."""
    g = list(nh.prototype(topology, "baseline").genome)
    with pytest.raises(NeurohoverError, match=rf"^{topology} genomes=.* are not allowed: give an array of real numbers \(P, {len(g)}\), rows of equal"):
        PolicyTable.from_genomes([g, g[:-1]], topology)
    assert len(PolicyTable.from_genomes([g, g], topology)) == 2


def test_b11_evaluate_jobs_refuses_a_2d_fallback_index() -> None:
    """T34-B11: a (1, 2) fallback_index was flattened, while the three job indexes refuse 2-D arrays."""
    fam = nh.get_task_family("ghh08")
    policies, mdps = [nh.baseline_policy(), nh.prototype("mlp", "baseline")], fam.training_mdps()
    with pytest.raises(NeurohoverError, match=r"^fallback_index must be a 1-D array of job indices, got shape \(1, 2\)"):
        nh.evaluate_jobs(policies, mdps, [0, 1], [0, 1], [0, 1], fallback_index=np.array([[1, -1]]), n_steps=20)
    ev = nh.evaluate_jobs(policies, mdps, [0, 1], [0, 1], [0, 1], fallback_index=np.array([1, -1]), n_steps=20)
    assert ev.returns.shape == (2,)


@pytest.fixture(scope="module")
def flight(tmp_path_factory) -> Path:
    """A recording as ``neurohover fly --record`` writes it (ghh08 train:1, one episode)."""
    return FE.recorded(tmp_path_factory.mktemp("flight"), 1)


def _other_kinds(folder: Path) -> dict[str, str]:
    """A policy file, a model-like file, a checkpoint and a history of neurohover's, each as its first bytes (name -> kind)."""
    folder.mkdir(exist_ok=True)
    nh.save_policy(nh.baseline_policy(), folder / "pol.json")
    (folder / "mod.json").write_text(json.dumps({"format": "neurohover-model/1"}) + "\n")
    (folder / "ck.json").write_text(json.dumps({"format": "neurohover-evolution-checkpoint/1"}) + "\n")
    (folder / "h.csv").write_text("generation,evaluations,episodes,champion_return\n0,1,1,-5.0\n")
    return {"pol.json": "a policy file", "mod.json": "a model file", "ck.json": "an evolution checkpoint", "h.csv": "an evolution history"}


def test_b03_flight_data_save_writes_over_no_other_kind_of_file(flight: Path, tmp_path: Path) -> None:
    """T34-B03: FlightData.save replaced a policy file, a model file, a checkpoint or a history reached by a symbolic link
    named .npz, or simply named .npz, as save_policy, LearnedModel.save and evolve(checkpoint=) refuse to."""
    fd = nh.FlightData.load(flight)
    for name, kind in _other_kinds(tmp_path / "k").items():
        target = tmp_path / "k" / name
        before = target.read_bytes()
        link = tmp_path / f"link_{name}.npz"
        link.symlink_to(target)
        renamed = tmp_path / f"{name}.npz"
        renamed.write_bytes(before)
        for path in (link, renamed):
            with pytest.raises(NeurohoverError, match=rf"^flight-data file .* is {kind}.*: give another path \(writing flight data"):
                fd.save(path)
        assert target.read_bytes() == before and renamed.read_bytes() == before
    again = tmp_path / "again.npz"  # flight data over flight data, through a link too: written as before
    again.write_bytes(flight.read_bytes())
    (tmp_path / "again_link.npz").symlink_to(again)
    assert fd.save(tmp_path / "again_link.npz") == tmp_path / "again_link.npz"
    assert nh.FlightData.load(again).n_transitions == fd.n_transitions


def test_b03_fly_record_through_a_link_to_a_checkpoint_is_refused_before_flying(cli, tmp_path: Path) -> None:
    """T34-B03: ``fly --record link.npz`` (a link to an evolution checkpoint) turned the checkpoint into a zip archive."""
    _other_kinds(tmp_path)
    before = (tmp_path / "ck.json").read_bytes()
    (tmp_path / "link.npz").symlink_to(tmp_path / "ck.json")
    code, out, err = cli("fly", "--task", "ghh08", "--mdp", "train:1", "--episodes", "1", "--record", str(tmp_path / "link.npz"))
    assert code != 0 and "is an evolution checkpoint: give another path (writing flight data" in err, err
    assert (tmp_path / "ck.json").read_bytes() == before


@pytest.mark.parametrize(("family", "kwargs"), [("ghh08", {}), ("fghh", {"sigma": 0.5}), ("ghh09", {})])
def test_b15_make_of_a_2d_array_names_its_shape(family: str, kwargs: dict) -> None:
    """T34-B15: ``make(np.array([[0.5, 1.0]]))`` said "must be 2 numbers, got 2"; the flat parameters still make an MDP."""
    fam = nh.get_task_family(family, **kwargs)
    params = fam.sample_params(np.random.default_rng(0), 1)[0]
    n = params.size
    with pytest.raises(NeurohoverError, match=rf"must be a flat sequence of {n} numbers, got shape \(1, {n}\): "):
        fam.make(params[None, :])
    assert fam.make(params).family == fam.make(list(params)).family


def test_b16_saving_float32_flight_data_warns_nothing(flight: Path, tmp_path: Path) -> None:
    """T34-B16: FlightData of float32 readings printed NumPy's "overflow encountered in cast" (flightmeta.py) at save,
    as the policy check compared them with MAX_OBSERVATION (1e60, past float32's range); the file was written."""
    fd = nh.FlightData.load(flight)
    f32 = nh.FlightData(tuple(o.astype(np.float32) for o in fd.observations), fd.actions, metadata=dict(fd.metadata))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for dtype in ("float64", "float32"):
            assert nh.FlightData.load(f32.save(tmp_path / f"{dtype}.npz", dtype=dtype)).n_transitions == fd.n_transitions


def _crash_step(env) -> float:
    """The reward of the step that ends an episode flown at zero controls (a crash within 20 steps on train:0)."""
    env.reset(seed=0)
    while True:
        _, r, terminated, truncated, _ = env.step(np.zeros(4, dtype=env.action_space.dtype))
        if terminated or truncated:
            return float(r)


def test_b05_crash_aware_reward_refuses_changed_or_crash_aware_rewards_inside() -> None:
    """T34-B05: CrashAwareReward over ClipReward, TransformReward, NormalizeReward or itself squashed the crash as an
    ordinary step (-0.69 instead of -98), and an -RL-v0 id (crash-aware already) was wrapped again without a word."""
    import gymnasium as gym
    from gymnasium.wrappers import ClipReward, NormalizeReward, RecordEpisodeStatistics, TransformReward

    from neurohover.wrappers import CrashAwareReward

    def base():
        return gym.make("neurohover/GHH08-v0", mdp="train:0", episode_steps=20)

    for inner in (ClipReward(base(), -1, 1), TransformReward(base(), lambda r: r / 1000), NormalizeReward(base())):
        name = type(inner).__name__
        with pytest.raises(NeurohoverError, match=rf"its {name} changes the rewards before CrashAwareReward sees them.*put reward wrappers outside"):
            CrashAwareReward(RecordEpisodeStatistics(inner))
    for inner in (CrashAwareReward(base()), gym.make("neurohover/GHH08-RL-v0", mdp="train:0")):
        with pytest.raises(NeurohoverError, match=r"its rewards are crash-aware already"):
            CrashAwareReward(inner)
    plain = _crash_step(CrashAwareReward(RecordEpisodeStatistics(base())))  # what the docs advise: statistics inside
    assert plain < -50 and _crash_step(ClipReward(CrashAwareReward(base()), -1, 1)) == -1.0  # transforms go outside
