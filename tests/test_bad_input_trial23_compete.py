"""Bad-input trial 23, compete output directories as ``neurohover plot --compete`` reads them (neurohover.compete_files):
a summary.json of values compete never writes (T23-06) and an episodes.csv of rows no competition writes (T23-07), each
refused naming the file, the key or line, the value and what is allowed; what compete genuinely writes still reads."""

from __future__ import annotations

import json
import re
import shutil
from pathlib import Path

import pytest

from neurohover.compete_files import CSV_COLUMNS, SUMMARY_FIELDS, read_compete_dir
from neurohover.compete_labels import NO_SAFEGUARD, ONE_POLICY
from neurohover.errors import NeurohoverError

#: Small real competitions (2 runs of 3 episodes of 40 steps; fghh's of 2 of 20): (task, agent, extra arguments).
REAL = {
    "baseline": ("ghh08", "baseline", {}),
    "incremental": ("ghh08", "incremental", {}),  # learns: its policy changes, so its mean after learning is not its mean
    "hybrid": ("ghh08", "hybrid", {}),  # flies under a safeguard
    "fghh": ("fghh", "baseline", {"sigma": 0.5, "mdps": "sample", "episodes": 2, "n_steps": 20}),
}


@pytest.fixture(scope="module")
def real(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """Each competition of :data:`REAL` as ``neurohover compete --out`` writes it."""
    from neurohover.compete import compete

    root = tmp_path_factory.mktemp("real")
    for name, (task, agent, extra) in REAL.items():
        settings = {"runs": 2, "episodes": 3, "n_steps": 40} | extra
        compete(task, agent, out=root / name, **settings)  # type: ignore[arg-type]
    return {name: root / name for name in REAL}


def _copy(real: dict[str, Path], folder: Path, name: str = "baseline", **edits: object) -> Path:
    """The episodes.csv and summary.json of the real competition ``name`` in ``folder``, the summary's keys set as ``edits``."""
    folder.mkdir()
    shutil.copy(real[name] / "episodes.csv", folder / "episodes.csv")
    summary = json.loads((real[name] / "summary.json").read_text())
    (folder / "summary.json").write_text(json.dumps(summary | edits, indent=1))
    return folder


def _edit_rows(folder: Path, lines: list[int], column: str, value: str) -> None:
    """Set ``column`` of the episodes.csv's ``lines`` (2: the first row) to ``value``."""
    path = folder / "episodes.csv"
    rows = [line.split(",") for line in path.read_text().splitlines()]
    for line in lines:
        rows[line - 1][rows[0].index(column)] = value
    path.write_text("".join(",".join(r) + "\n" for r in rows))


def _refused(folder: Path, message: str, cli, tmp_path: Path) -> None:
    """``folder`` refused by read_compete_dir and by ``neurohover plot --compete`` (status 2, no traceback, no file),
    the message starting with the file's name and holding ``message``."""
    with pytest.raises(NeurohoverError, match=rf"^--compete '{re.escape(str(folder))}/.*{re.escape(message)}"):
        read_compete_dir(folder)
    rc, out, err = cli("plot", "--compete", str(folder), "--out", str(tmp_path / "plots"))
    assert rc == 2 and "Traceback" not in err and message in err and out == "", err
    assert not (tmp_path / "plots" / "compete.png").exists()


@pytest.mark.slow
def test_what_compete_writes_is_read(real: dict[str, Path], cli, tmp_path: Path) -> None:
    """T23-06/T23-07: every check takes what compete writes: baseline, a learning agent (its policy changes, the mean
    after learning from its last policy), an agent under a safeguard and fghh's sigma on sampled MDPs; its summary's keys
    are those checked, and compete writes the columns checked."""
    from neurohover import compete_folder  # the writer of compete's episodes.csv

    assert compete_folder.CSV_COLUMNS == CSV_COLUMNS
    for name, (task, agent, _) in REAL.items():
        result = read_compete_dir(real[name])
        assert result.label == f"{agent} ({task})" and result.returns.shape == ((2, 2) if name == "fghh" else (2, 3))
        assert list(json.loads((real[name] / "summary.json").read_text())) == list(SUMMARY_FIELDS)
    assert read_compete_dir(real["fghh"]).conditions["sigma"] == 0.5
    rc, out, err = cli("plot", "--compete", *(str(real[name]) for name in REAL), "--out", str(tmp_path / "plots"))
    assert rc == 0 and out.strip().endswith("compete.png"), err


SUMMARY_CASES = [
    ({"mean_return_after_learning": 5.0}, "says mean_return_after_learning 5.0 where its episodes.csv's returns average -"),
    ({"sigma": 0.5}, "says sigma 0.5, which compete never flies under: sigma applies to the fghh task only, not to 'ghh08'"),
    ({"mean_seconds_per_run": -1.0}, "its mean_seconds_per_run -1.0 is not allowed: a finite number of seconds >= 0 (what compete writes)"),
    ({"mean_offline_seconds_per_run": float("nan")}, "its mean_offline_seconds_per_run nan is not allowed: a finite number of seconds >= 0"),
    ({"seed": "x"}, "its seed 'x' is not allowed: an integer in 0..2**63-1 (what compete writes)"),
    ({"scale": "paper"}, "its scale 'paper' is not allowed: settings- and 10 hex digits (a digest of the settings)"),
    ({"store": 5}, "its store 5 is not allowed: the results store's path"),
    ({"note": "x"}, "its key 'note' is not allowed: compete writes the keys task, agent, mdps, seed, store, episode_steps, sigma,"),
]


@pytest.mark.slow
@pytest.mark.parametrize(("edits", "message"), SUMMARY_CASES, ids=[next(iter(e)) for e, _ in SUMMARY_CASES])
def test_a_summary_of_values_compete_never_writes_is_refused(real: dict[str, Path], cli, tmp_path: Path, edits: dict, message: str) -> None:
    """T23-06: a summary.json with mean_return_after_learning 5.0 (its rows give a mean <= 0), a sigma on a ghh08
    competition, negative or NaN seconds, seed 'x', scale 'paper', store 5 or a key compete never writes was plotted
    without a word; each is refused, naming the file, the key, the value and what is allowed."""
    _refused(_copy(real, tmp_path / "c", **edits), message, cli, tmp_path)


@pytest.mark.slow
def test_a_mean_after_learning_out_of_range_is_refused_where_the_rows_do_not_give_it(real: dict[str, Path], cli, tmp_path: Path) -> None:
    """T23-06: rows that name no policy (an older file) give no mean after learning to compare with; a positive one is
    still refused by its range."""
    folder = _copy(real, tmp_path / "c", mean_return_after_learning=5.0)
    _edit_rows(folder, list(range(2, 8)), "policy", "")
    _refused(folder, "its mean_return_after_learning 5.0 is not allowed: an episode's mean return, in [", cli, tmp_path)


ROWS = "episodes.csv', line "
ROW_CASES = [
    ([3], "mdp", "ghh08/test:1", f"{ROWS}3: mdp 'ghh08/test:1' is not allowed: run 0 flies 'ghh08/test:0' (line 2), and a run flies one MDP"),
    (
        [5, 6, 7],
        "mdp",
        "ghh08/test:999",
        f"{ROWS}5: mdp 'ghh08/test:999' is not allowed: a competition of 2 runs on ghh08's test MDPs flies ghh08/test:0 to ghh08/test:1",
    ),
    ([2], "safeguard_fired", "1", f"{ROWS}2: safeguard_fired '1' is not allowed: agent baseline flies under no safeguard"),
    ([2], "policy", "specialised:3", f"{ROWS}2: policy 'specialised:3' is not allowed: agent baseline flies 'baseline' only"),
]


@pytest.mark.slow
@pytest.mark.parametrize(("lines", "column", "value", "message"), ROW_CASES, ids=["two_mdps", "test999", "fired", "policy"])
def test_rows_no_competition_writes_are_refused_with_their_line(
    real: dict[str, Path], cli, tmp_path: Path, lines: list[int], column: str, value: str, message: str
) -> None:
    """T23-07: in episodes.csv one run on two MDPs, an MDP ghh08/test:999 of a 2-run competition (it flies test:0 and
    test:1), and safeguard_fired 1 and a policy 'specialised:3' for the baseline agent (no safeguard, one policy) were
    plotted without a word; each is refused, naming the line, the value and what is allowed."""
    folder = _copy(real, tmp_path / "c")
    _edit_rows(folder, lines, column, value)
    _refused(folder, message, cli, tmp_path)


@pytest.mark.slow
@pytest.mark.parametrize(
    ("header", "row", "message"),
    [
        (",note", ",x", f"{ROWS}1: column 'note' is not allowed: compete writes the columns {', '.join(CSV_COLUMNS)}, each once"),
        (",policy", ",x", f"{ROWS}1: column 'policy' is not allowed: compete writes the columns {', '.join(CSV_COLUMNS)}, each once"),
        ("", ",x", f"{ROWS}2: it holds 9 values where the header names 8 columns: give one value per column"),
    ],
    ids=["extra", "twice", "ragged"],
)
def test_a_column_compete_never_writes_is_refused(real: dict[str, Path], cli, tmp_path: Path, header: str, row: str, message: str) -> None:
    """T23-07: an extra column in episodes.csv (one compete never writes, or one of its own twice; or a row of more values
    than the header's columns) was ignored without a word; refused, naming it and the columns compete writes."""
    folder = _copy(real, tmp_path / "c")
    path = folder / "episodes.csv"
    path.write_text("".join(f"{line}{row if i else header}\n" for i, line in enumerate(path.read_text().splitlines())))
    _refused(folder, message, cli, tmp_path)


def test_the_agents_without_a_safeguard_are_those_registered_without_one() -> None:
    """T23-07: NO_SAFEGUARD (the agents whose safeguard_fired is 0 in every row) names registered agents, and every other
    registered agent flies under a safeguard (a Choice with a fallback): a new agent is added to one side or the other."""
    from neurohover.agents.registry import AGENTS

    assert NO_SAFEGUARD <= set(AGENTS) and set(ONE_POLICY) <= NO_SAFEGUARD
    with_safeguard = {"hybrid", "hybrid-baseline", "hybrid-risk", "hybrid-baseline-risk", "continual", "authors-zero", "authors-fixed", "authors-race"}
    assert set(AGENTS) - NO_SAFEGUARD == with_safeguard
