"""Bad-input trial 51, side B (the Python API): evaluate and evaluate_jobs given a sized object that cannot be iterated (a
PolicyTable) as mdps raised TypeError "not iterable" (T51-B01); a user family's sample_params answering 4 rows for 3 was
taken by sample_rows without a word (T51-B04), and one answering shape (11,) for n=1 had sample(), the seeded sets and
the environments hand its first number to make(), whose message was the user's own (T51-B05): its answer is checked in
one place for every caller, naming sample_params, the shape given and the shape asked."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest

import neurohover as nh
from neurohover.envs import HoverEnv, HoverVectorEnv
from neurohover.errors import NeurohoverError
from neurohover.evaluate import PolicyTable
from neurohover.sim.constants import DEFAULT_PARAMS, ROW_PARAMS
from neurohover.tasks import MDP, TASK_FAMILIES, TaskFamily, finite_vector

_NAMES = ("C_u", "C_v", "D_v", "C_w", "D_w", "C_p", "D_p", "C_q", "D_q", "C_r", "D_r")


# --------------------------------------------------------------------------- T51-B01: a sized non-iterable as mdps


class _Sized:
    def __len__(self) -> int:
        return 2


@pytest.mark.parametrize("mdps", ["table", "sized"])
def test_a_sized_object_that_cannot_be_iterated_as_mdps_is_refused(mdps: str) -> None:
    """T51-B01: TypeError "'PolicyTable' object is not iterable" from evaluate and evaluate_jobs; refused now as a list
    holding it is, naming it and what is allowed."""
    b = nh.baseline_policy()
    table = PolicyTable.from_genomes(np.stack([b.genome] * 2), "slp")
    given = table if mdps == "table" else _Sized()
    shown = "PolicyTable" if mdps == "table" else "<.*_Sized object"
    message = rf"^mdps={shown}.* is not allowed: give an MDP, a non-empty sequence of MDPs or an array of MDP rows"
    with pytest.raises(NeurohoverError, match=message):
        nh.evaluate(b, given, n_steps=10)
    with pytest.raises(NeurohoverError, match=message):
        nh.evaluate_jobs(table, given, [0], [0], [0], n_steps=10)
    assert nh.evaluate(b, (nh.get_task_family("ghh08").zero(),), n_steps=5).returns.shape == (1, 1, 1)


# --------------------------------------------------------------------------- T51-B04, B05: sample_params' answer


def _user_family(name: str, code: int, sample_params, doc: str) -> type[TaskFamily]:
    """A user's family of the 11 GHH parameters (as README's Extending neurohover writes one) whose sample_params is
    ``sample_params``."""

    def make(self, params, label=""):
        return MDP(name, params=tuple(finite_vector(params, 11, "p").tolist()), label=label)

    body = {"name": name, "n_params": 11, "param_names": _NAMES, "row_slice": ROW_PARAMS, "set_code": code, "__doc__": doc}
    body |= {"make": make, "zero": lambda self: MDP(name, label=f"{name}/zero"), "sample_params": sample_params}
    return dataclass(frozen=True)(type(name.title(), (TaskFamily,), body))


Extra51 = _user_family("extra51", 151, lambda self, rng, n: np.repeat(DEFAULT_PARAMS[None, :], n + 1, axis=0), "One row too many.")
Flat51 = _user_family(
    "flat51",
    152,
    lambda self, rng, n: DEFAULT_PARAMS.copy() if n == 1 else np.repeat(DEFAULT_PARAMS[None, :], n, axis=0),
    "One MDP's parameters flat, shape (11,), for n=1.",
)


def _asked(name: str, n: int, shape: str) -> str:
    asked = rf"it must be an array of shape \(n, n_params\) = \({n}, 11\) of finite numbers \(C_u, C_v,"
    return rf"^{name} sample_params\(rng, {n}\)'s answer of shape {shape} is not allowed: {asked}"


def test_too_many_rows_from_sample_params_are_refused() -> None:
    """T51-B04: sample_rows(rng, 3) handed back 4 rows."""
    with pytest.raises(NeurohoverError, match=_asked("extra51", 3, r"\(4, 11\)")):
        Extra51().sample_rows(np.random.default_rng(0), 3)
    with pytest.raises(NeurohoverError, match=_asked("extra51", 1, r"\(2, 11\)")):
        Extra51().sample(np.random.default_rng(0))


def test_a_flat_answer_of_sample_params_is_refused_by_every_caller(monkeypatch: pytest.MonkeyPatch) -> None:
    """T51-B05: sample(), training_mdps() and the environments passed its first number to make(), whose message was the
    user's own "p must be 11 numbers, got 1"."""
    family = Flat51()
    message = _asked("flat51", 1, r"\(11,\)")
    for call in (
        lambda: family.sample(np.random.default_rng(0)),
        lambda: family.training_mdps(),
        lambda: family.sample_rows(np.random.default_rng(0), 1),
        lambda: family.mdp("sample", 3),
    ):
        with pytest.raises(NeurohoverError, match=message):
            call()
    monkeypatch.setitem(TASK_FAMILIES, "flat51", Flat51)
    with pytest.raises(NeurohoverError, match=message):
        HoverEnv(task="flat51").reset(seed=0)
    with pytest.raises(NeurohoverError, match=message):
        HoverVectorEnv(2, task="flat51").reset(seed=0)


def test_the_shipped_families_answers_pass_unchanged() -> None:
    """The check returns the shipped families' draws as they are (no copy) and every row flies as before."""
    for name in ("ghh08", "ghh09", "fghh"):
        family = nh.get_task_family(name)
        params = family.sample_params(np.random.default_rng(4), 3)
        assert params.shape == (3, family.n_params) and params.dtype == np.float64
        np.testing.assert_array_equal(family.sample_rows(np.random.default_rng(4), 3), family.rows(params))


_ANSWER: dict[str, object] = {}


Odd51 = _user_family("odd51", 153, lambda self, rng, n: _ANSWER["value"], 'Whatever _ANSWER["value"] holds.')


@pytest.mark.parametrize(
    ("answer", "message"),
    [
        (np.full((1, 11), np.nan), r"answer \[\[nan, .* is not allowed: it must be an array of shape"),
        ([["a"] * 11], r"answer \[\['a', .* is not allowed: it must be an array of shape"),
        (None, r"answer None is not allowed: it must be an array of shape"),
        (np.full((1, 11), 1e5), r"answer row 0 \[100000.0, .* is out of range: each parameter must lie in \[-10000, 10000\]"),
    ],
    ids=["nan", "text", "none", "outside"],
)
def test_other_bad_answers_of_sample_params_are_refused(answer: object, message: str) -> None:
    """Not finite, not numbers, or past the family's param_bounds (the vector environment writes the draws into its rows)."""
    _ANSWER["value"] = answer
    with pytest.raises(NeurohoverError, match=r"^odd51 sample_params\(rng, 1\)'s " + message):
        Odd51().sample(np.random.default_rng(0))
