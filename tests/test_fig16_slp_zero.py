"""Figure 16's zero-setting agents with an SLP generic (issue 32): the generics' topology as a setting, the runs on
Figure 16's seeds, and the report pairing them with Figure 16's runs."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from neurohover.errors import NeurohoverError
from neurohover.experiments import Store, reproduce, write_report
from neurohover.experiments.config import load_config, make_config
from neurohover.experiments.executors import make_executor
from neurohover.experiments.plans import plan
from neurohover.experiments.units import unit_seed
from neurohover.policies import Policy, load_policy, prototype, save_policy


def test_the_zero_setting_generics_are_slps_and_the_runs_take_figure_16s_seeds() -> None:
    cfg = load_config("fig16-slp-zero", "paper")
    units = plan(cfg, {}).units
    generics = [u for u in units if u.key.startswith("policy/generic-zero")]
    assert len(generics) == 100 and all(u.params["topology"] == "slp" for u in generics)
    mlp = [u for u in plan(load_config("fig16", "paper"), {}).units if u.key.startswith("policy/generic-zero")]
    assert mlp and all(u.params["topology"] == "mlp" for u in mlp)  # Figure 16's own, as before
    done = {u.key: {"champion": {"topology": "slp", "genome": [0.0] * 40}} for u in generics}
    runs = [u for u in plan(cfg, done).units if u.kind == "test_run"]
    assert len(runs) == 200
    for u in runs[:5]:
        agent = u.params["agent"]
        assert u.params["seed"] == unit_seed(2016, "fig16", u.key.replace(f"run/{agent}/slp/", f"run/{agent}/"))


def test_the_generics_topology_is_refused_where_no_generic_is_evolved() -> None:
    base = {"task": "fghh", "seed": 1, "episodes": 2, "generic_topology": "slp", "groups": [{"agent": "authors-zero", "n_mdps": 1}]}
    with pytest.raises(NeurohoverError, match="generic_topology applies to the FGHH generics an experiment evolves itself"):
        make_config("x", "test_runs", "quick", {**base, "policies": "shipped"})
    with pytest.raises(NeurohoverError, match="generic_topology applies"):
        make_config("x", "test_runs", "quick", {**base, "task": "ghh08", "groups": [{"agent": "incremental", "n_mdps": 1}]})
    with pytest.raises(NeurohoverError, match="generic_topology = 'rnn' is not allowed"):
        make_config("x", "test_runs", "quick", {**base, "generic_topology": "rnn"})


@pytest.mark.slow
def test_the_report_pairs_each_run_with_figure_16s(committed_store: Path, tmp_path: Path) -> None:
    path = tmp_path / "s.sqlite"
    shutil.copyfile(committed_store, path)
    with Store(path) as store:
        executor = make_executor("local", jobs=1)
        try:
            reproduce(load_config("fig16-slp-zero", "quick"), store, executor, progress=False)
        finally:
            executor.close()
        write_report(store, tmp_path / "out", scale="quick", names=["fig16-slp-zero"])
    text = (tmp_path / "out" / "report.md").read_text()
    block = text[text.index("### Paired with another experiment's runs") :]
    assert "| authors-zero/slp | fig16/authors-zero | 3 |" in block
    assert "authors-zero/slp vs fig16's authors-zero on the same seeds:" in text


def _generics(folder: Path, shift: float = 0.0) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    base = prototype("slp", "baseline")
    for i in range(3):
        save_policy(Policy("slp", base.genome * (1.0 + 0.01 * i) + shift), folder / f"policy_{i:02d}.json")
    return folder


def test_generics_drawn_from_a_directory_of_policy_files(tmp_path: Path) -> None:
    """Figure 16 with the authors' published generics (their .net files) is this with their folder."""
    folder = _generics(tmp_path / "race")
    settings = {"task": "fghh", "sigma": 0.3, "seed": 3, "episodes": 2, "generics_from": {"race": f"dir:{folder}"}}
    cfg = make_config("x", "test_runs", "quick", {**settings, "groups": [{"agent": "authors-race", "n_mdps": 4}]})
    runs = [u for u in plan(cfg, {}).units if u.kind == "test_run"]
    genomes = {tuple(load_policy(folder / f"policy_{i:02d}.json").genome) for i in range(3)}
    assert len(runs) == 4 and all(tuple(u.params["policies"]["generic"]["genome"]) in genomes for u in runs)
    other = make_config(
        "x", "test_runs", "quick", {**settings, "generics_from": {"race": f"dir:{_generics(tmp_path / 'other', 0.5)}"}, "groups": cfg.settings["groups"]}
    )
    assert cfg.hash != other.hash  # the files' genomes are part of the config
    with pytest.raises(NeurohoverError, match="no directory of policy files"):
        make_config("x", "test_runs", "quick", {**settings, "generics_from": {"race": f"dir:{tmp_path / 'none'}"}, "groups": cfg.settings["groups"]})


def test_a_directorys_policy_files_are_drawn_whatever_the_case_of_their_suffix(tmp_path: Path) -> None:
    """A file of the folder named .JSON or .Net was left out of the draw without a word, as load_policy reads it."""
    folder = _generics(tmp_path / "race")
    (folder / "policy_01.json").rename(folder / "policy_01.JSON")
    (folder / "policy_02.json").rename(folder / "policy_02.Json")
    settings = {"task": "fghh", "sigma": 0.3, "seed": 3, "episodes": 2, "generics_from": {"race": f"dir:{folder}"}}
    cfg = make_config("x", "test_runs", "quick", {**settings, "groups": [{"agent": "authors-race", "n_mdps": 8}]})
    drawn = {u.params["policies"]["generic_source"].rsplit("/", 1)[-1] for u in plan(cfg, {}).units if u.kind == "test_run"}
    assert drawn == {"policy_00.json", "policy_01.JSON", "policy_02.Json"}
