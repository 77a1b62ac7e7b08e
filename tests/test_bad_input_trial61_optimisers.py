"""Bad-input trial 61, side B: a run-time optimiser's answers and spec.

T61-B02: a state_dict() nested 900 lists deep passed the state check and its checkpoint was written; evolve(...,
resume=True) then failed with a RecursionError copying it (150 deep resumed). T61-B03: 5,000 deep, the state check
itself was a RecursionError (it walked the state recursively). A state is now refused by name, measured without
recursion, deeper than the limit policy notes have (100 lists or tables, T33-B03), when state_dict() answers it and
before each checkpoint is written; a state at the limit resumes.
T61-B04: a run-time OptimiserSpec's min_genes was never checked: '40' or None was a TypeError, and NaN (no minimum),
-1, True, 0 and 1.5 were taken. A spec's min_genes is now a whole number >= 1, refused by name otherwise.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from neurohover.errors import NeurohoverError
from neurohover.evolution import evolve
from neurohover.evolution.answers import check_state_json
from neurohover.evolution.optimisers import OPTIMISERS, OptimiserSpec
from neurohover.jsontext import MAX_NOTE_DEPTH
from neurohover.tasks import get_task_family

NAME = "t61-answers-opt"


def deep(n: int) -> Any:
    """A list nested ``n`` levels deep around 1."""
    value: Any = 1
    for _ in range(n):
        value = [value]
    return value


@dataclasses.dataclass(frozen=True)
class Settings:
    k: int = 1


class Mine:
    """A toy optimiser whose state carries ``TREE(generation)`` and restores itself exactly."""

    TREE: Any = staticmethod(lambda generation: 0)

    def __init__(self, proto: Any, settings: Any, seed: int) -> None:
        self.p, self.best, self.r, self.last, self.n = np.asarray(proto, float), None, -np.inf, None, 0

    def ask(self) -> np.ndarray:
        self.last = self.p + np.zeros((4, self.p.size))
        return self.last

    def tell(self, fitness: Any, info: Any = None) -> None:
        i = int(np.argmax(fitness))
        self.best, self.r, self.n = self.last[i], float(fitness[i]), self.n + 1

    def stop(self) -> bool:
        return False

    champion_genome = property(lambda self: self.best)
    champion_return = property(lambda self: self.r)

    def state_dict(self) -> dict:
        best, last = (None if a is None else a.tolist() for a in (self.best, self.last))
        return {"tree": type(self).TREE(self.n), "best": best, "r": self.r if np.isfinite(self.r) else "-inf", "last": last, "n": self.n}

    @classmethod
    def from_state_dict(cls, state: dict) -> Mine:
        opt = cls(np.zeros(len(state["last"][0])), Settings(), 0)
        opt.best, opt.last = (None if a is None else np.array(a) for a in (state["best"], state["last"]))
        opt.r, opt.n = float(state["r"]), state["n"]
        return opt


@pytest.fixture
def registered(monkeypatch: pytest.MonkeyPatch) -> Any:
    monkeypatch.setitem(OPTIMISERS, NAME, OptimiserSpec(NAME, "user", Settings, Mine, stops_itself=False))
    yield
    Mine.TREE = staticmethod(lambda generation: 0)


def _evolve(checkpoint: Path, budget: int, resume: bool = False, every: float | None = None) -> Any:
    mdp = get_task_family("ghh08").mdp("zero")
    return evolve(mdp, topology="slp", optimizer=NAME, budget=budget, n_steps=10, seed=0, checkpoint=checkpoint, resume=resume, checkpoint_every_s=every)


def test_a_state_5000_deep_is_refused_by_name_not_a_recursion_error() -> None:
    with pytest.raises(NeurohoverError, match=rf"optimizer 'mine': its state_dict\(\) is nested 5,001 lists or tables deep .* at most {MAX_NOTE_DEPTH}"):
        check_state_json({"tree": deep(5000)}, "mine")


@pytest.mark.usefixtures("registered")
def test_a_state_900_deep_is_refused_before_a_checkpoint_is_written(tmp_path: Path) -> None:
    Mine.TREE = staticmethod(lambda generation: deep(900))
    with pytest.raises(NeurohoverError, match=rf"optimizer '{NAME}': its state_dict\(\) is nested 901 lists or tables deep .*\['tree'\]"):
        _evolve(tmp_path / "ck.json", 12)
    assert not (tmp_path / "ck.json").exists()


@pytest.mark.usefixtures("registered")
def test_a_state_turned_too_deep_later_is_refused_before_its_checkpoint_is_written(tmp_path: Path) -> None:
    Mine.TREE = staticmethod(lambda generation: deep(900) if generation >= 2 else 0)
    with pytest.raises(NeurohoverError, match=rf"optimizer '{NAME}': its state_dict\(\) is nested 901 lists or tables deep"):
        _evolve(tmp_path / "ck.json", 40, every=1e-9)


@pytest.mark.usefixtures("registered")
def test_a_state_at_the_limit_resumes_and_one_level_more_is_refused(tmp_path: Path) -> None:
    Mine.TREE = staticmethod(lambda generation: deep(MAX_NOTE_DEPTH - 1))  # the state's own table is one level
    first = _evolve(tmp_path / "ck.json", 12)
    resumed = _evolve(tmp_path / "ck.json", 24, resume=True)
    assert resumed.history[0] == first.history[0]
    Mine.TREE = staticmethod(lambda generation: deep(MAX_NOTE_DEPTH))
    with pytest.raises(NeurohoverError, match=rf"nested {MAX_NOTE_DEPTH + 1} lists or tables deep .* at most {MAX_NOTE_DEPTH}"):
        _evolve(tmp_path / "other.json", 12)


@pytest.mark.usefixtures("registered")
@pytest.mark.parametrize("value", ["40", None, float("nan"), -1, True, 0, 1.5])
def test_a_bad_min_genes_is_refused_by_name(monkeypatch: pytest.MonkeyPatch, tmp_path: Path, value: Any) -> None:
    monkeypatch.setitem(OPTIMISERS, NAME, OptimiserSpec(NAME, "user", Settings, Mine, stops_itself=False, min_genes=value))
    with pytest.raises(NeurohoverError, match=rf"its min_genes {'nan' if value != value else repr(value)} is no whole number >= 1"):
        _evolve(tmp_path / "ck.json", 8)
