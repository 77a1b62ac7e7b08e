"""Trial 29a, output paths and the environment: T29-A01 (a name too long for evolve --out, with the files it writes beside
it, and the name suggested for one), T29-A03 (a TQDM_* variable tqdm cannot read), T29-A04 (a default build's policy-set
manifest told apart) and T29-A06 (no writer but build-policies adds files to a policy set's directory)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from neurohover.errors import NeurohoverError

EVOLVE = ("evolve", "--task", "ghh08", "--budget", "10", "--episode-steps", "20", "--out")


# T29-A01 ------------------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("name", ["a" * 300 + ".json", "a" * 300, "a" * 250], ids=["300.json", "300", "250"])
def test_evolve_refuses_a_name_too_long_for_it_or_its_checkpoint_by_name(cli, tmp_path: Path, name: str) -> None:
    """T29-A01: 300 characters were a bare "File name too long" printing the whole name; 250 without a suffix were told
    to take a 255-character .json name, whose checkpoint name (NAME.json.checkpoint.json) is too long."""
    from neurohover.filekinds import name_limit

    rc, _, err = cli(*EVOLVE, str(tmp_path / name))
    assert rc == 2 and f"is too long: at most {name_limit(tmp_path)} bytes in one file or directory name" in err, err
    assert "with the .checkpoint.json it writes beside it" in err and "File name too long" not in err and len(err) < 400, err
    assert list(tmp_path.iterdir()) == []


def test_the_json_name_suggested_for_evolve_out_is_one_evolve_takes(cli, tmp_path: Path) -> None:
    """T29-A01: the name suggested for --out without .json fits with the longest file evolve writes beside it."""
    from neurohover.filekinds import RUN_FILE_ENDS, name_limit
    from neurohover.policies import check_json_policy_name

    room = name_limit(tmp_path) - len(".json.checkpoint.json")
    given = tmp_path / ("a" * (room + 2))  # fits as given (room + 2 + 16 bytes), but not with .json added
    with pytest.raises(NeurohoverError, match=rf"give a path ending \.json \(e\.g\. .* \({len(str(tmp_path)) + 1 + room + 5:,} characters\)\)") as refused:
        check_json_policy_name(given, "--out", tuple(RUN_FILE_ENDS))
    assert "a" * (room + 2) + ".json" not in str(refused.value)
    suggested = tmp_path / ("a" * room + ".json")
    rc, _, err = cli(*EVOLVE, str(suggested))
    assert rc == 0 and suggested.is_file() and Path(f"{suggested}.checkpoint.json").is_file(), err


def test_a_file_of_the_longest_name_is_written_whole(tmp_path: Path) -> None:
    """T29-A01: the partial file beside a name of 250 bytes and more, .NAME.PID.partial, was too long to create."""
    from neurohover.filekinds import name_limit
    from neurohover.paths import output_file, writing

    out = output_file(tmp_path / ("b" * (name_limit(tmp_path) - 4) + ".csv"), "--out")
    with writing(out, "--out") as partial:
        partial.write_text("x\n")
    assert out.read_text() == "x\n" and list(tmp_path.iterdir()) == [out]


# T29-A03 ------------------------------------------------------------------------------------------------------------


def _run(*argv: str, **env: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, *argv], capture_output=True, text=True, env={**os.environ, **env}, timeout=120)


@pytest.mark.slow
def test_a_tqdm_variable_tqdm_cannot_read_is_refused_by_name(tmp_path: Path) -> None:
    """T29-A03: TQDM_MININTERVAL=abc was tqdm's ValueError traceback from fly, evolve, compete, learn-model, reproduce
    and report."""
    run = _run("-m", "neurohover", "fly", "--task", "ghh08", "--episodes", "1", TQDM_MININTERVAL="abc")
    why = "neurohover fly: error: environment variable TQDM_MININTERVAL='abc' is not allowed: tqdm (the progress bar) cannot read it"
    assert run.returncode == 2 and why in run.stderr and "Traceback" not in run.stderr, run.stderr


@pytest.mark.slow
def test_a_bar_not_drawn_does_not_import_tqdm_and_one_drawn_names_the_variable() -> None:
    """T29-A03: reproduce --no-progress imported tqdm, and its bad TQDM_POSITION, all the same."""
    script = (
        "import io, sys\n"
        "from neurohover.errors import NeurohoverError\n"
        "from neurohover.progress import progress_bar\n"
        "with progress_bar(total=3, disable=True) as bar:\n"
        "    bar.update(2); bar.total = 4; bar.refresh(); bar.set_postfix_str('x'); bar.write('said', file=sys.stdout)\n"
        "assert bar.n == 2 and list(progress_bar(iterable=[1, 2], file=io.StringIO())) == [1, 2]\n"
        "assert 'tqdm' not in sys.modules\n"
        "try:\n"
        "    progress_bar(total=3, disable=False)\n"
        "except NeurohoverError as err:\n"
        "    print(err)\n"
    )
    run = _run("-c", script, TQDM_POSITION="x")
    assert run.returncode == 0 and run.stdout.startswith("said\nenvironment variable TQDM_POSITION='x' is not allowed"), run.stdout + run.stderr


# T29-A04 and T29-A06 ------------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def sets(tmp_path_factory) -> dict[str, Path]:
    """Two tiny GHH-08 sets as build-policies builds them: its default optimiser (no "optimizer" in the manifest) and cma."""
    from neurohover.policysets import build_policy_set

    where = tmp_path_factory.mktemp("sets")
    built = {}
    for optimizer in ("ne", "cma"):
        build_policy_set("ghh08", where / optimizer, budget=2, n_steps=5, safety_episodes=1, optimizer=optimizer)
        built[optimizer] = where / optimizer
    assert "optimizer" not in json.loads((built["ne"] / "ghh08" / "manifest.json").read_text())
    return built


@pytest.mark.parametrize("optimizer", ["ne", "cma"])
def test_every_manifest_build_policies_writes_is_told_apart(sets, optimizer: str) -> None:
    """T29-A04: a default build's manifest (no "optimizer" key) was no neurohover file to the file-kind check, and
    results --out, evaluate-agent --json, learn-model --out and evolve --out wrote over it."""
    from neurohover.filekinds import POLICY_SET_KIND, held_kind
    from neurohover.policysets import policy_dir

    assert held_kind(sets[optimizer] / "ghh08" / "manifest.json") == POLICY_SET_KIND
    for task in ("ghh08", "ghh09", "fghh"):  # the shipped sets' too
        assert held_kind(policy_dir(task) / "manifest.json") == POLICY_SET_KIND


@pytest.mark.slow
@pytest.mark.parametrize("optimizer", ["ne", "cma"])
def test_no_writer_but_build_policies_adds_a_file_to_a_policy_set(cli, sets, tmp_path: Path, optimizer: str) -> None:
    """T29-A04, T29-A06: compete --out, evaluate-agent --json and evolve --out into a set's directory were taken (evolve
    --out over its manifest too, for a default build), and compete --policy-dir then refused the set."""
    folder = sets[optimizer] / "ghh08"
    before = {p.name: p.read_bytes() for p in folder.iterdir()}
    compete = ("compete", "--task", "ghh08", "--runs", "1", "--episodes", "2", "--episode-steps", "5", "--out")
    tries = [
        (*compete, str(folder), "--agent", "baseline"),
        ("evaluate-agent", "--task", "ghh08", "--policy", "baseline", "--n-mdps", "1", "--episode-steps", "5", "--json", str(folder / "ev.json")),
        (*EVOLVE, str(folder / "new.json")),
        (*EVOLVE, str(folder / "manifest.json")),
        ("fly", "--task", "ghh08", "--episodes", "1", "--record", str(folder / "flight.npz")),
    ]
    for argv in tries:
        rc, _, err = cli(*argv)
        assert rc == 2 and "a policy set's directory (its manifest.json)" in err and "give another directory" in err, (argv, err)
    assert {p.name: p.read_bytes() for p in folder.iterdir()} == before
    rc, _, err = cli(*compete, str(tmp_path / "k"), "--agent", "model-free", "--policy-dir", str(sets[optimizer]))
    assert rc == 0, err
