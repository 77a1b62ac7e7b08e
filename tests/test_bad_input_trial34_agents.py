"""Bad-input trial 34 (the Python API), the agents, the results store and the kernel's threading layer: T34-B06 (a final
Choice that asks to record: the flight data were never delivered), T34-B07 (a Choice's dangerous rule without a
fallback was ignored), T34-B14 (a Store dropped without close() kept its writer lock, and its own process was then told
that "another run" held it) and T34-B13 (multiprocessing's fork after a flight hung in libgomp)."""

from __future__ import annotations

import pytest

import neurohover as nh
from neurohover.agents import Choice


def test_final_choice_that_records_is_refused():
    """T34-B06: a final choice flies the rest of the run in one batch, without update; its recording was never seen."""
    with pytest.raises(nh.NeurohoverError, match=r"final=True with record=True is not allowed: .*update never sees"):
        Choice(nh.baseline_policy(), "baseline", final=True, record=True)
    assert Choice(nh.baseline_policy(), "baseline", final=True).final  # each alone is taken
    assert Choice(nh.baseline_policy(), "baseline", record=True).record


def test_dangerous_rule_without_fallback_is_refused():
    """T34-B07: without a fallback the safeguard acts on nothing (as evaluate_jobs refuses its limits alone, T28-B16)."""
    b = nh.baseline_policy()
    with pytest.raises(nh.NeurohoverError, match=r"Choice dangerous=DangerousState\(.* is not allowed without a fallback"):
        Choice(b, "x", dangerous=nh.DangerousState(box=0.001, tilt=0.001))
    assert Choice(b, "x", dangerous=nh.DangerousState()).fallback is None  # the default rule, named or not, is taken
    assert Choice(b, "x", fallback=b, dangerous=nh.DangerousState(box=0.001, tilt=0.001)).fallback is b


def test_continual_agent_without_safeguard_flies():
    """T34-B07: the continual agent with its safeguard off (or flying the generic) chose its own rule without a fallback."""
    from neurohover.agents.continual import ContinualAgent, ContinualSettings

    agent = ContinualAgent(nh.baseline_policy(), settings=ContinualSettings(safeguard_after=5))  # flying the generic: no fallback
    assert agent.choose(0).fallback is None
