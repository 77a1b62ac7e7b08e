"""Trial 42, side A (command line): T42-A02 (plot --compete checked a hand-edited summary.json against its store only at
the summary's own scale, so a scale edited too let an edited sensor through), T42-A03 (plot FLIGHT.npz left the figures
of another flight of the same name beside its own without a word, where report names its own) and T42-A04 (evolve --out
through a symbolic link to a file in a policy set replaced the set's policy, and the set was then refused)."""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

import pytest
from flight_edits import recorded
from store_edits import edited_policy_set

from neurohover.errors import NeurohoverError

COMPETE = ("compete", "--task", "ghh08", "--agent", "baseline", "--runs", "1", "--episodes", "2", "--episode-steps", "10")
EVOLVE = ("evolve", "--task", "ghh08", "--budget", "10", "--episode-steps", "20", "--out")


@pytest.mark.slow
def test_a02_a_summary_naming_a_scale_its_store_does_not_hold_is_refused(tmp_path: Path, monkeypatch, cli) -> None:
    """The store there and holding the experiment, at its real scale only: the summary's scale is named, and the
    scales the store holds; a store no longer there is still not read (documented)."""
    monkeypatch.chdir(tmp_path)
    rc, _, err = cli(*COMPETE, "--out", "a")
    assert rc == 0, err
    summary = json.loads((tmp_path / "a" / "summary.json").read_text())
    real = summary["scale"]
    plot = ("plot", "--out", str(tmp_path / "png"), "--compete", "a")
    for edit in ({"scale": "settings-0000000000"}, {"scale": "settings-0000000000", "sensor": {"level": 0.5}}):
        shutil.rmtree("b", ignore_errors=True)
        shutil.copytree("a", "b")
        (tmp_path / "b" / "summary.json").write_text(json.dumps({**summary, **edit, "store": str(tmp_path / "b" / "results.sqlite")}))
        rc, _, err = cli(*plot, "b")
        assert rc == 2 and "Traceback" not in err and len(err.strip().splitlines()) == 1, err
        assert "'b/summary.json'" in err and "its scale 'settings-0000000000' is not one its store" in err, err
        assert f"holds for compete-ghh08-baseline: it holds {real}" in err, err
        assert not (tmp_path / "png" / "compete.png").exists()
    (tmp_path / "b" / "results.sqlite").unlink()  # a store no longer there is not read (the documented limit)
    assert cli(*plot, "b")[0] == 0


@pytest.mark.slow
def test_a03_plot_names_the_figures_of_another_flight_it_leaves(tmp_path: Path, cli) -> None:
    """Never removed; a flight's own episodes (of another --episodes choice) and files of other names are not named."""
    flight = recorded(tmp_path, 2)
    out = tmp_path / "p"
    out.mkdir()
    left = ["f-episode2.png", "f-episode10.png", "f-episode00.png"]
    others = ["f-episode1.png", "g-episode5.png", "f-episode3.png.bak", "f-episodex.png"]
    for name in left + others:
        (out / name).write_bytes(b"old")
    rc, stdout, err = cli("plot", str(flight), "--out", str(out), "--episodes", "0")
    assert rc == 0 and stdout.splitlines()[-1] == str(out / "f-episode0.png"), (stdout, err)  # after recorded's own line
    assert len(err.strip().splitlines()) == 1 and err.startswith(f"neurohover plot: note: {str(out)!r} holds figures of another flight named 'f'"), err
    assert "(this one has 2 episode(s)), left in the folder (remove them if unwanted): f-episode2.png, f-episode00.png, f-episode10.png" in err
    assert all((out / name).read_bytes() == b"old" for name in left + others if name != "f-episode1.png")
    for name in left:
        (out / name).unlink()
    rc, _, err = cli("plot", str(flight), "--out", str(out), "--episodes", "0")
    assert rc == 0 and err == "", err


def test_a04_no_writer_writes_through_a_file_link_into_a_policy_set(tmp_path: Path, monkeypatch, cli) -> None:
    """evolve --out and save_policy through a symbolic link to a set's policy are refused, naming the set; a hard link is
    replaced by evolve, the set unharmed."""
    from neurohover.policies import baseline_policy, save_policy
    from neurohover.policysets import load_policy_set

    monkeypatch.chdir(tmp_path)
    where = edited_policy_set(tmp_path, "ghh08", lambda manifest: None)
    folder = where / "ghh08"
    before = {p.name: p.read_bytes() for p in folder.iterdir()}
    for target in ("generic.json", "ancestor.json", "specialised_0.json"):
        link = tmp_path / f"to-{target}"
        link.symlink_to(folder / target)
        rc, _, err = cli(*EVOLVE, link.name)
        assert rc == 2 and f"--out '{link.name}' is a symbolic link to a file in '" in err and "pd/ghh08' (" in err, err  # cut by brief
        assert "), which is a policy set's directory (its manifest.json)" in err, err
        with pytest.raises(NeurohoverError, match="is a symbolic link to a file in .*, which is a policy set's directory"):
            save_policy(baseline_policy(), link)
    (tmp_path / "chain.json").symlink_to(tmp_path / "to-generic.json")  # a link to a link into the set
    rc, _, err = cli(*EVOLVE, "chain.json")
    assert rc == 2 and "a policy set's directory (its manifest.json)" in err, err
    assert {p.name: p.read_bytes() for p in folder.iterdir()} == before
    os.link(folder / "specialised_3.json", tmp_path / "hl.json")
    rc, _, err = cli(*EVOLVE, "hl.json")
    assert rc == 0 and not (tmp_path / "hl.json").samefile(folder / "specialised_3.json"), err  # replaced, not written through
    assert {p.name: p.read_bytes() for p in folder.iterdir()} == before
    assert len(load_policy_set("ghh08", where).specialised) == 10
