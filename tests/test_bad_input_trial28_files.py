"""Trial 28 (bad input of the Python API and of hand-edited files): T28-B07 (the API's writers replaced neurohover files
of another kind), T28-B08 (a KeyboardInterrupt from evolve's last progress call lost the finished run), T28-B13
(read_history_csv took rows write_history_csv never writes; a NaN record was written), T28-B12 (episodes.csv numbers
read with int()/float()), T28-B16 (safeguard_limits without fallback_index ignored), T28-B10 and T28-B11
(gym.make's max_episode_steps of True, a NumPy integer, 5.5), T28-B04 (a refused first reset under Gymnasium's
passive checker: documented)."""

from __future__ import annotations

import json
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

import neurohover  # noqa: F401  (registers the environments)
from neurohover import DangerousState, NeurohoverError, Policy, baseline_policy, evaluate_jobs, get_task_family, save_policy
from neurohover.compete_files import read_compete_dir
from neurohover.envs.hover import HoverEnv
from neurohover.evolution import EvolutionInterrupted, evolve
from neurohover.evolution.evolve import read_history_csv, write_history_csv
from neurohover.evolution.records import HISTORY_COLUMNS, HistoryRecord
from neurohover.filekinds import held_kind
from neurohover.flightdata import FlightData
from neurohover.models import learn_lr

ZERO = get_task_family("ghh08").zero()
RUN = dict(budget=10, n_steps=5, seed=1)


@pytest.fixture(scope="module")
def kinds(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """A file of each kind the API writes: a policy, a model, a checkpoint (with its history) and flight data."""
    folder = tmp_path_factory.mktemp("kinds")
    ev = evaluate_jobs([baseline_policy()], ZERO, [0, 0], [0, 0], [0, 1], n_steps=30, record=[True, True])
    flight = ev.flight_data
    assert isinstance(flight, FlightData)
    files = {
        "policy": save_policy(baseline_policy(), folder / "pol.json"),
        "model": learn_lr(flight).save(folder / "mod.json"),
        "flight": flight.save(folder / "f.npz"),
        "checkpoint": folder / "ck.json",
    }
    result = evolve(ZERO, checkpoint=files["checkpoint"], **RUN)
    files["history"] = write_history_csv(result.history, folder / "h.history.csv")
    return files


def _unchanged(path: Path, write) -> str:
    before = path.read_bytes()
    with pytest.raises(NeurohoverError) as err:
        write()
    assert path.read_bytes() == before
    return str(err.value)


def test_the_api_writers_refuse_a_file_of_another_kind(kinds: dict[str, Path]) -> None:
    """T28-B07: LearnedModel.save, save_policy, evolve(checkpoint=) and write_history_csv replaced a policy, a model,
    a model and a policy file without a word, as the CLI does not."""
    from neurohover.models import LearnedModel

    model = LearnedModel.load(kinds["model"])
    message = _unchanged(kinds["policy"], lambda: model.save(kinds["policy"]))
    assert "is a policy file: give another path (writing a model file there would destroy it)" in message
    message = _unchanged(kinds["model"], lambda: save_policy(baseline_policy(), kinds["model"]))
    assert "is a model file: give another path (writing a policy file there" in message
    message = _unchanged(kinds["model"], lambda: evolve(ZERO, checkpoint=kinds["model"], **RUN))
    assert "checkpoint" in message and "is a model file" in message
    message = _unchanged(kinds["policy"], lambda: write_history_csv([], kinds["policy"]))
    assert "history file" in message and "a history is CSV" in message
    message = _unchanged(kinds["flight"], lambda: write_history_csv([], kinds["flight"]))
    assert "a history is CSV" in message
    csv_policy = kinds["policy"].with_name("pol.csv")
    csv_policy.write_bytes(kinds["policy"].read_bytes())  # a policy under a .csv name: told by its content
    assert "is a policy file" in _unchanged(csv_policy, lambda: write_history_csv([], csv_policy))
    assert held_kind(kinds["history"]) == "an evolution history (.history.csv)"
    other = kinds["history"].with_name("other.history.csv")
    other.write_bytes(kinds["history"].read_bytes())
    write_history_csv([], other)  # its own kind is replaced
    assert read_history_csv(other) == []


def test_a_checkpoint_is_json_by_name(tmp_path: Path) -> None:
    """T28-B07: evolve(checkpoint='ck.npz') wrote JSON under a flight-data name."""
    with pytest.raises(NeurohoverError, match=r"^checkpoint .*ck\.npz' \(\d+ characters\) is not allowed: a checkpoint is JSON; give a path ending \.json"):
        evolve(ZERO, checkpoint=tmp_path / "ck.npz", **RUN)
    assert not (tmp_path / "ck.npz").exists()


def test_an_interrupt_from_the_last_progress_call_keeps_the_result(tmp_path: Path) -> None:
    """T28-B08: a KeyboardInterrupt from progress(done=True) escaped as itself, and the finished run's result was lost."""

    def stop(info) -> None:
        if info.done:
            raise KeyboardInterrupt

    stopped: BaseException | None = None
    try:
        evolve(ZERO, progress=stop, checkpoint=tmp_path / "k.json", **RUN)
    except KeyboardInterrupt as err:  # caught here: a bare one (T28-B08) would stop pytest itself
        stopped = err
    assert isinstance(stopped, EvolutionInterrupted), repr(stopped)
    assert stopped.checkpoint == tmp_path / "k.json" and stopped.result is not None
    assert stopped.result.episodes == stopped.episodes and (tmp_path / "k.json").is_file()
    assert stopped.result.champion == evolve(ZERO, **RUN).champion


def _history(tmp_path: Path, *rows: str) -> Path:
    path = tmp_path / "h.history.csv"
    path.write_text("\n".join([",".join(HISTORY_COLUMNS), *rows]) + "\n")
    return path


GOOD = ["1,1,1,1,-5.0,0.1000", "2,3,4,3,-4.0,0.2000"]


@pytest.mark.parametrize(
    ("row", "message"),
    [
        ("3,5,6,2,nan,0.3000", "row 4: champion_return 'nan' is not allowed"),
        ("3,5,6,2,inf,0.3000", "row 4: champion_return 'inf' is not allowed"),
        ("3,5,6,2,-nan,0.3000", "row 4: champion_return '-nan' is not allowed: allowed a number"),
        ("3,5,6,2,-3.0,-1.0000", "row 4: wall_seconds '-1.0000' is not allowed"),
        ("3,5,6,2,-3.0,0.0500", "row 4: wall_seconds '0.0500' is not allowed (below row 3's 0.2"),
        ("-3,5,6,2,-3.0,0.3000", "row 4: generation '-3' is not allowed"),
        ("3,5,1_0,2,-3.0,0.3000", "row 4: episodes '1_0' is not allowed: allowed a whole number"),
        ("3,5,\u0661\u0660,2,-3.0,0.3000", "row 4: episodes '\u0661\u0660' is not allowed"),
        ("3,5,6.0,2,-3.0,0.3000", "row 4: episodes '6.0' is not allowed: allowed a whole number"),
        ("3,500,50,2,-3.0,0.3000", "episodes=50 is not allowed (below its 500 evaluations"),
        ("3,5,50,99,-3.0,0.3000", "generation_episodes=99 is not allowed (more than its 50 episodes)"),
        ("3,5,2,2,-3.0,0.3000", "episodes=2 is not allowed (below row 1's 4)"),
        ("3,5,6,2,-3.0", "row 4: '3,5,6,2,-3.0' is not a history record"),
    ],
)
def test_read_history_csv_takes_only_what_write_history_csv_writes(tmp_path: Path, row: str, message: str) -> None:
    """T28-B13: plain int()/float() took NaN and positive returns, negative counts and seconds, '1_0' and other scripts'
    digits, and counts that fall or exceed each other. (A positive champion_return is a family run's 1/ln(error) fitness.)"""
    assert [h.generation for h in read_history_csv(_history(tmp_path, *GOOD, "3,5,6,2,-3.0,0.3000"))] == [1, 2, 3]
    with pytest.raises(NeurohoverError) as err:
        read_history_csv(_history(tmp_path, *GOOD, row))
    assert message in str(err.value)


def test_write_history_csv_refuses_a_record_a_run_never_keeps(tmp_path: Path) -> None:
    """T28-B13: a NaN record was written without a word."""
    with pytest.raises(NeurohoverError, match=r"history record 1 \(from 0\): champion_return=nan is not allowed .*nothing is written"):
        write_history_csv([HistoryRecord(1, 1, 1, 1, -5.0, 0.1), HistoryRecord(2, 2, 2, 1, float("nan"), 0.2)], tmp_path / "h.history.csv")
    assert not (tmp_path / "h.history.csv").exists()


ROW = "run,mdp,episode,return,crashed,steps,policy,safeguard_fired\n{}\n"


@pytest.mark.parametrize(
    ("row", "message"),
    [
        ("0_0,ghh08/test:0,0,-13.0,0,20,p,0", "line 2: run '0_0' is not allowed: allowed a whole number"),
        ("\u0660,ghh08/test:0,0,-13.0,0,20,p,0", "line 2: run '\u0660' is not allowed"),
        ("0,ghh08/test:0,\u0661,-13.0,0,20,p,0", "line 2: episode '\u0661' is not allowed"),
        ("0,ghh08/test:0,0,-13.0,0,\uff12\uff10,p,0", "line 2: steps '\uff12\uff10' is not allowed"),
        ("0,ghh08/test:0,0,-7_387,0,20,p,0", "line 2: return '-7_387' is not allowed: allowed a number"),
        ("0,ghh08/test:0,0,-\u0663,0,20,p,0", "line 2: return '-\u0663' is not allowed"),
        ("0,ghh08/test:0,0,-13.0,0,20.0,p,0", "line 2: steps '20.0' is not allowed: allowed a whole number"),
        ("0,ghh08/test:0,0,-13.0,+0,20,p,0", "line 2: crashed '+0' is not allowed: allowed a whole number"),
    ],
)
def test_episodes_csv_numbers_are_read_as_compete_writes_them(tmp_path: Path, row: str, message: str) -> None:
    """T28-B12: int()/float() took '0_0', Arabic-Indic and full-width digits; steps '20.0' was "must be numbers"."""
    (tmp_path / "episodes.csv").write_text(ROW.format("0,ghh08/test:0,0,-13.004158354747982,0,20,p,0"), encoding="utf-8")
    assert read_compete_dir(tmp_path).returns.shape == (1, 1)
    (tmp_path / "episodes.csv").write_text(ROW.format(row), encoding="utf-8")
    with pytest.raises(NeurohoverError) as err:
        read_compete_dir(tmp_path)
    assert message in str(err.value)


def test_safeguard_limits_without_fallback_index_are_refused() -> None:
    """T28-B16: the limits were ignored without a word where no job had a fallback."""
    zero, lim = Policy("slp", np.zeros(40)), DangerousState(rule="paper", box=1e-6).limits()
    with pytest.raises(NeurohoverError, match=r"safeguard_limits needs fallback_index= .*give both, or neither"):
        evaluate_jobs([zero, baseline_policy()], ZERO, [0], [0], [0], n_steps=20, safeguard_limits=lim)
    ev = evaluate_jobs([zero, baseline_policy()], ZERO, [0], [0], [0], n_steps=20, fallback_index=[1], safeguard_limits=lim)
    assert ev.safeguard_step[0] >= 0


@pytest.mark.parametrize("limit", [True, np.int64(5), 5.5, "5"])
def test_a_time_limit_gymnasium_would_misread_is_refused_by_name(limit: object) -> None:
    """T28-B10: max_episode_steps=True truncated at one step without a word; T28-B11: np.int64(5), 5.5 and '5' were
    Gymnasium's TypeError (make() hands TimeLimit the argument itself, so it cannot be converted)."""
    with pytest.raises(NeurohoverError, match=r"max_episode_steps=.* is not allowed: gymnasium\.make's TimeLimit takes a Python int"):
        gym.make("neurohover/GHH08-v0", episode_steps=20, max_episode_steps=limit)
    with pytest.raises(NeurohoverError, match="max_episode_steps"):
        gym.make_vec("neurohover/GHH08-v0", num_envs=1, vectorization_mode="sync", episode_steps=20, max_episode_steps=limit)
    env = gym.make("neurohover/GHH08-v0", episode_steps=20, max_episode_steps=20, mdp="zero")
    env.reset(seed=0)
    assert not env.step(np.array([0, 0, 0, 0.23]))[3]


def test_a_refused_first_reset_under_the_passive_checker_is_documented() -> None:
    """T28-B04 (not fixable here): Gymnasium 1.4's passive checker marks its reset check done before it calls reset, so
    after a refused first reset its next step is its own TypeError whatever the env checks first; documented, and a
    newly made environment flies."""
    doc = " ".join((HoverEnv.__doc__ or "").split())
    assert "disable_env_checker=False)`` a refused *first* reset" in doc and "make the environment again after one (T28-B04)" in doc
    env = gym.make("neurohover/GHH08-v0", episode_steps=20, disable_env_checker=False)
    with pytest.raises(NeurohoverError, match="seed=-1"):
        env.reset(seed=-1)
    env = gym.make("neurohover/GHH08-v0", episode_steps=20, disable_env_checker=False)
    env.reset(seed=0)
    assert env.step(np.zeros(4))[0].shape == (12,)


def test_what_neurohover_writes_reads_back(kinds: dict[str, Path]) -> None:
    """The strict readers take every file the writers write (T28-B12, T28-B13)."""
    records = read_history_csv(kinds["history"])
    assert records and all(isinstance(h, HistoryRecord) for h in records)
    assert json.loads(kinds["checkpoint"].read_text())["format"].startswith("neurohover-evolution-checkpoint/")
