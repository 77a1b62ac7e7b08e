"""Trial 48, side A: ``reproduce --only`` and the robustness units that fly the champions of evolve units.

T48-A01: `--only 'robust/**'` on an empty store ran only robust/policy-set/train0 and said "selection finished": the
robust/<variant>/trainN units, planned once their evolve units are stored, were neither run nor named. The evolve units
they wait for are now made first, as the policy/ units of test runs are.
T48-A02: `--only 'robust/mlp-baseline/train0'`, a real unit key of fig2, was refused "matches no unit".
"""

from __future__ import annotations

import sqlite3

import pytest

SHRUNK = ["--set", "n_mdps=1", "--set", "runs=1", "--set", "budget=10", "--set", "n_steps=20"]
SHRUNK += ["--set", "validation_episodes=1", "--set", "robustness_episodes=1", "--no-progress"]


def _stored(path) -> set[str]:
    with sqlite3.connect(path) as db:
        return {row[0] for row in db.execute("select key from units")}


def test_only_robust_units_makes_the_evolve_units_they_fly_first(cli, tmp_path) -> None:
    """T48-A01: every robust unit the pattern matches is run, after the evolve units whose champions it flies."""
    store = tmp_path / "o7.sqlite"
    rc, out, err = cli("reproduce", "fig2", "--store", str(store), *SHRUNK, "--only", "robust/**")
    assert rc == 0, err
    robust = {"robust/mlp-baseline/train0", "robust/slp-baseline/train0", "robust/policy-set/train0"}
    assert _stored(store) == robust | {"evolve/mlp-baseline/train0/run0", "evolve/slp-baseline/train0/run0"}


@pytest.mark.parametrize("pattern", ["robust/mlp-baseline/train0", "robust/mlp-baseline/*"])
def test_only_a_robust_unit_key_of_a_later_stage_is_taken(cli, tmp_path, pattern) -> None:
    """T48-A02: a key that exists once the evolve units are stored is a unit of the experiment, not a typo."""
    store = tmp_path / "o6.sqlite"
    rc, _, err = cli("reproduce", "fig2", "--store", str(store), *SHRUNK, "--only", pattern)
    assert rc == 0, err
    assert _stored(store) == {"evolve/mlp-baseline/train0/run0", "robust/mlp-baseline/train0"}


def test_only_an_unknown_robust_key_is_still_refused_before_the_store_changes(cli, tmp_path) -> None:
    """A robust key of no variant matches nothing: refused at once, naming robust keys among the examples."""
    store = tmp_path / "o5.sqlite"
    rc, _, err = cli("reproduce", "fig2", "--store", str(store), *SHRUNK, "--only", "robust/zzz/train0")
    assert rc == 2 and "--only 'robust/zzz/train0' matches no unit" in err and "robust/slp-baseline/train0" in err, err
    assert not store.exists() or not _stored(store)
