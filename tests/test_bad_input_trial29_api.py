"""Trial 29b (bad input, Python API): T29-B03 (run_test flew a plain MDP without its family's sensor or drift),
T29-B08 (format_parameter_table on a ParamRow of None or text), T29-B09 (strip_timing on a result holding itself),
T29-B10 (validation_return's refusal named evolve; check_vector's "got 1" for an object or an iterator), and the
report's unnumbered case: parameter_table's substeps/dt overriding a true MDP's own integration."""

from __future__ import annotations

import re

import numpy as np
import pytest

import neurohover as nh
import neurohover.models as M
from neurohover.agents import run_test
from neurohover.agents.registry import make_agent
from neurohover.errors import NeurohoverError
from neurohover.evolution import validation_return
from neurohover.experiments import strip_timing
from neurohover.models.model import DEFAULT_NOISE_STD, DEFAULT_PARAMS

G8 = nh.get_task_family("ghh08")
SENSOR = nh.Sensor(velocity=0.5, delay=2)
DRIFT = nh.Drift(walk=0.2)


def _returns(family: nh.TaskFamily, mdp: nh.MDP) -> list[float]:
    return run_test(make_agent("baseline", family), family, mdp, episodes=2, n_steps=30).returns.tolist()


def test_run_test_flies_a_plain_mdp_through_its_familys_sensor_and_drift() -> None:
    """T29-B03: a family's sensor or drift was ignored for an MDP that had none (the plain run's returns), while the
    environments fly an explicit exact MDP through their sensor (envs.arguments.sensed_mdp)."""
    plain = G8.mdp("test:0")
    g8s, g8d = G8.with_sensor(SENSOR), G8.with_drift(DRIFT)
    assert _returns(g8s, plain) == _returns(g8s, g8s.mdp("test:0")) != _returns(G8, plain)
    assert _returns(g8d, plain) == _returns(g8d, g8d.mdp("test:0")) != _returns(G8, plain)
    r = run_test(make_agent("baseline", g8s), g8s, plain, episodes=1, n_steps=10)
    assert r.mdp == plain.with_sensor(SENSOR)  # the MDP flown
    # an MDP's own sensor still flies in a family of exact sensors, as in the environments
    assert _returns(G8, g8s.mdp("test:0")) == _returns(g8s, plain)


def test_run_test_refuses_an_mdp_sensor_or_drift_other_than_its_familys() -> None:
    """T29-B03: two different sensors (or drifts) are refused by name, as the environments refuse them."""
    other = G8.with_sensor(nh.Sensor(velocity=0.1))
    with pytest.raises(
        NeurohoverError, match=re.escape("mdp 'ghh08/test:0' carries its own sensor Sensor(velocity=0.5, delay=2), not the run's family's Sensor(velocity=0.1)")
    ):
        _returns(other, G8.with_sensor(SENSOR).mdp("test:0"))
    with pytest.raises(NeurohoverError, match=r"carries its own drift Drift\(walk=0\.2.*not the run's family's Drift\(walk=0\.1"):
        _returns(G8.with_drift(nh.Drift(walk=0.1)), G8.with_drift(DRIFT).mdp("test:0"))


def test_an_agent_made_for_the_plain_family_is_the_same_in_a_sensor_run() -> None:
    """T29-B03's second case is no bug: made_for records (name, sigma), and an agent's policies and choices do not
    depend on the family's sensor (the sensor run's MDP carries it), so the plain family's agent flies alike."""
    g8s = G8.with_sensor(SENSOR)
    mdp = g8s.mdp("test:0")
    ours = run_test(make_agent("baseline", G8), g8s, mdp, episodes=2, n_steps=30).returns
    assert ours.tolist() == _returns(g8s, mdp)


@pytest.mark.parametrize(
    "row, field, value",
    [
        (M.ParamRow("C_u", 1.0, None, None), "true", "None"),  # type: ignore[arg-type]
        (M.ParamRow("C_u", None, 2.0, 0.1), "learned", "None"),  # type: ignore[arg-type]
        (M.ParamRow("x", "a", "b", "c"), "learned", "'a'"),  # type: ignore[arg-type]
        (M.ParamRow(3, 1.0, 1.0, 0.0), "name", "3"),  # type: ignore[arg-type]
    ],
)
def test_format_parameter_table_refuses_a_row_of_other_fields(row: M.ParamRow, field: str, value: str) -> None:
    """T29-B08: was a TypeError or ValueError from the number formatting."""
    with pytest.raises(NeurohoverError, match=re.escape(f"its {field} {value} is not allowed: a ParamRow holds a name")):
        M.format_parameter_table([row])
    # the table's own non-finite values still format
    assert "inf%" in M.format_parameter_table([M.ParamRow("C_u", 1.0, 0.0, float("inf")), M.ParamRow("std_u", float("nan"), 1.0, 0.0)])


def test_strip_timing_refuses_a_result_holding_itself() -> None:
    """T29-B09: was a RecursionError."""
    d: dict = {}
    d["self"] = d
    with pytest.raises(NeurohoverError, match="it holds itself"):
        strip_timing(d)
    deep: list = []
    inner = deep
    for _ in range(5000):
        inner.append([])
        inner = inner[0]
    with pytest.raises(NeurohoverError, match="nested too deep"):
        strip_timing(deep)
    shared = [1]  # a value shared, not a cycle
    assert strip_timing({"a": shared, "b": shared, "timing": 3, "c": [{"timing": 1, "z": 2}]}) == {"a": [1], "b": [1], "c": [{"z": 2}]}


def test_validation_return_names_itself() -> None:
    """T29-B10: its refusal named evolve."""
    with pytest.raises(NeurohoverError, match=r"^validation_return needs an MDP, a learned model or a task family as target, got str$"):
        validation_return(nh.baseline_policy(), "ghh08/train:0", episodes=2, n_steps=20)


def test_vector_checks_name_an_object_or_an_iterator() -> None:
    """T29-B10: a LearnedModel or an iterator of 11 numbers was "got 1"; iterators are refused, as MDP(params=...) and
    a family's make() refuse them."""
    model = M.LearnedModel(DEFAULT_PARAMS, DEFAULT_NOISE_STD, "lr")
    with pytest.raises(NeurohoverError, match=re.escape("model parameters must be 11 numbers, got one LearnedModel object (give its .params): LearnedModel(")):
        M.equivalent_params(model)
    with pytest.raises(NeurohoverError, match=re.escape("parameters must be 11 numbers, got an iterator <range_iterator")):
        M.one_substep_params(iter(range(11)))
    with pytest.raises(NeurohoverError, match=r"x must be 2 numbers, got None$"):
        M.check_vector(None, 2, "x")
    with pytest.raises(NeurohoverError, match=re.escape("x must be 2 numbers, got an iterator")):
        M.check_vector((v for v in (1.0, 2.0)), 2, "x")
    with pytest.raises(NeurohoverError, match=re.escape("x must be 2 numbers, got 1: 5.0")):  # a number: the count
        M.check_vector(5.0, 2, "x")
    assert M.check_vector(np.array([1.0, 2.0]), 2, "x") == (1.0, 2.0)


def test_parameter_table_refuses_another_integration_beside_an_mdp() -> None:
    """Trial 29b (unnumbered): substeps=1, dt=0.1 beside an MDP of 10 x 0.01 s changed the table without a word."""
    model = M.LearnedModel(DEFAULT_PARAMS, DEFAULT_NOISE_STD, "lr")
    mdp = G8.mdp("train:1")
    with pytest.raises(NeurohoverError, match=re.escape("substeps=1, dt=0.1 is not allowed beside the MDP 'ghh08/train:1', which integrates 10 x 0.01 s")):
        M.parameter_table(model, mdp, substeps=1, dt=0.1)
    with pytest.raises(NeurohoverError, match=r"^dt=0\.02 is not allowed beside"):
        M.parameter_table(model, mdp, dt=0.02)
    assert M.format_parameter_table(M.parameter_table(model, mdp, substeps=10, dt=0.01)) == M.format_parameter_table(M.parameter_table(model, mdp))  # its own
    assert len(M.parameter_table(model, list(mdp.params), substeps=1, dt=0.1)) == 11  # 11 numbers: any integration
