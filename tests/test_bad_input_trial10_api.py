"""Issue 38, the tenth fresh trial, the Python API's side: ``==`` on an Evaluation or FlightData compares values (it was
NumPy's "truth value of an array is ambiguous") and hash() says they are unhashable; SB3VecEnv's get_attr names an
unknown attribute (still an AttributeError, which SB3 catches), get_images says how to render, and ``indices`` outside
0..num_envs-1 or of no ints are refused by name; get_attr gives each helicopter its own entry."""

from __future__ import annotations

import pickle

import numpy as np
import pytest

from neurohover.errors import NeurohoverError
from neurohover.evaluate import Evaluation, evaluate
from neurohover.flightdata import FlightData
from neurohover.policies import baseline_policy
from neurohover.tasks import get_task_family


def _flight(metadata: dict | None = None, dtype=np.float64) -> FlightData:
    obs = np.arange(36, dtype=dtype).reshape(3, 12)
    return FlightData((obs,), (np.zeros((2, 4), dtype=dtype),), {"episode_steps": 2} if metadata is None else metadata)


def _evaluation(returns=(1.0, 2.0), seconds: float = 0.5, flight: FlightData | None = None) -> Evaluation:
    n = len(returns)
    # minus the returns given: every return is <= 0 (T27-B10)
    return Evaluation(-np.array(returns), np.zeros(n, dtype=bool), np.full(n, 20), np.full(n, -1), flight, seconds)


def test_flown_evaluations_compare_by_value() -> None:
    mdps = get_task_family("ghh08").training_mdps()[:2]
    first = evaluate(baseline_policy(), mdps, episodes=2, n_steps=20, record=True)
    again = evaluate(baseline_policy(), mdps, episodes=2, n_steps=20, record=True)
    assert first == again and pickle.loads(pickle.dumps(first)) == first  # was NumPy's ValueError
    assert first.flight_data == again.flight_data
    assert first != evaluate(baseline_policy(), mdps, episodes=2, n_steps=20, record=True, seed=1)


def test_evaluation_equality_leaves_out_seconds_only() -> None:
    assert _evaluation(seconds=0.5) == _evaluation(seconds=9.0)
    assert _evaluation((1.0, float("nan"))) == _evaluation((1.0, float("nan")))  # a NaN return equals itself here
    assert _evaluation((1.0, 2.0)) != _evaluation((1.0, 3.0))
    assert _evaluation((1.0, 2.0)) != _evaluation((1.0, 2.0, 3.0))
    assert _evaluation(flight=_flight()) != _evaluation() and _evaluation(flight=_flight()) == _evaluation(flight=_flight())
    assert _evaluation() != "an evaluation" and _evaluation() != _evaluation().reshape((2, 1))


def test_flight_data_compare_episodes_and_metadata(tmp_path) -> None:
    assert _flight() == _flight() and _flight() == FlightData.load(_flight().save(tmp_path / "fd.npz"))
    assert _flight() != _flight({"episode_steps": 3})
    assert _flight() != _flight(dtype=np.float32)  # the same numbers, another dtype: not the same arrays
    assert _flight({"x": np.ones(3)}) == _flight({"x": np.ones(3)}) and _flight({"x": np.ones(3)}) != _flight({"x": [1.0] * 3})
    assert _flight({"x": np.float64(1.0)}) != _flight({"x": [1.0, 2.0]})  # elementwise, not an error
    assert _flight() + _flight() != _flight() and _flight() != None  # noqa: E711


@pytest.mark.parametrize("value", [_evaluation(), _flight()], ids=["Evaluation", "FlightData"])
def test_evaluation_and_flight_data_are_unhashable_as_documented(value) -> None:
    with pytest.raises(TypeError, match="unhashable type"):
        hash(value)
    assert "unhashable" in type(value).__doc__ and "``==``" in type(value).__doc__


@pytest.fixture(scope="module")
def venv():
    pytest.importorskip("stable_baselines3", reason="stable-baselines3 is not installed (pip install 'neurohover[examples]')")
    from neurohover.integrations.sb3 import SB3VecEnv

    mdps = get_task_family("ghh08").training_mdps()[:2]
    v = SB3VecEnv("neurohover/GHH08-Short-v0", 2, mdp=mdps)
    v.reset()
    yield v
    v.close()


def test_get_attr_of_an_unknown_name_is_named_and_still_an_attribute_error(venv) -> None:
    from neurohover.integrations.sb3 import UnknownAttributeError

    with pytest.raises(UnknownAttributeError, match=r"get_attr\('mdp'\).*no such attribute.*per helicopter: mdps") as err:
        venv.get_attr("mdp")
    assert isinstance(err.value, AttributeError) and isinstance(err.value, NeurohoverError)
    assert venv.has_attr("family") and not venv.has_attr("nonexist")  # SB3's has_attr catches AttributeError


def test_get_images_says_how_to_render(venv) -> None:
    with pytest.raises(NotImplementedError, match=r"draws no images.*render_mode='rgb_array'"):
        venv.get_images()


def test_get_attr_gives_each_helicopter_its_own(venv) -> None:
    mdps = venv.native.mdps
    assert mdps[0] != mdps[1] and venv.get_attr("mdps") == mdps and venv.get_attr("mdps", 1) == [mdps[1]]
    assert venv.get_attr("mdp_specs", [1, 0]) == [venv.native.mdp_specs[1], venv.native.mdp_specs[0]]
    assert venv.get_attr("observation_space", np.array([0])) == [venv.native.single_observation_space]
    assert venv.get_attr("num_envs", range(2)) == [2, 2] and venv.get_attr("num_envs", []) == []
    assert venv.env_is_wrapped(object, indices=1) == [False]


@pytest.mark.parametrize("indices", [[5], 2, -1, "abc", 1.0, True, [0, True], [0, 1.5], {0: 1}, np.array(1)])
@pytest.mark.parametrize("call", ["get_attr", "env_is_wrapped"])
def test_indices_outside_the_helicopters_are_refused(venv, call, indices) -> None:
    with pytest.raises(NeurohoverError, match=r"indices=.* is not allowed.*iterable of ints in 0\.\.1"):
        if call == "get_attr":
            venv.get_attr("num_envs", indices=indices)
        else:
            venv.env_is_wrapped(object, indices=indices)
