"""The twenty-seventh bad-input trial's findings in policy-file records, stored test runs and compete output: a return
no episode of the recorded length can have (-1e9 of a 20-step episode, whose worst is about -34,976) was taken as a
policy file's champion_return or validation_return, a stored run's return and a compete row's return (T27-B03); a
compete folder without summary.json whose uncrashed episodes have different lengths was plotted (T27-B04); a policy
file's episode_steps of -5, 0 or '20' beside no n_steps was loaded (T27-B07); a stored test run whose policy_changes
name no policy for episode 0 ([] or [[1, 'specialised:1']]) was exported (T27-B09). Each is refused in one message
naming the file or unit, the field, the value and what is allowed."""

from __future__ import annotations

import json
import sqlite3
from pathlib import Path

import pytest
from conftest import CliRun, tiny_test_runs
from policy_edits import edited, evolved_policy_file, refused
from store_edits import refused_by_every_command
from test_bad_input_trial23_results import _edited, _refused, _reproduced

import neurohover as nh
from neurohover.compete_files import read_compete_dir
from neurohover.sim.constants import CRASH_STEP_PENALTY, lowest_return

RUN = "run/model-free/test0/rep0"
HEADER = "run,mdp,episode,return,crashed,steps,policy,safeguard_fired\n"


@pytest.fixture(scope="module")
def policy_file(tmp_path_factory) -> Path:
    """A policy file as evolve writes it: a 10-episode run of 20-step episodes on ghh08/train:0."""
    return evolved_policy_file(tmp_path_factory.mktemp("p27"))


@pytest.fixture(scope="module")
def mf(tmp_path_factory) -> tuple[Path, Path]:
    """A config of one model-free test run (two 20-step episodes on a GHH-08 test MDP) and a store of it."""
    return _reproduced(tmp_path_factory.mktemp("mf27"), tiny_test_runs("model-free", name="mf1"))


def test_the_lowest_return_is_the_worst_step_for_every_step() -> None:
    """The bound every check shares: 20 steps of the worst step, about -34,976."""
    assert lowest_return(20) == -20 * CRASH_STEP_PENALTY
    assert -34_980 < lowest_return(20) < -34_970


@pytest.mark.parametrize("key", ["champion_return", "validation_return"])
def test_a_policy_files_return_below_its_episodes_lowest_is_refused(policy_file: Path, tmp_path: Path, key: str) -> None:
    """T27-B03 (1): a 20-step run's champion_return or validation_return of -1e9 was loaded; the file's own loads."""
    record = json.loads(policy_file.read_text())
    assert record["n_steps"] == record["episode_steps"] == 20
    nh.load_policy(policy_file)
    nh.load_policy(edited(policy_file, tmp_path / "low.json", **{key: lowest_return(20)}))
    refused(edited(policy_file, tmp_path / "p.json", **{key: -1e9}), f"its {key} -1000000000.0 is not allowed", "-34976", "n_steps 20")
    refused(edited(policy_file, tmp_path / "q.json", n_steps=None, **{key: -1e9}), f"its {key} -1000000000.0 is not allowed", "episode_steps 20")


@pytest.mark.parametrize("steps", [-5, 0, "20", 2.5, 10**8])
def test_a_policy_files_episode_steps_is_a_count_of_steps(policy_file: Path, tmp_path: Path, steps: object) -> None:
    """T27-B07: episode_steps was only compared with n_steps: -5, 0 or '20' beside no n_steps were loaded."""
    nh.load_policy(edited(policy_file, tmp_path / "ok.json", n_steps=None))
    refused(edited(policy_file, tmp_path / "p.json", n_steps=None, episode_steps=steps), "its episode_steps", "is not allowed", "control steps per episode")


def test_a_stored_return_below_its_episodes_lowest_is_refused_by_every_command(mf, cli: CliRun, tmp_path: Path) -> None:
    """T27-B03 (2): a stored 20-step run's return of -1e9 (its score matching) was exported and reported."""
    config, good = mf
    store = _edited(good, tmp_path / "s.sqlite", RUN, returns=lambda r: [-1e9, *r["returns"][1:]], score=lambda r: -1e9 + sum(r["returns"][1:]))
    says = "returns[0] = -1000000000.0 is not allowed: its unit's episodes are 20 control steps long: allowed at least -34976"
    line = _refused(store, "mf1", RUN, says)
    refused_by_every_command(cli, config, store, "mf1", line, tmp_path / "r")


@pytest.mark.parametrize(
    ("changes", "shown"), [([], "policy_changes = []"), ([[1, "specialised:1"]], "policy_changes[0] = [1, 'specialised:1']")], ids=["none", "late"]
)
def test_a_stored_run_with_no_policy_for_episode_0_is_refused_by_every_command(mf, cli: CliRun, tmp_path: Path, changes: list, shown: str) -> None:
    """T27-B09: policy_changes of [] or starting past episode 0 were exported: every episode flies a policy (every run of
    the committed store's 8,786 starts at episode 0)."""
    config, good = mf
    with sqlite3.connect(good) as conn:
        (stored,) = conn.execute("SELECT result FROM units WHERE key = ?", (RUN,)).fetchone()
    conn.close()
    assert json.loads(stored)["policy_changes"][0] == [0, "specialised:0"]
    store = _edited(good, tmp_path / "s.sqlite", RUN, policy_changes=changes)
    line = _refused(store, "mf1", RUN, f"{shown} is not allowed: every episode flies a policy, so the changes start at episode 0")
    refused_by_every_command(cli, config, store, "mf1", line, tmp_path / "r")


def _folder(at: Path, *rows: str) -> Path:
    """A compete folder without summary.json whose episodes.csv holds ``rows``."""
    at.mkdir()
    (at / "episodes.csv").write_text(HEADER + "".join(f"{row}\n" for row in rows))
    return at


def test_a_compete_row_below_its_episodes_lowest_is_refused(tmp_path: Path, cli: CliRun) -> None:
    """T27-B03 (3): a 20-step row returning -1e9 was plotted; the lowest a 20-step episode can return is taken."""
    low = lowest_return(20)
    assert read_compete_dir(_folder(tmp_path / "ok", f"0,ghh08/test:0,0,{low!r},0,20,specialised:0,0")).returns.shape == (1, 1)
    bad = _folder(tmp_path / "bad", "0,ghh08/test:0,0,-1e9,0,20,specialised:0,0")
    rc, _, err = cli("plot", "--compete", str(bad), "--out", str(tmp_path / "pl"))
    assert rc == 2 and "line 2: return -1000000000.0 is not allowed: allowed at least -34976" in err and "of its 20 steps" in err, err


@pytest.mark.parametrize(
    ("rows", "says"),
    [
        (("0,5,0", "1,20,0"), "line 3: steps 20 is not allowed: an uncrashed episode of 20 steps, where line 2's uncrashed episode flies 5 steps"),
        (("0,20,0", "1,25,1"), "line 3: steps 25 is not allowed: a crash at step 25, where line 2's uncrashed episode flies 20 steps"),
    ],
    ids=["uncrashed", "crash-past"],
)
def test_compete_rows_of_different_episode_lengths_are_refused(tmp_path: Path, cli: CliRun, rows: tuple, says: str) -> None:
    """T27-B04: uncrashed rows of 5 and 20 steps (no summary) were plotted; a crash before the end is taken."""
    line = "0,ghh08/test:0,{0},{1},{2},{3},specialised:{0},0"
    ok = _folder(tmp_path / "ok", line.format(0, -100.0, 0, 20), line.format(1, -30000.0, 1, 5))
    assert read_compete_dir(ok).crashes == 1
    bad = _folder(tmp_path / "bad", *(line.format(e, -30000.0 if c == "1" else -100.0, c, s) for e, s, c in (r.split(",") for r in rows)))
    rc, _, err = cli("plot", "--compete", str(bad), "--out", str(tmp_path / "pl"))
    assert rc == 2 and says in err, err
