"""Bad-input trial 46 (46a), the environment: T46-A03 (under NUMBA_DISABLE_JIT=1 every evolution ended in "<intrinsic
_fetch_add> is not usable in pure-python": the lanes' atomic queue, fence and packed fma had no pure-Python form), T46-A04 (a
matplotlibrc that matplotlib accepts, text.usetex without LaTeX, savefig.dpi 1 or an empty axes.prop_cycle, made plot, compete,
plot --compete and report a traceback: the figures are drawn in matplotlib's default style)."""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys

import numpy as np
import pytest


def _neurohover(*args: str, env: dict[str, str] | None = None, cwd=None) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "neurohover", *args], env={**os.environ, **(env or {})}, cwd=cwd, capture_output=True, text=True, timeout=120)


@pytest.mark.slow
def test_a03_an_evolution_runs_as_plain_python_with_the_compiled_runs_champion(tmp_path, cli) -> None:
    """T46-A03: ``NUMBA_DISABLE_JIT=1 neurohover evolve`` (ne, cma; build-policies, reproduce's evolve units) was a traceback
    from sim/lanes.py's queue. Its champion is the compiled run's, its returns the same to rounding (the compiled kernel
    contracts some ``a*b + c`` into FMAs, plain Python does not)."""
    args = ("evolve", "--task", "ghh08", "--budget", "10", "--episode-steps", "5", "--validation-episodes", "1")
    run = _neurohover(*args, "--out", str(tmp_path / "python.json"), env={"NUMBA_DISABLE_JIT": "1"})
    assert run.returncode == 0 and "Traceback" not in run.stderr, run.stderr[-2000:]
    rc, _, err = cli(*args, "--out", str(tmp_path / "compiled.json"))
    assert rc == 0, err
    python, compiled = (json.loads((tmp_path / f"{name}.json").read_text()) for name in ("python", "compiled"))
    assert python["genome"] == compiled["genome"] and python["episodes"] == compiled["episodes"] == 50
    for key in ("champion_return", "validation_return"):
        assert python[key] == pytest.approx(compiled[key], rel=1e-12), key


def test_a03_the_pure_python_fma_rounds_once_and_the_queue_counts() -> None:
    from neurohover.sim.lanes import _python_fetch_add
    from neurohover.sim.packed import _python_fma

    assert _python_fma(1 + 2**-52, 1 - 2**-52, -1.0) == -(2.0**-104)  # a*b + c rounded twice is 0.0
    assert _python_fma(1e308, 10.0, -1e308) == math.inf and _python_fma(-1e308, 10.0, 0.0) == -math.inf  # past the largest float
    assert _python_fma(1e-200, 1e-200, 1.0) == 1.0 and _python_fma(1e300, 1e-300, -1.0) == pytest.approx(1e300 * 1e-300 - 1.0)
    assert str(_python_fma(-0.0, 1.0, -0.0)) == "-0.0" and str(_python_fma(2.0, 3.0, -6.0)) == "0.0"
    counter = np.array([5], dtype=np.int64)
    assert _python_fetch_add(counter, 1) == 5 and counter[0] == 6 and _python_fetch_add(counter, -1) == 6 and counter[0] == 5


#: A matplotlibrc that matplotlib accepts and that made every drawing command a traceback (T46-A04): LaTeX that is not
#: there (or is: usetex is then not matplotlib's default), a 1-dpi save (FreeType's "invalid ppem value"), no colours.
_USERS_RC = "text.usetex: True\nsavefig.dpi: 1\naxes.prop_cycle: cycler('color', [])\n"

#: The drawing commands in one process (matplotlib reads the rc once, at import): each one's exit status, then the rc.
_DRAWING = """
import sys
from pathlib import Path
from neurohover.cli import main
import matplotlib

config = Path("tr.toml")
config.write_text(sys.argv[1])
runs = [
    ["fly", "--task", "ghh08", "--episodes", "1", "--record", "f.npz"],
    ["plot", "f.npz", "--out", "flight"],
    ["compete", "--task", "ghh08", "--agent", "baseline", "--runs", "1", "--episodes", "2", "--episode-steps", "20", "--out", "c"],
    ["plot", "--compete", "c", "--out", "overlay"],
    ["reproduce", "tr.toml", "--store", "s.sqlite"],
    ["report", "--store", "s.sqlite", "--out", "report"],
]
print([main(argv) for argv in runs])
print(matplotlib.rcParams["text.usetex"], matplotlib.rcParams["savefig.dpi"], len(matplotlib.rcParams["axes.prop_cycle"]))
"""


@pytest.mark.slow
def test_a04_the_figures_are_drawn_in_matplotlibs_default_style_whatever_the_users_rc(tmp_path) -> None:
    """T46-A04: with that rc in ./matplotlibrc or $MATPLOTLIBRC, plot, compete (exit 1 after its runs were stored, no
    cumulative.png), plot --compete and report ended in a traceback. The figures are drawn in matplotlib's default style
    (plots.house_style), and the process's rcParams are the user's again afterwards."""
    from conftest import tiny_test_runs

    (tmp_path / "users.rc").write_text(_USERS_RC)
    run = subprocess.run(
        [sys.executable, "-c", _DRAWING, tiny_test_runs("baseline")],
        env={**os.environ, "MATPLOTLIBRC": str(tmp_path / "users.rc"), "MPLBACKEND": "Agg"},
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert run.returncode == 0 and "Traceback" not in run.stderr, run.stderr[-3000:]
    statuses, rc = run.stdout.strip().splitlines()[-2:]
    assert statuses == "[0, 0, 0, 0, 0, 0]", run.stderr[-3000:]
    assert rc == "True 1.0 0"  # the user's rc, read by matplotlib, still in force around neurohover's figures
    pngs = sorted(p.relative_to(tmp_path).as_posix() for p in tmp_path.rglob("*.png"))
    assert pngs == ["c/cumulative.png", "flight/f-episode0.png", "overlay/compete.png", "report/tr1-quick.png"], pngs
    from PIL import Image

    with Image.open(tmp_path / "overlay" / "compete.png") as image:
        assert image.size == (1100, 450)  # 11 x 4.5 inches at matplotlib's default savefig.dpi ("figure": 100), not 1


def test_a04_house_style_draws_in_the_defaults_and_gives_the_callers_rc_back(tmp_path) -> None:
    import matplotlib

    from neurohover.plots import house_style

    @house_style
    def seen() -> tuple:
        return matplotlib.rcParams["text.usetex"], matplotlib.rcParams["savefig.dpi"], matplotlib.get_backend()

    backend = matplotlib.get_backend()
    with matplotlib.rc_context({"text.usetex": True, "savefig.dpi": 1}):
        assert seen() == (False, "figure", backend)
        assert matplotlib.rcParams["text.usetex"] is True and matplotlib.rcParams["savefig.dpi"] == 1


def test_a04_the_envs_frames_are_drawn_whatever_the_users_rc() -> None:
    """After T46-A04: render_mode='rgb_array' drew its frames in the user's rc (an empty axes.prop_cycle was matplotlib's
    ZeroDivisionError at the first render, text.usetex without LaTeX a RuntimeError); they are drawn as every figure is."""
    import gymnasium as gym
    import matplotlib
    from cycler import cycler

    import neurohover  # noqa: F401  (registers the ids)

    with matplotlib.rc_context({"axes.prop_cycle": cycler(color=[]), "text.usetex": True}):
        env = gym.make("neurohover/GHH08-Short-v0", render_mode="rgb_array")
        env.reset(seed=0)
        first = env.render()
        env.step(np.zeros(4, dtype=np.float32))
        assert first.shape == env.render().shape and first.dtype == np.uint8
        env.close()
        assert matplotlib.rcParams["text.usetex"] is True  # the caller's rc given back
