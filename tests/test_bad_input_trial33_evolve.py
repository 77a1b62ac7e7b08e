"""The thirty-third bad-input trial's findings in evolve, its checkpoints and the agents' settings (T33-B02, T33-B05,
T33-B06, T33-B07, T33-B08, T33-B12, T33-B15, T33-B16): settings with keys that are not text were Python's TypeError;
a checkpoint edited (resampling, a population gene past Policy's cap, n_steps, champion null) was resumed or refused
with Python's text; a budget given twice dropped one silently; agent settings refused NumPy integers; 0-d arrays were
"out of range"."""

from __future__ import annotations

import dataclasses
import json
import re

import numpy as np
import pytest

from neurohover.agents.continual import ContinualSettings
from neurohover.agents.fghh_code import CodeAgentSettings
from neurohover.agents.model_based import IncrementalSettings, ModelEvolution
from neurohover.agents.registry import AgentOptions, make_agent
from neurohover.agents.risk import RiskSettings
from neurohover.errors import NeurohoverError
from neurohover.evolution.evolve import evolve
from neurohover.evolution.steady_state import SteadyStateSettings
from neurohover.tasks import get_task_family

ZERO = get_task_family("ghh08").zero()
#: The run behind the tiny_checkpoint fixture (conftest.py).
MDP_RUN = dict(topology="slp", prototype="baseline", seed=3, n_steps=20)


@pytest.mark.parametrize("key", [b"pop_size", 1, (1, 2)])
def test_evolve_settings_with_a_key_that_is_not_text_are_refused_naming_it(key) -> None:
    """T33-B02: settings={1: 10} was "TypeError: sequence item 0: expected str instance, int found"."""
    with pytest.raises(NeurohoverError, match=re.escape(f"unknown steady-state setting(s) {key!r}: allowed ")):
        evolve(ZERO, budget=5, settings={key: 10}, **MDP_RUN)
    with pytest.raises(NeurohoverError, match=re.escape(f"unknown cma setting(s) {key!r}")):  # keys of mixed types sort
        evolve(ZERO, budget=5, optimizer="cma", settings={key: 10, "zz": 1}, **MDP_RUN)


def test_hybrid_agent_settings_with_a_key_that_is_not_text_are_refused_naming_it() -> None:
    """T33-B02: make_agent('hybrid', ..) with settings {1: 10} was a TypeError (continual's was clean)."""
    with pytest.raises(NeurohoverError, match=re.escape("unknown hybrid setting(s) 1, b'x': allowed box, model_from")):
        make_agent("hybrid", "ghh08", options=AgentOptions(settings={1: 10, b"x": 2}))


def test_a_budget_given_twice_and_different_is_refused() -> None:
    """T33-B08: evolve(budget=100, settings=SteadyStateSettings(budget=30)) flew 100 episodes without a word."""
    settings = SteadyStateSettings(pop_size=4, elite_size=3, budget=6)
    with pytest.raises(NeurohoverError, match=re.escape("budget=8 is not allowed beside settings.budget=6: give the budget once")):
        evolve(ZERO, budget=8, settings=settings, **MDP_RUN)
    assert evolve(ZERO, budget=6, settings=settings, **MDP_RUN).episodes == 6  # both alike: taken
    assert evolve(ZERO, settings=settings, **MDP_RUN).episodes == 6  # the settings' own: as before


@pytest.mark.parametrize(
    "cls, name",
    [
        (ContinualSettings, "window"),
        (ContinualSettings, "patience"),
        (ContinualSettings, "max_learning_episodes"),
        (ContinualSettings, "cooldown"),
        (ContinualSettings, "safeguard_after"),
        (RiskSettings, "trials"),
        (CodeAgentSettings, "model_budget"),
        (CodeAgentSettings, "evolutions"),
        (IncrementalSettings, "max_learning_episodes"),
        (ModelEvolution, "authors_generations"),
        (ModelEvolution, "budget"),
        (ModelEvolution, "predict_episodes"),
        (ModelEvolution, "model_substeps"),
    ],
)
def test_agent_settings_take_numpy_integers_and_store_python_ints(cls, name: str) -> None:
    """T33-B12: np.int64(10) was "not allowed: allowed an integer"; it is taken and stored as a Python int (JSON)."""
    given = getattr(cls(), name)
    settings = cls(**{name: np.int64(given or 1)})
    assert type(getattr(settings, name)) is int and getattr(settings, name) == (given or 1)
    json.dumps(dataclasses.asdict(settings), default=str)


def test_agent_settings_from_make_agent_take_numpy_integers() -> None:
    """T33-B12 as the trial met it: through make_agent's settings dicts."""
    make_agent("continual", "ghh08", options=AgentOptions(settings={"cooldown": np.int64(10)}))
    make_agent("incremental", "ghh08", options=AgentOptions(settings={"max_learning_episodes": np.int64(5)}))


@pytest.mark.parametrize("name, value", [("budget", "x"), ("budget", 0), ("predict_episodes", 1.5), ("n_steps", 0), ("n_steps", 10**8)])
def test_model_evolution_checks_its_counts(name: str, value) -> None:
    """Noticed with T33-B12: ModelEvolution's budget, predict_episodes and n_steps were not checked at all ('x' taken)."""
    with pytest.raises(NeurohoverError, match=re.escape(f"{name}={value!r} is ")):
        ModelEvolution(**{name: value})


@pytest.mark.parametrize("value", [np.array(0.1), "0.1", None, np.timedelta64(1)])
def test_a_sensor_dropout_of_another_type_is_not_a_number(value) -> None:
    """T33-B16: Sensor(dropout=np.array(0.1)) was "out of range" (0.1 is in range): refused for its type, it is "not a number"."""
    from neurohover.tasks.sensor import Sensor

    with pytest.raises(NeurohoverError, match=re.escape("is not a number: allowed a probability 0 <= dropout < 1")):
        Sensor(dropout=value)
    with pytest.raises(NeurohoverError, match=re.escape("sensor dropout=1.5 is out of range")):
        Sensor(dropout=1.5)


def test_progress_every_s_of_another_type_is_not_a_number() -> None:
    """T33-B16: evolve(progress_every_s=np.array(0.1)) was "out of range"."""
    with pytest.raises(NeurohoverError, match=re.escape("progress_every_s=array(0.1) is not a number: allowed a finite number of seconds")):
        evolve(ZERO, budget=5, progress=print, progress_every_s=np.array(0.1), **MDP_RUN)
    with pytest.raises(NeurohoverError, match=re.escape("progress_every_s=-1 is out of range")):
        evolve(ZERO, budget=5, progress=print, progress_every_s=-1, **MDP_RUN)


@pytest.mark.parametrize("entry", ["champion", "counters", "config"])
@pytest.mark.parametrize("value", [None, 5, []])
def test_a_checkpoint_table_that_is_no_table_is_refused_naming_it(tiny_checkpoint, tmp_path, entry: str, value) -> None:
    """T33-B15: "champion": null was "a damaged checkpoint: TypeError: 'NoneType' object is not subscriptable" (counters and
    config alike); now the entry is named with what is allowed."""
    state = json.loads(tiny_checkpoint.read_text())
    state[entry] = value
    ckpt = tmp_path / "run.ckpt.json"
    ckpt.write_text(json.dumps(state))
    with pytest.raises(NeurohoverError, match=re.escape(f"is a damaged checkpoint: {entry}={value!r} is not allowed: allowed a table of ")) as err:
        evolve(ZERO, budget=60, checkpoint=ckpt, resume=True, **MDP_RUN)
    assert "Error:" not in str(err.value)


@pytest.mark.parametrize("gene", [1e300, -1.5e120])
def test_a_checkpoint_population_gene_past_a_policys_cap_is_refused(tiny_checkpoint, tmp_path, gene: float) -> None:
    """T33-B06: a population gene of 1e300 was resumed and kept, though a Policy caps genes at 1e120 (T30-B01)."""
    state = json.loads(tiny_checkpoint.read_text())
    state["optimizer_state"]["population"]["data"][1] = gene
    ckpt = tmp_path / "run.ckpt.json"
    ckpt.write_text(json.dumps(state))
    fragment = f"population holds a gene that is out of range: data entry 1 (genome 0, gene 1) is {gene!r}; allowed numbers in [-1e+120, 1e+120]"
    with pytest.raises(NeurohoverError, match=re.escape(fragment)):
        evolve(ZERO, budget=60, checkpoint=ckpt, resume=True, **MDP_RUN)
    state["optimizer_state"]["population"]["data"][1] = 1e120  # at the cap: taken
    ckpt.write_text(json.dumps(state))
    assert evolve(ZERO, budget=55, checkpoint=ckpt, resume=True, **MDP_RUN).episodes == 55


def _edited(tiny_checkpoint, tmp_path, edit):
    state = json.loads(tiny_checkpoint.read_text())
    edit(state)
    ckpt = tmp_path / "run.ckpt.json"
    ckpt.write_text(json.dumps(state))
    return ckpt


def test_a_checkpoints_resampling_edited_against_its_counters_is_refused(tiny_checkpoint, tmp_path) -> None:
    """T33-B05: resampling fixed:1 edited to fixed:2 (and resumed with it) beside 50 episodes of 50 evaluations was
    resumed, a run half fixed:1; the command line refused it only after the whole run, naming the policy file."""
    ckpt = _edited(tiny_checkpoint, tmp_path, lambda s: s["config"].update(resampling="fixed:2"))
    fragment = (
        "counter 'episodes' is 50, not allowed beside its 50 evaluations under the config's resampling fixed:2: each evaluation flies 2 episodes, 100 in all"
    )
    with pytest.raises(NeurohoverError, match=re.escape(fragment)):
        evolve(ZERO, budget=200, resampling="fixed:2", checkpoint=ckpt, resume=True, **MDP_RUN)


def test_a_checkpoints_resampling_edited_is_refused_before_the_command_line_flies(tiny_checkpoint, tmp_path, cli) -> None:
    """T33-B05 on the command line: refused at once, naming the checkpoint, nothing flown or written."""
    state = json.loads(tiny_checkpoint.read_text())
    state["config"]["resampling"] = "fixed:2"
    (tmp_path / "run.json.checkpoint.json").write_text(json.dumps(state))
    out = tmp_path / "run.json"
    run = ("evolve", "--task", "ghh08", "--mdp", "zero", "--topology", "slp", "--seed-policy", "baseline", "--seed", "3", "--episode-steps", "20")
    rc, _, err = cli(*run, "--resampling", "fixed:2", "--budget", "200", "--out", str(out), "--resume")
    assert rc == 2 and not out.exists() and "Traceback" not in err, err
    text = " ".join(err.split())
    assert "run.json.checkpoint.json' is a damaged checkpoint: counter 'episodes' is 50" in text and "policy file" not in text


def test_a_checkpoints_n_steps_edited_against_its_steps_is_refused(tiny_checkpoint, tmp_path) -> None:
    """T33-B07: n_steps 20 edited to 6000 (and resumed with it) was taken, though its episodes flew a few hundred steps in
    all and their returns say few of them crashed (a crash is charged the worst step for each step left)."""
    ckpt = _edited(tiny_checkpoint, tmp_path, lambda s: s["config"].update(n_steps=6000))
    fragment = r"counter 'steps' is [\d,]+, fewer than the [\d,]+ that the population's returns in optimizer_state.fitness need"
    with pytest.raises(NeurohoverError, match=fragment):
        evolve(ZERO, budget=60, checkpoint=ckpt, resume=True, **{**MDP_RUN, "n_steps": 6000})
