"""Small rough edges a newcomer met (issue 19): each mended, each checked."""

from __future__ import annotations

import importlib.util
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import neurohover as nh

ROOT = Path(__file__).parent.parent


def test_an_mdp_reads_as_plain_numbers() -> None:
    mdp = nh.get_task_family("ghh08").mdp("train:3")
    assert "np.float64" not in repr(mdp) and "params=(-0.18, -0.43" in repr(mdp)
    built = nh.get_task_family("fghh", 0.3).make(np.array(mdp.params))
    assert all(type(x) is float for x in built.params) and built.params == mdp.params


def test_make_images_help_describes_and_draws_nothing(tmp_path: Path) -> None:
    images = ROOT / "docs" / "images"
    before = {p.name: p.stat().st_mtime_ns for p in images.glob("*.png")}
    proc = subprocess.run([sys.executable, str(images / "make_images.py"), "--help"], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0 and "usage: make_images.py" in proc.stdout
    assert {p.name: p.stat().st_mtime_ns for p in images.glob("*.png")} == before


@pytest.mark.skipif(importlib.util.find_spec("stable_baselines3") is not None, reason="the examples extra is installed")
def test_the_ppo_example_without_its_extra_says_what_to_install() -> None:
    proc = subprocess.run([sys.executable, str(ROOT / "examples" / "ppo_ghh08.py"), "--help"], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2 and "Traceback" not in proc.stderr
    assert proc.stderr.strip().splitlines() == [
        f"examples/ppo_ghh08.py needs {'torch' if importlib.util.find_spec('torch') is None else 'stable_baselines3'}: "
        "pip install 'neurohover[examples]' (for a CPU build of torch first: pip install torch==2.13.0)"
    ]


@pytest.mark.skipif(importlib.util.find_spec("stable_baselines3") is not None, reason="the examples extra is installed")
def test_the_rl_zoo_evaluation_example_without_its_extra_says_what_to_install() -> None:
    proc = subprocess.run([sys.executable, str(ROOT / "examples" / "evaluate_rl_zoo.py"), "--help"], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2 and "Traceback" not in proc.stderr
    assert "needs stable_baselines3: pip install 'neurohover[examples]'" in proc.stderr


@pytest.mark.skipif(importlib.util.find_spec("evotorch") is not None, reason="evotorch is installed")
def test_the_evotorch_example_without_its_extra_says_what_to_install() -> None:
    proc = subprocess.run([sys.executable, str(ROOT / "examples" / "evotorch_snes.py"), "--help"], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2 and "Traceback" not in proc.stderr and "needs torch: pip install 'neurohover[evotorch]'" in proc.stderr


def test_plot_draws_only_the_episodes_asked_for(tmp_path: Path, capsys) -> None:
    from neurohover.cli import main

    flights = tmp_path / "f.npz"
    nh.evaluate(nh.baseline_policy(), nh.get_task_family("ghh08").zero(), episodes=4, record=True, n_steps=40).flight_data.save(flights)
    assert main(["plot", str(flights), "--episodes", "0,2-3"]) == 0
    assert sorted(p.name for p in tmp_path.glob("*.png")) == ["f-episode0.png", "f-episode2.png", "f-episode3.png"]
    capsys.readouterr()
    assert main(["plot", str(flights), "--episodes", "4"]) == 2
    assert "--episodes '4' is out of range: the flight data hold episodes 0..3" in capsys.readouterr().err


def test_compete_says_when_it_reuses_stored_runs(tmp_path: Path, capsys) -> None:
    from neurohover.cli import main

    args = ["compete", "--task", "ghh08", "--agent", "baseline", "--runs", "2", "--episodes", "3", "--out", str(tmp_path / "c")]
    assert main(args) == 0
    assert "reused" not in capsys.readouterr().err
    assert main(args) == 0
    assert "2 of 2 units (runs and the policies they fly) were already in" in capsys.readouterr().err


def test_a_failed_command_leaves_no_empty_output_directory(tmp_path: Path, capsys) -> None:
    from neurohover.cli import main
    from neurohover.experiments import Store

    Store(tmp_path / "empty.sqlite").close()
    out = tmp_path / "new" / "report"
    assert main(["report", "--store", str(tmp_path / "empty.sqlite"), "--out", str(out), "fig7"]) == 2
    err = capsys.readouterr().err
    assert "created directory" in err and f"removed the empty directory {str(tmp_path / 'new')!r}" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["empty.sqlite"]
    # compete: refused after its --out check (an unknown MDP), so nothing was written there either
    assert main(["compete", "--task", "ghh08", "--agent", "model-free", "--runs", "1", "--episodes", "2", "--mdps", "nope", "--out", str(out)]) == 2
    assert sorted(p.name for p in tmp_path.iterdir()) == ["empty.sqlite"]
    # a directory that was there already stays, empty or not
    (tmp_path / "mine").mkdir()
    assert main(["report", "--store", str(tmp_path / "empty.sqlite"), "--out", str(tmp_path / "mine"), "fig7"]) == 2
    assert (tmp_path / "mine").is_dir()


def test_flight_data_can_be_recorded_in_float32_in_half_the_space(tmp_path: Path, capsys) -> None:
    from neurohover.cli import main
    from neurohover.flightdata import FlightData

    sizes = {}
    for dtype in ("float64", "float32"):
        path = tmp_path / f"{dtype}.npz"
        assert main(["fly", "--task", "ghh08", "--mdp", "train:3", "--episodes", "2", "--record", str(path), "--record-dtype", dtype, "--json"]) == 0
        sizes[dtype] = path.stat().st_size
    capsys.readouterr()
    exact, rounded = FlightData.load(tmp_path / "float64.npz"), FlightData.load(tmp_path / "float32.npz")
    assert sizes["float32"] < 0.6 * sizes["float64"]
    for a, b in zip(exact.observations + exact.actions, rounded.observations + rounded.actions):
        assert b.dtype == np.float64 and np.array_equal(b, a.astype(np.float32).astype(np.float64))
    assert rounded.metadata["returns"] == exact.metadata["returns"]
    with pytest.raises(nh.NeurohoverError, match="flight-data dtype 'float16' is not allowed: use float64 or float32"):
        exact.save(tmp_path / "x.npz", dtype="float16")
