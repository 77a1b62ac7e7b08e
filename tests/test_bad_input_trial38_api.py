"""Bad-input trial 38 (the Python API): evolve(checkpoint=P) without resume replaced an existing checkpoint, an
unfinished run's too, without a word, where the command line says so (T38-B08): it warns (CheckpointReplaced), and the
command line, which says it in its own words, does not repeat it."""

from __future__ import annotations

import json
import warnings

import pytest

from neurohover.evolution import CheckpointReplaced  # where evolve() is


def test_evolve_warns_as_it_replaces_a_checkpoint(tmp_path, cli):
    from neurohover import get_task_family
    from neurohover.evolution import evolve

    mdp, path = get_task_family("ghh08").training_mdps()[0], tmp_path / "run.json"
    run = {"topology": "slp", "n_steps": 10, "checkpoint": path}
    with warnings.catch_warnings():
        warnings.simplefilter("error", CheckpointReplaced)
        evolve(mdp, budget=10, seed=0, **run)  # no checkpoint there yet: no word
        evolve(mdp, budget=60, seed=0, resume=True, **run)  # continued, not replaced
    with pytest.warns(CheckpointReplaced, match="holds a run's checkpoint: this run starts afresh and replaces it \\(resume=True continues it\\)"):
        evolve(mdp, budget=10, seed=5, **run)
    assert json.loads(path.read_text())["config"]["seed"] == 5
    out = tmp_path / "p.json"
    argv = ("evolve", "--task", "ghh08", "--budget", "10", "--episode-steps", "10", "--out", str(out))
    assert cli(*argv)[0] == 0
    with warnings.catch_warnings():
        warnings.simplefilter("error", CheckpointReplaced)  # the command line's own note, not the warning
        rc, _, err = cli(*argv)
    assert rc == 0 and "starting afresh; " in err and "(--resume continues it)" in err and "CheckpointReplaced" not in err, err


def test_the_vector_env_takes_the_autoreset_mode_it_resets_in():
    """T38-B01: make_vec(..., autoreset_mode=AutoresetMode.NEXT_STEP), the mode its metadata names, was refused as an
    unknown argument (Gymnasium passes a vector entry point's arguments only as keywords), and SAME_STEP likewise
    without naming the mode it takes."""
    import gymnasium as gym
    from gymnasium.vector import AutoresetMode

    from neurohover.errors import NeurohoverError

    make = {"id": "neurohover/GHH08-v0", "num_envs": 2, "vectorization_mode": "vector_entry_point"}
    for given in (AutoresetMode.NEXT_STEP, "NextStep"):
        env = gym.make_vec(**make, autoreset_mode=given)
        assert env.unwrapped.autoreset_mode is AutoresetMode.NEXT_STEP is env.metadata["autoreset_mode"]
        env.reset(seed=0)
        env.close()
    for given in (AutoresetMode.SAME_STEP, AutoresetMode.DISABLED, "x", 3):
        with pytest.raises(NeurohoverError, match="is not supported: this vector env resets in AutoresetMode.NEXT_STEP \\('NextStep'\\) only"):
            gym.make_vec(**make, autoreset_mode=given)


@pytest.mark.slow
def test_plot_compete_checks_a_summary_against_its_store(cli, tmp_path, monkeypatch):
    """T38-B06: a compete summary.json edited to a sensor or drift its runs never flew was plotted under that label
    (nothing in the folder contradicts it); plot --compete checks the flight conditions against the store the summary
    names, which compete now names by its absolute path (an older relative one from the working directory)."""
    import shutil

    monkeypatch.chdir(tmp_path)
    argv = ("compete", "--task", "ghh08", "--agent", "baseline", "--runs", "1", "--episodes", "2", "--episode-steps", "10")
    rc, _, err = cli(*argv, "--out", "c", "--store", "c.sqlite")
    assert rc == 0, err
    summary = json.loads((tmp_path / "c" / "summary.json").read_text())
    assert summary["store"] == str(tmp_path / "c.sqlite")
    plot = ("plot", "--out", str(tmp_path / "png"), "--compete")
    assert cli(*plot, "c")[0] == 0
    for edit, named in (({"sensor": {"velocity": 0.5}}, "sensor.velocity: its store's 0.0, given 0.5"),
                        ({"drift": {"walk": 0.1}}, "drift.walk: its store's 0.0, given 0.1"),
                        ({"seed": 7}, "seed: its store's 0, given 7"),
                        ({"store": "c.sqlite", "seed": 3}, "seed: its store's 0, given 3")):  # an older relative store path  # fmt: skip
        shutil.rmtree("e", ignore_errors=True)
        shutil.copytree("c", "e")
        (tmp_path / "e" / "summary.json").write_text(json.dumps({**summary, **edit}))
        rc, _, err = cli(*plot, "e")
        assert rc == 2 and "is not what its store" in err and named in err and "compete-ghh08-baseline" in err, err
    (tmp_path / "c.sqlite").rename(tmp_path / "moved.sqlite")  # a store no longer where the summary says is not read
    assert cli(*plot, "e")[0] == 0
