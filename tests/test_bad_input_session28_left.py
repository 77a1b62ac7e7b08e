"""Items left open by earlier sessions' trials of issue 37, fixed in the twenty-eighth session: an optimiser's
state_dict() that holds itself was followed without end (a RecursionError) by the check that names what strict JSON
cannot write. The smallest sensor std, noise level and drift walk (2**-52 and a multiple of it) were shown rounded down
(2.22e-16 for 2.2204e-16), a number the same range refused: the bound shown is rounded up now, and is allowed. Flight
data + flight data of no episodes (``sum(recordings, FlightData((), ()))``) dropped the per-episode entries (crashed,
returns) of the other: a recording of no episodes adds none and contradicts no entry. Masked residuals given to
noise_from_residuals or authors_noise lost their mask: the hidden residuals counted in the noise; refused now. A policy
record's mdp beside a target of its own label (what evolve --wind writes, ``ghh08/wind=[1.0, 2.0]``) could be any word
('banana'), where beside a task alone it must be what --wind or --params wrote: one rule for both now."""

from __future__ import annotations

import re

import numpy as np
import pytest

import neurohover as nh
from neurohover import NeurohoverError
from neurohover.errors import lowest_allowed
from neurohover.evolution.answers import check_state_json
from neurohover.models import Transitions, authors_noise, noise_from_residuals


def _holding_itself(where: str) -> dict:
    state: dict = {"mean": [0.0, 1.0], "step": 3}
    if where == "table":
        state["again"] = state
    else:
        inner: list = [1.0]
        inner.append(inner)
        state["history"] = [inner]
    return state


@pytest.mark.parametrize(("where", "entry"), [("table", "['again']"), ("list", "['history'][0][1]")])
def test_a_state_that_holds_itself_is_named_not_followed(where: str, entry: str) -> None:
    with pytest.raises(NeurohoverError, match=r"entry " + entry.replace("[", r"\[").replace("]", r"\]") + r" \(a list or table that holds itself"):
        check_state_json(_holding_itself(where), "mine")


def test_a_state_that_holds_one_list_twice_is_written() -> None:
    shared = [1.0, 2.0]
    check_state_json({"a": shared, "b": shared, "c": [shared, shared]}, "mine")  # the same list twice is no cycle


def _refusal(make) -> str:
    with pytest.raises(NeurohoverError) as err:
        make()
    return str(err.value)


@pytest.mark.parametrize(
    ("too_small", "at"),
    [
        (lambda: nh.Sensor(velocity=1e-17), lambda x: nh.Sensor(velocity=x)),
        (lambda: nh.Sensor.at_level(1e-17), nh.Sensor.at_level),
        (lambda: nh.Drift(walk=1e-17), lambda x: nh.Drift(walk=x)),
    ],
)
def test_the_smallest_value_a_refusal_shows_is_allowed(too_small, at) -> None:
    shown = re.search(r"or a (?:number|std) in ([0-9.e+-]+)\.\.", _refusal(too_small))
    assert shown is not None
    at(float(shown.group(1)))  # the number the message allows flies


@pytest.mark.parametrize("bound", [2.0**-52, 100 * 2.0**-52, 1.0, 1e-3, 9.99951e-5, 1.234e-7, 123456.0])
def test_a_lower_bound_is_shown_at_or_above_itself_in_three_digits(bound: float) -> None:
    shown = lowest_allowed(bound)
    assert float(shown) >= bound and float(shown) <= bound * 1.01 and len(shown.partition("e")[0].replace(".", "").lstrip("0")) <= 3, shown


def test_adding_flight_data_of_no_episodes_keeps_the_others_entries() -> None:
    fam = nh.get_task_family("ghh08")
    one = nh.evaluate(nh.baseline_policy(), fam.zero(), n_steps=10, record=True, episodes=2).flight_data
    two = nh.evaluate(nh.baseline_policy(), fam.zero(), n_steps=10, record=True, episodes=1, seed=5).flight_data
    assert "crashed" in one.metadata
    empty = nh.FlightData((), ())
    assert empty + one == one and one + empty == one and empty + empty == empty
    total = sum([one, two], nh.FlightData((), ()))
    assert total == one + two and total.metadata["crashed"] == one.metadata["crashed"] + two.metadata["crashed"]


@pytest.mark.parametrize("noise", [noise_from_residuals, authors_noise])
def test_masked_residuals_are_refused_not_counted(noise) -> None:
    flown = nh.evaluate(nh.baseline_policy(), nh.get_task_family("ghh08").mdp("train:0"), record=True, n_steps=50).flight_data
    tr = Transitions(flown)
    values = np.zeros((tr.n, 6))
    values[3, 2] = 1e3  # hidden by the mask: it must not count
    with pytest.raises(NeurohoverError, match=r"a masked array: give its values, e.g. .filled\(\)"):
        noise(tr, np.ma.masked_array(values, mask=values != 0))
    noise(tr, values)  # the same values unmasked are taken


@pytest.mark.parametrize("mdp", ["banana", "", "train:0", "G"])
def test_a_records_mdp_beside_a_target_of_its_own_label_is_what_evolve_wrote(tmp_path, mdp: str) -> None:
    target = "ghh08/wind=[1.0, 2.0]"  # what `evolve --task ghh08 --wind 1,2` writes, beside mdp 'wind=1,2'
    with pytest.raises(NeurohoverError, match=f"its mdp {re.escape(repr(mdp))} is not allowed beside its target"):
        nh.save_policy(nh.baseline_policy(), tmp_path / "p.json", task="ghh08", mdp=mdp, target=target)
    nh.save_policy(nh.baseline_policy(), tmp_path / "p.json", task="ghh08", mdp="wind=1,2", target=target)
    assert nh.load_policy(tmp_path / "p.json").metadata["mdp"] == "wind=1,2"
