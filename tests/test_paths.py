"""Output files written whole or not at all, and paths refused by name before anything is made (issue 37)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from neurohover import NeurohoverError
from neurohover.paths import NAME_MAX, checked_path, output_file, write_png, writing


def test_an_interrupted_write_leaves_the_old_file_and_no_partial_one(tmp_path: Path) -> None:
    """fourth trial: a Ctrl-C or SIGTERM while fly --record wrote left a half-written .npz that no reader could open."""
    out = tmp_path / "rec.npz"
    out.write_text("the old result\n")
    with pytest.raises(KeyboardInterrupt), writing(out, "--record") as partial:
        partial.write_text("half of the new")
        raise KeyboardInterrupt
    assert out.read_text() == "the old result\n" and sorted(p.name for p in tmp_path.iterdir()) == ["rec.npz"]
    with writing(out, "--record") as partial:
        partial.write_text("the new result\n")
    assert out.read_text() == "the new result\n" and sorted(p.name for p in tmp_path.iterdir()) == ["rec.npz"]


@pytest.mark.parametrize("given, too_long", [("x" * 300 + ".json", 305), ("d/" + "y" * 256 + "/p.json", 256)], ids=["file", "directory"])
def test_a_name_longer_than_the_file_system_takes_is_refused_by_name(tmp_path: Path, given: str, too_long: int) -> None:
    """fourth trial: a 300-character file name was an OSError [Errno 36] traceback in every command."""
    with pytest.raises(NeurohoverError, match=rf"--out .* is too long: at most {NAME_MAX} bytes in one file or directory name \(here {too_long}\)"):
        output_file(tmp_path / given, "--out")
    assert list(tmp_path.iterdir()) == []
    assert checked_path("x" * NAME_MAX, "--out").name == "x" * NAME_MAX


@pytest.mark.slow
def test_every_command_names_a_name_too_long_without_a_traceback(tmp_path: Path) -> None:
    long = str(tmp_path / ("x" * 300 + ".json"))
    for argv in (["fly", "--task", "ghh08", "--episodes", "1", "--policy", long], ["results", "fig7", "--store", long]):
        run = subprocess.run([sys.executable, "-m", "neurohover", *argv], capture_output=True, text=True)
        assert run.returncode == 2 and "is too long: at most 255 bytes" in run.stderr and "Traceback" not in run.stderr, run.stderr


def _full_disk(tmp_path: Path) -> Path:
    """A 64 KiB tmpfs already 40 KiB full (root only: skipped with the reason elsewhere)."""
    disk = tmp_path / "full"
    disk.mkdir()
    if os.geteuid() != 0 or subprocess.run(["mount", "-t", "tmpfs", "-o", "size=64k", "tmpfs", str(disk)], capture_output=True).returncode:
        pytest.skip("a full disk needs a tmpfs, which only root can mount here")
    (disk / "pad").write_bytes(bytes(40 * 1024))
    return disk


def test_a_full_disk_leaves_no_empty_figure_store_or_partial_file(tmp_path: Path) -> None:
    """fourth trial: a full disk left a 0-byte PNG (and a traceback) and a 0-byte results.sqlite, which the next
    compete refused as 'not a neurohover results store'."""
    from matplotlib.figure import Figure

    from neurohover.experiments import Store

    disk = _full_disk(tmp_path)
    try:
        fig = Figure(figsize=(30, 30), dpi=100)
        fig.add_subplot().plot(range(1000), [i * i for i in range(1000)])
        with pytest.raises(NeurohoverError, match="plot file .*cannot write it .No space left on device.; no partial file is left"):
            write_png(fig, disk / "f.png", "plot file")
        with pytest.raises(NeurohoverError, match="cannot create the results store .* no file is left"):
            Store(disk / "results.sqlite")
        assert sorted(p.name for p in disk.iterdir()) == ["pad"]
    finally:
        subprocess.run(["umount", str(disk)], check=False)


def test_a_config_file_name_too_long_and_bad_safeguard_limits_are_named() -> None:
    """fourth trial: `reproduce <300 x's>.toml` was an OSError, safeguard_limits='x' NumPy's ValueError."""
    from neurohover import evaluate_jobs, get_task_family
    from neurohover.experiments import load_config
    from neurohover.policies import baseline_policy

    with pytest.raises(NeurohoverError, match="config file .* is too long"):
        load_config("x" * 300 + ".toml", "quick")
    jobs = [0]
    with pytest.raises(NeurohoverError, match="safeguard_limits must be 25 numbers"):
        evaluate_jobs([baseline_policy()], [get_task_family("ghh08").zero()], jobs, jobs, jobs, n_steps=20, fallback_index=jobs, safeguard_limits="x")
