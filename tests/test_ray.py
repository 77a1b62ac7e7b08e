"""Distributed runs on a REAL local Ray cluster: same results and seeds as the local executor,
worker deaths retried or reported (never recorded as finished), and a clear message without Ray.

Ray is an optional extra (``pip install 'neurohover[ray]'``); these tests need it and fail (they do
not skip) when it is missing.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
from conftest import ROOT

from neurohover.cli import main
from neurohover.errors import NeurohoverError
from neurohover.experiments import (
    LocalExecutor,
    RayExecutor,
    Store,
    load_config,
    make_executor,
    plan,
    reproduce,
    run_unit,
    strip_timing,
)
from neurohover.experiments.plans import Plan
from neurohover.experiments.units import Unit


@pytest.fixture(scope="session")
def ray_cluster():
    try:
        import ray
    except ImportError:
        pytest.fail("ray is not installed: the Ray tests need it (pip install 'neurohover[ray]' or 'ray>=2.9')")
    if not ray.is_initialized():
        ray.init(num_cpus=2, include_dashboard=False)
    yield ray
    ray.shutdown()


def _subset_config():
    """A representative subset in few units: policy evolution (steady state and over G with fixed
    resampling and races: no generics drawn from other experiments), and test runs of the authors'
    and the incremental model-based agents."""
    return load_config("fig16", "quick", {"generics_per_agent": 1, "generics_from": {}, "generic_budget": 2000})


@pytest.mark.slow
def test_ray_and_local_runs_give_identical_results(ray_cluster, tmp_path: Path) -> None:
    cfg = _subset_config()
    with Store(tmp_path / "local.sqlite") as local, Store(tmp_path / "ray.sqlite") as remote:
        a = reproduce(cfg, local, LocalExecutor(1), progress=False)
        executor = RayExecutor()
        assert not executor.started  # the session's cluster is reused, not restarted
        b = reproduce(cfg, remote, executor, progress=False)
        assert a.status == b.status == "finished" and a.units_run == b.units_run == a.units_total == 15
        assert b.executor == "ray" and b.cores == 2
        ra, rb = local.results(cfg.name, cfg.scale), remote.results(cfg.name, cfg.scale)
        assert ra.keys() == rb.keys()
        for key in ra:
            assert strip_timing(ra[key]) == strip_timing(rb[key]), key
        # The same seeds travelled with the units.
        pa = {u["key"]: u["params"]["seed"] for u in local.units(cfg.name, cfg.scale)}
        pb = {u["key"]: u["params"]["seed"] for u in remote.units(cfg.name, cfg.scale)}
        assert pa == pb and pa == {u.key: u.params["seed"] for u in plan(cfg, ra).units}
        assert any(w != "" for w in (u["worker"] for u in remote.units(cfg.name, cfg.scale)))


@pytest.mark.slow
def test_reproduce_command_with_the_ray_executor(ray_cluster, tmp_path: Path, capsys) -> None:
    store = tmp_path / "s.sqlite"
    argv = ["reproduce", "fig15", "--scale", "quick", "--set", "runs=1", "--set", "budget=600", "--store", str(store), "--executor", "ray", "--no-progress"]
    assert main(argv) == 0
    out = capsys.readouterr().out
    assert "ran 2 units, 0 already in the store" in out and "(ray)" in out
    assert main(argv) == 0
    assert "ran 0 units, 2 already in the store" in capsys.readouterr().out
    assert main(["reproduce", "fig15", "--store", str(store), "--executor", "ray", "--jobs", "2"]) == 2
    assert "--jobs applies to --executor local" in capsys.readouterr().err


@pytest.mark.slow
def test_a_driver_in_another_process_joins_the_cluster_with_address(ray_cluster, tmp_path: Path) -> None:
    address = ray_cluster.get_runtime_context().gcs_address
    store = tmp_path / "s.sqlite"
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "neurohover.experiments",
            "reproduce",
            "fig15",
            "--set",
            "runs=1",
            "--set",
            "budget=600",
            "--store",
            str(store),
            "--executor",
            "ray",
            "--address",
            address,
            "--no-progress",
        ],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert "ran 2 units" in proc.stdout and "on 2 cores (ray)" in proc.stdout
    assert ray_cluster.is_initialized()  # the cluster outlives the driver that joined it
    with Store(store) as s:
        local = {u.key: run_unit(u) for u in plan(load_config("fig15", "quick", {"runs": 1, "budget": 600}), {}).units}
        assert {k: strip_timing(v) for k, v in s.results("fig15", "quick").items()} == {k: strip_timing(v) for k, v in local.items()}


@pytest.mark.slow
def test_a_dying_worker_is_retried_by_ray(ray_cluster, tmp_path: Path) -> None:
    marker = tmp_path / "died-once"
    unit = Unit("diag", "retry", "diagnostic", {"exit_unless": str(marker), "value": 42})
    results, errors = [], []
    RayExecutor(max_retries=2).run([unit], lambda u, r, s, w: results.append(r), lambda u, e: errors.append(e))
    assert marker.exists(), "the first attempt should have killed its worker"
    assert errors == [] and results == [{"value": 42, "seed": None}]


@pytest.mark.slow
def test_a_unit_whose_worker_keeps_dying_is_reported_not_recorded(ray_cluster, tmp_path: Path, monkeypatch) -> None:
    from neurohover.experiments import runner

    cfg = load_config("fig15", "quick")
    units = [Unit(cfg.name, "good", "diagnostic", {"value": 1}), Unit(cfg.name, "dies", "diagnostic", {"always_exit": True})]
    monkeypatch.setattr(runner, "plan", lambda config, results, sources=None: Plan(units, 2))
    with Store(tmp_path / "s.sqlite") as store:
        summary = reproduce(cfg, store, RayExecutor(max_retries=1), progress=False)
        assert summary.status == "failed" and [k for k, _ in summary.failed] == ["dies"]
        assert set(store.results(cfg.name, cfg.scale)) == {"good"}
        assert store.sessions(cfg.name, cfg.scale)[-1]["status"] == "failed"


def test_without_ray_the_ray_executor_says_how_to_install_it(monkeypatch, tmp_path: Path, capsys) -> None:
    monkeypatch.setitem(sys.modules, "ray", None)  # `import ray` now raises ImportError
    with pytest.raises(NeurohoverError, match=r"pip install 'neurohover\[ray\]'"):
        make_executor("ray")
    rc = main(["reproduce", "fig15", "--store", str(tmp_path / "s.sqlite"), "--executor", "ray"])
    assert rc == 2 and "pip install 'neurohover[ray]'" in capsys.readouterr().err
    assert isinstance(make_executor("local"), LocalExecutor)
