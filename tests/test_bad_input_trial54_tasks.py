"""Bad-input trial 54, side B (user-written task families): a family whose sample_params(rng, n) drew one value for a
whole batch was taken, so batched draws gave MDPs single draws never give (T54-B01); a family name with '/', ':' or
spaces was registered, and 'he/avy/seeded-train:1' read as family 'he' (T54-B08); has_sigma True without a sigma field
was a TypeError at get_task_family(name, 0.3) (T54-B10); has_sigma and generic_over_distribution given as text were read
by truthiness (T54-B11); a make() that ignores its params, or a wrong row_slice, was a RuntimeError (T54-B12); a make()
that ignores the label it is given labelled every fixed MDP alike (T54-B13)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pytest

import neurohover.tasks.base as base
from neurohover.errors import NeurohoverError
from neurohover.sim.constants import DEFAULT_PARAMS, ROW_PARAMS
from neurohover.tasks import MDP, TASK_FAMILIES, TaskFamily, finite_vector, get_task_family, task_names

_NAMES = ("C_u", "C_v", "D_v", "C_w", "D_w", "C_p", "D_p", "C_q", "D_q", "C_r", "D_r")


def _draws(self, rng, n):
    """A heavier helicopter's draws: D_w scaled by a factor in [0.5, 1], one per MDP."""
    out = np.repeat(DEFAULT_PARAMS[None, :], n, axis=0)
    out[:, 4] *= rng.uniform(0.5, 1.0, n)
    return out


def _family(name: str, *, sample=_draws, make=None, body=None, sigma: bool = False) -> type[TaskFamily]:
    """A user's family of the 11 GHH parameters (README's Extending neurohover), registered under ``name``."""

    def made(self, params, label=""):
        return MDP(name, params=tuple(finite_vector(params, 11, "p").tolist()), label=label)

    attributes = {"__module__": __name__, "name": name, "n_params": 11, "param_names": _NAMES, "row_slice": ROW_PARAMS, "set_code": 154}
    attributes |= {"make": make or made, "zero": lambda self: MDP(name, label=f"{name}/zero"), "sample_params": sample, **(body or {})}
    if sigma:
        attributes["__annotations__"] = {"sigma": float}
        attributes["sigma"] = field(default=0.3)
    return dataclass(frozen=True)(type("Heavy54", (TaskFamily,), attributes))


@pytest.fixture
def register(monkeypatch):
    """Register a family for this test only, with private fixed sets and row templates."""
    monkeypatch.setattr(base, "_FIXED_SETS", {})
    monkeypatch.setattr(base, "_ROW_LAYOUTS", {})

    def put(name: str, **kwargs) -> type[TaskFamily]:
        cls = _family(name, **kwargs)
        monkeypatch.setitem(TASK_FAMILIES, name, cls)
        return cls

    return put


# --------------------------------------------------------------------------- T54-B01: batches drawn as single draws


def _one_draw_per_batch(self, rng, n):
    out = np.repeat(DEFAULT_PARAMS[None, :], n, axis=0)
    out[:, 4] *= rng.uniform(0.5, 1.0, 1)[0]
    return out


def test_a_sample_params_that_draws_a_batch_otherwise_than_single_draws_is_refused(register):
    """T54-B01: sample_rows(rng, 3) gave D_w -38.04 three times where three single draws gave -38.04, -38.10, -31.94."""
    register("batch54", sample=_one_draw_per_batch)
    family = get_task_family("batch54")
    message = r"^batch54 sample_params\(rng, 2\)'s answer is not allowed: its row 1 has D_w="
    with pytest.raises(NeurohoverError, match=message + r"-38\.04.*, where single draws .* give -38\.10.* \(draw 1\); give n draws that consume"):
        family.sample_rows(np.random.default_rng(5), 3)
    for call in (lambda: family.sample(5), family.training_mdps):  # every first draw, until the class passes
        with pytest.raises(NeurohoverError, match=message):
            call()


def test_a_family_that_draws_as_single_draws_passes_and_its_stream_is_unchanged(register):
    register("single54")
    family = get_task_family("single54")
    rows = family.sample_rows(np.random.default_rng(5), 3)[:, 4]
    rng = np.random.default_rng(5)
    assert rows.tolist() == [family.sample(rng).params[4] for _ in range(3)]  # the check drew from a copy of the caller's generator
    assert get_task_family("fghh", 0.2).sample_rows(np.random.default_rng(1), 2).shape[0] == 2


def test_a_sample_params_that_consumes_the_generator_otherwise_is_refused(register):
    def extra(self, rng, n):  # the right values, and one draw more in a batch of several
        out = _draws(self, rng, n)
        if n > 1:
            rng.uniform()
        return out

    register("extra54", sample=extra)
    with pytest.raises(NeurohoverError, match=r"^extra54 sample_params\(rng, 2\)'s answer is not allowed: it leaves the generator elsewhere"):
        get_task_family("extra54").sample(1)


# --------------------------------------------------------------------------- T54-B08: a name the records can hold


@pytest.mark.parametrize("name", ["he/avy", "he:avy", "he avy", "Heavy", "he-avy", "x" * 65])
def test_a_family_name_the_records_cannot_hold_is_refused(register, name):
    """T54-B08: 'he/avy' was registered and its champion's target 'he/avy/seeded-train:1' loaded as family 'he'."""
    register(name)
    message = r"is not allowed: a task family's name is one line of at most 64 lowercase letters, digits, '\.' and '_' \(no '/', ':'"
    with pytest.raises(NeurohoverError, match=rf"^TASK_FAMILIES\['{name[:8]}.*\] = .* {message}"):
        get_task_family(name)
    assert name not in task_names()


def test_a_family_name_of_letters_digits_dots_and_underscores_is_taken(register):
    register("heavy_2.b")
    assert get_task_family("heavy_2.b").mdp("train:1").label == "heavy_2.b/seeded-train:1"


# --------------------------------------------------------------------------- T54-B10, B11: the flags


def test_has_sigma_without_a_sigma_field_is_refused(register):
    """T54-B10: get_task_family('sigx', 0.3) was "TypeError: __init__() got an unexpected keyword argument 'sigma'"."""
    register("sigx", body={"has_sigma": True})
    with pytest.raises(NeurohoverError, match=r"^TASK_FAMILIES\['sigx'\] = .* is not allowed: its has_sigma is True, but it has no sigma field"):
        get_task_family("sigx", 0.3)
    register("sigy", body={"has_sigma": True}, sigma=True)
    assert get_task_family("sigy", 0.2).sigma == 0.2 and get_task_family("sigy").sigma == 0.3


@pytest.mark.parametrize(("flag", "value"), [("generic_over_distribution", "no"), ("has_sigma", "yes"), ("has_sigma", 1)])
def test_a_flag_that_is_no_bool_is_refused(register, flag, value):
    """T54-B11: generic_over_distribution='no' made the family's policy set FGHH-like (generics by kind)."""
    register("flag54", body={flag: value})
    with pytest.raises(NeurohoverError, match=rf"^TASK_FAMILIES\['flag54'\] = .* is not allowed: its {flag} {value!r} is no bool: give True \(.*\) or False$"):
        get_task_family("flag54")
    register("flag54", body={flag: np.bool_(False)})
    assert get_task_family("flag54").name == "flag54"


# --------------------------------------------------------------------------- T54-B12: make() and row_slice


def test_a_make_that_ignores_its_params_is_a_neurohover_error(register):
    """T54-B12: RuntimeError 'ign54: make() does not put the parameters in row_slice slice(0, 11, None)'."""
    register("ign54", make=lambda self, p, label="": MDP("ign54", label=label))
    with pytest.raises(NeurohoverError, match=r"^ign54 make\(\)'s kernel row is not allowed: it does not put the parameters .* they sit nowhere in its row"):
        get_task_family("ign54").sample_rows(np.random.default_rng(1), 2)


def test_a_row_slice_off_by_one_is_refused_naming_where_the_parameters_sit(register):
    register("off54", body={"row_slice": slice(1, 12)})
    with pytest.raises(NeurohoverError, match=r"in row_slice slice\(1, 12, None\) .* they sit at slice\(0, 11\): give row_slice = slice\(0, 11\)$"):
        get_task_family("off54").sample_rows(np.random.default_rng(1), 2)


# --------------------------------------------------------------------------- T54-B13: make() and its label


def test_a_make_that_ignores_its_label_is_refused(register):
    """T54-B13: all 20 fixed MDPs were labelled 'lab54/whatever'."""
    register("lab54", make=lambda self, p, label="": MDP("lab54", params=tuple(map(float, p)), label="lab54/whatever"))
    family = get_task_family("lab54")
    message = r"^lab54 make\(\)'s answer labelled 'lab54/whatever' is not allowed: make\(params, label='{}'\) must answer an MDP of that label"
    with pytest.raises(NeurohoverError, match=message.format("lab54/seeded-train:0")):
        family.training_mdps()
    with pytest.raises(NeurohoverError, match=message.format("mine")):
        family.make(DEFAULT_PARAMS, label="mine")
    assert family.make(DEFAULT_PARAMS).label == "lab54/whatever"  # no label given: the family's own
