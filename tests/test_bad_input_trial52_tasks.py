"""Bad-input trial 52, side B (user-written task families): a subclass of GHH08 that kept the name "ghh08" replaced
GHH-08's seeded sets for the rest of the process (T52-B01), and a user's family defined again (a notebook cell run
again) kept the first definition's fixed sets (T52-B02): the sets are cached by the family's class, not its name; a
set_code NumPy takes as no seed was accepted at definition and failed at training_mdps() (T52-B03); make() or zero()
answering no MDP was an AttributeError 'label' (T52-B04), and a renamed subclass of a shipped family, whose inherited make
and zero answer the shipped family's MDPs, was refused only at run_test (T52-B05): their answers are checked as
sample_params' are; a neurohover id given a run-time family's task said "make a wide id instead", of which there is none
(T52-B06); tasks.discover took a TASK_FAMILY that is no TaskFamily subclass (an AttributeError 'name') and a bad package
(ModuleNotFoundError, AttributeError), which the agents' discover refuses by name (T52-B16)."""

from __future__ import annotations

import re
from dataclasses import dataclass

import gymnasium as gym
import numpy as np
import pytest

import neurohover.tasks.base as base
from neurohover.envs import HoverEnv
from neurohover.errors import NeurohoverError
from neurohover.sim.constants import DEFAULT_PARAMS, ROW_PARAMS
from neurohover.tasks import GHH08, GHH09, MDP, TASK_FAMILIES, TaskFamily, discover, finite_vector, get_task_family

_NAMES = ("C_u", "C_v", "D_v", "C_w", "D_w", "C_p", "D_p", "C_q", "D_q", "C_r", "D_r")


def _family(name: str, code: object = 152, *, low: float = 0.5, make=None, zero=None) -> type[TaskFamily]:
    """A user's family of the 11 GHH parameters (README's Extending neurohover), its D_w scaled by a draw in [low, low + 0.01],
    defined as a notebook cell defines it (the same module and class name each time)."""

    def made(self, params, label=""):
        return MDP(name, params=tuple(finite_vector(params, 11, "p").tolist()), label=label)

    def sample_params(self, rng, n):
        return DEFAULT_PARAMS[None, :] * np.where(np.arange(11) == 4, rng.uniform(low, low + 0.01, (n, 1)), 1.0)

    body = {"__module__": __name__, "name": name, "n_params": 11, "param_names": _NAMES, "row_slice": ROW_PARAMS, "set_code": code}
    body |= {"make": make or made, "zero": zero or (lambda self: MDP(name, label=f"{name}/zero")), "sample_params": sample_params}
    return dataclass(frozen=True)(type(name.title(), (TaskFamily,), body))


@pytest.fixture
def private_sets(monkeypatch):
    """The fixed sets and row templates as private caches, so that the order of building is this test's own."""
    monkeypatch.setattr(base, "_FIXED_SETS", {})
    monkeypatch.setattr(base, "_ROW_LAYOUTS", {})


# --------------------------------------------------------------------------- T52-B01, B02: the fixed sets' cache


@dataclass(frozen=True)
class _Calm(GHH08):
    """A subclass that forgot its own name: still "ghh08", its draws all zero wind."""

    def sample_params(self, rng, n):
        return super().sample_params(rng, n) * 0.0


def test_a_subclass_under_a_shipped_name_leaves_the_shipped_sets_alone(private_sets) -> None:
    assert _Calm().mdp("seeded-train:0").wind == (0.0, 0.0)
    shipped = get_task_family("ghh08")
    assert shipped.mdp("seeded-train:0").wind != (0.0, 0.0)  # was (0.0, 0.0): Calm's set, cached under "ghh08"
    assert _Calm().seeded_test_mdps()[5].wind == (0.0, 0.0) and shipped.seeded_test_mdps()[5].wind != (0.0, 0.0)
    assert np.array_equal(_Calm().rows(np.ones((1, 2))), shipped.rows(np.ones((1, 2))))


def test_a_family_defined_again_has_its_new_definitions_sets(private_sets) -> None:
    first = _family("heavy52", low=0.5)
    assert 0.5 <= first().training_mdps()[0].params[4] / DEFAULT_PARAMS[4] <= 0.51
    again = _family("heavy52", low=0.1)  # the cell run again: a new class object, the same name
    assert 0.1 <= again().training_mdps()[0].params[4] / DEFAULT_PARAMS[4] <= 0.11  # was the first definition's 0.5
    assert 0.1 <= again().sample(0).params[4] / DEFAULT_PARAMS[4] <= 0.11
    assert again().training_mdps() == again().training_mdps() and first().training_mdps() != again().training_mdps()


# --------------------------------------------------------------------------- T52-B03: set_code


@pytest.mark.parametrize("code", [1.5, -1, "x", None, True, 2**63, np.float64(3.0)])
def test_a_set_code_that_is_no_seed_is_refused_at_definition(code: object) -> None:
    allowed = r"give an integer in 0\.\.2\*\*63-1, a seed that distinguishes its seeded fixed sets"
    with pytest.raises(NeurohoverError, match=rf"^task family class Code52 \('code52'\): its set_code .* is not allowed: {allowed}"):
        _family("code52", code)


def test_a_whole_set_code_is_taken() -> None:
    for code in (0, np.int64(7), 2**63 - 1):
        assert len(_family("code52b", code)().training_mdps()) == 10


# --------------------------------------------------------------------------- T52-B04, B05: make's and zero's answers


@pytest.mark.parametrize("answer", [None, "zero", (1, 2), MDP("ghh08")])
def test_a_zero_or_make_answering_no_mdp_of_the_family_is_refused(answer: object) -> None:
    family = _family("answer52", zero=lambda self: answer, make=lambda self, params, label="": answer)()
    what = "it is a 'ghh08' MDP, but make and zero must answer MDPs of 'answer52'" if isinstance(answer, MDP) else "it must be an MDP of the family"
    for call, method in ((family.zero, "zero"), (lambda: family.mdp("train:0"), "make"), (lambda: family.sample(0), "make")):
        with pytest.raises(NeurohoverError, match=rf"^answer52 {method}\(\)'s answer .* is not allowed: {re.escape(what)}"):
            call()


@dataclass(frozen=True)
class _My09(GHH09):
    name = "my52"


def test_a_renamed_subclass_of_a_shipped_family_says_to_override_make_and_zero() -> None:
    family = _My09()
    for call, method in ((family.zero, "zero"), (lambda: family.mdp("test:1"), "make"), (lambda: family.sample(0), "make")):
        with pytest.raises(
            NeurohoverError, match=rf"^my52 {method}\(\)'s answer .* it is a 'ghh09' MDP, .*My09 inherits {method} from GHH09: .*override make and zero"
        ):
            call()


# --------------------------------------------------------------------------- T52-B06: a run-time family on a shipped id


def test_a_shipped_id_given_a_run_time_family_names_what_works(monkeypatch) -> None:
    cls = _family("wide52")
    monkeypatch.setitem(TASK_FAMILIES, "wide52", cls)
    with pytest.raises(NeurohoverError, match=r"task='wide52' conflicts with it; neurohover has no id for it .*HoverEnv\(task='wide52'\)"):
        gym.make("neurohover/GHH08-v0", task="wide52")
    with pytest.raises(NeurohoverError, match=r"task='ghh09' conflicts with it; make a ghh09 id instead \(neurohover/GHH09-v0"):
        gym.make("neurohover/GHH08-v0", task="ghh09")  # a family with ids: named as before
    assert HoverEnv(task="wide52", episode_steps=5).reset(seed=0)[1]["mdp_info"]["family"] == "wide52"


# --------------------------------------------------------------------------- T52-B16: discover


def _package(tmp_path, monkeypatch, name: str, modules: dict[str, str]) -> str:
    (tmp_path / name).mkdir()
    (tmp_path / name / "__init__.py").write_text("")
    for module, text in modules.items():
        (tmp_path / name / f"{module}.py").write_text(text)
    monkeypatch.syspath_prepend(str(tmp_path))
    return name


@pytest.mark.parametrize(
    "text",
    [
        'TASK_FAMILY = "heavy"\n',
        "from neurohover.tasks import GHH08\nTASK_FAMILY = GHH08()\n",
        "from neurohover.tasks import GHH08\nclass Calm(GHH08):\n    pass\nTASK_FAMILY = Calm\n",
    ],
    ids=["text", "instance", "no-name"],
)
def test_discover_refuses_a_task_family_that_is_no_named_class(tmp_path, monkeypatch, request, text: str) -> None:
    package = _package(tmp_path, monkeypatch, f"t52fams_{request.node.callspec.id.replace('-', '_')}", {"heavy": text})
    with pytest.raises(NeurohoverError, match=rf"^module {package}\.heavy's TASK_FAMILY=.* is not allowed: declare a TaskFamily subclass \(the class"):
        discover(package)


def test_discover_refuses_a_bad_package_and_a_name_declared_twice(tmp_path, monkeypatch) -> None:
    for package, why in (
        ("no_such_package_t52", "no module named 'no_such_package_t52' is importable"),
        (5, "give"),
        ("neurohover.tasks.base", "it is a module"),
    ):
        with pytest.raises(NeurohoverError, match=rf"^package={re.escape(repr(package))} is not allowed: {why}"):
            discover(package)  # type: ignore[arg-type]
    twice = "from neurohover.tasks import GHH08\nTASK_FAMILY = GHH08\n"
    package = _package(tmp_path, monkeypatch, "t52fams_twice", {"a": twice, "b": twice, "_private": "raise SystemExit\n"})
    with pytest.raises(NeurohoverError, match=r"^task family 'ghh08' is declared twice \(module t52fams_twice\.b and another\)"):
        discover(package)
    assert list(discover("neurohover.tasks")) == ["ghh08", "ghh09", "fghh"]
