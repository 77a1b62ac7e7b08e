"""Issue 37, the ninth fresh trial, its files: a store row, checkpoint, policy-set manifest, build state or flight data
holding JSON nested 100,000 deep or an integer of 5,000 digits gives one clear message (exit 2 / NeurohoverError), not a
RecursionError or ValueError traceback; a policy set's policies, flight data's lengths and metadata, a drift's window
and a reading past any flight are checked against what they claim."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest
from test_bad_input_trial7 import _config, _damaged, tiny_store  # noqa: F401  (tiny_store: the fixture)

import neurohover as nh
from neurohover.errors import NeurohoverError
from neurohover.jsontext import JSONError, parse_json, strict_json

DEEP = '{"a": ' + "[" * 100_000 + "]" * 100_000 + "}"
HUGE = '{"a": 1' + "0" * 5000 + "}"


def test_strict_json_refuses_deep_nesting_huge_integers_and_keys_given_twice_with_one_error_class() -> None:
    """The one decision every JSON reader shares: a 5,000-digit integer was int()'s own ValueError past 4,300 digits."""
    for text, why in (
        (DEEP, "nested too deeply"),
        (HUGE, r"1000000000.*\(5001 digits\) is out of range"),
        ('{"a": 1, "a": 2}', "key 'a' is given more than once"),
    ):
        with pytest.raises(JSONError, match=why):
            strict_json(text)
    with pytest.raises(JSONError, match="must be str, bytes or bytearray"):
        strict_json(None)  # type: ignore[arg-type]
    assert strict_json(b'{"a": [1, 2.5, {"b": null}]}') == {"a": [1, 2.5, {"b": None}]}
    with pytest.raises(NeurohoverError, match="^x.json is not allowed: its JSON is nested too deeply$"):
        parse_json(DEEP, "x.json")
    with pytest.raises(NeurohoverError, match="^x.json is not valid JSON: the number"):
        parse_json(HUGE, "x.json")


@pytest.mark.parametrize("row", [DEEP, HUGE], ids=["deep", "huge"])
def test_a_store_row_nested_deeply_or_holding_a_huge_integer_is_damaged(tiny_store, tmp_path, cli, row) -> None:  # noqa: F811
    """T5: results, report, wins and reproduce gave a RecursionError or ValueError traceback."""
    from neurohover.experiments import Store

    store = _damaged(tiny_store, tmp_path, f"UPDATE units SET result = '{row}' WHERE key = (SELECT min(key) FROM units)")
    with Store(store) as s, pytest.raises(NeurohoverError, match=r"unit .*'s result is damaged \(not JSON: "):
        s.results("mytest", "quick")
    for argv in (["results", "mytest"], ["wins", "mytest", "--runs", "2"], ["reproduce", str(_config(tmp_path)), "--no-progress"]):
        rc, _, err = cli(*argv, "--store", str(store))
        assert rc == 2 and "'s result is damaged (not JSON" in err and "Traceback" not in err, (argv, err)
    rc, _, err = cli("report", "--store", str(store), "--out", str(tmp_path / "rep"))
    text = (tmp_path / "rep" / "report.md").read_text() if rc == 0 else err
    assert "'s result is damaged (not JSON" in text, text[-600:]


def test_a_checkpoint_holding_a_huge_integer_is_refused_by_name(tmp_path, cli) -> None:
    """T6: evolve --resume on a checkpoint with a 5,001-digit budget was a ValueError traceback."""
    out = str(tmp_path / "ev" / "p.json")
    argv = ["evolve", "--task", "ghh08", "--mdp", "train:0", "--budget", "20", "--episode-steps", "20", "--out", out]
    assert cli(*argv)[0] == 0
    checkpoint = Path(out + ".checkpoint.json")
    checkpoint.write_text(checkpoint.read_text().replace('"budget": ', '"budget": 1' + "0" * 5000 + ', "x_budget": ', 1))
    rc, _, err = cli(*argv[:-6], "--budget", "100", "--episode-steps", "20", "--out", out, "--resume")
    assert rc == 2 and "is not valid JSON: the number 10000000000000000000... (5001 digits) is out of range" in err, err


@pytest.fixture(scope="module")
def tiny_set(tmp_path_factory) -> Path:
    """A GHH-08 policy set built at a budget of 3 with 20-step episodes (each test changes a copy)."""
    from neurohover.policysets import build_policy_set

    root = tmp_path_factory.mktemp("set")
    build_policy_set("ghh08", root, budget=3, n_steps=20, safety_episodes=1)
    return root


def _edited(tiny_set: Path, tmp_path: Path, name: str, edit) -> Path:
    root = tmp_path / "bp"
    shutil.copytree(tiny_set, root)
    path = root / "ghh08" / name
    path.write_text(edit(path.read_text()))
    return root


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (
            lambda t: t.replace('"budget": ', '"budget": 1' + "0" * 5000 + ', "x_budget": '),
            r"cannot be read as JSON: the number .*\(5001 digits\) is out of range",
        ),
        (
            lambda t: t.replace('"budget": ', '"budget": ' + "[" * 100_000 + "]" * 100_000 + ', "x_budget": '),
            "cannot be read as JSON: its JSON is nested too deeply",
        ),
        (lambda t: t.replace('"safe": ', '"safe": [0, 2], "safe": '), "cannot be read as JSON: key 'safe' is given more than once"),
    ],
    ids=["huge", "deep", "twice"],
)
def test_a_damaged_manifest_is_refused_by_name(tiny_set, tmp_path, cli, edit, message) -> None:
    """T7: a manifest's huge integer or deep nesting was a traceback in compete; "safe" given twice kept the last."""
    from neurohover.policysets import load_policy_set

    root = _edited(tiny_set, tmp_path, "manifest.json", edit)
    with pytest.raises(NeurohoverError, match="policy-set manifest .*manifest.json' " + message):
        load_policy_set("ghh08", root)
    argv = ["--agent", "model-free", "--runs", "1", "--episodes", "2", "--episode-steps", "20", "--out", str(tmp_path / "cv")]
    rc, _, err = cli("compete", "--task", "ghh08", *argv, "--policy-dir", str(root))
    assert rc == 2 and "cannot be read as JSON" in err and "Traceback" not in err, err


def _meta(key: str, value: str):
    return lambda text: json.dumps({**json.loads(text), key: value})


@pytest.mark.parametrize(
    ("name", "edit", "message"),
    [
        ("specialised_3.json", lambda _t: None, "specialised_3.json \\(specialised policy 3\\) records name 'specialised_4', not 'specialised_3'"),
        ("specialised_3.json", _meta("target", "ghh08/train:4"), "records target 'ghh08/train:4', not 'ghh08/train:3'"),
        ("generic.json", _meta("task", "ghh09"), "generic.json': its task 'ghh09' is not allowed beside its target 'ghh08/zero'"),  # T24-02: load_policy's
        ("generic.json", _meta("target", "ghh08/train:0"), "records target 'ghh08/train:0', not 'ghh08/zero'"),
    ],
    ids=["copied", "target", "task", "generic-target"],
)
def test_a_policy_recording_another_place_in_its_set_is_refused(tiny_set, tmp_path, name, edit, message) -> None:
    """S9: specialised_4.json copied over specialised_3.json, or a generic of task ghh09, was flown without a word."""
    from neurohover.policysets import load_policy_set

    copied = (tiny_set / "ghh08" / "specialised_4.json").read_text()
    root = _edited(tiny_set, tmp_path, name, lambda t: edit(t) or copied)
    with pytest.raises(NeurohoverError, match=message):
        load_policy_set("ghh08", root)
    for task in ("ghh08", "ghh09", "fghh"):  # the shipped sets record each policy's own place
        load_policy_set(task)


@pytest.mark.parametrize("value", ["1" + "0" * 5000, "[" * 100_000 + "]" * 100_000], ids=["huge", "deep"])
def test_a_damaged_build_state_is_refused_with_the_way_to_start_over(tmp_path, value) -> None:
    """T8: build-policies resuming from a build.json with a huge integer or deep nesting was a traceback."""
    from neurohover.policysets import build_policy_set

    state = tmp_path / "ghh08.building" / "stages" / "build.json"
    state.parent.mkdir(parents=True)
    state.write_text('{"task": "ghh08", "budget": ' + value + "}")
    with pytest.raises(NeurohoverError, match=r"the interrupted build's state .*build.json' is damaged \((the number|its JSON).*\): delete .* to start"):
        build_policy_set("ghh08", tmp_path, budget=3, n_steps=20, safety_episodes=1)


@pytest.fixture(scope="module")
def flight(tmp_path_factory) -> Path:
    """Two recorded 30-step ghh08 episodes, as fly --record writes them."""
    path = tmp_path_factory.mktemp("flight") / "flight.npz"
    policy = nh.load_policy(Path(nh.__file__).parent / "data" / "policies" / "ghh08" / "generic.json")
    zero = nh.get_task_family("ghh08").zero()
    ev = nh.evaluate(policy, zero, episodes=2, record=True, n_steps=30)
    fd, returns = ev.flight_data, ev.returns.ravel().tolist()  # as flown: returns [-1.0, -2.0] are refused (T23-03)
    fd.metadata.update({"task": "ghh08", "mdps": [zero.to_dict()] * 2, "policy": "generic", "seed": 0, "returns": returns})
    fd.save(path)
    return path


def _rewritten(flight: Path, tmp_path: Path, **changes) -> Path:
    with np.load(flight) as z:
        arrays = {k: z[k] for k in z.files}
    meta = json.loads(str(arrays["metadata"]))
    for key in [k for k in changes if k in meta]:
        meta[key] = changes.pop(key)
    path = tmp_path / "bad.npz"
    np.savez(path, **{**arrays, "metadata": np.array(json.dumps(meta)), **changes})
    return path


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        ({"metadata": np.array(DEEP)}, "is not a readable flight-data file \\(JSONError: its JSON is nested too deeply\\)"),
        ({"lengths": np.array([0, 60])}, "is not a readable flight-data file: episode 0 has 0 steps \\(a flown one has at least 1\\)"),
        ({"episode_steps": 10}, "episode 0 has 30 steps, more than its metadata's episode_steps=10"),
        ({"task": "ghh09"}, "its metadata task 'ghh09' is not its MDPs' family: episode 0 flew a 'ghh08' MDP"),
    ],
    ids=["deep", "zero-length", "past-episode-steps", "task"],
)
def test_flight_data_nested_deeply_or_contradicting_its_metadata_is_refused(flight, tmp_path, cli, changes, message) -> None:
    """T9, S7: deep metadata was a RecursionError in learn-model and plot; lengths [0, 60] for two 30-step episodes, a
    task ghh09 over ghh08's MDPs and episode_steps 10 for 30-step episodes were all taken."""
    path = _rewritten(flight, tmp_path, **changes)
    with pytest.raises(NeurohoverError, match=message):
        nh.FlightData.load(path)
    for argv in (
        ["learn-model", "--flight-data", str(path), "--method", "lr", "--out", str(tmp_path / "m.json")],
        ["plot", str(path), "--out", str(tmp_path / "p")],
    ):
        rc, _, err = cli(*argv)
        assert rc == 2 and "Traceback" not in err and len(err.strip().splitlines()) == 1, err
    assert nh.FlightData.load(flight).n_transitions == 60


def test_joined_flight_data_keeps_metadata_its_episodes_fit(flight, tmp_path) -> None:
    """The checks above hold for two recordings joined and saved: the per-episode lists of both halves, and no task
    where the halves' differ; no episode_steps where a shorter budget's full episodes would read as cut short (T22-01)."""
    a = nh.FlightData.load(flight)
    b = nh.FlightData(
        a.observations[:1], a.actions[:1], {**a.metadata, "episode_steps": 40, "task": "ghh09", "returns": [-0.5], "mdps": [{}], "crashed": [True]}
    )
    both = a + b
    assert "episode_steps" not in both.metadata and "task" not in both.metadata and both.metadata["returns"] == [*a.metadata["returns"], -0.5]
    both.save(tmp_path / "both.npz")
    assert nh.FlightData.load(tmp_path / "both.npz").metadata["mdps"][2] == {}
    short = nh.FlightData((a.observations[0][:6],), (a.actions[0][:5],), {"episode_steps": 5})  # 5 steps: within its budget (T18-4)
    assert (a + short).metadata["episode_steps"] == 30


def test_a_drift_window_past_any_run_or_empty_after_at_is_refused() -> None:
    """T10, S13: change_at (0, 10**30) was NumPy's "high is out of bounds for int64" at reset; 'D_w=0.8@' was read as the
    default window (200, 800) and '@200-' as (200, 200)."""
    change = (("D_w", 0.8),)
    for call in (
        lambda: nh.Drift(0.0, change, change_at=(0, 10**30)),
        lambda: gym.make("neurohover/GHH08-AbruptChange-v0", drift="D_w=0.8@0-99999999999999999999").reset(seed=0),
        lambda: nh.Drift.from_dict({"change": {"D_w": 0.8}, "change_at": [0, 2**63]}),
    ):
        with pytest.raises(NeurohoverError, match=r"change_at=.* is out of range: allowed whole episode numbers 0 <= lo <= hi <= 1,000,000,000,000"):
            call()
    gym.make("neurohover/GHH08-AbruptChange-v0", drift=nh.Drift(0.0, change, change_at=(0, 10**12))).reset(seed=0)
    with pytest.raises(NeurohoverError, match="empty window after '@' in 'D_w=0.8@': give @LO-HI"):
        nh.Drift.parse("D_w=0.8@")
    with pytest.raises(NeurohoverError, match="'D_w=0.8@200-' is not understood"):
        nh.Drift.parse("D_w=0.8@200-")
    assert nh.Drift.parse("D_w=0.8@5").change_at == (5, 5) and nh.Drift.parse("D_w=0.8").change_at == (200, 800)


def test_a_reading_past_any_flight_is_named_not_called_collinear(flight, tmp_path, cli) -> None:
    """U1: one observation of 1e300 made learn-model say the regressors of the u axis are collinear."""
    from neurohover.models.transitions import MAX_READING, Transitions

    with np.load(flight) as z:
        obs = z["observations"].copy()
    obs[5, 0] = 1e300
    path = _rewritten(flight, tmp_path, observations=obs)
    rc, _, err = cli("learn-model", "--flight-data", str(path), "--method", "lr", "--out", str(tmp_path / "m.json"))
    assert rc == 2 and "episode 0 is flagged uncrashed, yet after step 5 its speed is 1e+300, past the crash bound" in err, err  # at load (T26-B11)
    data = nh.FlightData.load(flight)
    far = data.observations[1].copy()
    far[2, 5] = -2 * MAX_READING
    with pytest.raises(NeurohoverError, match="episode 1, step 2 reads z = -2e\\+06"):
        Transitions(nh.FlightData((data.observations[0], far), data.actions))
    Transitions(data)  # a real flight is far below the bound
