"""Bad-input trial 42, side B (the Python API and hand-edited files): evaluate_callable and compare_agent given a 0-d array
as mdps raised "iteration over a 0-d array", and took a 1-D object array of MDPs that evaluate refuses (T42-B02);
evaluate(record=True, safeguard=...) recorded episodes whose later steps the fallback flew without a word in their
metadata, and EC-MER learnt them as one policy's closed loop (T42-B03: the metadata safeguard_step, refused by EC-MER);
a policy file's sigma beside a GHH target loaded where the file had no task (T42-B06); after importlib.reload of
neurohover.tasks.sensor, tasks.drift, flightdata or tasks.base, their Sensor, Drift, FlightData and MDP were refused
with messages naming no cause, or empty lists (T42-B07..B09: named as another import, as T36-B10 names a Policy's)."""

from __future__ import annotations

import importlib
import json
import re
import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import pytest
from flight_edits import edited_copy

import neurohover as nh
from neurohover.errors import NeurohoverError
from neurohover.flightdata import FlightData
from neurohover.integrations.flying import compare_agent, evaluate_callable
from neurohover.models import learn_ec_mer, learn_lr

GHH08 = nh.get_task_family("ghh08")
MDP = GHH08.training_mdps()[0]


# --------------------------------------------------------------------------- T42-B02: an array as evaluate_callable's mdps


def _zero_d(value: object) -> np.ndarray:
    """A 0-d object array holding ``value`` (np.asarray(mdp, dtype=object) is one)."""
    out = np.empty((), dtype=object)
    out[()] = value
    return out


def _one_d(value: object) -> np.ndarray:
    out = np.empty(1, dtype=object)
    out[0] = value
    return out


_ARRAYS = [np.array(2), np.array(2.5), _zero_d(MDP), _one_d(MDP)]


@pytest.mark.parametrize("mdps", _ARRAYS, ids=["int0d", "float0d", "mdp0d", "mdp1d"])
@pytest.mark.parametrize("fly", ["evaluate_callable", "compare_agent"])
def test_an_array_as_mdps_is_refused_as_evaluate_refuses_it(fly: str, mdps: np.ndarray) -> None:
    """T42-B02: a 0-d array was a TypeError "iteration over a 0-d array"; a 1-D object array of MDPs flew, though
    evaluate refuses it. Both refuse every array now, naming it; a list of the same MDP still flies."""
    with pytest.raises(NeurohoverError, match=r"MDP rows must be a float array"):
        nh.evaluate(nh.baseline_policy(), mdps, n_steps=5)
    call: Callable = (
        (lambda m: evaluate_callable(lambda obs: np.zeros((len(obs), 4)), m, n_steps=5))
        if fly == "evaluate_callable"
        else (lambda m: compare_agent(nh.baseline_policy(), m, n_steps=5))
    )
    with pytest.raises(
        NeurohoverError, match=r"^mdps=array\(.* is not allowed: mdps must be one MDP or a non-empty sequence of MDPs \(a list or tuple, not an array"
    ):
        call(mdps)
    call([MDP])


# --------------------------------------------------------------------------- T42-B03: the safeguard's handover recorded


def _safeguarded(arm_after: int, n_steps: int, box: float = 0.05) -> nh.Evaluation:
    """Two episodes of a policy three times the baseline's gains, its safeguard's fallback the baseline, recorded."""
    b = nh.baseline_policy()
    guard = nh.Safeguard(b, nh.DangerousState(rule="paper", box=box, arm_after=arm_after))
    return nh.evaluate(nh.Policy("slp", b.genome * 3), MDP, episodes=2, seed=0, n_steps=n_steps, record=True, safeguard=guard)


def test_a_safeguarded_recording_records_the_handover_and_ec_mer_refuses_it(tmp_path: Path) -> None:
    """T42-B03: the fallback flew from step 210 on, past the 200 steps the action test reads, and EC-MER learnt the
    episodes as the policy's. The flight data record each episode's handover step, through save and load, and EC-MER
    refuses them by episode and step."""
    ev = _safeguarded(arm_after=210, n_steps=230)
    handed = ev.safeguard_step.ravel().tolist()
    assert handed == [210, 210]
    fd = ev.flight_data
    assert fd.metadata == {"episode_steps": 230, "crashed": [False, False], "safeguard_step": handed, "mdps": [MDP.to_dict()] * 2}  # mdps: T59-B04
    path = fd.save(tmp_path / "sg.npz")
    assert FlightData.load(path) == fd
    bad = nh.Policy("slp", nh.baseline_policy().genome * 3)
    with pytest.raises(
        NeurohoverError,
        match=r"^flight data: episode 0 is not allowed: a safeguard's fallback flew it from step 210 on \(metadata safeguard_step=\[210, 210\]\)",
    ):
        learn_ec_mer(fd, bad, budget=10, seed=0)
    assert learn_lr(fd).method == "lr"  # LR learns the dynamics from any steps, the fallback's too


def test_learn_model_ec_mer_refuses_a_safeguarded_recording(tmp_path: Path, cli) -> None:
    """T42-B03: `learn-model --method ec-mer --policy` took the same file (rc 0, model written)."""
    _safeguarded(arm_after=210, n_steps=230).flight_data.save(tmp_path / "sg.npz")
    nh.save_policy(nh.Policy("slp", nh.baseline_policy().genome * 3), tmp_path / "bad.json")
    out = tmp_path / "m.json"
    for extra in (["--policy", str(tmp_path / "bad.json")], []):
        rc, _, stderr = cli("learn-model", "--flight-data", str(tmp_path / "sg.npz"), "--method", "ec-mer", *extra, "--out", str(out))
        assert rc == 2 and "Traceback" not in stderr and "episode 0 is not allowed: a safeguard's fallback flew it from step 210 on" in stderr, stderr
        assert not out.exists()


def test_a_recording_no_fallback_took_over_is_learnt_and_unflagged_ones_are_unchanged() -> None:
    """T42-B03: a safeguard that never took over records -1 per episode, which EC-MER takes; a recording without a
    safeguard writes no safeguard_step (as fly --record's, which EC-MER takes as before), and joined with a
    safeguarded one its episodes count -1."""
    calm = _safeguarded(arm_after=5, n_steps=20, box=1e6).flight_data
    assert calm.metadata["safeguard_step"] == [-1, -1]
    b = nh.baseline_policy()
    plain = nh.evaluate(b, MDP, episodes=1, n_steps=20, record=True).flight_data
    assert plain.metadata == {"episode_steps": 20, "crashed": [False], "mdps": [MDP.to_dict()]}  # mdps: T59-B04
    bad = nh.Policy("slp", b.genome * 3)
    assert learn_ec_mer(calm, bad, budget=10, seed=0).method == "ec-mer"
    handed = _safeguarded(arm_after=10, n_steps=20).flight_data
    assert (plain + handed).metadata["safeguard_step"] == [-1, *handed.metadata["safeguard_step"]]
    assert (calm + plain).metadata["safeguard_step"] == [-1, -1, -1]
    assert "safeguard_step" not in (plain + plain).metadata


@pytest.mark.parametrize(
    ("steps", "message"),
    [
        (
            [20, -1],
            "its metadata safeguard_step=[20, -1] is not allowed: episode 0 has 20 steps, yet its fallback took over at step 20: allowed -1 (never) or 0..19",
        ),
        (
            [-2, -1],
            "its metadata safeguard_step=[-2, -1] is not allowed: one control step (-1: no fallback flew it; k: one flew from step k on) per episode (2)",
        ),
        ([True, -1], "its metadata safeguard_step=[True, -1] is not allowed: one control step"),
        ([-1], "its metadata safeguard_step=[-1] is not allowed: one control step"),
    ],
)
def test_a_hand_edited_safeguard_step_is_refused(tmp_path: Path, steps: list, message: str) -> None:
    """T42-B03: the new entry is checked as the other per-episode entries are, and against the episodes' lengths."""
    src = _safeguarded(arm_after=5, n_steps=20, box=1e6).flight_data.save(tmp_path / "f.npz")
    path = edited_copy(src, tmp_path / "e.npz", lambda meta: meta.update(safeguard_step=steps))
    with pytest.raises(NeurohoverError) as err:
        FlightData.load(path)
    assert message in str(err.value), str(err.value)


# --------------------------------------------------------------------------- T42-B06: sigma beside a GHH target


def test_a_sigma_beside_a_ghh_target_without_a_task_is_refused(tmp_path: Path) -> None:
    """T42-B06: the API's evolve writes a target and no task; sigma 0.3 beside 'ghh08/train:0' loaded. Refused as beside
    the task 'ghh08'; beside an FGHH target it still loads."""
    b = nh.baseline_policy()
    for target, sigma in (("ghh08/train:0", 0.3), ("ghh09/train:0", 0.1)):
        path = tmp_path / "sig.json"
        path.write_text(json.dumps({"topology": "slp", "genome": b.genome.tolist(), "target": target, "sigma": sigma}))
        family = target.partition("/")[0]
        with pytest.raises(NeurohoverError, match=rf"its sigma {sigma} is not allowed beside its target '{target}': {family}'s MDPs have no breadth"):
            nh.load_policy(path)
    path.write_text(json.dumps({"topology": "slp", "genome": b.genome.tolist(), "target": "fghh/G(sigma=0.3)", "sigma": 0.3}))
    assert nh.load_policy(path).metadata["sigma"] == 0.3


# --------------------------------------------------------------------------- T42-B07..B09: reloaded modules


@contextmanager
def _reloaded(name: str) -> Iterator:
    """``importlib.reload`` of the module ``name``, its first contents put back afterwards (as T36-B10's test does)."""
    module = sys.modules[name]
    saved = dict(module.__dict__)
    try:
        yield importlib.reload(module)
    finally:
        module.__dict__.clear()
        module.__dict__.update(saved)


def _cause(module: str, name: str) -> str:
    article = "an" if name == "MDP" else "a"
    return rf"is not allowed: it is {article} {name} of another import of {re.escape(module)} \(the module was reloaded\?\), .*restart the interpreter"


def test_a_sensor_or_drift_of_a_reloaded_module_is_refused_by_its_cause() -> None:
    """T42-B07: "sensor must be a neurohover Sensor, got Sensor(...)" and "drift must be a neurohover Drift, got Drift(...)"."""
    zero = nh.get_task_family("fghh").zero()
    with _reloaded("neurohover.tasks.sensor") as sensor:
        for call in (lambda: zero.with_sensor(sensor.Sensor(delay=1)), lambda: nh.get_task_family("fghh", sensor=sensor.Sensor(delay=1))):
            with pytest.raises(NeurohoverError, match=r"^sensor Sensor\(.*" + _cause("neurohover.tasks.sensor", "Sensor")):
                call()
    with _reloaded("neurohover.tasks.drift") as drift:
        for call in (lambda: zero.with_drift(drift.Drift(0.01)), lambda: nh.get_task_family("fghh", drift=drift.Drift(0.01))):
            with pytest.raises(NeurohoverError, match=r"^drift Drift\(.*" + _cause("neurohover.tasks.drift", "Drift")):
                call()
    assert zero.with_sensor(nh.Sensor(delay=1)).sensor.delay == 1  # the first import's again


def test_flight_data_of_a_reloaded_module_is_refused_by_its_cause() -> None:
    """T42-B08: "flight data must be a FlightData, got FlightData"."""
    fd = nh.evaluate(nh.baseline_policy(), MDP, n_steps=30, record=True).flight_data
    with _reloaded("neurohover.flightdata") as flightdata:
        other = flightdata.FlightData(fd.observations, fd.actions)
        with pytest.raises(NeurohoverError, match=r"^flight data FlightData\(.*" + _cause("neurohover.flightdata", "FlightData")):
            learn_lr(other)
    assert learn_lr(FlightData(fd.observations * 1, fd.actions)).method == "lr"


def test_an_mdp_of_a_reloaded_base_module_is_refused_by_its_cause() -> None:
    """T42-B09: "its  differ from every fghh MDP's ()", the lists empty; an MDP made before the reload was refused as "a
    subclass of neurohover.MDP"."""
    zero = nh.get_task_family("fghh").zero()
    with _reloaded("neurohover.tasks.base") as base:
        for make in (lambda: base.MDP("fghh"), lambda: nh.MDP("fghh")):
            with pytest.raises(NeurohoverError, match=r"^MDP \(no label\) " + _cause("neurohover.tasks.base", "MDP")):
                nh.evaluate(nh.baseline_policy(), make(), n_steps=5)
    assert nh.evaluate(nh.baseline_policy(), zero, n_steps=5).returns.shape == (1, 1, 1)
