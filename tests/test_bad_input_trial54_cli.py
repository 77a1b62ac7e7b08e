"""Bad-input trial 54, side A (the command line): a negative inf or nan given as an option's separate argument
(``--sigma -inf``, ``--wind -nan,0``, ``--checkpoint-every -Infinity``) said only argparse's "expected one argument":
it is joined to its option as a negative number is (T54-A02), and the option's own check names it."""

from __future__ import annotations

from pathlib import Path

import pytest


@pytest.mark.parametrize(
    ("argv", "said"),
    [
        (("fly", "--task", "fghh", "--episodes", "1", "--sigma", "-inf"), "FGHH sigma=-inf is out of range"),
        (("fly", "--task", "ghh08", "--episodes", "1", "--wind", "-nan,0"), "GHH-08 wind (wind_u, wind_v) must be finite numbers"),
        (("fly", "--task", "ghh08", "--episodes", "1", "--wind", "-Infinity,0"), "GHH-08 wind (wind_u, wind_v) must be finite numbers"),
        (("fly", "--task", "ghh08", "--episodes", "1", "--obs-noise", "-INF"), "sensor noise level=-inf is out of range"),
        (("evolve", "--task", "ghh08", "--budget", "5", "--out", "e.json", "--checkpoint-every", "-Infinity"), "--checkpoint-every -inf is out of range"),
        (("compete", "--task", "ghh09", "--agent", "hybrid", "--runs", "1", "--episodes", "2", "--out", "c", "--safeguard-tilt", "-nan"), "safeguard tilt"),
    ],
)
def test_a02_a_negative_inf_or_nan_apart_from_its_option_is_named_by_the_option(tmp_path: Path, monkeypatch, cli, argv, said: str) -> None:
    monkeypatch.chdir(tmp_path)
    rc, _, err = cli(*argv)
    assert rc == 2 and said in err and "expected one argument" not in err, err
    assert sorted(p.name for p in tmp_path.iterdir()) == []  # refused before anything is written
