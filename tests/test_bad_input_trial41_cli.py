"""Trial 41, side A (command line): T41-A01 (flight data, and every kind told apart by its ends, over 64 MiB was no
neurohover file, so evolve --out replaced it without a word), T41-A02 (fly --record and learn-model --out took no
writer lock: two runs at once both said they wrote the file), T41-A03 ('.5' in a TOML-valued option was read as text
and refused as "must be a finite number"), T41-A04 (plot --episodes 0--1 was a reversed range, with -1-0 as its
example)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from flight_edits import recorded

from neurohover.errors import NeurohoverError
from neurohover.experiments.config import parse_override
from neurohover.filekinds import FLIGHT_DATA_KIND, PNG_KIND, PNG_SIGNATURE, REPORT_HEADER, REPORT_KIND, SQLITE_HEADER, held_kind

BIG = 65 * 2**20  # past the 64 MiB held_kind read whole


def _sparse(path: Path, head: bytes, tail: bytes = b"") -> Path:
    """A file of BIG bytes or more: ``head``, a hole, ``tail`` at its end (cheap: nothing written between)."""
    with open(path, "wb") as f:
        f.write(head)
        f.seek(max(BIG, len(head)) - len(tail))
        f.write(tail)
        f.truncate(max(BIG, len(head)))
    return path


@pytest.mark.parametrize(
    ("head", "kind"),
    [
        (SQLITE_HEADER + bytes(84), "a results store (SQLite)"),
        (PNG_SIGNATURE + b"\x00\x00\x00\rIHDR", PNG_KIND),
        (REPORT_HEADER.encode() + b"\n", REPORT_KIND),
        (b"run,episode,return,crashed\n0,0,-1.5,false\n", "a competition's episodes (episodes.csv)"),
        (b"\xef\xbb\xbfgeneration,evaluations,episodes,champion_return\r\n", "an evolution history (.history.csv)"),
        (b"experiment,scale,key,kind\n", "a results export (results --format csv)"),
    ],
)
def test_a01_every_kind_told_by_its_head_is_told_whatever_its_size(tmp_path: Path, head: bytes, kind: str) -> None:
    assert held_kind(_sparse(tmp_path / "f.bin", head)) == kind


def test_a01_flight_data_over_64_mib_is_flight_data_and_not_replaced(tmp_path: Path, cli) -> None:
    """The archive's first member named in its head (neurohover's flight data) or only in its central directory at its
    end (numpy.savez of another order); a zip of no NumPy archive stays unknown."""
    real = recorded(tmp_path, 1).read_bytes()
    big = _sparse(tmp_path / "big.json", real[: len(real) // 2], real[len(real) // 2 :])
    assert held_kind(big) == FLIGHT_DATA_KIND
    argv = ["evolve", "--task", "ghh08", "--episode-steps", "20", "--budget", "10", "--out", str(big)]
    rc, _, err = cli(*argv)
    assert rc == 2 and "--out '" in err and "is flight data (a NumPy archive): give another path" in err, err
    assert big.stat().st_size == BIG
    np.savez(tmp_path / "other.npz", lengths=np.zeros(3), format=np.array("x"))  # format last: named at the end only
    other = (tmp_path / "other.npz").read_bytes()
    assert b"format.npy" not in other[:200]
    assert held_kind(_sparse(tmp_path / "o.csv", other[:200], other[-400:])) == FLIGHT_DATA_KIND
    assert held_kind(_sparse(tmp_path / "zip.json", b"PK\x03\x04" + bytes(26) + b"model.bin", b"PK\x05\x06")) is None
    assert held_kind(_sparse(tmp_path / "line.csv", b"run,episode,return" + b"x" * 2**21)) is None  # no header line in its head


def _second_run_inside_save(monkeypatch, owner: type, argv: list[str]) -> list[int]:
    """``owner.save`` patched to run ``neurohover ARGV`` once more, in-process, while the first run holds its output's
    lock (before it writes): no timing decides whether the two overlap. Returns the second run's exit statuses."""
    from neurohover.cli import main

    second: list[int] = []
    save = owner.save

    def save_during_another(self, path, *a, **k):
        if not second:
            second.append(main(argv))
        return save(self, path, *a, **k)

    monkeypatch.setattr(owner, "save", save_during_another)
    return second


def test_a02_a_second_fly_record_on_a_file_being_written_is_refused(tmp_path: Path, cli, monkeypatch) -> None:
    """The first run holds --record's lock while it writes: a second run on the file then is refused (the test, not
    the machine's speed, decides when the second starts: inside the first's save); one after the other still replaces it."""
    from neurohover.flightdata import FlightData

    monkeypatch.chdir(tmp_path)  # the names in messages short
    out = Path("r.npz")
    argv = ["fly", "--task", "ghh08", "--mdp", "train:1", "--episodes", "1", "--threads", "1", "--json", "--record", str(out)]
    second = _second_run_inside_save(monkeypatch, FlightData, argv)
    rc, _, err = cli(*argv)
    assert rc == 0 and second == [2] and out.is_file(), err
    assert f"--record '{out}' is being written by another run (pid " in err and "give another --record" in err, err
    assert not (tmp_path / ".r.npz.lock").exists()
    assert cli(*argv)[0] == 0  # sequential runs: the later replaces the file, as documented


def test_a02_a_second_learn_model_on_a_model_being_written_is_refused(tmp_path: Path, cli, monkeypatch) -> None:
    from neurohover.models import LearnedModel

    monkeypatch.chdir(tmp_path)  # the names in messages short
    data = recorded(tmp_path, 1)
    out = Path("m.json")
    argv = ["learn-model", "--flight-data", str(data), "--method", "lr", "--out", str(out)]
    second = _second_run_inside_save(monkeypatch, LearnedModel, argv)
    rc, _, err = cli(*argv)
    assert rc == 0 and second == [2] and out.is_file(), err
    assert f"--out '{out}' is being written by another run (pid " in err, err
    assert not (tmp_path / ".m.json.lock").exists()


def test_a02_a_second_results_export_or_evaluate_agent_rows_on_a_file_being_written_is_refused(tmp_path: Path, cli, monkeypatch) -> None:
    """results --out and evaluate-agent --json, the CLI's other single-file outputs, hold theirs alike: a second run
    started inside the first's export or flight is refused; the plot command writes into a directory, PNGs only."""
    import neurohover.experiments as experiments
    import neurohover.integrations.flying as flying
    from neurohover.cli import main
    from neurohover.experiments import Store

    monkeypatch.chdir(tmp_path)
    with Store("s.sqlite"):
        pass
    results = ["results", "fig2", "--store", "s.sqlite", "--out", "r.csv"]
    rows = ["evaluate-agent", "--task", "ghh08", "--policy", "baseline", "--n-mdps", "1", "--episodes", "1", "--episode-steps", "20", "--json", "e.json"]
    second: list[int] = []
    compare = flying.compare_agent

    def export_during_another(store, *a, **k) -> str:
        second.append(main(results))
        return "experiment,scale,key,kind\n"

    def flight_during_another(*a, **k):
        second.append(main(rows))
        return compare(*a, **k)

    monkeypatch.setattr(experiments, "export_results", export_during_another)
    monkeypatch.setattr(flying, "compare_agent", flight_during_another)
    rc, _, err = cli(*results)
    assert rc == 0 and second == [2] and "--out 'r.csv' is being written by another run (pid " in err, err
    rc, _, err = cli(*rows)
    assert rc == 0 and second == [2, 2] and "--json 'e.json' is being written by another run (pid " in err, err
    assert Path("r.csv").is_file() and Path("e.json").is_file() and not list(tmp_path.glob(".*.lock"))


@pytest.mark.parametrize(("value", "written"), [(".5", "0.5"), ("5.", "5.0"), ("+.5", "0.5"), ("-.5", "-0.5"), ("01", "1"), ("1.e5", "100000.0")])
def test_a03_a_number_toml_does_not_read_is_named_as_text(value: str, written: str) -> None:
    with pytest.raises(NeurohoverError) as err:
        parse_override(f"mutate_std={value}", "--setting")
    assert f"{value!r} is text, not a TOML number: write mutate_std={written}" in str(err.value)
    assert parse_override(f"mutate_std={written}", "--setting") == ("mutate_std", float(written) if "." in written else int(written))


@pytest.mark.parametrize("value", ["abc", "./x", "1.2.3", "v1.5", "inf", "1e5", "0.5"])
def test_a03_words_and_toml_numbers_are_read_as_before(value: str) -> None:
    assert parse_override(f"k={value}")[0] == "k"


def test_a03_on_the_command_line(cli, tmp_path: Path) -> None:
    argv = ["evolve", "--task", "ghh08", "--episode-steps", "20", "--budget", "10", "--out", str(tmp_path / "p.json")]
    rc, _, err = cli(*argv, "--setting", "mutate_std=.5")
    assert rc == 2 and "'.5' is text, not a TOML number: write mutate_std=0.5" in err, err
    argv = ["compete", "--task", "ghh08", "--agent", "hybrid-risk", "--runs", "1", "--episodes", "2", "--episode-steps", "20"]
    rc, _, err = cli(*argv, "--out", str(tmp_path / "c"), "--agent-setting", "level=5.")
    assert rc == 2 and "'5.' is text, not a TOML number: write level=5.0" in err, err


def test_a04_a_negative_episode_is_named_and_the_example_is_taken(tmp_path: Path, cli) -> None:
    from neurohover.cli.plots import _episodes

    with pytest.raises(NeurohoverError) as err:
        _episodes("0--1", 4)
    assert str(err.value) == (
        "--episodes '0--1' is not allowed: -1 is no episode number (they are 0 or more: the flight data hold episodes 0..3); "
        "give FIRST-LAST with 0 <= FIRST <= LAST, e.g. 0-3"
    )
    assert _episodes("0-3", 4) == [0, 1, 2, 3]
    with pytest.raises(NeurohoverError, match=r"'5-3' is out of range: the flight data hold episodes 0\.\.3"):
        _episodes("5-3", 4)  # its ends swapped, 3-5, would be out of range too
    with pytest.raises(NeurohoverError, match=r"'3-1' is a reversed range: .* e\.g\. 1-3$"):
        _episodes("3-1", 4)
    flight = recorded(tmp_path, 1)
    rc, _, err = cli("plot", str(flight), "--episodes", "0--1", "--out", str(tmp_path / "pl"))
    assert rc == 2 and "-1 is no episode number" in err and "e.g. 0-0" in err, err
