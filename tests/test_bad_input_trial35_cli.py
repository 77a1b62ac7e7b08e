"""Bad-input trial 35 (the command line): a subnormal CMA-ES sigma0 taken, then pycma's AssertionError (T35-A01)."""

from __future__ import annotations

from pathlib import Path

import pytest


@pytest.mark.parametrize("sigma0", ["1e-320", "5e-324", "1e-101"])
def test_a_step_size_too_small_to_adapt_is_refused_before_flying(cli, tmp_path: Path, sigma0: str) -> None:
    out = tmp_path / "p.json"
    argv = ["evolve", "--task", "ghh08", "--optimizer", "cma", "--setting", f"sigma0={sigma0}", "--budget", "10", "--episode-steps", "20"]
    rc, _, err = cli(*argv, "--out", str(out))
    assert rc == 2 and "must be a finite number >= 1e-100 and <= 1e+100" in err and "Traceback" not in err, err
    assert not out.exists()
