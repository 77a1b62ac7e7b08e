"""Bad-input trial 24, flight data: joined recordings kept the second's seed and policy for every episode (T24-04); an MDP
label of the form fly --wind writes was not checked against the MDP's wind (T24-05); a metadata policy_flown that is no
policy, or does not give the recorded actions, was plotted and learned from, and EC-MER's refusal named 'baseline'
(T24-06). Every file fly --record writes still loads, joined, saved and reloaded too."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest
from flight_edits import edited_copy, refused_everywhere

from neurohover.errors import NeurohoverError
from neurohover.flightdata import FlightData

ZERO_POLICY = {"topology": "slp", "genome": [0.0] * 40}  # no control at all: it falls, and crashes within a second
OTHER_POLICY = {"topology": "slp", "genome": [0.0] * 36 + [0.02, 0.0, 0.0, 0.23]}


@pytest.fixture(scope="module")
def flights(tmp_path_factory) -> dict[str, Path]:
    """Recordings as ``neurohover fly --record`` writes them (the trial's: train:1 seed 3 with the baseline, seed 7 with
    p.json), and what fly --wind, a noisy delayed sensor and float32 write."""
    from neurohover.cli import main

    folder = tmp_path_factory.mktemp("flights24")
    (folder / "p.json").write_text(json.dumps(OTHER_POLICY))
    (folder / "zero.json").write_text(json.dumps(ZERO_POLICY))
    runs = {
        "f": ["--mdp", "train:1", "--episodes", "2", "--seed", "3"],
        "fp": ["--mdp", "train:1", "--episodes", "1", "--seed", "7", "--policy", str(folder / "p.json")],
        "f7": ["--mdp", "train:1", "--episodes", "1", "--seed", "7"],
        "f32": ["--mdp", "train:1", "--episodes", "1", "--seed", "3", "--record-dtype", "float32"],
        "wind": ["--wind=-0.228,2.898", "--episodes", "1"],
        "wind0": ["--wind", "0,0", "--episodes", "1"],
        "wind-0": ["--wind=-0,1e-5", "--episodes", "1", "--record-dtype", "float32"],
        "noisy": ["--mdp", "test:4", "--episodes", "2", "--obs-noise", "0.5", "--obs-delay", "3"],
        "fall": ["--mdp", "sample", "--episodes", "2", "--policy", str(folder / "zero.json")],
    }
    paths = {}
    for name, argv in runs.items():
        paths[name] = folder / f"{name}.npz"
        assert main(["fly", "--task", "ghh08", *argv, "--threads", "1", "--json", "--record", str(paths[name])]) == 0
    return paths


# --------------------------------------------------------------------------- T24-04: joined recordings


@pytest.mark.slow
def test_joined_recordings_keep_no_seed_or_policy_the_halves_do_not_share(flights: dict[str, Path], tmp_path: Path) -> None:
    """T24-04: f (baseline, seed 3) + fp (p.json, seed 7) recorded seed 7 and policy p.json for all three episodes."""
    f, fp, f7 = (FlightData.load(flights[n]) for n in ("f", "fp", "f7"))
    joined = f + fp
    assert "seed" not in joined.metadata and "policy" not in joined.metadata and joined.metadata["policy_flown"] is None
    assert joined.metadata["task"] == "ghh08" and len(joined.metadata["returns"]) == 3
    assert "seed" not in (f + f7).metadata and (f + f7).metadata["policy"] == "baseline"  # one policy, two seeds
    assert (f + f7).metadata["policy_flown"] == f.metadata["policy_flown"]
    assert (f + f).metadata["seed"] == 3 and (f + f).metadata["policy"] == "baseline"  # what both halves record is kept
    python_made = FlightData(f.observations, f.actions, {"crashed": f.metadata["crashed"], "comment": "mine"})
    both = f + python_made  # a half that records nothing of the kind: neither seed nor comment holds for every episode
    assert not {"seed", "policy", "comment", "task"} & set(both.metadata) and both.metadata["policy_flown"] is None
    for sum_ in (joined, f + f7, both):  # joined, saved and reloaded: loads back as it was
        assert FlightData.load(sum_.save(tmp_path / "j.npz")) == sum_


def test_joined_older_files_of_two_policies_name_no_policy_for_ec_mer(flights: dict[str, Path], tmp_path: Path) -> None:
    """T24-04: older files (no policy_flown) of two policies, their policy name dropped, would have been taken for the
    baseline's by EC-MER: the join records policy_flown null, so EC-MER asks for --policy."""

    def older(meta: dict) -> None:
        del meta["policy_flown"]

    a = FlightData.load(edited_copy(flights["f"], tmp_path / "a.npz", older))
    b = FlightData.load(edited_copy(flights["fp"], tmp_path / "b.npz", older))
    assert (a + a).metadata["policy"] == "baseline" and "policy_flown" not in (a + a).metadata
    assert "policy" not in (a + b).metadata and (a + b).metadata["policy_flown"] is None
    with pytest.raises(NeurohoverError, match=r"were flown by more than one policy \(joined recordings\)"):
        (a + b).recorded_policy()


# --------------------------------------------------------------------------- T24-05: a wind label


@pytest.mark.parametrize("label", ["ghh08/wind=[9.0, 9.0]", "ghh08/wind=[-0.228, 2.899]", "wind=[2.898, -0.228]", "ghh08/wind=[1]"])
def test_a_wind_label_that_is_not_the_mdps_wind_is_refused(flights: dict[str, Path], tmp_path: Path, cli, label: str) -> None:
    """T24-05: a wind [-0.228, 2.898] labelled 'ghh08/wind=[9.0, 9.0]' was plotted and learned 'in wind' under that name."""

    def relabel(meta: dict) -> None:
        meta["mdps"][0]["label"] = label

    path = edited_copy(flights["wind"], tmp_path / "relabelled.npz", relabel)
    message = f"mdps entry 0 is not allowed: MDP '{label}' is not allowed: its wind=[-0.228, 2.898] contradicts its label, which names the wind"
    refused_everywhere(path, message, cli, tmp_path)


@pytest.mark.parametrize("label", ["ghh08/wind=[zz]", "ghh09/wind=[-0.228, 2.898]"])
def test_a_wind_label_naming_no_wind_or_another_family_is_refused(flights: dict[str, Path], tmp_path: Path, label: str) -> None:
    def relabel(meta: dict) -> None:
        meta["mdps"][0]["label"] = label

    expected = "its label names no wind: give wind=[u, v]" if "zz" in label else "its label names a 'ghh09' MDP, but the MDP's family is 'ghh08'"
    with pytest.raises(NeurohoverError, match=rf"mdps entry 0 is not allowed: MDP '{label[:10]}.*' is not allowed: {re.escape(expected)}"):
        FlightData.load(edited_copy(flights["wind"], tmp_path / "named.npz", relabel))


def test_what_fly_wind_writes_loads_and_labels_it_does_not_write_are_left(flights: dict[str, Path], tmp_path: Path) -> None:
    """A wind of 0,0, -0 and 1e-5 (float32) loads as fly --wind wrote it; a --params label ('ghh08/custom') or any label
    of the user's names no parameters and is not checked."""
    labels = {FlightData.load(flights[n]).metadata["mdps"][0]["label"] for n in ("wind", "wind0", "wind-0")}
    assert labels == {"ghh08/wind=[-0.228, 2.898]", "ghh08/wind=[0.0, 0.0]", "ghh08/wind=[0.0, 1e-05]"}  # -0 is 0 (T31-A07)

    def older(meta: dict) -> None:  # as fly wrote a wind of -0 before T31-A07
        meta["mdps"][0]["label"] = "ghh08/wind=[-0.0, 1e-05]"

    assert FlightData.load(edited_copy(flights["wind-0"], tmp_path / "older.npz", older)).n_episodes == 1
    for label in ("ghh08/custom", "my wind", "ghh08/sample:3"):

        def relabel(meta: dict, label: str = label) -> None:
            meta["mdps"][0]["label"] = label

        assert FlightData.load(edited_copy(flights["wind"], tmp_path / "other.npz", relabel)).n_episodes == 1


# --------------------------------------------------------------------------- T24-06: policy_flown


@pytest.mark.parametrize(
    ("flown", "message"),
    [
        ("x", "policy_flown='x' is not allowed: it is no policy: a policy must be a JSON object with keys 'topology' and 'genome'"),
        ({"topology": "mlp", "genome": [0.0] * 3}, "is not allowed: it is no policy: a mlp genome has 42 genes, got shape (3,)"),
        ({"topology": "slp"}, "is not allowed: it is no policy: missing key(s) genome"),
        (False, "policy_flown=False is not allowed: it is no policy"),
    ],
)
def test_a_policy_flown_that_is_no_policy_is_refused(flights: dict[str, Path], tmp_path: Path, cli, flown: object, message: str) -> None:
    """T24-06: load, plot and learn-model --method lr took policy_flown 'x' or a genome of 3 genes; EC-MER alone refused."""

    def edit(meta: dict) -> None:
        meta["policy_flown"] = flown

    refused_everywhere(edited_copy(flights["f"], tmp_path / "flown.npz", edit), message, cli, tmp_path)
    f = FlightData.load(flights["f"])
    with pytest.raises(NeurohoverError, match=r"^flight data: its metadata policy_flown=.* is not allowed: it is no policy"):
        FlightData(f.observations, f.actions, {**f.metadata, "policy_flown": flown})


def test_a_policy_flown_that_did_not_fly_the_episodes_is_refused_at_load(flights: dict[str, Path], tmp_path: Path, cli) -> None:
    """T24-06: the real policy with genome[1] = 0.5 no longer gives the recorded actions: a float64 file is refused at
    load (200 steps flown again, whatever its size), and save() does not write one."""

    def edit(meta: dict) -> None:
        meta["policy_flown"]["genome"][1] = 0.5

    path = edited_copy(flights["f"], tmp_path / "gene.npz", edit)
    refused_everywhere(path, "it did not fly the episodes: at step 1 of episode 0 it gives action 0 = ", cli, tmp_path)
    f = FlightData.load(flights["f"])
    edited = FlightData(f.observations, f.actions, {**f.metadata, "policy_flown": json.loads(str(np.load(path)["metadata"]))["policy_flown"]})
    with pytest.raises(NeurohoverError, match=r"^flight data: its metadata policy_flown=.* is not allowed: it did not fly the episodes"):
        edited.save(tmp_path / "again.npz")
    assert not (tmp_path / "again.npz").exists()
    swapped = FlightData(f.observations, f.actions, {**f.metadata, "policy_flown": OTHER_POLICY})
    with pytest.raises(NeurohoverError, match=r"it did not fly the episodes: at step 1 of episode 0 it gives action 3 = 0.23 where"):
        FlightData.load(edited_copy(flights["f"], tmp_path / "swapped.npz", lambda m: m.update(policy_flown=OTHER_POLICY)))
    assert swapped.save(tmp_path / "f32.npz", dtype="float32").exists()  # float32: left to EC-MER's check (rounded readings)


def test_ec_mer_names_the_policy_flown_that_did_not_fly_them(flights: dict[str, Path], tmp_path: Path, cli) -> None:
    """T24-06: EC-MER's refusal of an edited policy_flown named 'baseline' (the policy's name), which it had not flown."""

    def edit(meta: dict) -> None:
        meta["policy_flown"]["genome"][1] = 0.5

    path = edited_copy(flights["f32"], tmp_path / "gene32.npz", edit)
    assert FlightData.load(path).n_episodes == 1  # float32: loads, rounded readings are not checked at load
    out = tmp_path / "m.json"
    rc, _, err = cli("learn-model", "--flight-data", str(path), "--method", "ec-mer", "--budget", "2", "--out", str(out))
    assert rc == 2 and not out.exists() and "Traceback" not in err, err
    assert "the policy their metadata policy_flown records (an slp network, genome [0.0, 0.5, " in err and ") did not fly them" in err, err
    assert "'baseline'" not in err, err


@pytest.mark.slow
def test_every_recording_fly_writes_loads_joined_saved_and_reloaded(flights: dict[str, Path], tmp_path: Path) -> None:
    """What is not refused: every file above (two policies, seeds, --wind, a noisy delayed sensor, crashes, float32),
    and their joins saved as float64 and float32 and loaded back."""
    loaded = {name: FlightData.load(path) for name, path in flights.items()}
    assert all(loaded["fall"].metadata["crashed"])
    names = list(loaded)
    for a, b in zip(names, names[1:] + names[:1]):
        joined = loaded[a] + loaded[b]
        for dtype in ("float64", "float32"):
            back = FlightData.load(joined.save(tmp_path / f"{a}-{b}-{dtype}.npz", dtype=dtype))
            assert back.n_episodes == joined.n_episodes and back.metadata == joined.metadata


def test_an_mdp_off_its_family_is_named_by_the_fields_at_fault(tmp_path: Path) -> None:
    """T25-13: a recorded ghh08/zero MDP with substeps 3 was said to differ in its wind_kind and wind too, which are the
    zero MDP's own (fly --record writes wind_kind 0, wind () for it); only the field at fault is named now (a D_u here:
    substeps 3 is refused before, as no MDP's, T27-B05)."""
    from neurohover.cli import main

    flown = tmp_path / "f0.npz"
    assert main(["fly", "--task", "ghh08", "--episodes", "1", "--record", str(flown)]) == 0

    def edit(meta: dict) -> None:
        meta["mdps"][0]["d_u"] = 0.5

    path = edited_copy(flown, tmp_path / "e06.npz", edit)
    with pytest.raises(NeurohoverError) as err:
        FlightData.load(path)
    assert "its d_u=0.5 differ from every ghh08 MDP's (d_u=0.0)," in str(err.value), str(err.value)
