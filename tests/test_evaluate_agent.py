"""`neurohover evaluate-agent` (issue 36): any trained policy flown as the paper measured its agents, beside the baseline
and the shipped generic on the same gusts."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pytest

import neurohover as nh
from neurohover.integrations.flying import AgentRow, compare_agent
from neurohover.policysets import load_policy_set

GENERIC = Path(nh.__file__).parent / "data" / "policies" / "ghh08" / "generic.json"


def _rows(text: str) -> dict[str, list[str]]:
    return {line.split()[0]: line.split() for line in text.splitlines() if line.split() and line.split()[0] in ("agent", "baseline", "generic")}


def test_a_policy_file_flies_the_gusts_of_the_baseline_and_generic(cli, tmp_path: Path) -> None:
    out = tmp_path / "rows.json"
    rc, printed, err = cli("evaluate-agent", "--task", "ghh08", "--policy", str(GENERIC), "--n-mdps", "2", "--episodes", "2",
                           "--episode-steps", "300", "--json", str(out))  # fmt: skip
    assert rc == 0, err
    rows = _rows(printed)
    assert rows["agent"][1:] == rows["generic"][1:]  # the shipped generic as the agent: the same episodes, the same numbers
    assert rows["baseline"][1] != rows["agent"][1]
    stored = json.loads(out.read_text())
    assert stored["n_mdps"] == 2 and [r["name"] for r in stored["rows"]] == ["agent", "baseline", "generic"] and stored["rows"][0]["episodes"] == 4


def test_a_callable_flies_as_the_kernel_flies_the_same_policy(cli, tmp_path: Path, monkeypatch) -> None:
    (tmp_path / "my_agents.py").write_text(
        "import numpy as np\nimport neurohover as nh\nB = nh.baseline_policy()\ndef act(obs):\n    return np.array([B.act(o) for o in obs])\n"
    )
    monkeypatch.syspath_prepend(str(tmp_path))
    rc, printed, err = cli("evaluate-agent", "--task", "ghh08", "--mdps", "train", "--callable", "my_agents:act", "--n-mdps", "2",
                           "--episode-steps", "300", "--obs-dtype", "float64")  # fmt: skip
    assert rc == 0, err
    rows = _rows(printed)
    assert float(rows["agent"][1]) == pytest.approx(float(rows["baseline"][1]), rel=1e-9)  # the baseline, flown in Python
    sys.modules.pop("my_agents", None)


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        ((), "give exactly one of --policy, --callable, --rl-zoo, --sb3, --cleanrl (the agent to fly); got none"),
        (("--policy", str(GENERIC), "--callable", "m:f"), "got --policy, --callable"),
        (("--callable", "nomodule"), "--callable 'nomodule' is not allowed: give MODULE:FUNCTION"),
        (("--callable", "no_such_module_here:act"), "--callable 'no_such_module_here:act': No module named"),
        (("--policy", str(GENERIC), "--n-mdps", "11", "--mdps", "train"), "--n-mdps 11 is out of range: allowed 1..10 (ghh08 has 10 train MDPs)"),
        (("--policy", str(GENERIC), "--episodes", "0"), "--episodes 0 is out of range"),
        (("--policy", str(GENERIC), "--seed", "-1"), "seed=-1 is out of range: allowed an integer in 0..2**63-1"),
    ],
)
def test_bad_input_is_refused_with_one_clear_message(cli, argv, message: str) -> None:
    rc, _, err = cli("evaluate-agent", "--task", "ghh08", *argv)
    assert rc == 2 and message in err and "Traceback" not in err


def test_compare_agent_rows_are_the_papers_measures() -> None:
    ghh09 = nh.get_task_family("ghh09")
    mdps = [ghh09.mdp("train:0"), ghh09.mdp("train:1")]
    generic = load_policy_set("ghh09").generic
    rows = compare_agent(lambda obs: np.zeros((len(obs), 4)), mdps, episodes=2, n_steps=200)  # a do-nothing agent
    assert [r.name for r in rows] == ["agent", "baseline", "generic"]
    by_kernel = nh.evaluate(generic, mdps, episodes=2, n_steps=200)
    assert rows[2] == AgentRow.of("generic", by_kernel) and rows[2].episodes == 4
    assert rows[0].crashes > 0 and rows[0].return_per_episode < rows[1].return_per_episode  # doing nothing crashes in wind


def test_an_sb3_model_file_is_flown(cli, tmp_path: Path) -> None:
    pytest.importorskip("stable_baselines3", reason="the examples extra (Stable-Baselines3) is not installed")
    import gymnasium as gym
    from stable_baselines3 import PPO

    model = PPO("MlpPolicy", gym.make("neurohover/GHH08-Short-v0"), n_steps=64, batch_size=64, seed=0)  # untrained: its shapes
    model.save(tmp_path / "model.zip")
    rc, printed, err = cli("evaluate-agent", "--task", "ghh08", "--sb3", str(tmp_path / "model.zip"), "--n-mdps", "1", "--episode-steps", "50")
    assert rc == 0, err
    assert _rows(printed)["agent"][-1] == "1" or "of 1" in printed  # one episode flown
    rc, _, err = cli("evaluate-agent", "--task", "ghh08", "--sb3", str(tmp_path / "missing.zip"))
    assert rc == 2 and "no such SB3 model file (.zip)" in err
    np.savez(tmp_path / "flight.npz", x=np.zeros(3))  # a zip, but no model (fourth trial: SB3's AssertionError)
    rc, _, err = cli("evaluate-agent", "--task", "ghh08", "--sb3", str(tmp_path / "flight.npz"))
    assert rc == 2 and "is a zip file but not a Stable-Baselines3 model" in err


def test_sensor_options_fly_every_policy_through_the_same_sensors(cli, tmp_path, monkeypatch) -> None:
    """Issue 36: an agent trained on a sensor variant is measured through its sensors: the baseline as a batch
    function earns exactly the kernel's baseline row through them, and not the exact sensors' return."""
    (tmp_path / "base_act.py").write_text(
        "import numpy as np, neurohover\n_p = neurohover.baseline_policy()\n\ndef act(obs):\n"
        "    return np.array([_p.act(o) for o in np.asarray(obs, dtype=np.float64)])\n"
    )
    monkeypatch.syspath_prepend(str(tmp_path))
    rows = {}
    for name, extra in (("sensed", ["--obs-noise", "1.0", "--obs-delay", "2"]), ("exact", [])):
        out = tmp_path / f"{name}.json"
        argv = ["evaluate-agent", "--task", "ghh08", "--callable", "base_act:act", "--n-mdps", "2", "--episode-steps", "200"]
        rc, _, err = cli(*argv, "--obs-dtype", "float64", "--json", str(out), *extra)
        assert rc == 0, err
        rows[name] = {r["name"]: r["return_per_episode"] for r in json.loads(out.read_text())["rows"]}
    assert rows["sensed"]["agent"] == pytest.approx(rows["sensed"]["baseline"], rel=1e-9)
    assert rows["sensed"]["agent"] != pytest.approx(rows["exact"]["agent"], rel=1e-6)


def test_a_callable_that_does_not_import_or_returns_no_numbers_is_refused_by_name(cli, tmp_path: Path, monkeypatch) -> None:
    (tmp_path / "nh_strings.py").write_text('import numpy as np\n\n\ndef act(obs):\n    return np.full((len(obs), 4), "a")\n')
    (tmp_path / "nh_broken.py").write_text("def act(:\n    pass\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    base = ("evaluate-agent", "--task", "ghh08", "--n-mdps", "1", "--episodes", "1", "--episode-steps", "20")
    rc, _, err = cli(*base, "--callable", "nh_strings:act")
    assert rc == 2 and "act returned ndarray" in err and "expected numbers" in err
    rc, _, err = cli(*base, "--callable", "nh_broken:act")
    assert rc == 2 and "--callable 'nh_broken:act': SyntaxError" in err
    # A function of the wrong signature, or one that raises, was a traceback (bad-input trial): its error, named.
    (tmp_path / "nh_raises.py").write_text('def act(obs):\n    raise RuntimeError("boom")\n')
    rc, _, err = cli(*base, "--callable", "nh_raises:act")
    assert rc == 2 and "--callable 'nh_raises:act' raised RuntimeError: boom when called with a batch of observations" in err
    rc, _, err = cli(*base, "--callable", "os:getcwd")
    assert rc == 2 and "--callable 'os:getcwd' raised TypeError" in err and "Traceback" not in err
    rc, out, _ = cli(*base, "--policy", "baseline")
    assert rc == 0 and out.count("baseline") >= 1
