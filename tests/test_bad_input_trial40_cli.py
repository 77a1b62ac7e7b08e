"""Bad-input trial 40 (the command line): --obs-noise with a bare level beside key=value pairs, a trailing comma or two
levels said the level itself "is not understood" while listing it as allowed (T40-A01); compete --drift walk=1e-320 (a
subnormal walk, drifting nothing) was flown (T40-A02, fixed in tasks.drift: pinned here on the command line);
--model-policy was taken and ignored by the authors' FGHH agents, each value a settings hash of its own (T40-A03);
report --out over another store's report replaced report.md without a word, its figures left unreferenced (T40-A04)."""

from __future__ import annotations

from pathlib import Path

import pytest
from store_edits import COMPETE, competed_store

from neurohover.agents.model_based import ModelEvolution
from neurohover.agents.registry import make_agent
from neurohover.agents.spec import AgentOptions
from neurohover.errors import NeurohoverError
from neurohover.tasks.sensor import Sensor

FGHH = ("compete", "--task", "fghh", "--runs", "1", "--episodes", "2", "--episode-steps", "20")


@pytest.mark.parametrize(
    ("text", "said"),
    [
        ("0.5,velocity=0.1", "gives the bare level '0.5' beside another setting: a bare level is allowed only alone; among key=value pairs write level=0.5"),
        ("velocity=0.1,0.5", "gives the bare level '0.5' beside another setting"),
        ("0.5,0.6", "gives the bare level '0.5' beside another setting: .*write level=0.5 \\(one level\\)"),
        ("0.5,", "'0.5,' has an empty setting between commas"),
        ("0.5, ", "has an empty setting between commas"),
    ],
)
def test_a_bare_level_beside_other_settings_is_named_as_such(text: str, said: str) -> None:
    with pytest.raises(NeurohoverError, match=said):
        Sensor.parse(text)


def test_obs_noise_with_a_bare_level_and_pairs_says_what_is_wrong(cli) -> None:
    for command in (("fly", "--task", "ghh08", "--episodes", "1"), ("evaluate-agent", "--task", "ghh08", "--n-mdps", "1", "--policy", "baseline")):
        rc, _, err = cli(*command, "--obs-noise", "0.5,dropout=0.1")
        assert rc == 2 and "bare level '0.5' beside another setting" in err and "write level=0.5" in err, err
        assert "is not understood" not in err
    assert Sensor.parse("level=0.5,dropout=0.1") == Sensor.from_dict({"level": 0.5, "dropout": 0.1})  # the form it names


def test_a_walk_that_drifts_nothing_is_refused_by_compete(cli, tmp_path: Path) -> None:
    rc, _, err = cli(*COMPETE, "--drift", "walk=1e-320", "--out", str(tmp_path / "c"))
    assert rc == 2 and "walk=1e-320 is out of range, too small to change the dynamics" in err, err
    assert not (tmp_path / "c").exists()


@pytest.mark.parametrize("agent", ["authors-zero", "authors-fixed", "authors-race"])
@pytest.mark.parametrize("value", ["ours", "authors"])
def test_model_policy_is_refused_for_the_authors_fghh_agents(cli, tmp_path: Path, agent: str, value: str) -> None:
    rc, _, err = cli(*FGHH, "--agent", agent, "--model-policy", value, "--out", str(tmp_path / "c"))
    assert rc == 2 and "--model-policy applies to the agents that evolve policies on their models as it says (model-based," in err, err
    assert f"not to --agent {agent}, which would ignore it" in err and "authors-" not in err.split("(")[1].split(")")[0]  # the takers named
    assert not (tmp_path / "c").exists()


def test_model_policy_is_refused_for_them_by_the_python_api(tmp_path: Path) -> None:
    from neurohover.compete import compete

    with pytest.raises(NeurohoverError, match="model_policy='authors' is not allowed for agent 'authors-race': it evolves on the model as the authors'"):
        make_agent("authors-race", "fghh", options=AgentOptions(evolution=ModelEvolution(model_policy="authors")))
    make_agent("authors-race", "fghh", options=AgentOptions(evolution=ModelEvolution()))  # the default is no choice made
    for value in ("ours", "authors"):  # a config group's key: refused by the schema, as compete's lr_fit reaches it
        with pytest.raises(NeurohoverError, match="group 'authors-fixed': model_policy is not allowed for agent 'authors-fixed', which would ignore it"):
            compete("fghh", "authors-fixed", runs=1, episodes=2, n_steps=20, out=tmp_path / "c", lr_fit={"model_policy": value})
    assert not (tmp_path / "c").exists()


@pytest.mark.slow
def test_report_over_another_stores_report_says_what_it_replaces(cli, tmp_path: Path) -> None:
    first = competed_store(tmp_path / "a")
    second = tmp_path / "b.sqlite"
    assert cli(*COMPETE, "--seed", "1", "--out", str(tmp_path / "c"), "--store", str(second))[0] == 0
    out = tmp_path / "r"
    rc, _, err = cli("report", "--store", str(first), "--out", str(out))
    assert rc == 0 and "note" not in err, err
    (old,) = [p.name for p in out.glob("*.png")]
    (out / "mine.png").write_bytes(b"not neurohover's")
    rc, _, err = cli("report", "--store", str(second), "--out", str(out))
    assert rc == 0, err
    assert f"held the report of another results store ({str(first)!r}); it is replaced" in err, err
    assert f"its figures that this report does not show are left in the folder (remove them if unwanted): {old}" in err
    assert "mine.png" not in err and (out / old).is_file() and (out / "mine.png").is_file()  # named, never removed
    assert old not in (out / "report.md").read_text()
    rc, _, err = cli("report", "--store", str(second), "--out", str(out))  # the same report again: nothing to say
    assert rc == 0 and "note" not in err, err
