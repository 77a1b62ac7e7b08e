"""The twelfth bad-input trial's findings in policysets, the continual agent, evolve's resampling, wins, results and
fly --record: each gives one clear message (exit 2 / NeurohoverError) naming the value and what is allowed."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from conftest import tiny_test_runs

from neurohover.errors import NeurohoverError


@pytest.fixture
def tiny_store(tmp_path: Path, cli) -> Path:
    """A store holding a tiny test-runs experiment of two groups (baseline, generic)."""
    config, store = tmp_path / "tr1.toml", tmp_path / "tr1.sqlite"
    config.write_text(tiny_test_runs("baseline", "generic"))
    assert cli("reproduce", str(config), "--store", str(store), "--no-progress")[0] == 0
    return store


def test_policy_set_roles_takes_a_task_name_and_refuses_other_values() -> None:
    """T7: policy_set_roles("ghh08") was an AttributeError; it takes a task's name as load_policy_set does, and names a
    value that is neither a name nor a TaskFamily."""
    import neurohover as nh
    from neurohover.policysets import policy_set_roles

    assert policy_set_roles("ghh08") == policy_set_roles(nh.get_task_family("ghh08"))
    with pytest.raises(NeurohoverError, match=r"family=5 is not allowed: give a task's name or a TaskFamily"):
        policy_set_roles(5)


@pytest.mark.parametrize(
    ("crashes", "returns", "message"),
    [
        (np.zeros((3, 2)), np.zeros((3, 2)), "crashes of shape (3, 2) is not allowed: give a (P, P) array of numbers, P >= 2"),
        ([[0]], [[0]], "crashes of shape (1, 1) is not allowed: give a (P, P) array of numbers, P >= 2"),
        (np.zeros((3, 3)), np.zeros((4, 4)), "returns of shape (4, 4) is not allowed beside crashes of shape (3, 3): give both (P, P)"),
        (np.zeros((2, 2)), "x", "returns 'x' is not allowed: give a (P, P) array of numbers"),
    ],
)
def test_choose_safe_names_the_shapes_it_takes(crashes, returns, message: str) -> None:
    """T7: a (3, 2) array was an IndexError, a plain list an AttributeError; now the shape allowed is named."""
    from neurohover.policysets import choose_safe

    with pytest.raises(NeurohoverError) as err:
        choose_safe(crashes, returns)
    assert message in str(err.value)


def test_choose_safe_takes_plain_lists_of_the_right_shape() -> None:
    """T7: a list of lists of the right shape is read as the array it spells (it was an AttributeError)."""
    from neurohover.policysets import choose_safe

    crashes = [[0, 0, 1], [0, 0, 0], [1, 1, 0]]
    returns = [[0, -5, -1], [-2, 0, -3], [-1, -1, 0]]
    assert choose_safe(crashes, returns) == choose_safe(np.array(crashes), np.array(returns)) == (1, 0)


@pytest.mark.parametrize("n", [-1, 0, 4, True, 1.5])
def test_choose_safe_refuses_n_outside_one_to_the_number_of_policies(n) -> None:
    """S8: n=-1 returned two policies (a slice [:-1]), n=0 none."""
    from neurohover.policysets import choose_safe

    with pytest.raises(NeurohoverError, match=rf"n={n!r} is out of range: allowed an integer in 1\.\.3 \(the number of policies\)"):
        choose_safe(np.zeros((3, 3)), np.zeros((3, 3)), n=n)


@pytest.mark.parametrize("spec", ["race:0.5:", "race:auto:", "race::0.5", "race:0.2:prose:"])
def test_resampling_with_an_empty_field_is_refused(spec: str, tmp_path: Path, monkeypatch, cli) -> None:
    """S8: 'race:0.5:' and 'race:auto:' were read as race:0.5 and race:auto; the empty field is now named."""
    from neurohover.evolution.config import parse_resampling

    with pytest.raises(NeurohoverError) as err:
        parse_resampling(spec)
    assert f"resampling {spec!r} is not allowed: it has an empty field" in str(err.value)
    assert "race:auto[:K]" in str(err.value)  # the allowed forms, auto among them
    monkeypatch.chdir(tmp_path)
    rc, _, err_text = cli("evolve", "--task", "ghh08", "--budget", "10", "--resampling", spec, "--out", "never.json")
    assert rc == 2 and f"resampling {spec!r} is not allowed: it has an empty field" in err_text, err_text
    assert list(tmp_path.iterdir()) == []


@pytest.mark.slow
def test_a_continual_safeguard_delayed_past_the_episode_is_refused_before_flying() -> None:
    """S3: safeguard_after at or past the episode length was accepted, so the safeguard never tested."""
    import neurohover as nh
    from neurohover.agents import run_test
    from neurohover.agents.registry import make_agent
    from neurohover.agents.spec import AgentOptions

    family = nh.get_task_family("ghh08")
    for after in (20, 100000):
        agent = make_agent("continual", family, options=AgentOptions(settings={"safeguard_after": after}))
        with pytest.raises(NeurohoverError) as err:
            run_test(agent, family, family.test_mdps()[0], episodes=2, n_steps=20)
        assert (
            f"continual safeguard_after={after} is not below the episode's 20 control steps (--episode-steps, n_steps): "
            "the safeguard would never test; give safeguard_after below 20, or safeguard=false"
        ) in str(err.value)
    agent = make_agent("continual", family, options=AgentOptions(settings={"safeguard_after": 19}))
    assert run_test(agent, family, family.test_mdps()[0], episodes=1, n_steps=20).returns.shape == (1,)


def test_wins_refuses_the_against_group_among_the_agents(tiny_store: Path, cli) -> None:
    """S4: `wins --against baseline --agents baseline,generic` dropped baseline from the table without a word."""
    rc, out, err = cli("wins", "tr1", "--store", str(tiny_store), "--against", "baseline", "--agents", "baseline,generic")
    assert rc == 2 and out == ""
    assert "--against baseline is also in --agents 'baseline,generic': an agent is not compared with itself; give --agents generic" in err, err
    rc, out, err = cli("wins", "tr1", "--store", str(tiny_store), "--against", "baseline", "--agents", "generic")
    assert rc == 0 and "generic" in out, err


def test_results_takes_its_format_from_the_out_suffix(tiny_store: Path, tmp_path: Path, monkeypatch, cli) -> None:
    """S2: `results --out r2.json` without --format wrote CSV into the .json file; a contradicting --format is refused."""
    import json

    monkeypatch.chdir(tmp_path)  # short names: messages shorten long ones
    rc, _, err = cli("results", "tr1", "--store", str(tiny_store), "--out", "r2.json")
    assert rc == 0, err
    assert json.loads((tmp_path / "r2.json").read_text())["experiment"] == "tr1"
    rc, _, err = cli("results", "tr1", "--store", str(tiny_store), "--out", "r2.csv")
    assert rc == 0 and (tmp_path / "r2.csv").read_text().startswith("experiment,scale,key"), err
    rc, _, err = cli("results", "tr1", "--store", str(tiny_store), "--out", "new/r3.json", "--format", "csv")
    assert rc == 2 and "--format csv is not allowed beside --out 'new/r3.json', whose name says json: give one that agrees" in err, err
    assert not (tmp_path / "new").exists()


@pytest.mark.parametrize("name", ["rx.csv", "sub/rx.json", "rx"])
def test_fly_record_refuses_a_name_not_ending_npz(name: str, tmp_path: Path, monkeypatch, cli) -> None:
    """S2: `fly --record rx.csv` wrote an .npz archive named rx.csv."""
    from neurohover.policysets import SHIPPED

    monkeypatch.chdir(tmp_path)  # short names: messages shorten long ones
    rc, _, err = cli("fly", "--task", "ghh08", "--episodes", "1", "--mdp", "train:1", "--policy", str(SHIPPED / "ghh08" / "generic.json"), "--record", name)
    assert rc == 2, err
    like = str(Path(name).with_suffix(".npz"))
    assert f"--record {name!r} is not allowed: flight data are a NumPy archive; give a path ending .npz (e.g. {like!r})" in err, err
    assert list(tmp_path.iterdir()) == []
