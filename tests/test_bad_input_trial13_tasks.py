"""The thirteenth fresh trial's findings in drift, sensor, .net files, worker pools, bench and settingsdoc: each bad
value gives one NeurohoverError naming it and what is allowed, and in-range NumPy scalars and Fractions are taken."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest

from neurohover.errors import NeurohoverError
from neurohover.tasks.drift import Drift, DriftRun
from neurohover.tasks.sensor import Sensor


@pytest.mark.parametrize("factor", [np.float32(0.8), np.int64(2), Fraction(4, 5)])
def test_drift_takes_in_range_factors_of_any_real_type(factor) -> None:
    """F8: Drift(change={'D_w': np.float32(0.8)}) was refused as 'out of range' (0.8 is in 0.01..100); np.int64, Fraction too."""
    expected = 0.8 if isinstance(factor, np.float32) else float(factor)  # a float32 as the decimal it prints as (T56-B03)
    assert Drift(change={"D_w": factor}).change == (("D_w", expected),)


def test_sensor_takes_in_range_levels_and_delays_of_any_real_type() -> None:
    """F8: Sensor.at_level(np.float32(0.5)) and Sensor.of(...) were 'out of range: allowed 0..1000'; Sensor.of(0.5, np.int64(2))
    refused the delay that Sensor(delay=np.int64(2)) takes."""
    assert Sensor.at_level(np.float32(0.5)) == Sensor.at_level(Fraction(1, 2)) == Sensor.at_level(0.5) == Sensor.of(np.float32(0.5))
    assert Sensor.at_level(np.int64(1)) == Sensor.at_level(1)
    assert Sensor.of(0.5, np.int64(2)).delay == 2
    with pytest.raises(NeurohoverError, match=r"obs_delay=1.5 is not allowed: give a whole number of control steps in 0..10"):
        Sensor.of(0.5, 1.5)


_DRIFT = Drift(walk=0.01, change={"D_w": 0.8}, change_at=(1, 2))


def _row() -> np.ndarray:
    from neurohover.tasks import get_task_family

    return get_task_family("fghh").zero().row()


@pytest.mark.parametrize("episodes", ["a", None, 0, -5, 2.5])
def test_drift_check_run_names_a_bad_episode_count(episodes) -> None:
    """F9: check_run('a') was a TypeError; check_run(0) suggested the impossible window 0..-1."""
    with pytest.raises(NeurohoverError, match=rf"episodes={episodes!r} is not allowed: give a whole number of episodes >= 1"):
        _DRIFT.check_run(episodes)


@pytest.mark.parametrize("seed", [-1, 1.5, "x", None, 2**63])
def test_drift_change_episode_names_a_bad_seed(seed) -> None:
    """F9: change_episode(-1) was NumPy's 'expected non-negative integer', 1.5 silently seed 1."""
    with pytest.raises(NeurohoverError, match=rf"seed={seed!r} is not allowed: give a whole number in 0..{2**63 - 1}"):
        _DRIFT.change_episode(seed)


def test_drift_rows_names_bad_counts_seeds_and_rows() -> None:
    """F9: rows(row, 0, 0) was an IndexError, (row, -1, 0) / (row, 3, -1) ValueErrors, a 3-number row a broadcast error."""
    row = _row()
    for episodes in (0, -1, 2.5):
        with pytest.raises(NeurohoverError, match=rf"episodes={episodes!r} is not allowed: give a whole number of episodes >= 1"):
            _DRIFT.rows(row, episodes, 0)
    with pytest.raises(NeurohoverError, match=r"seed=-1 is not allowed"):
        _DRIFT.rows(row, 3, -1)
    for bad in ([1.0, 2.0, 3.0], None):
        with pytest.raises(NeurohoverError, match=r"is not allowed: give an MDP's row of 36 finite numbers"):
            _DRIFT.rows(bad, 3, 0)
    assert _DRIFT.rows(row, np.int64(3), np.uint64(4)).shape == (3, 36)


def test_drift_run_names_bad_seeds_episodes_and_drifts() -> None:
    """F9: DriftRun(d, row, -1).row(0) was a ValueError, .row(-1) the last row computed or an IndexError, .row(1.5) an
    IndexError, DriftRun('x', ...) an AttributeError."""
    row = _row()
    with pytest.raises(NeurohoverError, match=r"seed=-1 is not allowed"):
        DriftRun(_DRIFT, row, -1)
    run = DriftRun(_DRIFT, row, 0)
    for episode in (-1, 1.5):
        with pytest.raises(NeurohoverError, match=rf"episode={episode!r} is not allowed: give an episode number, a whole number >= 0"):
            run.row(episode)
    with pytest.raises(NeurohoverError, match=r"drift='x' is not allowed: give a Drift"):
        DriftRun("x", row, 0)  # type: ignore[arg-type]
    assert np.array_equal(run.row(np.int64(2)), _DRIFT.rows(row, 3, 0)[2])


@pytest.mark.parametrize("values", [[0] * 3, None, ["a"] * 7, [0.1] * 4 + [0, 0, 0, 9, 9]])
def test_sensor_from_row_values_refuses_what_is_not_seven_numbers(values) -> None:
    """F10: 3 values were an IndexError, None a TypeError, 'a' a ValueError, and 9 values a sensor of the first seven."""
    with pytest.raises(NeurohoverError, match=r"sensor row values .* are not allowed: give the 7 numbers of an MDP row's sensor slots"):
        Sensor.from_row_values(values)
    assert Sensor.from_row_values(Sensor.at_level(1, delay=2).row_values()) == Sensor.at_level(1, delay=2)


@pytest.mark.parametrize(("old", "new"), [("s 12 16 +0", "s 12 16 ٣"), ("n 1 0 0", "n ١ 0 0")])
def test_net_files_take_ascii_digits_only(old: str, new: str) -> None:
    """F2: a .net file's Arabic-Indic digits were read as numbers: weight '٣' as 3, node id '١' as node 1."""
    from neurohover.netfile import policy_from_net, policy_to_net
    from neurohover.policies import baseline_policy

    text = policy_to_net(baseline_policy())
    assert old in text
    with pytest.raises(NeurohoverError, match=r"network file, line \d+: characters other than ASCII are not allowed: give numbers in ASCII digits"):
        policy_from_net(text.replace(old, new, 1))


@pytest.mark.parametrize("jobs", [0, -1, "2", 1.5, None, True])
def test_worker_pool_names_a_bad_worker_count(jobs) -> None:
    """F16: worker_pool(0) / (-1) was concurrent.futures' 'max_workers must be greater than 0', '2' and 1.5 TypeErrors."""
    from neurohover import procs

    with pytest.raises(NeurohoverError, match=rf"jobs={jobs!r} is not allowed: give a whole number of worker processes >= 1"):
        procs.worker_pool(jobs)


def test_stop_pool_names_what_is_not_a_pool() -> None:
    """F16: stop_pool(None) was an AttributeError; a pool of np.int64(1) workers is made and stopped."""
    from neurohover import procs

    with pytest.raises(NeurohoverError, match=r"pool=None is not allowed: give the ProcessPoolExecutor that worker_pool made"):
        procs.stop_pool(None)  # type: ignore[arg-type]
    procs.stop_pool(procs.worker_pool(np.int64(1)))


def test_bench_functions_refuse_sizes_below_one() -> None:
    """F3, F4: steps=0 was a ZeroDivisionError, repeats=0 an UnboundLocalError, episodes=-2 NumPy's error, 1.5 a TypeError,
    and episodes=0 / n_steps=0 / repeats=0 rates of 0.0."""
    from neurohover import bench

    cases = [
        (lambda: bench.vector_env_steps_per_second(2, 0), "steps=0", "control steps"),
        (lambda: bench.benchmark_evolution(quick=True, repeats=0), "repeats=0", "repeats"),
        (lambda: bench.benchmark_evolution(quick=True, repeats=1.5), "repeats=1.5", "repeats"),
        (lambda: bench.kernel_episodes_per_second(-2, 1, 1), "episodes=-2", "episodes"),
        (lambda: bench.kernel_episodes_per_second(0, 1, 1), "episodes=0", "episodes"),
        (lambda: bench.kernel_episodes_per_second(1, 1, 0), "repeats=0", "repeats"),
        (lambda: bench.reference_episodes_per_second(1.5, 20), "episodes=1.5", "episodes"),
        (lambda: bench.reference_episodes_per_second(-1, 20), "episodes=-1", "episodes"),
        (lambda: bench.reference_episodes_per_second(1, 0), "n_steps=0", "control steps"),
    ]
    for call, named, what in cases:
        with pytest.raises(NeurohoverError, match=rf"^{named} is not allowed: give a whole number of {what} >= 1$"):
            call()


@pytest.mark.parametrize("report", [{}, None, {"machine": 5, "workload": "w", "reference_episodes_per_second": 1.0}])
def test_bench_format_report_names_what_is_not_a_report(report) -> None:
    """F3: format_report({}) was a KeyError 'machine', format_report(None) a TypeError."""
    from neurohover.bench import format_report

    with pytest.raises(NeurohoverError, match=r"is not allowed: give the table that run_benchmarks returns"):
        format_report(report)
