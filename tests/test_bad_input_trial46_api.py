"""Bad input, trial 46: ``==`` of the public results holding arrays (T46-B08), a task family registered at run time
in policy records, compete summaries and configs (T46-B07), and an FGHH policy set's manifest without its sigma
(T46-B12)."""

from __future__ import annotations

import copy
import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest

import neurohover as nh
import neurohover.tasks as T
from neurohover.errors import NeurohoverError
from neurohover.evolution import races
from neurohover.sim.constants import WIND_CONSTANT
from tests.store_edits import edited_policy_set


def _results() -> list:
    """One of each public result that holds arrays, NaN among the values."""
    from neurohover.agents.protocol import RunResult
    from neurohover.compete_files import CompeteResult
    from neurohover.evolution.common import TellInfo

    mdp = nh.get_task_family("ghh08").zero()
    ones = np.ones(3)
    return [
        races.fixed_resampling(lambda idx: -np.ones(len(idx)), 3, 2),
        races.selection_race(lambda i: -np.arange(len(i), dtype=float), 4, 2, 0.2),
        RunResult("a", mdp, np.array([-1.0, np.nan, -2.0]), np.zeros(3, bool), np.full(3, 6000), ["p"] * 3, np.zeros(3, bool), ones),
        CompeteResult("a on ghh08", np.array([[-1.0, np.nan], [-2.0, -3.0]]), 0, Path("out")),
        TellInfo(crashed=np.array([True, False]), selected=np.array([1, 0]), episodes=4),
    ]


@pytest.mark.parametrize("result", _results(), ids=lambda r: type(r).__name__)
def test_results_holding_arrays_compare_by_value(result) -> None:
    """T46-B08: ``r == copy.deepcopy(r)`` was NumPy's "truth value of an array is ambiguous"."""
    assert result == copy.deepcopy(result) and result in [5, copy.deepcopy(result)]
    name = next(f.name for f in dataclasses.fields(result) if isinstance(getattr(result, f.name), np.ndarray))
    other = copy.deepcopy(getattr(result, name))
    other.flat[0] = not other.flat[0] if other.dtype == bool else 7
    changed = copy.copy(result)
    object.__setattr__(changed, name, other)
    assert changed != result and result != 5
    with pytest.raises(TypeError, match="unhashable"):
        hash(result)


@pytest.fixture
def mine(monkeypatch):
    """A task family registered at run time, as ``TASK_FAMILIES["mine"] = Mine``: GHH-08's under a name of its own, its
    make and zero its own (the inherited ones answer ghh08 MDPs, refused as mine's; T52-B05)."""

    def make(self, params, label=""):
        return T.MDP("mine", wind_kind=WIND_CONSTANT, wind=tuple(T.finite_vector(params, 2, "wind").tolist()), label=label)

    body = {"name": "mine", "set_code": 98, "make": make, "zero": lambda self: T.MDP("mine", label="mine/zero")}
    cls = dataclasses.dataclass(frozen=True)(type("Mine", (T.GHH08,), body))
    monkeypatch.setitem(T.TASK_FAMILIES, "mine", cls)
    return cls


def test_a_family_registered_at_run_time_is_a_policys_task_and_target(tmp_path, mine) -> None:
    """T46-B07: save_policy of a champion evolved on one was refused ("'mine' is no task family (allowed ghh08, ghh09,
    fghh, the registered ones)"): the records read TASK_NAMES, frozen at import."""
    from neurohover.evolution import evolve

    champion = evolve(nh.get_task_family("mine").training_mdps()[0], topology="slp", budget=20, n_steps=50).champion
    assert nh.load_policy(nh.save_policy(champion, tmp_path / "p.json")).metadata["target"] == "mine/seeded-train:0"
    nh.save_policy(nh.baseline_policy(), tmp_path / "g.json", task="mine", mdp="G", target="mine/G")
    with pytest.raises(NeurohoverError, match=r"its task 'ghh10' is not allowed: allowed ghh08, ghh09, fghh, mine \(the registered"):
        nh.save_policy(nh.baseline_policy(), tmp_path / "q.json", task="ghh10")
    with pytest.raises(NeurohoverError, match=r"'ghh10' is no task family \(allowed ghh08, ghh09, fghh, mine, the registered ones\)"):
        nh.save_policy(nh.baseline_policy(), tmp_path / "q.json", target="ghh10/train:0")


def test_a_family_registered_at_run_time_is_a_configs_task_and_an_agents(mine) -> None:
    """T46-B07: experiments/settings and agents/spec read the frozen tuple too."""
    from neurohover.agents.registry import usable_agents
    from neurohover.experiments.checks import schema_of
    from neurohover.experiments.settings import ExperimentSettings

    check = schema_of(ExperimentSettings)["task"][1]
    assert check("mine")[0] and not check("ghh10")[0] and "'mine'" in check("ghh10")[1]
    assert "mine" in usable_agents()["baseline"].tasks


@pytest.mark.parametrize("change", [lambda m: m.pop("sigma"), lambda m: m.update(sigma=None)], ids=["deleted", "null"])
def test_an_fghh_set_without_its_sigma_is_refused_by_name(tmp_path, change) -> None:
    """T46-B12: without sigma the generic agent flew the set's sigma-0.3 generics at sigma 0.7."""
    from neurohover.agents.registry import make_agent

    pd = edited_policy_set(tmp_path, "fghh", change)
    assert json.loads((pd / "fghh" / "generic_fixed.json").read_text())["target"] == "fghh/G(sigma=0.3)"
    what = "no sigma" if "sigma" not in json.loads((pd / "fghh" / "manifest.json").read_text()) else "its sigma null"
    for sigma in (0.7, 0.3):
        with pytest.raises(NeurohoverError, match=rf"manifest.json' has {what}: not allowed for a fghh set, .* give the sigma build-policies wrote"):
            make_agent("generic", nh.get_task_family("fghh", sigma), policy_dir=pd)
