"""Bad-input trial 34 (34b), the Python API: T34-B02 (PolicyTable.from_genomes given a ragged list raised NumPy's
ValueError), T34-B03 (FlightData.save and fly --record overwrote a policy file, model file, checkpoint or history reached
by an .npz name or a symbolic link), T34-B05 (CrashAwareReward over another reward wrapper lost the crash charge),
T34-B11 (evaluate_jobs took a 2-D fallback_index), T34-B15 (TaskFamily.make of a (1, N) array said "must be N numbers,
got N") and T34-B16 (saving float32 flight data printed NumPy's overflow RuntimeWarning)."""

from __future__ import annotations

import numpy as np
import pytest

import neurohover as nh
from neurohover.errors import NeurohoverError
from neurohover.evaluate import PolicyTable


@pytest.mark.parametrize("topology", ["slp", "mlp"])
def test_b02_from_genomes_refuses_a_ragged_list_by_name(topology: str) -> None:
    """T34-B02: rows of unequal length were NumPy's "inhomogeneous shape" ValueError; equal rows still make a table."""
    g = list(nh.prototype(topology, "baseline").genome)
    with pytest.raises(NeurohoverError, match=rf"^{topology} genomes=.* are not allowed: give an array of real numbers \(P, {len(g)}\), rows of equal"):
        PolicyTable.from_genomes([g, g[:-1]], topology)
    assert len(PolicyTable.from_genomes([g, g], topology)) == 2


def test_b11_evaluate_jobs_refuses_a_2d_fallback_index() -> None:
    """T34-B11: a (1, 2) fallback_index was flattened, while the three job indexes refuse 2-D arrays."""
    fam = nh.get_task_family("ghh08")
    policies, mdps = [nh.baseline_policy(), nh.prototype("mlp", "baseline")], fam.training_mdps()
    with pytest.raises(NeurohoverError, match=r"^fallback_index must be a 1-D array of job indices, got shape \(1, 2\)"):
        nh.evaluate_jobs(policies, mdps, [0, 1], [0, 1], [0, 1], fallback_index=np.array([[1, -1]]), n_steps=20)
    ev = nh.evaluate_jobs(policies, mdps, [0, 1], [0, 1], [0, 1], fallback_index=np.array([1, -1]), n_steps=20)
    assert ev.returns.shape == (2,)
