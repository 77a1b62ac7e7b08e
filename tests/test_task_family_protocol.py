"""The task-family protocol: one module per family, found without a list to edit, read by everyone."""

from __future__ import annotations

import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

import neurohover as nh
from neurohover.envs import ENV_IDS
from neurohover.errors import NeurohoverError
from neurohover.tasks import TASK_FAMILIES, TASK_NAMES, TaskFamily, discover, family_for, get_task_family


def test_the_paper_families_are_registered_in_the_papers_order() -> None:
    assert TASK_NAMES == ("ghh08", "ghh09", "fghh")
    assert [n for n, c in TASK_FAMILIES.items() if c.has_sigma] == ["fghh"]
    assert [n for n, c in TASK_FAMILIES.items() if c.generic_over_distribution] == ["fghh"]
    assert set(ENV_IDS.values()) == set(TASK_NAMES)


@pytest.mark.parametrize("name", TASK_NAMES)
def test_sampled_rows_are_the_rows_of_consecutive_samples_whatever_the_batch(name: str) -> None:
    family = get_task_family(name)
    rng = np.random.default_rng(11)
    one_by_one = np.stack([family.sample(rng).row() for _ in range(7)])
    rng = np.random.default_rng(11)
    batched = np.vstack([family.sample_rows(rng, 3), family.sample_rows(rng, 4)])
    np.testing.assert_array_equal(batched, one_by_one)
    params = family.sample_params(np.random.default_rng(2), 5)
    assert params.shape == (5, family.n_params) == (5, len(family.param_names))
    np.testing.assert_array_equal(family.rows(params), np.stack([family.make(p).row() for p in params]))


def test_sigma_goes_to_families_that_have_one() -> None:
    assert get_task_family("fghh", 0.2).sigma == 0.2 and get_task_family("ghh08").sigma is None
    with pytest.raises(NeurohoverError, match="sigma applies to the fghh task only, not to 'ghh09'"):
        get_task_family("ghh09", 0.2)
    assert family_for("ghh09", 0.2).name == "ghh09" and family_for("fghh", 0.2).sigma == 0.2


def test_a_new_family_module_is_discovered_and_gets_samples_rows_and_sets(tmp_path: Path, monkeypatch) -> None:
    package = tmp_path / "myfamilies"
    package.mkdir()
    (package / "__init__.py").write_text("")
    (package / "heavy.py").write_text(
        textwrap.dedent('''
        from dataclasses import dataclass

        from neurohover.sim.constants import DEFAULT_PARAMS, ROW_PARAMS
        from neurohover.tasks.base import MDP, TaskFamily, finite_vector


        @dataclass(frozen=True)
        class Heavy(TaskFamily):
            """A heavier helicopter: the vertical gain D_w scaled by a factor in [0.5, 1]."""

            name = "heavy"
            n_params = 11
            param_names = ("C_u", "C_v", "D_v", "C_w", "D_w", "C_p", "D_p", "C_q", "D_q", "C_r", "D_r")
            row_slice = ROW_PARAMS
            set_code = 99

            def make(self, params, label=""):
                return MDP("heavy", params=tuple(finite_vector(params, 11, "heavy params").tolist()), label=label)

            def zero(self):
                return MDP("heavy", label="heavy/zero")

            def sample_params(self, rng, n):
                out = np.repeat(DEFAULT_PARAMS[None, :], n, axis=0)
                out[:, 4] *= rng.uniform(0.5, 1.0, n)
                return out


        import numpy as np
        TASK_FAMILY = Heavy
    ''')
    )
    monkeypatch.syspath_prepend(str(tmp_path))
    found = discover("myfamilies")
    assert list(found) == ["heavy"]
    heavy = found["heavy"]()
    assert isinstance(heavy, TaskFamily)
    train = heavy.training_mdps()
    assert len(train) == 10 and train[3].label == "heavy/seeded-train:3" == heavy.mdp("train:3").label
    assert len({m.params[4] for m in train}) == 10
    rows = heavy.sample_rows(np.random.default_rng(0), 2)
    assert rows.shape[0] == 2 and np.all((rows[:, 4] >= -42.15) & (rows[:, 4] <= -42.15 * 0.5))  # D_w < 0
    sys.modules.pop("myfamilies", None)
    sys.modules.pop("myfamilies.heavy", None)


def test_an_mdp_reads_as_plain_numbers() -> None:
    mdp = nh.get_task_family("ghh08").mdp("train:3")
    assert "np.float64" not in repr(mdp) and "params=(-0.18, -0.43" in repr(mdp)
    built = nh.get_task_family("fghh", 0.3).make(np.array(mdp.params))
    assert all(type(x) is float for x in built.params) and built.params == mdp.params
