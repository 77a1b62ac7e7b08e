"""Bad-input trial 33 (33b), the Python API: T33-B01 (an MDP label ``wind=[[[...]]]`` nested 1,000 deep was a
RecursionError), T33-B03 (a policy file's note nested 600 deep loaded, and the Policy could not be copied or pickled),
T33-B04 (plots.new_figure passed matplotlib's errors through), T33-B09 (a learned model's MDP labelled ``train:3`` without
its family), T33-B10 (PolicyTable kinds that contradict its padded genomes), T33-B11 (a Policy subclass's own act) and
T33-B13 (FlightData.load and LearnedModel.save refused an os.PathLike)."""

from __future__ import annotations

import copy
import dataclasses
import json
import pickle
import re
from pathlib import Path

import flight_edits as FE
import numpy as np
import pytest
from flight_edits import edited_copy, refused_everywhere

import neurohover as nh
from neurohover.errors import NeurohoverError

DEEP = 1000


@pytest.fixture(scope="module")
def flight(tmp_path_factory) -> Path:
    """A recording as ``neurohover fly --record`` writes it (ghh08 train:1, two episodes)."""
    return FE.recorded(tmp_path_factory.mktemp("flight"), 2)


def test_b01_a_wind_label_nested_deep_is_refused_by_name(flight: Path, cli, tmp_path: Path) -> None:
    """T33-B01: ``ghh08/wind=[[[...]]]`` 1,000 deep was a RecursionError from json.loads in the label's check, through
    dataclasses.replace, MDP.from_dict, FlightData.load, learn-model and plot; 10 deep was refused by name already."""
    m = nh.get_task_family("ghh08").mdp("train:0")
    label = "ghh08/wind=" + "[" * DEEP + "]" * DEEP
    with pytest.raises(NeurohoverError, match="its label names no wind: give wind=.u, v., a list of numbers"):
        dataclasses.replace(m, label=label)
    with pytest.raises(NeurohoverError, match="its label names no wind"):
        type(m).from_dict({**m.to_dict(), "label": label})

    def deep(meta: dict) -> None:
        meta["mdps"][0]["label"] = label

    path = edited_copy(flight, tmp_path / "deep.npz", deep)
    refused_everywhere(path, "its label names no wind", cli, tmp_path)
    assert dataclasses.replace(m, label="ghh08/wind=" + json.dumps(list(m.wind))).wind == m.wind  # its own wind still names it


def test_b03_a_policy_note_nested_deep_is_refused_at_load_and_save(tmp_path: Path) -> None:
    """T33-B03: a note 600 deep loaded (Python's JSON reader follows about 990 levels), and the Policy could then not be
    deep-copied or pickled. Notes nest at most 100 lists or tables deep, at load and at save alike."""
    b = nh.baseline_policy()
    path = tmp_path / "deep.json"
    for depth, taken in ((100, True), (101, False), (600, False)):
        note = "[" * depth + "]" * depth
        path.write_text(f'{{"topology": "slp", "genome": {json.dumps(b.genome.tolist())}, "note": {note}}}')
        if taken:
            p = nh.load_policy(path)
            assert copy.deepcopy(p) == p and pickle.loads(pickle.dumps(p)) == p
            nh.save_policy(p, tmp_path / "again.json")
            continue
        deep = r"its note \[\[\[.* is not allowed: it is nested more than 100 lists or tables deep$"
        with pytest.raises(NeurohoverError, match=r"^policy file '.*deep.json': " + deep):
            nh.load_policy(path)
        with pytest.raises(NeurohoverError, match="its note .* is not allowed: it is nested more than 100 lists or tables deep"):
            nh.save_policy(b, tmp_path / "out.json", note=json.loads(note))


def test_b03_a_flight_data_note_nested_deep_is_refused_at_load_and_save(flight: Path, tmp_path: Path) -> None:
    """T33-B03, the same in flight data: a metadata note 600 deep loaded, and the FlightData could not be deep-copied."""
    deep = "note=[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[... is not allowed: it is nested more than 100 lists or tables deep"

    def note(meta: dict) -> None:
        meta["note"] = json.loads("[" * 600 + "]" * 600)

    with pytest.raises(NeurohoverError, match=re.escape(f"flight-data file '{tmp_path / 'deep.npz'}': its metadata {deep}")):
        nh.FlightData.load(edited_copy(flight, tmp_path / "deep.npz", note))
    data = nh.FlightData.load(flight)
    with pytest.raises(NeurohoverError, match=re.escape(f"flight data metadata {deep}")):
        nh.FlightData(data.observations, data.actions, {**data.metadata, "note": json.loads("[" * 101 + "]" * 101)})
    kept = nh.FlightData(data.observations, data.actions, {**data.metadata, "note": json.loads("[" * 100 + "]" * 100)})
    assert copy.deepcopy(kept) == kept and nh.FlightData.load(kept.save(tmp_path / "kept.npz")) == kept


@pytest.mark.parametrize(
    ("args", "message"),
    [
        ((-1, 1), "figure width=-1 is out of range: allowed a number of inches, 0 < width <= 100"),
        ((float("nan"), 1), "figure width=nan is out of range: allowed a number of inches"),
        (("1", 1), "figure width='1' is not allowed: allowed a number of inches"),
        ((1, 0), "figure height=0 is out of range: allowed a number of inches, 0 < height <= 100"),
        ((1, 1, 10**9), "figure dpi=1000000000 is out of range: allowed an integer in 1..1000"),
        ((80, 2, 1000), "figure dpi=1000 is out of range: 80 inches at dpi 1000 is 80,000 pixels, and a side is at most 65,536 pixels"),
    ],
)
def test_b04_new_figure_refuses_sizes_matplotlib_cannot_draw(args: tuple, message: str) -> None:
    """T33-B04: plots.new_figure passed matplotlib's ValueError or TypeError through (dpi=10**9 only as it was saved)."""
    from neurohover.plots import new_figure

    with pytest.raises(NeurohoverError) as err:
        new_figure(*args)
    assert str(err.value) == message or str(err.value).startswith(message), str(err.value)
    assert new_figure(2.5, 1, dpi=50).get_size_inches().tolist() == [2.5, 1.0]


@pytest.mark.parametrize("label", ["train:3", "zero", "test:5", "seeded-train:2", "wind=[1.0, 2.0]"])
def test_b09_a_learned_models_mdp_takes_no_set_label_without_its_family(label: str) -> None:
    """T33-B09: T28-B09 refused 'ghh08/train:3' on a model's MDP, but 'train:3' or 'zero' was taken, and a policy evolved
    on it recorded the target 'train:3', a competition MDP's name."""
    from neurohover.models import LearnedModel, one_substep_params

    model = LearnedModel(tuple(one_substep_params()[0]), (0.1,) * 6, "lr")
    says = f"MDP {label!r} is not allowed: its label names a task family's MDP ({label!r}, as a family names its own), but the MDP is a learned model's"
    with pytest.raises(NeurohoverError, match=re.escape(says)):
        model.mdp(label=label)
    with pytest.raises(NeurohoverError, match=re.escape(says)):
        nh.MDP("model", substeps=1, dt=0.1, label=label)
    assert model.mdp(label="model/train:3").label == "model/train:3" and model.mdp(label="mine").label == "mine"


def test_b10_a_policy_table_row_whose_padding_is_not_zero_is_refused() -> None:
    """T33-B10: PolicyTable(kinds=[0, 0], genomes) flew an MLP row as an SLP (-31,508 against its own -39), though its
    genes 40 and 41, which pad an SLP row with zeros, showed the mistake. An SLP flown as an MLP cannot be told."""
    from neurohover.evaluate import PolicyTable

    t = PolicyTable.from_policies([nh.baseline_policy(), nh.prototype("mlp", "baseline")])
    says = "PolicyTable row 1 is not allowed: its kind 0 (slp) reads genes 0..39, but its gene 40 is 1.0, not the zero that pads an slp genome"
    with pytest.raises(NeurohoverError, match=re.escape(says)):
        PolicyTable(np.array([0, 0]), t.genomes)
    genomes = t.genomes.copy()
    genomes[0, 41] = np.nan
    with pytest.raises(NeurohoverError, match=re.escape("row 0 is not allowed: its kind 0 (slp) reads genes 0..39, but its gene 41 is nan")):
        PolicyTable(t.kinds, genomes)
    genomes[0, 41], genomes[0, 5] = 0.0, np.nan  # a non-finite gene it reads is flown, and crashes (documented)
    assert PolicyTable(t.kinds, genomes) == PolicyTable(t.kinds.astype(np.uint8), genomes)
    assert PolicyTable(np.array([1, 1]), t.genomes).kinds.tolist() == [1, 1]


class _PathLike:
    """An os.PathLike that is no pathlib object (a py.path.local, a fsspec local path)."""

    def __init__(self, text: str) -> None:
        self.text = text

    def __fspath__(self) -> str:
        return self.text


def test_b13_flight_data_and_model_files_take_an_os_pathlike(flight: Path, tmp_path: Path, monkeypatch) -> None:
    """T33-B13: FlightData.load refused an os.PathLike ("is not allowed: give a path"), and LearnedModel.save took its
    repr for the name ("give a path ending .json (e.g. '<__main__.json')"); load_policy, save_policy, FlightData.save
    and LearnedModel.load took it."""
    from neurohover.models import LearnedModel, one_substep_params

    monkeypatch.chdir(tmp_path)
    data = nh.FlightData.load(_PathLike(str(flight)))
    assert data == nh.FlightData.load(flight)
    assert data.save(_PathLike("again.npz")) == Path("again.npz")
    model = LearnedModel(tuple(one_substep_params()[0]), (0.1,) * 6, "lr")
    assert model.save(_PathLike("m.json")) == Path("m.json") and LearnedModel.load(_PathLike("m.json")) == model
    with pytest.raises(NeurohoverError, match=re.escape("model file 'm.txt' is not allowed: a model file is JSON; give a path ending .json (e.g. 'm.json')")):
        model.save(_PathLike("m.txt"))
    with pytest.raises(NeurohoverError, match=re.escape("flight-data file 'f.txt' is not allowed: flight data are a NumPy archive")):
        data.save(_PathLike("f.txt"))
    assert not Path("m.txt").exists() and not Path("f.txt").exists()


class _Still(nh.Policy):
    """A subclass whose own act gives no thrust: what a researcher writes to fly a controller of their own."""

    def act(self, observation):
        return (0.0, 0.0, 0.0, 0.0)


class _Named(nh.Policy):
    """A subclass that adds a method but keeps Policy's act: flown as its genome, as before."""

    def name(self) -> str:
        return "named"


def test_b11_a_policy_subclass_with_its_own_act_is_refused_where_flown_or_saved(tmp_path: Path) -> None:
    """T33-B11: a subclass's own act was ignored by evaluate, run_test and save_policy (the kernel flies the genome, a
    file holds it): it flew as the baseline, without a word. Refused where the kernel would fly it or a file hold it;
    evaluate_callable flies a Python act. A subclass that keeps Policy's act flies, and p.act itself is the user's."""
    from neurohover.agents.model_free import ModelFreeAgent
    from neurohover.agents.protocol import run_test

    b = nh.baseline_policy()
    family = nh.get_task_family("ghh08")
    m = family.mdp("train:0")
    still = _Still(b.topology, b.genome)
    says = "policy of type '_Still' is not allowed: it has an act of its own, which is never flown (the kernel flies the genome); fly your own act with"
    flown = (lambda: nh.evaluate(still, m, n_steps=5), lambda: nh.evaluate([b, still], m, n_steps=5))
    for call in (*flown, lambda: run_test(ModelFreeAgent([still]), family, m, episodes=1, n_steps=5)):
        with pytest.raises(NeurohoverError, match=re.escape(says)):
            call()
    with pytest.raises(NeurohoverError, match=re.escape("policy of type '_Still' is not allowed: it has an act of its own, which is never saved")):
        nh.save_policy(still, tmp_path / "still.json")
    assert not (tmp_path / "still.json").exists() and still.act([0.0] * 12) == (0.0, 0.0, 0.0, 0.0)
    named = _Named(b.topology, b.genome)
    assert nh.evaluate(named, m, n_steps=5).returns.tolist() == nh.evaluate(b, m, n_steps=5).returns.tolist()
    assert nh.load_policy(nh.save_policy(named, tmp_path / "named.json")) == b
