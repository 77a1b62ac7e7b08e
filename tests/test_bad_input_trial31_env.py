"""Bad-input trial 31 (31a), the environment and the locale: T31-A01 (characters the plot font lacks leaked matplotlib's
"Glyph ... missing" UserWarnings), T31-A05 (under an ASCII locale a config's non-ASCII path was "no such directory", with an
unquoted suggested command), T31-A06 (NUMBA_DISABLE_JIT=1 leaked the RNG's uint64 overflow RuntimeWarnings, a traceback under
PYTHONWARNINGS=error), T31-A07 (a wind of -0.0 made another MDP label, so --resume called the same run "a different run"),
and the borderline note: under NUMBA_NUM_THREADS the --threads range names the variable that limits it."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest


def _neurohover(*args: str, env: dict[str, str] | None = None, cwd=None) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "neurohover", *args], env={**os.environ, **(env or {})}, cwd=cwd, capture_output=True, text=True, timeout=120)


@pytest.mark.slow
def test_a06_the_pure_python_kernel_wraps_its_uint64_arithmetic_silently() -> None:
    """T31-A06: NUMBA_DISABLE_JIT=1 (numba's documented pure-Python switch) printed "overflow encountered" from sim/rng.py's
    SplitMix64 and xoshiro256**, whose uint64 products wrap on purpose; under PYTHONWARNINGS=error ``fly`` was a traceback."""
    run = _neurohover("fly", "--task", "ghh08", "--episodes", "1", env={"NUMBA_DISABLE_JIT": "1", "PYTHONWARNINGS": "error"})
    assert run.returncode == 0 and "Traceback" not in run.stderr, run.stderr[-2000:]
    assert "overflow" not in run.stderr and "RuntimeWarning" not in run.stderr, run.stderr[-2000:]
    assert "mean_return: -962.946" in run.stdout, run.stdout  # the compiled kernel's return: the same streams
    assert "compiling" not in run.stderr, run.stderr  # nothing compiles under it: the note said so on every run


def test_a06_the_compiled_streams_are_still_numbas() -> None:
    from numba.core.registry import CPUDispatcher

    from neurohover.sim import rng

    assert all(isinstance(f, CPUDispatcher) for f in (rng.splitmix64, rng.seed_stream, rng.next_u64))


def test_a07_a_wind_of_minus_zero_is_the_mdp_of_zero(tmp_path) -> None:
    """T31-A07: ``evolve --wind=1,-0 --resume`` over a checkpoint of ``--wind=1,0`` (the same MDP) was refused as "a different run":
    the MDP label kept the sign ('ghh08/wind=[1.0, -0.0]'). An MDP's numbers read -0.0 as 0.0, as a policy's genes do (T28-B15)."""
    from neurohover.evolution.evolve import evolve
    from neurohover.tasks import MDP, get_task_family

    ghh08 = get_task_family("ghh08")
    assert ghh08.make([1.0, -0.0]).label == "ghh08/wind=[1.0, 0.0]" == ghh08.make([1.0, 0.0]).label
    assert str(ghh08.make([-0.0, -0.0]).to_dict()["wind"]) == "[0.0, 0.0]"
    model = MDP("model", params=(-0.0,) * 11, d_u=-0.0, label="model/lr")
    assert str(model.params[0]) == "0.0" and str(model.d_u) == "0.0"
    ckpt = tmp_path / "run.ckpt.json"
    given = dict(budget=5, checkpoint=ckpt, topology="slp", prototype="baseline", seed=3, n_steps=20)
    evolve(ghh08.make([1.0, 0.0]), **given)
    resumed = evolve(ghh08.make([1.0, -0.0]), **{**given, "budget": 100}, resume=True)
    assert resumed.history


def test_a07_the_cli_resumes_a_wind_of_minus_zero(tmp_path, cli) -> None:
    from neurohover.evolution.evolve import evolve
    from neurohover.tasks import get_task_family

    out = tmp_path / "p.json"
    evolve(get_task_family("ghh08").make([1.0, 0.0]), budget=5, checkpoint=f"{out}.checkpoint.json", seed=0, n_steps=20)
    rc, _, err = cli("evolve", "--task", "ghh08", "--wind=1,-0", "--budget", "100", "--episode-steps", "20", "--out", str(out), "--resume")
    assert rc == 0 and "different run" not in err, err


def test_the_thread_range_names_numba_num_threads_where_it_limits(monkeypatch) -> None:
    """Trial 31a, borderline: under NUMBA_NUM_THREADS=1 on 2 cores, --threads 2 was "allowed 1..1 on this machine"."""
    import numba
    import pytest

    from neurohover.errors import NeurohoverError
    from neurohover.launch import num_threads

    monkeypatch.setattr(numba.config, "NUMBA_DEFAULT_NUM_THREADS", 2, raising=False)
    monkeypatch.setattr(numba.config, "NUMBA_NUM_THREADS", 1, raising=False)
    with pytest.raises(NeurohoverError, match=r"^threads=2 is out of range: allowed 1\.\.1 under NUMBA_NUM_THREADS=1 \(this machine has 2 cores\)$"):
        with num_threads(2):
            pass
    monkeypatch.setattr(numba.config, "NUMBA_NUM_THREADS", 2, raising=False)
    with pytest.raises(NeurohoverError, match=r"^threads=3 is out of range: allowed 1\.\.2 on this machine$"):
        with num_threads(3):
            pass


@pytest.mark.slow
def test_a01_a_character_the_plot_font_lacks_is_one_note(tmp_path, cli, monkeypatch) -> None:
    """T31-A01: a flight-data name with 𝄞 or CJK (legal) made ``plot`` print matplotlib's "Glyph ... missing from font(s)"
    UserWarnings with their source lines (from plots.py's tight_layout and paths.py's savefig); now one neurohover note."""
    import warnings

    import neurohover as nh
    from neurohover import plots

    monkeypatch.setattr(plots, "_NOTED_GLYPHS", set())
    monkeypatch.chdir(tmp_path)
    data = nh.evaluate(nh.load_policy("baseline"), nh.get_task_family("ghh08").zero(), n_steps=20, record=True).flight_data
    data.save(tmp_path / "u 𝄞中.npz")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("error")  # PYTHONWARNINGS=error: a glyph warning was a traceback
        rc, out, err = cli("plot", "u 𝄞中.npz", "--out", "u13")
    assert rc == 0 and not caught, err
    assert "UserWarning" not in err and "Glyph" not in err, err
    notes = [line for line in err.splitlines() if "note" in line]
    assert notes == ["neurohover: note: the plot font (DejaVu Sans) has no glyph for '𝄞' (U+1D11E), '中' (U+4E2D): drawn as boxes"], err
    assert (tmp_path / "u13" / "u 𝄞中-episode0.png").stat().st_size > 0 and out.strip() == "u13/u 𝄞中-episode0.png"


def test_a01_the_figure_helpers_note_once_and_keep_other_warnings(tmp_path, capsys, monkeypatch) -> None:
    import warnings

    import pytest

    from neurohover import plots

    monkeypatch.setattr(plots, "_NOTED_GLYPHS", set())
    fig = plots.new_figure(3, 2)
    fig.add_subplot().set_title("t\u6587\u5b57")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        with plots.noting_missing_glyphs():
            fig.tight_layout()
        plots.save_figure(fig, tmp_path / "a.png")
        plots.save_figure(fig, tmp_path / "b.png")
    assert not [w for w in caught if "Glyph" in str(w.message)], [str(w.message) for w in caught]
    assert capsys.readouterr().err == "neurohover: note: the plot font (DejaVu Sans) has no glyph for '文' (U+6587), '字' (U+5B57): drawn as boxes\n"
    with pytest.warns(RuntimeWarning, match="kept"):
        with plots.noting_missing_glyphs():
            warnings.warn("kept", RuntimeWarning, stacklevel=1)


ASCII_LOCALE = {"LC_ALL": "C", "PYTHONUTF8": "0", "PYTHONIOENCODING": ""}

_A05_SCRIPT = """
import sys
from pathlib import Path
from neurohover.errors import NeurohoverError
from neurohover.experiments import Store
from neurohover.experiments.config import make_config
from neurohover.experiments.external import dir_champions as _dir_champions, load_external as _load_external
from neurohover.experiments.report import write_report

print(sys.getfilesystemencoding())
try:
    _load_external("ghh08", "pd \\xe9")
except NeurohoverError as err:
    print(ascii(str(err)))
try:
    _dir_champions("dir:pd \\xe9")
except NeurohoverError as err:
    print(ascii(str(err)))
settings = dict(task="ghh08", seed=1, policies="shipped", episodes=2, n_steps=20, groups=[dict(agent="baseline", mdps="test", n_mdps=1)])
cfg = make_config("ml1", "test_runs", "quick", settings, title="t\\u4e2d\\u6587")
with Store(Path(sys.argv[1]) / "s.sqlite") as store:
    store.begin(cfg.name, cfg.scale, cfg.hash, cfg.to_dict())
    print(write_report(store, Path(sys.argv[1]) / "rep"))
"""


@pytest.mark.slow
def test_a05_an_unencodable_config_path_is_refused_by_its_encoding_and_the_report_is_utf8(tmp_path) -> None:
    """T31-A05: under LC_ALL=C PYTHONUTF8=0 a config's policies = "pd é" (an existing set, read as --policy-dir reads it) was
    "no such directory": the ASCII file system encoding cannot encode it. It is refused naming the encoding, as every path
    entry point does (T31-B03), with the UTF-8 locale to run under; and report.md is UTF-8 under any locale (it wrote
    the title as escapes)."""
    (tmp_path / "pd é").mkdir()
    run = subprocess.run([sys.executable, "-c", _A05_SCRIPT, str(tmp_path)], env={**os.environ, **ASCII_LOCALE}, capture_output=True, text=True,
                         encoding="utf-8", timeout=120)  # fmt: skip
    assert run.returncode == 0 and "Traceback" not in run.stderr, run.stderr
    lines = run.stdout.splitlines()
    assert lines[0] == "ascii", lines
    assert lines[1] == ascii(
        "policies = 'pd \xe9' is not allowed: the file system's encoding (ascii) cannot encode the characters '\\xe9' in it: give a name "
        "of characters it can encode or run under a UTF-8 locale (LC_ALL=C.UTF-8, or PYTHONUTF8=1)"
    ), lines
    assert lines[2].startswith(ascii("generics_from dir: 'pd \xe9' is not allowed: the file system's encoding (ascii) cannot encode")[:-1]), lines
    assert "## t\u4e2d\u6587 [quick]" in (tmp_path / "rep" / "report.md").read_text(encoding="utf-8")


def test_a05_the_suggested_build_command_is_quoted(tmp_path) -> None:
    import pytest

    from neurohover.errors import NeurohoverError
    from neurohover.experiments.external import load_external as _load_external

    missing = str(tmp_path / "pd 1")
    with pytest.raises(NeurohoverError) as err:
        _load_external("ghh08", missing)
    assert str(err.value).endswith(f"(no such directory; build it with: neurohover build-policies --task ghh08 --out '{missing}')")
