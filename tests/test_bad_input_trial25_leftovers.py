"""Bad input, trial 25's leftovers: a results export written over a competition's episodes.csv.

``results NAME --out DIR/episodes.csv`` replaced a competition's episodes with the export's rows: held_kind knew only
JSON kinds, so a CSV output was checked by its suffix alone. Each CSV neurohover writes is now told apart by its header
(:data:`neurohover.filekinds.CSV_KINDS`), and an export replaces only an export."""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import CliRun, tiny_test_runs

from neurohover.compete import compete
from neurohover.compete_files import COMPETE_COLUMNS, CSV_COLUMNS
from neurohover.evolution.records import HISTORY_COLUMNS, HistoryRecord, write_history_csv
from neurohover.filekinds import CSV_KINDS, held_kind


@pytest.fixture(scope="module")
def written(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """A competition's folder, an evolution history and a results export (CSV) as neurohover writes them."""
    from neurohover.cli import main

    root = tmp_path_factory.mktemp("csv-kinds")
    compete("ghh08", "baseline", out=root / "c1", runs=1, episodes=2, n_steps=20)
    write_history_csv([HistoryRecord(1, 2, 2, 2, -5.0, 0.1)], root / "p.json.history.csv")
    (root / "tr1.toml").write_text(tiny_test_runs("baseline"))
    store = root / "s.sqlite"
    assert main(["reproduce", str(root / "tr1.toml"), "--store", str(store), "--no-progress"]) == 0
    assert main(["results", "tr1", "--store", str(store), "--out", str(root / "export.csv")]) == 0
    return {"episodes": root / "c1" / "episodes.csv", "history": root / "p.json.history.csv", "export": root / "export.csv", "store": store}


def test_each_csv_neurohover_writes_is_told_apart_by_its_header(written: dict[str, Path]) -> None:
    assert CSV_KINDS["a competition's episodes (episodes.csv)"] == set(COMPETE_COLUMNS) < set(CSV_COLUMNS)  # older files too
    assert CSV_KINDS["an evolution history (.history.csv)"] < set(HISTORY_COLUMNS)
    assert all(not a <= b for a in CSV_KINDS.values() for b in CSV_KINDS.values() if a is not b)  # no kind's cells hold another's
    kinds = {name: held_kind(written[name]) for name in ("episodes", "history", "export")}
    assert kinds == {
        "episodes": "a competition's episodes (episodes.csv)",
        "history": "an evolution history (.history.csv)",
        "export": "a results export (results --format csv)",
    }


def test_an_older_competitions_episodes_are_told_apart_too(tmp_path: Path) -> None:
    (tmp_path / "episodes.csv").write_text("run,episode,return\n0,0,-5.0\n")
    assert held_kind(tmp_path / "episodes.csv") == "a competition's episodes (episodes.csv)"
    (tmp_path / "other.csv").write_text("run,score\n0,1\n")
    assert held_kind(tmp_path / "other.csv") is None


def test_a_results_export_replaces_an_export_but_not_a_competitions_episodes(written: dict[str, Path], cli: CliRun) -> None:
    before = written["episodes"].read_bytes()
    rc, out, err = cli("results", "tr1", "--store", str(written["store"]), "--out", str(written["episodes"]))
    assert (rc, out) == (2, "") and written["episodes"].read_bytes() == before
    said = "is a competition's episodes (episodes.csv): give another path (writing a results export (results --format csv) there would destroy it)"
    assert err.strip().endswith(said), err
    assert cli("results", "tr1", "--store", str(written["store"]), "--out", str(written["export"]))[0] == 0  # the same kind again
    rc, _, err = cli("results", "tr1", "--store", str(written["store"]), "--format", "json", "--out", str(written["export"].with_suffix(".json")))
    assert rc == 0, err
