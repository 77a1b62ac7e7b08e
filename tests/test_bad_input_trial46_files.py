"""Bad-input trial 46 (files and names): T46-B01 (a flight-data member NAME.npy that is no .npy was an AttributeError),
T46-B02 (a flight-data archive with bytes in front was refused with NumPy's advice on pickles), T46-B09 (load_configs
given a NumPy string array: a ValueError, or all configs), T46-B10 (a README that is no UTF-8 was a UnicodeDecodeError
after the report was written), T46-B11 (a README's generated block twice: the second left stale), T46-B13 (a
directory or pipe to resume from "does not exist") and T46-B14 (evolve's checkpoint replaced a user's file, with a
false warning)."""

from __future__ import annotations

import os
import warnings
import zipfile

import numpy as np
import pytest
from flight_edits import recorded
from store_edits import begin

from neurohover.errors import CheckpointReplaced, NeurohoverError
from neurohover.flightdata import FlightData


@pytest.fixture(scope="module")
def flight(tmp_path_factory):
    return recorded(tmp_path_factory.mktemp("t46-flight"), 1)


@pytest.mark.parametrize("member", ["lengths.npy", "observations.npy", "actions.npy"])
@pytest.mark.parametrize("content", [b"", b"not an npy"])
def test_a_flight_data_member_that_is_no_npy_is_refused_by_name(flight, tmp_path, member, content):
    """T46-B01."""
    with zipfile.ZipFile(flight) as z:
        members = {n: z.read(n) for n in z.namelist()}
    members[member] = content
    bad = tmp_path / "bad.npz"
    with zipfile.ZipFile(bad, "w") as w:
        for name, data in members.items():
            w.writestr(name, data)
    with pytest.raises(NeurohoverError, match=f"is not a readable flight-data file: its member {member} is no NumPy array: allowed") as err:
        FlightData.load(bad)
    assert str(bad) in str(err.value)


@pytest.mark.parametrize("front", [b"\0" * 512, b"#!/bin/sh\nexit 0\n"])
def test_a_flight_data_archive_with_bytes_in_front_is_refused_as_such(flight, tmp_path, front):
    """T46-B02: not NumPy's "pickled (object) data ... allow_pickle"."""
    padded = tmp_path / "padded.npz"
    padded.write_bytes(front + flight.read_bytes())
    with pytest.raises(NeurohoverError) as err:
        FlightData.load(padded)
    said = str(err.value)
    assert "its zip archive has bytes in front of it: allowed an .npz that neurohover or numpy.savez wrote" in said and str(padded) in said, said
    assert "pickle" not in said
    assert FlightData.load(flight).n_transitions > 0  # the archive itself still loads


@pytest.mark.parametrize("name", [np.array(["fig2", "fig7"]), np.array(["all"]), np.array("all"), np.array(["fig2"]), None, b"all"])
def test_load_configs_refuses_anything_but_text_by_name(name):
    """T46-B09: two names were NumPy's "truth value is ambiguous", np.array(["all"]) gave every config."""
    from neurohover.experiments import load_configs
    from neurohover.experiments.config import load_config

    for load in (load_configs, load_config):
        with pytest.raises(NeurohoverError, match="is not allowed: give one experiment's name, 'all', or a path to a .toml config file"):
            load(name, "quick")
    assert [c.name for c in load_configs("fig2", "quick")] == ["fig2"]


B, E = "<!-- generated: status -->", "<!-- /generated: status -->"


@pytest.mark.parametrize(
    "readme",
    [
        f"# Étude\n{B}\nold\n{E}\n".encode("latin-1"),
        f"# Study\n{B}\nold\n{E}\n".encode("utf-16"),
        b"# \xed\xa0\x80\n" + f"{B}\nold\n{E}\n".encode(),
        f"# Study\n{B}\nold1\n{E}\n\n## Appendix\n{B}\nold2\n{E}\n".encode(),
    ],
    ids=["latin-1", "utf-16", "surrogate", "block-twice"],
)
def test_a_readme_the_report_cannot_fill_is_refused_before_anything_is_written(tmp_path, readme):
    """T46-B10 (a UnicodeDecodeError after report.md and the figures were written) and T46-B11 (the second copy of a
    block left stale without a word)."""
    from neurohover.experiments import Store, write_report

    out = tmp_path / "rep"
    out.mkdir()
    (out / "README.md").write_bytes(readme)
    with Store(tmp_path / "s.sqlite") as store:
        begin(store)
        with pytest.raises(NeurohoverError) as err:
            write_report(store, out)
    said = str(err.value)
    assert said.startswith(f"README {str(out / 'README.md')!r} ") and "nothing written" in said, said
    assert ("cannot be read: the report fills its generated blocks in UTF-8 text" in said) != ("more than once" in said), said
    assert sorted(os.listdir(out)) == ["README.md"] and (out / "README.md").read_bytes() == readme


RUN = {"topology": "slp", "budget": 10, "n_steps": 10}


def test_a_checkpoint_to_resume_from_that_is_no_file_is_named_as_without_resume(tmp_path):
    """T46-B13: a directory or a pipe was "no checkpoint to resume from: ... does not exist"."""
    from neurohover import get_task_family
    from neurohover.evolution import evolve

    mdp = get_task_family("ghh08").training_mdps()[0]
    (tmp_path / "adir").mkdir()
    os.mkfifo(tmp_path / "pipe.json")
    for name, said in (("adir", "is a directory; give a file path"), ("pipe.json", "is not a regular file (a device, pipe or socket); give a file path")):
        for resume in (False, True):
            with pytest.raises(NeurohoverError, match=f"^checkpoint '{tmp_path / name}' {said}".replace("(", r"\(").replace(")", r"\)")):
                evolve(mdp, checkpoint=tmp_path / name, resume=resume, **RUN)
    with pytest.raises(NeurohoverError, match="no checkpoint to resume from: .* does not exist"):
        evolve(mdp, checkpoint=tmp_path / "absent.json", resume=True, **RUN)


def test_evolve_replaces_no_file_at_its_checkpoint_path_but_a_checkpoint(tmp_path):
    """T46-B14: a user's notes (JSON or text) were replaced with a warning that they held a run's checkpoint; an empty
    file is taken without a word, a checkpoint replaced with the warning (T38-B08)."""
    from neurohover import get_task_family
    from neurohover.evolution import evolve

    mdp = get_task_family("ghh08").training_mdps()[0]
    for name, text in (("notes.json", '{"experiment": "my lab notes", "todo": ["fly more"]}'), ("plain.json", "hello, not json at all")):
        path = tmp_path / name
        path.write_text(text)
        with pytest.raises(NeurohoverError, match=f"^checkpoint '{path}' is a file neurohover did not write: give another path"):
            evolve(mdp, checkpoint=path, **RUN)
        assert path.read_text() == text
    empty = tmp_path / "empty.json"
    empty.touch()
    with warnings.catch_warnings():
        warnings.simplefilter("error", CheckpointReplaced)
        evolve(mdp, checkpoint=empty, **RUN)
    assert empty.read_text().startswith('{"format": "neurohover-evolution-checkpoint/')
    with pytest.warns(CheckpointReplaced, match="holds a run's checkpoint"):
        evolve(mdp, checkpoint=empty, seed=1, **RUN)


@pytest.mark.slow
def test_a_checkpoint_over_the_json_read_limit_is_still_a_checkpoint(tmp_path):
    """After T46-B14: a checkpoint of a large genome's CMA state (about 1,400 genes and more) is over the 64 MiB that
    held_kind parses, was called a file of no kind, and evolve then refused to write its own checkpoint over it."""
    from neurohover import get_task_family
    from neurohover.evolution import evolve
    from neurohover.filekinds import CHECKPOINT_KIND, held_kind

    big = tmp_path / "big.json"
    with open(big, "w") as f:  # a checkpoint's format first, as run.py writes it, then 65 MiB of state
        f.write('{"format": "neurohover-evolution-checkpoint/1", "pad": "')
        f.write("x" * (65 * 2**20))
        f.write('"}')
    assert held_kind(big) == CHECKPOINT_KIND
    mdp = get_task_family("ghh08").training_mdps()[0]
    with pytest.warns(CheckpointReplaced, match="holds a run's checkpoint"):
        evolve(mdp, checkpoint=big, **RUN)
    assert big.stat().st_size < 2**20
    other = tmp_path / "other.json"
    other.write_text('{"notes": "' + "x" * (65 * 2**20) + '"}')
    assert held_kind(other) is None
