"""The sixteenth bad-input trial's findings at the command line and the package's import: the environment's numba and
matplotlib settings, integer options, a policy set's files and ``reproduce --only`` each give one clear message (exit 2 /
NeurohoverError) naming the value and what is allowed, before anything is run or stored."""

from __future__ import annotations

import argparse
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import tiny_model_learning

import neurohover
from neurohover.errors import NeurohoverError


def _command(env: dict[str, str], *args: str, code: str | None = None) -> subprocess.CompletedProcess:
    """``neurohover ARGS`` (or ``python -c CODE``) with ``env`` added to the environment."""
    argv = [sys.executable, "-c", code] if code is not None else [sys.executable, "-m", "neurohover", *args]
    return subprocess.run(argv, env={**os.environ, **env}, capture_output=True, text=True, timeout=120)


@pytest.mark.slow
def test_an_unknown_matplotlib_backend_is_named() -> None:
    """T16-1: MPLBACKEND=bogus was matplotlib's ValueError traceback from every command, --help too (pycma imports it)."""
    proc = _command({"MPLBACKEND": "bogus"}, "--help")
    assert proc.returncode == 2 and proc.stdout == "" and len(proc.stderr.splitlines()) == 1, proc.stderr
    assert proc.stderr.startswith("neurohover: error: environment variable MPLBACKEND='bogus' is not allowed: give one of matplotlib's backends (")
    assert " agg," in proc.stderr and proc.stderr.endswith("), or unset it\n")
    proc = _command({"MPLBACKEND": "pdf"}, code="import neurohover, matplotlib; print(matplotlib.get_backend())")
    assert proc.returncode == 0 and proc.stdout == "pdf\n", proc.stderr  # a known backend is matplotlib's, as without us


@pytest.mark.parametrize("layer", ["bogus", " omp", "tbb "])
def test_an_unknown_threading_layer_is_named(monkeypatch, layer: str) -> None:
    """T16-2: NUMBA_THREADING_LAYER=bogus was numba's traceback at the first flight ("unknown to Numba")."""
    monkeypatch.setenv("NUMBA_THREADING_LAYER", layer)
    allowed = "give one of default, safe, threadsafe, forksafe, omp, tbb, workqueue, or unset it"
    with pytest.raises(NeurohoverError, match=re.escape(f"environment variable NUMBA_THREADING_LAYER={layer!r} is not allowed: {allowed}")):
        neurohover._check_numba_variables()
    for good in ("workqueue", "OMP", "default", "forksafe"):
        monkeypatch.setenv("NUMBA_THREADING_LAYER", good)
        neurohover._check_numba_variables()
        neurohover._check_threading_layer()


def test_a_threading_layer_that_cannot_load_is_named(monkeypatch) -> None:
    """T16-2: NUMBA_THREADING_LAYER=tbb without TBB was numba's "No threading layer could be loaded" traceback at the first
    flight; the command line says so up front (exit 2)."""
    if neurohover._loads("numba.np.ufunc.tbbpool"):
        pytest.skip("Intel TBB is installed here: numba loads its layer")
    monkeypatch.setenv("NUMBA_THREADING_LAYER", "tbb")
    with pytest.raises(NeurohoverError, match=re.escape("NUMBA_THREADING_LAYER='tbb' names a threading layer numba cannot load here: it needs Intel TBB")):
        neurohover._check_threading_layer()
    proc = _command({"NUMBA_THREADING_LAYER": "bogus"}, "--help")
    assert proc.returncode == 2 and proc.stderr.startswith("neurohover: error: environment variable NUMBA_THREADING_LAYER='bogus' is not allowed")


@pytest.mark.parametrize(
    ("name", "value", "allowed"),
    [
        ("NUMBA_DISABLE_JIT", "x", "give 0 or 1 (1: the kernels run as plain Python, very slowly), or unset it"),
        ("NUMBA_BOUNDSCHECK", "x", "give 0 or 1 (1: every array index is checked), or unset it"),
        ("NUMBA_OPT", "x", "give 0, 1, 2, 3 or max (the compiler's optimisation level), or unset it"),
        ("NUMBA_OPT", "4", "give 0, 1, 2, 3 or max"),
        ("NUMBA_THREADING_LAYER_PRIORITY", "omp tbb", "give tbb, omp and workqueue in the order numba tries them"),
    ],
)
def test_numba_variables_numba_cannot_read_are_named(monkeypatch, name: str, value: str, allowed: str) -> None:
    """T16-3: NUMBA_DISABLE_JIT=x (NUMBA_OPT, NUMBA_BOUNDSCHECK) was numba's warning holding a Python traceback, then its
    default was flown."""
    monkeypatch.setenv(name, value)
    with pytest.raises(NeurohoverError, match=re.escape(f"environment variable {name}={value!r} is not allowed: {allowed}")):
        neurohover._check_numba_variables()
    for good in {"NUMBA_OPT": ("max", "0"), "NUMBA_THREADING_LAYER_PRIORITY": ("workqueue omp tbb",)}.get(name, ("0", "1")):
        monkeypatch.setenv(name, good)
        neurohover._check_numba_variables()


@pytest.mark.slow
def test_any_numba_variable_numba_cannot_parse_is_named() -> None:
    """T16-3: any other numba variable read with int() (NUMBA_DEBUG_CACHE=x) printed numba's warning with a traceback."""
    proc = _command({"NUMBA_DEBUG_CACHE": "x"}, "--help")
    assert (
        proc.returncode == 2
        and proc.stdout == ""
        and proc.stderr
        == (
            "neurohover: error: environment variable NUMBA_DEBUG_CACHE='x' is not allowed: numba cannot read it (ValueError: invalid literal "
            "for int() with base 10: 'x'); give what numba's docs allow, or unset it\n"
        )
    )
    proc = _command({"NUMBA_DEBUG_CACHE": "0"}, code="import neurohover")
    assert proc.returncode == 0 and proc.stderr == ""


def _integer_options() -> list[tuple[str, argparse.Action]]:
    """(command, option) of every option of every command that reads a whole number (its type gives 10 for '10')."""
    from neurohover.cli.app import build_parser

    parser = build_parser()
    commands = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction)).choices
    found = []
    for command, sub in commands.items():
        for action in sub._actions:
            try:
                reads = action.option_strings and callable(action.type) and type(action.type("10")) is int
            except (ValueError, TypeError, argparse.ArgumentTypeError):
                reads = False
            if reads:
                found.append((command, action))
    return found


INTEGER_OPTIONS = _integer_options()


@pytest.mark.parametrize(("command", "action"), INTEGER_OPTIONS, ids=[f"{c} {a.option_strings[0]}" for c, a in INTEGER_OPTIONS])
def test_every_integer_option_refuses_an_underscore(command: str, action: argparse.Action) -> None:
    """T16-4: --episodes 1_0 (every integer option, argparse's type=int) flew 10 episodes: int() reads '1_0' as 10."""
    for bad in ("1_0", "1_000", "\u0661"):
        with pytest.raises(ValueError):
            action.type(bad)
    assert action.type("10") == 10 and action.type(" -3 ") == -3


def test_integer_options_at_the_command_line(cli, capsys, tmp_path: Path) -> None:
    """T16-4 end to end, and the lists of whole numbers that read int() themselves (wins --runs, plot --episodes)."""
    from neurohover.cli.app import build_parser
    from neurohover.cli.plots import _episodes

    assert len(INTEGER_OPTIONS) >= 30  # every command's options were found
    with pytest.raises(SystemExit) as stop:  # argparse's own error
        cli("fly", "--task", "ghh08", "--episodes", "1_0")
    assert stop.value.code == 2 and "neurohover fly: error: argument --episodes: invalid integer value: '1_0'" in capsys.readouterr().err
    store = tmp_path / "s.sqlite"
    store.write_bytes(b"x")
    rc, _, err = cli("wins", "fig7", "--store", str(store), "--runs", "1_0")
    assert rc == 2 and "--runs '1_0' is not allowed: give whole numbers >= 1" in err
    with pytest.raises(NeurohoverError, match=re.escape("--episodes '0,1_0' is not allowed")):
        _episodes("0,1_0", 20)
    assert _episodes("0,3,10-12", 20) == [0, 3, 10, 11, 12]
    assert build_parser().parse_args(["fly", "--task", "ghh08", "--episodes", "10", "--seed", "7"]).episodes == 10


@pytest.mark.parametrize("damage", ["directory", "link loop"])
def test_a_policy_file_that_is_no_file_is_named(tmp_path: Path, damage: str) -> None:
    """T16-7: generic.json as a directory (or a symbolic-link loop) was "policy set ... is missing the generic policy"."""
    from neurohover.policysets import load_policy_set, policy_dir

    shutil.copytree(policy_dir("ghh08"), tmp_path / "ghh08")
    assert load_policy_set("ghh08", tmp_path).generic is not None  # the set as shipped loads
    generic = tmp_path / "ghh08" / "generic.json"
    generic.unlink()
    if damage == "directory":
        generic.mkdir()
        why = "is a directory; give a JSON file"
    else:
        generic.symlink_to("generic.json")
        why = "cannot be read (too many levels of symbolic links)"
    with pytest.raises(NeurohoverError, match=re.escape(f"policy set {str(tmp_path / 'ghh08')!r}: generic.json (the generic policy) {why}")):
        load_policy_set("ghh08", tmp_path)


ML_CONFIG = tiny_model_learning("ml16", "evolve")


class _UnitRan(Exception):
    pass


def test_only_matching_no_unit_is_refused_before_the_store_changes(cli, tmp_path: Path, monkeypatch) -> None:
    """T16-8: `reproduce table4 --only 'zzz*'` flew and stored the policy unit policy/generic, then refused: the store (new,
    a 0-byte file, or one holding another experiment) held the experiment, its unit and a failed session."""
    from neurohover.experiments import Store, load_config
    from neurohover.experiments.executors import LocalExecutor

    def run(self, units, on_result, on_error) -> None:
        raise _UnitRan([u.key for u in units])

    monkeypatch.setattr(LocalExecutor, "run", run)  # no unit may run: the refusal comes first
    config = tmp_path / "ml16.toml"
    config.write_text(ML_CONFIG)
    other = tmp_path / "other.toml"
    other.write_text(ML_CONFIG.replace('"ml16"', '"ml16other"'))
    held = tmp_path / "held.sqlite"
    with Store(held) as store:
        c = load_config(str(other), "quick")
        store.begin(c.name, c.scale, c.hash, c.to_dict())
    empty = tmp_path / "empty.sqlite"
    empty.write_bytes(b"")
    before = {path: path.read_bytes() for path in (held, empty)}
    for store_path in (tmp_path / "new.sqlite", empty, held):
        rc, _, err = cli("reproduce", str(config), "--scale", "quick", "--store", str(store_path), "--only", "zzz*", "--no-progress")
        assert rc == 2 and "ml16: --only 'zzz*' matches no unit; unit keys look like policy/generic, model/lr/test0" in err, err
        assert store_path.read_bytes() == before[store_path] if store_path in before else not store_path.exists()
    with pytest.raises(_UnitRan, match=re.escape("['policy/generic']")):  # a pattern of a later stage passes the check
        cli("reproduce", str(config), "--scale", "quick", "--store", str(tmp_path / "new.sqlite"), "--only", "model/lr/*", "--no-progress")
