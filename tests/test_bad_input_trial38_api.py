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
