"""Bad-input trial 35 (the command line): a subnormal CMA-ES sigma0 taken, then pycma's AssertionError (T35-A01); a
baseline-only run refused because a policy set it never flies changed (T35-A02)."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

import neurohover
from neurohover.experiments import Store


@pytest.mark.parametrize("sigma0", ["1e-320", "5e-324", "1e-101"])
def test_a_step_size_too_small_to_adapt_is_refused_before_flying(cli, tmp_path: Path, sigma0: str) -> None:
    out = tmp_path / "p.json"
    argv = ["evolve", "--task", "ghh08", "--optimizer", "cma", "--setting", f"sigma0={sigma0}", "--budget", "10", "--episode-steps", "20"]
    rc, _, err = cli(*argv, "--out", str(out))
    assert rc == 2 and "must be a finite number >= 1e-100 and <= 1e+100" in err and "Traceback" not in err, err
    assert not out.exists()


BASELINE_ONLY = """name = "mine"
kind = "test_runs"
[settings]
task = "ghh08"
seed = 1
policies = "{policies}"
groups = [{{ agent = "baseline", mdps = "test", n_mdps = 1 }}]
[scales.quick]
episodes = 2
n_steps = 20
"""


def _nudge_unflown_policy(policies: Path) -> None:
    path = policies / "ghh08" / "specialised_3.json"
    policy = json.loads(path.read_text())
    policy["genome"][0] += 0.01
    path.write_text(json.dumps(policy))


def test_a_baseline_only_experiment_runs_on_after_a_policy_it_never_flies_changed(cli, tmp_path: Path) -> None:
    policies = tmp_path / "pd2"
    shutil.copytree(Path(neurohover.__file__).parent / "data" / "policies", policies)
    config = tmp_path / "c.toml"
    config.write_text(BASELINE_ONLY.format(policies=policies))
    store = tmp_path / "s.sqlite"
    assert cli("reproduce", str(config), "--store", str(store), "--no-progress")[0] == 0
    with Store(store) as db:
        before = db.results("mine", "quick")
    _nudge_unflown_policy(policies)
    rc, _, err = cli("reproduce", str(config), "--store", str(store), "--no-progress")
    assert rc == 0, err
    with Store(store) as db:
        assert db.results("mine", "quick") == before


def test_a_baseline_competition_stored_with_the_sets_digest_is_taken_and_relabelled(cli, tmp_path: Path, monkeypatch) -> None:
    """A folder an older neurohover wrote (its config hashed the shipped set) takes a baseline compete again, runs kept."""
    from neurohover.experiments import plans

    argv = ["compete", "--task", "ghh08", "--agent", "baseline", "--runs", "1", "--episodes", "2", "--episode-steps", "20", "--out", str(tmp_path / "c")]
    with monkeypatch.context() as m:  # as neurohover hashed it before T35-A02: every named set
        m.setattr(plans, "_flies_set", lambda kind, settings: True)
        assert cli(*argv)[0] == 0
    with Store(tmp_path / "c" / "results.sqlite") as db:
        ((name, scale, *_),) = db.experiments()
        old_hash, before = db.config_hash(name, scale), db.results(name, scale)
        assert db.config(name, scale)["external_digest"]
    rc, _, err = cli(*argv)
    assert rc == 0 and "hashed a policy set none of them flies" in err, err
    with Store(tmp_path / "c" / "results.sqlite") as db:
        assert db.results(name, scale) == before and db.config_hash(name, scale) != old_hash
        assert db.config(name, scale)["external_digest"] == ""
