"""``device="cuda"`` behind the evolution, the experiments' units and the CLI (docs/gpu.md).

As in tests/test_cuda.py, the GPU runs are flown under numba's CUDA simulator in a subprocess
(NUMBA_ENABLE_CUDASIM=1 must be set before numba is imported): tiny runs, each compared with the
same run on the CPU. The simulator interprets the kernel in Python floats, so returns agree with the
CPU kernel's to rounding (within 1e-9 relative; measured about 4e-16) and the champions, chosen by
the same comparisons, are the same genomes.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from cuda_sim import run_simulated

from neurohover.cli import main

SIM_RTOL = 1e-9  # docs/gpu.md's tolerance for the simulator

SCRIPT = r"""
import json, sys, warnings
from pathlib import Path
from neurohover import get_task_family
from neurohover.cli import main
from neurohover.evolution.evolve import evolve
from neurohover.experiments import Store, strip_timing
from neurohover.sim import cuda as sim_cuda

warnings.filterwarnings("ignore", "overflow encountered", RuntimeWarning)  # uint64 streams wrap in plain Python
tmp = Path(sys.argv[1])
ghh = get_task_family("ghh08")
small = {"pop_size": 4, "select_size": 2}
cases = {
    "steady": dict(target=ghh.mdp("train:0"), topology="slp", budget=20, n_steps=20, seed=3, settings={"pop_size": 6, "elite_size": 3}),
    "fixed2": dict(target=ghh, topology="slp", budget=16, n_steps=10, seed=4, resampling="fixed:2", settings=small),
    "race": dict(target=ghh, topology="slp", budget=24, n_steps=10, seed=5, resampling="race:0.05", settings=small),
    "cma": dict(target=ghh.mdp("train:0"), topology="slp", budget=12, n_steps=10, seed=6, optimizer="cma", settings={"sigma0": 0.1, "popsize": 4}),
}
out = {"simulating": sim_cuda.simulating(), "evolve": {}}
for name, kw in cases.items():
    for device in ("cpu", "cuda"):
        r = evolve(device=device, **kw)
        out["evolve"][f"{name}/{device}"] = {
            "genome": r.champion.genome.tolist(), "return": r.champion_return, "episodes": r.episodes,
            "history": [[h.episodes, h.champion_return] for h in r.history],
        }
config = tmp / "tiny.toml"
config.write_text('''
name = "tinygpu"
title = "device plumbing test"
kind = "evolution"
[settings]
task = "ghh08"
seed = 7
target = "family"
runs = 1
validation_episodes = 2
[[settings.variants]]
key = "k2"
label = "fixed, k = 2"
resampling = "fixed:2"
[[settings.variants]]
key = "race"
label = "races"
resampling = "race:0.05"
[scales.quick]
budget = 20
n_steps = 10
[scales.paper]
budget = 20
n_steps = 10
''')
stores = {}
for device in ("cpu", "cuda"):
    path = tmp / f"{device}.sqlite"
    rc = main(["reproduce", str(config), "--store", str(path), "--device", device, "--no-progress"])
    with Store(path) as store:
        stores[device] = {"rc": rc, "results": strip_timing(store.results("tinygpu", "quick"))}
# The device is no part of the config hash: the CPU's store counts as finished for a GPU run.
rc = main(["reproduce", str(config), "--store", str(tmp / "cpu.sqlite"), "--device", "cuda", "--no-progress"])
with Store(tmp / "cpu.sqlite") as store:
    stores["cpu_then_cuda"] = {"rc": rc, "results": strip_timing(store.results("tinygpu", "quick"))}
out["reproduce"] = stores
cli = {}
for device in ("cpu", "cuda"):
    target = tmp / f"champ-{device}.json"
    rc = main(["evolve", "--task", "ghh08", "--mdp", "train:0", "--topology", "slp", "--budget", "20", "--episode-steps", "10",
               "--validation-episodes", "2", "--seed", "2", "--device", device, "--out", str(target)])
    policy = json.loads(target.read_text())
    policy.pop("seconds"), policy.pop("history")  # wall time; the history file's name (it holds the device's own name)
    cli[device] = {"rc": rc, "policy": policy}
out["cli"] = cli
print(json.dumps(out))
"""


@pytest.fixture(scope="module")
def simulated(tmp_path_factory) -> dict:
    tmp = tmp_path_factory.mktemp("cudasim")
    return run_simulated(SCRIPT, str(tmp))


def _close(a, b, path: str = "") -> None:
    """Equal, except floats within SIM_RTOL relative."""
    if isinstance(a, dict):
        assert isinstance(b, dict) and set(a) == set(b), path
        for k in a:
            _close(a[k], b[k], f"{path}/{k}")
    elif isinstance(a, list):
        assert isinstance(b, list) and len(a) == len(b), path
        for i, (x, y) in enumerate(zip(a, b, strict=True)):
            _close(x, y, f"{path}[{i}]")
    elif isinstance(a, float) and not isinstance(a, bool):
        assert isinstance(b, (int, float)), path
        np.testing.assert_allclose(b, a, rtol=SIM_RTOL, atol=0, err_msg=path)
    else:
        assert a == b, path


@pytest.mark.slow
@pytest.mark.parametrize("case", ["steady", "fixed2", "race", "cma"])
def test_evolve_on_cuda_finds_the_cpu_champion(simulated: dict, case: str) -> None:
    assert simulated["simulating"]
    cpu, gpu = simulated["evolve"][f"{case}/cpu"], simulated["evolve"][f"{case}/cuda"]
    assert gpu["genome"] == cpu["genome"]  # the same champion, bit for bit
    assert gpu["episodes"] == cpu["episodes"] and len(gpu["history"]) == len(cpu["history"]) >= 1
    _close(cpu["history"], gpu["history"])
    np.testing.assert_allclose(gpu["return"], cpu["return"], rtol=SIM_RTOL, atol=0)


@pytest.mark.slow
def test_evolve_runs_generations_and_races(simulated: dict) -> None:
    # Not one generation only: replacement (steady state), resampling, races and CMA-ES updates ran.
    ev = simulated["evolve"]
    assert ev["steady/cpu"]["episodes"] >= 20 and len(ev["steady/cpu"]["history"]) > 1
    assert len(ev["fixed2/cpu"]["history"]) >= 2 and len(ev["race/cpu"]["history"]) >= 2 and len(ev["cma/cpu"]["history"]) >= 3


@pytest.mark.slow
def test_reproduce_on_cuda_matches_the_cpu_store(simulated: dict) -> None:
    runs = simulated["reproduce"]
    assert runs["cpu"]["rc"] == runs["cuda"]["rc"] == 0
    assert set(runs["cpu"]["results"]) == {"evolve/k2/run0", "evolve/race/run0"}
    _close(runs["cpu"]["results"], runs["cuda"]["results"])
    # Same config hash on either device: nothing is flown again, nothing changes.
    assert runs["cpu_then_cuda"]["rc"] == 0 and runs["cpu_then_cuda"]["results"] == runs["cpu"]["results"]


@pytest.mark.slow
def test_cli_evolve_on_cuda_matches_the_cpu(simulated: dict) -> None:
    cli = simulated["cli"]
    assert cli["cpu"]["rc"] == cli["cuda"]["rc"] == 0
    _close(cli["cpu"]["policy"], cli["cuda"]["policy"])


def _no_gpu() -> bool:
    from neurohover.sim.cuda import cuda_problem

    return cuda_problem() is not None


@pytest.mark.parametrize(
    "argv",
    [
        ["evolve", "--task", "ghh08", "--mdp", "train:0", "--budget", "5", "--episode-steps", "5"],
        ["reproduce", "fig2"],
        ["compete", "--task", "ghh08", "--agent", "generic", "--runs", "1", "--episodes", "1"],
    ],
    ids=["evolve", "reproduce", "compete"],
)
def test_cli_refuses_an_unknown_device(argv: list[str], tmp_path: Path, capsys) -> None:
    with pytest.raises(SystemExit) as exc:
        main([*argv, "--device", "tpu", "--out" if argv[0] != "reproduce" else "--store", str(tmp_path / "x")])
    assert exc.value.code == 2
    assert "invalid choice: 'tpu'" in capsys.readouterr().err


@pytest.mark.parametrize(
    "argv",
    [
        ["evolve", "--task", "ghh08", "--mdp", "train:0", "--budget", "5", "--episode-steps", "5", "--out"],
        ["reproduce", "fig2", "--store"],
        ["compete", "--task", "ghh08", "--agent", "generic", "--runs", "1", "--episodes", "1", "--episode-steps", "5", "--out"],
    ],
    ids=["evolve", "reproduce", "compete"],
)
def test_cli_cuda_without_a_gpu_is_one_clear_error(argv: list[str], tmp_path: Path, capsys) -> None:
    if not _no_gpu():
        pytest.skip("a CUDA GPU (or the simulator) is usable here")
    out = tmp_path / "out"
    assert main([*argv, str(out), "--device", "cuda"]) == 2
    assert "device='cuda' cannot run here" in capsys.readouterr().err
    assert not list(tmp_path.iterdir())  # refused before anything was written


def test_executors_and_flyer_check_the_device() -> None:
    from neurohover import NeurohoverError
    from neurohover.evaluate import KernelFlyer
    from neurohover.experiments import LocalExecutor, make_executor

    with pytest.raises(NeurohoverError, match="device='tpu' is unknown"):
        KernelFlyer("slp", 0, 10, device="tpu")
    with pytest.raises(NeurohoverError, match="device='tpu' is unknown"):
        make_executor("local", device="tpu")
    assert LocalExecutor(1).device == "cpu"
    if _no_gpu():
        with pytest.raises(NeurohoverError, match="device='cuda' cannot run here"):
            KernelFlyer("slp", 0, 10, device="cuda")
