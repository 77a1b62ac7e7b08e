"""Trial 32's bad-input findings on file paths in the Python API: T32-B01 (threads saving into one path left a corrupt
file, and the others failed "No such file or directory"), T32-B06 (a relative path over PATH_MAX once absolute was an
OSError "File name too long"), T32-B07 and T32-B08 (a file path ending '/', '/.' was read as the file, or was a
NotADirectoryError, and 'X/.' written as X), T32-B20 (LearnedModel.save wrote a name without a suffix) and T32-B21
(an authors' .net file named .NET was read as JSON)."""

from __future__ import annotations

import os
import re
import threading
from pathlib import Path

import numpy as np
import pytest

import neurohover as nh
from neurohover import baseline_policy, evaluate, get_task_family
from neurohover.errors import NeurohoverError, brief
from neurohover.evolution.records import read_checkpoint, read_history_csv, write_checkpoint
from neurohover.experiments.store import Store
from neurohover.flightdata import FlightData
from neurohover.models import LearnedModel, learn_lr
from neurohover.netfile import policy_to_net
from neurohover.paths import PATH_MAX


def _raises(fragment: str):
    return pytest.raises(NeurohoverError, match=re.escape(fragment))


@pytest.fixture(scope="module")
def flight() -> FlightData:
    """A baseline episode of 200 steps on GHH-08's zero MDP, recorded."""
    return evaluate(baseline_policy(), get_task_family("ghh08").zero(), record=True, seed=1, n_steps=200).flight_data


def _race(write, n_threads: int, rounds: int, check) -> None:
    """``n_threads`` threads call ``write(i)`` at once, ``rounds`` times; every call succeeds and ``check()`` passes
    after each round."""
    failures: list[str] = []

    def one(i: int, start: threading.Barrier) -> None:
        start.wait()
        try:
            write(i)
        except Exception as err:  # noqa: BLE001 - every failure is the finding
            failures.append(f"{type(err).__name__}: {err}")

    for _ in range(rounds):
        start = threading.Barrier(n_threads)
        threads = [threading.Thread(target=one, args=(i, start)) for i in range(n_threads)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        assert not failures, failures[:3]
        check()


# T32-B01 ------------------------------------------------------------------------------------------------------------


def test_threads_saving_one_policy_path_each_succeed_and_leave_one_whole_policy(tmp_path: Path) -> None:
    """T32-B01: the partial file was named by the process only; threads truncated and moved each other's."""
    pols = [nh.Policy("slp", np.full(40, float(i)), {"note": "x" * (i * 40000 + 10)}) for i in range(5)]
    out = tmp_path / "race.json"

    def check() -> None:
        got = nh.load_policy(out)
        assert got == pols[int(got.genome[0])] and got.metadata == pols[int(got.genome[0])].metadata

    _race(lambda i: nh.save_policy(pols[i], out), 5, 12, check)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["race.json"]  # no partial file left


def test_threads_saving_one_flight_data_path_leave_one_whole_archive(flight: FlightData, tmp_path: Path) -> None:
    """T32-B01: FlightData.save from threads: "No such file or directory", and a .npz of bad CRC."""
    out = tmp_path / "race.npz"
    _race(lambda i: flight.save(out), 4, 6, lambda: FlightData.load(out))
    assert sorted(p.name for p in tmp_path.iterdir()) == ["race.npz"]


def test_flight_data_saved_by_another_thread_while_its_kind_is_read_is_not_called_a_foreign_file(
    flight: FlightData, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """T32-B01 again (CI, 2026-12-07): the path's kind was read while it did not exist yet, its size once another
    thread's save had put flight data there: "a file neurohover did not write". The interleaving, made certain."""
    import neurohover.paths as paths

    out = tmp_path / "race.npz"
    other = flight.save(tmp_path / "other.npz")
    real_held_kind = paths.held_kind

    def held_kind_then_another_save(path):  # the other thread's save lands just after this one read the kind
        held = real_held_kind(path)
        if not out.exists():
            os.replace(other, out)
        return held

    monkeypatch.setattr(paths, "held_kind", held_kind_then_another_save)
    assert flight.save(out) == out
    assert FlightData.load(out).n_transitions == flight.n_transitions


def test_threads_writing_one_checkpoint_path_leave_one_whole_checkpoint(tmp_path: Path) -> None:
    """T32-B01: evolve threads sharing a checkpoint path: "cannot write it (No such file or directory)"."""
    out = tmp_path / "ck.json"
    states = [{"who": i, "pad": "y" * (i * 30000)} for i in range(5)]

    def check() -> None:
        got = read_checkpoint(out)
        assert got == states[got["who"]]

    _race(lambda i: write_checkpoint(out, states[i]), 5, 12, check)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["ck.json"]


def test_the_writers_temporary_files_differ_by_thread(tmp_path: Path) -> None:
    """T32-B01: the one helper naming them gives each thread its own name, cut to fit as before (T29-A01)."""
    from neurohover.filekinds import name_limit
    from neurohover.paths import writer_file

    names: list[Path] = []
    threads = [threading.Thread(target=lambda: names.append(writer_file(tmp_path / "p.json", ".partial", hidden=True))) for _ in range(3)]
    for t in threads:
        t.start()
        t.join()  # one after the other: a native thread id may be reused only by a thread started after one ends
    assert all(n.name.startswith(".p.json.") and n.name.endswith(".partial") for n in names)
    long = writer_file(tmp_path / ("b" * (name_limit(tmp_path) - 4) + ".csv"), ".tmp")
    assert len(os.fsencode(long.name)) <= name_limit(tmp_path) and long.name.endswith(".tmp")


# T32-B06 ------------------------------------------------------------------------------------------------------------


def test_a_relative_path_over_the_limit_once_absolute_is_refused_by_every_writer(flight: FlightData, tmp_path: Path, monkeypatch) -> None:
    """T32-B06: 4,081 characters relative, 4,107 absolute: OSError "File name too long" from pathlib's stat."""
    here = tmp_path / "h"
    here.mkdir()
    monkeypatch.chdir(here)
    model = learn_lr(flight)
    deep = "/".join(["g" * 200] * 19)  # 3,818 characters, not made yet
    room = PATH_MAX - 1 - len(deep) - 1  # the longest name the relative path could take
    for suffix, write in (
        (".json", lambda p: nh.save_policy(baseline_policy(), p)),
        (".npz", flight.save),
        (".json", model.save),
        (".sqlite", Store),
    ):
        given = f"{deep}/{'o' * (room - len(suffix) - 30)}{suffix}"
        absolute = len(os.path.abspath(given))
        assert len(given) < PATH_MAX <= absolute
        with _raises(f"and {PATH_MAX - 1:,} in the whole path (here {len(given):,}, {absolute:,} made absolute)"):
            write(given)
    assert list(here.iterdir()) == []  # refused before any directory was made


# T32-B07, T32-B08 ---------------------------------------------------------------------------------------------------


def test_a_file_path_ending_in_a_slash_or_dot_is_refused_by_readers(flight: FlightData, tmp_path: Path) -> None:
    """T32-B07: read_history_csv('X/') was a NotADirectoryError; T32-B08: load_policy('p.json/'), FlightData.load('f.npz/')
    and LearnedModel.load('m.json/.') read the file X."""
    history = tmp_path / "p.json.history.csv"
    history.write_text("x\n")
    for end in ("/", "/.", "//", "/./", "/.."):
        with _raises(f"history file '{history}{end}' ends in '{end[-1] if end.endswith('/') else end}', which names a directory"):
            read_history_csv(f"{history}{end}")
    policy = nh.save_policy(baseline_policy(), tmp_path / "p.json")
    with _raises(f"policy file '{policy}/' ends in '/', which names a directory: give a policy file"):
        nh.load_policy(f"{policy}/")
    data = flight.save(tmp_path / "f.npz")
    with _raises(f"flight-data file '{data}/.' ends in '/.', which names a directory"):
        FlightData.load(f"{data}/.")
    model = learn_lr(flight).save(tmp_path / "m.json")
    with _raises(f"model file '{model}/.' ends in '/.', which names a directory"):
        LearnedModel.load(f"{model}/.")
    store = tmp_path / "st.sqlite"
    Store(store).close()
    for end in ("/", "/."):
        with _raises(f"results store '{store}{end}' ends in '{end}', which names a directory"):
            Store(f"{store}{end}")
    with _raises(f"policy file '{tmp_path}/' is a directory"):  # a directory is still named as one
        nh.load_policy(f"{tmp_path}/")


def test_a_file_path_ending_in_slash_dot_is_refused_by_writers_as_slash_is(flight: FlightData, tmp_path: Path) -> None:
    """T32-B08: save_policy(b, 'o.json/') was refused, but 'o.json/.' wrote o.json (FlightData.save, LearnedModel.save)."""
    model = learn_lr(flight)
    for name, write in (("o.json", lambda p: nh.save_policy(baseline_policy(), p)), ("o.npz", flight.save), ("m.json", model.save)):
        for end in ("/", "/."):
            with _raises(f"'{tmp_path / name}{end}' ends in '{end}', which names a directory: give a file path"):
                write(f"{tmp_path / name}{end}")
    assert list(tmp_path.iterdir()) == []


# T32-B20 ------------------------------------------------------------------------------------------------------------


def test_a_model_name_without_a_suffix_is_refused_as_a_policys_is(flight: FlightData, tmp_path: Path) -> None:
    """T32-B20: LearnedModel.save('m') was written though 'm.model' was refused; save_policy('p') is refused."""
    model = learn_lr(flight)
    with _raises(
        f"model file {brief(str(tmp_path / 'm'))} is not allowed: a model file is JSON; give a path ending .json (e.g. {brief(str(tmp_path / 'm.json'))})"
    ):
        model.save(tmp_path / "m")
    assert list(tmp_path.iterdir()) == []
    assert LearnedModel.load(model.save(tmp_path / "M.JSON")) == model


# T32-B21 ------------------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("suffix", [".NET", ".Net"])
def test_an_authors_net_file_is_read_as_one_in_any_case_of_its_suffix(tmp_path: Path, suffix: str) -> None:
    """T32-B21: p.NET was read as JSON ("not valid JSON"), though .JSON is taken as .json."""
    policy = baseline_policy()
    (tmp_path / f"p{suffix}").write_text(policy_to_net(policy))
    assert nh.load_policy(tmp_path / f"p{suffix}") == nh.load_policy(tmp_path / f"p{suffix}")
    assert nh.load_policy(tmp_path / f"p{suffix}").genome.tolist() == pytest.approx(policy.genome.tolist())
    with _raises("a policy is written as JSON, which load_policy would misread under the .net suffix"):
        nh.save_policy(policy, tmp_path / f"q{suffix}")


def test_a_file_another_threads_check_made_and_removed_between_two_opens_is_checked_again(tmp_path: Path, monkeypatch) -> None:
    """T32-B01 again (seen under load): one thread's check found the file another thread's check had just made
    (O_EXCL failed), which removed it before the first opened it to append: "cannot write this file (No such file or
    directory)". The interleaving, forced: the check tries again, and the save succeeds."""
    import neurohover.paths as paths

    real_open, calls = os.open, []

    def interleaved(path, flags, *args):
        calls.append(flags)
        if len(calls) == 1 and flags & os.O_EXCL:
            raise FileExistsError(17, "made by another thread's check", str(path))
        if len(calls) == 2 and flags & os.O_APPEND:
            raise FileNotFoundError(2, "removed by that check", str(path))
        return real_open(path, flags, *args)

    monkeypatch.setattr(paths.os, "open", interleaved)
    out = paths.output_file(tmp_path / "p.json", "policy file")
    assert out == tmp_path / "p.json" and len(calls) >= 3 and not out.exists()  # probed, and the probe's file removed
