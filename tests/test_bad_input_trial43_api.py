"""Bad-input trial 43, side B (the Python API): flight data's metadata edited after making were not checked again by
their readers, which FlightData(...) and save() refuse (an edited safeguard_step was a TypeError in learn_ec_mer, an
episode_steps 'x' or crashed 'yes' learned from without a word, a crashed list of the wrong length dropped by ``+``;
T43-B06); the dict tasks.competition_rows returned was the module's cache, so an edit of it changed the competition's
MDPs for the whole process and ``.clear()`` had the family refused (T43-B07); edits of the registry tasks.TASK_FAMILIES
went through (a shipped name holding another family, an entry that is no class, an alias key), and the refusal of an
unknown name listed a deleted entry (T43-B10); a second evolve on a checkpoint being written warned that it replaced the
checkpoint, then was refused as its second writer (T43-B16)."""

from __future__ import annotations

import copy
import json
import warnings

import pytest

import neurohover as nh
import neurohover.tasks as T
from neurohover.errors import CheckpointReplaced, NeurohoverError
from neurohover.models import Transitions, ec_mer_policy, learn_ec_meno, learn_ec_mer, learn_lr, lr_determined
from neurohover.tasks import base

MDP = nh.get_task_family("ghh08").training_mdps()[0]


# --------------------------------------------------------------------------- T43-B06: flight data's metadata edited


@pytest.fixture(scope="module")
def flown() -> nh.FlightData:
    """Three 30-step episodes of the baseline, recorded as evaluate() records them."""
    return nh.evaluate(nh.baseline_policy(), MDP, episodes=3, n_steps=30, record=True).flight_data


def _edited(flown: nh.FlightData, **edit: object) -> nh.FlightData:
    data = nh.FlightData(flown.observations, flown.actions, copy.deepcopy(flown.metadata))
    data.metadata.update(edit)  # after making: FlightData(...) refuses each of these
    return data


READERS = {
    "learn_lr": learn_lr,
    "lr_determined": lr_determined,
    "learn_ec_mer": lambda data: learn_ec_mer(data, nh.baseline_policy(), budget=10),
    "learn_ec_meno": lambda data: learn_ec_meno(data, budget=10),
    "Transitions": Transitions,
    "ec_mer_policy": lambda data: ec_mer_policy(None, data, "f.npz"),
}
EDITS = [
    ({"safeguard_step": ["a", None, -1]}, r"its metadata safeguard_step=\['a', None, -1\] is not allowed"),
    ({"episode_steps": "x", "crashed": "yes"}, r"its metadata episode_steps='x' is not allowed"),
    ({"crashed": "yes"}, r"its metadata crashed='yes' is not allowed"),
    ({"episode_steps": 5}, r"more than its metadata's episode_steps=5"),
    ({"episode_steps": 10}, r"more than its metadata's episode_steps=10"),
]


@pytest.mark.parametrize("edit, message", EDITS, ids=[next(iter(e)) + str(i) for i, (e, _) in enumerate(EDITS)])
@pytest.mark.parametrize("reader", sorted(READERS))
def test_readers_check_edited_flight_metadata_again(flown, reader, edit, message):
    with pytest.raises(NeurohoverError, match=message):
        nh.FlightData(flown.observations, flown.actions, {**flown.metadata, **edit})  # the constructor's own refusal
    with pytest.raises(NeurohoverError, match=message):
        READERS[reader](_edited(flown, **edit))


def test_flight_metadata_as_recorded_still_read(flown):
    assert Transitions(flown).n == 90 and lr_determined(flown)
    assert learn_ec_mer(flown, nh.baseline_policy(), budget=10).method == "ec-mer"
    assert (flown + flown).metadata["crashed"] == flown.metadata["crashed"] * 2


def test_adding_flight_data_checks_each_half_again(flown):
    """An edited crashed list of the wrong length was dropped from the sum without a word."""
    short = _edited(flown, crashed=[False])
    with pytest.raises(NeurohoverError, match=r"^flight data \(the first of \+\): its metadata crashed=\[False\] is not allowed"):
        short + flown
    with pytest.raises(NeurohoverError, match=r"^flight data \(the second of \+\): its metadata crashed=\[False\] is not allowed"):
        flown + short


# --------------------------------------------------------------------------- T43-B07: the competition rows' cache


@pytest.fixture
def private_cache(monkeypatch):
    """The competition rows' cache and the fixed sets as a private copy, so that a failing test leaves the process's alone."""
    base.competition_families()  # loaded
    monkeypatch.setattr(base, "_COMPETITION", copy.deepcopy(base._COMPETITION))
    monkeypatch.setattr(base, "_FIXED_SETS", {})


def test_editing_the_competition_rows_changes_no_mdp(private_cache):
    shipped = json.loads(base.COMPETITION_MDPS_FILE.read_text(encoding="utf-8"))["ghh08"]
    rows = T.competition_rows("ghh08")
    assert rows == shipped
    rows["train"][0][0] = 0.5
    rows["test"].clear()
    assert T.competition_rows("ghh08") == shipped
    mdp = nh.GHH08().mdp("train:0")
    assert mdp.label == "ghh08/train:0" and mdp == MDP
    T.competition_rows("ghh08").clear()
    assert T.competition_rows("ghh08") == shipped and len(nh.GHH08().test_mdps()) == 100


# --------------------------------------------------------------------------- T43-B10: the TASK_FAMILIES registry edited


@pytest.mark.parametrize(
    "key, entry, why",
    [
        ("ghh08", T.GHH09, r"'ghh08' is a shipped task family's name and holds its shipped class"),
        ("ghh09", None, r"register a TaskFamily subclass under its name"),
        ("zz", 5, r"register a TaskFamily subclass under its name"),
        ("zz", T.GHH08, r"its class's name 'ghh08' is not its key"),
        ("zz", T.GHH08(), r"register a TaskFamily subclass under its name"),
    ],
)
def test_an_edited_task_family_entry_is_refused_by_name(monkeypatch, key, entry, why):
    monkeypatch.setitem(T.TASK_FAMILIES, key, entry)
    for use in (lambda: nh.get_task_family(key), lambda: T.family_for(key, 0.3), lambda: T.family_from_dict({"family": key})):
        with pytest.raises(NeurohoverError, match=rf"^TASK_FAMILIES\['{key}'\] = .* is not allowed: {why}"):
            use()
    assert nh.get_task_family("fghh", 0.3).name == "fghh"  # the other entries still serve


@pytest.fixture
def registry_in_order():
    """The registry put back in its order afterwards (monkeypatch puts a deleted entry back at the end, and the
    refusals of other tests in this worker list the names in the registry's order)."""
    saved = dict(T.TASK_FAMILIES)
    yield
    T.TASK_FAMILIES.clear()
    T.TASK_FAMILIES.update(saved)


def test_an_unknown_task_lists_the_registry_as_it_is(registry_in_order, monkeypatch):  # put back after monkeypatch
    monkeypatch.delitem(T.TASK_FAMILIES, "ghh08")
    monkeypatch.setitem(T.TASK_FAMILIES, "zz", 5)  # a bad entry is no name to offer
    with pytest.raises(NeurohoverError, match=r"^unknown task 'ghh08': allowed ghh09, fghh$"):
        nh.get_task_family("ghh08")
    monkeypatch.setitem(T.TASK_FAMILIES, "ghh08", T.GHH08)  # put back as shipped: taken
    assert nh.get_task_family("ghh08").mdp("train:0") == MDP


# --------------------------------------------------------------------------- T43-B16: a second run on a checkpoint


def test_a_second_run_on_a_checkpoint_is_refused_without_saying_it_replaces_it(tmp_path):
    from neurohover.evolution import evolve

    path = tmp_path / "ck.json"
    kw = {"budget": 20, "n_steps": 10, "settings": {"pop_size": 4, "elite_size": 3}, "checkpoint": path}
    evolve(MDP, **kw)  # a checkpoint there: the next run replaces it, and says so
    refusals: list[str] = []

    def progress(info):
        if not refusals:
            try:
                evolve(MDP, **kw)  # the same checkpoint, while the first run writes it
            except NeurohoverError as err:
                refusals.append(str(err))

    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        evolve(MDP, progress=progress, **kw)
    replaced = [w for w in said if issubclass(w.category, CheckpointReplaced)]
    assert len(refusals) == 1 and "is being written by another run" in refusals[0], refusals
    assert len(replaced) == 1 and replaced[0].filename == __file__, [str(w.message) for w in said]  # the outer run's alone
