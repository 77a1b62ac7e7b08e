"""The twenty-second bad-input trial's findings in evolution runs and their checkpoints (T22-10 to T22-14): a
checkpoint's champion, history, prototype or stop reason that contradicts the rest of it is refused on resume, as a
damaged checkpoint, and a tell() of fewer episodes than genomes asked is refused; a generation's episodes that are no
integer are "not allowed", not "out of range"."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest

from neurohover.errors import NeurohoverError
from neurohover.evolution.common import TellInfo
from neurohover.evolution.evolve import evolve
from neurohover.evolution.generational import GenerationalNE, GenerationalSettings
from neurohover.evolution.optimisers import OPTIMISERS
from neurohover.evolution.steady_state import SteadyStateNE
from neurohover.tasks import get_task_family


def _raises(fragment: str):
    return pytest.raises(NeurohoverError, match=re.escape(fragment))


# --------------------------------------------------------------------------- T22-14: episodes that are no integer


@pytest.mark.parametrize("episodes", [3.0, True, "3", np.float64(2.0)])
def test_a_generations_episodes_of_the_wrong_type_are_not_allowed(episodes) -> None:
    """T22-14: TellInfo(episodes=3.0) said "is out of range" (a type problem); now "is not allowed", with the range."""
    with _raises(f"episodes={episodes!r} is not allowed: allowed an integer in 0..10,000,000,000 (the episodes one generation cost)"):
        TellInfo(episodes=episodes)


@pytest.mark.parametrize("episodes", [-1, 10**10 + 1])
def test_a_generations_episodes_out_of_range_stay_out_of_range(episodes: int) -> None:
    """T22-14: an integer outside 0..MAX_EPISODES is still "out of range"."""
    with _raises(f"episodes={episodes!r} is out of range: allowed an integer in 0..10,000,000,000"):
        TellInfo(episodes=episodes)


# --------------------------------------------------------------------------- T22-13: fewer episodes than genomes asked


def test_a_generation_of_fewer_episodes_than_genomes_is_refused() -> None:
    """T22-13: GenerationalNE.tell(fitness, TellInfo(episodes=0)) was taken for a generation of ten asked genomes: its
    evaluations (the episodes its budget counts) stayed 0 and stop() never came. Each evaluation flies an episode or
    more, so now a TellInfo of fewer episodes than genomes asked is refused, naming both, and nothing is told."""
    g = GenerationalNE(np.zeros(40), GenerationalSettings(budget=100, pop_size=10, select_size=3))
    x = g.ask()
    for episodes in (0, 9):
        with _raises(f"TellInfo episodes={episodes} is not allowed: fewer than the 10 genomes asked"):
            g.tell(-np.ones(len(x)), TellInfo(episodes=episodes))
    assert g.state_dict()["evaluations"] == 0 and g.generation == 0
    g.tell(-np.ones(len(x)), TellInfo(episodes=10))  # the batch still asked, told as flown
    for _ in range(9):  # as many as asked: the budget of 100 episodes stops it after ten generations
        g.tell(-np.ones(len(g.ask())), TellInfo(episodes=10))
    assert g.evaluations == 100 and g.stop()


def test_a_generation_of_fewer_episodes_given_directly_is_refused() -> None:
    """T22-13 through GenerationalNE.tell's own episodes argument, which skipped TellInfo's check."""
    g = GenerationalNE(np.zeros(40), GenerationalSettings(budget=100, pop_size=10, select_size=3))
    x = g.ask()
    with _raises("episodes=0 is not allowed: fewer than the 10 genomes asked"):
        g.tell(-np.ones(len(x)), episodes=0)
    assert g.generation == 0
    g.tell(-np.ones(len(x)), episodes=10)
    assert g.evaluations == 10


@pytest.mark.parametrize("name", ["steady-state", *sorted(OPTIMISERS)])
def test_every_optimiser_refuses_fewer_episodes_than_genomes(name: str) -> None:
    """T22-13: the check is TellInfo's (at every tell), also for optimisers that do not read its episodes."""
    genome = np.zeros(6)
    opt = SteadyStateNE(genome, seed=1) if name == "steady-state" else OPTIMISERS[name].make(genome, OPTIMISERS[name].settings(), 1)
    n = len(opt.ask())
    with _raises(f"TellInfo episodes={n - 1} is not allowed: fewer than the {n} genomes asked"):
        opt.tell(-np.ones(n), TellInfo(episodes=n - 1))
    opt.tell(-np.ones(n), TellInfo(episodes=n))  # the same batch, told as flown


# --------------------------------------------------------------------------- checkpoints

GHH08 = get_task_family("ghh08")
#: The run behind the tiny_checkpoint fixture (conftest.py): steady state on GHH-08's zero MDP, 50 episodes of 20 steps.
MDP_RUN = dict(topology="slp", prototype="baseline", seed=3, n_steps=20)
#: The same run on the command line (resumed from a copy of the fixture's checkpoint).
CLI_RUN = ("evolve", "--task", "ghh08", "--mdp", "zero", "--topology", "slp", "--seed-policy", "baseline", "--seed", "3", "--episode-steps", "20")
#: A tiny generational run on the GHH-08 family, and a tiny CMA-ES one (a population optimiser keeps its own champion).
FAMILY_RUN = dict(topology="slp", prototype="baseline", seed=3, n_steps=10, settings=GenerationalSettings(pop_size=4, select_size=2))
CMA_RUN = dict(topology="slp", prototype="baseline", seed=3, n_steps=10, optimizer="cma", settings={"sigma0": 0.1, "popsize": 4})


@pytest.fixture(scope="module")
def family_checkpoints(tmp_path_factory) -> dict[str, Path]:
    """Sound checkpoints of two generations of FAMILY_RUN and of CMA_RUN (tests damage a copy)."""
    out = {}
    for name, run in (("generational", FAMILY_RUN), ("cma", CMA_RUN)):
        out[name] = tmp_path_factory.mktemp(f"{name}-checkpoint") / "run.ckpt.json"
        evolve(GHH08, budget=8, checkpoint=out[name], **run)
    return out


def _runs(which: str, tiny: Path, family: dict[str, Path]) -> tuple[Path, object, dict]:
    """The checkpoint, target and run of ``which``: steady state, generational or cma."""
    return (tiny, GHH08.zero(), MDP_RUN) if which == "steady-state" else (family[which], GHH08, FAMILY_RUN if which == "generational" else CMA_RUN)


def _resume_damaged(source: Path, tmp_path: Path, edit, target, run: dict, fragment: str) -> None:
    """The checkpoint ``source`` resumes (with its episodes as the budget: it stops at once); damaged by ``edit``, it is
    refused as a damaged checkpoint with a message holding ``fragment``."""
    state = json.loads(source.read_text())
    ckpt = tmp_path / "run.ckpt.json"
    ckpt.write_text(json.dumps(state))
    flown = state["counters"]["episodes"]
    assert evolve(target, budget=flown, checkpoint=ckpt, resume=True, **run).episodes == flown  # the sound checkpoint resumes
    state = json.loads(source.read_text())
    edit(state)
    ckpt.write_text(json.dumps(state))
    with _raises(f"is a damaged checkpoint: {fragment}"):
        evolve(target, budget=flown + 8, checkpoint=ckpt, resume=True, **run)


# --------------------------------------------------------------------------- T22-11: a history without the champion's row


def test_an_empty_history_beside_a_champion_is_refused_on_the_command_line(tiny_checkpoint: Path, tmp_path: Path, cli) -> None:
    """T22-11: a steady-state checkpoint's history of [] at generation 1 (its optimiser's champion found there) was
    resumed (exit 0) and its history.csv lacked the generation-1 row; a run records a row whenever its champion changes,
    so now the checkpoint is refused as damaged, with exit status 2 and no traceback."""
    state = json.loads(tiny_checkpoint.read_text())
    assert state["counters"]["generation"] == 1 and len(state["history"]) == 1
    champion = state["history"][0][4]
    state["history"] = []
    (tmp_path / "run.json.checkpoint.json").write_text(json.dumps(state))
    rc, _, err = cli(*CLI_RUN, "--budget", "60", "--out", str(tmp_path / "run.json"), "--resume")
    assert rc == 2 and "Traceback" not in err, err
    assert (
        f"is a damaged checkpoint: history is not the champion's: it has no rows where the run's champion (at generation 1) has return {champion!r}"
        in " ".join(err.split())
    )


@pytest.mark.parametrize("which", ["steady-state", "generational", "cma"])
def test_a_history_whose_last_row_is_not_the_champions_is_refused(which: str, tiny_checkpoint: Path, family_checkpoints, tmp_path: Path) -> None:
    """T22-11: the last history row holds the run's champion's return (the optimiser's, or for a population optimiser
    on a family its own champion table's); another one is refused, naming both."""
    source, target, run = _runs(which, tiny_checkpoint, family_checkpoints)
    state = json.loads(source.read_text())
    last, generation = state["history"][-1][4], state["counters"]["generation"]
    fragment = (
        f"history is not the champion's: its last row's champion_return is -12345.5 where the run's champion (at generation {generation}) has return {last!r}"
    )
    _resume_damaged(source, tmp_path, lambda s: s["history"][-1].__setitem__(4, -12345.5), target, run, fragment)


# --------------------------------------------------------------------------- T22-10: a champion table the run keeps none in


def test_a_champion_table_of_a_steady_state_run_is_refused_on_the_command_line(tiny_checkpoint: Path, tmp_path: Path, cli) -> None:
    """T22-10: a steady-state checkpoint's champion {genome: 42 zeros, return: 0.0} (the run writes null and '-inf':
    its champion is its optimiser's) was accepted and ignored (exit 0); now it is refused as damaged, naming the
    optimiser's champion, with exit status 2 and no traceback."""
    state = json.loads(tiny_checkpoint.read_text())
    assert state["champion"] == {"genome": None, "return": "-inf"}
    state["champion"] = {"genome": [0.0] * len(state["config"]["prototype"]), "return": 0.0}
    (tmp_path / "run.json.checkpoint.json").write_text(json.dumps(state))
    rc, _, err = cli(*CLI_RUN, "--budget", "60", "--out", str(tmp_path / "run.json"), "--resume")
    assert rc == 2 and "Traceback" not in err, err
    champion = state["history"][-1][4]
    assert (
        "is a damaged checkpoint: the champion table holds a genome and return 0.0 where a steady-state run keeps none (allowed genome null and"
        f" return '-inf'): its champion is its optimiser's, in optimizer_state (return {champion!r})" in " ".join(err.split())
    )


@pytest.mark.parametrize("which", ["steady-state", "generational"])
def test_a_champion_genome_beside_the_optimisers_is_refused(which: str, tiny_checkpoint: Path, family_checkpoints, tmp_path: Path) -> None:
    """T22-10: steady-state and generational runs keep their champion in the optimiser state; a genome in the
    checkpoint's champion table (with '-inf' as its return too) is refused."""
    source, target, run = _runs(which, tiny_checkpoint, family_checkpoints)
    size = len(json.loads(source.read_text())["config"]["prototype"])
    fragment = f"the champion table holds a genome and return '-inf' where a {which} run keeps none (allowed genome null and return '-inf')"
    _resume_damaged(source, tmp_path, lambda s: s["champion"].update(genome=[0.0] * size), target, run, fragment)


def test_a_population_optimiser_on_a_family_keeps_its_champion_in_the_table(family_checkpoints, tmp_path: Path) -> None:
    """T22-10: CMA-ES on a family keeps the best of its last generation in the champion table: its genome is there once
    a generation is flown, and its return is the last history row's (T22-11's check)."""
    source = family_checkpoints["cma"]
    state = json.loads(source.read_text())
    assert state["champion"]["genome"] is not None and state["champion"]["return"] == state["history"][-1][4]
    fragment = "the champion table holds no champion genome at generation 2: a population optimiser on a task family has one exactly once"
    _resume_damaged(source, tmp_path, lambda s: s["champion"].update(genome=None, **{"return": "-inf"}), GHH08, CMA_RUN, fragment)
    last = state["history"][-1][4]
    fragment = f"history is not the champion's: its last row's champion_return is {last!r} where the run's champion (at generation 2) has return -5.5"
    _resume_damaged(source, tmp_path, lambda s: s["champion"].update(**{"return": -5.5}), GHH08, CMA_RUN, fragment)


# --------------------------------------------------------------------------- T22-12: a prototype or stop reason not the run's


def test_an_optimiser_prototype_not_the_configs_is_refused_on_the_command_line(tiny_checkpoint: Path, tmp_path: Path, cli) -> None:
    """T22-12: optimizer_state.prototype.data[0]=9.0 beside the config's unchanged prototype was accepted (exit 0); the
    optimiser's first population was bred from the config's, so now it is refused as damaged, naming the gene."""
    state = json.loads(tiny_checkpoint.read_text())
    config = state["config"]["prototype"][0]
    state["optimizer_state"]["prototype"]["data"][0] = 9.0
    (tmp_path / "run.json.checkpoint.json").write_text(json.dumps(state))
    rc, _, err = cli(*CLI_RUN, "--budget", "60", "--out", str(tmp_path / "run.json"), "--resume")
    assert rc == 2 and "Traceback" not in err, err
    assert f"is a damaged checkpoint: optimizer_state's prototype is not the config's: gene 0 is 9.0 where the config's prototype has {config!r}" in " ".join(
        err.split()
    )


def test_a_generational_prototype_not_the_configs_is_refused(family_checkpoints, tmp_path: Path) -> None:
    """T22-12: generational NE keeps its prototype too; a gene of it changed (and then all of them) is refused."""
    source = family_checkpoints["generational"]
    state = json.loads(source.read_text())
    genes = state["config"]["prototype"]

    def shifted(s):
        s["optimizer_state"]["prototype"]["data"] = [g + 1.0 for g in genes]

    fragment = f"optimizer_state's prototype is not the config's: gene 0 is {genes[0] + 1.0!r} where the config's prototype has {genes[0]!r}"
    fragment += f" (and {len(genes) - 1} more genes differ)"
    _resume_damaged(source, tmp_path, shifted, GHH08, FAMILY_RUN, fragment)


def test_a_stop_reason_the_run_does_not_stop_by_is_refused_on_the_command_line(tiny_checkpoint: Path, tmp_path: Path, cli) -> None:
    """T22-12: stop_reason 'plateau' on a run that stopped by its budget was accepted and the run went on (exit 0). A
    resume continues a budget stop under a larger budget, but stops a plateau at once, so a stop reason that is not the
    one the checkpoint's state stops by is refused as damaged, naming what it stops by."""
    state = json.loads(tiny_checkpoint.read_text())
    assert state["stop_reason"] == "budget" and state["budget"] == 5
    state["stop_reason"] = "plateau"
    (tmp_path / "run.json.checkpoint.json").write_text(json.dumps(state))
    rc, _, err = cli(*CLI_RUN, "--budget", "60", "--out", str(tmp_path / "run.json"), "--resume")
    assert rc == 2 and "Traceback" not in err, err
    assert (
        "is a damaged checkpoint: stop_reason='plateau' is not allowed: the run it holds stops by 'budget' (its 50 episodes reached its budget of 5);"
        " allowed 'budget' or null" in " ".join(err.split())
    )


@pytest.mark.parametrize(
    ("reason", "fragment"),
    [
        ("budget", "stop_reason='budget' is not allowed: the run it holds stops by 'plateau' (its optimiser's own stop() is true); allowed 'plateau' or null"),
        ("generations", "stop_reason='generations' is not allowed: the run it holds stops by 'plateau'"),
    ],
)
def test_a_plateau_stays_a_plateau(tmp_path_factory, tmp_path: Path, reason: str, fragment: str) -> None:
    """T22-12, the choice documented in evolution.restore: a run stopped by its plateau, resumed with a larger budget,
    stops again at once by it (a budget stop goes on); a checkpoint that says it stopped by anything else is refused."""
    run = dict(MDP_RUN, n_steps=10, settings={"pop_size": 4, "elite_size": 3, "plateau_threshold": 3})
    source = tmp_path_factory.mktemp("plateau") / "run.ckpt.json"
    result = evolve(GHH08.zero(), budget=200, checkpoint=source, **run)
    assert result.stop_reason == "plateau" and json.loads(source.read_text())["stop_reason"] == "plateau"
    resumed = evolve(GHH08.zero(), budget=400, checkpoint=source, resume=True, **run)
    assert (resumed.stop_reason, resumed.episodes) == ("plateau", result.episodes)
    _resume_damaged(source, tmp_path, lambda s: s.update(stop_reason=reason), GHH08.zero(), run, fragment)


def test_a_stop_reason_of_a_run_that_went_on_is_refused(family_checkpoints, tmp_path: Path) -> None:
    """T22-12: a checkpoint written while the run went on says null; a stop reason beside counters short of its budget
    (and an optimiser that has not stopped) is refused."""
    fragment = (
        "stop_reason='budget' is not allowed: the run it holds has not stopped (its 8 episodes are short of its budget of 100 and its optimiser's"
        " stop() is false); allowed null"
    )
    _resume_damaged(family_checkpoints["generational"], tmp_path, lambda s: s.update(budget=100), GHH08, FAMILY_RUN, fragment)
