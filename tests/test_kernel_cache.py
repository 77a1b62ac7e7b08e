"""numba's on-disk cache never runs a kernel compiled from older simulator sources.

The end-to-end test compiles a copy of the package in subprocesses (two compiles of the kernel's
integrate, a few seconds each), edits the copy and checks what runs.
"""

from __future__ import annotations

import ast
import importlib
import json
import os
import pkgutil
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from numba.core.registry import CPUDispatcher

import neurohover
from neurohover.sim._cache import SimSourceLocator, sim_source_hash

PACKAGE = Path(neurohover.__file__).resolve().parent

# Seeds one noise stream (envs/vector.py, compiled code linking sim/rng.py) and, with "step", flies
# one control step without noise or wind (sim/kernel.py's integrate, compiled code inlining sim/constants.py).
PROBE = """
import json, sys
import numpy as np
import neurohover
from neurohover.envs.vector import _seed_streams
from neurohover.sim import kernel
from neurohover.sim.constants import DEFAULT_PARAMS

out = {"file": neurohover.__file__}
rngs = np.zeros((1, 4), dtype=np.uint64)
_seed_streams(rngs, np.zeros(1, dtype=np.int64), np.array([[7, 3]], dtype=np.int64))
out["stream"] = [int(x) for x in rngs[0]]
if "step" in sys.argv:
    # One control step at rest, no noise or wind: integrate alone (a light compile) inlines GRAVITY.
    dyn = (*(float(x) for x in DEFAULT_PARAMS), 0.0)
    state = (0.0,) * 12 + (1.0,)
    wind = (0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    out["state"] = list(kernel.integrate(state, (0.0,) * 6, 0.0, 0.0, 0.0, 0.0, 0, dyn, 10, 0.01, wind))
out["stats"] = {
    name: [sum(f.stats.cache_hits.values()), sum(f.stats.cache_misses.values())]
    for name, f in (("seed_streams", _seed_streams), ("step", kernel.integrate))
    if hasattr(f, "stats")  # plain Python functions under NUMBA_DISABLE_JIT
}
print(json.dumps(out))
"""


def _edit(path: Path, old: str, new: str) -> None:
    text = path.read_text()
    assert text.count(old) == 1, f"{old!r} not found once in {path}"
    path.write_text(text.replace(old, new))


@pytest.mark.slow
def test_edits_outside_kernel_py_recompile_and_unchanged_sources_load_from_cache(tmp_path: Path) -> None:
    copy = tmp_path / "src"
    shutil.copytree(PACKAGE, copy / "neurohover", ignore=shutil.ignore_patterns("__pycache__", "*.nb[ic]"))
    (tmp_path / "probe.py").write_text(PROBE)
    env = {k: v for k, v in os.environ.items() if not k.startswith("NUMBA_")}
    env.update(PYTHONPATH=str(copy), NUMBA_CACHE_DIR=str(tmp_path / "numba-cache"))

    def run(*args: str, jit: bool = True) -> dict:
        e = env if jit else {**env, "NUMBA_DISABLE_JIT": "1"}
        proc = subprocess.run(
            [sys.executable, "-W", "ignore", str(tmp_path / "probe.py"), *args], env=e, cwd=tmp_path, capture_output=True, text=True, timeout=600
        )
        assert proc.returncode == 0, proc.stderr
        out = json.loads(proc.stdout)
        assert Path(out["file"]).resolve().is_relative_to(copy)
        return out

    first = run("step")
    assert first["stats"] == {"seed_streams": [0, 1], "step": [0, 1]}  # compiled, cache empty

    again = run("step")
    assert again["stats"] == {"seed_streams": [1, 0], "step": [1, 0]}  # loaded, no compile
    assert again["state"] == first["state"] and again["stream"] == first["stream"]

    # A constant the kernel inlines: gravity doubles the climb of the first step.
    _edit(copy / "neurohover/sim/constants.py", "GRAVITY = 9.81\n", "GRAVITY = 19.62\n")
    heavier = run("step")
    assert heavier["stats"]["step"] == [0, 1]
    assert heavier["state"][2] == pytest.approx(2 * first["state"][2], rel=0.05)
    assert heavier["state"] == pytest.approx(run("step", jit=False)["state"], rel=1e-12, abs=1e-15)

    # A constant of the random streams that a function outside sim/ links in.
    _edit(copy / "neurohover/sim/rng.py", "_U64(0xD1B54A32D192ED03)", "_U64(0xD1B54A32D192ED05)")
    rekeyed = run()
    assert rekeyed["stats"]["seed_streams"] == [0, 1]
    assert rekeyed["stream"] != first["stream"]
    assert rekeyed["stream"] == run(jit=False)["stream"]


def test_every_cached_function_of_the_package_is_keyed_on_the_simulator_sources() -> None:
    dispatchers = []
    for info in pkgutil.walk_packages(neurohover.__path__, "neurohover."):
        if info.name.endswith("__main__") or info.name.startswith("neurohover.integrations."):
            continue  # the integrations import optional libraries and compile nothing
        module = importlib.import_module(info.name)
        dispatchers += [f for f in vars(module).values() if isinstance(f, CPUDispatcher) and f.__module__ == module.__name__]
    assert len(dispatchers) > 20
    for f in dispatchers:
        assert isinstance(f._cache._impl.locator, SimSourceLocator), f.__qualname__


@pytest.mark.slow
def test_simulator_modules_import_nothing_of_the_package_outside_sim() -> None:
    # The hash covers sim/*.py only, so compiled code there must not depend on other modules of ours. The one exception,
    # neurohover.errors, holds no compiled code: the Python entry points' argument checks raise its NeurohoverError.
    for path in (PACKAGE / "sim").glob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom) and node.level == 2 and node.module == "errors":
                continue
            if isinstance(node, ast.ImportFrom):
                assert node.level <= 1, f"{path.name} imports from outside sim/: {ast.unparse(node)}"
                assert node.level == 1 or not (node.module or "").startswith("neurohover"), ast.unparse(node)
            elif isinstance(node, ast.Import):
                assert not any(a.name.startswith("neurohover") for a in node.names), ast.unparse(node)


def test_source_hash_sees_every_simulator_file(tmp_path: Path) -> None:
    for name in ("constants.py", "rng.py", "kernel.py"):
        shutil.copy(PACKAGE / "sim" / name, tmp_path / name)
    before = sim_source_hash(tmp_path)
    assert sim_source_hash(tmp_path) == before
    for name in ("constants.py", "rng.py"):
        with open(tmp_path / name, "a") as f:
            f.write("\n")
        assert sim_source_hash(tmp_path) != before
        before = sim_source_hash(tmp_path)


def test_a_command_says_when_the_kernel_is_about_to_compile(monkeypatch, capsys) -> None:
    """Issue 37: the first flight of a fresh install compiles for tens of seconds; the command says so first."""
    import neurohover.sim as sim
    from neurohover.cli import main
    from neurohover.sim import _cache
    from neurohover.sim.lanes import fly_queue

    assert main(["fly", "--task", "ghh08", "--episodes", "1"]) == 0
    capsys.readouterr()
    assert sim.kernel_compiled() and _cache.compiled_on_disk(fly_queue)  # compiled now: no note
    assert not _cache.compiled_on_disk(object())  # what numba's cache cannot answer counts as not compiled
    monkeypatch.setattr(sim, "kernel_compiled", lambda: False)
    assert main(["fly", "--task", "ghh08", "--episodes", "1"]) == 0
    assert "compiling the simulation kernel" in capsys.readouterr().err
    assert main(["fly", "--task", "ghh08", "--episodes", "1", "--json"]) == 0  # one JSON object, nothing else said
    assert capsys.readouterr().err == ""
    assert main(["results", "fig2", "--store", "absent.sqlite"]) == 2  # a command that flies nothing says nothing of it
    assert "compiling" not in capsys.readouterr().err
