"""Trial 50, side B (Python API): an FGHH sigma too small to change any parameter (T50-B02), evaluate_jobs' record given
as one bool for every job (T50-B05), a flight-data file whose metadata (or format) member is bytes or a 1-element array
(T50-B06), and an OMP_NUM_THREADS libgomp cannot read (trial 50's extra: refused by name at import)."""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

import numpy as np
import pytest

import neurohover as nh
from neurohover.errors import NeurohoverError, brief
from neurohover.experiments.config import shipped_configs

MIN_SIGMA = 2.0**-52  # float64's epsilon, the smallest sigma but 0
SMALL = r"FGHH sigma={} is out of range, too small to change the dynamics \(a parameter's std below 2\*\*-52 of it\): allowed 0 "


@pytest.mark.parametrize("sigma", [5e-324, 1e-300, 1e-17, 2e-16, np.float32(1e-20)])
def test_an_fghh_sigma_that_changes_no_parameter_is_refused(sigma) -> None:
    """T50-B02: 1e-300 was taken, every draw the zero setting, labelled and recorded as its own sigma."""
    with pytest.raises(NeurohoverError, match="^" + SMALL.format(re.escape(brief(sigma))) + r".* 2\.220446049250313e-16\.\.1 "):
        nh.get_task_family("fghh", sigma=sigma)


def _sigmas(value) -> list[float]:
    """Every value of a key named sigma in the parsed TOML ``value``."""
    if isinstance(value, dict):
        return [v for k, x in value.items() for v in ([x] if k == "sigma" and not isinstance(x, (dict, list)) else _sigmas(x))]
    return [v for x in value for v in _sigmas(x)] if isinstance(value, list) else []


def test_sigma_zero_the_smallest_and_every_shipped_sigma_stay_allowed() -> None:
    """T50-B02: 0 (every draw the zero setting) stays allowed, the bound itself changes parameters, and the shipped
    configs' sigmas (0.2, 0.3) pass."""
    shipped = {s for path in shipped_configs().values() for s in _sigmas(tomllib.loads(Path(path).read_text()))}
    assert shipped >= {0.2, 0.3}
    for sigma in [0, 0.0, MIN_SIGMA, 1, *sorted(shipped)]:
        assert nh.get_task_family("fghh", sigma=sigma).sigma == sigma
    fam = nh.get_task_family("fghh", sigma=MIN_SIGMA)
    assert fam.sample(np.random.default_rng(0)).params != fam.zero().params


def test_the_command_line_refuses_a_too_small_sigma_alike(cli) -> None:
    """T50-B02: --sigma goes through the same check: exit 2, the same one-line message."""
    rc, _, err = cli("fly", "--task", "fghh", "--sigma", "1e-17", "--mdp", "seeded-train:0", "--episodes", "1")
    assert rc == 2 and re.search(SMALL.format("1e-17"), err) and len(err.strip().splitlines()) == 1, err


@pytest.mark.parametrize("flag", [True, np.True_, np.array(True), False, np.False_])
def test_evaluate_jobs_takes_one_bool_for_every_job(flag) -> None:
    """T50-B05: record=True was "record must have one flag per job (2), got 1", while evaluate takes a bool."""
    mdps = nh.get_task_family("ghh08").training_mdps()
    args = ([nh.baseline_policy()], mdps, [0, 0], [0, 1], [0, 1])
    one = nh.evaluate_jobs(*args, seed=0, n_steps=5, record=flag)
    each = nh.evaluate_jobs(*args, seed=0, n_steps=5, record=[bool(flag)] * 2)
    assert np.array_equal(one.returns, each.returns)
    assert (one.flight_data is None) == (each.flight_data is None) == (not flag)
    if flag:
        assert one.flight_data == each.flight_data


@pytest.mark.parametrize("flag", [1, "yes", np.array([1, 0]), [True]])
def test_evaluate_jobs_still_refuses_what_is_no_bool_per_job(flag) -> None:
    """T50-B05: what is no bool, or a list of another length, is refused as before; None stays the default (none)."""
    args = ([nh.baseline_policy()], nh.get_task_family("ghh08").training_mdps(), [0, 0], [0, 1], [0, 1])
    with pytest.raises(NeurohoverError, match=r"record.* (give one True/False flag per job \(2\), or one for every job|one flag per job \(2\), got 1)"):
        nh.evaluate_jobs(*args, seed=0, n_steps=5, record=flag)
    assert nh.evaluate_jobs(*args, seed=0, n_steps=5, record=None).flight_data is None


@pytest.fixture(scope="module")
def saved_flight(tmp_path_factory) -> tuple[Path, dict]:
    """Flight data as FlightData.save writes them, and its arrays."""
    path = tmp_path_factory.mktemp("t50") / "f.npz"
    nh.evaluate(nh.baseline_policy(), nh.get_task_family("ghh08").zero(), episodes=2, n_steps=30, seed=2, record=True).flight_data.save(path)
    with np.load(path) as z:
        return path, {k: z[k] for k in z.files}


@pytest.mark.parametrize(
    ("member", "edit", "holds"),
    [
        ("metadata", lambda text: np.array(text.encode()), r"a \|S\d+ array of shape \(\)"),
        ("metadata", lambda text: np.array([text]), r"a <U\d+ array of shape \(1,\)"),
        ("metadata", lambda text: np.array(3.0), r"a float64 array of shape \(\)"),
        ("format", lambda text: np.array(text.encode()), r"a \|S\d+ array of shape \(\)"),
    ],
)
def test_a_text_member_of_another_kind_is_named_with_what_is_allowed(saved_flight, tmp_path: Path, member, edit, holds) -> None:
    """T50-B06: metadata re-saved as bytes was "(JSONError: Expecting value: line 1 column 1 (char 0))", the member unnamed."""
    path, arrays = saved_flight
    np.savez(tmp_path / "m.npz", **{**arrays, member: edit(str(arrays[member]))})
    said = rf"is not a readable flight-data file: its member {member}\.npy holds {holds}: allowed a 0-d text array \(NumPy dtype 'U'"
    with pytest.raises(NeurohoverError, match=said):
        nh.FlightData.load(tmp_path / "m.npz")
    assert nh.FlightData.load(path).metadata == nh.FlightData.load(path).metadata  # as saved, it loads


def test_metadata_that_is_no_json_names_its_member(saved_flight, tmp_path: Path) -> None:
    """T50-B06: text that is no JSON names the metadata member and what it holds (a JSON object)."""
    _, arrays = saved_flight
    np.savez(tmp_path / "m.npz", **{**arrays, "metadata": np.array("{x")})
    with pytest.raises(NeurohoverError, match=r"\(JSONError: .*\) in its member metadata\.npy: allowed a JSON object, as save writes it$"):
        nh.FlightData.load(tmp_path / "m.npz")


@pytest.mark.parametrize(
    ("value", "allowed"),
    [
        ("1.0", False),
        ("", False),
        ("0", False),
        ("2,0", False),
        ("0x2", False),
        ("2 1", False),
        ("\u0663", False),
        ("1", True),
        (" 4 ", True),
        ("4,2", True),
        ("2, 1", True),
        ("+2", True),
    ],
)
def test_omp_num_threads_is_refused_by_name_where_libgomp_cannot_read_it(monkeypatch, value: str, allowed: bool) -> None:
    """Trial 50's extra: OMP_NUM_THREADS=1.0 was libgomp's "Invalid value" line at the first flight, then its default."""
    monkeypatch.setenv("OMP_NUM_THREADS", value)
    if allowed:
        nh._check_numba_variables()
        return
    with pytest.raises(NeurohoverError, match=rf"^environment variable OMP_NUM_THREADS={re.escape(repr(value))} is not allowed: give a whole number > 0"):
        nh._check_numba_variables()
