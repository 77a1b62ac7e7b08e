"""Bad-input trial 23, flight-data metadata that contradicts itself or its episodes (neurohover.flightmeta): an MDP its
task family does not hold (T23-02), returns above 0 or not what the observations give (T23-03), an MDP label naming
another MDP (T23-04), a seed that is none (T23-05), an episode flagged crashed that flew calm to its end (T23-19).
Every file ``fly --record`` writes still loads (two tasks, crashes and none, float64 and float32)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from flight_edits import edited_copy, refused_everywhere

from neurohover.errors import NeurohoverError
from neurohover.flightdata import FlightData

ZERO_POLICY = {"topology": "slp", "genome": [0.0] * 40}  # no control at all: it falls, and crashes within a second


@pytest.fixture(scope="module")
def flights(tmp_path_factory) -> dict[str, Path]:
    """Recordings as ``neurohover fly --record`` writes them: ghh08 train:3 (calm, float64 and float32), ghh08 flown with
    no control (every episode crashes) and FGHH at sigma 1 (crashes and full episodes, float32)."""
    from neurohover.cli import main

    folder = tmp_path_factory.mktemp("flights")
    (folder / "zero.json").write_text(json.dumps(ZERO_POLICY))
    runs = {
        "calm": ["--task", "ghh08", "--mdp", "train:3", "--episodes", "2"],
        "calm32": ["--task", "ghh08", "--mdp", "train:3", "--episodes", "2", "--record-dtype", "float32"],
        "fall": ["--task", "ghh08", "--mdp", "sample", "--episodes", "3", "--policy", str(folder / "zero.json")],
        "fall32": ["--task", "ghh08", "--mdp", "sample", "--episodes", "3", "--policy", str(folder / "zero.json"), "--record-dtype", "float32"],
        "fghh32": ["--task", "fghh", "--sigma", "1", "--mdp", "sample", "--episodes", "6", "--seed", "1", "--record-dtype", "float32"],
        "fghh": ["--task", "fghh", "--sigma", "1", "--mdp", "sample", "--episodes", "6", "--seed", "1"],
        "ghh09": ["--task", "ghh09", "--mdp", "test:7", "--episodes", "2", "--record-dtype", "float32"],
    }
    paths = {}
    for name, argv in runs.items():
        paths[name] = folder / f"{name}.npz"
        assert main(["fly", *argv, "--threads", "1", "--json", "--record", str(paths[name])]) == 0
    return paths


def test_every_recording_fly_writes_loads_back(flights: dict[str, Path], tmp_path: Path) -> None:
    """What is not refused: every file fly --record writes (ghh08, ghh09 and FGHH; crashed episodes, at once or after
    some steps, and full ones; float64 and float32), and two recordings joined and saved."""
    loaded = {name: FlightData.load(path) for name, path in flights.items()}
    assert all(loaded["fall"].metadata["crashed"]) and not any(loaded["calm"].metadata["crashed"])
    fghh = loaded["fghh32"].metadata["crashed"]
    assert any(fghh) and not all(fghh)  # crashes and full episodes in one file
    joined = loaded["calm32"] + loaded["fall"]
    assert FlightData.load(joined.save(tmp_path / "joined.npz", dtype="float32")).n_episodes == 5
    assert FlightData.load((loaded["fghh"] + loaded["fall"]).save(tmp_path / "j2.npz")).metadata["crashed"][-1] is True


def test_an_mdp_its_task_family_does_not_hold_is_refused(flights: dict[str, Path], tmp_path: Path, cli) -> None:
    """T23-02: an MDP of ghh08 whose wind is [9, 9] (ghh08 holds winds in [-5, 5]) was plotted and learned from."""

    def wind(meta: dict) -> None:
        meta["mdps"][0].update(wind=[9, 9], label="ghh08/custom")

    path = edited_copy(flights["calm"], tmp_path / "wind.npz", wind)
    refused_everywhere(
        path, "mdps entry 0 is not allowed: MDP 'ghh08/custom' is not allowed: it is no ghh08 MDP: GHH-08 wind [9.0, 9.0] m/s is out of range", cli, tmp_path
    )

    def dt(meta: dict) -> None:  # in range, but not the family's dynamics
        meta["mdps"][1].update(dt=0.02, label="x")

    with pytest.raises(
        NeurohoverError, match=r"mdps entry 1 is not allowed: MDP substeps=10 x dt=0.02 is not allowed: the substeps must cover one 0.1 s control step"
    ):
        FlightData.load(edited_copy(flights["calm"], tmp_path / "dt.npz", dt))

    def d_u(meta: dict) -> None:  # in range, but not the family's dynamics: every true MDP has D_u 0
        meta["mdps"][1].update(d_u=0.5, label="x")

    with pytest.raises(NeurohoverError, match=r"mdps entry 1 is not allowed: MDP 'x' is not allowed: it is no ghh08 MDP: its d_u=0.5 differ .*\(d_u=0.0\)"):
        FlightData.load(edited_copy(flights["calm"], tmp_path / "d_u.npz", d_u))


def test_returns_above_0_or_not_what_the_observations_give_are_refused(flights: dict[str, Path], tmp_path: Path, cli) -> None:
    """T23-03: returns [5.0, 3.0] were taken; so were returns the readings contradict (a return is minus the sum of its
    steps' rewards, each minus the sum of squares of the readings, a crash charged for the steps left)."""

    def positive(meta: dict) -> None:
        meta["returns"] = [5.0, 3.0]

    path = edited_copy(flights["calm"], tmp_path / "positive.npz", positive)
    refused_everywhere(path, "returns=[5.0, 3.0] is not allowed: episode 0's return 5.0 is not in", cli, tmp_path)
    obs, act = (np.full((4, 12), 0.01),), (np.zeros((3, 4)),)
    with pytest.raises(NeurohoverError, match=r"^flight data: its metadata returns=\[1.5\] is not allowed"):
        FlightData(obs, act, {"returns": [1.5]})  # no MDP recorded: above 0 is refused all the same
    for name in ("calm", "calm32", "fall32", "fghh32"):

        def halved(meta: dict) -> None:
            meta["returns"][-1] = meta["returns"][-1] / 2

        edited = edited_copy(flights[name], tmp_path / f"half-{name}.npz", halved)
        with pytest.raises(NeurohoverError, match=r"is not what its observations give: .*its returns and observations contradict"):
            FlightData.load(edited)

    def off(meta: dict) -> None:  # a crash charged one step fewer than its budget leaves
        meta["returns"][0] += 1748.8

    with pytest.raises(NeurohoverError, match=r"episode 0's return .* less 1748.8\d* for each of the 5,99\d steps left of its budget"):
        FlightData.load(edited_copy(flights["fall"], tmp_path / "off.npz", off))


@pytest.mark.parametrize("label", ["ghh08/train:4", "train:4", "ghh08/zero", "ghh08/test:100", "fghh/train:3"])
def test_an_mdp_label_that_names_another_mdp_is_refused(flights: dict[str, Path], tmp_path: Path, cli, label: str) -> None:
    """T23-04: an MDP of train:3's wind labelled 'train:4' (another MDP of the set) was plotted under that name."""

    def relabel(meta: dict) -> None:
        meta["mdps"][1]["label"] = label

    path = edited_copy(flights["calm"], tmp_path / "label.npz", relabel)
    with pytest.raises(NeurohoverError) as err:
        FlightData.load(path)
    assert str(err.value).startswith(f"flight-data file '{path}': its metadata mdps entry 1 is not allowed: MDP {label!r} is not allowed: "), str(err.value)
    assert any(text in str(err.value) for text in ("contradict its label: ghh08's ", "its label names no ghh08 MDP", "its label names a 'fghh' MDP")), str(
        err.value
    )
    if label == "train:4":
        refused_everywhere(path, "its wind=(3.81178, 1.41884) contradict its label: ghh08's train:4 has wind=", cli, tmp_path)


@pytest.mark.parametrize("seed", ["abc", -5, 1.5, 2**63])
def test_a_seed_that_is_no_seed_is_refused(flights: dict[str, Path], tmp_path: Path, cli, seed: object) -> None:
    """T23-05: metadata seed 'abc' or -5 were taken; a seed is an integer in 0..2**63-1, as sim.rng checks it."""

    def reseed(meta: dict) -> None:
        meta["seed"] = seed

    path = edited_copy(flights["calm"], tmp_path / "seed.npz", reseed)
    refused_everywhere(path, f"seed={seed!r} is ", cli, tmp_path)
    with pytest.raises(NeurohoverError, match=r"allowed an integer in 0..2\*\*63-1"):
        FlightData.load(path)


def test_an_episode_flagged_crashed_that_flew_calm_to_its_end_is_refused(flights: dict[str, Path], tmp_path: Path, cli) -> None:
    """T23-19: crashed [true, true] on two full, calm flights were drawn and learned from as crashes. A crash leaves its
    last reading out of the crash bounds (or follows a NaN action), so a calm last reading after a finite action
    disproves the flag; a crash on the budget's last step and one after a NaN action are taken."""

    def crashed(meta: dict) -> None:
        meta["crashed"] = [True, True]

    for name in ("calm", "calm32"):
        path = edited_copy(flights[name], tmp_path / f"crashed-{name}.npz", crashed)
        refused_everywhere(path, "crashed=[True, True] is not allowed: episode 0 is flagged crashed, yet after its last step (6,000)", cli, tmp_path)
    calm = FlightData.load(flights["calm"])
    mdp = calm.metadata["mdps"][0]
    obs, act = [np.zeros((7, 12))], [np.zeros((6, 4))]
    obs[0][-1, 2] = 5.2  # falling faster than 5 m/s after the budget's last step: a genuine crash there
    FlightData(
        tuple(obs), tuple(act), {"episode_steps": 6, "crashed": [True], "mdps": [mdp], "returns": [0.0]}
    )  # the crashing step earns its charge: 0 steps left
    nan_act = [np.zeros((3, 4))]
    nan_act[0][-1, 0] = np.nan  # a policy's NaN action crashes the episode where the helicopter is
    FlightData((np.zeros((4, 12)),), tuple(nan_act), {"episode_steps": 6, "crashed": [True], "mdps": [mdp]})
    with pytest.raises(NeurohoverError, match=r"^flight data: its metadata crashed=\[True\] is not allowed: episode 0 is flagged crashed, yet"):
        FlightData((np.zeros((7, 12)),), (np.zeros((6, 4)),), {"episode_steps": 6, "crashed": [True], "mdps": [mdp]})
