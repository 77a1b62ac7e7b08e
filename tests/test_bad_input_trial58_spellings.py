"""Bad-input trial 58 (spellings): an experiment config's ``task = "GHH08"`` ("GHH-08", "Ghh09", "FGHH") was refused
("expected one of 'ghh08', 'ghh09', 'fghh'") though every command takes ``--task GHH08`` and get_task_family reads a
task's name in any case with hyphens dropped; it is now read by that one rule (tasks.task_key) and stored as the
family's name, so the config hashes and resumes as the one that spells it 'ghh08' (T58-A01). ``wins --agents
"baseline, generic"`` was refused over the space after the comma ("agent ' generic' has no test runs") where --runs
"1, 5" is read (T58-A02). ``roulette_weights`` gave a +inf return weight 0, so the best return there is was never
picked; it is refused, as ``tell`` and ``bayes_mean_bounds`` refuse it (T58-B06)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from conftest import CliRun, tiny_test_runs

from neurohover.errors import NeurohoverError
from neurohover.evolution import roulette_weights
from neurohover.experiments import Store
from neurohover.experiments.config import load_config
from neurohover.tasks import TASK_FAMILIES
from neurohover.tasks.ghh08 import GHH08


def _config(tmp_path: Path, task: str, name: str = "tr1", policies: str = "shipped") -> Path:
    """A tiny test-runs config of the baseline on ``task``, as written."""
    path = tmp_path / f"{name}-{len(list(tmp_path.iterdir()))}.toml"
    text = tiny_test_runs("baseline", name=name).replace('task = "ghh08"', f'task = "{task}"')
    path.write_text(text.replace('policies = "shipped"', f'policies = "{policies}"'), encoding="utf-8")
    return path


@pytest.mark.parametrize(("spelt", "task"), [("GHH08", "ghh08"), ("GHH-08", "ghh08"), ("Ghh09", "ghh09"), ("FGHH", "fghh"), ("gHh-0-9", "ghh09")])
def test_a_configs_task_is_read_as_the_command_line_reads_it(tmp_path: Path, spelt: str, task: str) -> None:
    config = load_config(str(_config(tmp_path, spelt)), "quick")
    plain = load_config(str(_config(tmp_path, task)), "quick")
    assert config.settings["task"] == task  # stored as the family's name
    assert config.hash == plain.hash  # the same experiment as the one spelt in lowercase
    assert load_config(str(_config(tmp_path, "ghh08")), "quick", {"task": spelt}).hash == plain.hash  # --set task=... alike


def test_a_run_time_family_is_read_in_any_case(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    class Mine58(GHH08):
        name = "mine58"

    monkeypatch.setitem(TASK_FAMILIES, "mine58", Mine58)
    plain = load_config(str(_config(tmp_path, "mine58", policies="evolve")), "quick")
    config = load_config(str(_config(tmp_path, "MINE-58", policies="evolve")), "quick")
    assert (config.settings["task"], config.hash) == ("mine58", plain.hash)
    with pytest.raises(NeurohoverError, match=r"\[settings\]: task = 'MINE8' is not allowed: expected one of 'ghh08', 'ghh09', 'fghh', 'mine58'"):
        load_config(str(_config(tmp_path, "MINE8", policies="evolve")), "quick")  # an unknown name still refused as written


def test_a_config_spelling_its_task_otherwise_resumes_the_stored_runs(tmp_path: Path, cli: CliRun) -> None:
    store = tmp_path / "s.sqlite"
    rc, out, err = cli("reproduce", str(_config(tmp_path, "GHH-08")), "--store", str(store))
    assert (rc, err) == (0, ""), err
    assert "ran 1 unit, 0 already" in out
    rc, out, err = cli("reproduce", str(_config(tmp_path, "ghh08")), "--store", str(store))
    assert (rc, err) == (0, ""), err
    assert "ran 0 units, 1 already in the store" in out
    with Store(store, create=False) as s:
        assert [e[2] for e in s.experiments()] == [load_config(str(_config(tmp_path, "ghh08")), "quick").hash]


@pytest.fixture(scope="module")
def two_agents(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A store of a test-runs experiment 'tr1' of the baseline and the generic agent."""
    from neurohover.cli import main

    folder = tmp_path_factory.mktemp("wins58")
    config = folder / "tr1.toml"
    config.write_text(tiny_test_runs("baseline", "generic"), encoding="utf-8")
    store = folder / "s.sqlite"
    assert main(["reproduce", str(config), "--store", str(store)]) == 0
    return store


@pytest.mark.parametrize("agents", ["baseline, generic", " baseline ,generic ", "baseline,\tgeneric"])
def test_wins_reads_agents_with_spaces_around_the_commas(two_agents: Path, cli: CliRun, agents: str) -> None:
    rc, out, err = cli("wins", "tr1", "--store", str(two_agents), "--agents", agents, "--runs", "1, 5", "--json")
    assert (rc, err) == (0, ""), err
    _, plain, _ = cli("wins", "tr1", "--store", str(two_agents), "--agents", "baseline,generic", "--runs", "1,5", "--json")
    assert out == plain


def test_wins_reads_against_with_spaces_around_it(two_agents: Path, cli: CliRun) -> None:
    rc, out, err = cli("wins", "tr1", "--store", str(two_agents), "--against", " generic ", "--runs", "1", "--json")
    assert (rc, err) == (0, ""), err
    _, plain, _ = cli("wins", "tr1", "--store", str(two_agents), "--against", "generic", "--runs", "1", "--json")
    assert out == plain


@pytest.mark.parametrize(("option", "value"), [("--agents", "baseline, "), ("--agents", "baseline, ,generic"), ("--against", " ")])
def test_wins_still_refuses_a_label_of_spaces_only(two_agents: Path, cli: CliRun, option: str, value: str) -> None:
    rc, _, err = cli("wins", "tr1", "--store", str(two_agents), option, value, "--runs", "1")
    assert rc == 2
    assert f"{option} {value!r}: an agent's label is empty; allowed baseline, generic" in err


def test_roulette_weights_refuses_plus_inf() -> None:
    with pytest.raises(NeurohoverError, match=r"^returns contains \+inf; returns must be finite, NaN or -inf$"):
        roulette_weights(np.array([-1.0, np.inf]))
    w = roulette_weights(np.array([-1.0, -np.inf, np.nan]))  # the worst returns still get weight 0
    assert w[0] > 0 and w[1] == w[2] == 0
