"""Issue 37, items left by the twenty-sixth session and closed in the twenty-seventh, and three seen on the way: an MDP made before
``importlib.reload(neurohover.tasks.drift)`` was refused by evaluate as "give an MDP or a task family", although it is
one (its Drift is of the first import): now named by its cause, as T42-B07 names a reloaded Sensor's or Drift's; FGHH
sigmas of one set variant shared the seeded set first built; a crash joined with a longer budget was charged for it;
a Ctrl-C that Python wrapped in a RuntimeError while the command imported was a traceback."""

from __future__ import annotations

import importlib
import sys

import pytest

import neurohover as nh
from neurohover import NeurohoverError


def test_an_mdp_made_before_a_reload_of_drift_is_named_by_its_cause() -> None:
    mdp = nh.get_task_family("ghh08").test_mdps()[0]
    module = sys.modules["neurohover.tasks.drift"]
    saved = dict(module.__dict__)
    try:
        importlib.reload(module)
        cause = r"^mdp's drift Drift\(.*is a Drift of another import of neurohover\.tasks\.drift \(the module was reloaded\?\)"
        with pytest.raises(NeurohoverError, match=cause):
            nh.evaluate(nh.baseline_policy(), mdp, n_steps=10)
    finally:
        module.__dict__.clear()
        module.__dict__.update(saved)
    assert nh.evaluate(nh.baseline_policy(), mdp, n_steps=10).returns.size == 1  # the first import's again


def test_fghh_sigmas_of_one_set_variant_fly_their_own_seeded_sets() -> None:
    """Seen while fixing T50-B02: FGHH's seeded sets were cached by set_variant (round(sigma * 1e6)), so after sigma
    0.2000001's test set, sigma 0.2000004's was the same MDPs, drawn at the other sigma, without a word. Both draw from
    one seed (one variant), so each parameter's distance from the default scales with its own sigma."""
    import numpy as np

    from neurohover.tasks.fghh import DEFAULT_PARAMS

    first = nh.get_task_family("fghh", 0.2000001).test_mdps()[0]
    second = nh.get_task_family("fghh", 0.2000004).test_mdps()[0]
    ratio = (np.asarray(second.params) - DEFAULT_PARAMS) / (np.asarray(first.params) - DEFAULT_PARAMS)
    assert np.allclose(ratio, 0.2000004 / 0.2000001, rtol=1e-9, atol=0)


def test_a_crash_joined_with_a_longer_budget_keeps_no_budget() -> None:
    """Seen while fixing T51-B03: a + b kept the longer episode_steps where only the shorter recording crashed, so
    observed_return charged its crash for the longer budget's steps left, a wrong return without a word. Now the joined
    recording keeps no budget, and the crashed episode's return is refused by name; the other's is its own."""
    from neurohover.models import observed_return

    mdp = nh.get_task_family("ghh08").mdp("train:0")
    crashed = nh.evaluate(nh.prototype("slp", "zero"), mdp, record=True, n_steps=100)
    full = nh.evaluate(nh.baseline_policy(), mdp, record=True, n_steps=200)
    assert crashed.crashed.all() and not full.crashed.any()
    both = crashed.flight_data + full.flight_data
    assert "episode_steps" not in both.metadata
    with pytest.raises(NeurohoverError, match=r"episode 0: its metadata episode_steps=None is not allowed: the episode crashed"):
        observed_return(both, 0)
    assert observed_return(both, 1) == pytest.approx(float(full.returns.ravel()[0]), rel=1e-12)
    assert (full.flight_data + full.flight_data).metadata["episode_steps"] == 200  # one budget: kept


@pytest.mark.slow
def test_a_ctrl_c_python_wraps_while_the_package_imports_ends_with_one_line() -> None:
    """Seen in this session's full run: a Ctrl-C landing in a class body's __set_name__ (functools.cached_property) while
    the command imported its modules is raised by Python as RuntimeError("Error calling __set_name__") from the
    KeyboardInterrupt, and the import-time hook printed its traceback: now it ends with one line and 130, as a bare one."""
    import subprocess
    import sys

    script = (
        "import neurohover\n"
        "try:\n"
        "    try:\n"
        "        raise KeyboardInterrupt\n"
        "    except KeyboardInterrupt as stop:\n"
        "        raise RuntimeError(\"Error calling __set_name__ on 'cached_property' instance\") from stop\n"
        "except RuntimeError as err:\n"
        "    neurohover._interrupted(type(err), err, err.__traceback__)\n"
    )
    proc = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 130 and proc.stderr.strip() == "neurohover: interrupted", proc.stderr[-1500:]
